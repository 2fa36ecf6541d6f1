//! One model-predictive period's re-plan, shared by `benches/control.rs`
//! (which times it) and `work_precision` (whose `MPC pattern` line counts
//! its predictor calls): the plan's first push run for 0.2 s on the dynamic
//! model with μ × 0.8 as the plant, so the warm start has something to
//! correct, and the re-plan's start and warm parameters from there.

use pushval::control::mpc::PlantScale;
use pushval::control::plan::{Params, Planner, Solution};
use pushval::control::predict::{Motion, Start};
use pushval_engine::EngineState;
use pushval_model::{DynamicModel, Problem, Simulator, Vec2};

/// How long the plant runs the plan's first push before the re-plan (s).
pub const PERIOD_AT: f64 = 0.2;

/// The measured start of the re-plan (the plant's state after
/// [`PERIOD_AT`]) and the plan's parameters over the time left.
pub fn replan_case(problem: &Problem, planner: &Planner, plan: &Solution) -> (Start, Params) {
    let mut plant = PlantScale {
        mu_scale: 0.8,
        inertia_scale: 1.0,
    }
    .apply(problem)
    .unwrap();
    plant.pushes = vec![pushval_model::Push {
        duration: PERIOD_AT,
        ..plan.pushes[0]
    }];
    let s = *DynamicModel::default()
        .simulate(&plant)
        .unwrap()
        .samples
        .last()
        .unwrap();
    let v_cm = pushval_engine::rigid_cm_velocity(problem, Some(&plant.pushes[0]), s.theta, s.omega);
    let st = EngineState {
        t: s.t,
        x: s.x,
        y: s.y,
        theta: s.theta,
        omega: s.omega,
        v_cm,
    };
    let from = Start {
        theta: s.theta,
        position: Vec2::new(s.x, s.y),
        motion: Motion::Moving {
            omega: s.omega,
            momentum: st.contact_momentum(problem),
        },
    };
    let warm = planner.with_duration(&plan.params, planner.duration(&plan.params) - PERIOD_AT);
    (from, warm)
}
