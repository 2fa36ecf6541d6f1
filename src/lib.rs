//! The pushval harness: runs a scenario's models, compares them with the
//! dynamic model, and writes the contract outputs (`summary.json`,
//! `trajectory.csv`). The command line in `main.rs` is a thin layer over this.

pub mod atomic;
pub mod compare;
pub mod control;
pub mod fit;
pub mod harness;
pub mod init;
pub mod inject;
pub mod manifest;
pub mod outdir;
pub mod output;
pub mod parallel;
pub mod plot;
pub mod power;
pub mod registry;
pub mod report;
pub mod scenario_dir;
pub mod shard;
pub mod shipped;
pub mod slide;
pub mod stress;
pub mod study;
pub mod track;

pub use harness::{run_scenario, Comparison, ModelRun, RunOptions, ScenarioReport, SegmentInfo};
pub use registry::engines_table;
