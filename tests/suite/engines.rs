//! Engines as plug-ins: the registry, `pushval engines`, and `[run] gate`
//! naming any engine.

use std::process::Command;

use crate::common::root;

fn pushval() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pushval"))
}

/// The version Cargo.lock locks for a crate (every engine crate is locked once).
fn locked_version(krate: &str) -> Option<String> {
    let lock = std::fs::read_to_string(root().join("Cargo.lock")).unwrap();
    let mut lines = lock.lines();
    while let Some(l) = lines.next() {
        if l == format!("name = \"{krate}\"") {
            let v = lines.next()?;
            return v
                .strip_prefix("version = \"")
                .and_then(|v| v.strip_suffix('"'))
                .map(String::from);
        }
    }
    None
}

/// The version each adapter reports is the one Cargo.lock builds: nobody
/// types an engine's version by hand where it can drift.
#[test]
fn every_engine_reports_the_version_cargo_locks() {
    let entries = pushval::registry::entries();
    assert!(entries.len() >= 9, "{} engine models", entries.len());
    for e in entries {
        let engine = e.default_engine();
        assert_eq!(
            engine.name(),
            e.name,
            "the row and the model agree on the name"
        );
        let c = engine.engine_crate();
        assert_eq!(
            locked_version(c.name).as_deref(),
            Some(c.version),
            "{}: {} is not locked at {}",
            e.name,
            c.name,
            c.version
        );
        assert!(
            engine.order() >= 1.0,
            "{}: order {}",
            e.name,
            engine.order()
        );
        assert!(engine.default_dt() > 0.0);
        let settings = engine.settings(1e-3);
        assert_eq!(
            settings["dt"], 1e-3,
            "{}: settings carry the run's dt",
            e.name
        );
        assert!(settings["engine"].as_str().unwrap().contains(c.version));
    }
}

/// Names are unique and never shadow an analytic model.
#[test]
fn registry_names_are_unique() {
    let names = pushval::registry::known_models();
    for (i, a) in names.iter().enumerate() {
        assert!(!names[i + 1..].contains(a), "{a} listed twice");
    }
}

#[test]
fn engines_lists_one_row_per_engine_model() {
    let st = pushval().arg("engines").output().unwrap();
    assert!(st.status.success());
    let out = String::from_utf8(st.stdout).unwrap();
    for e in pushval::registry::entries() {
        let engine = e.default_engine();
        let row = out
            .lines()
            .find(|l| l.split_whitespace().next() == Some(e.name.as_str()))
            .unwrap_or_else(|| panic!("no row for {}:\n{out}", e.name));
        assert!(row.contains(engine.adapter()), "{row}");
        assert!(row.contains(&engine.version()), "{row}");
        match engine.availability() {
            Ok(()) => assert!(row.trim_end().ends_with("yes"), "{row}"),
            Err(why) => assert!(row.contains(&why), "{row}"),
        }
    }
}

/// Writes the paper scenario with extra `[run]` lines into a temp folder.
fn paper_with_run(dir: &std::path::Path, extra: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(root().join("scenarios/paper-square-v1.0.toml")).unwrap();
    assert!(text.contains("\n[run]\n"));
    let path = dir.join("gated.toml");
    std::fs::write(
        &path,
        text.replace("\n[run]\n", &format!("\n[run]\n{extra}\n")),
    )
    .unwrap();
    path
}

/// rapier3d's own contact friction turns the plate faster than Coulomb
/// support friction: gating it must fail, and say which engine failed.
#[test]
fn gating_rapier3d_on_the_paper_scene_fails_and_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = paper_with_run(dir.path(), "gate = [\"rapier2d\", \"rapier3d\"]");
    let st = pushval().arg("validate").arg(&path).output().unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(st.status.code(), Some(1), "{err}");
    assert!(
        err.contains("/ rapier3d: omega_steady_rel_max")
            || err.contains("/ rapier3d: position_max"),
        "{err}"
    );
    assert!(!err.contains("/ rapier2d:"), "rapier2d still passes: {err}");
}

#[test]
fn an_unknown_gate_exits_2_naming_run_gate() {
    let dir = tempfile::tempdir().unwrap();
    let path = paper_with_run(dir.path(), "gate = [\"bullet\"]");
    let st = pushval().arg("validate").arg(&path).output().unwrap();
    assert_eq!(st.status.code(), Some(2));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("run.gate[0]") && err.contains("bullet"),
        "{err}"
    );
}

/// A gated engine this build lacks is an error naming the feature, never a
/// silently skipped gate.
#[test]
fn a_gated_engine_missing_from_the_build_exits_2_naming_the_feature() {
    let missing = pushval::registry::entries()
        .into_iter()
        .find(|e| e.default_engine().availability().is_err());
    let Some(e) = missing else {
        // Every engine is in this build (e.g. --features mujoco): nothing to refuse.
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let path = paper_with_run(dir.path(), &format!("gate = [\"{}\"]", e.name));
    let st = pushval().arg("validate").arg(&path).output().unwrap();
    assert_eq!(st.status.code(), Some(2));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("run.gate[0]") && err.contains("--features"),
        "{err}"
    );
}

/// Without `gate`, the default engine is gated where the scenario runs it;
/// an explicit gate runs its engine even when `models` does not list it.
#[test]
fn gate_defaults_and_explicit_gates() {
    let sc = crate::common::load(&root().join("scenarios/paper-square-v0.2.toml"));
    assert_eq!(sc.gate, vec!["rapier2d".to_string()]);
    let dir = tempfile::tempdir().unwrap();
    let path = paper_with_run(dir.path(), "gate = [\"rapier2d_regularised_linear\"]");
    let sc = pushval::registry::load(&path).unwrap();
    assert!(sc.models.iter().any(|m| m == "rapier2d_regularised_linear"));
    let r = pushval::run_scenario(&sc, &pushval::RunOptions::default()).unwrap();
    let gated: Vec<_> = r
        .comparisons
        .iter()
        .filter(|c| c.pass.is_some())
        .map(|c| c.model.as_str())
        .collect();
    assert_eq!(gated, ["rapier2d_regularised_linear"]);
    // Coulomb regularised below 0.01 m/s is Coulomb on this scene (every
    // support slides faster), so the gate passes at its chosen step, and the
    // convergence check ran through the trait.
    let c = r
        .comparisons
        .iter()
        .find(|c| c.model == "rapier2d_regularised_linear")
        .unwrap();
    assert_eq!(c.pass, Some(true), "{:?}", c.failed);
    assert!(c.convergence.is_some());
}
