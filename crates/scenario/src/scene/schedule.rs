//! `[[push]]` and `[initial]`: the input schedule and the state it starts
//! from.

use std::path::Path;

use pushval_model::{Initial, Push};

use super::check::{finite, finite_pos, point};
use crate::raw::{RawInitial, RawPush};
use crate::ScenarioError;

/// The pushes, in order: at least one, each with a duration > 0 and a speed
/// >= 0.
pub(super) fn pushes(raw: &[RawPush], file: &Path) -> Result<Vec<Push>, ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    if raw.is_empty() {
        return Err(err(
            "push",
            "the schedule is empty: add at least one [[push]]".into(),
        ));
    }
    raw.iter()
        .enumerate()
        .map(|(i, p)| {
            let duration = finite_pos(file, &format!("push[{i}].duration"), p.duration)?;
            let speed = finite(file, &format!("push[{i}].speed"), p.speed)?;
            if speed < 0.0 {
                return Err(err(
                    &format!("push[{i}].speed"),
                    format!("must be >= 0, got {speed}"),
                ));
            }
            let phi = finite(file, &format!("push[{i}].phi"), p.phi)?;
            Ok(Push {
                duration,
                speed,
                phi,
            })
        })
        .collect()
}

/// The initial state; every key defaults to zero (`from_rest` to false).
pub(super) fn initial(raw: Option<RawInitial>, file: &Path) -> Result<Initial, ScenarioError> {
    let ri = raw.unwrap_or_default();
    Ok(Initial {
        theta: finite(file, "initial.theta", ri.theta.unwrap_or(0.0))?,
        omega: finite(file, "initial.omega", ri.omega.unwrap_or(0.0))?,
        position: point(file, "initial.position", ri.position.unwrap_or([0.0, 0.0]))?,
        from_rest: ri.from_rest.unwrap_or(false),
    })
}
