//! The scene every study runs: the seed paper's plate, its push grids and
//! the Coulomb model's answer for it.

use std::f64::consts::FRAC_PI_4;

use pushval_engine::rel_err;
use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};

/// Friction coefficient of every support (dimensionless).
pub const MU: f64 = 0.5;
/// Gravity (m/s²).
pub const G: f64 = 9.81;
/// Mass of the plate (kg).
pub const MASS: f64 = 1.0;
/// Half the side of the square plate (m): the supports sit at its corners.
pub const HALF: f64 = 0.125;
/// The push direction of the studies' tables (rad).
pub const PHI_TABLE: f64 = FRAC_PI_4 + 0.3;
/// The pusher speeds of the studies' tables (m/s).
pub const TABLE_SPEEDS: [f64; 3] = [0.2, 0.5, 1.0];
/// The Froude numbers of the (Fr, φ) maps: 20 log-spaced from 0.02 to 2
/// (3 significant digits), so each map has 20 × 20 = 400 cells.
pub const FRS: [f64; 20] = [
    0.02, 0.0255, 0.0325, 0.0414, 0.0527, 0.0672, 0.0856, 0.109, 0.139, 0.177, 0.226, 0.288, 0.367,
    0.467, 0.595, 0.759, 0.967, 1.23, 1.57, 2.0,
];
/// The quick grid's Froude numbers (tests): 5 log-spaced over the same range.
pub const FRS_QUICK: [f64; 5] = [0.02, 0.0632, 0.2, 0.632, 2.0];
/// Range of the maps' push directions (rad).
pub const PHI_RANGE: (f64, f64) = (0.15, 1.42);

/// The paper plate: a 2 HALF square of mass MASS on four corner supports
/// with friction MU and equal loads (each `μ m g / 4`), pushed at the corner
/// (−HALF, −HALF), geometric inertia `m (2 HALF)² / 6`.
pub fn plate() -> Body {
    let h = HALF;
    let supports: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: MU * MASS * G / 4.0,
        })
        .collect();
    let side = 2.0 * h;
    Body::new(MASS, MASS * side * side / 6.0, Vec2::new(-h, -h), &supports)
        .expect("the paper plate is a valid body")
}

/// One push of the paper plate at `speed` (m/s) in direction `phi` (rad) for
/// `duration` (s), from θ = 0 moving with the pusher (ω = 0), samples every
/// 10 ms; with `supports_half` (m), the supports moved to the corners of a
/// square of that half side (same loads, contact and inertia).
pub fn paper_plate(speed: f64, phi: f64, duration: f64, supports_half: Option<f64>) -> Problem {
    let mut body = plate();
    if let Some(h) = supports_half {
        let s: Vec<Support> = body
            .supports()
            .map(|s| Support {
                position: s.position * (h / HALF),
                friction: s.friction,
            })
            .collect();
        body = Body::new(body.mass(), body.inertia_cm(), body.contact(), &s)
            .expect("the plate on moved supports is a valid body");
    }
    Problem {
        body,
        limits: Default::default(),
        pushes: vec![Push {
            duration,
            speed,
            phi,
        }],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

/// L = |p_c − p_cm| (m), the length of the Froude number.
pub fn length() -> f64 {
    plate().contact().norm()
}

/// Pusher speed (m/s) of a Froude number `Fr = v_c²/(μ g L)`.
pub fn speed_of(fr: f64) -> f64 {
    (fr * MU * G * length()).sqrt()
}

/// Froude number of a pusher speed (m/s).
pub fn froude(speed: f64) -> f64 {
    speed * speed / (MU * G * length())
}

/// The maps' push directions (rad): 20 evenly spaced in [`PHI_RANGE`] (5
/// on the quick grid).
pub fn phis(quick: bool) -> Vec<f64> {
    let n = if quick { 5 } else { 20 };
    let (lo, hi) = PHI_RANGE;
    (0..n)
        .map(|k| lo + k as f64 * (hi - lo) / (n - 1) as f64)
        .collect()
}

/// The maps' Froude numbers.
pub fn frs(quick: bool) -> &'static [f64] {
    if quick {
        &FRS_QUICK
    } else {
        &FRS
    }
}

/// The engine against a reference ω: relative with the gate's floor
/// (`rel_err`); against a lock (reference 0), |ω| over |ω*|, the size of
/// what the lock removes.
pub fn err(engine: f64, reference: f64, coulomb: f64, speed: f64) -> f64 {
    if reference == 0.0 {
        rel_err(engine, 0.0, speed, length()).min(engine.abs() / coulomb.abs())
    } else {
        rel_err(engine, reference, speed, length())
    }
}
