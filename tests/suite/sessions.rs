//! Sessions that cannot be fooled and no survivor (issue 40, items 3 and
//! 4), through the binary: an answer closed with another request's number,
//! a row of 1e300 between two samples, a protocol 1 adapter declared with
//! `session = true`, and a `setsid()` child that execs with an empty
//! environment. Each exits 2 naming the engine, or leaves no process
//! behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

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

fn adapter(name: &str) -> String {
    root()
        .join("adapters/python")
        .join(name)
        .display()
        .to_string()
}

/// `pushval run` of the first two pushes of the paper scene gating
/// `mine`, declared as `command` with `extra` keys.
fn run(dir: &Path, command: &[&str], extra: &str) -> Output {
    let quoted: Vec<String> = command.iter().map(|a| format!("{a:?}")).collect();
    let engines = dir.join("engines.toml");
    std::fs::write(
        &engines,
        format!("[engine.mine]\ncommand = [{}]\n{extra}", quoted.join(", ")),
    )
    .unwrap();
    let sc = std::fs::read_to_string(root().join("scenarios/outside-pure-python-heun.toml"))
        .unwrap()
        .replace("\"pure_python_heun\"", "\"mine\"");
    let file = dir.join("mine.toml");
    std::fs::write(&file, sc).unwrap();
    pushval()
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(dir.join("out"))
        .arg("--engines")
        .arg(&engines)
        .output()
        .unwrap()
}

fn gone(pid: u32) -> bool {
    let until = Instant::now() + Duration::from_secs(3);
    while Instant::now() < until {
        // A zombie is gone too (its parent, not pushval, reaps it).
        let state = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
        let state = state.rsplit(')').next().unwrap_or("").trim_start();
        if state.is_empty() || state.starts_with('Z') {
            return true;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    false
}

fn read_pid(file: &PathBuf) -> u32 {
    let until = Instant::now() + Duration::from_secs(3);
    loop {
        if let Ok(t) = std::fs::read_to_string(file) {
            if let Ok(p) = t.trim().parse() {
                return p;
            }
        }
        assert!(Instant::now() < until, "no pid in {}", file.display());
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn an_answer_closed_with_another_requests_number_exits_2_naming_the_engine() {
    let dir = tempfile::tempdir().unwrap();
    let script = "import json, sys\nfor line in sys.stdin:\n    n = json.loads(line)['request']\n    print('#ok', n + 1, flush=True)\n";
    let o = run(dir.path(), &["python3", "-c", script], "session = true\n");
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("outside engine \"mine\"")
            && t.contains("closed its answer with request number 2 (`#ok 2`) while request 1 (start) was asked"),
        "{t}"
    );
    assert!(!dir.path().join("out").exists(), "nothing written");
}

#[test]
fn a_row_of_1e300_between_two_samples_exits_2_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    // pure_python.py's rows, with the x of the row at line 5 (t = 0.003 s,
    // between the samples at 0 and 0.01 s) replaced by 1e300.
    let filter = "import sys\nfor i, l in enumerate(sys.stdin, 1):\n    f = l.split(',')\n    if i == 5: f[1] = '1e300'\n    sys.stdout.write(','.join(f))\n";
    let script = format!(
        "python3 '{}' --scheme heun | python3 -c \"{filter}\"",
        adapter("pure_python.py")
    );
    let o = run(dir.path(), &["sh", "-c", &script], "order = 2\n");
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("outside engine \"mine\"")
            && t.contains("line 5: the centre of mass jumps 1.0")
            && t.contains("more than the push allows"),
        "{t}"
    );
}

/// A protocol 1 adapter (it reads its document to the end of its standard
/// input) declared with `session = true` never answers: pushval says why
/// after 5 s instead of waiting silently for its timeout.
#[test]
fn a_protocol_1_adapter_under_session_true_is_named_as_the_likely_cause() {
    let dir = tempfile::tempdir().unwrap();
    let start = Instant::now();
    let o = run(
        dir.path(),
        &["python3", &adapter("plain_protocol1.py")],
        "session = true\ntimeout_s = 8\n",
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("warning: outside engine \"mine\"")
            && stderr.contains("has not answered request 1 (start), its first document, after 5 s")
            && stderr.contains("most likely a protocol 1 adapter"),
        "{t}"
    );
    assert!(
        t.contains("within its timeout of 8 s")
            && t.contains("declare [engine.mine] session = false"),
        "{t}"
    );
    assert!(start.elapsed() < Duration::from_secs(60));
}

/// A child that calls setsid() and execs with an empty environment, in the
/// background, outlives its adapter (re-parented to pushval): it is ended
/// when pushval exits.
#[test]
fn a_setsid_child_with_an_empty_environment_does_not_outlive_pushval() {
    let dir = tempfile::tempdir().unwrap();
    let pid_file = dir.path().join("escaped");
    let escape = "import os; os.setsid(); os.execve('/bin/sleep', ['sleep', '300'], {})";
    let script = format!(
        "python3 -c \"{escape}\" </dev/null >/dev/null 2>&1 & echo $! > '{}'; exec python3 '{}' --scheme heun",
        pid_file.display(),
        adapter("pure_python.py")
    );
    let o = run(dir.path(), &["sh", "-c", &script], "order = 2\n");
    let t = text(&o);
    let escaped = read_pid(&pid_file);
    assert!(o.status.code().is_some(), "{t}");
    assert!(
        gone(escaped),
        "the setsid() sleep {escaped} (empty environment) outlived pushval: {t}"
    );
}
