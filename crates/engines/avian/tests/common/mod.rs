//! The paper plate and the comparisons the tests share.
#![allow(dead_code)]

use std::f64::consts::FRAC_PI_4;

use pushval_model::{
    Body, DynamicModel, Initial, Problem, Push, SegmentDynamics, Simulator, Support, Switching,
    Trajectory, Vec2,
};

/// 0.25 m square, 1 kg, I_cm = m(a²+a²)/12, four corner supports with μ = 0.5
/// and equal loads, contact at the corner (−0.125, −0.125); one push per
/// `(duration, speed, phi)`.
pub fn plate(pushes: &[(f64, f64, f64)], from_rest: bool) -> Problem {
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
        pushes: pushes
            .iter()
            .map(|&(duration, speed, phi)| Push {
                duration,
                speed,
                phi,
            })
            .collect(),
        initial: Initial {
            from_rest,
            ..Default::default()
        },
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

/// The brief's push: φ = π/4 + 0.3 for `duration` s at `speed`.
pub fn paper(speed: f64, duration: f64) -> Problem {
    plate(&[(duration, speed, FRAC_PI_4 + 0.3)], false)
}

/// The stable Coulomb root ω* the analytic model settles on from rest.
pub fn coulomb_root(p: &Problem, segment: usize) -> f64 {
    SegmentDynamics::new(&p.body, &p.pushes[segment])
        .attractor_from(0.0)
        .unwrap()
        .omega
}

/// The analytic dynamic model's trajectory.
pub fn reference(p: &Problem) -> Trajectory {
    DynamicModel::default().simulate(p).unwrap()
}

/// Largest CM distance (m) and angle difference (rad) over the samples.
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
