//! Outside engines step (protocol 3): `Engine::start` keeps the adapter's
//! world between pushes, `run` is start + advance per push + finish, and an
//! adapter of protocol 1 or 2 is advanced by replaying the schedule applied
//! so far.
//!
//! The adapters: `adapters/python/pure_python.py` (written with the kit,
//! which serves protocol 3 from its reset/step) and
//! `adapters/python/plain_protocol1.py` (written without the kit, protocol
//! 1 only, the same semi-implicit Euler line for line). Expected values
//! come from another road to the same rows: a one-shot protocol 1 run of the
//! same step, which the kit and the plain adapter both write per step.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};

use pushval_engine::{rigid_cm_velocity, Engine, EngineOptions};
use pushval_model::Problem;
use pushval_outside::{shutdown_sessions, Config, OutsideEngine, Spec};
use pushval_scenario::Scenario;

mod common;

static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn serial() -> MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn spec(script: &str, extra: &str) -> Arc<Spec> {
    let text = format!(
        "[engine.stepper]\ncommand = [\"python3\", \"adapters/python/{script}\"]\ntimeout_s = 60\n{extra}"
    );
    let cfg = Config::from_toml(&text, &root().join("pushval.toml")).unwrap();
    Arc::new(cfg.engines.into_iter().next().unwrap())
}

fn problem() -> (Problem, EngineOptions) {
    let sc = Scenario::from_path(root().join("scenarios/paper-square-v1.0.toml")).unwrap();
    (sc.problem(), common::options(&sc))
}

const DT: f64 = 1e-3;

#[test]
fn session_true_steps_by_default() {
    let s = spec("pure_python.py", "session = true\n");
    assert_eq!((s.protocol, s.rows), (3, pushval_outside::Rows::Samples));
}

/// Protocol 3 with every step: `run` gives what a one-shot protocol 1 run
/// of the same adapter gives, bit for bit (the same rows, read the same
/// way), and says it did not replay.
#[test]
fn a_stepped_run_is_the_one_shot_run_bit_for_bit() {
    let _g = serial();
    let (p, options) = problem();
    let one_shot = OutsideEngine::new(spec("pure_python.py", ""), &options)
        .run(&p, DT)
        .unwrap();
    let stepped = OutsideEngine::new(
        spec("pure_python.py", "session = true\nrows = \"steps\"\n"),
        &options,
    )
    .run(&p, DT)
    .unwrap();
    assert_eq!(stepped.diagnostics["protocol"], 3);
    assert_eq!(stepped.diagnostics["replays"], false);
    // start, five advances, finish: seven requests, numbered 1..7.
    assert_eq!(
        stepped.diagnostics["session"]["requests"],
        serde_json::json!([1, 2, 3, 4, 5, 6, 7])
    );
    assert_eq!(stepped.steps, one_shot.steps);
    assert_eq!(stepped.trajectory.samples, one_shot.trajectory.samples);
    assert_eq!(stepped.trajectory.segments, one_shot.trajectory.segments);
    shutdown_sessions();
}

/// With rows at the sample times only, the poses at the sample times are
/// the per-step ones (the sample times fall on step ends: sample_dt is 10
/// steps), and ω is within what its reading allows: the step's ω read at
/// the middle of a 10-step interval instead of a 1-step one.
#[test]
fn rows_at_the_sample_times_keep_the_poses() {
    let _g = serial();
    let (p, options) = problem();
    let steps = OutsideEngine::new(spec("pure_python.py", ""), &options)
        .run(&p, DT)
        .unwrap();
    let samples = OutsideEngine::new(spec("pure_python.py", "session = true\n"), &options)
        .run(&p, DT)
        .unwrap();
    assert_eq!(samples.diagnostics["rows_asked"], "samples");
    let rows = samples.diagnostics["rows"].as_u64().unwrap();
    assert_eq!(rows as usize, p.sample_times().len(), "one row per sample");
    // The engine's steps, from the rows' `steps` column: 10 s at 1e-3 s.
    assert_eq!((samples.steps, steps.steps), (10_000, 10_000));
    assert_eq!(samples.trajectory.stats.rhs_evals, 10_000);
    for (a, b) in samples
        .trajectory
        .samples
        .iter()
        .zip(&steps.trajectory.samples)
    {
        assert_eq!(a.t, b.t);
        assert!(
            (a.x - b.x).abs() < 1e-12 && (a.y - b.y).abs() < 1e-12,
            "{a:?} {b:?}"
        );
        assert!((a.theta - b.theta).abs() < 1e-12, "{a:?} {b:?}");
    }
    // ω at a segment's end (the gate's steady reading) moves by less than
    // 1e-3 of the push's scale (speed / contact distance).
    let scale = 1.0 / p.body.contact().norm();
    for (a, b) in samples
        .trajectory
        .segments
        .iter()
        .zip(&steps.trajectory.segments)
    {
        assert!(
            (a.omega_end - b.omega_end).abs() < 1e-3 * scale,
            "{a:?} {b:?}"
        );
    }
    shutdown_sessions();
}

/// The caller owns the loop: after each push the state is the run's at
/// that push's end, with the CM velocity of the rigid contact.
#[test]
fn the_state_after_each_push_is_the_runs() {
    let _g = serial();
    let (p, options) = problem();
    let whole = OutsideEngine::new(spec("pure_python.py", ""), &options)
        .run(&p, DT)
        .unwrap();
    let engine = OutsideEngine::new(
        spec("pure_python.py", "session = true\nrows = \"steps\"\n"),
        &options,
    );
    let dynamic: &dyn Engine = &engine;
    let mut s = dynamic.start(&p, DT).unwrap();
    assert!(!s.replays());
    assert_eq!(s.state().t, 0.0);
    let times = p.segment_times();
    for (push, &(_, t1)) in p.pushes.iter().zip(&times) {
        s.advance(push).unwrap();
        let st = s.state();
        assert_eq!(st.t, t1);
        let at = whole
            .trajectory
            .samples
            .iter()
            .find(|x| (x.t - t1).abs() < 1e-12)
            .unwrap();
        assert_eq!((st.x, st.y, st.theta), (at.x, at.y, at.theta));
        assert_eq!(
            st.v_cm,
            rigid_cm_velocity(&p, Some(push), st.theta, st.omega)
        );
    }
    let run = s.finish().unwrap();
    assert_eq!(run.trajectory.samples, whole.trajectory.samples);
    shutdown_sessions();
}

/// An adapter written without the kit, protocol 1 only, is a plant through
/// replay: each advance re-runs the pushes so far, the state is the
/// one-shot run's at each push's end, and the session says it replays.
/// Its rows are the kit adapter's, bit for bit.
#[test]
fn a_protocol_1_adapter_without_the_kit_is_a_plant_by_replay() {
    let (p, options) = problem();
    let plain = OutsideEngine::new(spec("plain_protocol1.py", ""), &options);
    let kit = OutsideEngine::new(spec("pure_python.py", ""), &options)
        .run(&p, DT)
        .unwrap();
    let dynamic: &dyn Engine = &plain;
    let mut s = dynamic.start(&p, DT).unwrap();
    assert!(s.replays(), "protocol 1 cannot step");
    for (push, &(_, t1)) in p.pushes.iter().zip(&p.segment_times()) {
        s.advance(push).unwrap();
        let st = s.state();
        let at = kit
            .trajectory
            .samples
            .iter()
            .find(|x| (x.t - t1).abs() < 1e-12)
            .unwrap();
        assert_eq!((st.t, st.x, st.y, st.theta), (at.t, at.x, at.y, at.theta));
    }
    // 1 + 2 + … + 5 segments of 2000 steps each were run.
    assert_eq!(s.steps_taken(), 15 * 2000);
    let run = s.finish().unwrap();
    assert_eq!(run.trajectory.samples, kit.trajectory.samples);
}

/// A protocol 2 session cannot step either: replayed, whole documents.
#[test]
fn a_protocol_2_session_replays() {
    let _g = serial();
    let (p, options) = problem();
    let engine = OutsideEngine::new(
        spec("pure_python.py", "session = true\nprotocol = 2\n"),
        &options,
    );
    let dynamic: &dyn Engine = &engine;
    let s = dynamic.start(&p, DT).unwrap();
    assert!(s.replays());
    shutdown_sessions();
}

/// The document carries one step: `dt` at the top, none in `options`, even
/// when the scenario's `[engine]` table sets one (the ladder's 2·dt run is
/// at another step than the table's).
#[test]
fn the_document_carries_one_dt() {
    let (p, mut options) = problem();
    options.dt = Some(1e-3);
    let doc = pushval_outside::problem_document("e", &p, &options, 2e-3);
    assert_eq!(doc["dt"], 2e-3);
    assert!(doc["options"].get("dt").is_none(), "{}", doc["options"]);
}

/// Answers that arrive together (all seven of a run in one write, as a
/// loaded machine delivers them): each is read against its own request and
/// its own cap, and the run is the one-shot run's.
#[test]
fn answers_read_together_are_each_their_own() {
    let _g = serial();
    let (p, options) = problem();
    let one_shot = OutsideEngine::new(spec("pure_python.py", ""), &options)
        .run(&p, DT)
        .unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/batching.py")
        .display()
        .to_string();
    let text = format!(
        "[engine.batched]\ncommand = [\"python3\", {fixture:?}, \"7\", \"--\", \"python3\", \"adapters/python/pure_python.py\"]\nsession = true\nrows = \"steps\"\ntimeout_s = 60\n"
    );
    let cfg = Config::from_toml(&text, &root().join("pushval.toml")).unwrap();
    let s = Arc::new(cfg.engines.into_iter().next().unwrap());
    let run = OutsideEngine::new(s, &options).run(&p, DT).unwrap();
    assert_eq!(run.trajectory.samples, one_shot.trajectory.samples);
    shutdown_sessions();
}

/// The release: a protocol 1 adapter (one-shot, or replayed in a session)
/// is refused a release problem naming the engine and the release, never
/// run to the release's end; a protocol 3 session of the kit's
/// pure_python releases with one `release` request after the pushes, and
/// its run ends at rest (the last row the stop time, as the report says).
#[test]
fn a_release_is_asked_of_protocol_3_and_refused_by_protocol_1() {
    let _g = serial();
    let (mut p, options) = problem();
    p.pushes.truncate(2);
    p.release = Some(pushval_model::Release { max_duration: 5.0 });
    let one = OutsideEngine::new(spec("plain_protocol1.py", ""), &options);
    for r in [
        one.run(&p, DT),
        (&one as &dyn Engine).start(&p, DT).and_then(|mut s| {
            for q in &p.pushes {
                s.advance(q)?;
            }
            s.release(5.0)?;
            s.finish()
        }),
    ] {
        match r {
            Err(e @ pushval_model::ModelError::NoRelease { .. }) => {
                let text = e.to_string();
                assert!(text.contains("stepper cannot release"), "{text}");
            }
            other => panic!("not refused: {:?}", other.map(|r| r.steps)),
        }
    }
    let three = OutsideEngine::new(spec("pure_python.py", "session = true\n"), &options);
    let run = three.run(&p, DT).unwrap();
    let slide = run.trajectory.slide.clone().expect("a slide report");
    let stop = slide.t_stop.expect("the plate stops");
    assert_eq!(slide.t_release, p.duration());
    assert_eq!(run.trajectory.samples.last().unwrap().t, stop);
    // start, two advances, the release, finish.
    assert_eq!(
        run.diagnostics["session"]["requests"],
        serde_json::json!([1, 2, 3, 4, 5])
    );
    shutdown_sessions();
}
