//! Outside engines through the binary: `pushval.toml` / `--engines`, the
//! gate on the pure-Python adapter, and every way an adapter can fail
//! (exit 2 with a sentence naming the engine and the cause; nothing written).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common::root;

fn pushval() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pushval"))
}

fn text(o: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// An engines file in `dir` declaring `pure_python` as `command`.
fn engines_file(dir: &Path, command: &[&str], extra: &str) -> PathBuf {
    let quoted: Vec<String> = command.iter().map(|a| format!("{a:?}")).collect();
    let path = dir.join("engines.toml");
    std::fs::write(
        &path,
        format!(
            "[engine.pure_python]\ncommand = [{}]\n{extra}",
            quoted.join(", ")
        ),
    )
    .unwrap();
    path
}

fn adapter() -> String {
    root()
        .join("adapters/python/pure_python.py")
        .display()
        .to_string()
}

fn scenario() -> PathBuf {
    root().join("scenarios/outside-pure-python.toml")
}

/// The scenario gating only `pure_python` (the shipped one gates the heun
/// variant too).
fn single_gate(dir: &Path) -> PathBuf {
    // The heun scene (auto tolerances), its engine renamed to the one the
    // test's engines file declares.
    let text = std::fs::read_to_string(root().join("scenarios/outside-pure-python-heun.toml"))
        .unwrap()
        .replace("\"pure_python_heun\"", "\"pure_python\"");
    let p = dir.join("one.toml");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn engines_lists_the_outside_engines_of_pushval_toml() {
    let o = pushval()
        .arg("engines")
        .current_dir(root())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let out = String::from_utf8(o.stdout).unwrap();
    let row = out
        .lines()
        .find(|l| l.starts_with("pure_python "))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(row.contains("outside: pushval.toml"), "{row}");
    assert!(row.contains("pure_python.py (Coulomb per support"), "{row}");
    // Not listed without a pushval.toml in the current directory.
    let dir = tempfile::tempdir().unwrap();
    let o = pushval()
        .arg("engines")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(!String::from_utf8(o.stdout).unwrap().contains("pure_python"));
}

#[test]
fn the_shipped_outside_scenario_gates_and_passes() {
    let o = pushval()
        .args(["validate", "--json"])
        .arg(scenario())
        .arg(root().join("scenarios/outside-pure-python-heun.toml"))
        .current_dir(root())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let s = v.to_string();
    assert!(
        s.contains("\"pure_python\"") && s.contains("\"pure_python_heun\""),
        "{s}"
    );
}

/// The same adapter with I_cm 1 % high fails the gate (exit 1) where the
/// second-order scheme's own error is far below the change; with the right
/// I_cm the same declaration passes (so the failure is the inertia's).
#[test]
fn an_adapter_with_inertia_one_percent_off_fails_the_gate() {
    let dir = tempfile::tempdir().unwrap();
    let sc = single_gate(dir.path());
    let a = adapter();
    let right = engines_file(
        dir.path(),
        &["python3", &a, "--scheme", "heun"],
        "order = 2\n",
    );
    let o = pushval()
        .arg("validate")
        .arg(&sc)
        .arg("--engines")
        .arg(&right)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let wrong = engines_file(
        dir.path(),
        &["python3", &a, "--scheme", "heun", "--inertia-scale", "1.01"],
        "order = 2\n",
    );
    let o = pushval()
        .arg("validate")
        .arg(&sc)
        .arg("--engines")
        .arg(&wrong)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("FAIL outside-pure-python-heun / pure_python: "),
        "{}",
        text(&o)
    );
}

/// Runs `pushval run` on the single-gate scenario with `pure_python`
/// declared as `command`; returns the output and whether the out folder
/// exists afterwards.
fn run_with(command: &[&str], extra: &str) -> (Output, bool) {
    let dir = tempfile::tempdir().unwrap();
    let sc = single_gate(dir.path());
    let engines = engines_file(dir.path(), command, extra);
    let out = dir.path().join("out");
    let o = pushval()
        .arg("run")
        .arg(&sc)
        .arg("--out")
        .arg(&out)
        .arg("--engines")
        .arg(&engines)
        .output()
        .unwrap();
    (o, out.exists())
}

#[test]
fn an_adapter_exiting_3_is_an_input_error_naming_it() {
    let (o, written) = run_with(
        &["python3", "-c", "import sys; sys.stdin.read(); print('no licence for mysim', file=sys.stderr); sys.exit(3)"],
        "",
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("outside engine \"pure_python\"") && t.contains("exited with status 3"),
        "{t}"
    );
    assert!(
        t.contains("no licence for mysim"),
        "the last stderr lines: {t}"
    );
    assert!(t.contains("python3 -c"), "the command: {t}");
    assert!(!written, "nothing is written");
}

#[test]
fn a_malformed_row_names_its_line_and_column() {
    let (o, written) = run_with(
        &["python3", "-c", "import sys; sys.stdin.read(); print('t,x,y,theta,omega'); print('0,0,0,0,0'); print('0.001,0.001,zero,0,0')"],
        "",
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("outside engine \"pure_python\"")
            && t.contains("line 3: column `y`: `zero` is not a number"),
        "{t}"
    );
    assert!(!written);
}

#[test]
fn an_adapter_past_its_timeout_is_killed_and_named() {
    let start = std::time::Instant::now();
    let (o, written) = run_with(
        &["python3", "-c", "import sys, time; sys.stdin.read(); print('thinking', file=sys.stderr, flush=True); time.sleep(60)"],
        "timeout_s = 1\n",
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("outside engine \"pure_python\"") && t.contains("timeout of 1 s: killed"),
        "{t}"
    );
    assert!(t.contains("thinking"), "{t}");
    assert!(!written);
    // Killed at the first timeout, not once per ladder rung.
    assert!(
        start.elapsed().as_secs_f64() < 30.0,
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn a_missing_program_says_how_to_get_it() {
    let (o, _) = run_with(&["python3-not-installed-anywhere", "x.py"], "");
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("run.gate[0]") && t.contains("python3-not-installed-anywhere on PATH"),
        "{t}"
    );
    assert!(t.contains("install Python 3"), "{t}");
}

/// A scenario can name an outside engine, never define one: an engine
/// table in a scenario is only `[engine]` options, and a name no registry
/// or engines file defines is an input error naming the key and the file
/// searched; the command in the scenario never runs.
#[test]
fn a_scenario_cannot_define_an_engine() {
    let dir = tempfile::tempdir().unwrap();
    let marker = dir.path().join("ran");
    let base = std::fs::read_to_string(root().join("scenarios/paper-square-v1.0.toml")).unwrap();
    let evil = base.replace(
        "[run]\n",
        &format!(
            "[engine.evil]\ncommand = [\"touch\", {:?}]\n\n[run]\nmodels = [\"dynamic\", \"evil\"]\n",
            marker.display().to_string()
        ),
    );
    let sc = dir.path().join("evil.toml");
    std::fs::write(&sc, evil).unwrap();
    let o = pushval()
        .arg("validate")
        .arg(&sc)
        .current_dir(dir.path())
        .output()
        .unwrap();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("run.models[1]") && t.contains("unknown model \"evil\""),
        "{t}"
    );
    assert!(
        t.contains("pushval.toml (not found)"),
        "the file searched: {t}"
    );
    assert!(!marker.exists());
    let gated = base.replace("[run]\n", "[run]\ngate = [\"evil\"]\n");
    std::fs::write(&sc, gated).unwrap();
    let o = pushval()
        .arg("validate")
        .arg(&sc)
        .current_dir(dir.path())
        .output()
        .unwrap();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("run.gate[0]") && t.contains("pushval.toml (not found)"),
        "{t}"
    );
}

#[test]
fn problem_prints_the_document() {
    let o = pushval()
        .args(["problem", "--dt", "0.0005", "--engine", "pure_python"])
        .arg(scenario())
        .current_dir(root())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "pushval-problem/1");
    assert_eq!(v["dt"], 5e-4);
    assert_eq!(v["engine"], "pure_python");
    assert_eq!(v["pushes"].as_array().unwrap().len(), 2);
}

/// A bad engines file stops every command before any work, naming the file
/// and the key.
#[test]
fn a_bad_engines_file_is_an_input_error() {
    let dir = tempfile::tempdir().unwrap();
    let f = engines_file(dir.path(), &["python3"], "shell = true\n");
    let o = pushval()
        .arg("engines")
        .arg("--engines")
        .arg(&f)
        .output()
        .unwrap();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("engines.toml: engine.pure_python.shell: unknown key"),
        "{t}"
    );
    let f = engines_file(dir.path(), &["python3"], "law = \"stribeck\"\n");
    let o = pushval()
        .arg("engines")
        .arg("--engines")
        .arg(&f)
        .output()
        .unwrap();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("engine.pure_python.law: unknown law \"stribeck\"")
            && t.contains("impulse_rows_disk"),
        "{t}"
    );
    let o = pushval()
        .arg("engines")
        .arg("--engines")
        .arg(dir.path().join("none.toml"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// `pushval power` on an outside engine: the gate of the shipped
/// second-order pure-Python scenario (auto tolerances under the 1e-3
/// ceiling) catches an I_cm error of 1 % and a μ error of 1 % like the
/// compiled-in engines (the adapter with I_cm 1 % off fails `validate`, see
/// above); the engine runs once, as a process, and the errors are injected
/// into the model.
#[test]
fn power_measures_the_gate_of_an_outside_engine() {
    let sc = crate::common::load(&root().join("scenarios/outside-pure-python-heun.toml"));
    let rows = pushval::power::measure(&[sc], &[], 8).unwrap();
    let ours: Vec<_> = rows
        .iter()
        .filter(|r| r.engine == "pure_python_heun")
        .collect();
    assert!(!ours.is_empty(), "no rows for the outside engine: {rows:?}");
    for kind in [
        pushval::power::ErrorKind::InertiaCm,
        pushval::power::ErrorKind::MuAll,
    ] {
        let r = ours.iter().find(|r| r.kind == kind).unwrap();
        let caught = r.both().unwrap_or(f64::INFINITY);
        assert!(caught <= 0.01, "{}: caught from {caught:e}", kind.name());
        // The dt ladder chose the step: a rung 1/(60 · 2^k) s.
        let k = (1.0 / (60.0 * r.dt)).log2();
        assert!(
            k >= 1.0 && (k - k.round()).abs() < 1e-9,
            "the gate's dt {}",
            r.dt
        );
    }
}

/// `pushval fit` on an outside engine's trajectory: the pure-Python adapter
/// run with its inertia scaled by 1.05 (`--inertia-scale`), its trajectory
/// written by `pushval run`, and the fit of μ scale and I_cm from the
/// scenario's values recovers I_cm × 1.05 and μ × 1 (Heun at dt = 1e-3 is
/// accurate to ~1e-6 m, far below the parameters' effect).
#[test]
fn fit_recovers_the_inertia_of_an_outside_engine() {
    let dir = tempfile::tempdir().unwrap();
    let engines = dir.path().join("engines.toml");
    std::fs::write(
        &engines,
        format!(
            "[engine.heavy_python]\ncommand = [\"python3\", {:?}, \"--scheme\", \"heun\", \"--inertia-scale\", \"1.05\"]\norder = 2\n",
            adapter()
        ),
    )
    .unwrap();
    let text_sc = std::fs::read_to_string(root().join("scenarios/outside-pure-python-heun.toml"))
        .unwrap()
        .replace(
            "models = [\"dynamic\", \"kinematic\", \"pure_python_heun\"]",
            "models = [\"heavy_python\"]",
        )
        .replace("gate = [\"pure_python_heun\"]\n", "");
    assert!(text_sc.contains("models = [\"heavy_python\"]"));
    let sc = dir.path().join("heavy.toml");
    std::fs::write(&sc, text_sc).unwrap();
    let run_dir = dir.path().join("run");
    let o = pushval()
        .arg("run")
        .arg(&sc)
        .arg("--out")
        .arg(&run_dir)
        .arg("--engines")
        .arg(&engines)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let out = dir.path().join("fit");
    let o = pushval()
        .arg("fit")
        .arg(&sc)
        .arg("--trajectory")
        .arg(run_dir.join("trajectory.csv"))
        .args([
            "--model",
            "heavy_python",
            "--params",
            "mu_scale,inertia_cm",
            "--out",
        ])
        .arg(&out)
        .arg("--engines")
        .arg(&engines)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("fit.json")).unwrap()).unwrap();
    let mu = j["parameters"]["mu_scale"]["value"].as_f64().unwrap();
    let inertia = j["parameters"]["inertia_cm"]["value"].as_f64().unwrap();
    let truth = 1.05 * 0.0625 / 6.0;
    assert!((mu - 1.0).abs() < 2e-3, "mu_scale {mu}");
    assert!(
        (inertia / truth - 1.0).abs() < 5e-3,
        "inertia_cm {inertia}, the adapter's {truth}"
    );
}

/// A session engine through the binary: the gate's dt ladder runs the
/// problem several times on the processes of one pool (at most one per
/// core), and none of them outlives `pushval`. The engine is pure_python.py
/// itself (the adapter kit's session mode), started through `sh` so that
/// every process start is logged.
#[test]
fn a_session_engine_serves_the_ladder_and_ends_with_pushval() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("pids");
    let sc = single_gate(dir.path());
    let script = format!(
        "echo $$ >> '{}'; exec python3 '{}' --scheme heun",
        log.display(),
        adapter()
    );
    let engines = engines_file(
        dir.path(),
        &["sh", "-c", &script],
        "order = 2\nsession = true\n",
    );
    let o = pushval()
        .args(["validate", "--json"])
        .arg(&sc)
        .arg("--engines")
        .arg(&engines)
        .output()
        .unwrap();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let session = &doc[0]["models"]["pure_python"]["diagnostics"]["session"];
    // The last run was answered by a process that had answered others.
    assert!(
        session["answered_before"].as_u64().unwrap_or(0) >= 1,
        "{session}"
    );
    let pids: Vec<u32> = std::fs::read_to_string(&log)
        .unwrap()
        .lines()
        .map(|l| l.trim().parse().unwrap())
        .collect();
    let mut distinct = pids.clone();
    distinct.sort_unstable();
    distinct.dedup();
    let cores = std::thread::available_parallelism().unwrap().get();
    assert!(
        !distinct.is_empty() && distinct.len() <= cores,
        "{} processes started: {t}",
        distinct.len()
    );
    for pid in distinct {
        assert!(
            !Path::new(&format!("/proc/{pid}")).exists(),
            "session process {pid} outlived pushval"
        );
    }
}

/// An adapter that exits while a process it started still holds its
/// standard output open (so no end of file comes) is noticed by its own
/// exit, at once, and reported with its exit status and its standard
/// error: one-shot, whole-document session and stepping session alike. The
/// bound (10 s against a 30 s timeout) tells "noticed by the exit" from
/// "noticed at the timeout"; it is not a speed measure. The process it
/// left behind is ended with it.
#[test]
fn an_adapter_exiting_while_its_child_holds_stdout_is_noticed_at_once() {
    for (how, extra) in [
        ("one-shot", ""),
        ("protocol 2 session", "session = true\nprotocol = 2\n"),
        ("protocol 3 session", "session = true\n"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let held = dir.path().join("sleeper");
        let script = format!(
            "import subprocess, sys\n\
             child = subprocess.Popen(['sleep', '1000'])\n\
             open({:?}, 'w').write(str(child.pid))\n\
             sys.stdin.readline()\n\
             print('lost my licence server', file=sys.stderr, flush=True)\n\
             sys.exit(3)\n",
            held.display().to_string()
        );
        let sc = single_gate(dir.path());
        let engines = engines_file(
            dir.path(),
            &["python3", "-c", &script],
            &format!("timeout_s = 30\n{extra}"),
        );
        let start = std::time::Instant::now();
        let o = pushval()
            .arg("run")
            .arg(&sc)
            .arg("--out")
            .arg(dir.path().join("out"))
            .arg("--engines")
            .arg(&engines)
            .output()
            .unwrap();
        let elapsed = start.elapsed();
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{how}: {t}");
        assert!(elapsed.as_secs_f64() < 10.0, "{how}: took {elapsed:?}: {t}");
        assert!(t.contains("exited with status 3"), "{how}: {t}");
        assert!(t.contains("lost my licence server"), "{how}: {t}");
        assert!(!t.contains("timeout"), "{how}: not a timeout: {t}");
        let sleeper: u32 = std::fs::read_to_string(&held)
            .unwrap()
            .trim()
            .parse()
            .unwrap();
        let stat = std::fs::read_to_string(format!("/proc/{sleeper}/stat")).unwrap_or_default();
        assert!(
            stat.is_empty() || stat.contains(") Z "),
            "{how}: the child {sleeper} holding the pipe outlived the run: {stat}"
        );
    }
}
