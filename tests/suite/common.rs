//! Shared builders for the tests.

use std::f64::consts::FRAC_PI_4;
use std::path::{Path, PathBuf};

use pushval_model::{
    Body, ContactLimits, DynamicModel, Initial, Integrator, Problem, Push, Simulator, Support,
    Switching, Trajectory, Vec2,
};
use pushval_scenario::Scenario;

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

pub fn paper_plate() -> Body {
    square(0.25, 1.0, 0.5, G)
}

/// The paper-style angle `π/4 + 0.3` used for steady-state figures.
pub const PHI: f64 = FRAC_PI_4 + 0.3;

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

pub fn adaptive(tol: f64, skip: bool) -> DynamicModel {
    DynamicModel {
        integrator: Integrator::Adaptive { tol },
        skip_settled: skip,
        check_assumptions: true,
        ..Default::default()
    }
}

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

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Loads a scenario with the repository's outside engines (pushval.toml)
/// in the registry, as the command line run from the repository does.
pub fn load(p: &Path) -> Scenario {
    use_repo_engines();
    pushval::registry::load(p).unwrap_or_else(|e| panic!("{e}"))
}

/// Loads the repository's pushval.toml into the registry (once).
pub fn use_repo_engines() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        pushval::registry::use_engines_file(Some(&root().join("pushval.toml")))
            .unwrap_or_else(|e| panic!("{e}"))
    });
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
