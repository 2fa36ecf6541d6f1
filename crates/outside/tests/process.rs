//! One-shot runs: the output cap (a flooding adapter is stopped, the error
//! names the cap, memory stays bounded), every process an adapter started
//! ended at a timeout and at its exit (`setsid()` or not), and the document
//! each protocol version receives.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

mod common;

use pushval_engine::{Engine, EngineOptions};
use pushval_model::Problem;
use pushval_outside::{problem_document, problem_document_v2, Config, Limits, OutsideEngine, Spec};
use pushval_scenario::Scenario;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn engine(dir: &Path, command: &[&str], extra: &str) -> (Arc<Spec>, Problem, EngineOptions) {
    let quoted: Vec<String> = command.iter().map(|a| format!("{a:?}")).collect();
    let text = format!("[engine.probe]\ncommand = [{}]\n{extra}", quoted.join(", "));
    let cfg = Config::from_toml(&text, &dir.join("pushval.toml")).unwrap();
    let sc = Scenario::from_path(root().join("scenarios/paper-square-v1.0.toml")).unwrap();
    (
        Arc::new(cfg.engines.into_iter().next().unwrap()),
        sc.problem(),
        common::options(&sc),
    )
}

/// The peak resident memory of this process (kB).
fn peak_kb() -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap();
    s.lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap()
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

/// `yes` writes rows (or one endless line) far faster than any cap: the
/// run ends fast with an error naming the cap, and this process's peak
/// memory grows by no more than the cap (without it, the 20 s timeout would
/// let gigabytes in).
#[test]
fn a_flooding_adapter_is_stopped_at_its_cap() {
    let dir = tempfile::tempdir().unwrap();
    for (script, cap) in [
        (
            "cat >/dev/null; echo t,x,y,theta,omega; yes 0,0,0,0,0",
            "rows",
        ),
        ("cat >/dev/null; yes 0 | tr -d '\\n'", "bytes"),
    ] {
        let (spec, p, options) = engine(dir.path(), &["sh", "-c", script], "timeout_s = 20\n");
        let limits = Limits::for_problem(&p, 1e-3);
        let before = peak_kb();
        let start = Instant::now();
        let e = OutsideEngine::new(spec, &options)
            .run(&p, 1e-3)
            .unwrap_err()
            .to_string();
        let took = start.elapsed();
        let grew_kb = peak_kb().saturating_sub(before);
        let n = if cap == "rows" {
            limits.max_rows
        } else {
            limits.max_bytes
        };
        assert!(
            e.contains(&format!("wrote more than {n} {cap}")) && e.contains(&format!("max_{cap}")),
            "{e}"
        );
        assert!(took < Duration::from_secs(10), "{cap}: {took:?}");
        // The buffer holds at most the cap and a chunk; the rest is slack
        // for the allocator and the threads.
        let bound_kb = limits.max_bytes / 1024 * 2 + 64 * 1024;
        assert!(
            grew_kb < bound_kb,
            "{cap}: peak memory grew {grew_kb} kB (cap {} kB)",
            limits.max_bytes / 1024
        );
    }
}

/// The adapter starts `sleep` in a session of its own (so the process
/// group kill misses it), once with its environment cleared, then hangs:
/// at the timeout neither survives.
#[test]
fn a_timeout_ends_every_descendant_setsid_or_not() {
    let dir = tempfile::tempdir().unwrap();
    let f1 = dir.path().join("a");
    let f2 = dir.path().join("b");
    let script = format!(
        "import subprocess, sys, time\n\
         sys.stdin.read()\n\
         a = subprocess.Popen(['sleep', '1000'], start_new_session=True)\n\
         b = subprocess.Popen(['/bin/sleep', '1000'], start_new_session=True, env={{}})\n\
         open({:?}, 'w').write(str(a.pid))\n\
         open({:?}, 'w').write(str(b.pid))\n\
         time.sleep(1000)\n",
        f1.display().to_string(),
        f2.display().to_string()
    );
    let (spec, p, options) = engine(dir.path(), &["python3", "-c", &script], "timeout_s = 2\n");
    let e = OutsideEngine::new(spec, &options)
        .run(&p, 1e-3)
        .unwrap_err()
        .to_string();
    assert!(e.contains("timeout of 2 s: killed"), "{e}");
    for f in [&f1, &f2] {
        let pid: u32 = std::fs::read_to_string(f).unwrap().parse().unwrap();
        assert!(gone(pid), "{} survived the timeout", pid);
    }
}

/// The escape the process group, the mark and the parent links all miss
/// (issue 40): a child that calls setsid() and execs with an empty
/// environment, whose parent (a shell in the background) has exited, so
/// it is re-parented to this process (a child subreaper). At the adapter's
/// timeout it is ended too.
#[test]
fn a_timeout_ends_an_orphan_with_an_empty_environment() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("orphan");
    let escape = "import os; os.setsid(); os.execve('/bin/sleep', ['sleep', '300'], {})";
    let script = format!(
        "(python3 -c \"{escape}\" </dev/null >/dev/null 2>&1 & echo $! > '{}'); sleep 1000",
        f.display()
    );
    let (spec, p, options) = engine(dir.path(), &["sh", "-c", &script], "timeout_s = 2\n");
    let e = OutsideEngine::new(spec, &options)
        .run(&p, 1e-3)
        .unwrap_err()
        .to_string();
    assert!(e.contains("timeout of 2 s: killed"), "{e}");
    let pid: u32 = std::fs::read_to_string(&f).unwrap().trim().parse().unwrap();
    assert!(gone(pid), "the orphan {pid} survived the timeout");
}

/// An adapter that answers and exits 0 but leaves a daemon behind (double
/// fork and setsid: re-parented away from the adapter): the daemon ends
/// with the run.
#[test]
fn a_daemon_left_behind_ends_with_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("daemon");
    let script = format!(
        "import os, subprocess, sys\n\
         doc = sys.stdin.read()\n\
         subprocess.run(['sh', '-c', 'setsid sleep 1000 >/dev/null 2>&1 </dev/null & echo $! > {}'])\n\
         print('t,x,y,theta,omega')\n\
         print('0,0,0,0,0')\n\
         print('10,0,0,0,0')\n",
        f.display()
    );
    let (spec, p, options) = engine(dir.path(), &["python3", "-c", &script], "");
    OutsideEngine::new(spec, &options).run(&p, 1e-3).unwrap();
    let pid: u32 = std::fs::read_to_string(&f).unwrap().trim().parse().unwrap();
    assert!(gone(pid), "the daemon {pid} survived the run");
}

/// A version 1 engine receives exactly the version 1 document; one
/// declaring `protocol = 2` the version 2 one, with the switching rule and
/// the run's cap.
#[test]
fn each_engine_receives_its_protocol_version() {
    let dir = tempfile::tempdir().unwrap();
    let got = dir.path().join("doc.json");
    let script = format!(
        "import sys; open({:?}, 'wb').write(sys.stdin.buffer.read()); sys.exit(5)",
        got.display().to_string()
    );
    let (v1, p, options) = engine(dir.path(), &["python3", "-c", &script], "");
    assert_eq!((v1.protocol, v1.session), (1, false));
    let e = OutsideEngine::new(v1, &options).run(&p, 2e-3).unwrap_err();
    assert!(e.to_string().contains("exited with status 5"), "{e}");
    let expected = serde_json::to_vec(&problem_document("probe", &p, &options, 2e-3)).unwrap();
    assert_eq!(std::fs::read(&got).unwrap(), expected);

    let (v2, _, _) = engine(dir.path(), &["python3", "-c", &script], "protocol = 2\n");
    assert_eq!((v2.protocol, v2.session), (2, false));
    OutsideEngine::new(v2, &options).run(&p, 2e-3).unwrap_err();
    let limits = Limits::for_problem(&p, 2e-3);
    let sent = problem_document_v2("probe", &p, &options, 2e-3, limits);
    assert_eq!(
        std::fs::read(&got).unwrap(),
        serde_json::to_vec(&sent).unwrap()
    );
    let doc = sent;
    assert_eq!(doc["format"], "pushval-problem/2");
    // paper-square-v1.0.toml: switching = "impulsive".
    assert_eq!(doc["switching"], "impulsive");
    // 10 s at 2 ms: 5001 rows expected, the cap 4 × that + 1000 + 5 pushes.
    let rows = 4 * 5001 + 1000 + p.pushes.len() as u64;
    assert_eq!(doc["limits"]["max_rows"], rows);
    assert_eq!(doc["limits"]["max_bytes"], rows * 512 + 4096);
    let mut v1_part = doc.clone();
    let o = v1_part.as_object_mut().unwrap();
    o.remove("switching");
    o.remove("limits");
    o.insert("format".into(), "pushval-problem/1".into());
    assert_eq!(v1_part, problem_document("probe", &p, &options, 2e-3));
}

#[test]
fn protocol_and_session_keys_are_checked() {
    let file = Path::new("/proj/pushval.toml");
    for (extra, key, what) in [
        ("protocol = 4\n", "engine.a.protocol", "must be 1"),
        (
            "protocol = 3\n",
            "engine.a.protocol",
            "runs in a session: set session = true",
        ),
        ("session = \"yes\"\n", "engine.a.session", "true or false"),
        (
            "session = true\nprotocol = 1\n",
            "engine.a.protocol",
            "needs protocol 2 or 3",
        ),
        (
            "session = true\nrows = \"all\"\n",
            "engine.a.rows",
            "\"samples\" or \"steps\"",
        ),
    ] {
        let e = Config::from_toml(&format!("[engine.a]\ncommand = [\"x\"]\n{extra}"), file)
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("{key}:")) && e.contains(what), "{e}");
    }
}
