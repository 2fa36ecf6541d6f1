//! The checks every table shares: a number or a point must be finite (and
//! a number often > 0); the error names the key and the value.

use std::path::Path;

use pushval_model::Vec2;

use crate::ScenarioError;

/// `v` if it is finite and > 0.
pub(super) fn finite_pos(file: &Path, key: &str, v: f64) -> Result<f64, ScenarioError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ScenarioError::new(
            file,
            key,
            format!("must be a finite number > 0, got {v}"),
        ))
    }
}

/// `v` if it is finite.
pub(super) fn finite(file: &Path, key: &str, v: f64) -> Result<f64, ScenarioError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ScenarioError::new(
            file,
            key,
            format!("must be finite, got {v}"),
        ))
    }
}

/// The point `[x, y]` if both coordinates are finite.
pub(super) fn point(file: &Path, key: &str, p: [f64; 2]) -> Result<Vec2, ScenarioError> {
    if p.iter().all(|c| c.is_finite()) {
        Ok(Vec2::new(p[0], p[1]))
    } else {
        Err(ScenarioError::new(
            file,
            key,
            format!("must be finite, got [{}, {}]", p[0], p[1]),
        ))
    }
}
