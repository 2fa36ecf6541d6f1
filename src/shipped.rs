//! What pushval ships inside its binary: the scenarios, the study files and
//! the protocol's JSON schemas, embedded at build time (`build.rs`), so that
//! an installed `pushval` works in any folder without its source tree.
//!
//! Where a command looks for them (docs/architecture.md, "Anywhere"):
//! - scenarios: the project's `scenarios/` (beside the `pushval.toml` in use,
//!   else `./scenarios`), else the shipped ones;
//! - study files: `--studies DIR`, else `./studies`, else the shipped ones;
//! - `pushval shipped --out DIR` writes them all out, to read or edit.

use std::path::{Path, PathBuf};

use anyhow::Context;

include!(concat!(env!("OUT_DIR"), "/shipped.rs"));

/// The label that stands for a shipped file's path in messages and reports:
/// `shipped:scenarios/NAME`.
pub fn label(folder: &str, name: &str) -> PathBuf {
    PathBuf::from(format!("shipped:{folder}/{name}"))
}

/// The text of the shipped scenario `name` (a file name such as
/// `paper-square-v1.0.toml`).
pub fn scenario_text(name: &str) -> Option<&'static str> {
    SCENARIOS.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// The text of the shipped study file of `model` (`studies/MODEL.toml`).
pub fn study_text(model: &str) -> Option<&'static str> {
    let file = format!("{model}.toml");
    STUDIES.iter().find(|(n, _)| *n == file).map(|(_, t)| *t)
}

/// The shipped scenario `name`, parsed and checked against the registry.
pub fn scenario(name: &str) -> anyhow::Result<pushval_scenario::Scenario> {
    let text = scenario_text(name).with_context(|| format!("no shipped scenario `{name}`"))?;
    Ok(crate::registry::from_toml(text, &label("scenarios", name))?)
}

/// Writes every shipped file under `dir` (`scenarios/`, `studies/`,
/// `schemas/`), refusing to overwrite an existing file unless `force`; each
/// file is written atomically. Returns the files written.
pub fn write_out(dir: &Path, force: bool) -> anyhow::Result<Vec<PathBuf>> {
    let sets: [(&str, &[(&str, &str)]); 3] = [
        ("scenarios", SCENARIOS),
        ("studies", STUDIES),
        ("schemas", SCHEMAS),
    ];
    let files: Vec<(PathBuf, &str)> = sets
        .iter()
        .flat_map(|(folder, rows)| {
            rows.iter()
                .map(move |(name, text)| (dir.join(folder).join(name), *text))
        })
        .collect();
    if !force {
        if let Some((p, _)) = files.iter().find(|(p, _)| p.exists()) {
            anyhow::bail!("{}: already exists; pass --force to overwrite", p.display());
        }
    }
    for (p, text) in &files {
        let parent = p.parent().expect("under dir");
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
        crate::atomic::write_atomic(p, text.as_bytes())?;
    }
    Ok(files.into_iter().map(|(p, _)| p).collect())
}

/// A folder holding the shipped files of `folder` (`"scenarios"` or
/// `"studies"`), for commands that read them by path: written once per
/// content under the system's temporary folder
/// (`pushval-VERSION-HASH/FOLDER`), each file atomically, and reused.
pub fn materialized(folder: &str) -> anyhow::Result<PathBuf> {
    use std::hash::{Hash, Hasher};
    let rows = match folder {
        "scenarios" => SCENARIOS,
        "studies" => STUDIES,
        _ => anyhow::bail!("nothing shipped under `{folder}`"),
    };
    // A content hash in the name: a newer binary never reads older files.
    let mut h = std::collections::hash_map::DefaultHasher::new();
    rows.hash(&mut h);
    let dir = std::env::temp_dir()
        .join(format!(
            "pushval-{}-{:016x}",
            env!("CARGO_PKG_VERSION"),
            h.finish()
        ))
        .join(folder);
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    for (name, text) in rows {
        let p = dir.join(name);
        if std::fs::read_to_string(&p).ok().as_deref() != Some(*text) {
            crate::atomic::write_atomic(&p, text.as_bytes())?;
        }
    }
    Ok(dir)
}
