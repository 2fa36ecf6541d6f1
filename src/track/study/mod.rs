//! `pushval track-study`: what online friction estimation costs and how
//! well it does, on the seed paper's pushes (`scenarios/paper-square-v*.toml`:
//! the 0.25 m plate, five 2 s segments at 0.2, 0.6 and 1.0 m/s).
//!
//! Truth: the scenario with μ × 1.1 and I_cm × 0.95 (centre of friction as
//! in the file), the dynamic model's DOP853 trajectory at tolerance 1e-11
//! sampled at the study's rate, plus Gaussian noise (fixed seeds) on x, y
//! and θ. The estimators start from the file's values. Writes into OUT:
//!
//! * `track_cost.csv`: thread CPU time per update (median, 99th
//!   percentile) of each method at 1 kHz, and of the clock call pair itself;
//! * `track_convergence.csv`: per scenario, method, rate (30 Hz to 1 kHz)
//!   and noise (0.1 to 3 mm with as many mrad): the time after which each
//!   estimate stays within 1 % (μ), 1 mm (centre of friction, both
//!   components) or 2 % (I_cm) of the truth, the median over the seeds
//!   (empty when a seed never gets there);
//! * `track_efficiency.csv`: the final estimates' empirical std over
//!   [`SEEDS_EFFICIENCY`] seeds against the Cramér–Rao bound of `pushval
//!   fit`'s Fisher information at the truth, `efficiency = (σ_CRB / σ)²`;
//! * `track_step.csv`: μ stepping by +20 % at t = 5 s (mid-segment) on the
//!   1 m/s push: when the lack-of-fit test fires and when the estimate is
//!   back within 1 % of the new μ, with and without re-opening;
//! * `track_engines.csv`: the filter run on every engine of the build (and
//!   on the dynamic model) on `paper-square-v1.0`: lack-of-fit episodes and
//!   the apparent parameters at each segment's end;
//! * `track.svg` and `track.md` (every number from these files).
//!
//! The study is one pipeline: this module holds what every stage shares
//! (the truth, the methods, the settings grid) and runs the stages in order
//! ([`cli`]); [`measure`] times and scores the estimators on the truth (cost,
//! convergence, efficiency), [`step`] follows a step in μ, [`engines`]
//! tracks every engine, and [`write_up`] draws `track.svg` and writes
//! `track.md` from the stages' rows.

use std::path::{Path, PathBuf};

mod engines;
mod measure;
mod step;
mod write_up;

use engines::engines;
use measure::{convergence, cost, efficiency};
use step::step;
use write_up::{figure, figure_run, md_text};

use anyhow::Context;
use pushval_model::track::{Ekf, EkfSettings, Estimator, Free, Measurement, Rls, RlsSettings};
use pushval_model::{DynamicModel, Initial, Integrator, Problem, Sample, Simulator, Vec2};
use pushval_scenario::Scenario;
use rayon::prelude::*;

use super::{thread_cpu_time, track_model};
use crate::atomic::write_atomic;
use crate::fit::{fisher_at, noise, Param, Parametrised, Settings};
use crate::outdir::{records, Csv};
use crate::plot::{self, Axis, Figure, Legend, Panel, Series, Stroke};

/// The broad prior of [`Method::EkfBroadPrior`].
pub const BROAD_PRIOR: [f64; 3] = [0.5, 0.25, 0.5];
/// The truth's factor on μ.
pub const MU_FACTOR: f64 = 1.1;
/// The truth's factor on I_cm.
pub const INERTIA_FACTOR: f64 = 0.95;
/// Seeds per efficiency point.
pub const SEEDS_EFFICIENCY: u64 = 40;
/// Seeds per convergence cell.
pub const SEEDS_CONVERGENCE: u64 = 5;
/// The μ step of the change test (relative).
pub const STEP: f64 = 0.2;
/// When μ steps (s).
pub const STEP_AT: f64 = 5.0;

/// Per sample: time (s), estimate `[mu_scale, c_x, c_y, I_cm]` and its std.
type History = Vec<(f64, [f64; 4], [f64; 4])>;

/// One method of the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// [`Ekf`] with default settings.
    Ekf,
    /// [`Rls`] with a window of about 0.2 s (at least 5 samples).
    Rls,
    /// [`Ekf`] told the start state exactly (std 1e-9), as `pushval fit`'s
    /// Fisher information assumes.
    EkfKnownStart,
    /// [`Ekf`] with a broad prior (μ ±50 %, centre of friction ±25 % of the
    /// size, I_cm ±50 %).
    EkfBroadPrior,
    /// [`Method::EkfKnownStart`] started at the truth instead of the file's
    /// values: whether what it lacks comes from linearising far from it.
    EkfKnownStartAtTruth,
}

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Ekf => "ekf",
            Method::Rls => "rls",
            Method::EkfKnownStart => "ekf_known_start",
            Method::EkfBroadPrior => "ekf_broad_prior",
            Method::EkfKnownStartAtTruth => "ekf_known_start_at_truth",
        }
    }
}

fn estimator(sc: &Scenario, method: Method, rate: f64, sp: f64, st: f64) -> Box<dyn Estimator> {
    let md = track_model(sc).expect("the paper scenarios load");
    match method {
        Method::Ekf => Box::new(Ekf::new(
            md,
            Free::default(),
            EkfSettings {
                sigma_position: sp,
                sigma_theta: st,
                initial_std: [sp, st, 1e-2],
                ..Default::default()
            },
            None,
        )),
        Method::EkfKnownStart | Method::EkfKnownStartAtTruth => Box::new(Ekf::new(
            md,
            Free::default(),
            EkfSettings {
                sigma_position: sp,
                sigma_theta: st,
                initial_std: [1e-9; 3],
                ..Default::default()
            },
            (method == Method::EkfKnownStartAtTruth).then(|| truth(sc).2),
        )),
        Method::EkfBroadPrior => Box::new(Ekf::new(
            md,
            Free::default(),
            EkfSettings {
                sigma_position: sp,
                sigma_theta: st,
                initial_std: [sp, st, 1e-2],
                prior: BROAD_PRIOR,
                ..Default::default()
            },
            None,
        )),
        Method::Rls => Box::new(Rls::new(
            md,
            Free::default(),
            RlsSettings {
                window: ((0.2 * rate).round() as usize).max(5),
                sigma_theta: st,
                ..Default::default()
            },
        )),
    }
}

/// The truth's parameter values `[c_x, c_y, I_cm, mu_scale]` in
/// [`Parametrised`]'s order, and as the estimators report them
/// `[mu_scale, c_x, c_y, I_cm]` (c from the centre of mass).
fn truth(sc: &Scenario) -> (Parametrised, Vec<f64>, [f64; 4]) {
    let pm = Parametrised::new(
        sc,
        &[Param::CenterOfFriction, Param::InertiaCm, Param::MuScale],
    )
    .expect("the paper plate's supports carry a centre of friction");
    let mut v = pm.file_values();
    v[2] *= INERTIA_FACTOR;
    v[3] = MU_FACTOR;
    let c = Vec2::new(v[0], v[1]) - sc.center_of_mass;
    (pm, v.clone(), [v[3], c.x, c.y, v[2]])
}

fn simulate(problem: &Problem) -> Vec<Sample> {
    DynamicModel {
        integrator: Integrator::Dop853 { tol: 1e-11 },
        check_assumptions: false,
        ..Default::default()
    }
    .simulate(problem)
    .expect("the paper pushes run")
    .samples
}

fn measurements(s: &[Sample]) -> Vec<Measurement> {
    s.iter()
        .map(|s| Measurement {
            t: s.t,
            x: s.x,
            y: s.y,
            theta: s.theta,
            omega: None,
            force: None,
        })
        .collect()
}

/// A shipped scenario (the binary's own copy: the study measures pushval's
/// scenarios whatever folder it runs in).
fn load(name: &str) -> anyhow::Result<Scenario> {
    crate::shipped::scenario(name)
}

/// The paper pushes.
pub const SCENARIOS: [&str; 3] = [
    "paper-square-v0.2.toml",
    "paper-square-v0.6.toml",
    "paper-square-v1.0.toml",
];

/// The study's grids.
#[derive(Debug, Clone)]
pub struct Grid {
    /// Sample rates (Hz).
    pub rates: Vec<f64>,
    /// Noise levels: position (m) and θ (rad) in pairs.
    pub noise: Vec<(f64, f64)>,
    /// Scenario files.
    pub scenarios: Vec<&'static str>,
    /// Seeds per convergence cell.
    pub seeds: u64,
    /// Seeds per efficiency point.
    pub seeds_efficiency: u64,
    /// Updates timed per method.
    pub cost_updates: usize,
}

impl Grid {
    /// The full grids, or the reduced ones of `--quick`.
    pub fn new(quick: bool) -> Self {
        if quick {
            Self {
                rates: vec![30.0, 1000.0],
                noise: vec![(1e-3, 1e-3)],
                scenarios: vec![SCENARIOS[2]],
                seeds: 2,
                seeds_efficiency: 6,
                cost_updates: 2000,
            }
        } else {
            Self {
                rates: vec![30.0, 100.0, 300.0, 1000.0],
                noise: vec![(1e-4, 1e-4), (3e-4, 3e-4), (1e-3, 1e-3), (3e-3, 3e-3)],
                scenarios: SCENARIOS.to_vec(),
                seeds: SEEDS_CONVERGENCE,
                seeds_efficiency: SEEDS_EFFICIENCY,
                cost_updates: usize::MAX,
            }
        }
    }
}

/// The truth trajectory of `sc` at `rate`.
fn truth_samples(sc: &Scenario, rate: f64) -> Vec<Sample> {
    let mut sc = sc.clone();
    sc.sample_dt = 1.0 / rate;
    let (pm, v, _) = truth(&sc);
    simulate(&pm.problem(&v).expect("the truth is a problem"))
}

/// Runs `est` over `data`; returns `(t, value, std)` per sample.
fn run(est: &mut dyn Estimator, data: &[Measurement]) -> History {
    data.iter()
        .map(|m| {
            est.update(m).expect("the study's samples are valid");
            let e = est.estimate();
            (m.t, e.value, e.std())
        })
        .collect()
}

/// First time after which `f(value)` holds to the end.
fn settled(hist: &[(f64, [f64; 4], [f64; 4])], f: impl Fn(&[f64; 4]) -> bool) -> Option<f64> {
    let mut at = None;
    for (t, v, _) in hist.iter().rev() {
        if f(v) {
            at = Some(*t);
        } else {
            break;
        }
    }
    at
}

/// `pushval track-study`.
pub fn cli(out: &Path, quick: bool) -> anyhow::Result<std::process::ExitCode> {
    let grid = Grid::new(quick);
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    // Timing first, alone.
    let cost_csv = cost(&grid)?;
    let (conv, conv_csv) = convergence(&grid)?;
    let (eff, eff_csv) = efficiency(&grid)?;
    let (steps, step_csv) = step(&grid)?;
    let (eng, eng_csv) = engines()?;
    let sc = load(SCENARIOS[2])?;
    let (hist, points, tr) = figure_run(&sc);
    let step_fig = steps
        .iter()
        .filter(|r| r.reopen)
        .min_by(|a, b| (a.rate - 100.0).abs().total_cmp(&(b.rate - 100.0).abs()))
        .expect("a step row");
    let svg = plot::render(&figure(&sc, &hist, &points, tr, step_fig))?;
    let files: Vec<(PathBuf, String)> = vec![
        (out.join("track_cost.csv"), cost_csv.text().into()),
        (out.join("track_convergence.csv"), conv_csv.text().into()),
        (out.join("track_efficiency.csv"), eff_csv.text().into()),
        (out.join("track_step.csv"), step_csv.text().into()),
        (out.join("track_engines.csv"), eng_csv.text().into()),
        (out.join("track.svg"), svg),
        (
            out.join("track.md"),
            md_text(
                quick,
                grid.seeds_efficiency,
                cost_csv.text(),
                &conv,
                &eff,
                &steps,
                &eng,
            ),
        ),
    ];
    for (p, text) in &files {
        write_atomic(p, text.as_bytes())?;
        println!("wrote {}", p.display());
    }
    Ok(std::process::ExitCode::SUCCESS)
}
