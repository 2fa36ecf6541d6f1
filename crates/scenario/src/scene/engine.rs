//! `[engine]`: `dt` is checked here, every other key by the engines that
//! read it.

use std::collections::BTreeMap;
use std::path::Path;

use pushval_model::Push;

use super::check::finite_pos;
use crate::raw::RawEngine;
use crate::ScenarioError;

/// Most engine steps one run of the schedule may take at `[engine] dt`: the
/// same cap as the samples (`run.sample_dt`). The gate runs the engine at
/// dt, 2 dt and 4 dt and keeps each trajectory, so a step count past this
/// costs minutes and gigabytes for a time step no engine needs; a finer dt
/// than `duration / 1e7` is refused, not attempted.
pub const MAX_ENGINE_STEPS: f64 = 1e7;

/// The scenario's `[engine]` table: the time step every engine reads,
/// checked here, and the other keys verbatim (as JSON values) for the
/// engines that read them. This crate knows no engine: the command line's
/// registry turns the table into each engine's options
/// (`pushval_engine::EngineOptions::from_table`) and refuses keys no engine
/// reads, naming the file and `engine.KEY`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EngineTable {
    /// `[engine] dt` (s), kept exactly when set; None: each engine's default.
    pub dt: Option<f64>,
    /// The other keys with their values.
    pub values: BTreeMap<String, serde_json::Value>,
}

/// The `[engine]` table: `dt` a finite number > 0 (s) giving at most
/// [`MAX_ENGINE_STEPS`] steps over the schedule, the other keys as JSON
/// values for the engines.
pub(super) fn from_raw(
    raw: Option<RawEngine>,
    file: &Path,
    pushes: &[Push],
) -> Result<EngineTable, ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    let mut engine = EngineTable::default();
    for (key, value) in raw.unwrap_or_default() {
        if key == "dt" {
            let dt = value
                .as_float()
                .or_else(|| value.as_integer().map(|i| i as f64))
                .ok_or_else(|| err("engine.dt", format!("must be a number, got {value}")))?;
            let dt = finite_pos(file, "engine.dt", dt)?;
            let total: f64 = pushes.iter().map(|p| p.duration).sum();
            if total / dt > MAX_ENGINE_STEPS {
                return Err(err(
                    "engine.dt",
                    format!(
                        "{dt:e} s over {total} s is more than {MAX_ENGINE_STEPS:e} engine steps; the smallest dt this schedule allows is {:e} s",
                        total / MAX_ENGINE_STEPS
                    ),
                ));
            }
            engine.dt = Some(dt);
        } else {
            let json = serde_json::to_value(&value)
                .map_err(|e| err(&format!("engine.{key}"), format!("unreadable value: {e}")))?;
            engine.values.insert(key, json);
        }
    }
    Ok(engine)
}
