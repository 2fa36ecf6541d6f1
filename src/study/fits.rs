//! Which Coulomb parameters each engine behaves as (`OUT/coulomb_fits.csv`,
//! and `OUT/mujoco/coulomb_fit.csv` with the `mujoco` feature): the Coulomb
//! model fitted to every informational engine's trajectory on the paper
//! plate by [`crate::fit`] (Levenberg–Marquardt on the dynamic model's fast
//! trajectory), and whether the fitted model explains the engine.
//!
//! # Scenes
//!
//! Two schedules of the same plate, read from the shipped scenario files
//! (so "the file's values" are theirs): `friction-engines.toml`, one push of
//! 6 s at 0.5 m/s with φ = π/4 + 0.3, and `paper-square-v1.0.toml`, the
//! paper's five 2 s segments at 1 m/s (five directions). Each engine runs
//! through the registry ([`crate::registry::engine`], [`Engine::run`]) at
//! a quarter of its default time step ([`fit_engine`] says why).
//!
//! # What is fitted
//!
//! `mu_scale` (μ of every support × this factor), `center_of_friction`
//! (the loads shifted to put it there) and `inertia_cm`, each kept only
//! when the schedule identifies it: the Fisher information of the full set
//! at the file's values ([`crate::fit::fisher_at`]) decides, the same for
//! every engine on a schedule. Parameters it marks unidentifiable are
//! dropped (and stay at the file's values); `mu_scale` is always fitted.
//! A single constant push leaves the centre of friction unidentifiable (only
//! ω* and one relaxation from ω = 0 show in it: μ and I_cm), so on
//! `friction-engines` the fit is of `mu_scale` and `inertia_cm`; the paper
//! schedule's five directions and impulsive switches identify all four
//! components.
//!
//! # Verdict
//!
//! The engine's own error is its Richardson estimate from a second run at
//! twice the step: `e = rms_k |X_k(2Δt) − X_k(Δt)| / (2^p − 1)` (p the
//! engine's order), for the position of the centre of mass (m) and θ (rad).
//! The threshold of each is `T = max(10 e, 1e-6)` (1 µm, 1 µrad: numerical
//! noise of the fit's own trajectory is far below). Per engine and schedule:
//!
//! * **explained**: the fit's residual rms is ≤ T in position and in θ, and
//!   ≤ 1 mm (1 mrad): these Coulomb parameters reproduce the engine to within
//!   what its own time step resolves;
//! * **not explained**: the residual exceeds T in position or θ: no Coulomb
//!   parameters (of those fitted) explain the engine;
//! * **undecided**: the residual is within T but above 1 mm (1 mrad), so T
//!   is larger still: the engine's own time-step error is too large to tell.

use std::path::Path;

use pushval_engine::Engine;
use pushval_model::Sample;
use pushval_scenario::Scenario;

use crate::fit::{fisher_at, fit, Param, Parametrised, Settings};
use crate::report::Writer;

use super::opt;

/// The engines whose Coulomb fit is written to `coulomb_fits.csv`, the
/// Coulomb engine (`rapier2d`, the control) first.
pub const ENGINES: [&str; 7] = [
    "rapier2d",
    "rapier2d_impulse_disk",
    "rapier2d_impulse_box",
    "rapier2d_regularised_linear",
    "rapier2d_regularised_tanh",
    "rapier3d",
    "rapier3d_simplified",
];
/// The quick run's engines (tests): the control and the one that locks.
pub const ENGINES_QUICK: [&str; 2] = ["rapier2d", "rapier2d_impulse_box"];
/// The engine fitted into `mujoco/coulomb_fit.csv` when the build has it.
pub const MUJOCO_ENGINE: &str = "mujoco_elliptic";

/// The scenario files of the schedules, single push first.
pub const SCHEDULES: [&str; 2] = ["friction-engines.toml", "paper-square-v1.0.toml"];

/// The parameters tried, in the order they are dropped when the schedule
/// does not identify them (`mu_scale` is never dropped).
const TRIED: [Param; 3] = [Param::InertiaCm, Param::CenterOfFriction, Param::MuScale];

/// Floor of the thresholds: 1 µm and 1 µrad.
pub const THRESHOLD_FLOOR: f64 = 1e-6;
/// The thresholds are this many times the engine's own error.
pub const THRESHOLD_FACTOR: f64 = 10.0;
/// Above this (m, rad) a threshold no longer decides: 1 mm, 1 mrad.
pub const THRESHOLD_CAP: f64 = 1e-3;

/// The output files (relative to the output folder).
pub const CSV: &str = "coulomb_fits.csv";
/// The MuJoCo fit, beside the MuJoCo study's files.
pub const MUJOCO_CSV: &str = "mujoco/coulomb_fit.csv";

/// The Coulomb-fit study.
#[derive(Debug, Clone, Copy)]
pub struct Fits {
    pub quick: bool,
}

/// One fit: an engine (its registry name) on a schedule (index into
/// [`SCHEDULES`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Task {
    pub engine: &'static str,
    pub schedule: usize,
}

/// The numbers of one fit, in the order of a task's row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitRow {
    /// The step of the fitted run (s): the engine's default over
    /// [`STEP_DIVISOR`].
    pub dt: f64,
    /// The engine's order of accuracy.
    pub order: f64,
    /// The engine's own error at `dt` (Richardson from the run at 2 dt, rms):
    /// position (m), θ (rad).
    pub engine_error: [f64; 2],
    /// The same at the engine's default step (from the runs at it and twice it).
    pub default_step_error: [f64; 2],
    /// Residual rms at the file's values (before the fit): position, θ.
    pub start_rms: [f64; 2],
    /// Estimates: μ scale, centre of friction x, y (m, the file's object
    /// frame), I_cm (kg m²); the file's values where not fitted.
    pub value: [f64; 4],
    /// Their std: the fit's (`s² (JᵀJ)⁻¹`) combined with `dt_error`; NaN
    /// where not fitted.
    pub std: [f64; 4],
    /// Their time-step error: the same fit to the run at 2 dt, Richardson
    /// `|p(2dt) − p(dt)| / (2^order − 1)`; NaN where not fitted.
    pub dt_error: [f64; 4],
    /// Residual rms of the fit: position (m), θ (rad).
    pub rms: [f64; 2],
    /// 1 when the solver converged.
    pub converged: f64,
    /// 1 where the parameter was fitted: centre of friction, I_cm.
    pub fitted: [f64; 2],
    /// 1 where the fit's own Fisher analysis (at the estimate) finds a
    /// fitted parameter unidentifiable: centre of friction, I_cm, μ scale.
    pub unidentifiable: [f64; 3],
    /// Residual evaluations the solver used.
    pub evaluations: f64,
}

impl FitRow {
    const WIDTH: usize = 29;

    fn to_vec(self) -> Vec<f64> {
        let mut v = vec![self.dt, self.order];
        v.extend(self.engine_error);
        v.extend(self.default_step_error);
        v.extend(self.start_rms);
        v.extend(self.value);
        v.extend(self.std);
        v.extend(self.dt_error);
        v.extend(self.rms);
        v.push(self.converged);
        v.extend(self.fitted);
        v.extend(self.unidentifiable);
        v.push(self.evaluations);
        debug_assert_eq!(v.len(), Self::WIDTH);
        v
    }

    /// The row of a task (as [`Self::to_vec`] wrote it).
    pub fn from_slice(r: &[f64]) -> Self {
        let a2 = |i: usize| [r[i], r[i + 1]];
        let a4 = |i: usize| [r[i], r[i + 1], r[i + 2], r[i + 3]];
        Self {
            dt: r[0],
            order: r[1],
            engine_error: a2(2),
            default_step_error: a2(4),
            start_rms: a2(6),
            value: a4(8),
            std: a4(12),
            dt_error: a4(16),
            rms: a2(20),
            converged: r[22],
            fitted: a2(23),
            unidentifiable: [r[25], r[26], r[27]],
            evaluations: r[28],
        }
    }

    /// `[position, θ]` thresholds: `max(10 e, 1e-6)`.
    pub fn threshold(&self) -> [f64; 2] {
        self.engine_error
            .map(|e| (THRESHOLD_FACTOR * e).max(THRESHOLD_FLOOR))
    }

    /// The verdict (see the module doc).
    pub fn verdict(&self) -> Verdict {
        let t = self.threshold();
        let within = self.rms[0] <= t[0] && self.rms[1] <= t[1];
        if !within || self.rms.iter().any(|r| !r.is_finite()) {
            Verdict::NotExplained
        } else if self.rms[0] <= THRESHOLD_CAP && self.rms[1] <= THRESHOLD_CAP {
            Verdict::Explained
        } else {
            Verdict::Undecided
        }
    }
}

/// Whether a Coulomb fit explains an engine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    Explained,
    NotExplained,
    Undecided,
}

impl Verdict {
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Explained => "explained",
            Verdict::NotExplained => "not_explained",
            Verdict::Undecided => "undecided",
        }
    }
}

/// The scenario of schedule `k` from the shipped scenarios.
pub fn schedule(k: usize) -> anyhow::Result<Scenario> {
    let dir = crate::report::default_scenario_dir();
    Ok(crate::registry::load(dir.join(SCHEDULES[k]))?)
}

/// The parameters the schedule identifies: the full set, less those the
/// Fisher information at the file's values marks unidentifiable (dropped in
/// [`TRIED`] order, one at a time, until the rest is identifiable).
pub fn identified(sc: &Scenario, settings: &Settings) -> anyhow::Result<Vec<Param>> {
    let mut set: Vec<Param> = TRIED.to_vec();
    loop {
        let model = Parametrised::new(sc, &set).map_err(anyhow::Error::msg)?;
        let f = fisher_at(&model, &model.file_values(), settings).map_err(anyhow::Error::msg)?;
        let slots = model.slots();
        let bad: Vec<Param> = slots
            .iter()
            .zip(&f.unidentifiable)
            .filter(|(_, u)| **u)
            .map(|((p, _), _)| *p)
            .collect();
        let Some(drop) = TRIED
            .iter()
            .find(|p| **p != Param::MuScale && bad.contains(p))
        else {
            return Ok(set);
        };
        set.retain(|p| p != drop);
    }
}

/// RMS over the samples of the centre of mass's distance and of the angle
/// difference between two runs on the same grid.
pub fn rms_difference(a: &[Sample], b: &[Sample]) -> [f64; 2] {
    let n = a.len().min(b.len()).max(1) as f64;
    let (mut p, mut t) = (0.0, 0.0);
    for (s, r) in a.iter().zip(b) {
        p += (s.x - r.x).powi(2) + (s.y - r.y).powi(2);
        t += (s.theta - r.theta).powi(2);
    }
    [(p / n).sqrt(), (t / n).sqrt()]
}

/// The fitted run's step is the engine's default over this (see
/// [`fit_engine`]).
pub const STEP_DIVISOR: f64 = 4.0;

/// The file's values `[μ scale = 1, centre of friction x, y (m), I_cm (kg m²)]`.
pub fn file_values(sc: &Scenario) -> anyhow::Result<[f64; 4]> {
    let v = Parametrised::new(sc, &TRIED)
        .map_err(anyhow::Error::msg)?
        .file_values();
    // Parametrised orders its slots as Param::ALL: centre (x, y), I_cm, μ.
    Ok([v[3], v[0], v[1], v[2]])
}

/// Which of `[μ scale, x, y, I_cm]` the parameter set fits.
fn slots_fitted(set: &[Param]) -> [bool; 4] {
    let cof = set.contains(&Param::CenterOfFriction);
    [
        set.contains(&Param::MuScale),
        cof,
        cof,
        set.contains(&Param::InertiaCm),
    ]
}

/// One fit to `data` from the file's values: the estimate and the fit's std
/// as `[μ scale, x, y, I_cm]` (the file's value and NaN where not fitted),
/// and the fit.
fn fit_once(
    model: &Parametrised,
    data: &[Sample],
    file: [f64; 4],
    settings: &Settings,
) -> anyhow::Result<([f64; 4], [f64; 4], crate::fit::Fit)> {
    let f = fit(model, data, &model.file_values(), settings).map_err(anyhow::Error::msg)?;
    let (mut value, mut std) = (file, [f64::NAN; 4]);
    for (p, at) in [
        (Param::MuScale, 0),
        (Param::CenterOfFriction, 1),
        (Param::InertiaCm, 3),
    ] {
        if let Some((v, s)) = f.get(p) {
            value[at..at + v.len()].copy_from_slice(&v);
            std[at..at + s.len()].copy_from_slice(&s);
        }
    }
    Ok((value, std, f))
}

/// Runs `engine` on the scenario and fits the parameters the schedule
/// identifies ([`identified`]) to its trajectory.
///
/// The fitted run is at the engine's default step over [`STEP_DIVISOR`];
/// its error and each parameter's time-step error come from a second run
/// (and fit) at twice that step, and the default step's own error from runs
/// at the default and twice it. (Why not the default step itself: rapier3d's
/// rest loads settle to a split that depends on the step, and on the paper
/// schedule its run at 1 ms differs by 0.08 rad from its runs at 0.5 and
/// 2 ms, which agree within 1 mrad; the CSV's `default_step_error` columns
/// show it.)
pub fn fit_engine(sc: &Scenario, engine: &dyn Engine) -> anyhow::Result<FitRow> {
    let settings = Settings::default();
    let problem = sc.problem();
    let default_dt = engine.default_dt();
    let dt = default_dt / STEP_DIVISOR;
    let run = |h: f64| {
        engine
            .run(&problem, h)
            .map(|r| r.trajectory.samples)
            .map_err(|e| anyhow::anyhow!("{} at dt = {h}: {e}", engine.name()))
    };
    let data = run(dt)?;
    let coarse = run(2.0 * dt)?;
    let at_default = run(default_dt)?;
    let at_double = run(2.0 * default_dt)?;
    crate::fit::check_grid(sc, &data).map_err(anyhow::Error::msg)?;
    let order = engine.order();
    let k = 1.0 / (2f64.powf(order) - 1.0);
    let engine_error = rms_difference(&coarse, &data).map(|d| k * d);
    let default_step_error = rms_difference(&at_double, &at_default).map(|d| k * d);

    let set = identified(sc, &settings)?;
    let model = Parametrised::new(sc, &set).map_err(anyhow::Error::msg)?;
    let file = file_values(sc)?;
    let reference = pushval_model::Simulator::simulate(
        &pushval_model::DynamicModel::default(),
        &model
            .problem(&model.file_values())
            .map_err(|e| anyhow::anyhow!("{e}"))?,
    )?;
    let start_rms = rms_difference(&reference.samples, &data);
    let (value, fit_std, f) = fit_once(&model, &data, file, &settings)?;
    let (value_coarse, _, _) = fit_once(&model, &coarse, file, &settings)?;
    let fitted = slots_fitted(&set);
    let mut std = [f64::NAN; 4];
    let mut dt_error = [f64::NAN; 4];
    for i in 0..4 {
        if fitted[i] {
            dt_error[i] = k * (value_coarse[i] - value[i]).abs();
            std[i] = fit_std[i].hypot(dt_error[i]);
        }
    }
    let flag = |p: Param| f64::from(u8::from(f.unidentifiable.contains(&p)));
    let has = |p: Param| f64::from(u8::from(set.contains(&p)));
    Ok(FitRow {
        dt,
        order,
        engine_error,
        default_step_error,
        start_rms,
        value,
        std,
        dt_error,
        rms: [f.position_rms, f.theta_rms],
        converged: f64::from(u8::from(f.converged)),
        fitted: [has(Param::CenterOfFriction), has(Param::InertiaCm)],
        unidentifiable: [
            flag(Param::CenterOfFriction),
            flag(Param::InertiaCm),
            flag(Param::MuScale),
        ],
        evaluations: f.evaluations as f64,
    })
}

impl Fits {
    fn engines(&self) -> Vec<&'static str> {
        let mut v: Vec<&'static str> = if self.quick {
            ENGINES_QUICK.to_vec()
        } else {
            ENGINES.to_vec()
        };
        if mujoco_available() {
            v.push(MUJOCO_ENGINE);
        }
        v
    }
}

/// Whether this build runs [`MUJOCO_ENGINE`].
pub fn mujoco_available() -> bool {
    crate::registry::entry(MUJOCO_ENGINE).is_some_and(|e| e.default_engine().availability().is_ok())
}

impl super::Study for Fits {
    type Task = Task;

    fn name(&self) -> &'static str {
        "coulomb_fits"
    }

    fn dir(&self) -> &'static str {
        ""
    }

    fn tasks(&self) -> Vec<Task> {
        let mut t = Vec::new();
        for engine in self.engines() {
            for schedule in 0..SCHEDULES.len() {
                t.push(Task { engine, schedule });
            }
        }
        t
    }

    fn width(&self, _task: &Task) -> Option<usize> {
        Some(FitRow::WIDTH)
    }

    fn eval(&self, task: &Task) -> Vec<f64> {
        let sc = schedule(task.schedule).expect("the shipped scenarios load");
        let engine = crate::registry::engine(task.engine, &sc.engine);
        fit_engine(&sc, engine.as_ref())
            .unwrap_or_else(|e| panic!("Coulomb fit of {}: {e:#}", task.engine))
            .to_vec()
    }

    fn write(
        &self,
        tasks: &[Task],
        rows: &[Vec<f64>],
        _out: &Path,
        w: &mut Writer,
    ) -> anyhow::Result<()> {
        let mut main = csv_header();
        let mut mujoco = csv_header();
        for (t, r) in tasks.iter().zip(rows) {
            let sc = schedule(t.schedule)?;
            let line = csv_line(t.engine, &sc, &FitRow::from_slice(r))?;
            if t.engine == MUJOCO_ENGINE {
                mujoco.push_str(&line);
            } else {
                main.push_str(&line);
            }
        }
        w.file(CSV, main.as_bytes())?;
        if tasks.iter().any(|t| t.engine == MUJOCO_ENGINE) {
            w.file(MUJOCO_CSV, mujoco.as_bytes())?;
        }
        Ok(())
    }
}

/// The columns of the CSV files.
pub const COLUMNS: [&str; 38] = [
    "engine",
    "schedule",
    "segments",
    "fitted",
    "dt",
    "order",
    "engine_error_position",
    "engine_error_theta",
    "threshold_position",
    "threshold_theta",
    "default_dt",
    "default_step_error_position",
    "default_step_error_theta",
    "start_position_rms",
    "start_theta_rms",
    "mu_file",
    "mu_scale",
    "mu_scale_std",
    "mu_scale_dt_error",
    "mu_effective",
    "mu_effective_std",
    "cof_file_x",
    "cof_file_y",
    "cof_x",
    "cof_y",
    "cof_x_std",
    "cof_y_std",
    "cof_dt_error",
    "inertia_cm_file",
    "inertia_cm",
    "inertia_cm_std",
    "inertia_cm_dt_error",
    "position_rms",
    "theta_rms",
    "converged",
    "unidentifiable",
    "evaluations",
    "verdict",
];

fn csv_header() -> String {
    let mut s = COLUMNS.join(",");
    s.push('\n');
    s
}

/// The file's μ (one value for every support: the schedules' plate).
fn file_mu(sc: &Scenario) -> f64 {
    sc.supports.first().map_or(f64::NAN, |s| s.mu)
}

fn csv_line(engine: &str, sc: &Scenario, r: &FitRow) -> anyhow::Result<String> {
    let file = file_values(sc)?;
    let mut fitted = vec!["mu_scale"];
    if r.fitted[0] == 1.0 {
        fitted.push("center_of_friction");
    }
    if r.fitted[1] == 1.0 {
        fitted.push("inertia_cm");
    }
    let unident: Vec<&str> = [
        (r.unidentifiable[0], "center_of_friction"),
        (r.unidentifiable[1], "inertia_cm"),
        (r.unidentifiable[2], "mu_scale"),
    ]
    .iter()
    .filter(|(f, _)| *f == 1.0)
    .map(|(_, n)| *n)
    .collect();
    let mu = file_mu(sc);
    let t = r.threshold();
    let fields: Vec<String> = vec![
        engine.to_string(),
        sc.name.clone(),
        sc.pushes.len().to_string(),
        fitted.join("+"),
        opt(r.dt),
        opt(r.order),
        opt(r.engine_error[0]),
        opt(r.engine_error[1]),
        opt(t[0]),
        opt(t[1]),
        opt(r.dt * STEP_DIVISOR),
        opt(r.default_step_error[0]),
        opt(r.default_step_error[1]),
        opt(r.start_rms[0]),
        opt(r.start_rms[1]),
        opt(mu),
        opt(r.value[0]),
        opt(r.std[0]),
        opt(r.dt_error[0]),
        opt(mu * r.value[0]),
        opt(mu * r.std[0]),
        opt(file[1]),
        opt(file[2]),
        opt(r.value[1]),
        opt(r.value[2]),
        opt(r.std[1]),
        opt(r.std[2]),
        opt(r.dt_error[1].hypot(r.dt_error[2])),
        opt(file[3]),
        opt(r.value[3]),
        opt(r.std[3]),
        opt(r.dt_error[3]),
        opt(r.rms[0]),
        opt(r.rms[1]),
        (r.converged == 1.0).to_string(),
        unident.join("+"),
        opt(r.evaluations),
        r.verdict().as_str().to_string(),
    ];
    debug_assert_eq!(fields.len(), COLUMNS.len());
    let mut s = fields.join(",");
    s.push('\n');
    Ok(s)
}

type Row = std::collections::HashMap<String, String>;

fn field(r: &Row, k: &str) -> f64 {
    r.get(k)
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(f64::NAN)
}

fn text<'a>(r: &'a Row, k: &str) -> &'a str {
    r.get(k).map_or("", String::as_str)
}

/// `a ± b`, both times `unit_scale`, `a` to the decimals of `b`'s second
/// significant digit (`a (fixed)` where `b` is NaN: not fitted).
fn pm(a: f64, b: f64, unit_scale: f64) -> String {
    let (a, b) = (a * unit_scale, b * unit_scale);
    if !b.is_finite() {
        return format!("{a:.4} (fixed)");
    }
    if b == 0.0 {
        return format!("{a:.6} ± 0");
    }
    let decimals = (1 - b.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{a:.decimals$} ± {b:.1e}")
}

fn verdict_text(v: &str) -> &'static str {
    match v {
        "explained" => "**explained**",
        "not_explained" => "not explained: no Coulomb parameters explain it",
        "undecided" => {
            "undecided (residual above 1 mm / 1 mrad, within the engine's own step error)"
        }
        _ => "—",
    }
}

/// The README section on the Coulomb fits, from `OUT/coulomb_fits.csv` and
/// (when a build with the `mujoco` feature wrote it) `OUT/mujoco/coulomb_fit.csv`.
/// `idioms` puts it into `OUT/README.md`; `study all` runs this study first.
pub fn readme_section(out: &Path) -> String {
    let mut md = String::from("## Which Coulomb parameters each engine behaves as\n\n");
    let Some(mut rows) = super::idioms::read_csv(&out.join(CSV)) else {
        md.push_str(&format!(
            "(`{CSV}` not generated yet: `pushval study coulomb_fits`.)\n\n"
        ));
        return md;
    };
    let mujoco = super::idioms::read_csv(&out.join(MUJOCO_CSV));
    if let Some(m) = &mujoco {
        rows.extend(m.iter().cloned());
    }
    let schedules: Vec<(String, String)> = {
        let mut v: Vec<(String, String)> = Vec::new();
        for r in &rows {
            let s = (
                text(r, "schedule").to_string(),
                text(r, "fitted").to_string(),
            );
            if !v.iter().any(|(n, _)| *n == s.0) {
                v.push(s);
            }
        }
        v
    };
    let fitted_on = |name: &str| {
        schedules
            .iter()
            .find(|(n, _)| n == name)
            .map_or(String::new(), |(_, f)| f.replace('+', ", "))
    };
    let single = SCHEDULES[0].trim_end_matches(".toml");
    let multi = SCHEDULES[1].trim_end_matches(".toml");
    let rapier = rows.iter().find(|r| text(r, "engine") == ENGINES[0]);
    let divisor = STEP_DIVISOR;
    md.push_str(&format!(
        "Generated by `pushval study coulomb_fits` (data: `{CSV}`; MuJoCo's in `{MUJOCO_CSV}`, \
         written only by a build with `--features mujoco`). The Coulomb model is fitted to the \
         trajectory of each of {fitted} (built by default) and, with `--features mujoco`, \
         {MUJOCO_ENGINE}; Box2D, Avian and PhysX are not fitted here: their own studies \
         (`box2d/`, `avian/`, `physx/`) test each against the closed form of its friction law \
         instead. The fit is `pushval fit`'s Levenberg–Marquardt (x, y and θ at every 10 ms \
         sample, from the file's values) on two schedules of the paper plate: `{single}` (one \
         push, 6 s at 0.5 m/s, φ = π/4 + 0.3) and `{multi}` (the paper's five 2 s segments at \
         1 m/s in five directions). Fitted: the parameters the schedule identifies, by the Fisher \
         information of the full set (μ scale, centre of friction, I_cm) at the file's values: \
         on `{single}` {fs}; on `{multi}` {fm} (a single constant push shows only ω* and one \
         relaxation, not where the friction acts). The rest stay at the file's values. Effective \
         μ = μ scale × {mu}. Each engine runs through the registry at its default step / \
         {divisor} (the fitted run) and at twice that; the engine's own error e is the Richardson \
         estimate `rms |X(2Δt) − X(Δt)| / (2^p − 1)` (position of the centre of mass, θ), and each \
         std combines the fit's `s² (JᵀJ)⁻¹` with the parameter's time-step error (the same fit \
         to the 2Δt run, Richardson). **Verdict**: explained when the residual rms is at most \
         T = max({fac} e, 1 µm) in position and max({fac} e, 1 µrad) in θ, and at most 1 mm / \
         1 mrad; not explained when it exceeds T (no Coulomb parameters explain the engine); \
         undecided when it is within T but above 1 mm / 1 mrad (T larger still: the \
         engine's own step error is too large to tell).\n\n",
        fitted = ENGINES.join(", "),
        fs = fitted_on(single),
        fm = fitted_on(multi),
        mu = rapier.map_or(f64::NAN, |r| field(r, "mu_file")),
        fac = THRESHOLD_FACTOR,
    ));
    for (sched, title) in [
        (multi, "five segments (identifies the centre of friction)"),
        (single, "one push"),
    ] {
        md.push_str(&format!("### `{sched}`: {title}\n\n"));
        md.push_str(
            "| engine | Δt (s) | effective μ | centre of friction (mm) | I_cm (kg m²) | residual rms: position (m), θ (rad) | threshold T: position, θ | verdict |\n\
             |---|---|---|---|---|---|---|---|\n",
        );
        for r in rows.iter().filter(|r| text(r, "schedule") == sched) {
            let cof = if text(r, "fitted").contains("center_of_friction") {
                format!(
                    "({}, {})",
                    pm(field(r, "cof_x"), field(r, "cof_x_std"), 1e3),
                    pm(field(r, "cof_y"), field(r, "cof_y_std"), 1e3)
                )
            } else {
                format!(
                    "({:.1}, {:.1}) (fixed)",
                    1e3 * field(r, "cof_x"),
                    1e3 * field(r, "cof_y")
                )
            };
            let inertia = if text(r, "unidentifiable").contains("inertia_cm") {
                format!("{:.3e} (unidentifiable here)", field(r, "inertia_cm"))
            } else {
                pm(field(r, "inertia_cm"), field(r, "inertia_cm_std"), 1.0)
            };
            md.push_str(&format!(
                "| {} | {} | {} | {cof} | {inertia} | {:.2e}, {:.2e} | {:.1e}, {:.1e} | {} |\n",
                text(r, "engine"),
                super::dt_label(field(r, "dt")),
                pm(field(r, "mu_effective"), field(r, "mu_effective_std"), 1.0),
                field(r, "position_rms"),
                field(r, "theta_rms"),
                field(r, "threshold_position"),
                field(r, "threshold_theta"),
                verdict_text(text(r, "verdict")),
            ));
        }
        md.push('\n');
    }
    md.push_str(&fit_findings(&rows, single, multi, mujoco.is_some()));
    md
}

/// The bullets under the tables, every number from the rows.
fn fit_findings(rows: &[Row], single: &str, multi: &str, mujoco: bool) -> String {
    let mut md = String::new();
    let find = |engine: &str, sched: &str| {
        rows.iter()
            .find(|r| text(r, "engine") == engine && text(r, "schedule") == sched)
    };
    if let Some(r) = find(ENGINES[0], multi) {
        let (mu, s) = (field(r, "mu_scale"), field(r, "mu_scale_std"));
        let d = (field(r, "cof_x") - field(r, "cof_file_x"))
            .hypot(field(r, "cof_y") - field(r, "cof_file_y"));
        let di = field(r, "inertia_cm") / field(r, "inertia_cm_file") - 1.0;
        md.push_str(&format!(
            "* **The control.** rapier2d (Coulomb force at every support) on `{multi}`: μ scale \
             {mu:.8} (|μ scale − 1| = {:.1} std), centre of friction {:.2e} m from the file's, \
             I_cm {:+.1e} relative to the file's, residual {:.1e} m and {:.1e} rad against T = \
             {:.1e} m, {:.1e} rad: the fit recovers the file's parameters to within the engine's \
             own time-step error and explains it.\n",
            (mu - 1.0).abs() / s,
            d,
            di,
            field(r, "position_rms"),
            field(r, "theta_rms"),
            field(r, "threshold_position"),
            field(r, "threshold_theta"),
        ));
    }
    let zero_mu: Vec<&str> = rows
        .iter()
        .filter(|r| {
            text(r, "schedule") == single
                && text(r, "verdict") == "explained"
                && field(r, "mu_scale") < 1e-3
        })
        .map(|r| text(r, "engine"))
        .collect();
    if !zero_mu.is_empty() {
        let refuted: Vec<String> = zero_mu
            .iter()
            .filter_map(|e| find(e, multi))
            .filter(|r| text(r, "verdict") == "not_explained")
            .map(|r| {
                format!(
                    "{} ({:.3} m, {:.3} rad)",
                    text(r, "engine"),
                    field(r, "position_rms"),
                    field(r, "theta_rms")
                )
            })
            .collect();
        md.push_str(&format!(
            "* **One push explains a lock by μ → 0.** On `{single}` {} are \"explained\" with \
             μ scale below 1e-3: a frictionless plate pushed from ω = 0 keeps its orientation \
             and translates with the pusher, which is what an engine that locks the orientation \
             does on one push. The five segments refute it: not explained there: {}.\n",
            zero_mu.join(", "),
            if refuted.is_empty() {
                "none".to_string()
            } else {
                refuted.join(", ")
            }
        ));
    }
    let anomalies: Vec<String> = rows
        .iter()
        .filter(|r| {
            field(r, "default_step_error_position") > 10.0 * field(r, "engine_error_position")
                && field(r, "default_step_error_position") > 1e-3
        })
        .map(|r| {
            format!(
                "{} on `{}` ({:.3} m, {:.3} rad at Δt = {}; {:.1e} m, {:.1e} rad at {})",
                text(r, "engine"),
                text(r, "schedule"),
                field(r, "default_step_error_position"),
                field(r, "default_step_error_theta"),
                super::dt_label(field(r, "default_dt")),
                field(r, "engine_error_position"),
                field(r, "engine_error_theta"),
                super::dt_label(field(r, "dt")),
            )
        })
        .collect();
    if !anomalies.is_empty() {
        md.push_str(&format!(
            "* **Why a step finer than the default.** The engine's own error at its default step \
             exceeds 1 mm and 10 times that at the fitted step for {}: at the default step the \
             verdict would say more about the step than about the friction law.\n",
            anomalies.join("; ")
        ));
    }
    for r in rows.iter().filter(|r| text(r, "verdict") == "undecided") {
        md.push_str(&format!(
            "* **Undecided: {} on `{}`.** The fit leaves {:.2e} m and {:.2e} rad, but the \
             engine's own runs at Δt = {} and twice it differ by e = {:.2e} m and {:.2e} rad \
             (Richardson, order {}), and the fitted parameters move with the step (μ scale by \
             {:.1e}{}{}): each run behaves as a Coulomb plate, a slightly different one at each \
             step, so whether one Coulomb plate explains the engine to 1 mm / 1 mrad is not \
             resolved.\n",
            text(r, "engine"),
            text(r, "schedule"),
            field(r, "position_rms"),
            field(r, "theta_rms"),
            super::dt_label(field(r, "dt")),
            field(r, "engine_error_position"),
            field(r, "engine_error_theta"),
            field(r, "order"),
            field(r, "mu_scale_dt_error"),
            if field(r, "cof_dt_error").is_finite() {
                format!(
                    ", the centre of friction by {:.1} mm",
                    1e3 * field(r, "cof_dt_error")
                )
            } else {
                String::new()
            },
            if field(r, "inertia_cm_dt_error").is_finite() {
                format!(", I_cm by {:.1e} kg m²", field(r, "inertia_cm_dt_error"))
            } else {
                String::new()
            },
        ));
    }
    if !mujoco {
        md.push_str(&format!(
            "* MuJoCo ({MUJOCO_ENGINE}): skipped, not in this build and no `{MUJOCO_CSV}` from \
             an earlier one: {}.\n",
            super::MUJOCO_FEATURE
        ));
    }
    md.push('\n');
    md
}
