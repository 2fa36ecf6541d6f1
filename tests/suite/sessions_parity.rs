//! The caller owns the loop: for every compiled-in engine of the build,
//! `run` is `start`, one `advance` per push and `finish`, bit for bit, on
//! every shipped scenario (as given, and from rest); and every engine steps
//! natively, keeping its world between pushes instead of replaying.

use pushval_engine::{Engine, EngineRun, EngineSession};
use pushval_model::{ModelError, Problem};

use crate::common::*;

/// The run with its wall-clock time cleared (the only field that may differ).
fn timeless(r: Result<EngineRun, ModelError>) -> Result<EngineRun, String> {
    r.map(|mut r| {
        r.wall_time = Default::default();
        r
    })
    .map_err(|e| format!("{e:?}"))
}

/// Equal as values; where both hold NaN at the same places (`==` is false
/// on NaN), equal in their exact (round-trip) Debug text.
fn same(a: &Result<EngineRun, String>, b: &Result<EngineRun, String>) -> bool {
    a == b || format!("{a:?}") == format!("{b:?}")
}

/// Every shipped scenario, as given and from rest, with each compiled-in
/// engine this build can run (the scenario's `[engine]` options where the
/// engine takes them) and its time step.
fn cases() -> Vec<(String, Problem, Box<dyn Engine>, f64)> {
    let mut paths: Vec<_> = std::fs::read_dir(root().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    let mut out = Vec::new();
    for path in paths {
        let sc = load(&path);
        for entry in pushval::registry::entries() {
            let engine = entry
                .build(&pushval::registry::engine_options(&sc))
                .unwrap_or_else(|_| entry.default_engine());
            if engine.availability().is_err() || engine.adapter().starts_with("outside") {
                continue;
            }
            let dt = sc.engine.dt.unwrap_or(engine.default_dt());
            for from_rest in [false, true] {
                let mut problem = sc.problem();
                problem.initial.from_rest = from_rest;
                let engine = entry
                    .build(&pushval::registry::engine_options(&sc))
                    .unwrap_or_else(|_| entry.default_engine());
                let name = format!(
                    "{} on {}{}",
                    engine.name(),
                    path.file_name().unwrap().to_string_lossy(),
                    if from_rest { " from rest" } else { "" }
                );
                out.push((name, problem, engine, dt));
            }
        }
    }
    out
}

/// The explicit session: start, one advance per push (checking the state
/// it reports), finish.
fn stepped(
    name: &str,
    engine: &dyn Engine,
    problem: &Problem,
    dt: f64,
) -> Result<EngineRun, ModelError> {
    let mut session: Box<dyn EngineSession + '_> = engine.start(problem, dt)?;
    // Every compiled-in engine steps natively: none replays.
    assert!(!session.replays(), "{name}: replays");
    let mut t = 0.0;
    for push in &problem.pushes {
        session.advance(push)?;
        t += push.duration;
        let s = session.state();
        assert!(
            (s.t - t).abs() <= 1e-12 * t.max(1.0),
            "{name}: t {} ≠ {t}",
            s.t
        );
        for v in [s.x, s.y, s.theta, s.omega, s.v_cm[0], s.v_cm[1]] {
            assert!(v.is_finite(), "{name}: state {s:?}");
        }
        // The CM velocity is the engine's: close to what the contact,
        // moving with the push, gives a rigid body at that ω.
        let rigid = pushval_engine::rigid_cm_velocity(problem, Some(push), s.theta, s.omega);
        let gap = (s.v_cm[0] - rigid[0]).hypot(s.v_cm[1] - rigid[1]);
        assert!(
            gap <= 0.05 * push.speed.abs() + 1e-9,
            "{name}: v_cm {:?} vs the rigid contact's {rigid:?}",
            s.v_cm
        );
    }
    let steps = session.steps_taken();
    let run = session.finish()?;
    assert_eq!(steps, run.steps, "{name}: steps_taken");
    Ok(run)
}

#[test]
fn run_is_start_advance_finish_bit_for_bit() {
    let cases = cases();
    let engines: std::collections::BTreeSet<String> = cases
        .iter()
        .map(|(_, _, e, _)| e.name().to_string())
        .collect();
    // Every compiled-in engine of the default build is covered.
    for name in ["rapier2d", "rapier3d", "box2d"] {
        assert!(engines.contains(name), "{name} not among {engines:?}");
    }
    let mut ran = 0;
    for (name, problem, engine, dt) in &cases {
        let whole = timeless(engine.run(problem, *dt));
        let by_push = timeless(stepped(name, engine.as_ref(), problem, *dt));
        assert!(
            same(&whole, &by_push),
            "{name}: run and start/advance/finish differ"
        );
        ran += whole.is_ok() as usize;
    }
    assert!(ran * 2 > cases.len(), "{ran} of {} runs ran", cases.len());
}

/// A native session's state after each push is where the object is at that
/// time in the whole run: its pose and ω at the end of each segment (the
/// sample at the switch time) agree with `run`'s trajectory.
#[test]
fn session_state_follows_the_run() {
    let sc = load(&root().join("scenarios/paper-square-v1.0.toml"));
    let problem = sc.problem();
    for entry in pushval::registry::entries() {
        let engine = entry.default_engine();
        if engine.availability().is_err() || engine.adapter().starts_with("outside") {
            continue;
        }
        let dt = engine.default_dt();
        let run = engine.run(&problem, dt).unwrap();
        let mut session = engine.start(&problem, dt).unwrap();
        let ends = problem.segment_times();
        for (push, (_, t_end)) in problem.pushes.iter().zip(ends) {
            session.advance(push).unwrap();
            let s = session.state();
            let sample = run
                .trajectory
                .samples
                .iter()
                .rev()
                .find(|q| (q.t - t_end).abs() < 1e-9)
                .unwrap_or_else(|| panic!("{}: no sample at {t_end}", engine.name()));
            for (got, want, what) in [
                (s.x, sample.x, "x"),
                (s.y, sample.y, "y"),
                (s.theta, sample.theta, "theta"),
            ] {
                assert!(
                    (got - want).abs() <= 1e-9,
                    "{}: {what} {got} at {t_end} vs the run's {want}",
                    engine.name()
                );
            }
        }
        assert_eq!(session.finish().unwrap().trajectory, run.trajectory);
    }
}
