//! Sessions answer only what they are asked, for every compiled-in engine
//! of the build and the outside reference adapter (`pure_python`, protocol
//! 3): a session started on one schedule and advanced by another ends with
//! the run of the other; a push advanced as two halves is that push; a
//! session is owned and `Send` (it can be advanced on another thread); and
//! its state after each push is where the run is at that time.
//!
//! Feature engines (mujoco, physx, avian, jolt) are among them when their
//! feature is on.

use pushval_engine::{Engine, EngineRun, Session};
use pushval_model::{Problem, Push};

use crate::common::*;

/// The scene every test pushes (the paper's plate, its four pushes).
fn scene() -> pushval_scenario::Scenario {
    load(&root().join("scenarios/paper-square-v1.0.toml"))
}

/// Every compiled-in engine this build can run, and `pure_python`, with
/// the scene's `[engine]` options where the engine takes them; each with
/// its time step.
fn engines() -> Vec<(Box<dyn Engine>, f64)> {
    let sc = scene();
    let mut out = Vec::new();
    for entry in pushval::registry::entries() {
        let engine = entry
            .build(&pushval::registry::engine_options(&sc))
            .unwrap_or_else(|_| entry.default_engine());
        let outside = engine.adapter().starts_with("outside");
        if engine.availability().is_err() || (outside && engine.name() != "pure_python") {
            continue;
        }
        let dt = sc.engine.dt.unwrap_or(engine.default_dt());
        out.push((engine, dt));
    }
    let names: Vec<&str> = out.iter().map(|(e, _)| e.name()).collect();
    for name in ["rapier2d", "rapier3d", "box2d", "pure_python"] {
        assert!(names.contains(&name), "{name} not among {names:?}");
    }
    out
}

/// A session of `engine` started on `announced` at `dt`, advanced by
/// `applied`, finished.
fn session_run(
    engine: &dyn Engine,
    announced: &Problem,
    applied: &[Push],
    dt: f64,
) -> Result<EngineRun, String> {
    let mut s = engine.start(announced, dt).map_err(|e| e.to_string())?;
    for p in applied {
        s.advance(p).map_err(|e| e.to_string())?;
    }
    // Every compiled-in engine and the protocol 3 adapter step natively.
    assert!(!s.replays(), "{}: replays", engine.name());
    s.finish().map_err(|e| e.to_string())
}

/// The largest distance (m) between the two runs' positions and the
/// largest difference (rad) of their angles, over every sample (the last
/// included); the sample times must agree.
fn gap(name: &str, a: &EngineRun, b: &EngineRun) -> (f64, f64) {
    let (sa, sb) = (&a.trajectory.samples, &b.trajectory.samples);
    assert_eq!(sa.len(), sb.len(), "{name}: sample counts");
    assert!(!sa.is_empty(), "{name}: no samples");
    let (mut dp, mut dth) = (0.0f64, 0.0f64);
    for (p, q) in sa.iter().zip(sb) {
        assert!((p.t - q.t).abs() <= 1e-12, "{name}: t {} vs {}", p.t, q.t);
        dp = dp.max((p.x - q.x).hypot(p.y - q.y));
        dth = dth.max((p.theta - q.theta).abs());
    }
    // NaN compares false: a NaN pose fails the bounds.
    if sa
        .iter()
        .chain(sb)
        .any(|s| !(s.x.is_finite() && s.theta.is_finite()))
    {
        return (f64::NAN, f64::NAN);
    }
    (dp, dth)
}

/// Another schedule than the scene's: other directions and speeds, one
/// push more, so that every push the scene applies is followed by one in
/// the announced schedule and the first push differs.
fn announced(p: &Problem) -> Problem {
    let mut pushes: Vec<Push> = p
        .pushes
        .iter()
        .rev()
        .map(|q| Push {
            duration: 0.7 * q.duration + 0.013,
            speed: 1.9 * q.speed + 0.01,
            phi: -q.phi + 0.4,
        })
        .collect();
    pushes.push(Push {
        duration: 0.5,
        speed: 0.3,
        phi: 0.2,
    });
    Problem {
        pushes,
        ..p.clone()
    }
}

/// (a) A session started on one schedule and advanced by another equals
/// the run of the other, at every sample and at the end (≤ 1e-12 m, 1e-12
/// rad), from rest and moving at the start (where the start's velocity
/// comes from the first push: the one applied, never the one announced).
#[test]
fn a_session_answers_only_the_pushes_it_is_advanced_by() {
    let sc = scene();
    for (engine, dt) in engines() {
        let name = engine.name().to_string();
        for from_rest in [true, false] {
            let mut applied = sc.problem();
            applied.initial.from_rest = from_rest;
            // The last two pushes of the scene: the announced schedule's
            // first push differs from the one applied.
            applied.pushes = applied.pushes[2..].to_vec();
            let other = announced(&applied);
            assert_ne!(other.pushes[0], applied.pushes[0]);
            let whole = engine.run(&applied, dt);
            let asked = session_run(engine.as_ref(), &other, &applied.pushes, dt);
            let (whole, asked) = match (whole, asked) {
                (Ok(w), Ok(a)) => (w, a),
                (Err(w), Err(a)) => {
                    // Both refuse: for the same reason.
                    assert_eq!(w.to_string(), a, "{name}");
                    continue;
                }
                (w, a) => panic!("{name}: run {w:?} vs session {a:?}"),
            };
            let (dp, dth) = gap(&name, &whole, &asked);
            eprintln!(
                "{name} (from rest: {from_rest}): announced ≠ applied: {dp:.3e} m, {dth:.3e} rad"
            );
            assert!(dp <= 1e-12 && dth <= 1e-12, "{name}: {dp} m, {dth} rad");
            assert_eq!(whole.steps, asked.steps, "{name}: steps");
        }
    }
}

/// (b) A push advanced as two halves is that push (≤ 1e-9 m, 1e-9 rad at
/// every sample and at the end). The halves are cut on the engine's step
/// grid (each a whole number of steps of `dt`, and of sample intervals), so
/// that a fixed-step engine takes the same steps both ways.
#[test]
fn a_push_advanced_as_two_halves_is_that_push() {
    let sc = scene();
    for (engine, dt) in engines() {
        let name = engine.name().to_string();
        let mut one = sc.problem();
        let first = one.pushes[0];
        // Half a second, on the step grid and a whole number of samples.
        let half = (0.5 / dt).round() * dt;
        assert!((half / one.sample_dt - (half / one.sample_dt).round()).abs() < 1e-9);
        one.pushes = vec![Push {
            duration: 2.0 * half,
            ..first
        }];
        let halves = [Push {
            duration: half,
            ..first
        }; 2];
        let whole = engine
            .run(&one, dt)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let split = session_run(engine.as_ref(), &one, &halves, dt)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let (dp, dth) = gap(&name, &whole, &split);
        eprintln!("{name}: one push vs two halves: {dp:.3e} m, {dth:.3e} rad");
        assert!(dp <= 1e-9 && dth <= 1e-9, "{name}: {dp} m, {dth} rad");
    }
}

/// A session is owned and `Send`: started here, advanced and finished on
/// another thread, it gives the run.
#[test]
fn a_session_is_owned_and_sent_to_another_thread() {
    fn owned_and_send<T: Send + 'static>(_: &T) {}
    let problem = scene().problem();
    for (engine, dt) in engines() {
        let mut session: Session = engine.start(&problem, dt).unwrap();
        owned_and_send(&session);
        let pushes = problem.pushes.clone();
        let elsewhere = std::thread::spawn(move || {
            for p in &pushes {
                session.advance(p).unwrap();
            }
            session.finish().unwrap()
        })
        .join()
        .unwrap();
        let whole = engine.run(&problem, dt).unwrap();
        let (dp, dth) = gap(engine.name(), &whole, &elsewhere);
        assert!(dp <= 1e-12 && dth <= 1e-12, "{}: {dp} m", engine.name());
    }
}

/// A session's state after each push is where the object is at that time
/// in the whole run: its pose at the end of each segment (the sample at the
/// switch time) agrees with `run`'s trajectory.
#[test]
fn session_state_follows_the_run() {
    let problem = scene().problem();
    for (engine, dt) in engines() {
        let run = engine.run(&problem, dt).unwrap();
        let mut session = engine.start(&problem, dt).unwrap();
        let ends = problem.segment_times();
        for (push, (_, t_end)) in problem.pushes.iter().zip(ends) {
            session.advance(push).unwrap();
            let s = session.state();
            assert!((s.t - t_end).abs() <= 1e-12 * t_end.max(1.0));
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
            // The CM velocity is the engine's: close to what the contact,
            // moving with the push, gives a rigid body at that ω.
            let rigid = pushval_engine::rigid_cm_velocity(&problem, Some(push), s.theta, s.omega);
            let gap = (s.v_cm[0] - rigid[0]).hypot(s.v_cm[1] - rigid[1]);
            assert!(
                gap <= 0.05 * push.speed.abs() + 1e-9,
                "{}: v_cm {:?} vs the rigid contact's {rigid:?}",
                engine.name(),
                s.v_cm
            );
        }
        let steps = session.steps_taken();
        let finished = session.finish().unwrap();
        assert_eq!(steps, finished.steps, "{}: steps_taken", engine.name());
        assert_eq!(finished.trajectory, run.trajectory, "{}", engine.name());
    }
}
