//! Where the commands find scenarios when none is named
//! (docs/architecture.md, "Anywhere").

use std::path::PathBuf;

/// The scenarios folder the commands read: the project's `scenarios/`
/// (beside the `pushval.toml` in use), else `./scenarios`, else the shipped
/// scenarios written out once ([`crate::shipped::materialized`]).
pub fn default_scenario_dir() -> PathBuf {
    let dirs = [
        crate::registry::project_dir().map(|d| d.join("scenarios")),
        Some(PathBuf::from("scenarios")),
    ];
    dirs.into_iter()
        .flatten()
        .find(|d| d.is_dir())
        .or_else(|| crate::shipped::materialized("scenarios").ok())
        .unwrap_or_else(|| PathBuf::from("scenarios"))
}
