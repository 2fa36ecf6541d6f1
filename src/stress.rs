//! The stress sweep: how far each solver can be pushed before it leaves the
//! tolerance, and where it blows up.
//!
//! Every case is one scene (a rectangle on support points, pushed at a corner
//! so that `p_c · n_φ < 0`: one stable steady state) run by one solver — the
//! dynamic model's adaptive integrator, its fixed-step RK4, or the rapier2d
//! engine — and measured against the dynamic model at a tight tolerance
//! (`REFERENCE_TOL`, closed-form tails). Each run gets one of three verdicts:
//!
//! * `ok`: within the default `[tolerance]` of a scenario (5 mm, 0.01 rad, 0.5 %
//!   on the steady ω);
//! * `degraded`: finite and bounded, but outside that tolerance;
//! * `unstable`: the run blew up — the state left the finite numbers, the
//!   integrator gave up, or |ω| passed [`blowup_bound`]. The failure is named
//!   with the time and the step where it happened; its error columns stay empty.
//!
//! The grids: a map over dt × v_c × μ (rectangle 0.25 m square, 4 corner
//! supports, 2 s), and one-dimensional sweeps over the number of supports
//! (1 to 10,000), the aspect ratio (up to 50:1) and the horizon (up to
//! 1,000 s). Cases run in parallel (rayon); the results do not depend on the
//! number of threads.
//!
//! # `stress.csv`
//! One row per case and solver:
//! `sweep,solver,dt,speed,mu,supports,aspect,horizon,status,position_err,theta_err,omega_rel_err,blowup_t,blowup_step,detail`.
//! SI units (s, m/s, m, rad). `dt` is empty for the adaptive integrator;
//! error columns are empty for unstable runs, `blowup_*` for the others. No
//! NaN or infinity is ever written.
//!
//! # `stability.csv`
//! Per solver, μ and v_c on the map: the largest dt within tolerance
//! (`dt_ok_max`, with every smaller dt also within it) and the largest dt that
//! does not blow up (`dt_stable_max`); empty when none.

use std::fmt::Write as _;
use std::path::Path;

use crate::harness::Figures;
use anyhow::Context;
use pushval_engine::EngineOptions;
use pushval_model::{
    DynamicModel, Initial, Integrator, ModelError, Problem, Push, SegmentDynamics, Simulator,
    Support, Switching, Trajectory, Vec2,
};
use pushval_scenario::DEFAULT_GATE;
use rayon::prelude::*;

use crate::harness::{rel_err, tail_omega};
use crate::outdir::Csv;

/// A case is `ok` when its run stays within these of the reference (5 mm,
/// 0.01 rad, 0.5 % steady ω: fixed here so the stability map does not move
/// with the gate's engine-derived tolerances), `degraded` otherwise.
pub const OK_WITHIN: Figures = Figures {
    position_max: 0.005,
    theta_max: 0.01,
    omega_steady_rel: 0.005,
};

/// Tolerance of the reference runs (adaptive Dormand–Prince, closed-form tails).
pub const REFERENCE_TOL: f64 = 1e-11;
/// Tolerance of the adaptive integrator under test (no closed-form tails).
pub const ADAPTIVE_TOL: f64 = 1e-8;
/// Standard gravity (m/s²).
const G: f64 = 9.81;

/// One of the solvers the sweep stresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Solver {
    /// The dynamic model, Dormand–Prince at [`ADAPTIVE_TOL`], integrating to the end.
    Adaptive,
    /// The dynamic model, classical RK4 at the case's dt, integrating to the end.
    Rk4,
    /// The default gated engine (its default settings) at the case's dt.
    Engine,
}

impl Solver {
    pub const ALL: [Solver; 3] = [Solver::Adaptive, Solver::Rk4, Solver::Engine];
    /// `"adaptive"`, `"rk4"` or the default gated engine's name.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Adaptive => "adaptive",
            Solver::Rk4 => "rk4",
            Solver::Engine => DEFAULT_GATE[0],
        }
    }
}

/// One scene of the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Case {
    /// Which sweep it belongs to: `"map"`, `"supports"`, `"aspect"`, `"horizon"`
    /// (or a test's own name).
    pub sweep: &'static str,
    pub solver: Solver,
    /// Time step (s); ignored by the adaptive integrator.
    pub dt: f64,
    /// Pusher speed v_c (m/s).
    pub speed: f64,
    /// Support friction coefficient μ.
    pub mu: f64,
    /// Number of supports (1: one support under the centre of mass; 4: the
    /// corners; otherwise a uniform grid of about that many, equal loads).
    pub supports: usize,
    /// Long side over short side of the rectangle (≥ 1); the long side is 0.25 m.
    pub aspect: f64,
    /// Duration of the single push (s).
    pub horizon: f64,
    /// Initial ω (rad/s); 0 in the sweeps.
    pub omega0: f64,
    /// Push direction φ (rad, object frame); default `π/4 + 0.3` from the corner.
    pub phi: f64,
}

impl Case {
    /// The paper's plate, v_c = 0.2 m/s, μ = 0.5, 2 s, dt = 1e-3.
    pub fn base(solver: Solver) -> Self {
        Self {
            sweep: "map",
            solver,
            dt: 1e-3,
            speed: 0.2,
            mu: 0.5,
            supports: 4,
            aspect: 1.0,
            horizon: 2.0,
            omega0: 0.0,
            phi: std::f64::consts::FRAC_PI_4 + 0.3,
        }
    }

    /// The problem this case runs: mass 1 kg, uniform-density inertia, one
    /// push from the corner `(−a, −b)`, ~400 samples.
    pub fn problem(&self) -> Problem {
        let a = 0.125;
        let b = a / self.aspect;
        let m = 1.0;
        let n = self.supports.max(1);
        let pts: Vec<Vec2> = match n {
            1 => vec![Vec2::zeros()],
            4 => vec![
                Vec2::new(-a, -b),
                Vec2::new(a, -b),
                Vec2::new(a, b),
                Vec2::new(-a, b),
            ],
            _ => {
                // A grid with cells as square as the rectangle allows.
                let ny = ((n as f64 / self.aspect).sqrt().round() as usize).max(1);
                let nx = (n / ny).max(1);
                let mut v = Vec::with_capacity(nx * ny);
                for j in 0..ny {
                    for i in 0..nx {
                        v.push(Vec2::new(
                            -a + 2.0 * a * (i as f64 + 0.5) / nx as f64,
                            -b + 2.0 * b * (j as f64 + 0.5) / ny as f64,
                        ));
                    }
                }
                v
            }
        };
        let f = self.mu * m * G / pts.len() as f64;
        let supports: Vec<Support> = pts
            .iter()
            .map(|p| Support {
                position: *p,
                friction: f,
            })
            .collect();
        let inertia = m * (4.0 * a * a + 4.0 * b * b) / 12.0;
        let body = pushval_model::Body::new(m, inertia, Vec2::new(-a, -b), &supports)
            .expect("stress scenes are valid bodies");
        Problem {
            body,
            limits: Default::default(),
            pushes: vec![Push {
                duration: self.horizon,
                speed: self.speed,
                phi: self.phi,
            }],
            initial: Initial {
                omega: self.omega0,
                ..Default::default()
            },
            switching: Switching::Impulsive,
            sample_dt: self.horizon / 400.0,
            release: None,
        }
    }
}

/// A run's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Status {
    /// Within the default scenario tolerance.
    Ok,
    /// Finite and bounded but outside the tolerance.
    Degraded,
    /// Blew up (see [`BlowUp`]).
    Unstable,
}

impl Status {
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Degraded => "degraded",
            Status::Unstable => "unstable",
        }
    }
}

/// Where and how a run blew up.
#[derive(Debug, Clone, PartialEq)]
pub struct BlowUp {
    /// Time of the first bad state (s).
    pub t: f64,
    /// The solver step (1-based) that produced it.
    pub step: usize,
    /// What went wrong.
    pub what: String,
}

/// The result of one case.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    pub case: Case,
    pub status: Status,
    /// Largest CM distance from the reference at the samples (m); None when unstable.
    pub position_err: Option<f64>,
    /// Largest angle difference (rad); None when unstable.
    pub theta_err: Option<f64>,
    /// Relative error of the tail-mean ω (last 20 %) against the reference's,
    /// floored as in [`rel_err`]; None when unstable.
    pub omega_rel_err: Option<f64>,
    pub blowup: Option<BlowUp>,
}

/// |ω| (rad/s) beyond which a run counts as blown up: 100 times the largest
/// ω any steady state of the scene can have (`v_c / r_min`, with `r_min` the
/// nearest support to the contact), or of the initial ω.
pub fn blowup_bound(problem: &Problem) -> f64 {
    let pc = problem.body.contact();
    let rmin = problem
        .body
        .supports()
        .map(|s| (s.position - pc).norm())
        .filter(|r| *r > 0.0)
        .fold(f64::INFINITY, f64::min);
    let v = problem.pushes.iter().map(|p| p.speed).fold(0.0, f64::max);
    100.0 * (v / rmin).max(problem.initial.omega.abs()).max(1.0)
}

fn model_for(solver: Solver, dt: f64) -> DynamicModel {
    DynamicModel {
        integrator: match solver {
            Solver::Rk4 => Integrator::Rk4 { dt },
            _ => Integrator::Adaptive { tol: ADAPTIVE_TOL },
        },
        skip_settled: false,
        check_assumptions: false,
        ..Default::default()
    }
}

fn blowup_of(e: &ModelError) -> BlowUp {
    match e {
        ModelError::NonFinite { t, step } => BlowUp {
            t: *t,
            step: *step,
            what: format!("non-finite state at t = {t} s (step {step})"),
        },
        ModelError::Runaway { t, step, .. } => BlowUp {
            t: *t,
            step: *step,
            what: e.to_string(),
        },
        ModelError::Integration { t, reason } => BlowUp {
            t: *t,
            step: 0,
            what: format!("integration failed at t = {t} s: {reason}"),
        },
        other => BlowUp {
            t: 0.0,
            step: 0,
            what: other.to_string(),
        },
    }
}

/// Runs one case against the reference.
pub fn run_case(case: &Case) -> Outcome {
    let problem = case.problem();
    let reference = DynamicModel {
        integrator: Integrator::Adaptive { tol: REFERENCE_TOL },
        check_assumptions: false,
        ..Default::default()
    }
    .simulate(&problem);
    let bound = blowup_bound(&problem);
    let unstable = |b: BlowUp| Outcome {
        case: *case,
        status: Status::Unstable,
        position_err: None,
        theta_err: None,
        omega_rel_err: None,
        blowup: Some(b),
    };
    // Run the solver; a bound crossing is located at its first step.
    let run: Result<Trajectory, BlowUp> = match case.solver {
        Solver::Adaptive | Solver::Rk4 => {
            let r = model_for(case.solver, case.dt).simulate(&problem);
            match r {
                Err(e) => Err(blowup_of(&e)),
                Ok(tr) => match tr.samples.iter().find(|s| s.omega.abs() > bound) {
                    Some(s) => {
                        let step = match case.solver {
                            Solver::Rk4 => {
                                let n = (case.horizon / case.dt - 1e-9).ceil().max(1.0);
                                (s.t / (case.horizon / n)).ceil() as usize
                            }
                            _ => 0,
                        };
                        Err(BlowUp {
                            t: s.t,
                            step,
                            what: format!(
                                "|omega| = {:.3e} rad/s passed the bound {bound:.3e} rad/s",
                                s.omega.abs()
                            ),
                        })
                    }
                    None => Ok(tr),
                },
            }
        }
        Solver::Engine => {
            let engine = crate::registry::engine(DEFAULT_GATE[0], &EngineOptions::default());
            match engine.run(&problem, case.dt) {
                Err(e) => Err(blowup_of(&e)),
                Ok(run) => match run
                    .trajectory
                    .samples
                    .iter()
                    .find(|s| s.omega.abs() > bound)
                {
                    Some(s) => Err(BlowUp {
                        t: s.t,
                        step: (s.t / case.dt - 1e-9).ceil().max(1.0) as usize,
                        what: format!(
                            "|omega| = {:.3e} rad/s passed the bound {bound:.3e} rad/s",
                            s.omega.abs()
                        ),
                    }),
                    None => Ok(run.trajectory),
                },
            }
        }
    };
    let tr = match run {
        Ok(tr) => tr,
        Err(b) => return unstable(b),
    };
    let reference = match reference {
        Ok(r) => r,
        Err(e) => {
            return unstable(BlowUp {
                what: format!("reference run failed: {e}"),
                ..blowup_of(&e)
            })
        }
    };
    let (mut pos, mut th) = (0.0f64, 0.0f64);
    for (a, b) in tr.samples.iter().zip(&reference.samples) {
        pos = pos.max(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt());
        th = th.max((a.theta - b.theta).abs());
    }
    let seg = SegmentDynamics::new(&problem.body, &problem.pushes[0]);
    let target = seg.attractor(&seg.steady_states(), case.omega0);
    let length = problem.body.contact().norm();
    // The reference's own tail mean: the horizon may end before ω settles
    // (τ = v_c / (μ g) reaches seconds), and then ω* is not the right target.
    let w_ref = tail_omega(&reference, 0.0, case.horizon).or(target.map(|s| s.omega));
    let w_tail = tail_omega(&tr, 0.0, case.horizon);
    let omega_rel = match (w_tail, w_ref) {
        (Some(w), Some(r)) => rel_err(w, r, case.speed, length),
        _ => f64::INFINITY,
    };
    if !(pos.is_finite() && th.is_finite() && omega_rel.is_finite())
        || tr.samples.len() != reference.samples.len()
    {
        return unstable(BlowUp {
            t: case.horizon,
            step: 0,
            what: "non-finite or missing samples".into(),
        });
    }
    let tol = OK_WITHIN;
    let ok = pos <= tol.position_max && th <= tol.theta_max && omega_rel <= tol.omega_steady_rel;
    Outcome {
        case: *case,
        status: if ok { Status::Ok } else { Status::Degraded },
        position_err: Some(pos),
        theta_err: Some(th),
        omega_rel_err: Some(omega_rel),
        blowup: None,
    }
}

/// Time steps of the map (s).
pub const MAP_DT: [f64; 7] = [1e-5, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1];
/// Pusher speeds of the map (m/s).
pub const MAP_SPEED: [f64; 7] = [0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0];
/// Friction coefficients of the map.
pub const MAP_MU: [f64; 4] = [0.01, 0.1, 0.5, 2.0];

fn map_cases(dts: &[f64], speeds: &[f64], mus: &[f64]) -> Vec<Case> {
    let mut out = Vec::new();
    for &mu in mus {
        for &speed in speeds {
            let c = Case {
                speed,
                mu,
                ..Case::base(Solver::Adaptive)
            };
            out.push(c);
            for &dt in dts {
                for solver in [Solver::Rk4, Solver::Engine] {
                    out.push(Case { dt, solver, ..c });
                }
            }
        }
    }
    out
}

fn line_cases(sweep: &'static str, dts: &[f64], vary: &[Case]) -> Vec<Case> {
    let mut out = Vec::new();
    for c in vary {
        out.push(Case {
            sweep,
            solver: Solver::Adaptive,
            ..*c
        });
        for &dt in dts {
            for solver in [Solver::Rk4, Solver::Engine] {
                out.push(Case {
                    sweep,
                    solver,
                    dt,
                    ..*c
                });
            }
        }
    }
    out
}

/// The full grid of `pushval stress`.
pub fn full_grid() -> Vec<Case> {
    let base = Case::base(Solver::Adaptive);
    let mut out = map_cases(&MAP_DT, &MAP_SPEED, &MAP_MU);
    let supports: Vec<Case> = [1, 4, 100, 1_000, 10_000]
        .iter()
        .map(|&n| Case {
            supports: n,
            ..base
        })
        .collect();
    out.extend(line_cases("supports", &[1e-3, 1e-2], &supports));
    let aspect: Vec<Case> = [1.0, 5.0, 20.0, 50.0]
        .iter()
        .map(|&aspect| Case { aspect, ..base })
        .collect();
    out.extend(line_cases("aspect", &[1e-3, 1e-2], &aspect));
    let horizon: Vec<Case> = [10.0, 100.0, 1000.0]
        .iter()
        .map(|&horizon| Case { horizon, ..base })
        .collect();
    out.extend(line_cases("horizon", &[1e-3, 1e-2], &horizon));
    out
}

/// A small grid for the tests and `pushval stress --quick`.
pub fn quick_grid() -> Vec<Case> {
    let mut out = map_cases(&[1e-3, 0.1], &[0.1, 10.0], &[0.5]);
    let base = Case::base(Solver::Adaptive);
    out.extend(line_cases(
        "supports",
        &[1e-2],
        &[Case {
            supports: 100,
            ..base
        }],
    ));
    out.extend(line_cases(
        "aspect",
        &[1e-2],
        &[Case {
            aspect: 50.0,
            ..base
        }],
    ));
    out
}

/// Runs every case on `threads` worker threads (None: rayon's default).
/// The outcomes are in the order of `cases` and do not depend on `threads`.
pub fn run_grid(cases: &[Case], threads: Option<usize>) -> anyhow::Result<Vec<Outcome>> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        b = b.num_threads(n);
    }
    let pool = b.build().context("starting the worker threads")?;
    Ok(pool.install(|| cases.par_iter().map(run_case).collect()))
}

/// A finite number in full precision, or the empty field.
fn field(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:e}"),
        _ => String::new(),
    }
}

/// The `stress.csv` text (see the module docs).
pub fn csv(outcomes: &[Outcome]) -> String {
    let mut csv = Csv::new(&[
        "sweep",
        "solver",
        "dt",
        "speed",
        "mu",
        "supports",
        "aspect",
        "horizon",
        "status",
        "position_err",
        "theta_err",
        "omega_rel_err",
        "blowup_t",
        "blowup_step",
        "detail",
    ]);
    for o in outcomes {
        let c = &o.case;
        let dt = (c.solver != Solver::Adaptive).then_some(c.dt);
        let (bt, bs, what) = match &o.blowup {
            Some(b) => (
                Some(b.t),
                b.step.to_string(),
                // Kept free of commas and quotes, as the file always was:
                // a line of it splits on commas.
                b.what.replace([',', '"'], ";"),
            ),
            None => (None, String::new(), String::new()),
        };
        csv.row(&[
            c.sweep.to_string(),
            c.solver.name().to_string(),
            field(dt),
            field(Some(c.speed)),
            field(Some(c.mu)),
            c.supports.to_string(),
            field(Some(c.aspect)),
            field(Some(c.horizon)),
            o.status.name().to_string(),
            field(o.position_err),
            field(o.theta_err),
            field(o.omega_rel_err),
            field(bt),
            bs,
            what,
        ]);
    }
    csv.text().to_string()
}

/// Stability limits of one solver at one (μ, v_c) of the map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit {
    pub solver: Solver,
    pub mu: f64,
    pub speed: f64,
    /// Largest dt within tolerance, every smaller dt of the map also within it.
    pub dt_ok_max: Option<f64>,
    /// Largest dt that does not blow up, every smaller dt also not.
    pub dt_stable_max: Option<f64>,
}

/// The stability limits read off the map's outcomes.
pub fn limits(outcomes: &[Outcome]) -> Vec<Limit> {
    let mut out = Vec::new();
    let mut keys: Vec<(Solver, f64, f64)> = Vec::new();
    for o in outcomes.iter().filter(|o| o.case.sweep == "map") {
        let k = (o.case.solver, o.case.mu, o.case.speed);
        if o.case.solver != Solver::Adaptive && !keys.contains(&k) {
            keys.push(k);
        }
    }
    for (solver, mu, speed) in keys {
        let mut row: Vec<&Outcome> = outcomes
            .iter()
            .filter(|o| {
                o.case.sweep == "map"
                    && o.case.solver == solver
                    && o.case.mu == mu
                    && o.case.speed == speed
            })
            .collect();
        row.sort_by(|a, b| a.case.dt.total_cmp(&b.case.dt));
        let largest = |good: &dyn Fn(&Outcome) -> bool| {
            row.iter().take_while(|o| good(o)).last().map(|o| o.case.dt)
        };
        out.push(Limit {
            solver,
            mu,
            speed,
            dt_ok_max: largest(&|o| o.status == Status::Ok),
            dt_stable_max: largest(&|o| o.status != Status::Unstable),
        });
    }
    out
}

/// The `stability.csv` text.
pub fn limits_csv(limits: &[Limit]) -> String {
    let mut csv = Csv::new(&["solver", "mu", "speed", "dt_ok_max", "dt_stable_max"]);
    for l in limits {
        csv.row(&[
            l.solver.name().to_string(),
            field(Some(l.mu)),
            field(Some(l.speed)),
            field(l.dt_ok_max),
            field(l.dt_stable_max),
        ]);
    }
    csv.text().to_string()
}

/// A terminal summary: counts per sweep, solver and verdict, the blow-ups by
/// name, and the stability limits.
pub fn summary_text(outcomes: &[Outcome], limits: &[Limit]) -> String {
    let mut s = String::new();
    let mut sweeps: Vec<&str> = outcomes.iter().map(|o| o.case.sweep).collect();
    sweeps.dedup();
    let _ = writeln!(
        s,
        "{:<10} {:<9} {:>4} {:>9} {:>9}",
        "sweep", "solver", "ok", "degraded", "unstable"
    );
    for sw in &sweeps {
        for solver in Solver::ALL {
            let n = |st: Status| {
                outcomes
                    .iter()
                    .filter(|o| o.case.sweep == *sw && o.case.solver == solver && o.status == st)
                    .count()
            };
            let _ = writeln!(
                s,
                "{sw:<10} {:<9} {:>4} {:>9} {:>9}",
                solver.name(),
                n(Status::Ok),
                n(Status::Degraded),
                n(Status::Unstable)
            );
        }
    }
    for o in outcomes.iter().filter(|o| o.status == Status::Unstable) {
        let c = &o.case;
        let b = o.blowup.as_ref().map_or("", |b| b.what.as_str());
        let _ = writeln!(
            s,
            "unstable: {} {} dt={:e} v_c={} mu={} n={} aspect={} T={}: {b}",
            c.sweep,
            c.solver.name(),
            c.dt,
            c.speed,
            c.mu,
            c.supports,
            c.aspect,
            c.horizon
        );
    }
    let _ = writeln!(s, "\nlargest dt within tolerance / without blow-up (s):");
    let _ = writeln!(
        s,
        "{:<9} {:>5} {:>6} {:>10} {:>10}",
        "solver", "mu", "v_c", "ok", "stable"
    );
    let show = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x:e}"));
    for l in limits {
        let _ = writeln!(
            s,
            "{:<9} {:>5} {:>6} {:>10} {:>10}",
            l.solver.name(),
            l.mu,
            l.speed,
            show(l.dt_ok_max),
            show(l.dt_stable_max)
        );
    }
    s
}

/// Runs the grid and writes `DIR/stress.csv` and `DIR/stability.csv`
/// (through a temporary file and a rename). Returns the outcomes.
pub fn write_sweep(cases: &[Case], out: &Path) -> anyhow::Result<(Vec<Outcome>, Vec<Limit>)> {
    let outcomes = run_grid(cases, None)?;
    let lim = limits(&outcomes);
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    crate::atomic::write_atomic(&out.join("stress.csv"), csv(&outcomes).as_bytes())?;
    crate::atomic::write_atomic(&out.join("stability.csv"), limits_csv(&lim).as_bytes())?;
    if let Some(svg) = map_figure(&outcomes)? {
        crate::atomic::write_atomic(&out.join("stress_map.svg"), svg.as_bytes())?;
    }
    Ok((outcomes, lim))
}

/// Cell edges for a sorted log-spaced grid: geometric midpoints, extended
/// by half a step at both ends.
fn log_edges(v: &[f64]) -> Vec<(f64, f64)> {
    (0..v.len())
        .map(|i| {
            let lo = if i == 0 {
                v[0] * (v[0] / v[1.min(v.len() - 1)]).abs().sqrt().max(1e-300)
            } else {
                (v[i - 1] * v[i]).sqrt()
            };
            let hi = if i + 1 == v.len() {
                v[i] * (v[i] / v[i.saturating_sub(1)]).abs().sqrt()
            } else {
                (v[i] * v[i + 1]).sqrt()
            };
            (lo.min(hi), lo.max(hi))
        })
        .collect()
}

/// The stability map: for RK4 and rapier2d, one panel per μ of the map
/// sweep, cells over (v_c, dt) coloured ok / degraded / unstable. None when
/// the outcomes hold no map sweep.
pub fn map_figure(outcomes: &[Outcome]) -> anyhow::Result<Option<String>> {
    use crate::plot::{Axis, Cell, Figure, Key, Legend, Panel};
    use plotters::style::RGBColor;
    let map: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.case.sweep == "map" && o.case.solver != Solver::Adaptive)
        .collect();
    if map.is_empty() {
        return Ok(None);
    }
    let uniq = |f: &dyn Fn(&Case) -> f64| {
        let mut v: Vec<f64> = map.iter().map(|o| f(&o.case)).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let (dts, speeds, mus) = (uniq(&|c| c.dt), uniq(&|c| c.speed), uniq(&|c| c.mu));
    if dts.len() < 2 || speeds.len() < 2 {
        return Ok(None);
    }
    let (de, se) = (log_edges(&dts), log_edges(&speeds));
    let ok = RGBColor(120, 190, 120);
    let degraded = RGBColor(240, 180, 80);
    let unstable = RGBColor(210, 60, 60);
    let mut panels = Vec::new();
    for solver in [Solver::Rk4, Solver::Engine] {
        for &mu in &mus {
            let mut p = Panel::new(
                format!("{} — μ = {mu}", solver.name()),
                Axis::log("pusher speed v_c (m/s)").range(se[0].0, se[se.len() - 1].1),
                Axis::log("time step dt (s)").range(de[0].0, de[de.len() - 1].1),
            )
            .legend(Legend::None);
            for o in map
                .iter()
                .filter(|o| o.case.solver == solver && o.case.mu == mu)
            {
                let i = speeds.iter().position(|v| *v == o.case.speed).unwrap_or(0);
                let j = dts.iter().position(|v| *v == o.case.dt).unwrap_or(0);
                p.cells.push(Cell {
                    x: se[i],
                    y: de[j],
                    color: match o.status {
                        Status::Ok => ok,
                        Status::Degraded => degraded,
                        Status::Unstable => unstable,
                    },
                });
            }
            panels.push(p);
        }
    }
    let fig = Figure {
        size: (420 * mus.len() as u32 + 120, 820),
        cols: mus.len(),
        panels,
        key: Some(Key {
            title: "vs a tight model run".into(),
            entries: vec![
                ("ok".into(), ok),
                ("degraded".into(), degraded),
                ("unstable (blew up)".into(), unstable),
            ],
            ..Default::default()
        }),
    };
    crate::plot::render(&fig).map(Some)
}
