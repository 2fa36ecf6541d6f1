//! Sampling, settings, diagnostics and degenerate inputs.

mod common;

use pushval_model::{Simulator, Trajectory};
use pushval_rapier2d::{DetailedEngine, EngineSettings, Precision, RapierSimulator};

fn finite(t: &Trajectory) -> bool {
    t.samples
        .iter()
        .all(|s| s.x.is_finite() && s.y.is_finite() && s.theta.is_finite() && s.omega.is_finite())
}

#[test]
fn samples_at_problem_times_and_diagnostics() {
    let problem = common::plate(1.0, false);
    let sim = RapierSimulator::default();
    assert_eq!(sim.name(), "rapier2d");
    let run = sim.run(&problem).unwrap();
    let times = problem.sample_times();
    assert_eq!(run.trajectory.samples.len(), times.len());
    for (s, t) in run.trajectory.samples.iter().zip(&times) {
        assert_eq!(s.t, *t);
    }
    assert!(finite(&run.trajectory));
    assert_eq!(run.trajectory.model, "rapier2d");
    assert_eq!(run.settings, EngineSettings::default());
    // 1000 + 3000 steps plus one switch step per segment and (leapfrog, the
    // default) one closing step at the end of every segment (a segment's
    // steps depend on its push alone, not on whether another follows).
    assert_eq!(run.steps, 4004);
    // Where the time went: rapier's steps are part of the stepping loop,
    // which is part of the run.
    assert!(run.rapier_step_time > std::time::Duration::ZERO);
    assert!(run.rapier_step_time <= run.stepping_time);
    assert!(run.stepping_time <= run.wall_time);
    assert!(run.max_joint_drift < 1e-5, "drift {}", run.max_joint_drift);
    assert_eq!(run.segment_tail_omega.len(), 2);
    assert_eq!(run.trajectory.segments.len(), 2);
}

#[test]
fn steps_land_on_switch_times() {
    let mut problem = common::plate(0.5, false);
    problem.pushes[0].duration = 0.123_456;
    let run = RapierSimulator::new(EngineSettings {
        dt: 0.01,
        ..Default::default()
    })
    .run(&problem)
    .unwrap();
    assert!(run.history.iter().any(|r| r.t1 == 0.123_456));
    let end = run.history.last().unwrap().t1;
    assert!((end - problem.duration()).abs() < 1e-12);
}

#[test]
fn zero_speed_and_f32_stay_finite() {
    let mut problem = common::plate(1.0, false);
    problem.pushes[1].speed = 0.0; // every support stops: no friction direction
    for precision in [Precision::F64, Precision::F32] {
        let t = RapierSimulator::new(EngineSettings {
            precision,
            ..Default::default()
        })
        .simulate(&problem)
        .unwrap();
        assert!(finite(&t));
        let last = t.samples.last().unwrap();
        // Pinned at the contact, the object can only turn about it, and the
        // explicit Coulomb friction stops that turning up to a chatter of
        // about one step's friction impulse (F L h / I_P ≈ 0.013 rad/s here).
        assert!(last.omega.abs() < 0.05, "stopped: {}", last.omega);
        assert!(t.samples.iter().all(|s| s.omega.abs() < 3.0));
    }
}

#[test]
fn bad_settings_are_refused() {
    let problem = common::plate(1.0, false);
    for s in [
        EngineSettings {
            dt: 0.0,
            ..Default::default()
        },
        EngineSettings {
            solver_iterations: 0,
            ..Default::default()
        },
        EngineSettings {
            switch_step_fraction: 0.7,
            ..Default::default()
        },
    ] {
        assert!(RapierSimulator::new(s).run(&problem).is_err());
    }
}
