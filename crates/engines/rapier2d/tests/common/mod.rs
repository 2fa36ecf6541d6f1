//! The square plate of the seed paper, pushed at a corner.
#![allow(dead_code)]

use std::f64::consts::FRAC_PI_4;

use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Trajectory, Vec2};

/// 0.25 m square, 1 kg, I_cm = m(a²+a²)/12, four corner supports with μ = 0.5
/// and equal loads, contact at corner (−0.125, −0.125); 1 s at φ = π/4, then
/// 3 s at φ = π/4 + 0.3, both at `speed` (m/s).
pub fn plate(speed: f64, from_rest: bool) -> Problem {
    let (m, a, mu, g) = (1.0, 0.25, 0.5, 9.81);
    let h = a / 2.0;
    let supports: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: mu * m * g / 4.0,
        })
        .collect();
    let body = Body::new(m, m * (a * a + a * a) / 12.0, Vec2::new(-h, -h), &supports).unwrap();
    Problem {
        body,
        limits: Default::default(),
        pushes: vec![
            Push {
                duration: 1.0,
                speed,
                phi: FRAC_PI_4,
            },
            Push {
                duration: 3.0,
                speed,
                phi: FRAC_PI_4 + 0.3,
            },
        ],
        initial: Initial {
            from_rest,
            ..Default::default()
        },
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

/// Largest CM distance (m) and angle difference (rad) over the common samples.
pub fn max_errors(a: &Trajectory, b: &Trajectory) -> (f64, f64) {
    assert_eq!(a.samples.len(), b.samples.len());
    a.samples
        .iter()
        .zip(&b.samples)
        .fold((0.0f64, 0.0f64), |(p, t), (s, r)| {
            assert!((s.t - r.t).abs() < 1e-12);
            (
                p.max(((s.x - r.x).powi(2) + (s.y - r.y).powi(2)).sqrt()),
                t.max((s.theta - r.theta).abs()),
            )
        })
}
