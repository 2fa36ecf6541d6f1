//! The engine registry: every engine model pushval can run, by name, and the
//! only module of pushval that names an engine crate (a test checks it).
//!
//! Its files, one job each, none importing this one (so no file here is in a
//! circle; `tests/suite/architecture.rs`):
//! - `models.rs`: the registry proper, one row per engine crate
//!   ([`ENGINE_CRATES`]) then the outside engines of `pushval.toml`;
//! - `project.rs`: the `pushval.toml` in use, the commands' one global state;
//! - `check.rs`: the scenario checks only the registry can make;
//! - `listing.rs`: `pushval engines` and `pushval laws`.
//!
//! Adding an engine is its crate, one row in [`ENGINE_CRATES`] (with its
//! cargo feature, if any), and its Cargo entries (the workspace dependency,
//! the root package's dependency and, for heavy engines, a feature).
//! Nothing else in the harness, the studies, the manifest or the benches
//! names an engine.

mod check;
mod listing;
mod models;
mod project;

pub use check::{check, from_toml, load};
pub use listing::{declarations, engines_table, law_key, laws_json, laws_table};
pub use models::{
    engine, engine_options, entries, entry, feature_of, known_models, outside_law,
    use_engines_file, CrateRow, Entry, ENGINE_CRATES,
};
pub use project::{engines_file, find_engines_file, project_dir, ENGINES_FILE};

/// What the commands take from the outside-engine protocol besides the
/// engines themselves: the documents `pushval problem` prints, the default
/// step, the limits, and the end of every session at exit.
pub use pushval_outside::{
    problem_document, problem_document_v2, shutdown_sessions, Limits,
    DEFAULT_DT as OUTSIDE_DEFAULT_DT,
};

/// MuJoCo's creep scene and thresholds, for the creep report
/// (`crate::report::creep_law`), which reads what `examples/creep_law.rs`
/// measured.
pub mod mujoco_creep {
    pub use pushval_mujoco::creep::{CreepScene, CHATTER_HEIGHT_STD, SLIDING_SPEED};
}
