//! What the outside-engine protocol costs per run, against the engine's own
//! stepping: the 10 s paper push (`scenarios/paper-square-v1.0.toml`, five
//! 2 s segments) at dt = 1e-3 (10 000 steps, 10 001 rows) on the reference
//! adapter `adapters/python/pure_python.py` (semi-implicit Euler).
//!
//! `cargo bench --bench outside_overhead` (add `-- --quick` for fewer
//! repeats). Writes `results/outside_overhead.csv` (one row per quantity:
//! median and min over the repeats, in seconds, and a note), then runs the
//! in-process parts under criterion.
//!
//! Measured, each the median wall time of `runs` repeats:
//!
//! * `document`: building the pushval-problem/1 document and serialising it
//!   (pushval's side of the input);
//! * `parse_resample`: reading the adapter's CSV, checking it and resampling
//!   it onto the problem's samples (pushval's side of the output);
//! * `spawn_*`: starting the interpreter, writing the document to its
//!   standard input and reading it back to end of file, nothing else
//!   (`python3 -c "import sys; sys.stdin.buffer.read()"`), for the command
//!   as `pushval.toml` names it (`python3` found on PATH: on this machine a
//!   pyenv shim, a bash script that runs `pyenv exec`), for the interpreter
//!   the shim resolves to, and for that interpreter with `-S` (no `site`
//!   import: what the interpreter's own start costs without the `.pth` files
//!   of its site-packages);
//! * `adapter_stepping`: the adapter's own time stepping the problem, as it
//!   reports it (`--timing`: `time.perf_counter` around its loop);
//! * `adapter_process`: the whole process as pushval's runner sees it
//!   (start to exit, the document in and the CSV out), with `python3` from
//!   PATH and with the resolved interpreter;
//! * `engine_run`: `Engine::run` of the outside engine (the process plus
//!   pushval's document, parse and resample), with `python3` from PATH.
//!
//! * `engine_run_session_*`: pure_python.py as a session (`session = true`:
//!   one process answering every run, started by a warm-up run outside the
//!   timing), beside the one-process-per-run rows above: the default
//!   (protocol 3, stepping, rows at the sample times: 1001 rows for the
//!   10 001 steps), `engine_run_session_steps_*` (protocol 3, every step)
//!   and `engine_run_session_p2_*` (protocol 2, whole documents, every
//!   step).
//!
//! The protocol's overhead per run is `engine_run − adapter_stepping`; the
//! rows `overhead_*` give it and `overhead_share_*` its share of the run.
//! For a one-shot run the stepping is `adapter_stepping` (a one-shot
//! `--timing` run); for a session it is paired: each run's wall time
//! against the adapter's own stepping in that same run
//! (`adapter_stepping_session_*`).
//! (`spawn_venv`: the virtual environment of `scripts/setup-adapters.sh`,
//! when it exists.)

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::Criterion;
use pushval_engine::{trajectory_from_steps, Engine, EngineOptions};
use pushval_model::{Problem, Push};
use pushval_outside::{
    csv, history_from_rows, problem_document, run_process, shutdown_sessions, Config, Limits,
    OutsideEngine, Spec,
};
use pushval_scenario::Scenario;

const DT: f64 = 1e-3;
/// The control period of `pushval loop` (its default).
const PERIOD: f64 = 0.02;
/// The scenario every measurement runs.
const SCENARIO: &str = "scenarios/paper-square-v1.0.toml";
/// The goal of the whole-loop measurement (x m, y m, theta rad).
const GOAL: &str = "0.8,0.2,-0.5";
const TIMEOUT: Duration = Duration::from_secs(300);

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn median(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[0])
}

fn time<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, f64) {
    let mut t = Vec::with_capacity(runs);
    for _ in 0..runs {
        let s = Instant::now();
        std::hint::black_box(f());
        t.push(s.elapsed().as_secs_f64());
    }
    median(t)
}

/// The `pure_python` engine of a `pushval.toml` whose command starts with
/// `python`.
fn spec(python: &str) -> Arc<Spec> {
    let text = format!(
        "[engine.pure_python]\ncommand = [{python:?}, \"adapters/python/pure_python.py\"]\norder = 1\n"
    );
    let cfg = Config::from_toml(&text, &root().join("pushval.toml")).expect("a valid engines file");
    Arc::new(cfg.engines.into_iter().next().expect("one engine"))
}

/// pure_python.py as a session (`session = true`: one process answering
/// every run, the kit's session mode), with `extra` keys (`protocol`,
/// `rows`), run with `--timing` through `sh` so that the adapter's own
/// stepping time of each run lands in `log` (one `step_time_s=` line a
/// run).
fn session_spec(python: &str, extra: &str, log: &Path) -> Arc<Spec> {
    let script = format!(
        "exec '{python}' adapters/python/pure_python.py --timing 2>>'{}'",
        log.display()
    );
    let text = format!(
        "[engine.pure_python]\ncommand = [\"sh\", \"-c\", {script:?}]\norder = 1\nsession = true\n{extra}"
    );
    let cfg = Config::from_toml(&text, &root().join("pushval.toml")).expect("a valid engines file");
    Arc::new(cfg.engines.into_iter().next().expect("one engine"))
}

/// The stepping times (s) an adapter run with `--timing` logged, in order.
fn step_times(log: &Path) -> Vec<f64> {
    logged(log, "step_time_s=")
}

/// The numbers after `key` in an adapter's `--timing` lines, in order
/// (`answer_time_s=`: the time a protocol 3 problem's requests took the
/// kit to answer, from reading each line to the answer ready to write,
/// the stepping included).
fn logged(log: &Path, key: &str) -> Vec<f64> {
    std::fs::read_to_string(log)
        .unwrap_or_default()
        .split_whitespace()
        .filter_map(|w| w.strip_prefix(key).and_then(|n| n.parse().ok()))
        .collect()
}

fn resolved_python() -> String {
    let o = Command::new("python3")
        .args(["-c", "import sys; print(sys.executable)"])
        .output()
        .expect("python3 on PATH");
    String::from_utf8(o.stdout).unwrap().trim().to_string()
}

/// What `python3` on PATH is, without the machine's paths: a pyenv shim
/// (a bash script) or the interpreter itself.
fn shim_or_not() -> &'static str {
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|p| p.join("python3"))
            .find(|p| p.is_file())
    });
    match found {
        Some(p) if p.components().any(|c| c.as_os_str() == "shims") => {
            "on this machine a pyenv shim, a bash script that runs `pyenv exec`"
        }
        Some(_) => "the interpreter itself",
        None => "not on PATH",
    }
}

/// How a row's label names the interpreter, without the machine's paths.
fn interpreter(label: &str) -> &'static str {
    if label == "resolved" {
        "the resolved interpreter"
    } else {
        "python3 from PATH"
    }
}

fn process(program: &str, args: &[&str], input: &[u8]) -> pushval_outside::ProcessOutput {
    let args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
    let unlimited = Limits {
        max_rows: u64::MAX,
        max_bytes: u64::MAX,
    };
    let out = run_process(
        Path::new(program),
        &args,
        &root(),
        input,
        TIMEOUT,
        unlimited,
    )
    .unwrap_or_else(|e| panic!("{program}: {}", e.what));
    assert!(
        out.status.success(),
        "{program} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// One row of the results file: quantity, median, min, unit, note.
type Row = (String, f64, f64, &'static str, String);

fn put(rows: &mut Vec<Row>, name: &str, (med, min): (f64, f64), note: String) {
    eprintln!("{name:>32}: median {med:.4} s, min {min:.4} s");
    rows.push((name.to_string(), med, min, "s", note));
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let runs = if quick { 3 } else { 11 };
    let sc = Scenario::from_path(root().join(SCENARIO)).unwrap();
    let problem: Problem = sc.problem();
    let options: EngineOptions = pushval::registry::engine_options(&sc);
    let py = resolved_python();
    let input =
        serde_json::to_vec(&problem_document("pure_python", &problem, &options, DT)).unwrap();
    let adapter = "adapters/python/pure_python.py";

    let mut rows: Vec<Row> = Vec::new();

    // pushval's own work on each side of the process.
    put(
        &mut rows,
        "document",
        time(runs * 10, || {
            serde_json::to_vec(&problem_document("pure_python", &problem, &options, DT)).unwrap()
        }),
        format!(
            "problem_document + serde_json::to_vec ({} bytes)",
            input.len()
        ),
    );
    let sample = process(&py, &[adapter], &input);
    let text = String::from_utf8(sample.stdout.clone()).unwrap();
    let n_rows = text.lines().count() - 1;
    put(
        &mut rows,
        "parse_resample",
        time(runs * 10, || {
            let recs = csv::read(&text, problem.body.len()).unwrap();
            let history = history_from_rows(&problem, &recs).unwrap();
            trajectory_from_steps("pure_python", &problem, &history)
        }),
        format!(
            "csv::read + history_from_rows + trajectory_from_steps ({n_rows} rows, {} bytes)",
            text.len()
        ),
    );

    // Starting the interpreter and the pipes, nothing else.
    let echo = ["-c", "import sys; sys.stdin.buffer.read()"];
    put(
        &mut rows,
        "spawn_python3_on_path",
        time(runs, || process("python3", &echo, &input)),
        format!("`python3` as pushval.toml names it ({})", shim_or_not()),
    );
    put(
        &mut rows,
        "spawn_resolved_interpreter",
        time(runs, || process(&py, &echo, &input)),
        "the interpreter `python3` on PATH runs, named by its path".into(),
    );
    let echo_s = ["-S", "-c", "import sys; sys.stdin.buffer.read()"];
    put(
        &mut rows,
        "spawn_resolved_no_site",
        time(runs, || process(&py, &echo_s, &input)),
        "the resolved interpreter with -S (no site import, no .pth files)".into(),
    );
    let venv = root().join(".venv-adapters/bin/python");
    if venv.exists() {
        let v = venv.display().to_string();
        put(
        &mut rows,
            "spawn_venv",
            time(runs, || process(&v, &echo, &input)),
            ".venv-adapters/bin/python (scripts/setup-adapters.sh; the other adapters' interpreter)"
                .into(),
        );
    } else {
        eprintln!(
            "outside_overhead: no .venv-adapters (scripts/setup-adapters.sh): row spawn_venv not measured"
        );
    }

    // The adapter: its own stepping, the whole process.
    let mut stepping = Vec::new();
    let mut whole = Vec::new();
    for _ in 0..runs {
        let out = process(&py, &[adapter, "--timing"], &input);
        whole.push(out.elapsed.as_secs_f64());
        let err = String::from_utf8_lossy(&out.stderr);
        let t: f64 = err
            .split_whitespace()
            .find_map(|w| w.strip_prefix("step_time_s=").and_then(|n| n.parse().ok()))
            .unwrap_or_else(|| panic!("no stepping time in the adapter's stderr: {err}"));
        stepping.push(t);
    }
    let stepping = median(stepping);
    put(
        &mut rows,
        "adapter_stepping",
        stepping,
        format!(
            "pure_python.py --timing: its step loop alone ({} steps)",
            n_rows - 1
        ),
    );
    put(
        &mut rows,
        "adapter_process_resolved",
        median(whole),
        format!("the resolved interpreter running {adapter}: start to exit, document in, CSV out"),
    );
    put(
        &mut rows,
        "adapter_process_python3_on_path",
        time(runs, || process("python3", &[adapter], &input)),
        "python3 (PATH) adapters/python/pure_python.py: start to exit".into(),
    );

    // Through the Engine trait, as the harness runs it.
    let engine = OutsideEngine::new(spec("python3"), &options);
    let run = time(runs, || engine.run(&problem, DT).unwrap());
    put(
        &mut rows,
        "engine_run_python3_on_path",
        run,
        "OutsideEngine::run (command python3 from PATH): document, process, parse, resample".into(),
    );
    let engine_r = OutsideEngine::new(spec(&py), &options);
    let run_r = time(runs, || engine_r.run(&problem, DT).unwrap());
    put(
        &mut rows,
        "engine_run_resolved",
        run_r,
        "OutsideEngine::run (command: the resolved interpreter)".into(),
    );
    // Sessions, measured in pairs: each run's wall time against the
    // adapter's own stepping in that same run (warm, in the same process),
    // so the protocol's share does not mix a cold one-shot stepping time
    // with a warm session's run. The default session (protocol 3, rows at
    // the sample times), the same with every step, then protocol 2 (whole
    // documents, every step).
    let kinds = [
        (
            "session",
            "",
            "protocol 3, rows at the sample times (the default)",
        ),
        (
            "session_steps",
            "rows = \"steps\"\n",
            "protocol 3, rows = 'steps'",
        ),
        (
            "session_p2",
            "protocol = 2\n",
            "protocol 2: whole documents, a row per step",
        ),
    ];
    let logs = tempfile::tempdir().expect("a temporary folder");
    for (kind, extra, what) in kinds {
        for (label, python) in [("resolved", py.as_str()), ("python3_on_path", "python3")] {
            if kind != "session" && label != "resolved" {
                continue;
            }
            let log = logs.path().join(format!("{kind}_{label}"));
            let session = OutsideEngine::new(session_spec(python, extra, &log), &options);
            let warm = session.run(&problem, DT).unwrap();
            assert_eq!(warm.diagnostics["session"]["answered_before"], 0);
            let (mut walls, mut reads) = (Vec::with_capacity(runs), Vec::with_capacity(runs));
            for _ in 0..runs {
                let s = Instant::now();
                let run = std::hint::black_box(session.run(&problem, DT).unwrap());
                walls.push(s.elapsed().as_secs_f64());
                reads.push(run.diagnostics["parse_resample_time_s"].as_f64().unwrap());
            }
            let last = session.run(&problem, DT).unwrap();
            assert_eq!(
                last.diagnostics["session"]["pid"], warm.diagnostics["session"]["pid"],
                "one process served every run"
            );
            shutdown_sessions();
            let steps = step_times(&log);
            assert_eq!(steps.len(), runs + 2, "a stepping time per run: {steps:?}");
            let steps = &steps[1..=runs];
            let answers = logged(&log, "answer_time_s=");
            let kit: Option<Vec<f64>> = (answers.len() == runs + 2).then(|| {
                answers[1..=runs]
                    .iter()
                    .zip(steps)
                    .map(|(a, s)| a - s)
                    .collect()
            });
            let over: Vec<f64> = walls.iter().zip(steps).map(|(w, s)| w - s).collect();
            let share: Vec<f64> = walls.iter().zip(steps).map(|(w, s)| (w - s) / w).collect();
            let about = format!(
                "pure_python.py as a session, {what}, {} ({} rows a run; {runs} runs on one process started before the timing)",
                interpreter(label),
                last.diagnostics["rows"]
            );
            put(
                &mut rows,
                &format!("engine_run_{kind}_{label}"),
                median(walls.clone()),
                format!("OutsideEngine::run: {about}"),
            );
            put(
                &mut rows,
                &format!("adapter_stepping_{kind}_{label}"),
                median(steps.to_vec()),
                "the adapter's own stepping in those runs (--timing: reset, the switches and the step loop)"
                    .into(),
            );
            put(
                &mut rows,
                &format!("overhead_{kind}_{label}"),
                median(over.clone()),
                "engine_run − adapter_stepping, run by run: the protocol's cost per run".into(),
            );
            put(
                &mut rows,
                &format!("pushval_read_{kind}_{label}"),
                median(reads.clone()),
                "pushval's own side of the answers in those runs (reading and checking the rows, resampling: the run's parse_resample_time_s)".into(),
            );
            if let Some(kit) = kit {
                let handoff: Vec<f64> = (0..runs).map(|i| over[i] - kit[i] - reads[i]).collect();
                put(
                    &mut rows,
                    &format!("kit_{kind}_{label}"),
                    median(kit),
                    "the adapter kit's own work in those runs (--timing: answer_time_s − step_time_s, run by run: parsing the documents, taking and encoding the rows)".into(),
                );
                put(
                    &mut rows,
                    &format!("handoff_{kind}_{label}"),
                    median(handoff),
                    "overhead − kit − pushval_read, run by run: writing and reading the pipes, and the waits for a core at each handoff between pushval and the adapter".into(),
                );
            }
            let (med, min) = median(share);
            rows.push((
                format!("overhead_share_{kind}_{label}"),
                med,
                min,
                "fraction",
                "overhead / engine_run, run by run (median, min)".into(),
            ));
        }
    }
    // The MPC case: the caller owns the loop and steps one control period at
    // a time (`pushval loop`: one protocol 3 `advance` a period, each
    // answer awaited before the next request). The 10 s paper push cut
    // into 500 periods of 0.02 s (20 steps each), through start, advance
    // and finish directly; per run the adapter reports its stepping at
    // `finish` (--timing), so the rows are per advance: a run's wall time
    // and stepping divided by its 500 advances.
    let periods: Vec<Push> = problem
        .pushes
        .iter()
        .flat_map(|p| {
            let n = (p.duration / PERIOD).round().max(1.0) as usize;
            std::iter::repeat_n(
                Push {
                    duration: p.duration / n as f64,
                    ..*p
                },
                n,
            )
        })
        .collect();
    for (label, python) in [("resolved", py.as_str()), ("python3_on_path", "python3")] {
        let log = logs.path().join(format!("mpc_{label}"));
        let session = OutsideEngine::new(session_spec(python, "", &log), &options);
        let warm = session.run(&problem, DT).unwrap();
        let stepped = |s: &OutsideEngine| {
            let e: &dyn Engine = s;
            let mut sess = e.start(&problem, DT).unwrap();
            for p in &periods {
                sess.advance(p).unwrap();
            }
            sess.finish().unwrap()
        };
        let (mut walls, mut reads) = (Vec::with_capacity(runs), Vec::with_capacity(runs));
        for _ in 0..runs {
            let s = Instant::now();
            let run = std::hint::black_box(stepped(&session));
            walls.push(s.elapsed().as_secs_f64());
            reads.push(run.diagnostics["parse_resample_time_s"].as_f64().unwrap());
        }
        let last = stepped(&session);
        assert_eq!(
            last.diagnostics["session"]["pid"], warm.diagnostics["session"]["pid"],
            "one process served every run"
        );
        assert_eq!(
            last.diagnostics["session"]["requests"]
                .as_array()
                .map(Vec::len),
            Some(periods.len() + 2),
            "a request per period, a start and a finish"
        );
        shutdown_sessions();
        let steps = step_times(&log);
        assert_eq!(steps.len(), runs + 2, "a stepping time per run: {steps:?}");
        let steps = &steps[1..=runs];
        let answers = logged(&log, "answer_time_s=");
        assert_eq!(
            answers.len(),
            runs + 2,
            "an answering time per run: {answers:?}"
        );
        let kit: Vec<f64> = answers[1..=runs]
            .iter()
            .zip(steps)
            .map(|(a, s)| a - s)
            .collect();
        let k = periods.len() as f64;
        let per = |v: Vec<f64>| {
            let (med, min) = median(v);
            (med / k, min / k)
        };
        let over: Vec<f64> = walls.iter().zip(steps).map(|(w, s)| w - s).collect();
        let share: Vec<f64> = walls.iter().zip(steps).map(|(w, s)| (w - s) / w).collect();
        let handoff: Vec<f64> = (0..runs).map(|i| over[i] - kit[i] - reads[i]).collect();
        put(
            &mut rows,
            &format!("engine_run_mpc_{label}"),
            per(walls.clone()),
            format!(
                "per advance: pure_python.py as a session (protocol 3, rows at the sample times), {}; the 10 s paper push as {} advances of {PERIOD} s ({} steps each), start/advance/finish one request at a time, each answer awaited; {runs} runs (a run's wall time / {})",
                interpreter(label),
                periods.len(),
                (PERIOD / DT).round(),
                periods.len()
            ),
        );
        put(
            &mut rows,
            &format!("adapter_stepping_mpc_{label}"),
            per(steps.to_vec()),
            "per advance: the adapter's own stepping in those runs (--timing at finish: reset, the switches and the step loop, / the advances)".into(),
        );
        put(
            &mut rows,
            &format!("overhead_mpc_{label}"),
            per(over),
            "per advance: engine_run − adapter_stepping, run by run: the protocol's cost of one control period".into(),
        );
        put(
            &mut rows,
            &format!("kit_mpc_{label}"),
            per(kit),
            "per advance: the adapter kit's own work in those runs (--timing: answer_time_s − step_time_s, / the advances: parsing the request, cutting the push into steps, taking and encoding the rows)".into(),
        );
        put(
            &mut rows,
            &format!("handoff_mpc_{label}"),
            per(handoff),
            "per advance: overhead − kit − pushval_read, run by run: writing and reading the pipes, and the two waits for a core at each round trip between pushval and the adapter".into(),
        );
        put(
            &mut rows,
            &format!("pushval_read_mpc_{label}"),
            per(reads),
            "per advance: pushval's own side of the answers in those runs (reading and checking each answer's rows, and the resampling at finish: the run's parse_resample_time_s / the advances)".into(),
        );
        let (med, min) = median(share);
        rows.push((
            format!("overhead_share_mpc_{label}"),
            med,
            min,
            "fraction",
            "overhead / engine_run, run by run (median, min)".into(),
        ));
    }

    // A whole `pushval loop` (model-predictive control, src/control/mpc.rs)
    // in process, on a warm session: the goal (0.8 m, 0.2 m, -0.5 rad) at
    // 1 m/s from the paper square at rest. Its wall time holds the plan
    // from rest, the re-plans (the predictor), the adapter's stepping and
    // the protocol: the session's requests as pushval sees them (from
    // writing each document to its closing line, and reading the answers)
    // less the adapter's stepping in them.
    {
        use pushval::control::mpc::{plan_from_rest, run_loop, LoopSpec};
        use pushval::control::plan::PlanSpec;
        use pushval::control::{ModelKind as Predictor, Reach};
        let text = std::fs::read_to_string(root().join(SCENARIO)).unwrap();
        let loop_problem = pushval::control::cli::problem_from_rest(&sc, &text);
        let goal = pushval::control::parse_goal(GOAL).unwrap();
        let spec = LoopSpec {
            plan: PlanSpec {
                segments: 6,
                speed: 1.0,
                predictor: Predictor::Dynamic,
                at: pushval::control::At::Release,
            },
            period: PERIOD,
            reach: Reach::default(),
            adapt: false,
            sensor: Default::default(),
        };
        let plan_time = time(runs, || {
            plan_from_rest(&loop_problem, goal, spec.plan, spec.reach).is_some()
        });
        let log = logs.path().join("loop");
        let session = OutsideEngine::new(session_spec(&py, "", &log), &options);
        let warm = session.run(&problem, DT).unwrap();
        let (mut walls, mut planning, mut requests) = (Vec::new(), Vec::new(), Vec::new());
        let mut periods_run = 0;
        for _ in 0..runs {
            let s = Instant::now();
            let engine: &dyn pushval_engine::Engine = &session;
            let mut plant = engine.start(&loop_problem, DT).unwrap();
            let out = run_loop(&loop_problem, plant.as_mut(), DT, goal, spec, &mut ()).unwrap();
            let run = plant.finish().unwrap();
            walls.push(s.elapsed().as_secs_f64());
            assert!(out.success, "the loop reaches its goal");
            assert!(!out.replayed, "the session steps");
            assert_eq!(
                run.diagnostics["session"]["pid"], warm.diagnostics["session"]["pid"],
                "one process served every run"
            );
            planning.push(plan_time.0 + out.predictor_us.iter().sum::<f64>() * 1e-6);
            let d = &run.diagnostics;
            requests.push(
                d["process_wall_time_s"].as_f64().unwrap()
                    + d["parse_resample_time_s"].as_f64().unwrap(),
            );
            periods_run = out.steps;
        }
        shutdown_sessions();
        let steps = step_times(&log);
        assert_eq!(steps.len(), runs + 1, "a stepping time per run: {steps:?}");
        let steps = &steps[1..];
        let over: Vec<f64> = (0..runs).map(|i| requests[i] - steps[i]).collect();
        let rest: Vec<f64> = (0..runs)
            .map(|i| walls[i] - requests[i] - planning[i])
            .collect();
        let share: Vec<f64> = (0..runs).map(|i| over[i] / walls[i]).collect();
        put(
            &mut rows,
            "loop_run_resolved",
            median(walls.clone()),
            format!(
                "pushval's MPC loop (control::mpc::run_loop, as `pushval loop {SCENARIO} --goal {GOAL} --speed 1.0 --engine pure_python` runs it) in process on a warm session of pure_python.py (the resolved interpreter): {periods_run} periods of {PERIOD} s and the rest of the plan; {runs} runs"
            ),
        );
        put(
            &mut rows,
            "adapter_stepping_loop_resolved",
            median(steps.to_vec()),
            "the adapter's own stepping in those runs (--timing at finish)".into(),
        );
        put(
            &mut rows,
            "planning_loop_resolved",
            median(planning),
            "the plan from rest (timed alone, median) + the loop's re-plans (its predictor_us, summed), run by run".into(),
        );
        put(
            &mut rows,
            "requests_loop_resolved",
            median(requests.clone()),
            "the session's requests in those runs as pushval sees them: from writing each document to its closing line (process_wall_time_s), and reading the answers with the resampling at finish (parse_resample_time_s)".into(),
        );
        put(
            &mut rows,
            "overhead_loop_resolved",
            median(over),
            "requests_loop − adapter_stepping, run by run: the protocol's cost in a whole loop"
                .into(),
        );
        put(
            &mut rows,
            "rest_loop_resolved",
            median(rest),
            "loop_run − requests_loop − planning, run by run: the loop's own bookkeeping and what the planning estimate misses".into(),
        );
        let (med, min) = median(share);
        rows.push((
            "overhead_share_loop_resolved".into(),
            med,
            min,
            "fraction",
            "overhead_loop / loop_run, run by run (median, min)".into(),
        ));
    }

    // The adapter's own input and output (imports, json.load, writing the
    // rows), by difference.
    let med = |name: &str| {
        rows.iter()
            .find(|r| r.0 == name)
            .map(|r| (r.1, r.2))
            .unwrap()
    };
    let (proc_r, spawn_r) = (
        med("adapter_process_resolved"),
        med("spawn_resolved_interpreter"),
    );
    put(
        &mut rows,
        "adapter_io_resolved",
        (proc_r.0 - spawn_r.0 - stepping.0, proc_r.1 - spawn_r.1 - stepping.1),
        "adapter_process_resolved − spawn_resolved_interpreter − adapter_stepping: the adapter's imports, json.load and CSV writing".into(),
    );
    let overheads = vec![
        ("python3_on_path".to_string(), run),
        ("resolved".to_string(), run_r),
    ];
    for (label, r) in overheads {
        let over = r.0 - stepping.0;
        put(
            &mut rows,
            &format!("overhead_{label}"),
            (over, r.1 - stepping.1),
            format!("engine_run_{label} − adapter_stepping (median − median, min − min): the protocol's cost per run"),
        );
        rows.push((
            format!("overhead_share_{label}"),
            over / r.0,
            (r.1 - stepping.1) / r.1,
            "fraction",
            format!("overhead_{label} / engine_run_{label} (of the medians, of the mins)"),
        ));
    }

    // The main job (`pushval` with no command: every shipped scenario,
    // pushval's own pure-Python engines as sessions) as a user runs it: the
    // release binary from the repository's root, whole process, wall time.
    let bin = root().join("target/release/pushval");
    if bin.is_file() {
        let mut runs_ok = true;
        let wall = time(if quick { 2 } else { 5 }, || {
            let st = Command::new(&bin)
                .current_dir(root())
                .env_remove("CI")
                .output()
                .expect("the pushval binary runs");
            runs_ok &= st.status.success();
        });
        assert!(runs_ok, "the main job failed while timed");
        put(
            &mut rows,
            "main_job_wall",
            wall,
            format!(
                "target/release/pushval (the main job: {} scenarios, the pure-Python engines as sessions), whole process, {} cores",
                std::fs::read_dir(root().join("scenarios")).map_or(0, |d| d.count()),
                std::thread::available_parallelism().map_or(1, |n| n.get())
            ),
        );
        // `pushval loop` as a user runs it: the whole process, the engine
        // declared in the repository's pushval.toml (python3 from PATH), the
        // interpreter's start included.
        let out = tempfile::tempdir().expect("a temporary folder");
        let mut runs_ok = true;
        let wall = time(if quick { 2 } else { 5 }, || {
            let st = Command::new(&bin)
                .current_dir(root())
                .args(["loop", SCENARIO, "--goal", GOAL, "--speed", "1.0"])
                .args(["--engine", "pure_python", "--out"])
                .arg(out.path())
                .output()
                .expect("the pushval binary runs");
            runs_ok &= st.status.success();
        });
        assert!(runs_ok, "pushval loop failed while timed");
        put(
            &mut rows,
            "loop_cli_wall",
            wall,
            format!(
                "target/release/pushval loop {SCENARIO} --goal {GOAL} --speed 1.0 --engine pure_python (pushval.toml: python3 from PATH, a session), whole process: the interpreter's start, the plan, the loop, the outputs"
            ),
        );
    } else {
        eprintln!("outside_overhead: no target/release/pushval; main_job_wall and loop_cli_wall not measured (cargo build --release first)");
    }

    // How busy the machine was: the protocol's share grows with the wait
    // for a core at each handoff between pushval and the adapter.
    if let Some(load) = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next()?.parse::<f64>().ok())
    {
        rows.push((
            "load_average_1min".into(),
            load,
            load,
            "processes",
            format!(
                "the machine's 1-minute load average at the end of the measurements ({} cores)",
                std::thread::available_parallelism().map_or(1, |n| n.get())
            ),
        ));
    }

    let mut table = pushval::outdir::Csv::new(&["quantity", "median", "min", "unit", "note"]);
    for (name, med, min, unit, note) in &rows {
        let (med, min) = (format!("{med:.6}"), format!("{min:.6}"));
        table.row(&[name.as_str(), &med, &min, unit, note]);
    }
    let path = root().join("results/outside_overhead.csv");
    pushval::atomic::write_atomic(&path, table.as_bytes()).unwrap();
    eprintln!("wrote {}", path.display());

    // The in-process parts under criterion (its own statistics and report).
    let mut c = Criterion::default()
        .sample_size(20)
        .measurement_time(Duration::from_secs(if quick { 1 } else { 3 }))
        .configure_from_args();
    c.bench_function("outside/document", |b| {
        b.iter(|| serde_json::to_vec(&problem_document("pure_python", &problem, &options, DT)))
    });
    c.bench_function("outside/parse_resample", |b| {
        b.iter(|| {
            let recs = csv::read(&text, problem.body.len()).unwrap();
            let history = history_from_rows(&problem, &recs).unwrap();
            trajectory_from_steps("pure_python", &problem, &history)
        })
    });
    c.final_summary();
}
