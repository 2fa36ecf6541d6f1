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

/// The commands whose arguments this file checks (plan, loop and
/// control-study take theirs from the control module, checked with it).
const COMMANDS: &[&str] = &[
    "validate",
    "compare",
    "stress",
    "report",
    "study",
    "engines",
    "laws",
    "fit",
    "fit-study",
    "track",
    "track-study",
    "power",
    "problem",
    "init",
    "shipped",
    "manifest",
    "run",
];

/// The entries of a help's `Arguments:` and `Options:` sections: the
/// argument as written (`--dt <H>`, `<FILE>`) and its description (a long
/// description continues on lines indented past the argument).
fn help_entries(help: &str) -> Vec<(String, String)> {
    let mut entries: Vec<(String, String)> = Vec::new();
    let mut in_section = false;
    for line in help.lines() {
        if line == "Arguments:" || line == "Options:" {
            in_section = true;
            continue;
        }
        if !line.starts_with(' ') {
            in_section = false;
            continue;
        }
        if !in_section {
            continue;
        }
        let body = line.trim_start();
        let indent = line.len() - body.len();
        if indent <= 6 && (body.starts_with('-') || body.starts_with('<') || body.starts_with('['))
        {
            let (arg, about) = match body.find("  ") {
                Some(i) => (&body[..i], body[i..].trim()),
                None => (body, ""),
            };
            entries.push((arg.trim().to_string(), about.to_string()));
        } else if let Some(last) = entries.last_mut() {
            last.1.push(' ');
            last.1.push_str(body);
        }
    }
    entries
}

/// Every help says what each argument is, and every optional value gives
/// its default (`[default: …]`, or the word "default" in its description):
/// the arguments a command cannot run without are the only ones without.
#[test]
fn every_help_describes_each_argument_and_its_default() {
    for command in COMMANDS {
        let o = pushval().args([command, "--help"]).output().unwrap();
        assert!(o.status.success(), "{command}");
        let help = String::from_utf8(o.stdout).unwrap();
        let usage = help
            .lines()
            .find(|l| l.starts_with("Usage:"))
            .unwrap_or_else(|| panic!("{command}: no usage line: {help}"));
        let entries = help_entries(&help);
        assert!(!entries.is_empty(), "{command}: {help}");
        for (arg, about) in &entries {
            assert!(
                !about.is_empty(),
                "pushval {command}: `{arg}` is not described"
            );
            let takes_value = arg.contains('<') || arg.starts_with('[');
            // Required: written in the usage line as is, outside brackets.
            let flag = arg.split_whitespace().next().unwrap();
            let required = usage.contains(&format!(" {arg}"))
                || (arg.starts_with('<') && usage.contains(flag));
            if takes_value && !required && arg != "--engines <FILE>" {
                assert!(
                    about.to_lowercase().contains("default"),
                    "pushval {command}: optional `{arg}` gives no default: {about}"
                );
            }
        }
    }
    // --engines: its default is found as cargo finds Cargo.toml.
    let o = pushval().arg("--help").output().unwrap();
    let help = String::from_utf8(o.stdout).unwrap();
    let (_, engines) = help_entries(&help)
        .into_iter()
        .find(|(a, _)| a.starts_with("--engines"))
        .unwrap();
    assert!(
        engines.contains("current folder") && engines.contains("parent"),
        "{engines}"
    );
}

/// A negative number is a value wherever a number is taken, written any
/// way a number is (`-1`, `-1e-3`, `-.5`): it reaches the command, which
/// refuses it naming the option (exit 2), instead of being taken for an
/// unknown flag.
#[test]
fn negative_numbers_are_values_everywhere() {
    let scenario = root().join("scenarios/paper-square-v1.0.toml");
    for value in ["-1", "-1e-3", "-.5"] {
        let o = pushval()
            .arg("problem")
            .arg(&scenario)
            .args(["--dt", value])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--dt {value}: {err}");
        assert!(
            err.contains("--dt must be a finite number > 0"),
            "--dt {value}: {err}"
        );
        let dir = tempfile::tempdir().unwrap();
        let o = pushval()
            .arg("track")
            .arg(&scenario)
            .args(["--trajectory", "missing.csv", "--out"])
            .arg(dir.path().join("out"))
            .args(["--sigma-theta", value])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--sigma-theta {value}: {err}");
        assert!(
            err.contains("--sigma-theta: must be a finite number > 0"),
            "--sigma-theta {value}: {err}"
        );
    }
    // A whole number too: refused by its range, as a value.
    let o = pushval()
        .arg("problem")
        .arg(&scenario)
        .args(["--protocol", "-1"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("invalid value '-1' for '--protocol"), "{err}");
}
