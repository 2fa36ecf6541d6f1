//! `[run]`: which models run and which are gated, the switching rule and
//! the sample interval.

use std::path::Path;

use pushval_model::{Push, Switching};

use super::check::finite_pos;
use crate::raw::RawRun;
use crate::ScenarioError;

/// The analytic models every build has, in output order; the engine models
/// come from the command line's registry.
pub const ANALYTIC_MODELS: [&str; 3] = ["dynamic", "kinematic", "limit_surface"];

/// The models a scenario runs when `[run] models` is absent.
pub const DEFAULT_MODELS: [&str; 4] = ["dynamic", "kinematic", "limit_surface", "rapier2d"];

/// The engines a scenario gates when `[run] gate` is absent.
pub const DEFAULT_GATE: [&str; 1] = ["rapier2d"];

/// `[run]` checked.
pub(super) struct Run {
    /// s.
    pub(super) sample_dt: f64,
    pub(super) switching: Switching,
    /// In order, without repeats, every gated engine included.
    pub(super) models: Vec<String>,
    pub(super) gate: Vec<String>,
}

/// Most samples one trajectory may have: 1e7 samples of four f64 each is a
/// few hundred megabytes per model; anything denser is a typo.
pub const MAX_SAMPLES: f64 = 1e7;

/// Whether `sample_dt` (s) over `total` (s) stays within [`MAX_SAMPLES`];
/// the sentence to report when not. Every reader of a trajectory (the
/// loader, `compare`, `fit`) applies it before allocating.
pub fn check_sample_count(total: f64, sample_dt: f64) -> Result<(), String> {
    if !(total / sample_dt <= MAX_SAMPLES) {
        return Err(format!(
            "{sample_dt:e} s over {total} s gives more than {MAX_SAMPLES:e} samples"
        ));
    }
    Ok(())
}

/// The run settings for the schedule `pushes` and a slide of at most
/// `slide` s after it: a sample interval that gives at most 1e7 samples, a
/// known switching rule, model and gate lists (names are checked against
/// the engine registry by the command line).
pub(super) fn from_raw(
    raw: Option<RawRun>,
    pushes: &[Push],
    slide: f64,
    file: &Path,
) -> Result<Run, ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    let rr = raw.unwrap_or_default();
    let sample_dt = finite_pos(file, "run.sample_dt", rr.sample_dt.unwrap_or(0.01))?;
    let total: f64 = pushes.iter().map(|p| p.duration).sum::<f64>() + slide;
    if let Err(m) = check_sample_count(total, sample_dt) {
        return Err(err("run.sample_dt", m));
    }
    let switching = match rr.switching.as_deref().unwrap_or("impulsive") {
        "impulsive" => Switching::Impulsive,
        "continuous" => Switching::Continuous,
        other => {
            return Err(err(
                "run.switching",
                format!("unknown value \"{other}\"; expected \"impulsive\" or \"continuous\""),
            ))
        }
    };
    let names = |key: &str, list: Option<Vec<String>>, default: &[&str]| match list {
        None => Ok(default.iter().map(|m| m.to_string()).collect::<Vec<_>>()),
        Some(list) => {
            if list.is_empty() {
                return Err(err(key, "is empty".into()));
            }
            let mut out: Vec<String> = Vec::new();
            for m in list {
                if !out.contains(&m) {
                    out.push(m);
                }
            }
            Ok(out)
        }
    };
    let mut models = names("run.models", rr.models, &DEFAULT_MODELS)?;
    // Absent `gate`: the default engines the scenario runs. A gate named
    // explicitly runs whether `models` lists it or not.
    let gate = match rr.gate {
        None => DEFAULT_GATE
            .iter()
            .map(|g| g.to_string())
            .filter(|g| models.contains(g))
            .collect(),
        list => names("run.gate", list, &DEFAULT_GATE)?,
    };
    for g in &gate {
        if !models.contains(g) {
            models.push(g.clone());
        }
    }
    Ok(Run {
        sample_dt,
        switching,
        models,
        gate,
    })
}
