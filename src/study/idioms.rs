//! Where the friction idioms of 2-D game engines disagree with Coulomb
//! support friction, run in rapier2d on the paper plate (`OUT/`).
//!
//! Writes one CSV per idiom over a (Fr, φ) grid at two engine steps, the
//! table at φ = π/4 + 0.3, the Δt and slip-speed sweeps, the box law's angle
//! dependence and lock, the stop after the pusher halts, the error map
//! (`map.svg`), the box law's frozen ω*(θ) against the engine
//! (`box_angle.svg`), and a README that also gathers the other studies'
//! paper-plate numbers and findings from their folders.
//!
//! Every engine run goes through `pushval_rapier2d::RapierSimulator`, the
//! crate's own API, not the `Engine` trait: the steady ω, its range and
//! jitter are read from the engine's step history (not in a trajectory),
//! and the slip-speed sweep needs laws the registry does not list.

use std::f64::consts::FRAC_PI_2;
use std::fmt::Write as _;
use std::path::Path;

use pushval_model::{DynamicModel, Initial, Problem, Push, SegmentDynamics, Simulator};
use pushval_rapier2d::idioms::{
    lock_angles, predicted_angle_history, predicted_mean_omega, predicted_steady_omega, stop_gain,
};
use pushval_rapier2d::{EngineSettings, FrictionModel, RapierRun, RapierSimulator, StepRecord};

use super::plate::{
    coulomb_star, froude, frs, length, paper_plate, phis, plate, rel, speed_of, G, HALF, MASS, MU,
    PHI_TABLE, TABLE_SPEEDS,
};
use super::{dt_label, error_figure, error_panel, median, min_max, opt, range_text, ErrorCell};
use crate::report::plot::{Axis, Figure, Legend, Panel, Series, Stroke, BLUE_, GREY, ORANGE};
use crate::report::Writer;

/// Slip speed of the regularised laws on the grid and in the table (m/s).
const SLIP: f64 = 0.01;
/// Duration of every run but the stop and the angle dependence (s).
const T_RUN: f64 = 6.0;
/// A game engine's step (s).
const GAME_DT: f64 = 1.0 / 60.0;
/// A fine step (s).
const FINE_DT: f64 = 1e-3;
/// The two steps of the table, the grid and the stop.
const DTS: [f64; 2] = [GAME_DT, FINE_DT];
/// Starting angle of the grid and stop runs (rad): generic (θ = 0 is an
/// unstable balance of the box law).
const THETA0: f64 = 0.1;
/// Steps of the impulse idioms' Δt sweep (s).
const SWEEP_DTS: [f64; 6] = [1.0 / 30.0, GAME_DT, 1.0 / 120.0, 1.0 / 240.0, 1e-3, 2.5e-4];
/// Slip speeds of the regularised laws' sweep (m/s).
const SLIP_SPEEDS: [f64; 6] = [1.0, 0.3, 0.1, 0.03, 0.01, 0.001];
/// Pusher speed of the sweeps, the angle dependence, the stop and the lock (m/s).
const V_SWEEP: f64 = 0.5;
/// Starting angles of the angle dependence (rad).
const THETA0S: [f64; 4] = [0.0, 0.2, 0.4, 0.6];
/// Duration of the angle-dependence runs (s).
const T_SHORT: f64 = 0.5;
/// Angles of the frozen box law per quarter turn.
const FROZEN_STEPS: usize = 360;
/// The stop: pushing time, then resting time of the pusher, and the tail
/// over which ω is measured (s).
const STOP: (f64, f64, f64) = (1.0, 1.0, 0.5);
/// Status thresholds, as fractions of |ω*|: below `STOPS` the run stops, a
/// jitter above `CHATTERS` chatters, a range above `OSCILLATES` oscillates.
const STOPS: f64 = 0.05;
const CHATTERS: f64 = 0.05;
const OSCILLATES: f64 = 0.2;

/// The 2-D idioms study.
#[derive(Debug, Clone, Copy)]
pub struct Idioms {
    pub quick: bool,
}

/// The support-friction laws, Coulomb first.
fn idioms() -> [FrictionModel; 5] {
    [
        FrictionModel::Coulomb,
        FrictionModel::ImpulseDisk,
        FrictionModel::ImpulseBox,
        FrictionModel::RegularisedLinear { slip_speed: SLIP },
        FrictionModel::RegularisedTanh { slip_speed: SLIP },
    ]
}

/// One engine run and what it gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// At φ = π/4 + 0.3: `[ω*, ω, range, jitter, predicted]`.
    Table { dt: usize, v: usize, m: usize },
    /// A grid cell: `[Fr, v_c, φ, ω*, ω, range, jitter, predicted, position
    /// error, θ error, θ error vs the predicted history, final θ mod π/2,
    /// distance to the nearest predicted stable lock]`.
    Grid {
        dt: usize,
        i: usize,
        j: usize,
        m: usize,
    },
    /// The Δt or v_s sweep: `[ω*, ω, range, jitter, predicted]`.
    Sweep { m: FrictionModel, dt: f64 },
    /// The frozen laws at θ = (π/2) j/360: `[θ, ω* box, ω* disk]` (no engine).
    Frozen { j: usize },
    /// The box at Δt = 1/60 from θ = THETA0: `[t, θ, ω]` per step.
    BoxHistory,
    /// The box at Δt = 1e-3 from θ = THETA0: `[θ_end mod π/2, ω_end,
    /// nearest predicted stable lock, its distance]`.
    BoxLock,
    /// ω after T_SHORT from `THETA0S[k]`: `[ω]`.
    Theta { m: usize, k: usize },
    /// The stop: `[γ, mean |ω| over the resting tail, rms Δω, angle turned]`.
    Stop { m: usize, dt: usize },
}

/// Runs the problem in rapier2d with the law `model` at step `dt`.
fn engine(p: &Problem, model: FrictionModel, dt: f64) -> RapierRun {
    RapierSimulator::new(EngineSettings {
        dt,
        friction_model: model,
        ..Default::default()
    })
    .run(p)
    .expect("the paper plate runs in rapier2d")
}

/// The paper plate from `theta0`.
fn problem(push: Push, theta0: f64) -> Problem {
    Problem {
        initial: Initial {
            theta: theta0,
            ..Default::default()
        },
        ..paper_plate(push.speed, push.phi, push.duration)
    }
}

fn push(speed: f64, phi: f64, duration: f64) -> Push {
    Push {
        duration,
        speed,
        phi,
    }
}

/// `[ω, range, jitter]` of a run's second half: ω the mean (over whole
/// quarter turns when the body turns that far: the box law repeats every
/// π/2 for the square), range the largest minus the smallest step ω, jitter
/// the rms step-to-step change of ω.
fn measure(history: &[StepRecord]) -> [f64; 3] {
    let steps: Vec<_> = history.iter().filter(|r| r.t1 > r.t0).collect();
    let t_end = steps.last().expect("a run has steps").t1;
    let half: Vec<_> = steps.iter().filter(|r| r.t0 >= 0.5 * t_end).collect();
    let th_end = steps[steps.len() - 1].theta;
    let th_half = half[0].theta;
    let quarters = ((th_end - th_half).abs() / FRAC_PI_2).floor();
    let omega = if quarters >= 1.0 {
        // The last time θ was a whole number of quarter turns before the end.
        let target = th_end - (th_end - th_half).signum() * quarters * FRAC_PI_2;
        let mut t_a = half[0].t1;
        for w in steps.windows(2) {
            let (a, b) = (w[0], w[1]);
            if (a.theta - target) * (b.theta - target) <= 0.0 && b.theta != a.theta {
                t_a = a.t1 + (target - a.theta) / (b.theta - a.theta) * (b.t1 - a.t1);
            }
        }
        (th_end - target) / (t_end - t_a)
    } else {
        half.iter().map(|r| r.omega * (r.t1 - r.t0)).sum::<f64>()
            / half.iter().map(|r| r.t1 - r.t0).sum::<f64>()
    };
    let (lo, hi) = half
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), r| {
            (l.min(r.omega), h.max(r.omega))
        });
    let d: Vec<f64> = half.windows(2).map(|w| w[1].omega - w[0].omega).collect();
    let jitter = (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt();
    [omega, hi - lo, jitter]
}

/// `stops` (|ω| < STOPS |ω*|), `chatters` (jitter > CHATTERS |ω*|),
/// `oscillates` (range > OSCILLATES |ω*|) or `ok`.
fn status(omega: f64, range: f64, jitter: f64, star: f64) -> &'static str {
    if omega.abs() < STOPS * star.abs() {
        "stops"
    } else if jitter > CHATTERS * star.abs() {
        "chatters"
    } else if range > OSCILLATES * star.abs() {
        "oscillates"
    } else {
        "ok"
    }
}

/// A predicted value, NaN where the closed form has none.
fn or_nan(v: Option<f64>) -> f64 {
    v.unwrap_or(f64::NAN)
}

/// The stable lock angles (mod π/2) the box law predicts.
fn stable_locks(model: FrictionModel, push: &Push, dt: f64) -> Vec<f64> {
    lock_angles(model, &plate(), push, dt, 720)
        .iter()
        .filter(|l| l.1)
        .map(|l| l.0)
        .collect()
}

/// The nearest of `locks` to `theta` mod π/2: `(lock, distance)`; distance
/// ∞ when there is none.
fn nearest_lock(locks: &[f64], theta: f64) -> (f64, f64) {
    locks
        .iter()
        .map(|&l| {
            let d = (l - theta).rem_euclid(FRAC_PI_2);
            (l, d.min(FRAC_PI_2 - d))
        })
        .fold(
            (f64::NAN, f64::INFINITY),
            |a, b| if b.1 < a.1 { b } else { a },
        )
}

fn slip_of(m: FrictionModel) -> Option<f64> {
    match m {
        FrictionModel::RegularisedLinear { slip_speed }
        | FrictionModel::RegularisedTanh { slip_speed } => Some(slip_speed),
        _ => None,
    }
}

fn sweep_cases() -> Vec<(FrictionModel, f64)> {
    let mut cases = Vec::new();
    for dt in SWEEP_DTS {
        cases.push((FrictionModel::ImpulseDisk, dt));
        cases.push((FrictionModel::ImpulseBox, dt));
    }
    for vs in SLIP_SPEEDS {
        for dt in DTS {
            cases.push((FrictionModel::RegularisedLinear { slip_speed: vs }, dt));
            cases.push((FrictionModel::RegularisedTanh { slip_speed: vs }, dt));
        }
    }
    cases
}

impl super::Study for Idioms {
    type Task = Task;

    fn name(&self) -> &'static str {
        "idioms"
    }

    fn dir(&self) -> &'static str {
        ""
    }

    fn tasks(&self) -> Vec<Task> {
        let n_m = idioms().len();
        let mut t = Vec::new();
        for dt in 0..DTS.len() {
            for v in 0..TABLE_SPEEDS.len() {
                for m in 0..n_m {
                    t.push(Task::Table { dt, v, m });
                }
            }
        }
        for dt in 0..DTS.len() {
            for i in 0..frs(self.quick).len() {
                for j in 0..phis(self.quick).len() {
                    for m in 0..n_m {
                        t.push(Task::Grid { dt, i, j, m });
                    }
                }
            }
        }
        for (m, dt) in sweep_cases() {
            t.push(Task::Sweep { m, dt });
        }
        for j in 0..=FROZEN_STEPS {
            t.push(Task::Frozen { j });
        }
        t.push(Task::BoxHistory);
        t.push(Task::BoxLock);
        for m in 0..n_m {
            for k in 0..THETA0S.len() {
                t.push(Task::Theta { m, k });
            }
        }
        for m in 0..n_m {
            for dt in 0..DTS.len() {
                t.push(Task::Stop { m, dt });
            }
        }
        t
    }

    fn width(&self, task: &Task) -> Option<usize> {
        match task {
            Task::Table { .. } | Task::Sweep { .. } => Some(5),
            Task::Grid { .. } => Some(13),
            Task::Frozen { .. } => Some(3),
            Task::BoxHistory => None,
            Task::BoxLock => Some(4),
            Task::Theta { .. } => Some(1),
            Task::Stop { .. } => Some(4),
        }
    }

    fn eval(&self, task: &Task) -> Vec<f64> {
        let body = plate();
        match *task {
            Task::Table { dt, v, m } => {
                let (dt, m) = (DTS[dt], idioms()[m]);
                let p = push(TABLE_SPEEDS[v], PHI_TABLE, T_RUN);
                let star = coulomb_star(&body, &p);
                let e = measure(&engine(&problem(p, 0.0), m, dt).history);
                let pred = or_nan(predicted_mean_omega(m, &body, &p, dt, 720));
                vec![star, e[0], e[1], e[2], pred]
            }
            Task::Grid { dt, i, j, m } => {
                let (dt, m) = (DTS[dt], idioms()[m]);
                let v = speed_of(frs(self.quick)[i]);
                let phi = phis(self.quick)[j];
                let p = push(v, phi, T_RUN);
                let star = coulomb_star(&body, &p);
                let prob = problem(p, THETA0);
                let reference = DynamicModel::default()
                    .simulate(&prob)
                    .expect("the dynamic model runs the paper plate");
                let run = engine(&prob, m, dt);
                let e = measure(&run.history);
                let pred = or_nan(predicted_mean_omega(m, &body, &p, dt, 360));
                let hist = predicted_angle_history(m, &body, &p, dt, (THETA0, 0.0), T_RUN, 0.01);
                let (mut pe, mut te, mut tp) = (0.0f64, 0.0f64, 0.0f64);
                for (k, (s, r)) in run
                    .trajectory
                    .samples
                    .iter()
                    .zip(&reference.samples)
                    .enumerate()
                {
                    pe = pe.max(((s.x - r.x).powi(2) + (s.y - r.y).powi(2)).sqrt());
                    te = te.max((s.theta - r.theta).abs());
                    if let Some(h) = hist.get(k) {
                        tp = tp.max((s.theta - h.1).abs());
                    }
                }
                let (lock_th, lock_d) = if m.is_isotropic() {
                    (f64::NAN, f64::NAN)
                } else {
                    let th = run.history[run.history.len() - 1]
                        .theta
                        .rem_euclid(FRAC_PI_2);
                    (th, nearest_lock(&stable_locks(m, &p, dt), th).1)
                };
                vec![
                    froude(v),
                    v,
                    phi,
                    star,
                    e[0],
                    e[1],
                    e[2],
                    pred,
                    pe,
                    te,
                    tp,
                    lock_th,
                    lock_d,
                ]
            }
            Task::Sweep { m, dt } => {
                let p = push(V_SWEEP, PHI_TABLE, T_RUN);
                let star = coulomb_star(&body, &p);
                let e = measure(&engine(&problem(p, 0.0), m, dt).history);
                let pred = or_nan(predicted_mean_omega(m, &body, &p, dt, 720));
                vec![star, e[0], e[1], e[2], pred]
            }
            Task::Frozen { j } => {
                let p = push(V_SWEEP, PHI_TABLE, T_RUN);
                let th = FRAC_PI_2 * j as f64 / FROZEN_STEPS as f64;
                let w = |m| or_nan(predicted_steady_omega(m, &body, &p, GAME_DT, th, 0.0));
                vec![
                    th,
                    w(FrictionModel::ImpulseBox),
                    w(FrictionModel::ImpulseDisk),
                ]
            }
            Task::BoxHistory => {
                let p = push(V_SWEEP, PHI_TABLE, T_RUN);
                engine(&problem(p, THETA0), FrictionModel::ImpulseBox, GAME_DT)
                    .history
                    .iter()
                    .filter(|r| r.t1 > r.t0)
                    .flat_map(|r| [r.t1, r.theta, r.omega])
                    .collect()
            }
            Task::BoxLock => {
                let p = push(V_SWEEP, PHI_TABLE, T_RUN);
                let m = FrictionModel::ImpulseBox;
                let run = engine(&problem(p, THETA0), m, FINE_DT);
                let last = run.history[run.history.len() - 1];
                let th = last.theta.rem_euclid(FRAC_PI_2);
                let (lock, d) = nearest_lock(&stable_locks(m, &p, FINE_DT), th);
                vec![th, last.omega, lock, d]
            }
            Task::Theta { m, k } => {
                let p = push(V_SWEEP, PHI_TABLE, T_SHORT);
                let run = engine(&problem(p, THETA0S[k]), idioms()[m], GAME_DT);
                vec![run.history[run.history.len() - 1].omega]
            }
            Task::Stop { m, dt } => {
                let (m, dt) = (idioms()[m], DTS[dt]);
                let stop = Problem {
                    pushes: vec![
                        push(V_SWEEP, PHI_TABLE, STOP.0),
                        push(0.0, PHI_TABLE, STOP.1),
                    ],
                    ..problem(push(V_SWEEP, PHI_TABLE, T_RUN), THETA0)
                };
                let run = engine(&stop, m, dt);
                let steps: Vec<_> = run.history.iter().filter(|r| r.t1 > r.t0).collect();
                let tail: Vec<_> = steps
                    .iter()
                    .filter(|r| r.t0 >= STOP.0 + STOP.1 - STOP.2)
                    .collect();
                let mean_abs = tail.iter().map(|r| r.omega.abs()).sum::<f64>() / tail.len() as f64;
                let d: Vec<f64> = tail.windows(2).map(|w| w[1].omega - w[0].omega).collect();
                let jit = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
                let th_stop = steps
                    .iter()
                    .rev()
                    .find(|r| r.t1 <= STOP.0 + 1e-12)
                    .map_or(f64::NAN, |r| r.theta);
                let turned = steps[steps.len() - 1].theta - th_stop;
                let gain = or_nan(stop_gain(m, &body, dt, THETA0));
                vec![gain, mean_abs, jit, turned]
            }
        }
    }

    fn write(
        &self,
        tasks: &[Task],
        rows: &[Vec<f64>],
        out: &Path,
        w: &mut Writer,
    ) -> anyhow::Result<()> {
        let data = Data::collect(self.quick, tasks, rows);
        let mut readme = intro();
        readme.push_str(super::quick_note(self.quick));
        let table = write_table(&data, w)?;
        let grid = write_grid(&data, w)?;
        let sweeps = write_sweeps(&data, w)?;
        let angle = write_angle(&data, w)?;
        let stop = write_stop(&data, w)?;
        readme.push_str(&findings(&data));
        readme.push_str(&table);
        readme.push_str(&grid);
        readme.push_str(&sweeps);
        readme.push_str(&locks(&data, w)?);
        readme.push_str(&stop);
        readme.push_str(&angle);
        readme.push_str(&super::fits::readme_section(out));
        readme.push_str(&other_engines(out));
        w.file("README.md", readme.as_bytes())?;
        Ok(())
    }
}

/// A row of the table or the sweeps.
#[derive(Debug, Clone, Copy)]
struct Steady {
    star: f64,
    omega: f64,
    range: f64,
    jitter: f64,
    pred: f64,
}

impl Steady {
    fn from(r: &[f64]) -> Self {
        Self {
            star: r[0],
            omega: r[1],
            range: r[2],
            jitter: r[3],
            pred: r[4],
        }
    }
    fn status(&self) -> &'static str {
        status(self.omega, self.range, self.jitter, self.star)
    }
}

/// A grid cell's row.
#[derive(Debug, Clone, Copy)]
struct GridCell {
    dt: usize,
    i: usize,
    j: usize,
    m: usize,
    fr: f64,
    speed: f64,
    phi: f64,
    s: Steady,
    pos_err: f64,
    theta_err: f64,
    theta_err_pred: f64,
    lock_theta: f64,
    lock_dist: f64,
}

/// Every task's row, by kind.
struct Data {
    quick: bool,
    table: Vec<(usize, usize, usize, Steady)>,
    grid: Vec<GridCell>,
    sweeps: Vec<(FrictionModel, f64, Steady)>,
    frozen: Vec<[f64; 3]>,
    history: Vec<[f64; 3]>,
    lock: [f64; 4],
    theta: Vec<(usize, usize, f64)>,
    stop: Vec<(usize, usize, [f64; 4])>,
}

impl Data {
    fn collect(quick: bool, tasks: &[Task], rows: &[Vec<f64>]) -> Self {
        let mut d = Data {
            quick,
            table: Vec::new(),
            grid: Vec::new(),
            sweeps: Vec::new(),
            frozen: Vec::new(),
            history: Vec::new(),
            lock: [f64::NAN; 4],
            theta: Vec::new(),
            stop: Vec::new(),
        };
        for (t, r) in tasks.iter().zip(rows) {
            match *t {
                Task::Table { dt, v, m } => d.table.push((dt, v, m, Steady::from(r))),
                Task::Grid { dt, i, j, m } => d.grid.push(GridCell {
                    dt,
                    i,
                    j,
                    m,
                    fr: r[0],
                    speed: r[1],
                    phi: r[2],
                    s: Steady {
                        star: r[3],
                        omega: r[4],
                        range: r[5],
                        jitter: r[6],
                        pred: r[7],
                    },
                    pos_err: r[8],
                    theta_err: r[9],
                    theta_err_pred: r[10],
                    lock_theta: r[11],
                    lock_dist: r[12],
                }),
                Task::Sweep { m, dt } => d.sweeps.push((m, dt, Steady::from(r))),
                Task::Frozen { .. } => d.frozen.push([r[0], r[1], r[2]]),
                Task::BoxHistory => {
                    d.history = r.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
                }
                Task::BoxLock => d.lock = [r[0], r[1], r[2], r[3]],
                Task::Theta { m, k } => d.theta.push((m, k, r[0])),
                Task::Stop { m, dt } => d.stop.push((m, dt, [r[0], r[1], r[2], r[3]])),
            }
        }
        d
    }

    fn table_at(&self, m: FrictionModel) -> impl Iterator<Item = &(usize, usize, usize, Steady)> {
        let k = idioms().iter().position(|x| *x == m).unwrap_or(usize::MAX);
        self.table.iter().filter(move |r| r.2 == k)
    }

    fn cells(&self, m: usize, dt: usize) -> impl Iterator<Item = &GridCell> {
        self.grid.iter().filter(move |c| c.m == m && c.dt == dt)
    }

    fn stop_of(&self, m: FrictionModel, dt: usize) -> Option<[f64; 4]> {
        let k = idioms().iter().position(|x| *x == m)?;
        self.stop
            .iter()
            .find(|s| s.0 == k && s.1 == dt)
            .map(|s| s.2)
    }
}

fn intro() -> String {
    let rapier = crate::registry::engine("rapier2d", &Default::default());
    let f = MU * MASS * G / 4.0;
    format!(
        "# Game-engine friction idioms against Coulomb support friction\n\n\
         Generated by `pushval study idioms` (`pushval study all` regenerates every study in \
         `results/friction_models/`); do not edit by hand. Paper plate: {side} m square, {MASS} kg, \
         four corner supports with μ = {MU} and equal loads (F = μ m g / 4 = {f:.4} N each), \
         pushed at the corner (−{HALF}, −{HALF}); {engine}, {mode} mode, the idiom's force \
         applied at every support each step (`crates/rapier2d/src/idioms.rs`; the registry's \
         models `rapier2d_impulse_disk`, `rapier2d_impulse_box`, `rapier2d_regularised_linear`, \
         `rapier2d_regularised_tanh`). Fr = v_c²/(μ g L), L = |p_c| = {l:.4} m. Slip speed of \
         the regularised laws v_s = {SLIP} m/s unless stated. Each run: {T_RUN} s from ω = 0 \
         moving with the pusher; the engine's ω is the mean over the second half (over whole \
         quarter turns where the body turns that far).\n\n",
        side = 2.0 * HALF,
        engine = rapier.version(),
        mode = EngineSettings::default().friction_velocity.as_str(),
        l = length(),
    )
}

fn write_table(d: &Data, w: &mut Writer) -> anyhow::Result<String> {
    let mut csv = String::from(
        "dt,speed,idiom,omega_star,omega_engine,omega_predicted,rel_err_vs_star,rel_err_vs_predicted,jitter,status\n",
    );
    let mut md = String::from(
        "| v_c (m/s) | ω* Coulomb | Δt | impulse_disk | impulse_box | regularised_linear | regularised_tanh |\n|---:|---:|---|---:|---:|---:|---:|\n",
    );
    let mut row = String::new();
    for &(dt, v, m, s) in &d.table {
        let (dt, v, model) = (DTS[dt], TABLE_SPEEDS[v], idioms()[m]);
        writeln!(
            csv,
            "{dt},{v},{},{},{},{},{},{},{},{}",
            model.as_str(),
            s.star,
            s.omega,
            opt(s.pred),
            rel(s.omega, s.star),
            opt(rel(s.omega, s.pred)),
            s.jitter,
            s.status()
        )?;
        if m == 0 {
            row = format!("| {v} | {:.4} | {} |", s.star, dt_label(dt));
        } else {
            write!(
                row,
                " {:.4} ({:+.1} %; pred. {}) |",
                s.omega,
                100.0 * (s.omega - s.star) / s.star,
                if s.pred.is_nan() {
                    "—".to_string()
                } else {
                    format!("{:.4}", s.pred)
                }
            )?;
        }
        if m + 1 == idioms().len() {
            md.push_str(&row);
            md.push('\n');
        }
    }
    w.file("table_phi_pi4+0.3.csv", csv.as_bytes())?;
    Ok(format!(
        "## Steady ω at φ = π/4 + 0.3 (rad/s; in brackets the error against the Coulomb ω*, then the closed-form prediction)\n\n{md}\nData: `table_phi_pi4+0.3.csv`.\n\n"
    ))
}

fn write_grid(d: &Data, w: &mut Writer) -> anyhow::Result<String> {
    let (frs, phis) = (frs(d.quick), phis(d.quick));
    let mut summary = String::from(
        "| idiom | Δt | median ‖ω−ω*‖/ω* | max | median ‖ω−ω_pred‖/ω | max | max position error vs Coulomb (m) | max θ error vs Coulomb (rad) | max θ error vs predicted (rad) | cells not ok |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    let mut panels = Vec::new();
    for (mk, m) in idioms().iter().enumerate() {
        let mut csv = String::from("dt,froude,speed,phi,omega_star,omega_engine,omega_predicted,rel_err_vs_star,rel_err_vs_predicted,omega_range,jitter,position_err_max,theta_err_max,theta_err_vs_predicted_max,status,final_theta_mod_quarter,dist_to_predicted_lock\n");
        for c in d.grid.iter().filter(|c| c.m == mk) {
            let s = c.s;
            writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                DTS[c.dt],
                c.fr,
                c.speed,
                c.phi,
                s.star,
                s.omega,
                opt(s.pred),
                rel(s.omega, s.star),
                opt(rel(s.omega, s.pred)),
                s.range,
                s.jitter,
                c.pos_err,
                c.theta_err,
                c.theta_err_pred,
                s.status(),
                opt(c.lock_theta),
                opt(c.lock_dist)
            )?;
        }
        w.file(&format!("{}.csv", m.as_str()), csv.as_bytes())?;
        for (dt, &step) in DTS.iter().enumerate() {
            let cs: Vec<&GridCell> = d.cells(mk, dt).collect();
            let es: Vec<f64> = cs.iter().map(|c| rel(c.s.omega, c.s.star)).collect();
            let ps: Vec<f64> = cs
                .iter()
                .filter(|c| !c.s.pred.is_nan())
                .map(|c| rel(c.s.omega, c.s.pred))
                .collect();
            let bad: Vec<String> = cs
                .iter()
                .filter(|c| c.s.status() != "ok")
                .map(|c| format!("{} (Fr {:.2}, φ {:.2})", c.s.status(), c.fr, c.phi))
                .collect();
            let none = cs.len() - ps.len();
            let max = |f: &dyn Fn(&GridCell) -> f64| cs.iter().map(|c| f(c)).fold(0.0, f64::max);
            writeln!(
                summary,
                "| {} | {} | {:.2e} | {:.2e} | {} | {} | {:.3} | {:.3} | {:.2e} | {} |",
                m.as_str(),
                dt_label(step),
                median(&es),
                min_max(es.iter().copied()).1,
                if ps.is_empty() {
                    "—".to_string()
                } else {
                    format!("{:.2e}", median(&ps))
                },
                if ps.is_empty() {
                    "—".to_string()
                } else {
                    format!(
                        "{:.2e}{}",
                        min_max(ps.iter().copied()).1,
                        if none > 0 {
                            format!(" ({none} none)")
                        } else {
                            String::new()
                        }
                    )
                },
                max(&|c| c.pos_err),
                max(&|c| c.theta_err),
                max(&|c| c.theta_err_pred),
                if bad.is_empty() {
                    "—".to_string()
                } else {
                    format!("{}: {}", bad.len(), bad[..bad.len().min(3)].join("; "))
                }
            )?;
            if *m != FrictionModel::Coulomb {
                let cells: Vec<ErrorCell> = cs
                    .iter()
                    .map(|c| ErrorCell {
                        i: c.i,
                        j: c.j,
                        rel_err: rel(c.s.omega, c.s.star),
                        flags: match c.s.status() {
                            "stops" => "S",
                            "chatters" => "C",
                            "oscillates" => "O",
                            _ => "",
                        }
                        .to_string(),
                    })
                    .collect();
                let title = format!("{} Δt = {}", m.as_str(), dt_label(step));
                panels.push((dt, error_panel(&title, frs, &phis, &cells)));
            }
        }
    }
    // One row per step, one column per idiom.
    panels.sort_by_key(|p| p.0);
    let cols = idioms().len() - 1;
    w.figure(
        "map.svg",
        &error_figure(
            panels.into_iter().map(|p| p.1).collect(),
            cols,
            &[("S", "stops"), ("C", "chatters"), ("O", "oscillates")],
        ),
    )?;
    Ok(format!(
        "## Over the (Fr, φ) grid\n\nFr ∈ {frs:?}, φ ∈ {} values in [{:.2}, {:.2}] rad; per idiom \
         `IDIOM.csv`, map of the steady-ω error in `map.svg`. 'not ok': `stops` (|ω| < {s} % of \
         ω*), `chatters` (rms step-to-step change of ω > {c} % of ω*), `oscillates` (ω range over \
         the second half > {o} % of ω*).\n\n{summary}\n",
        phis.len(),
        phis[0],
        phis[phis.len() - 1],
        s = 100.0 * STOPS,
        c = 100.0 * CHATTERS,
        o = 100.0 * OSCILLATES,
    ))
}

fn write_sweeps(d: &Data, w: &mut Writer) -> anyhow::Result<String> {
    let mut csv = String::from(
        "idiom,dt,slip_speed,omega_star,omega_engine,omega_predicted,rel_err_vs_star,jitter,status\n",
    );
    let mut md = String::from("| idiom | Δt (s) | v_s (m/s) | ω engine | (ω−ω*)/ω* | predicted | status |\n|---|---:|---:|---:|---:|---:|---|\n");
    for &(m, dt, s) in &d.sweeps {
        let vs = slip_of(m).map_or(String::new(), |v| v.to_string());
        writeln!(
            csv,
            "{},{dt},{vs},{},{},{},{},{},{}",
            m.as_str(),
            s.star,
            s.omega,
            opt(s.pred),
            rel(s.omega, s.star),
            s.jitter,
            s.status()
        )?;
        writeln!(
            md,
            "| {} | {:.3e} | {} | {:.4} | {:+.2e} | {} | {} |",
            m.as_str(),
            dt,
            if vs.is_empty() { "—".to_string() } else { vs },
            s.omega,
            (s.omega - s.star) / s.star,
            if s.pred.is_nan() {
                "—".to_string()
            } else {
                format!("{:.4}", s.pred)
            },
            s.status()
        )?;
    }
    w.file("sweeps.csv", csv.as_bytes())?;
    let p = push(V_SWEEP, PHI_TABLE, T_RUN);
    let star = coulomb_star(&plate(), &p);
    let umin = SegmentDynamics::new(&plate(), &p).min_support_speed(star).0;
    Ok(format!(
        "## Δt and slip-speed sweeps (v_c = {V_SWEEP} m/s, φ = π/4 + 0.3, ω* = {star:.5})\n\n{md}\nData: `sweeps.csv`.\n\nAt ω* the slowest support slides at {umin:.4} m/s.\n\n"
    ))
}

fn write_angle(d: &Data, w: &mut Writer) -> anyhow::Result<String> {
    let mut frozen = String::from("theta,omega_box_frozen_game_dt,omega_disk_frozen_game_dt\n");
    for r in &d.frozen {
        writeln!(frozen, "{},{},{}", r[0], r[1], r[2])?;
    }
    w.file("box_frozen_omega_vs_theta.csv", frozen.as_bytes())?;
    let mut hist = String::from("t,theta,omega\n");
    for r in &d.history {
        writeln!(hist, "{},{},{}", r[0], r[1], r[2])?;
    }
    w.file("box_engine_history_game_dt.csv", hist.as_bytes())?;
    let mut csv = String::from("idiom,theta0,omega_at_0.5s\n");
    let mut md = String::from("| idiom (Δt = 1/60) |");
    for th0 in THETA0S {
        write!(md, " θ₀ = {th0} |")?;
    }
    md.push_str("\n|---|");
    md.push_str(&"---:|".repeat(THETA0S.len()));
    md.push('\n');
    for (mk, m) in idioms().iter().enumerate() {
        write!(md, "| {} |", m.as_str())?;
        for &(_, k, wv) in d.theta.iter().filter(|t| t.0 == mk) {
            writeln!(csv, "{},{},{wv}", m.as_str(), THETA0S[k])?;
            write!(md, " {wv:.4} |")?;
        }
        md.push('\n');
    }
    w.file("theta_dependence.csv", csv.as_bytes())?;
    let (fmin, fmax) = min_max(d.frozen.iter().map(|r| r[1]));
    // Where the frozen box law falls through zero (its stable lock), and
    // where the engine run ends and how it swings over its last second.
    let zero = d
        .frozen
        .windows(2)
        .find(|w| w[0][1] > 0.0 && w[1][1] <= 0.0)
        .map_or(f64::NAN, |w| {
            w[0][0] + w[0][1] / (w[0][1] - w[1][1]) * (w[1][0] - w[0][0])
        });
    let last = d.history.last().copied().unwrap_or([f64::NAN; 3]);
    let th_end = last[1].rem_euclid(FRAC_PI_2);
    let (sw_lo, sw_hi) = min_max(
        d.history
            .iter()
            .filter(|r| r[0] >= last[0] - 1.0)
            .map(|r| r[2]),
    );
    // The line plot: the frozen laws' ω*(θ) and the engine's ω against its
    // angle mod π/2.
    let engine: Vec<(f64, f64)> = d
        .history
        .iter()
        .map(|r| (r[1].rem_euclid(FRAC_PI_2), r[2]))
        .collect();
    let panel = Panel::new(
        format!("Frozen steady ω*(θ) at v_c = {V_SWEEP} m/s, φ = π/4 + 0.3, Δt = 1/60"),
        Axis::lin("object angle θ mod π/2 (rad)").range(0.0, FRAC_PI_2),
        Axis::lin("ω (rad/s)"),
    )
    .legend(Legend::LowerRight)
    .series(
        Series::new("impulse_box, frozen ω*(θ)", BLUE_, Stroke::Solid)
            .points(d.frozen.iter().map(|r| (r[0], r[1])).collect()),
    )
    .series(
        Series::new("impulse_disk, frozen ω*(θ)", ORANGE, Stroke::Dashed)
            .points(d.frozen.iter().map(|r| (r[0], r[2])).collect()),
    )
    .series(
        Series::new(
            format!("impulse_box engine run from θ = {THETA0}"),
            GREY,
            Stroke::Dots,
        )
        .width(2)
        .points(engine),
    );
    w.figure(
        "box_angle.svg",
        &Figure {
            size: (1100, 620),
            cols: 1,
            panels: vec![panel],
            key: None,
        },
    )?;
    Ok(format!(
        "## Angle dependence\n\nω after {T_SHORT} s for several starting angles θ₀ (v_c = \
         {V_SWEEP} m/s, φ = π/4 + 0.3):\n\n{md}\nThe box law's frozen steady ω*(θ) at Δt = 1/60 \
         ranges over [{fmin:.4}, {fmax:.4}] rad/s (period π/2; `box_frozen_omega_vs_theta.csv`, \
         {} angles); the engine's θ and ω along a run from θ₀ = {THETA0} at the same push and step \
         are in `box_engine_history_game_dt.csv`; `box_angle.svg` draws both. The frozen law \
         falls through zero (its stable lock at this step) at θ = {zero:.4} rad; the run turns \
         along the frozen ω*(θ) and ends at θ mod π/2 = {th_end:.4} rad, {short:.4} rad before \
         it, with ω swinging over [{sw_lo:.3}, {sw_hi:.3}] rad/s in its last second.\n\n",
        d.frozen.len(),
        short = zero - th_end,
    ))
}

fn locks(d: &Data, w: &mut Writer) -> anyhow::Result<String> {
    let mut md = String::from("## Box locks\n\n");
    let kb = idioms()
        .iter()
        .position(|m| *m == FrictionModel::ImpulseBox)
        .unwrap_or(2);
    for (dt, &step) in DTS.iter().enumerate() {
        let worst = d.cells(kb, dt).map(|c| c.lock_dist).fold(0.0, f64::max);
        writeln!(
            md,
            "* impulse_box at Δt = {}: largest distance (mod π/2) between the engine's final angle and the nearest predicted stable lock angle over the grid: {worst:.2e} rad.",
            dt_label(step)
        )?;
    }
    let p = push(V_SWEEP, PHI_TABLE, T_RUN);
    let locks = lock_angles(FrictionModel::ImpulseBox, &plate(), &p, FINE_DT, 720);
    let mut csv = String::from("dt,speed,phi,theta,stable\n");
    for l in &locks {
        writeln!(csv, "{FINE_DT},{V_SWEEP},{PHI_TABLE},{},{}", l.0, l.1)?;
    }
    let list = |stable: bool| -> Vec<String> {
        locks
            .iter()
            .filter(|l| l.1 == stable && l.0 < FRAC_PI_2)
            .map(|l| format!("{:.4}", l.0))
            .collect()
    };
    writeln!(
        md,
        "* At v_c = {V_SWEEP}, φ = π/4 + 0.3, Δt = 1e-3 the box law's lock angles in [0, π/2): stable {:?}, unstable {:?} rad (`box_lock_angles.csv`, the zeros of G(θ, 0) over a whole turn).",
        list(true),
        list(false)
    )?;
    let mut run = String::from(
        "dt,speed,phi,theta0,final_theta_mod_quarter,final_omega,nearest_stable_lock,distance\n",
    );
    writeln!(
        run,
        "{FINE_DT},{V_SWEEP},{PHI_TABLE},{THETA0},{},{},{},{}",
        d.lock[0], d.lock[1], d.lock[2], d.lock[3]
    )?;
    writeln!(
        md,
        "* The engine from θ₀ = {THETA0} at the same push ({T_RUN} s): final angle mod π/2 {:.4} rad, final ω {:.1e} rad/s, {:.4} rad from the stable lock {:.4} (`box_lock.csv`).\n",
        d.lock[0], d.lock[1], d.lock[3], d.lock[2]
    )?;
    w.file("box_lock_angles.csv", csv.as_bytes())?;
    w.file("box_lock.csv", run.as_bytes())?;
    Ok(md)
}

fn write_stop(d: &Data, w: &mut Writer) -> anyhow::Result<String> {
    let mut csv = String::from("idiom,dt,gain,mean_abs_omega_tail,jitter_tail,angle_after_stop\n");
    let mut md = format!("| idiom | Δt | predicted step gain γ | mean |ω| over the last {} s (rad/s) | rms step-to-step Δω | angle turned after the stop (rad) |\n|---|---|---:|---:|---:|---:|\n", STOP.2);
    for &(m, dt, [gain, mean_abs, jit, turned]) in &d.stop {
        let (m, dt) = (idioms()[m], DTS[dt]);
        writeln!(
            csv,
            "{},{dt},{},{mean_abs},{jit},{turned}",
            m.as_str(),
            opt(gain)
        )?;
        writeln!(
            md,
            "| {} | {} | {} | {mean_abs:.2e} | {jit:.2e} | {turned:+.4} |",
            m.as_str(),
            dt_label(dt),
            if gain.is_nan() {
                "—".to_string()
            } else {
                format!("{gain:.3}")
            }
        )?;
    }
    w.file("stop.csv", csv.as_bytes())?;
    Ok(format!(
        "## Stopping ({} s at {V_SWEEP} m/s, then the pusher at rest for {} s)\n\n{md}\nData: `stop.csv`.\n\n",
        STOP.0,
        STOP.1
    ))
}

/// The explanations, each with the numbers that support it computed from
/// this run's data (asserted in `crates/rapier2d/tests/idioms.rs`).
fn findings(d: &Data) -> String {
    let body = plate();
    let (m, i) = (body.mass(), body.inertia_cm());
    let f = MU * MASS * G / 4.0;
    let r2 = body
        .supports()
        .map(|s| s.position.norm_squared())
        .fold(0.0, f64::max);
    // K's eigenvalues at a support: 1/m along r, 1/m + |r|²/I across it.
    let (lam_lo, lam_hi) = (1.0 / m, 1.0 / m + r2 / i);
    let ratio = lam_hi / lam_lo;
    let zone = |dt: f64| (f * dt * lam_lo, f * dt * lam_hi);
    let (zf, zg) = (zone(FINE_DT), zone(GAME_DT));
    let idx = |m: FrictionModel| idioms().iter().position(|x| *x == m).unwrap_or(0);
    let (kd, kb, kl) = (
        idx(FrictionModel::ImpulseDisk),
        idx(FrictionModel::ImpulseBox),
        idx(FrictionModel::RegularisedLinear { slip_speed: SLIP }),
    );
    let fine = DTS.iter().position(|&x| x == FINE_DT).unwrap_or(1);
    let game = DTS.iter().position(|&x| x == GAME_DT).unwrap_or(0);

    // impulse_disk
    let disk: Vec<Steady> = d
        .table_at(FrictionModel::ImpulseDisk)
        .map(|r| r.3)
        .collect();
    let (dlo, dhi) = min_max(disk.iter().map(|s| 100.0 * (s.omega - s.star) / s.star));
    let dt_change = TABLE_SPEEDS
        .iter()
        .enumerate()
        .map(|(v, _)| {
            let at = |dt: usize| {
                d.table
                    .iter()
                    .find(|r| r.0 == dt && r.1 == v && r.2 == kd)
                    .map_or(f64::NAN, |r| r.3.omega)
            };
            rel(at(game), at(fine))
        })
        .fold(0.0, f64::max);
    let disk_pred = d
        .cells(kd, fine)
        .map(|c| rel(c.s.omega, c.s.pred))
        .fold(0.0, f64::max);
    let disk_chat: Vec<&GridCell> = d
        .cells(kd, game)
        .filter(|c| c.s.status() == "chatters")
        .collect();
    let n_cells = d.cells(kd, game).count();
    let chatter_text = if disk_chat.is_empty() {
        format!("At Δt = 1/60 it chatters in none of the {n_cells} cells of this grid.")
    } else {
        format!(
            "At Δt = 1/60 it chatters in {} of {n_cells} cells, all at Fr ≤ {:.3} (stop gain γ > 2, below).",
            disk_chat.len(),
            disk_chat.iter().map(|c| c.fr).fold(0.0, f64::max)
        )
    };

    // impulse_box
    let count = |k: usize, dt: usize, s: &str| d.cells(k, dt).filter(|c| c.s.status() == s).count();
    let box_w = d
        .grid
        .iter()
        .filter(|c| c.m == kb)
        .map(|c| c.s.omega.abs())
        .fold(0.0, f64::max);
    let (slo, shi) = min_max(d.cells(kb, fine).map(|c| c.s.star.abs()));
    let box_lock_fine = d.cells(kb, fine).map(|c| c.lock_dist).fold(0.0, f64::max);
    let box_nolock_game = d
        .cells(kb, game)
        .filter(|c| c.lock_dist.is_infinite())
        .count();

    // Regularised laws.
    let p = push(V_SWEEP, PHI_TABLE, T_RUN);
    let star = coulomb_star(&body, &p);
    let umin = SegmentDynamics::new(&body, &p).min_support_speed(star).0;
    let lin_vs_coulomb = d
        .grid
        .iter()
        .filter(|c| c.m == kl)
        .filter_map(|c| {
            d.grid
                .iter()
                .find(|o| o.m == 0 && o.dt == c.dt && o.i == c.i && o.j == c.j)
                .map(|o| (c.s.omega - o.s.omega).abs())
        })
        .fold(0.0, f64::max);
    let tanh: Vec<String> = d
        .sweeps
        .iter()
        .filter(|s| matches!(s.0, FrictionModel::RegularisedTanh { .. }) && s.1 == FINE_DT)
        .map(|s| {
            format!(
                "{:.1e} at v_s = {}",
                rel(s.2.omega, s.2.star),
                slip_of(s.0).unwrap_or(f64::NAN)
            )
        })
        .collect();
    let ip = body.inertia_contact();
    let pc = body.contact();
    let fd2: f64 = body
        .supports()
        .map(|s| s.friction * (s.position - pc).norm_squared())
        .sum();
    let vs_game = GAME_DT * fd2 / (2.0 * ip);
    let gain = |m: FrictionModel, dt: usize| d.stop_of(m, dt).map_or(f64::NAN, |s| s[0]);
    let lin = FrictionModel::RegularisedLinear { slip_speed: SLIP };

    format!(
        "## What explains each disagreement\n\n\
* **impulse_disk** (Box2D friction joint / Chipmunk pivot joint with max force, one per support): the force is \
`f = −clamp_len(K⁻¹u/Δt, F)` with `K = I/m + (D r)(D r)ᵀ/I` (r from the centre of mass). Below the cap it sticks \
(force `m_eff |u|/Δt` along an eigen-direction of K), but at these speeds the supports slide far above the sticking \
zone (`|K⁻¹u| < F Δt`, i.e. |u| below F Δt λ(K) = {z0:.1}–{z1:.1} mm/s at Δt = 1e-3, {g0:.3}–{g1:.3} m/s at 1/60, \
λ(K) ∈ [1/m, 1/m + |r|²/I]), so the error is not sticking: \
it is the **direction** of the capped impulse, `−K⁻¹u/|K⁻¹u|` instead of `−u/|u|`. K⁻¹ weights the part of u along r \
(eigenvalue m) {ratio:.2} times more than the part across it (eigenvalue 1/(1/m + |r|²/I) = m/{ratio:.2} here), so the friction \
moment about the contact changes and ω* is {dr} % too large at φ = π/4 + 0.3, **independent of Δt** (the two steps' ω \
differ by at most {dt_change:.1e} relative; the Δt → 0 law is the pure direction bias). The root of the moment balance \
with this law predicts the engine to ≤ {disk_pred:.1e} at Δt = 1e-3 over the whole grid. {chatter_text}\n\
* **impulse_box** (per world axis, each component capped at F Δt; rapier's joint-motor idiom): at large speeds every \
support's force is `−F (sgn u_x, sgn u_y)` in world axes, so the law depends on the angle θ. The moment `G(θ, 0)` at \
ω = 0 has stable zeros: the body **locks its orientation** and then translates with the pusher. Over the grid the \
mean ω of the second half is at most {box_w:.2} rad/s (|ω*| {slo:.4}–{shi:.2}); at Δt = 1e-3 {s_f} cells stop, \
{o_f} oscillate and {c_f} chatter about the lock ({k_f} ok), at Δt = 1/60 {s_g} stop, {o_g} oscillate, {c_g} chatter. \
The stable lock is near `θ = π/2 − φ (mod π/2)`, where the pusher runs along a world axis; \
`idioms::lock_angles` predicts it: at v_c = {V_SWEEP} from θ₀ = {THETA0} the engine's final angle is {lock_d:.4} rad from \
it (box locks, below); over the grid within {box_lock_fine:.2} rad at Δt = 1e-3, while at Δt = 1/60 {box_nolock_game} \
cells have no stable lock of the frozen law (`inf` below). `θ = 0` is an unstable balance (the runs start at θ = {THETA0}).\n\
* **regularised_linear / regularised_tanh**: the steady state only feels the law at supports slower than v_s. The \
linear law is exactly Coulomb whenever the slowest support at ω* slides faster than v_s ({umin:.3} m/s at v_c = {V_SWEEP}), so \
v_s = {SLIP} m/s changes nothing on the grid (engine ω within {lin_vs_coulomb:.1e} rad/s of Coulomb's in every cell); \
tanh converges exponentially (relative error {tanh} at Δt = 1e-3). Their failure is stopping: with the pusher at rest the \
explicit step maps ω to (1 − γ) ω with `γ = Δt Σ F_i |p_i − p_c|² / (v_s I_P)` (linear: γ = {gl_g:.3} at Δt = 1/60, \
{gl_f:.3} at 1e-3); γ > 2 (Δt > 2 v_s I_P / Σ F|d|², i.e. v_s < {vs_game:.3} m/s at Δt = 1/60) chatters like explicit \
Coulomb, γ < 2 stops cleanly (exponentially, no true sticking).\n\
* **Stopping, impulse idioms**: inside the sticking zone the one-pass Jacobi impulses give \
`γ = Σ_i (d_i × K_i⁻¹ D d_i)/I_P` (d_i = p_i − p_c), independent of Δt: {gd:.2} (disk), {gb:.2} (box), so the stop \
chatters at every Δt where γ > 2, with an amplitude of one capped impulse (a Gauss–Seidel solver iterating the four \
supports would damp this; not done).\n\n",
        z0 = 1e3 * zf.0,
        z1 = 1e3 * zf.1,
        g0 = zg.0,
        g1 = zg.1,
        dr = range_text(dlo, dhi, 0),
        s_f = count(kb, fine, "stops"),
        o_f = count(kb, fine, "oscillates"),
        c_f = count(kb, fine, "chatters"),
        k_f = count(kb, fine, "ok"),
        s_g = count(kb, game, "stops"),
        o_g = count(kb, game, "oscillates"),
        c_g = count(kb, game, "chatters"),
        lock_d = d.lock[3],
        tanh = tanh.join(", "),
        gl_g = gain(lin, game),
        gl_f = gain(lin, fine),
        gd = gain(FrictionModel::ImpulseDisk, fine),
        gb = gain(FrictionModel::ImpulseBox, fine),
    )
}

/// Rows of a CSV file as header → value maps (None when the file is missing).
pub(super) fn read_csv(path: &Path) -> Option<Vec<std::collections::HashMap<String, String>>> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next()?.split(',').collect();
    Some(
        lines
            .map(|l| {
                head.iter()
                    .zip(l.split(','))
                    .map(|(h, v)| (h.to_string(), v.to_string()))
                    .collect()
            })
            .collect(),
    )
}

/// The summary over every engine at φ = π/4 + 0.3, from this study's table
/// and the CSVs of the rapier3d and MuJoCo studies in `out` (`study all`
/// regenerates them first), followed by those studies' own READMEs.
fn other_engines(out: &Path) -> String {
    type Row = std::collections::HashMap<String, String>;
    let mut md = String::new();
    // Per row label: (v_c, ω engine, ω*) for each speed.
    type Cells = Vec<(f64, f64, f64)>;
    let mut rows: Vec<(String, Cells)> = Vec::new();
    let mut push_rows = |file: &str,
                         label: &dyn Fn(&Row) -> Option<String>,
                         speed: &str,
                         engine: &str,
                         star: &str| {
        let Some(table) = read_csv(&out.join(file)) else {
            return;
        };
        for r in &table {
            let Some(name) = label(r) else { continue };
            let num = |k: &str| {
                r.get(k)
                    .and_then(|v| v.parse::<f64>().ok())
                    .unwrap_or(f64::NAN)
            };
            let entry = (num(speed), num(engine), num(star));
            match rows.iter_mut().find(|(n, _)| *n == name) {
                Some((_, v)) => v.push(entry),
                None => rows.push((name, vec![entry])),
            }
        }
    };
    let at_1e3 = |r: &Row| r.get("dt").and_then(|v| v.parse::<f64>().ok()) == Some(FINE_DT);
    let field = |r: &Row, k: &str| r.get(k).cloned().unwrap_or_default();
    push_rows(
        "table_phi_pi4+0.3.csv",
        &|r| at_1e3(r).then(|| format!("rapier2d, {}", field(r, "idiom"))),
        "speed",
        "omega_engine",
        "omega_star",
    );
    push_rows(
        "rapier3d/paper_table.csv",
        &|r| at_1e3(r).then(|| format!("rapier3d, {}", field(r, "friction"))),
        "speed",
        "omega_engine",
        "omega_star",
    );
    push_rows(
        "mujoco/paper_plate.csv",
        &|r| {
            (field(r, "variant") == "default").then(|| format!("MuJoCo, {} cone", field(r, "cone")))
        },
        "v_c",
        "omega_mujoco",
        "omega_star",
    );
    // Box2D and Avian write one column per model.
    for (label, column) in [
        ("Box2D, Coulomb per support", "omega_box2d"),
        ("Box2D, motor joint", "omega_motor_joint"),
    ] {
        push_rows(
            "box2d/paper_plate.csv",
            &|_| Some(label.to_string()),
            "speed",
            column,
            "omega_star",
        );
    }
    for (label, column) in [
        ("avian2d, Coulomb per support", "omega_avian2d"),
        ("avian3d, own contact friction", "omega_avian3d"),
    ] {
        push_rows(
            "avian/paper_plate.csv",
            &|r| at_1e3(r).then(|| label.to_string()),
            "speed",
            column,
            "omega_star",
        );
    }
    push_rows(
        "physx/paper_plate.csv",
        &|r| {
            at_1e3(r).then(|| {
                format!(
                    "PhysX, {} ({} feet)",
                    field(r, "friction"),
                    field(r, "contacts")
                )
            })
        },
        "speed",
        "omega_engine",
        "omega_star",
    );
    md.push_str("## Every engine on the paper plate at φ = π/4 + 0.3\n\n");
    md.push_str("Steady ω in rad/s (relative error against the Coulomb model's ω*); Δt = 1e-3 s for rapier, Box2D, Avian and PhysX, MuJoCo at its defaults (Δt = 1e-3). Sources: `table_phi_pi4+0.3.csv`, `rapier3d/paper_table.csv`, `mujoco/paper_plate.csv`, `box2d/paper_plate.csv`, `avian/paper_plate.csv`, `physx/paper_plate.csv` (regenerate all with `pushval study all`; a study whose feature is missing keeps its folder). What explains each row is in the sections below.\n\n");
    let head: Vec<String> = TABLE_SPEEDS
        .iter()
        .enumerate()
        .map(|(k, v)| {
            if k == 0 {
                format!("v_c = {v:.1} m/s")
            } else {
                format!("{v:.1} m/s")
            }
        })
        .collect();
    md.push_str(&format!(
        "| engine, friction | {} |\n|---|{}\n",
        head.join(" | "),
        "---:|".repeat(TABLE_SPEEDS.len())
    ));
    let find = |v: &[(f64, f64, f64)], s: f64| v.iter().find(|e| (e.0 - s).abs() < 1e-9).copied();
    if let Some((_, v)) = rows.first() {
        let stars: Vec<String> = TABLE_SPEEDS
            .iter()
            .map(|&s| find(v, s).map_or("—".into(), |e| format!("{:.4}", e.2)))
            .collect();
        md.push_str(&format!("| Coulomb model ω* | {} |\n", stars.join(" | ")));
    }
    for (name, v) in &rows {
        let cells: Vec<String> = TABLE_SPEEDS
            .iter()
            .map(|&s| {
                find(v, s).map_or("—".into(), |e| {
                    format!("{:.4} ({:+.1} %)", e.1, 100.0 * (e.1 - e.2) / e.2)
                })
            })
            .collect();
        md.push_str(&format!("| {name} | {} |\n", cells.join(" | ")));
    }
    md.push('\n');
    for (dir, title) in [
        ("rapier3d", "rapier3d"),
        ("mujoco", "MuJoCo"),
        ("box2d", "Box2D"),
        ("avian", "Avian"),
        ("physx", "PhysX"),
    ] {
        match std::fs::read_to_string(out.join(dir).join("README.md")) {
            Ok(text) => {
                md.push_str(&format!("---\n\n(From `{dir}/README.md`: {title}.)\n\n"));
                for line in text.lines() {
                    if line.starts_with('#') {
                        md.push('#');
                    }
                    md.push_str(line);
                    md.push('\n');
                }
                md.push('\n');
            }
            Err(_) => md.push_str(&format!(
                "({title}: `{dir}/README.md` not generated yet: `pushval study {dir}`.)\n\n"
            )),
        }
    }
    md
}
