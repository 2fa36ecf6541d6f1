//! Which Coulomb parameters an engine behaves as: the dynamic model fitted
//! to an engine's trajectory by `pushval fit`'s machinery (Levenberg–
//! Marquardt), and whether the fit explains the engine. A fit of an engine
//! is a fit like any other, so it lives here; `pushval study` runs it as
//! one of its tasks and writes its rows as `coulomb_fit.csv`.
//!
//! Two schedules of the paper plate, read from the shipped scenarios (the
//! binary's, whatever folder the study runs in):
//! `friction-engines.toml` (one push of 6 s at 0.5 m/s, φ = π/4 + 0.3) and
//! `paper-square-v1.0.toml` (the paper's five 2 s segments at 1 m/s; not on
//! the quick grid). `mu_scale` is always fitted; `center_of_friction` and
//! `inertia_cm` where the schedule identifies them (the Fisher information
//! at the file's values, [`crate::fit::fisher_at`]; one constant push leaves
//! the centre of friction unidentifiable).
//!
//! The engine runs at its study step over 4; its own error is the
//! Richardson estimate from a second run at twice that step,
//! `e = rms |X(2Δt) − X(Δt)| / (2^p − 1)` (p its order). Verdict, with
//! `T = max(10 e, 1e-6)` in position (m) and θ (rad): **explained** when the
//! fit's residual rms is within T and within 1 mm / 1 mrad, **not_explained**
//! when it exceeds T, **undecided** otherwise (the engine's own error is too
//! large to tell); **degenerate**, whatever the residuals, when a fitted
//! μ scale or I_cm is near zero ([`crate::fit::degenerate_reasons`]: a
//! frictionless or massless plate explains nothing).

use pushval_engine::Engine;
use pushval_model::{DynamicModel, Sample, Simulator};

use super::{fisher_at, fit, Param, Parametrised, Settings};

/// The scenario files of the schedules, single push first.
pub const SCHEDULES: [&str; 2] = ["friction-engines.toml", "paper-square-v1.0.toml"];
/// The fitted run's step is the study's over this.
pub const STEP_DIVISOR: f64 = 4.0;
/// Thresholds: this many times the engine's own error, at least 1e-6.
pub const THRESHOLD_FACTOR: f64 = 10.0;
/// Above this (m, rad) a threshold no longer decides.
pub const THRESHOLD_CAP: f64 = 1e-3;
/// The columns of `coulomb_fit.csv` after `schedule`.
pub const COLUMNS: [&str; 15] = [
    "dt",
    "mu_scale",
    "mu_scale_std",
    "cof_x",
    "cof_y",
    "inertia_cm",
    "inertia_cm_std",
    "start_position_rms",
    "start_theta_rms",
    "position_rms",
    "theta_rms",
    "engine_error_position",
    "engine_error_theta",
    "converged",
    "fitted",
];
/// Values in a fit's row (the columns above less `fitted`, plus three
/// flags: centre of friction fitted, I_cm fitted, and which parameters are
/// near zero: 1 the μ scale, 2 I_cm, 3 both, 0 none).
pub const WIDTH: usize = 17;

fn rms_difference(a: &[Sample], b: &[Sample]) -> [f64; 2] {
    let n = a.len().min(b.len()).max(1) as f64;
    let (mut p, mut t) = (0.0, 0.0);
    for (s, r) in a.iter().zip(b) {
        p += (s.x - r.x).powi(2) + (s.y - r.y).powi(2);
        t += (s.theta - r.theta).powi(2);
    }
    [(p / n).sqrt(), (t / n).sqrt()]
}

/// The parameters schedule's scenario identifies (see the module doc).
fn identified(sc: &pushval_scenario::Scenario, s: &Settings) -> anyhow::Result<Vec<Param>> {
    let mut set = vec![Param::InertiaCm, Param::CenterOfFriction, Param::MuScale];
    loop {
        let model = Parametrised::new(sc, &set).map_err(anyhow::Error::msg)?;
        let f = fisher_at(&model, &model.file_values(), s).map_err(anyhow::Error::msg)?;
        let bad: Vec<Param> = model
            .slots()
            .iter()
            .zip(&f.unidentifiable)
            .filter(|(_, u)| **u)
            .map(|((p, _), _)| *p)
            .collect();
        match set
            .iter()
            .position(|p| *p != Param::MuScale && bad.contains(p))
        {
            Some(i) => {
                set.remove(i);
            }
            None => return Ok(set),
        }
    }
}

/// Where a fit task failed: its row holds NaN and, in its last value, the
/// stage's code negated ([`failed_row`], [`failure_reason`]), so that the
/// reason survives the numeric shard files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// The shipped schedule did not load.
    Schedule = 1,
    /// The engine's run of the schedule failed.
    EngineRun = 2,
    /// The engine's samples are not the schedule's.
    Grid = 3,
    /// The identifiability check or the Levenberg–Marquardt fit failed.
    Fit = 4,
}

impl Stage {
    const ALL: [Stage; 4] = [Stage::Schedule, Stage::EngineRun, Stage::Grid, Stage::Fit];

    /// What failed, as the `reason` column says it.
    pub fn reason(self) -> &'static str {
        match self {
            Stage::Schedule => "the shipped schedule did not load",
            Stage::EngineRun => "the engine's run of the schedule failed",
            Stage::Grid => "the engine's samples are not on the schedule's sample times",
            Stage::Fit => "the fit itself failed (identifiability check or Levenberg-Marquardt)",
        }
    }
}

/// The row of a fit that failed at `stage`.
pub fn failed_row(stage: Stage) -> Vec<f64> {
    let mut row = vec![f64::NAN; WIDTH];
    row[WIDTH - 1] = -(stage as i32 as f64);
    row
}

/// Why a row is `failed` (None when it is not): its stage's reason, and
/// where the error itself went.
pub fn failure_reason(row: &[f64]) -> Option<String> {
    if !row[0].is_nan() {
        return None;
    }
    let code = -row[WIDTH - 1];
    let stage = Stage::ALL.into_iter().find(|s| *s as i32 as f64 == code);
    Some(match stage {
        Some(s) => format!(
            "{} (the error is on the study's standard error)",
            s.reason()
        ),
        None => "the fit did not run (no stage recorded)".into(),
    })
}

/// Fits schedule `k` to `engine` run at `study_dt / STEP_DIVISOR`: the row
/// of [`COLUMNS`] (NaN where not fitted), or the stage that failed and why.
pub fn fit_engine(
    engine: &dyn Engine,
    k: usize,
    study_dt: f64,
) -> Result<Vec<f64>, (Stage, anyhow::Error)> {
    let settings = Settings::default();
    let at = |stage: Stage| move |e: anyhow::Error| (stage, e);
    // The shipped schedules, from the binary: a project's own scenarios/
    // (an init project's) holds neither.
    let sc = crate::shipped::scenario(SCHEDULES[k]).map_err(at(Stage::Schedule))?;
    let problem = sc.problem();
    let dt = study_dt / STEP_DIVISOR;
    let run = |h: f64| {
        engine
            .run(&problem, h)
            .map(|r| r.trajectory.samples)
            .map_err(|e| {
                (
                    Stage::EngineRun,
                    anyhow::anyhow!("{} at dt = {h}: {e}", engine.name()),
                )
            })
    };
    let (data, coarse) = (run(dt)?, run(2.0 * dt)?);
    crate::fit::check_grid(&sc, &data).map_err(|e| (Stage::Grid, anyhow::Error::msg(e)))?;
    let k_rich = 1.0 / (2f64.powf(engine.order()) - 1.0);
    let engine_error = rms_difference(&coarse, &data).map(|d| k_rich * d);
    let fail = at(Stage::Fit);
    let set = identified(&sc, &settings).map_err(fail)?;
    let model = Parametrised::new(&sc, &set)
        .map_err(anyhow::Error::msg)
        .map_err(fail)?;
    let start = model.file_values();
    let problem0 = model
        .problem(&start)
        .map_err(|e| (Stage::Fit, anyhow::anyhow!("{}", e.0)))?;
    let reference = DynamicModel::default()
        .simulate(&problem0)
        .map_err(|e| (Stage::Fit, e.into()))?;
    let start_rms = rms_difference(&reference.samples, &data);
    let f = fit(&model, &data, &start, &settings)
        .map_err(anyhow::Error::msg)
        .map_err(fail)?;
    let get = |p: Param| {
        f.get(p)
            .unwrap_or((vec![f64::NAN; p.dim()], vec![f64::NAN; p.dim()]))
    };
    let (mu, mu_std) = get(Param::MuScale);
    let (cof, _) = get(Param::CenterOfFriction);
    let (ic, ic_std) = get(Param::InertiaCm);
    let flag = |b: bool| if b { 1.0 } else { 0.0 };
    Ok(vec![
        dt,
        mu[0],
        mu_std[0],
        cof[0],
        cof[1],
        ic[0],
        ic_std[0],
        start_rms[0],
        start_rms[1],
        f.position_rms,
        f.theta_rms,
        engine_error[0],
        engine_error[1],
        flag(f.converged),
        flag(set.contains(&Param::CenterOfFriction)),
        flag(set.contains(&Param::InertiaCm)),
        // Which fitted parameters are near zero: 1 μ scale, 2 I_cm (a sum).
        f.degenerate
            .iter()
            .map(|why| {
                if why.starts_with(Param::MuScale.name()) {
                    1.0
                } else if why.starts_with(Param::InertiaCm.name()) {
                    2.0
                } else {
                    0.0
                }
            })
            .sum(),
    ])
}

/// Why a row is degenerate (empty when it is not): the fitted μ scale or
/// I_cm near zero ([`crate::fit::degenerate_reasons`]).
pub fn degenerate_reason(row: &[f64]) -> String {
    let bits = row[16] as u32;
    let mut why = Vec::new();
    if bits & 1 != 0 {
        why.push(format!("mu_scale {:.2e} (a frictionless plate)", row[1]));
    }
    if bits & 2 != 0 {
        why.push(format!(
            "inertia_cm {:.2e} kg m^2 (a massless plate)",
            row[5]
        ));
    }
    if why.is_empty() {
        return String::new();
    }
    format!(
        "near zero (at most {} x the file's value): {}",
        crate::fit::NEAR_ZERO,
        why.join(", ")
    )
}

/// What `coulomb_fit.csv` says of a row besides its numbers: the
/// parameters fitted, the verdict (`failed` where the fit did not run) and
/// why it failed or is degenerate (its commas read as `;`, as they always
/// have).
pub fn judged(row: &[f64]) -> [String; 3] {
    let fitted = match (row[14] == 1.0, row[15] == 1.0) {
        (true, true) => "mu_scale center_of_friction inertia_cm",
        (false, true) => "mu_scale inertia_cm",
        (true, false) => "mu_scale center_of_friction",
        _ => "mu_scale",
    };
    let verdict = if row[0].is_nan() {
        "failed"
    } else {
        verdict(row)
    };
    let reason = match verdict {
        "failed" => failure_reason(row).unwrap_or_default(),
        "degenerate" => degenerate_reason(row),
        _ => String::new(),
    };
    [fitted.into(), verdict.into(), reason.replace(',', ";")]
}

/// `[position, θ]` thresholds of a row: `max(10 e, 1e-6)`.
pub fn thresholds(row: &[f64]) -> [f64; 2] {
    [row[11], row[12]].map(|e| (THRESHOLD_FACTOR * e).max(1e-6))
}

/// The verdict of a row (see the module doc).
pub fn verdict(row: &[f64]) -> &'static str {
    if row[16] > 0.0 {
        return "degenerate";
    }
    let t = thresholds(row);
    let rms = [row[9], row[10]];
    if !(rms[0] <= t[0] && rms[1] <= t[1]) {
        "not_explained"
    } else if rms[0] <= THRESHOLD_CAP && rms[1] <= THRESHOLD_CAP {
        "explained"
    } else {
        "undecided"
    }
}
