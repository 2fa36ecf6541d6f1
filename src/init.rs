//! `pushval init`: a project in the current folder that gates the user's own
//! engine: `pushval.toml` declaring one Python engine, its adapter (written
//! with the adapter kit `pushval.adapter`: Coulomb forces per support, so the
//! gate passes before the user changes anything) and `scenarios/` with one
//! scenario gating it. `pushval` right after `init` runs that gate.
//!
//! The templates live in `assets/init/` and are embedded in the binary.
//! Where `python3` cannot import `pushval.adapter` (pushval installed with
//! cargo, not pip), the kit itself is written beside the adapter
//! (`pushval/adapter.py`), where Python finds it first.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

use anyhow::{bail, Context};

/// The project files: path under the folder, text.
const FILES: &[(&str, &str)] = &[
    ("pushval.toml", include_str!("../assets/init/pushval.toml")),
    ("adapter.py", include_str!("../assets/init/adapter.py")),
    (
        "scenarios/my_engine.toml",
        include_str!("../assets/init/scenarios/my_engine.toml"),
    ),
];

/// The adapter kit, written beside the adapter when Python lacks it.
const KIT: &[(&str, &str)] = &[
    (
        "pushval/__init__.py",
        include_str!("../python/pushval/__init__.py"),
    ),
    (
        "pushval/adapter.py",
        include_str!("../python/pushval/adapter.py"),
    ),
];

/// Whether `python3` (on PATH) can import the adapter kit from `dir`'s
/// point of view, without the files [`KIT`] would write.
fn python_has_kit(dir: &Path) -> bool {
    Command::new("python3")
        .args(["-c", "import pushval.adapter"])
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Writes the project into `dir`. An existing file is refused (nothing is
/// written, exit 2 naming it) unless `force`.
pub fn cli(dir: &Path, force: bool) -> anyhow::Result<ExitCode> {
    let mut files: Vec<(PathBuf, &str)> = FILES.iter().map(|(p, t)| (dir.join(p), *t)).collect();
    let vendored = !python_has_kit(dir);
    if vendored {
        files.extend(KIT.iter().map(|(p, t)| (dir.join(p), *t)));
    }
    if !force {
        if let Some((p, _)) = files.iter().find(|(p, _)| p.exists()) {
            bail!(
                "{}: already exists; pushval init writes nothing over an existing file (pass --force to overwrite)",
                p.display()
            );
        }
    }
    for (p, text) in &files {
        let parent = p.parent().expect("under dir");
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
        crate::atomic::write_atomic(p, text.as_bytes())?;
    }
    for (p, _) in &files {
        println!("wrote {}", p.display());
    }
    if vendored {
        println!(
            "python3 cannot import pushval.adapter, so the kit is written beside the adapter in pushval/ (to install it instead: `python3 -m pip install PATH/TO/pushval`, pushval's source folder; no package registry has it)"
        );
    } else {
        println!("python3 imports pushval.adapter as installed; the kit is not copied");
    }
    println!(
        "\nNext: `pushval` gates my_engine on scenarios/my_engine.toml; edit adapter.py's step() to call your simulator, set `order` in pushval.toml to its step's order in dt, then run it again.\n`pushval study my_engine --quick` maps its friction against Coulomb's law."
    );
    Ok(ExitCode::SUCCESS)
}
