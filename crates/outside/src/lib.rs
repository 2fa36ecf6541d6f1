//! Outside engines: a simulator pushval does not link, run as a process.
//!
//! A project declares its engines in `pushval.toml` (`[engine.NAME]`:
//! `command`, `order`, `dt`, `timeout_s`, `version`; see [`Config`]). One run
//! is one process, started in that file's folder: pushval writes one
//! `pushval-problem/1` JSON document ([`problem_document`]) to its standard
//! input and closes it; the process writes CSV (`t,x,y,theta,omega`, one row
//! per engine step or per sample over `[0, T]`) to its standard output and
//! exits 0. [`OutsideEngine`] implements [`pushval_engine::Engine`], so the
//! harness, the dt ladder, the gate, `compare`, `power`, `fit` and the studies
//! run an outside engine like a compiled-in one.
//!
//! Errors are [`pushval_model::ModelError::Adapter`]: they name the engine,
//! the command and the last lines of its standard error, or the line and the
//! column of a malformed row. A run past `timeout_s` is killed (with its
//! process group) and is an error, never a pass.
//!
//! The output is read in pushval's one trajectory format
//! ([`pushval_model::format`], through [`csv`]), the format `compare`, `fit`
//! and `track` read.
//!
//! What it is not: a sandbox. `pushval.toml` is trusted like a build script;
//! a scenario file can name an outside engine but never define one.
#![warn(missing_docs)]

mod config;
pub mod csv;
mod document;
mod engine;
mod process;

pub use config::{Config, ConfigError, Spec, DEFAULT_DT, DEFAULT_ORDER, DEFAULT_TIMEOUT_S};
pub use document::{problem_document, FORMAT};
pub use engine::{history_from_rows, OutsideEngine};
pub use process::{run_process, ProcessOutput};
