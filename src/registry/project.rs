//! The project in use: the `pushval.toml` the command line loaded (through
//! [`super::use_engines_file`]), the one piece of global state the commands
//! share. It knows no engine: the registry checks what the file declares
//! before it is stored here, and reads the outside engines back from here.

use std::path::{Path, PathBuf};
use std::sync::RwLock;

use pushval_outside::{Config, Spec};

/// The file outside engines are declared in when `--engines` names none:
/// `pushval.toml`, found as cargo finds `Cargo.toml` ([`find_engines_file`]).
pub const ENGINES_FILE: &str = "pushval.toml";

/// The `pushval.toml` that applies in `dir`: the one in `dir`, else in its
/// nearest parent that has one; None when no folder up to the root has one.
pub fn find_engines_file(dir: &Path) -> Option<PathBuf> {
    dir.ancestors()
        .map(|d| d.join(ENGINES_FILE))
        .find(|f| f.is_file())
}

/// The outside engines in use: the file searched and what it declared
/// (None: the file does not exist).
#[derive(Debug, Clone)]
struct Outside {
    searched: PathBuf,
    config: Option<Config>,
}

static OUTSIDE: RwLock<Option<Outside>> = RwLock::new(None);

/// Makes `config` (read from `searched`; None: the file does not exist) the
/// project in use, replacing what an earlier call stored.
pub(super) fn set(searched: PathBuf, config: Option<Config>) {
    *OUTSIDE.write().expect("not poisoned") = Some(Outside { searched, config });
}

/// The outside engines the loaded `pushval.toml` declares, in file order
/// (none when no file was loaded or found).
pub(super) fn outside_engines() -> Vec<Spec> {
    match OUTSIDE.read().expect("not poisoned").as_ref() {
        Some(Outside {
            config: Some(c), ..
        }) => c.engines.clone(),
        _ => Vec::new(),
    }
}

/// The folder of the `pushval.toml` in use (the project's root, whose
/// `scenarios/` the main job validates), or None when none was found.
pub fn project_dir() -> Option<PathBuf> {
    OUTSIDE
        .read()
        .expect("not poisoned")
        .as_ref()
        .filter(|o| o.config.is_some())
        .and_then(|o| o.searched.parent().map(Path::to_path_buf))
}

/// Where outside engines were looked for, for messages: the file and
/// whether it exists.
pub fn engines_file() -> String {
    match OUTSIDE.read().expect("not poisoned").as_ref() {
        Some(Outside {
            searched,
            config: Some(_),
        }) => searched.display().to_string(),
        Some(Outside {
            searched,
            config: None,
        }) => format!("{} (not found)", searched.display()),
        None => "none loaded".to_string(),
    }
}
