//! What every stage of the study shares: the truth, the methods and
//! their estimators, the settings grid, and a run of an estimator.

pub(super) use anyhow::Context;
pub(super) use pushval_model::track::{
    Ekf, EkfSettings, Estimator, Free, Measurement, Rls, RlsSettings,
};
pub(super) use pushval_model::{
    DynamicModel, Initial, Integrator, Problem, Sample, Simulator, Vec2,
};
pub(super) use pushval_scenario::Scenario;
pub(super) use rayon::prelude::*;

pub(super) use crate::fit::{fisher_at, noise, Param, Parametrised, Settings};
pub(super) use crate::outdir::{records, Csv};
pub(super) use crate::plot::{self, Axis, Figure, Legend, Panel, Series, Stroke};
pub(super) use crate::track::{thread_cpu_time, track_model};

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
pub(super) type History = Vec<(f64, [f64; 4], [f64; 4])>;

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
    pub(super) fn name(self) -> &'static str {
        match self {
            Method::Ekf => "ekf",
            Method::Rls => "rls",
            Method::EkfKnownStart => "ekf_known_start",
            Method::EkfBroadPrior => "ekf_broad_prior",
            Method::EkfKnownStartAtTruth => "ekf_known_start_at_truth",
        }
    }
}

pub(super) fn estimator(
    sc: &Scenario,
    method: Method,
    rate: f64,
    sp: f64,
    st: f64,
) -> Box<dyn Estimator> {
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
pub(super) fn truth(sc: &Scenario) -> (Parametrised, Vec<f64>, [f64; 4]) {
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

pub(super) fn simulate(problem: &Problem) -> Vec<Sample> {
    DynamicModel {
        integrator: Integrator::Dop853 { tol: 1e-11 },
        check_assumptions: false,
        ..Default::default()
    }
    .simulate(problem)
    .expect("the paper pushes run")
    .samples
}

pub(super) fn measurements(s: &[Sample]) -> Vec<Measurement> {
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
pub(super) fn load(name: &str) -> anyhow::Result<Scenario> {
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
pub(super) fn truth_samples(sc: &Scenario, rate: f64) -> Vec<Sample> {
    let mut sc = sc.clone();
    sc.sample_dt = 1.0 / rate;
    let (pm, v, _) = truth(&sc);
    simulate(&pm.problem(&v).expect("the truth is a problem"))
}

/// Runs `est` over `data`; returns `(t, value, std)` per sample.
pub(super) fn run(est: &mut dyn Estimator, data: &[Measurement]) -> History {
    data.iter()
        .map(|m| {
            est.update(m).expect("the study's samples are valid");
            let e = est.estimate();
            (m.t, e.value, e.std())
        })
        .collect()
}

/// First time after which `f(value)` holds to the end.
pub(super) fn settled(
    hist: &[(f64, [f64; 4], [f64; 4])],
    f: impl Fn(&[f64; 4]) -> bool,
) -> Option<f64> {
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
