//! Sessions (`session = true`): one process answers many problems, an
//! `#error` answer fails one run and the session goes on, a session that
//! crashes, hangs or floods is ended (with what it started) and replaced,
//! and `shutdown_sessions` ends them all.
//!
//! The adapter is `tests/fixtures/session_adapter.py` (standard library
//! only): it carries the object at the pusher's velocity without turning,
//! so a run's end point is known in closed form, and it logs its pid for
//! every problem it receives. The tests share one pool: they run one at a
//! time.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

mod common;

use pushval_engine::{Engine, EngineOptions};
use pushval_model::Problem;
use pushval_outside::{shutdown_sessions, Config, Limits, OutsideEngine, Spec};
use pushval_scenario::Scenario;
use serde_json::json;

static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn serial() -> MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn fixture() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/session_adapter.py")
        .display()
        .to_string()
}

/// A session engine named `name` in `dir`, its pid log in `dir/pids`.
fn spec(dir: &Path, name: &str, extra: &str) -> Arc<Spec> {
    let log = dir.join("pids").display().to_string();
    let text = format!(
        "[engine.{name}]\ncommand = [\"python3\", {:?}, \"--pid-log\", {log:?}]\nsession = true\nprotocol = 2\ntimeout_s = 20\n{extra}",
        fixture()
    );
    let cfg = Config::from_toml(&text, &dir.join("pushval.toml")).unwrap();
    let s = cfg.engines.into_iter().next().unwrap();
    assert_eq!(
        (s.protocol, s.session),
        (2, true),
        "a whole-document session"
    );
    Arc::new(s)
}

/// The pids the adapter logged, one per problem received.
fn pids(dir: &Path) -> Vec<u32> {
    std::fs::read_to_string(dir.join("pids"))
        .unwrap_or_default()
        .lines()
        .map(|l| l.split(' ').next().unwrap().parse().unwrap())
        .collect()
}

fn problem() -> (Problem, EngineOptions) {
    let sc = Scenario::from_path(root().join("scenarios/paper-square-v1.0.toml")).unwrap();
    (sc.problem(), common::options(&sc))
}

fn with(options: &EngineOptions, pairs: &[(&str, serde_json::Value)]) -> EngineOptions {
    let mut o = options.clone();
    for (k, v) in pairs {
        o.values.insert(k.to_string(), v.clone());
    }
    o
}

/// The end point of the object carried at the pusher's velocity without
/// turning: x0 + Σ duration · speed · (cos, sin)(θ0 + φ).
fn carried_end(p: &Problem) -> (f64, f64) {
    let th = p.initial.theta;
    p.pushes
        .iter()
        .fold((p.initial.position.x, p.initial.position.y), |(x, y), s| {
            (
                x + s.duration * s.speed * (th + s.phi).cos(),
                y + s.duration * s.speed * (th + s.phi).sin(),
            )
        })
}

fn gone(pid: u32) -> bool {
    let until = Instant::now() + Duration::from_secs(3);
    while Instant::now() < until {
        if !Path::new(&format!("/proc/{pid}")).exists() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    false
}

fn read_pid(file: &Path) -> u32 {
    std::fs::read_to_string(file)
        .unwrap()
        .trim()
        .parse()
        .unwrap()
}

#[test]
fn one_process_answers_several_problems() {
    let _g = serial();
    let dir = tempfile::tempdir().unwrap();
    let s = spec(dir.path(), "several", "");
    let (mut p, options) = problem();
    let engine = OutsideEngine::new(s, &options);
    for (k, speed) in [0.5, 1.0, 2.0].into_iter().enumerate() {
        for push in &mut p.pushes {
            push.speed = speed;
        }
        let run = engine.run(&p, 1e-3).unwrap();
        let last = run.trajectory.samples.last().unwrap();
        let (x, y) = carried_end(&p);
        assert!(
            (last.x - x).abs() < 1e-9 && (last.y - y).abs() < 1e-9,
            "speed {speed}: ({}, {}) vs ({x}, {y})",
            last.x,
            last.y
        );
        assert_eq!(run.diagnostics["protocol"], 2);
        assert_eq!(run.diagnostics["session"]["answered_before"], k as u64);
    }
    let logged = pids(dir.path());
    assert_eq!(logged.len(), 3, "{logged:?}");
    assert!(
        logged.iter().all(|&p| p == logged[0]),
        "one process: {logged:?}"
    );
    // The fixture refuses any document but a version 2 one with limits, so
    // three answers also say the documents were version 2.
    let log = std::fs::read_to_string(dir.path().join("pids")).unwrap();
    assert!(
        log.lines().all(|l| l.ends_with("pushval-problem/2")),
        "{log}"
    );
    shutdown_sessions();
    assert!(gone(logged[0]), "shutdown ends the session's process");
}

#[test]
fn an_error_answer_fails_one_run_and_the_session_goes_on() {
    let _g = serial();
    let dir = tempfile::tempdir().unwrap();
    let s = spec(dir.path(), "refusing", "");
    let (p, options) = problem();
    let ok = OutsideEngine::new(s.clone(), &options);
    let bad = OutsideEngine::new(s, &with(&options, &[("fixture", json!("error"))]));
    ok.run(&p, 1e-3).unwrap();
    let e = bad.run(&p, 1e-3).unwrap_err().to_string();
    assert!(
        e.contains("outside engine \"refusing\"")
            && e.contains("answered request 2 (problem) with `#error 2 deliberate failure`"),
        "{e}"
    );
    assert!(e.contains("problem 2 (error)"), "its standard error: {e}");
    ok.run(&p, 1e-3).unwrap();
    let logged = pids(dir.path());
    assert_eq!(logged.len(), 3);
    assert!(logged.iter().all(|&p| p == logged[0]), "{logged:?}");
    shutdown_sessions();
}

#[test]
fn a_session_crashing_mid_answer_is_replaced() {
    let _g = serial();
    let dir = tempfile::tempdir().unwrap();
    let s = spec(dir.path(), "crashing", "");
    let (p, options) = problem();
    let ok = OutsideEngine::new(s.clone(), &options);
    let crash = OutsideEngine::new(s, &with(&options, &[("fixture", json!("crash"))]));
    ok.run(&p, 1e-3).unwrap();
    let e = crash.run(&p, 1e-3).unwrap_err().to_string();
    assert!(
        e.contains("the session ended mid-answer") && e.contains("exited with status 3"),
        "{e}"
    );
    ok.run(&p, 1e-3).unwrap();
    let logged = pids(dir.path());
    assert_eq!(logged.len(), 3, "{logged:?}");
    assert_eq!(logged[0], logged[1]);
    assert_ne!(logged[1], logged[2], "a new process after the crash");
    shutdown_sessions();
}

/// A session that hangs is killed at its timeout with the process it
/// started in a session of its own; the next run starts a new one.
#[test]
fn a_hanging_session_is_killed_with_its_descendants() {
    let _g = serial();
    let dir = tempfile::tempdir().unwrap();
    let s = spec(dir.path(), "hanging", "");
    let short = {
        let mut t = (*s).clone();
        t.timeout_s = 1.0;
        Arc::new(t)
    };
    let (p, options) = problem();
    let daemon = dir.path().join("daemon");
    let hang = OutsideEngine::new(
        short,
        &with(
            &options,
            &[
                ("fixture", json!("spawn_hang")),
                ("spawn_pid_file", json!(daemon.display().to_string())),
            ],
        ),
    );
    let start = Instant::now();
    let e = hang.run(&p, 1e-3).unwrap_err().to_string();
    assert!(e.contains("within its timeout of 1 s: killed"), "{e}");
    assert!(
        start.elapsed() < Duration::from_secs(15),
        "{:?}",
        start.elapsed()
    );
    let sleeper = read_pid(&daemon);
    assert!(gone(sleeper), "the setsid() sleep {sleeper} survived");
    assert!(gone(pids(dir.path())[0]), "the session process survived");
    OutsideEngine::new(s, &options).run(&p, 1e-3).unwrap();
    let logged = pids(dir.path());
    assert_ne!(logged[0], logged[1]);
    shutdown_sessions();
}

/// What a healthy session started ends when the sessions are shut down.
#[test]
fn shutdown_ends_what_a_session_started() {
    let _g = serial();
    let dir = tempfile::tempdir().unwrap();
    let s = spec(dir.path(), "spawning", "");
    let (p, options) = problem();
    let daemon = dir.path().join("daemon");
    let spawn = OutsideEngine::new(
        s,
        &with(
            &options,
            &[
                ("fixture", json!("spawn")),
                ("spawn_pid_file", json!(daemon.display().to_string())),
            ],
        ),
    );
    spawn.run(&p, 1e-3).unwrap();
    let sleeper = read_pid(&daemon);
    assert!(Path::new(&format!("/proc/{sleeper}")).exists());
    assert_eq!(pushval_outside::live_sessions(), 1);
    shutdown_sessions();
    assert_eq!(pushval_outside::live_sessions(), 0);
    assert!(gone(sleeper), "the setsid() sleep {sleeper} survived");
    assert!(gone(pids(dir.path())[0]));
}

#[test]
fn a_flooding_session_is_stopped_at_its_cap() {
    let _g = serial();
    let dir = tempfile::tempdir().unwrap();
    let s = spec(dir.path(), "flooding", "");
    let (p, options) = problem();
    let flood = OutsideEngine::new(s.clone(), &with(&options, &[("fixture", json!("flood"))]));
    let start = Instant::now();
    let e = flood.run(&p, 1e-3).unwrap_err().to_string();
    let cap = Limits::for_problem(&p, 1e-3).max_rows;
    assert!(
        e.contains(&format!("wrote more than {cap} rows")) && e.contains("max_rows"),
        "{e}"
    );
    assert!(start.elapsed() < Duration::from_secs(15));
    OutsideEngine::new(s, &options).run(&p, 1e-3).unwrap();
    let logged = pids(dir.path());
    assert_ne!(logged[0], logged[1], "replaced after the cap");
    shutdown_sessions();
}

/// Runs from several threads share the pool: never more processes than
/// cores, and every run answered.
#[test]
fn parallel_runs_share_at_most_one_session_per_core() {
    let _g = serial();
    let dir = tempfile::tempdir().unwrap();
    let s = spec(dir.path(), "parallel", "");
    let (p, options) = problem();
    let engine = OutsideEngine::new(s, &options);
    std::thread::scope(|scope| {
        for _ in 0..4 {
            scope.spawn(|| {
                for _ in 0..3 {
                    engine.run(&p, 1e-3).unwrap();
                }
            });
        }
    });
    let logged = pids(dir.path());
    assert_eq!(logged.len(), 12);
    let mut distinct = logged.clone();
    distinct.sort_unstable();
    distinct.dedup();
    let cores = std::thread::available_parallelism().unwrap().get();
    assert!(
        distinct.len() <= cores,
        "{} processes, {cores} cores",
        distinct.len()
    );
    shutdown_sessions();
}

/// Request numbers (issue 40): an answer closed with another request's
/// number, with none, or a second answer to an earlier document, is a
/// protocol error naming the engine and the request; the session is
/// ended and the next run starts a new process.
#[test]
fn answers_must_carry_their_request_number() {
    let _g = serial();
    let dir = tempfile::tempdir().unwrap();
    let s = spec(dir.path(), "numbered", "");
    let (p, options) = problem();
    let run = |mode: &str| {
        OutsideEngine::new(s.clone(), &with(&options, &[("fixture", json!(mode))])).run(&p, 1e-3)
    };
    // A fresh process for each case: its first document is request 1.
    let e = run("wrong_number").unwrap_err().to_string();
    assert!(
        e.contains("outside engine \"numbered\"")
            && e.contains("closed its answer with request number 2 (`#end 2`) while request 1 (problem) was asked"),
        "{e}"
    );
    let e = run("no_number").unwrap_err().to_string();
    assert!(
        e.contains(
            "closed its answer to request 1 (problem) with `#end`, which carries no request number"
        ),
        "{e}"
    );
    // Answered twice: the first run reads the first answer, the second
    // run finds the second one where its own should be.
    run("twice").unwrap();
    std::thread::sleep(Duration::from_millis(200));
    let e = run("ok").unwrap_err().to_string();
    assert!(
        e.contains("outside engine \"numbered\"")
            && e.contains("before request 2 was sent (a second answer"),
        "{e}"
    );
    let logged = pids(dir.path());
    assert_eq!(logged.len(), 3, "{logged:?}");
    assert!(
        logged[0] != logged[1] && logged[1] != logged[2],
        "each broken session was replaced: {logged:?}"
    );
    shutdown_sessions();
}

/// A finite row far from its neighbours (x = 1e300 between two sample
/// times) is bad output naming its line, not a pass.
#[test]
fn a_row_beyond_what_the_push_allows_names_its_line() {
    let _g = serial();
    let dir = tempfile::tempdir().unwrap();
    let s = spec(dir.path(), "jumping", "");
    let (p, options) = problem();
    let e = OutsideEngine::new(s, &with(&options, &[("fixture", json!("far_row"))]))
        .run(&p, 1e-3)
        .unwrap_err()
        .to_string();
    // The header is line 1, rows[3] line 5, the inserted row line 6.
    assert!(
        e.contains("outside engine \"jumping\"")
            && e.contains("line 6: the centre of mass jumps 1.0")
            && e.contains("more than the push allows"),
        "{e}"
    );
    shutdown_sessions();
}
