//! `[engine]`: `dt` is checked here, every other key by the engines that
//! read it.

use std::path::Path;

use pushval_engine::EngineOptions;
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

/// The engine options: `dt` a finite number > 0 (s) giving at most
/// [`MAX_ENGINE_STEPS`] steps over the schedule, the other keys as JSON
/// values for the engines.
pub(super) fn from_raw(
    raw: Option<RawEngine>,
    file: &Path,
    pushes: &[Push],
) -> Result<EngineOptions, ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    let mut engine = EngineOptions::default();
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
