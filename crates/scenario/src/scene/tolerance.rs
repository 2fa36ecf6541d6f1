//! `[tolerance]`: what `validate` asserts between a gated engine and the
//! dynamic model.

use std::path::Path;

use super::check::finite_pos;
use crate::raw::{RawLimit, RawTolerance};
use crate::ScenarioError;

/// One `[tolerance]` figure: a number, or derived from the gated engine's
/// own accuracy (`"auto"`, and the default when the key is absent).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Limit {
    /// The number in the file (its unit is the figure's).
    Value(f64),
    /// A stated multiple of the gated engine's self-convergence estimate,
    /// plus the model's own error (resolved by the harness).
    #[default]
    Auto,
}

impl Limit {
    /// The number, None for `Auto`.
    pub fn value(self) -> Option<f64> {
        match self {
            Limit::Value(v) => Some(v),
            Limit::Auto => None,
        }
    }
}

/// `[tolerance]`: what `validate` asserts between a gated engine and the
/// dynamic model.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tolerance {
    /// Relative error of the steady ω per settled segment.
    pub omega_steady_rel: Limit,
    /// Largest centre-of-mass position difference (m).
    pub position_max: Limit,
    /// Largest angle difference (rad).
    pub theta_max: Limit,
}

/// Each figure a finite number > 0 or `"auto"`; absent: `"auto"`.
pub(super) fn from_raw(raw: Option<RawTolerance>, file: &Path) -> Result<Tolerance, ScenarioError> {
    let rt = raw.unwrap_or_default();
    let limit = |key: &str, v: Option<RawLimit>| match v {
        None => Ok(Limit::Auto),
        Some(RawLimit::Number(x)) => finite_pos(file, key, x).map(Limit::Value),
        Some(RawLimit::Word(w)) if w == "auto" => Ok(Limit::Auto),
        Some(RawLimit::Word(w)) => Err(ScenarioError::new(
            file,
            key,
            format!("must be a finite number > 0 or \"auto\", got \"{w}\""),
        )),
    };
    Ok(Tolerance {
        omega_steady_rel: limit("tolerance.omega_steady_rel", rt.omega_steady_rel)?,
        position_max: limit("tolerance.position_max", rt.position_max)?,
        theta_max: limit("tolerance.theta_max", rt.theta_max)?,
    })
}
