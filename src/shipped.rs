//! What pushval ships inside its binary: the scenarios, the study files and
//! the protocol's JSON schemas, embedded at build time (`build.rs`), so that
//! an installed `pushval` works in any folder without its source tree.
//!
//! Where a command looks for them (docs/architecture.md, "Anywhere"):
//! - scenarios: the project's `scenarios/` (beside the `pushval.toml` in use,
//!   else `./scenarios`), else the shipped ones;
//! - study files: `--studies DIR`, else `./studies`, else the shipped ones;
//! - `pushval shipped --out DIR` writes them all out, to read or edit;
//! - a command that needs them as files reads them from the user's cache
//!   folder ([`materialized`]), never from the shared temporary folder.

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

/// The user's cache folder for pushval: `$XDG_CACHE_HOME/pushval` (an
/// absolute path only, as the XDG spec asks), else `$HOME/.cache/pushval`.
pub fn cache_root() -> anyhow::Result<PathBuf> {
    let xdg = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute());
    let base = match xdg {
        Some(p) => p,
        None => std::env::var_os("HOME")
            .map(PathBuf::from)
            .filter(|p| p.is_absolute())
            .map(|h| h.join(".cache"))
            .context("no cache folder: neither XDG_CACHE_HOME nor HOME is an absolute path")?,
    };
    Ok(base.join("pushval"))
}

/// Creates `dir` owner-only (0700) if it is missing, then checks it as it
/// is: a real folder (not a symlink), owned by this user, with no access
/// for group or others. A folder someone else made or widened is refused,
/// never used or repaired.
fn private_dir(dir: &Path) -> anyhow::Result<()> {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    match std::fs::DirBuilder::new().mode(0o700).create(dir) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
        Err(e) => return Err(e).with_context(|| format!("creating {}", dir.display())),
    }
    let m = std::fs::symlink_metadata(dir).with_context(|| format!("reading {}", dir.display()))?;
    let uid = rustix::process::geteuid().as_raw();
    if m.file_type().is_symlink() || !m.is_dir() {
        anyhow::bail!("{}: not a folder (a symlink or a file); pushval keeps its shipped files only in a folder of its own", dir.display());
    }
    if m.uid() != uid {
        anyhow::bail!("{}: owned by user {}, not by this user ({uid}); pushval will not read shipped files from it", dir.display(), m.uid());
    }
    let mode = m.permissions().mode() & 0o777;
    if mode & 0o077 != 0 {
        anyhow::bail!(
            "{}: mode {mode:03o} lets others in; pushval needs it owner-only (chmod 700)",
            dir.display()
        );
    }
    Ok(())
}

/// A folder holding the shipped files of `folder` (`"scenarios"` or
/// `"studies"`), for commands that read them by path: written once per
/// content under the user's cache folder ([`cache_root`]`/VERSION-HASH/FOLDER`),
/// every level owner-only and checked before use, each file atomically and
/// compared with the binary's text before it is trusted. Nothing goes to
/// the system's shared temporary folder.
pub fn materialized(folder: &str) -> anyhow::Result<PathBuf> {
    // Callers fall back to a local folder on an error: say it here, once.
    materialize(folder).inspect_err(|e| {
        eprintln!("pushval: the shipped {folder} are not used: {e:#}");
    })
}

fn materialize(folder: &str) -> anyhow::Result<PathBuf> {
    use std::hash::{Hash, Hasher};
    let rows = match folder {
        "scenarios" => SCENARIOS,
        "studies" => STUDIES,
        _ => anyhow::bail!("nothing shipped under `{folder}`"),
    };
    // A content hash in the name: a newer binary never reads older files.
    let mut h = std::collections::hash_map::DefaultHasher::new();
    rows.hash(&mut h);
    let root = cache_root()?;
    if let Some(parent) = root.parent() {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    let version = root.join(format!("{}-{:016x}", env!("CARGO_PKG_VERSION"), h.finish()));
    let dir = version.join(folder);
    for d in [&root, &version, &dir] {
        private_dir(d)?;
    }
    for (name, text) in rows {
        let p = dir.join(name);
        // A symlink is replaced, never followed: rename swaps the link itself.
        let same = std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file())
            && std::fs::read_to_string(&p).ok().as_deref() == Some(*text);
        if !same {
            crate::atomic::write_atomic(&p, text.as_bytes())?;
        }
    }
    Ok(dir)
}
