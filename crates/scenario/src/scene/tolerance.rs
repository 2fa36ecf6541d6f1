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
#[derive(Debug, Clone, PartialEq)]
pub struct Tolerance {
    /// Relative error of the steady ω per settled segment.
    pub omega_steady_rel: Limit,
    /// Largest centre-of-mass position difference (m).
    pub position_max: Limit,
    /// Largest angle difference (rad).
    pub theta_max: Limit,
    /// The most an `"auto"` figure may be, `[position (m), theta (rad),
    /// steady ω (relative)]` (`[tolerance] auto_ceiling`; default
    /// [`DEFAULT_AUTO_CEILING`]). An engine whose own accuracy cannot back
    /// an auto figure below it fails the gate; the tolerance never widens
    /// past it.
    pub auto_ceiling: [f64; 3],
    /// `[tolerance] reason`: why the file loosens the gate (see
    /// [`Tolerance::loosened`]), shown beside the loosened figures.
    pub reason: Option<String>,
}

/// One number of a `[tolerance]` table above the default auto ceiling: a
/// gate the file loosened past what pushval would assert on its own.
#[derive(Debug, Clone, PartialEq)]
pub struct Loosened {
    /// The key, e.g. `tolerance.position_max` or `tolerance.auto_ceiling[0]`.
    pub key: String,
    /// The number written (in the figure's unit).
    pub value: f64,
    /// The default auto ceiling of that figure ([`DEFAULT_AUTO_CEILING`]).
    pub ceiling: f64,
}

impl Tolerance {
    /// Every number of the table above [`DEFAULT_AUTO_CEILING`] (a figure or
    /// a raised `auto_ceiling`), in the order position, theta, steady ω.
    pub fn loosened(&self) -> Vec<Loosened> {
        let figures = [
            ("tolerance.position_max", self.position_max),
            ("tolerance.theta_max", self.theta_max),
            ("tolerance.omega_steady_rel", self.omega_steady_rel),
        ];
        let mut out = Vec::new();
        for (i, (key, limit)) in figures.into_iter().enumerate() {
            let ceiling = DEFAULT_AUTO_CEILING[i];
            if let Some(v) = limit.value().filter(|v| *v > ceiling) {
                out.push(Loosened {
                    key: key.to_string(),
                    value: v,
                    ceiling,
                });
            }
            if self.auto_ceiling[i] > ceiling {
                out.push(Loosened {
                    key: format!("tolerance.auto_ceiling[{i}]"),
                    value: self.auto_ceiling[i],
                    ceiling,
                });
            }
        }
        out
    }
}

impl Default for Tolerance {
    fn default() -> Self {
        Self {
            omega_steady_rel: Limit::Auto,
            position_max: Limit::Auto,
            theta_max: Limit::Auto,
            auto_ceiling: DEFAULT_AUTO_CEILING,
            reason: None,
        }
    }
}

/// `[tolerance] auto_ceiling` when absent: 1 mm, 1 mrad, 0.1 % of steady ω.
/// At these a 1 % error in I_cm or μ still moves the shipped paper pushes
/// past the tolerance (results/gate_power.csv has the figures per scene).
pub const DEFAULT_AUTO_CEILING: [f64; 3] = [1e-3, 1e-3, 1e-3];

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
    let auto_ceiling = match rt.auto_ceiling {
        None => DEFAULT_AUTO_CEILING,
        Some(v) if v.len() == 3 => [
            finite_pos(file, "tolerance.auto_ceiling[0]", v[0])?,
            finite_pos(file, "tolerance.auto_ceiling[1]", v[1])?,
            finite_pos(file, "tolerance.auto_ceiling[2]", v[2])?,
        ],
        Some(v) => {
            return Err(ScenarioError::new(
                file,
                "tolerance.auto_ceiling",
                format!(
                    "must be [position m, theta rad, steady omega relative], 3 numbers; got {}",
                    v.len()
                ),
            ))
        }
    };
    let reason = match rt.reason {
        Some(r) if r.trim().is_empty() => {
            return Err(ScenarioError::new(
                file,
                "tolerance.reason",
                "must say why the gate is loosened; got an empty string",
            ))
        }
        r => r,
    };
    Ok(Tolerance {
        reason,
        auto_ceiling,
        omega_steady_rel: limit("tolerance.omega_steady_rel", rt.omega_steady_rel)?,
        position_max: limit("tolerance.position_max", rt.position_max)?,
        theta_max: limit("tolerance.theta_max", rt.theta_max)?,
    })
}
