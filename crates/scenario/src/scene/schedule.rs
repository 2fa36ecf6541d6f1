//! `[[push]]` and `[initial]`: the input schedule and the state it starts
//! from.

use std::path::Path;

use pushval_model::{Initial, Push, Release, Vec2};

use super::check::{finite, finite_pos, point};
use crate::raw::{RawInitial, RawPush, RawRelease};
use crate::ScenarioError;

/// The pushes, in order: at least one unless the file has a `[release]`
/// (the slide then starts at t = 0), each with a duration > 0 and a speed
/// >= 0.
pub(super) fn pushes(
    raw: &[RawPush],
    release: Option<&Release>,
    file: &Path,
) -> Result<Vec<Push>, ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    if raw.is_empty() && release.is_none() {
        return Err(err(
            "push",
            "the schedule is empty: add at least one [[push]] (or a [release] to slide from [initial])".into(),
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

/// `[release]`: `max_duration` finite and > 0 (s), default 10.
pub(super) fn release(
    raw: Option<RawRelease>,
    file: &Path,
) -> Result<Option<Release>, ScenarioError> {
    raw.map(|r| {
        Ok(Release {
            max_duration: match r.max_duration {
                Some(d) => finite_pos(file, "release.max_duration", d)?,
                None => Release::default().max_duration,
            },
        })
    })
    .transpose()
}

/// The initial state; every key defaults to zero (`from_rest` to false).
/// `velocity` only without pushes (a push sets the velocity itself).
pub(super) fn initial(
    raw: Option<RawInitial>,
    pushes: &[Push],
    file: &Path,
) -> Result<Initial, ScenarioError> {
    let ri = raw.unwrap_or_default();
    let velocity = match ri.velocity {
        None => Vec2::zeros(),
        Some(_) if !pushes.is_empty() => {
            return Err(ScenarioError::new(
                file,
                "initial.velocity",
                "is only allowed without [[push]] (a push sets the velocity; with [release] and no pushes the slide starts from it)",
            ))
        }
        Some(v) => point(file, "initial.velocity", v)?,
    };
    Ok(Initial {
        theta: finite(file, "initial.theta", ri.theta.unwrap_or(0.0))?,
        omega: finite(file, "initial.omega", ri.omega.unwrap_or(0.0))?,
        position: point(file, "initial.position", ri.position.unwrap_or([0.0, 0.0]))?,
        from_rest: ri.from_rest.unwrap_or(false),
        velocity,
    })
}
