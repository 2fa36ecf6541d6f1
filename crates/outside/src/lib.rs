//! Outside engines: a simulator pushval does not link, run as a process.
//!
//! A project declares its engines in `pushval.toml` (`[engine.NAME]`:
//! `command`, `order`, `dt`, `timeout_s`, `version`, `law`, `protocol`,
//! `session`, `rows`; see [`Config`]). By default one run is one process,
//! started in that file's folder: pushval writes one `pushval-problem/1`
//! JSON document ([`problem_document`]: one `dt`, none in its `options`) to
//! its standard input and closes it; the process writes CSV
//! (`t,x,y,theta,omega`, one row per engine step or per sample over
//! `[0, T]`) to its standard output and exits 0. An engine declaring
//! `protocol = 2` receives the `pushval-problem/2` document instead
//! ([`problem_document_v2`]: `switching` and `limits` added). One declaring
//! `session = true` is one process serving many requests (started with
//! `PUSHVAL_SESSION=1` in its environment, no argument), one document per
//! line, each carrying `"request": N` and each answer closed by `#end N`,
//! `#ok N` or `#error N MESSAGE` (a pool of at most one per core;
//! [`shutdown_sessions`] ends them): with protocol 2 each document is a
//! whole problem; with protocol 3 (the default of a session) the engine
//! steps: `start`, one `advance` per push, `finish`, so
//! [`pushval_engine::Engine::session`] keeps the adapter's world between
//! pushes. [`OutsideEngine`] implements [`pushval_engine::Engine`], so the
//! harness, the dt ladder, the gate, `compare`, `power`, `fit`, the studies
//! and the loop run an outside engine like a compiled-in one; one that
//! cannot step is replayed.
//!
//! Every row is checked ([`check`]): finite, in time order, and within what
//! the push allows of the row before.
//!
//! Errors are [`pushval_model::ModelError::Adapter`]: they name the engine,
//! the command and the last lines of its standard error, or the line and the
//! column of a malformed row. A run past `timeout_s`, or whose output passes
//! its cap ([`Limits`], from the problem's length), is killed and is an
//! error that says so, never a pass; the output is read as it arrives and
//! never held beyond the cap. At a timeout, at a cap and after every exit,
//! every process the adapter started is ended too, whether it left the
//! process group (`setsid`) or not; at a timeout and at shutdown, so is
//! every process re-parented to pushval, whatever its environment (see the
//! `tree` module).
//!
//! The output is read in pushval's one trajectory format
//! ([`pushval_model::format`], through [`csv`]), the format `compare`, `fit`
//! and `track` read.
//!
//! What it is not: a sandbox. `pushval.toml` is trusted like a build script;
//! a scenario file can name an outside engine but never define one.
#![warn(missing_docs)]

pub mod check;
mod config;
pub mod csv;
mod document;
mod engine;
pub mod limits;
mod process;
mod session;
mod stream;
mod tree;

pub use config::{
    Config, ConfigError, Rows, Spec, DEFAULT_DT, DEFAULT_ORDER, DEFAULT_PROTOCOL,
    DEFAULT_SESSION_PROTOCOL, DEFAULT_TIMEOUT_S,
};
pub use document::{problem_document, problem_document_v2, FORMAT, FORMAT_V2};
pub use engine::{history_from_rows, OutsideEngine};
pub use limits::Limits;
pub use process::{run_process, ProcessError, ProcessOutput};
pub use session::{live_sessions, shutdown_sessions};
