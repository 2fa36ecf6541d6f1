//! Shared scenes for the PhysX tests.
#![allow(dead_code)]

use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};

pub const MU: f64 = 0.5;
pub const G: f64 = 9.81;
pub const HALF: f64 = 0.125;

/// φ of the paper's runs (rad).
pub const PHI: f64 = std::f64::consts::FRAC_PI_4 + 0.3;

/// Four supports at (±half, ±half) in the order (−,−), (+,−), (+,+), (−,+),
/// each with friction magnitude `friction[i]` (N), on the paper plate's
/// mass and inertia (1 kg, 0.25 m square), pushed at the corner
/// (−0.125, −0.125).
pub fn plate_with(half: f64, friction: [f64; 4]) -> Body {
    let supports: Vec<Support> = corners(half)
        .iter()
        .zip(friction)
        .map(|(c, f)| Support {
            position: Vec2::new(c[0], c[1]),
            friction: f,
        })
        .collect();
    Body::new(
        1.0,
        0.25f64.powi(2) * 2.0 / 12.0,
        Vec2::new(-HALF, -HALF),
        &supports,
    )
    .unwrap()
}

/// The paper plate: four corner supports, μ 0.5, equal loads.
pub fn plate() -> Body {
    plate_with(HALF, [MU * G / 4.0; 4])
}

/// The corners (±half, ±half) in support order.
pub fn corners(half: f64) -> [[f64; 2]; 4] {
    [[-half, -half], [half, -half], [half, half], [-half, half]]
}

/// One push.
pub fn push(speed: f64, phi: f64, duration: f64) -> Push {
    Push {
        duration,
        speed,
        phi,
    }
}

/// One constant push of `duration` s, starting with the pusher at ω = 0.
pub fn problem(body: &Body, p: Push) -> Problem {
    Problem {
        body: body.clone(),
        limits: Default::default(),
        pushes: vec![p],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

/// `body` with support friction magnitudes `friction` (N).
pub fn with_friction(body: &Body, friction: &[f64]) -> Body {
    let supports: Vec<Support> = body
        .supports()
        .zip(friction)
        .map(|(s, &f)| Support {
            position: s.position,
            friction: f,
        })
        .collect();
    Body::new(body.mass(), body.inertia_cm(), body.contact(), &supports).unwrap()
}

pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}
