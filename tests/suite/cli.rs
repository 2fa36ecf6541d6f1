//! The command line's contract: exit codes and files written.

use std::process::Command;

use crate::common::root;

fn pushval() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pushval"))
}

#[test]
fn run_writes_summary_and_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let st = pushval()
        .args(["run"])
        .arg(root().join("scenarios/paper-square-v0.2.toml"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["scenario"], "paper-square-v0.2");
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert!(csv.starts_with("model,t,x,y,theta,omega\n"));
    // Only the two outputs, no temporary files left behind.
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 2);
}

#[test]
fn bad_file_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[object]\nmass = -1\n").unwrap();
    let out = dir.path().join("out");
    let st = pushval()
        .arg("run")
        .arg(&bad)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(2));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(err.contains("bad.toml"), "{err}");
    assert!(!out.exists(), "nothing may be written for a bad scenario");
    let st = pushval().arg("validate").arg(&bad).output().unwrap();
    assert_eq!(st.status.code(), Some(2));
}

#[test]
fn validate_passes_on_the_shipped_scenarios() {
    let st = pushval()
        .arg("validate")
        .current_dir(root())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&st.stdout);
    assert_eq!(
        st.status.code(),
        Some(0),
        "{text}\n{}",
        String::from_utf8_lossy(&st.stderr)
    );
    assert!(text.contains("paper-square-v1.0") && text.contains("kinematic"));
}

#[test]
fn failing_tolerance_exits_1_and_names_the_figure() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("scenarios/paper-square-v0.2.toml")).unwrap();
    let tight = dir.path().join("tight.toml");
    std::fs::write(
        &tight,
        format!("{text}\n[tolerance]\nposition_max = 1e-9\n"),
    )
    .unwrap();
    let st = pushval().arg("validate").arg(&tight).output().unwrap();
    assert_eq!(st.status.code(), Some(1));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("paper-square-v0.2 / rapier2d: position_max"),
        "{err}"
    );
}

/// `compare` gates an outside trajectory: the dynamic model's own samples,
/// renamed, pass; the kinematic model's samples fail with the figure named.
#[test]
fn compare_gates_an_outside_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let scen = root().join("scenarios/paper-square-v0.6.toml");
    let out = dir.path().join("run");
    assert!(pushval()
        .arg("run")
        .arg(&scen)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap()
        .status
        .success());
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let pick = |model: &str| {
        let mut s = String::from("model,t,x,y,theta,omega\n");
        for l in csv.lines().filter(|l| l.starts_with(&format!("{model},"))) {
            s.push_str(&l.replacen(model, "mine", 1));
            s.push('\n');
        }
        s
    };
    let good = dir.path().join("good.csv");
    std::fs::write(&good, pick("dynamic")).unwrap();
    let st = pushval()
        .arg("compare")
        .arg(&scen)
        .arg("--trajectory")
        .arg(&good)
        .output()
        .unwrap();
    assert_eq!(
        st.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&st.stdout)
    );
    assert!(
        !String::from_utf8_lossy(&st.stderr).contains("warning"),
        "the model's own start is the scenario's"
    );
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, pick("kinematic")).unwrap();
    let st = pushval()
        .arg("compare")
        .arg(&scen)
        .arg("--trajectory")
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(1));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(err.contains("mine vs dynamic: position_max"), "{err}");
    // Where it first fails: the kinematic model departs in the first segment.
    assert!(
        err.contains("(first at t = ") && err.contains(", segment 0)"),
        "{err}"
    );
    let broken = dir.path().join("broken.csv");
    std::fs::write(&broken, "model,t,x,y,theta,omega\nmine,0,0,0,zero,0\n").unwrap();
    let st = pushval()
        .arg("compare")
        .arg(&scen)
        .arg("--trajectory")
        .arg(&broken)
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&st.stderr).contains("line 2: column `theta`"));
}

/// `--junit` writes one testcase per scenario and model, failures named.
#[test]
fn junit_report_names_the_failing_figure() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("scenarios/paper-square-v0.2.toml")).unwrap();
    let tight = dir.path().join("tight.toml");
    std::fs::write(&tight, format!("{text}\n[tolerance]\ntheta_max = 1e-9\n")).unwrap();
    let xml = dir.path().join("report.xml");
    let st = pushval()
        .arg("validate")
        .arg(&tight)
        .arg("--junit")
        .arg(&xml)
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(1));
    let x = std::fs::read_to_string(&xml).unwrap();
    assert_eq!(x.matches("<testcase ").count(), 4, "{x}");
    assert_eq!(x.matches("<failure ").count(), 1);
    assert!(x.contains("name=\"rapier2d\"") && x.contains("theta_max"));
}

/// The commonest mistake: an outside run that starts at rest where the
/// scenario starts already sliding with the pusher. `compare` warns and
/// says what to check, and the failure says when and in which segment the
/// trajectory first leaves the tolerance.
#[test]
fn compare_warns_when_the_outside_run_starts_differently() {
    let dir = tempfile::tempdir().unwrap();
    let scen = root().join("scenarios/paper-square-v1.0.toml");
    let text = std::fs::read_to_string(&scen).unwrap();
    assert!(!text.contains("from_rest"));
    // The same scene started at rest (the pusher's impulse sets it moving).
    let at_rest = dir.path().join("at-rest.toml");
    std::fs::write(&at_rest, format!("{text}\n[initial]\nfrom_rest = true\n")).unwrap();
    let out = dir.path().join("run");
    let st = pushval()
        .args(["run"])
        .arg(&at_rest)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let mut mine = String::from("model,t,x,y,theta,omega\n");
    for l in csv.lines().filter(|l| l.starts_with("dynamic,")) {
        mine.push_str(&l.replacen("dynamic", "mine", 1));
        mine.push('\n');
    }
    let path = dir.path().join("mine.csv");
    std::fs::write(&path, mine).unwrap();
    let st = pushval()
        .arg("compare")
        .arg(&scen)
        .arg("--trajectory")
        .arg(&path)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("warning:") && err.contains("does not start as the scenario does"),
        "{err}"
    );
    assert!(err.contains("from_rest = false"), "{err}");
}

/// Outputs are readable by the group: a written file gets the mode a newly
/// created file gets under the user's umask, `0o666 & !umask` (POSIX
/// `open(O_CREAT)` semantics), not the 0600 of a private temporary file,
/// and still nothing but the outputs is left in the folder. Two umasks, so
/// the mode follows the umask rather than being a fixed 0644.
#[cfg(unix)]
#[test]
fn outputs_get_the_umask_mode() {
    use std::os::unix::fs::PermissionsExt;
    for (umask, mode) in [("022", 0o644), ("027", 0o640)] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let st = Command::new("sh")
            .arg("-c")
            .arg(format!("umask {umask}; exec \"$0\" \"$@\""))
            .arg(env!("CARGO_BIN_EXE_pushval"))
            .arg("run")
            .arg(root().join("scenarios/paper-square-v0.2.toml"))
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{}",
            String::from_utf8_lossy(&st.stderr)
        );
        for name in ["summary.json", "trajectory.csv"] {
            let m = std::fs::metadata(out.join(name))
                .unwrap()
                .permissions()
                .mode()
                & 0o777;
            assert_eq!(m, mode, "{name} under umask {umask}: mode {m:o}");
        }
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 2);
    }
}

/// A standard output nobody reads any more: the writing end of a pipe
/// whose reading end is closed (a `true` that has exited held it), so the
/// first write fails however fast pushval is.
fn closed_stdout() -> std::process::Stdio {
    let mut reader = Command::new("true")
        .stdin(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let pipe = reader.stdin.take().unwrap();
    reader.wait().unwrap();
    pipe.into()
}

/// `pushval engines | head -1`: every command that prints ends quietly
/// when its reader goes away, with the status a shell shows for a program
/// SIGPIPE ended (141), never a panic (101).
#[test]
fn a_closed_standard_output_ends_pushval_quietly() {
    let scenario = root().join("scenarios/paper-square-v1.0.toml");
    let scenario = scenario.to_str().unwrap();
    let commands: &[&[&str]] = &[
        &["engines"],
        &["laws"],
        &["laws", "--json"],
        &["problem", scenario],
        &["validate", scenario],
        &["--help"],
        &["run", "--help"],
        &["--version"],
    ];
    for args in commands {
        let o = pushval()
            .args(*args)
            .stdout(closed_stdout())
            .stderr(std::process::Stdio::piped())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(141), "pushval {args:?}: {err}");
        assert!(err.is_empty(), "pushval {args:?} said: {err}");
    }
}
