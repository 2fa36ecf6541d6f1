//! `pushval compare`: an outside trajectory (another implementation of a
//! model, or a recorded experiment) measured against the analytic model and
//! the engine with the same figures and tolerances as `validate`.

use std::path::Path;

use anyhow::{bail, Context};
use pushval_model::{Sample, Trajectory};
use pushval_scenario::Scenario;

use crate::harness::{
    compare_trajectory, run_scenario, Comparison, RunOptions, ScenarioReport, SteadyRead,
};

/// The trajectories of an outside CSV file, per value of its `model` column.
#[derive(Debug, Clone)]
pub struct Outside {
    pub runs: Vec<(String, Vec<Sample>)>,
}

/// Reads a CSV in `trajectory.csv`'s columns (`model,t,x,y,theta,omega`, in
/// any order, extra columns ignored). Parsed by hand: the format is fixed
/// and numeric, and errors must name the line and the column.
pub fn read_csv(path: &Path) -> anyhow::Result<Outside> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!("{}: the file is empty", path.display());
    };
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let find = |name: &str| {
        cols.iter().position(|c| *c == name).with_context(|| {
            format!(
                "{}: line 1: the header lacks the column `{name}` (need model,t,x,y,theta,omega)",
                path.display()
            )
        })
    };
    let (im, it, ix, iy, ith, iw) = (
        find("model")?,
        find("t")?,
        find("x")?,
        find("y")?,
        find("theta")?,
        find("omega")?,
    );
    let mut runs: Vec<(String, Vec<Sample>)> = Vec::new();
    for (n, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != cols.len() {
            bail!(
                "{}: line {}: {} fields, the header has {}",
                path.display(),
                n + 1,
                f.len(),
                cols.len()
            );
        }
        let num = |i: usize| -> anyhow::Result<f64> {
            let v: f64 = f[i].parse().with_context(|| {
                format!(
                    "{}: line {}: column `{}`: `{}` is not a number",
                    path.display(),
                    n + 1,
                    cols[i],
                    f[i]
                )
            })?;
            if !v.is_finite() {
                bail!(
                    "{}: line {}: column `{}`: {} is not finite",
                    path.display(),
                    n + 1,
                    cols[i],
                    v
                );
            }
            Ok(v)
        };
        let s = Sample {
            t: num(it)?,
            x: num(ix)?,
            y: num(iy)?,
            theta: num(ith)?,
            omega: num(iw)?,
        };
        match runs.iter_mut().find(|r| r.0 == f[im]) {
            Some(r) => r.1.push(s),
            None => runs.push((f[im].to_string(), vec![s])),
        }
    }
    if runs.is_empty() {
        bail!("{}: no data rows", path.display());
    }
    Ok(Outside { runs })
}

/// Measures every outside trajectory against the dynamic model and rapier2d.
/// The outside samples must lie on a uniform grid from t = 0; the models are
/// sampled on the same grid. Returns the report of the reference runs and one
/// comparison per outside trajectory and reference.
pub fn compare_outside(
    sc: &Scenario,
    outside: &Outside,
    file: &Path,
) -> anyhow::Result<(ScenarioReport, Vec<Comparison>)> {
    let mut sc = sc.clone();
    let first = &outside.runs[0].1;
    if first.len() >= 2 {
        sc.sample_dt = first[1].t - first[0].t;
    }
    if !(sc.sample_dt > 0.0) {
        bail!("{}: t must increase", file.display());
    }
    // The dynamic model and the scenario's gated engines.
    sc.models = std::iter::once("dynamic".to_string())
        .chain(sc.gate.iter().cloned())
        .collect();
    let report = run_scenario(&sc, &RunOptions::default()).context("running the models")?;
    let times = sc.problem().sample_times();
    let mut out = Vec::new();
    for (name, samples) in &outside.runs {
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
        let tr = Trajectory {
            model: name.clone(),
            samples: samples.clone(),
            ..Default::default()
        };
        for run in &report.runs {
            let mut c = compare_trajectory(
                &sc,
                &report.segments,
                &run.trajectory,
                name,
                &tr,
                SteadyRead::TailMean,
                true,
            );
            c.model = format!("{name} vs {}", run.name);
            out.push(c);
        }
    }
    Ok((report, out))
}
