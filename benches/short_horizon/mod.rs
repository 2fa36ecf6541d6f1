//! The model-predictive controller's unit of work, shared by the
//! `model_short_horizon` criterion bench and `work_precision`: one run of the
//! dynamic model over a 6-segment horizon from rest on the paper plate, with
//! two samples (its start and end) or the final state alone, and the
//! assumption checks off.

use pushval_model::{DynamicModel, Initial, Integrator, Problem, Push};
use pushval_scenario::Scenario;

/// Segments of the horizon.
pub const SEGMENTS: usize = 6;

/// The paper plate (scenarios/paper-square-v1.0.toml) pushed at 1 m/s from
/// rest for six 0.1 s segments whose directions step about the diagonal;
/// `sample_dt` is the whole horizon, so the samples are its start and end.
pub fn problem(root: &std::path::Path) -> Problem {
    let sc = Scenario::from_path(root.join("scenarios/paper-square-v1.0.toml")).unwrap();
    let mut p = sc.problem();
    let q = std::f64::consts::FRAC_PI_4;
    p.pushes = [q + 0.3, q, q - 0.3, q + 0.5, q + 0.15, q - 0.1]
        .iter()
        .map(|&phi| Push {
            duration: 0.1,
            speed: 1.0,
            phi,
        })
        .collect();
    assert_eq!(p.pushes.len(), SEGMENTS);
    p.initial = Initial {
        from_rest: true,
        ..p.initial
    };
    p.sample_dt = p.duration();
    p
}

/// The horizon's model: the dynamic model's default integrator (DOP853 at
/// 1e-10), assumption checks off.
pub fn model() -> DynamicModel {
    DynamicModel {
        check_assumptions: false,
        ..Default::default()
    }
}

/// The tolerance the planner's predictor runs DOP853 at (`Predict::new` in
/// the control code: 1e-9 per step).
pub const PREDICTOR_TOL: f64 = 1e-9;

/// The predictor's model: DOP853 at [`PREDICTOR_TOL`], the settled-arc
/// shortcut on, assumption checks off (it asks for the final state).
pub fn predictor() -> DynamicModel {
    DynamicModel {
        integrator: Integrator::Dop853 { tol: PREDICTOR_TOL },
        ..model()
    }
}
