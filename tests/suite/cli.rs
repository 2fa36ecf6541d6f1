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
