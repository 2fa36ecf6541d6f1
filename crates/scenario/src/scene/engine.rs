//! `[engine]`: `dt` is checked here, every other key by the engines that
//! read it.

use std::path::Path;

use pushval_engine::EngineOptions;

use super::check::finite_pos;
use crate::raw::RawEngine;
use crate::ScenarioError;

/// The engine options: `dt` a finite number > 0 (s), the other keys as JSON
/// values for the engines.
pub(super) fn from_raw(
    raw: Option<RawEngine>,
    file: &Path,
) -> Result<EngineOptions, ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    let mut engine = EngineOptions::default();
    for (key, value) in raw.unwrap_or_default() {
        if key == "dt" {
            let dt = value
                .as_float()
                .or_else(|| value.as_integer().map(|i| i as f64))
                .ok_or_else(|| err("engine.dt", format!("must be a number, got {value}")))?;
            engine.dt = Some(finite_pos(file, "engine.dt", dt)?);
        } else {
            let json = serde_json::to_value(&value)
                .map_err(|e| err(&format!("engine.{key}"), format!("unreadable value: {e}")))?;
            engine.values.insert(key, json);
        }
    }
    Ok(engine)
}
