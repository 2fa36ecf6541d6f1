//! The plug-in surface (models, settings, options) and the run's
//! bookkeeping: samples, steps on switch times, degenerate inputs.

mod common;

use pushval_box2d::{
    models, Box2dSettings, Box2dSimulator, DetailedEngine, Friction, ENGINE_CRATE,
};
use pushval_engine::EngineOptions;
use pushval_model::{Simulator, Trajectory};

fn finite(t: &Trajectory) -> bool {
    t.samples
        .iter()
        .all(|s| s.x.is_finite() && s.y.is_finite() && s.theta.is_finite() && s.omega.is_finite())
}

#[test]
fn models_names_settings_and_options() {
    let rows = models();
    let names: Vec<&str> = rows.iter().map(|e| e.name).collect();
    assert_eq!(names, ["box2d", "box2d_motor_joint"]);
    for e in &rows {
        let engine = e.default_engine();
        assert_eq!(engine.name(), e.name);
        assert_eq!(engine.adapter(), "pushval-box2d");
        assert_eq!(engine.engine_crate(), ENGINE_CRATE);
        assert!(engine.gateable());
        assert_eq!(engine.default_dt(), 1e-3);
        let s = engine.settings(2.5e-4);
        assert_eq!(s["dt"], 2.5e-4);
        assert!(s["engine"].as_str().unwrap().contains(ENGINE_CRATE.version));
        assert_eq!(s["substeps"], 1);
    }
    let mut opts = EngineOptions {
        dt: Some(5e-4),
        ..Default::default()
    };
    opts.values.insert("substeps".into(), serde_json::json!(4));
    let engine = (rows[0].build)(&opts).unwrap();
    assert_eq!(engine.default_dt(), 5e-4);
    assert_eq!(engine.settings(5e-4)["substeps"], 4);
    for bad in [
        serde_json::json!(0),
        serde_json::json!(65),
        serde_json::json!("four"),
    ] {
        opts.values.insert("substeps".into(), bad.clone());
        let e = (rows[0].build)(&opts).err().expect("refused");
        assert_eq!(e.key, "substeps", "{bad}");
    }
}

#[test]
fn samples_at_problem_times_and_diagnostics() {
    let problem = common::plate(1.0, false);
    let sim = Box2dSimulator::default();
    assert_eq!(sim.name(), "box2d");
    let run = sim.run(&problem).unwrap();
    let times = problem.sample_times();
    assert_eq!(run.trajectory.samples.len(), times.len());
    for (s, t) in run.trajectory.samples.iter().zip(&times) {
        assert_eq!(s.t, *t);
    }
    assert!(finite(&run.trajectory));
    assert_eq!(run.steps, 4000);
    assert_eq!(run.history.len(), 4001);
    assert!(run.step_time > std::time::Duration::ZERO && run.step_time <= run.wall_time);
    assert_eq!(run.segment_tail_omega.len(), 2);
    assert!(run.trajectory.assumptions.min_support_speed > 0.0);
    let motor = Box2dSimulator::new(Box2dSettings {
        friction: Friction::MotorJoint,
        ..Default::default()
    });
    assert_eq!(motor.name(), "box2d_motor_joint");
    assert!(finite(&motor.simulate(&problem).unwrap()));
}

#[test]
fn steps_land_on_switch_times() {
    let mut problem = common::plate(0.5, false);
    problem.pushes[0].duration = 0.123_456;
    let run = Box2dSimulator::new(Box2dSettings {
        dt: 0.01,
        ..Default::default()
    })
    .run(&problem)
    .unwrap();
    // ceil(0.123456 / 0.01) = 13 steps, then 300.
    assert_eq!(run.steps, 13 + 300);
    assert!(run.history.iter().any(|r| r.t1 == 0.123_456));
    let end = run.history.last().unwrap().t1;
    assert!((end - problem.duration()).abs() < 1e-12);
}

#[test]
fn zero_speed_stays_finite_and_stops() {
    let mut problem = common::plate(1.0, false);
    problem.pushes[1].speed = 0.0; // every support stops: no friction direction
    for friction in [Friction::Coulomb, Friction::MotorJoint] {
        let t = Box2dSimulator::new(Box2dSettings {
            friction,
            ..Default::default()
        })
        .simulate(&problem)
        .unwrap();
        assert!(finite(&t));
        // Pinned at the contact, the object can only turn about it; the
        // explicit Coulomb friction stops that up to a chatter of about one
        // step's friction impulse (F L h / I_P ≈ 0.013 rad/s here).
        let last = t.samples.last().unwrap();
        assert!(last.omega.abs() < 0.05, "{friction:?}: {}", last.omega);
    }
}

#[test]
fn bad_settings_are_refused() {
    let problem = common::plate(1.0, false);
    for s in [
        Box2dSettings {
            dt: 0.0,
            ..Default::default()
        },
        Box2dSettings {
            dt: f64::NAN,
            ..Default::default()
        },
        Box2dSettings {
            substeps: 0,
            ..Default::default()
        },
    ] {
        assert!(Box2dSimulator::new(s).run(&problem).is_err(), "{s:?}");
    }
}
