//! The closed-loop commands (`pushval plan`, `pushval loop`,
//! `pushval control-study`): thin callers of the control library
//! `pushval_control`, which holds the planner, the loop and the predictors.
//! Here: the command-line words (parsing `--goal`, `--tolerance`, `--plant`,
//! `--predictor`), the output folders and the study across engines.

pub mod adaptive;
pub mod cli;
pub mod figures;
pub mod grid;
pub mod study;
pub mod write_up;

use anyhow::{bail, Context};
use pushval_control::mpc::PlantScale;
pub use pushval_control::{
    estimate, gyration_length, mpc, plan, pose_errors, predict, push_cone, sensor, stats, At,
    ControlError, Goal, ModelKind, Reach,
};

/// Parses `--goal X,Y,THETA` (m, m, rad).
pub fn parse_goal(text: &str) -> anyhow::Result<Goal> {
    let v = parse_numbers(text, 3, "--goal X,Y,THETA (m, m, rad)")?;
    Ok(Goal {
        x: v[0],
        y: v[1],
        theta: v[2],
    })
}

/// Parses `--tolerance POS,ANGLE` (m, rad).
pub fn parse_reach(text: &str) -> anyhow::Result<Reach> {
    let v = parse_numbers(text, 2, "--tolerance POS,ANGLE (m, rad)")?;
    if v.iter().any(|&x| x <= 0.0) {
        bail!("--tolerance POS,ANGLE: both must be > 0, got {text}");
    }
    Ok(Reach {
        position: v[0],
        angle: v[1],
    })
}

/// Parses `--predictor` (dynamic, kinematic, limit_surface).
pub fn parse_model(text: &str) -> anyhow::Result<ModelKind> {
    ModelKind::from_name(text).with_context(|| {
        format!("--predictor: `{text}` is not one of dynamic, kinematic, limit_surface")
    })
}

/// Parses `--plant mu_scale=A,inertia_scale=B` (either may be left out).
pub fn parse_plant_scale(text: &str) -> anyhow::Result<PlantScale> {
    let mut out = PlantScale::default();
    for part in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (k, v) = part
            .split_once('=')
            .with_context(|| format!("--plant: `{part}` is not KEY=VALUE"))?;
        let v: f64 = v
            .trim()
            .parse()
            .with_context(|| format!("--plant: `{}` is not a number", v.trim()))?;
        if !(v.is_finite() && v > 0.0) {
            bail!("--plant: {k} must be finite and > 0, got {v}");
        }
        match k.trim() {
            "mu_scale" => out.mu_scale = v,
            "inertia_scale" => out.inertia_scale = v,
            other => bail!("--plant: unknown key `{other}` (mu_scale, inertia_scale)"),
        }
    }
    Ok(out)
}

fn parse_numbers(text: &str, n: usize, what: &str) -> anyhow::Result<Vec<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .with_context(|| format!("{what}: `{}` is not a number", s.trim()))
        })
        .collect::<anyhow::Result<_>>()?;
    if v.len() != n {
        bail!(
            "{what}: expected {n} numbers separated by commas, got {}",
            v.len()
        );
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        bail!("{what}: {x} is not finite");
    }
    Ok(v)
}
