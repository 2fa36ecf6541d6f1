//! Shared scenes for the MuJoCo tests.
#![allow(dead_code)]

use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};

pub const MU: f64 = 0.5;
pub const G: f64 = 9.81;
pub const HALF: f64 = 0.125;

/// The paper plate: 0.25 m square, 1 kg, four corner supports, μ 0.5, equal
/// loads, pushed at the corner (−0.125, −0.125).
pub fn plate() -> Body {
    let h = HALF;
    let supports: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: MU * G / 4.0,
        })
        .collect();
    Body::new(
        1.0,
        1.0 * (0.25f64.powi(2) * 2.0) / 12.0,
        Vec2::new(-h, -h),
        &supports,
    )
    .unwrap()
}

/// φ of the paper's runs (rad).
pub fn paper_phi() -> f64 {
    std::f64::consts::FRAC_PI_4 + 0.3
}

/// One constant push of `duration` s, starting with the pusher at ω = 0.
pub fn problem(body: &Body, speed: f64, phi: f64, duration: f64) -> Problem {
    Problem {
        body: body.clone(),
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

/// The body mirrored about the x axis (y → −y), supports and contact.
pub fn mirrored(body: &Body) -> Body {
    let supports: Vec<Support> = body
        .supports()
        .map(|s| Support {
            position: Vec2::new(s.position.x, -s.position.y),
            friction: s.friction,
        })
        .collect();
    let c = body.contact();
    Body::new(
        body.mass(),
        body.inertia_cm(),
        Vec2::new(c.x, -c.y),
        &supports,
    )
    .unwrap()
}
