//! The paper plate for the tests (as `src/study/plate.rs`).
#![allow(dead_code)]

use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};

pub const MU: f64 = 0.5;
pub const G: f64 = 9.81;
pub const HALF: f64 = 0.125;
pub const PHI: f64 = std::f64::consts::FRAC_PI_4 + 0.3;

/// The paper plate: mass 1 kg, supports at the corners of a 0.25 m square,
/// `μ m g / 4` each, pushed at (−HALF, −HALF).
pub fn plate() -> Body {
    let h = HALF;
    let s: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: MU * G / 4.0,
        })
        .collect();
    Body::new(1.0, 0.25 * 0.25 / 6.0, Vec2::new(-h, -h), &s).unwrap()
}

pub fn push(speed: f64, phi: f64, duration: f64) -> Push {
    Push {
        duration,
        speed,
        phi,
    }
}

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
