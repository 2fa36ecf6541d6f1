//! `results/MANIFEST.csv` (issue 34, item 7: one command per results file):
//! every file of `results/` is matched by exactly one rule of
//! `src/manifest.rs`, every row names a file that exists, the committed
//! manifest is what the rules give, and each generated Markdown file names
//! the manifest's command. The matcher itself is checked on a synthetic
//! tree with a file no rule matches and a file two rules match.

use std::path::Path;
use std::process::Command;

use pushval::manifest::{self, Row, Rule};

use crate::common::{root, use_repo_engines};

fn put(dir: &Path, rel: &str) {
    let p = dir.join(rel);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(p, "x\n").unwrap();
}

const SYNTHETIC: &[Rule] = &[
    Rule {
        command: "pushval report",
        source: "",
        files: &["results/kappa.csv", "results/path_v*.csv"],
    },
    Rule {
        command: "pushval study {model}",
        source: "",
        files: &[
            "results/friction_models/{model}/map.csv",
            "results/friction_models/{model}/sweep_*.csv",
        ],
    },
    Rule {
        command: "cargo bench --bench sweeps",
        source: "",
        files: &["results/friction_models/*/sweep_speed.csv"],
    },
    Rule {
        command: "pushval manifest",
        source: "",
        files: &[manifest::MANIFEST],
    },
];

fn synthetic_tree() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for f in [
        "results/kappa.csv",
        "results/path_v0.2.csv",
        "results/friction_models/m1/map.csv",
        "results/friction_models/m1/sweep_stop.csv",
        // Two rules: the study's sweep_* and the bench's sweep_speed.
        "results/friction_models/m1/sweep_speed.csv",
        // No rule: an old file, and a folder that names no model.
        "results/kappa_old.csv",
        "results/friction_models/other/map.csv",
        // Not walked: an interrupted write, shard parts.
        "results/.tmpAbc123",
        "results/parts/sweep-1-of-2.csv",
        // Known leftover.
        "results/old.csv",
    ] {
        put(dir.path(), f);
    }
    dir
}

#[test]
fn matcher_finds_unmatched_and_doubly_matched_files() {
    let dir = synthetic_tree();
    let models = vec!["m1".to_string()];
    let stale = [("results/old.csv", "why"), ("results/gone.csv", "why")];
    let w = manifest::walk(dir.path(), SYNTHETIC, &stale, &models).unwrap();
    assert_eq!(
        w.unmatched,
        [
            "results/friction_models/other/map.csv",
            "results/kappa_old.csv"
        ]
    );
    assert_eq!(w.ambiguous.len(), 1, "{:?}", w.ambiguous);
    assert_eq!(
        w.ambiguous[0].0,
        "results/friction_models/m1/sweep_speed.csv"
    );
    assert_eq!(
        w.ambiguous[0].1,
        ["pushval study m1", "cargo bench --bench sweeps"]
    );
    assert_eq!(w.stale.len(), 1);
    assert_eq!(w.stale[0].0, "results/old.csv");
    assert_eq!(w.stale_errors.len(), 1, "{:?}", w.stale_errors);
    assert!(w.stale_errors[0].contains("results/gone.csv"));
    // The manifest lists itself even before it is written.
    let paths: Vec<&str> = w.rows.iter().map(|r| r.path.as_str()).collect();
    assert_eq!(
        paths,
        [
            "results/MANIFEST.csv",
            "results/friction_models/m1/map.csv",
            "results/friction_models/m1/sweep_stop.csv",
            "results/kappa.csv",
            "results/path_v0.2.csv",
        ]
    );
    assert_eq!(w.rows[1].command, "pushval study m1");
    assert_eq!(w.errors().len(), 4, "{:?}", w.errors());
}

#[test]
fn differences_name_missing_files_and_changed_rows() {
    let dir = tempfile::tempdir().unwrap();
    for f in ["results/kappa.csv", "results/path_v0.2.csv"] {
        put(dir.path(), f);
    }
    let w = manifest::walk(dir.path(), SYNTHETIC, &[], &[]).unwrap();
    assert!(w.errors().is_empty(), "{:?}", w.errors());
    let text = manifest::csv(&w.rows);
    put(dir.path(), manifest::MANIFEST);
    let same = manifest::parse(&text, Path::new("m")).unwrap();
    assert!(manifest::differences(dir.path(), &w, &same).is_empty());

    let row = |p: &str, c: &str| Row {
        path: p.into(),
        command: c.into(),
    };
    let committed = vec![
        row("results/MANIFEST.csv", "pushval manifest"),
        row("results/kappa.csv", "pushval power"),
        row("results/tau.csv", "pushval report"),
    ];
    let d = manifest::differences(dir.path(), &w, &committed);
    let has = |s: &str| d.iter().any(|l| l.contains(s));
    assert!(has("results/tau.csv does not exist"), "{d:?}");
    assert!(
        has("`pushval power`, the rules say `pushval report`"),
        "{d:?}"
    );
    assert!(has("results/path_v0.2.csv: missing from"), "{d:?}");
    assert_eq!(d.len(), 3, "{d:?}");
}

#[test]
fn generated_markdown_must_name_the_manifest_command() {
    let dir = tempfile::tempdir().unwrap();
    let rules = [Rule {
        command: "pushval report",
        source: "",
        files: &["results/README.md"],
    }];
    std::fs::create_dir_all(dir.path().join("results")).unwrap();
    std::fs::write(
        dir.path().join("results/README.md"),
        "# r\n\nGenerated by `pushval study all`; do not edit by hand.\n",
    )
    .unwrap();
    let w = manifest::walk(dir.path(), &rules, &[], &[]).unwrap();
    let d = manifest::differences(dir.path(), &w, &w.rows);
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(d[0].contains("names its generator `pushval study all`"));
}

#[test]
fn commands_of_feature_models_run_their_build() {
    assert_eq!(
        manifest::command_for("pushval study {model}", Some("jolt_feet")),
        "cargo run --release --features jolt -- study jolt_feet"
    );
    assert_eq!(
        manifest::command_for("pushval study {model}", Some("rapier2d")),
        "pushval study rapier2d"
    );
    assert_eq!(
        manifest::pushval_form("cargo run --release --features jolt -- study jolt_feet"),
        "pushval study jolt_feet"
    );
    assert_eq!(
        manifest::pushval_form("cargo run --release --features mujoco --example creep_law"),
        "cargo run --release --features mujoco --example creep_law"
    );
}

/// A model behind a cargo feature is not in a build without it; every
/// other compiled-in model is (so the feature table matches Cargo.toml).
#[test]
fn feature_table_matches_the_build() {
    let enabled = |f: &str| match f {
        "mujoco" => cfg!(feature = "mujoco"),
        "physx" => cfg!(feature = "physx"),
        "avian" => cfg!(feature = "avian"),
        "jolt" => cfg!(feature = "jolt"),
        other => panic!("feature `{other}` is not in Cargo.toml's [features]"),
    };
    for row in pushval::registry::ENGINE_CRATES {
        for e in (row.models)() {
            let available = e.default_engine().availability().is_ok();
            let want = manifest::feature_of(e.name).is_none_or(enabled);
            assert_eq!(
                available,
                want,
                "{}: feature {:?}",
                e.name,
                manifest::feature_of(e.name)
            );
        }
    }
}

/// Each rule's source writes its files: every literal piece of a pattern's
/// file name occurs in the source (a renamed file fails here).
#[test]
fn rules_name_files_their_source_writes() {
    for r in manifest::RULES
        .iter()
        .filter(|r| r.command != manifest::BY_HAND)
    {
        let src = root().join(r.source);
        let mut text = String::new();
        let paths: Vec<std::path::PathBuf> = if src.is_dir() {
            std::fs::read_dir(&src)
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect()
        } else {
            vec![src.clone()]
        };
        for p in paths {
            text += &std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        }
        for pat in r.files {
            let name = pat.rsplit('/').next().unwrap();
            for piece in name.split('*').filter(|p| !p.is_empty()) {
                assert!(
                    text.contains(piece),
                    "{}: `{piece}` of {pat} does not occur in {}",
                    r.command,
                    r.source
                );
            }
        }
    }
}

/// The committed tree: one rule per file, the manifest as the rules say.
#[test]
fn committed_manifest_is_what_the_rules_give() {
    use_repo_engines();
    let w = manifest::walk(
        &root(),
        manifest::RULES,
        manifest::STALE,
        &manifest::models(),
    )
    .unwrap();
    let errors = w.errors();
    assert!(errors.is_empty(), "{}", errors.join("\n"));
    let path = root().join(manifest::MANIFEST);
    let text = std::fs::read_to_string(&path).expect("results/MANIFEST.csv (pushval manifest)");
    let committed = manifest::parse(&text, &path).unwrap();
    let d = manifest::differences(&root(), &w, &committed);
    assert!(
        d.is_empty(),
        "{}\n(`cargo run --release -- manifest` rewrites it)",
        d.join("\n")
    );
    assert_eq!(text, manifest::csv(&w.rows));
}

/// `pushval manifest --check` from the repository root: exit 0; in a tree
/// with a file no rule matches: exit 1, naming it.
#[test]
fn check_command_exit_codes() {
    let o = Command::new(env!("CARGO_BIN_EXE_pushval"))
        .args(["manifest", "--check"])
        .current_dir(root())
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );

    let dir = tempfile::tempdir().unwrap();
    put(dir.path(), "results/kappa.csv");
    put(dir.path(), "results/unknown.csv");
    std::fs::write(
        dir.path().join(manifest::MANIFEST),
        "path,command\nresults/MANIFEST.csv,pushval manifest\nresults/kappa.csv,pushval report\n",
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_pushval"))
        .args(["manifest", "--check", "--root"])
        .arg(dir.path())
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(out.contains("results/unknown.csv: no rule"), "{out}");
    // Writing refuses the same tree (exit 2, nothing written).
    let o = Command::new(env!("CARGO_BIN_EXE_pushval"))
        .args(["manifest", "--root"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("results/unknown.csv"));
}
