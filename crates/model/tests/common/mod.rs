//! Shared builders for the model's tests: the seed paper's plate, problems
//! around it, and the dynamic model at a chosen tolerance. Each test crate
//! uses a part of them.
#![allow(dead_code)]

use std::f64::consts::FRAC_PI_4;

use pushval_model::{
    Body, ContactLimits, DynamicModel, Initial, Integrator, Problem, Push, Simulator, Support,
    Switching, Trajectory, Vec2,
};

/// Standard gravity (m/s²).
pub const G: f64 = 9.81;

/// The seed paper's plate: side `side` (m), mass `m` (kg), four corner
/// supports with friction coefficient `mu`, equal loads, pushed at the corner
/// (−side/2, −side/2), geometric inertia `m side² / 6`.
pub fn square(side: f64, m: f64, mu: f64, g: f64) -> Body {
    let a = side / 2.0;
    let sup: Vec<Support> = [(-a, -a), (a, -a), (a, a), (-a, a)]
        .iter()
        .map(|&(x, y)| Support {
            position: Vec2::new(x, y),
            friction: mu * m * g / 4.0,
        })
        .collect();
    Body::new(m, m * side * side / 6.0, Vec2::new(-a, -a), &sup).unwrap()
}

/// The paper's plate: 0.25 m, 1 kg, μ = 0.5.
pub fn paper_plate() -> Body {
    square(0.25, 1.0, 0.5, G)
}

/// The paper-style angle `π/4 + 0.3` used for steady-state figures.
pub const PHI: f64 = FRAC_PI_4 + 0.3;

/// A problem without contact limits, sampled every 0.01 s.
pub fn problem(body: Body, pushes: Vec<Push>, initial: Initial, switching: Switching) -> Problem {
    Problem {
        body,
        limits: ContactLimits::default(),
        pushes,
        initial,
        switching,
        sample_dt: 0.01,
        release: None,
    }
}

/// One push of `duration` (s) at `speed` (m/s) and angle `phi` (rad), from
/// the default start.
pub fn one_push(body: Body, duration: f64, speed: f64, phi: f64) -> Problem {
    problem(
        body,
        vec![Push {
            duration,
            speed,
            phi,
        }],
        Initial::default(),
        Switching::Impulsive,
    )
}

/// The dynamic model with Dormand–Prince 5(4) at `tol`, the settled-arc
/// shortcut on or off.
pub fn adaptive(tol: f64, skip: bool) -> DynamicModel {
    DynamicModel {
        integrator: Integrator::Adaptive { tol },
        skip_settled: skip,
        check_assumptions: true,
        ..Default::default()
    }
}

/// Runs `model` on `p`; panics on an error.
pub fn run(model: &DynamicModel, p: &Problem) -> Trajectory {
    model.simulate(p).unwrap()
}

/// Largest position and angle difference between two runs at common samples.
#[track_caller]
pub fn max_diff(a: &Trajectory, b: &Trajectory) -> (f64, f64) {
    assert_eq!(a.samples.len(), b.samples.len());
    a.samples
        .iter()
        .zip(&b.samples)
        .fold((0.0f64, 0.0f64), |(p, t), (x, y)| {
            assert_eq!(x.t, y.t);
            (
                p.max(((x.x - y.x).powi(2) + (x.y - y.y).powi(2)).sqrt()),
                t.max((x.theta - y.theta).abs()),
            )
        })
}

/// The paper plate with one heavily loaded corner (−a, a) on the line through
/// the contact perpendicular to a push along +x: the object pivots on it.
pub fn pivot_body() -> Body {
    let a = 0.125;
    let f = [0.05, 0.05, 0.05, 20.0];
    let sup: Vec<Support> = [(-a, -a), (a, -a), (a, a), (-a, a)]
        .iter()
        .zip(f)
        .map(|(&(x, y), friction)| Support {
            position: Vec2::new(x, y),
            friction,
        })
        .collect();
    Body::new(1.0, 0.25f64.powi(2) / 6.0, Vec2::new(-a, -a), &sup).unwrap()
}
