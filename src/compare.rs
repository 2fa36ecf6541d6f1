//! `pushval compare`: an outside trajectory (another implementation of a
//! model, or a recorded experiment) measured against the analytic model and
//! the engine with the same figures and tolerances as `validate`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use pushval_model::{format, Sample, Trajectory};
use pushval_scenario::Scenario;

use crate::harness::{
    compare_trajectory, run_scenario, tolerance, Comparison, Resolved, RunOptions, ScenarioReport,
    SteadyRead,
};

/// One trajectory read from a file in the one trajectory format
/// ([`pushval_model::format`]).
#[derive(Debug, Clone)]
pub struct Outside {
    /// The file.
    pub file: PathBuf,
    /// Its `model` field, or the file's name without a `model` column.
    pub name: String,
    /// The samples, in time order.
    pub samples: Vec<Sample>,
    /// Whether ω came from the file (false: derived from θ).
    pub omega_read: bool,
}

impl Outside {
    /// The line saying ω was derived, when it was.
    pub fn omega_note(&self) -> Option<String> {
        (!self.omega_read).then(|| {
            format!(
                "note: {}: no `omega` column: omega derived from theta (second-order differences over t)",
                self.file.display()
            )
        })
    }
}

/// Reads the trajectory `model` of `path` (the only one when `model` is
/// None; a file holding several needs one named), at most
/// [`pushval_scenario::MAX_SAMPLES`] data rows.
pub fn read_trajectory(path: &Path, model: Option<&str>) -> anyhow::Result<Outside> {
    let file =
        std::fs::File::open(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let all = format::read(
        std::io::BufReader::new(file),
        &path.display().to_string(),
        pushval_scenario::MAX_SAMPLES as usize,
    )?;
    let run = all.select(model)?;
    let name = run.model.clone().unwrap_or_else(|| {
        path.file_name()
            .map_or_else(|| "outside".into(), |n| n.to_string_lossy().into_owned())
    });
    Ok(Outside {
        file: path.to_path_buf(),
        name,
        samples: run.samples.clone(),
        omega_read: all.omega_read,
    })
}

/// Measures the outside trajectory against the dynamic model and the
/// scenario's gated engines. The outside samples must lie on a uniform grid
/// from t = 0; the models are sampled on the same grid. Returns the report
/// of the reference runs and one comparison per reference.
pub fn compare_outside(
    sc: &Scenario,
    outside: &Outside,
) -> anyhow::Result<(ScenarioReport, Vec<Comparison>)> {
    let file = &outside.file;
    let mut sc = sc.clone();
    let first = &outside.samples;
    if first.len() >= 2 {
        sc.sample_dt = first[1].t - first[0].t;
    }
    if !(sc.sample_dt > 0.0) {
        bail!("{}: t must increase", file.display());
    }
    // The loader's cap, before the models allocate one sample per step.
    if let Err(m) = pushval_scenario::check_sample_count(sc.problem().duration(), sc.sample_dt) {
        bail!(
            "{}: column t: its first two rows set the sample interval: {m}",
            file.display()
        );
    }
    // The dynamic model and the scenario's gated engines.
    sc.models = std::iter::once("dynamic".to_string())
        .chain(sc.gate.iter().cloned())
        .collect();
    let report = run_scenario(&sc, &RunOptions::default()).context("running the models")?;
    let tol = outside_tolerance(&sc, &report);
    let times = sc.problem().sample_times();
    let mut out = Vec::new();
    let (name, samples) = (&outside.name, &outside.samples);
    if samples.len() != times.len()
        || samples
            .iter()
            .zip(&times)
            .any(|(s, t)| (s.t - t).abs() > 1e-6 * sc.sample_dt)
    {
        bail!(
            "{}: model `{name}`: t must run from 0 to {} s in steps of {} s ({} samples); got {} samples",
            file.display(),
            sc.problem().duration(),
            sc.sample_dt,
            times.len(),
            samples.len()
        );
    }
    if let Some(w) = start_mismatch(&sc, &tol, &report, name, samples) {
        eprintln!("warning: {}: {w}", file.display());
    }
    let tr = Trajectory {
        model: name.clone(),
        samples: samples.clone(),
        ..Default::default()
    };
    for run in &report.runs {
        // Against a gated engine: that engine's tolerances; against the
        // dynamic model: the loosest of the gated engines'.
        let own = report
            .comparisons
            .iter()
            .find(|c| c.model == run.name)
            .and_then(|c| c.tolerance.clone())
            .unwrap_or_else(|| tol.clone());
        let mut c = compare_trajectory(
            &sc,
            &report.segments,
            &run.trajectory,
            name,
            &tr,
            SteadyRead::TailMean,
            Some(&own.value),
        );
        c.model = format!("{name} vs {}", run.name);
        c.tolerance = Some(own);
        out.push(c);
    }
    Ok((report, out))
}

/// Whether an outside trajectory starts as the scenario does: its first
/// sample's pose and ω, and its first step's displacement, against the
/// dynamic model's. The commonest mistake is a run that starts at rest where
/// the scenario starts already moving with the pusher (`from_rest = false`),
/// or the other way round. Returns a message saying what differs.
pub fn start_mismatch(
    sc: &Scenario,
    tol: &Resolved,
    report: &ScenarioReport,
    name: &str,
    samples: &[Sample],
) -> Option<String> {
    let model = &report.dynamic().trajectory.samples;
    if samples.len() < 2 || model.len() < 2 {
        return None;
    }
    let (a0, a1, b0, b1) = (&samples[0], &samples[1], &model[0], &model[1]);
    let tol = &tol.value;
    let init = &sc.initial;
    let state = if init.from_rest {
        "at rest when the pusher starts (from_rest = true)".to_string()
    } else {
        format!(
            "moving with the pusher at omega = {} rad/s (from_rest = false)",
            init.omega
        )
    };
    let mut what = Vec::new();
    let dp0 = ((a0.x - b0.x).powi(2) + (a0.y - b0.y).powi(2)).sqrt();
    if dp0 > tol.position_max || (a0.theta - b0.theta).abs() > tol.theta_max {
        what.push(format!(
            "its first sample is at ({:.4}, {:.4}) m, theta = {:.4} rad; the scenario's [initial] is ({:.4}, {:.4}) m, theta = {:.4} rad",
            a0.x, a0.y, a0.theta, b0.x, b0.y, b0.theta
        ));
    }
    let w_scale = b0.omega.abs().max(b1.omega.abs()).max(1e-3);
    if (a0.omega - b0.omega).abs() > 0.1 * w_scale {
        what.push(format!(
            "its omega at t = 0 is {:.4} rad/s, the model's {:.4} rad/s",
            a0.omega, b0.omega
        ));
    }
    let step = |p: &Sample, q: &Sample| ((q.x - p.x).powi(2) + (q.y - p.y).powi(2)).sqrt();
    let (sa, sb) = (step(a0, a1), step(b0, b1));
    if (sa - sb).abs() > 0.25 * sb.max(1e-12) && (sa - sb).abs() > 0.1 * tol.position_max {
        what.push(format!(
            "its centre of mass moves {sa:.3e} m over the first {} s, the model's {sb:.3e} m",
            sc.sample_dt
        ));
    }
    (!what.is_empty()).then(|| {
        format!(
            "model `{name}` does not start as the scenario does: {}. The scenario starts {state}; check [initial] (a trajectory that starts at rest where the scenario starts sliding with the pusher is the commonest cause)",
            what.join("; ")
        )
    })
}

/// The tolerances an outside trajectory is held to against the dynamic
/// model, resolved as `validate` resolves them: the loosest of the gated
/// engines' (each figure separately), or, with no gated engine, the
/// scenario's numbers and the auto rule without an engine estimate.
pub fn outside_tolerance(sc: &Scenario, report: &ScenarioReport) -> Resolved {
    let gated: Vec<&Resolved> = report
        .comparisons
        .iter()
        .filter_map(|c| c.tolerance.as_ref())
        .collect();
    let Some(first) = gated.first() else {
        let problem = sc.problem();
        let model = tolerance::model_error(
            &problem,
            &report.dynamic().trajectory,
            RunOptions::default().model_tol,
        );
        return tolerance::resolve(sc, None, model);
    };
    let mut out = (*first).clone();
    for r in &gated[1..] {
        out.value.position_max = out.value.position_max.max(r.value.position_max);
        out.value.theta_max = out.value.theta_max.max(r.value.theta_max);
        out.value.omega_steady_rel = out.value.omega_steady_rel.max(r.value.omega_steady_rel);
    }
    out
}
