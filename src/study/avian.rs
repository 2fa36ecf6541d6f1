//! Where Avian's friction disagrees with Coulomb support friction, on the
//! paper plate (`OUT/avian/`). Compiled only with the root feature `avian`.
//!
//! Two models of the crate `pushval-avian`:
//!
//! * `avian2d`: a Coulomb force `−F_i u_i/|u_i|` at every support, from the
//!   body's own state in each of Avian's substeps: Coulomb's law itself, late
//!   by part of a substep, so the only disagreement is a first-order
//!   discretisation error. Shown by a ladder of steps (4 ms halved to
//!   0.25 ms) with the observed order, and by the (Fr, φ) map at two steps
//!   (the order of every cell);
//! * `avian3d`: the plate on ball feet on a floor with Avian's own contact
//!   friction, whose law `pushval_avian::predict` derives in closed form
//!   (Coulomb along −u per contact point, with that point's load; the loads
//!   of a rigid plate on soft contacts). At the default centre-of-mass height
//!   the prediction is the Coulomb root ω* itself; raised, the couple of the
//!   push and the friction moves load between the feet and ω leaves ω*,
//!   which `PlateScene::steady` predicts. Shown by the paper table, a
//!   load-transfer table and (Fr, φ) maps at two heights.
//!
//! Writes `paper_plate.csv`, `dt_ladder.csv` (+ `dt_ladder.svg`),
//! `load_transfer.csv`, one `map_*.csv` per (Fr, φ) map, `map.svg` and a
//! README whose numbers are computed from those files' data.
//!
//! The engines run through the crate's own simulators
//! (`Avian2dSimulator`, `Avian3dSimulator`), not the `Engine` trait: the
//! study reads the step history (for the exact tail mean of ω), the feet's
//! tail-mean loads, the calibrated rest loads, the tilt and the joint drift,
//! none of which a trajectory carries. The registry names and versions the
//! engines in the README.

use std::fmt::Write as _;
use std::path::Path;

use pushval_avian::predict::PlateScene;
use pushval_avian::{
    Avian2dSettings, Avian2dSimulator, Avian3dSettings, Avian3dSimulator, DEFAULT_SUBSTEPS,
};
use pushval_engine::{rel_err, step_tail_omega, tail_mean_omega, EngineOptions, StepRecord};
use pushval_model::{DynamicModel, Problem, SegmentDynamics, Simulator, Trajectory};

use super::plate::{
    coulomb_star, frs, length, paper_plate, phis, plate, G, HALF, MASS, MU, PHI_TABLE, TABLE_SPEEDS,
};
use super::{error_figure, error_panel, median, min_max, opt, range_text, ErrorCell};
use crate::report::plot::{Axis, Figure, Legend, Panel, Series, Stroke, GREY, PALETTE};
use crate::report::Writer;

/// Duration of the paper-plate and load-transfer runs (s).
const T_RUN: f64 = 3.0;
/// Duration of a map cell's run (s). The slowest relaxation on the map grid
/// is τ ≈ 0.11 s, so the transient has decayed by e^{−18} when the tail
/// window opens; the run's model tail mean checks it (flag `U`).
const T_MAP: f64 = 2.5;
/// The share of a run over which the steady ω is averaged (its end).
const TAIL: f64 = 0.2;
/// The step of the tables and of the maps (s).
const FINE_DT: f64 = 1e-3;
/// The convergence ladder (s): 4 ms halved four times.
const LADDER: [f64; 5] = [4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4];
/// The quick ladder (tests).
const LADDER_QUICK: [f64; 2] = [2e-3, 1e-3];
/// Centre-of-mass heights of the load-transfer table (m).
const CM_HEIGHTS: [f64; 3] = [0.0, 0.02, 0.05];
/// The quick table's heights (tests).
const CM_HEIGHTS_QUICK: [f64; 1] = [0.02];
/// The target: the closed form within this of the engine (the measure of
/// [`rel_err`]); a map cell beyond it is flagged `P`.
const PRED_TOL: f64 = 1e-2;
/// A map cell whose dynamic-model tail mean is farther than this from ω*
/// (the measure of [`rel_err`]) has not settled (flag `U`).
const SETTLED: f64 = 1e-6;

/// The two Avian models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    /// `avian2d`: Coulomb forces applied per support in the substep loop.
    Avian2d,
    /// `avian3d`: the plate on ball feet with Avian's contact friction.
    Avian3d,
}

impl Model {
    const ALL: [Model; 2] = [Model::Avian2d, Model::Avian3d];

    /// The registry's name.
    fn name(self) -> &'static str {
        match self {
            Model::Avian2d => "avian2d",
            Model::Avian3d => "avian3d",
        }
    }
}

/// One (Fr, φ) map: model, step (s), centre-of-mass height (m, avian3d).
#[derive(Debug, Clone, Copy, PartialEq)]
struct MapSpec {
    model: Model,
    dt: f64,
    cm_height: f64,
}

/// The maps: avian2d at two steps (the order of every cell), avian3d with
/// the centre of mass on the floor's plane (the prediction is ω*) and
/// raised by 2 cm (load transfer).
const MAPS: [MapSpec; 4] = [
    MapSpec {
        model: Model::Avian2d,
        dt: FINE_DT,
        cm_height: 0.0,
    },
    MapSpec {
        model: Model::Avian2d,
        dt: 2.0 * FINE_DT,
        cm_height: 0.0,
    },
    MapSpec {
        model: Model::Avian3d,
        dt: FINE_DT,
        cm_height: 0.0,
    },
    MapSpec {
        model: Model::Avian3d,
        dt: FINE_DT,
        cm_height: 0.02,
    },
];

impl MapSpec {
    /// The file stem, e.g. `avian2d_dt1e-3` or `avian3d_h0.02`.
    fn stem(&self) -> String {
        match self.model {
            Model::Avian2d => format!("avian2d_dt{:e}", self.dt),
            Model::Avian3d => format!("avian3d_h{}", self.cm_height),
        }
    }

    fn title(&self) -> String {
        match self.model {
            Model::Avian2d => format!("avian2d, Δt = {:e} s", self.dt),
            Model::Avian3d => format!("avian3d, h_cm = {} m", self.cm_height),
        }
    }
}

/// The Avian study.
#[derive(Debug, Clone, Copy)]
pub struct Avian {
    pub quick: bool,
}

/// One engine run and what it gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// The paper plate at φ = π/4 + 0.3, h_cm = 0: `[ω*, ω, ω_model,
    /// position error, θ error, joint drift, ω predicted, max tilt]` (the
    /// last two NaN for avian2d, whose law is Coulomb's: its prediction is ω*).
    Ladder { model: Model, dt: usize, v: usize },
    /// avian3d with the centre of mass at `CM_HEIGHTS[h]`, Δt = FINE_DT:
    /// `[ω*, ω predicted, ω, N₁…N₄ engine, N₁…N₄ predicted, max tilt, joint
    /// drift]`.
    Load { h: usize, v: usize },
    /// A map cell: `[v_c, ω*, ω, ω_model, ω predicted, τ]`.
    Map { map: usize, i: usize, j: usize },
}

fn ladder(quick: bool) -> &'static [f64] {
    if quick {
        &LADDER_QUICK
    } else {
        &LADDER
    }
}

fn cm_heights(quick: bool) -> &'static [f64] {
    if quick {
        &CM_HEIGHTS_QUICK
    } else {
        &CM_HEIGHTS
    }
}

fn settings3(dt: f64, cm_height: f64) -> Avian3dSettings {
    Avian3dSettings {
        dt,
        cm_height,
        ..Default::default()
    }
}

/// What every run gives: its step history and what only avian3d reports.
struct Run {
    history: Vec<StepRecord>,
    trajectory: Trajectory,
    drift: f64,
    /// avian3d: the feet's tail-mean loads (N) and the largest tilt (rad).
    tail_loads: Vec<f64>,
    tilt: f64,
}

fn run(model: Model, p: &Problem, dt: f64, cm_height: f64) -> Run {
    match model {
        Model::Avian2d => {
            let r = Avian2dSimulator::new(Avian2dSettings {
                dt,
                ..Default::default()
            })
            .run(p)
            .expect("the paper plate runs in avian2d");
            Run {
                history: r.history,
                trajectory: r.trajectory,
                drift: r.max_joint_drift,
                tail_loads: Vec::new(),
                tilt: f64::NAN,
            }
        }
        Model::Avian3d => {
            let r = Avian3dSimulator::new(settings3(dt, cm_height))
                .run(p)
                .expect("the paper plate runs in avian3d");
            Run {
                history: r.history,
                trajectory: r.trajectory,
                drift: r.max_joint_drift,
                tail_loads: r.segment_tail_loads[0].clone(),
                tilt: r.max_tilt,
            }
        }
    }
}

/// The engine's steady ω: the step-weighted mean over the last [`TAIL`].
fn tail(p: &Problem, r: &Run) -> f64 {
    step_tail_omega(p, &r.history, TAIL)[0]
}

/// The closed form's steady ω (rad/s) and loads (N) of avian3d.
fn predict(p: &Problem, cm_height: f64) -> Option<(f64, Vec<f64>)> {
    PlateScene::new(p, &settings3(FINE_DT, cm_height))
        .ok()?
        .steady(&p.pushes[0], p.initial.omega)
}

/// The gate's error measure: relative, in units of 1e-3 v_c/L where the
/// reference is ≈ 0; signed, positive where `w` turns faster than the
/// reference in its direction (`(w − ref) sign(ref) > 0`).
fn signed_err(w: f64, reference: f64, speed: f64) -> f64 {
    ((w - reference) * reference.signum()).signum() * rel_err(w, reference, speed, length())
}

fn err(w: f64, reference: f64, speed: f64) -> f64 {
    rel_err(w, reference, speed, length())
}

impl super::Study for Avian {
    type Task = Task;

    fn name(&self) -> &'static str {
        "avian"
    }

    fn dir(&self) -> &'static str {
        "avian"
    }

    fn tasks(&self) -> Vec<Task> {
        let mut t = Vec::new();
        for model in Model::ALL {
            for dt in 0..ladder(self.quick).len() {
                for v in 0..TABLE_SPEEDS.len() {
                    t.push(Task::Ladder { model, dt, v });
                }
            }
        }
        for h in 0..cm_heights(self.quick).len() {
            for v in 0..TABLE_SPEEDS.len() {
                t.push(Task::Load { h, v });
            }
        }
        for map in 0..MAPS.len() {
            for i in 0..frs(self.quick).len() {
                for j in 0..phis(self.quick).len() {
                    t.push(Task::Map { map, i, j });
                }
            }
        }
        t
    }

    fn width(&self, task: &Task) -> Option<usize> {
        Some(match task {
            Task::Ladder { .. } => 8,
            Task::Load { .. } => 13,
            Task::Map { .. } => 6,
        })
    }

    fn eval(&self, task: &Task) -> Vec<f64> {
        let body = plate();
        match *task {
            Task::Ladder { model, dt, v } => {
                let p = paper_plate(TABLE_SPEEDS[v], PHI_TABLE, T_RUN);
                let r = run(model, &p, ladder(self.quick)[dt], 0.0);
                let reference = DynamicModel::default()
                    .simulate(&p)
                    .expect("the dynamic model runs the paper plate");
                let (mut pos_err, mut theta_err) = (0.0f64, 0.0f64);
                for (a, b) in r.trajectory.samples.iter().zip(&reference.samples) {
                    pos_err = pos_err.max((a.x - b.x).hypot(a.y - b.y));
                    theta_err = theta_err.max((a.theta - b.theta).abs());
                }
                let pred = match model {
                    Model::Avian2d => f64::NAN,
                    Model::Avian3d => predict(&p, 0.0).map_or(f64::NAN, |x| x.0),
                };
                vec![
                    coulomb_star(&body, &p.pushes[0]),
                    tail(&p, &r),
                    tail_mean_omega(&p, &reference, TAIL)[0].unwrap_or(f64::NAN),
                    pos_err,
                    theta_err,
                    r.drift,
                    pred,
                    r.tilt,
                ]
            }
            Task::Load { h, v } => {
                let hcm = cm_heights(self.quick)[h];
                let p = paper_plate(TABLE_SPEEDS[v], PHI_TABLE, T_RUN);
                let r = run(Model::Avian3d, &p, FINE_DT, hcm);
                let (pred, loads) = predict(&p, hcm).unwrap_or((f64::NAN, vec![f64::NAN; 4]));
                let mut row = vec![coulomb_star(&body, &p.pushes[0]), pred, tail(&p, &r)];
                row.extend(&r.tail_loads);
                row.extend(loads);
                row.push(r.tilt);
                row.push(r.drift);
                row
            }
            Task::Map { map, i, j } => {
                let spec = MAPS[map];
                let speed = super::plate::speed_of(frs(self.quick)[i]);
                let p = paper_plate(speed, phis(self.quick)[j], T_MAP);
                let r = run(spec.model, &p, spec.dt, spec.cm_height);
                let reference = DynamicModel::default()
                    .simulate(&p)
                    .expect("the dynamic model runs the paper plate");
                let star = SegmentDynamics::new(&body, &p.pushes[0]).attractor_from(0.0);
                let pred = match spec.model {
                    Model::Avian2d => f64::NAN,
                    Model::Avian3d => predict(&p, spec.cm_height).map_or(f64::NAN, |x| x.0),
                };
                vec![
                    speed,
                    star.map_or(f64::NAN, |s| s.omega),
                    tail(&p, &r),
                    tail_mean_omega(&p, &reference, TAIL)[0].unwrap_or(f64::NAN),
                    pred,
                    star.and_then(|s| s.tau).unwrap_or(f64::NAN),
                ]
            }
        }
    }

    fn write(
        &self,
        tasks: &[Task],
        rows: &[Vec<f64>],
        _out: &Path,
        w: &mut Writer,
    ) -> anyhow::Result<()> {
        let mut ladder_rows = Vec::new();
        let mut loads = Vec::new();
        let mut cells = Vec::new();
        for (t, r) in tasks.iter().zip(rows) {
            match *t {
                Task::Ladder { model, dt, v } => ladder_rows.push(Rung {
                    model,
                    dt: ladder(self.quick)[dt],
                    v,
                    r: r.clone(),
                }),
                Task::Load { h, v } => loads.push(LoadRow {
                    h: cm_heights(self.quick)[h],
                    v,
                    r: r.clone(),
                }),
                Task::Map { map, i, j } => cells.push(Cell::from(map, i, j, r)),
            }
        }
        let mut readme = intro();
        readme.push_str(super::quick_note(self.quick));
        readme.push_str(&write_paper(&ladder_rows, w)?);
        readme.push_str(&write_ladder(self.quick, &ladder_rows, w)?);
        readme.push_str(&write_law(&ladder_rows, &loads, w)?);
        readme.push_str(&write_maps(self.quick, &cells, w)?);
        readme.push_str(NOT_COVERED);
        w.file("README.md", readme.as_bytes())?;
        Ok(())
    }
}

/// A ladder run.
#[derive(Debug, Clone)]
struct Rung {
    model: Model,
    dt: f64,
    v: usize,
    r: Vec<f64>,
}

impl Rung {
    fn speed(&self) -> f64 {
        TABLE_SPEEDS[self.v]
    }
    fn star(&self) -> f64 {
        self.r[0]
    }
    fn engine(&self) -> f64 {
        self.r[1]
    }
    /// Signed error against ω*.
    fn err(&self) -> f64 {
        signed_err(self.engine(), self.star(), self.speed())
    }
}

/// A load-transfer run.
#[derive(Debug, Clone)]
struct LoadRow {
    h: f64,
    v: usize,
    r: Vec<f64>,
}

/// A map cell's numbers.
#[derive(Debug, Clone, Copy)]
struct Cell {
    map: usize,
    i: usize,
    j: usize,
    speed: f64,
    star: f64,
    engine: f64,
    model: f64,
    pred: f64,
    tau: f64,
}

impl Cell {
    fn from(map: usize, i: usize, j: usize, r: &[f64]) -> Self {
        Self {
            map,
            i,
            j,
            speed: r[0],
            star: r[1],
            engine: r[2],
            model: r[3],
            pred: r[4],
            tau: r[5],
        }
    }
    fn err_star(&self) -> f64 {
        err(self.engine, self.star, self.speed)
    }
    /// Against the closed form (avian3d), NaN for avian2d.
    fn err_pred(&self) -> f64 {
        err(self.engine, self.pred, self.speed)
    }
    /// The model's own tail mean against ω*: what is left of the transient.
    fn unsettled(&self) -> f64 {
        err(self.model, self.star, self.speed)
    }
    fn flags(&self) -> String {
        let mut f = String::new();
        if !(self.unsettled() <= SETTLED) {
            f.push('U');
        }
        if self.err_pred() > PRED_TOL {
            f.push('P');
        }
        f
    }
}

fn intro() -> String {
    let version = |name: &str| crate::registry::engine(name, &EngineOptions::default()).version();
    let body = plate();
    format!(
        "# Avian's friction against Coulomb support friction\n\n\
         Generated by `pushval study avian` (needs `--features avian`; `pushval study all` \
         regenerates every study in `results/friction_models/`); do not edit by hand. Engines: \
         {v2} and {v3}, through the crate `pushval-avian`'s own simulators (the study reads \
         their step history, the feet's loads and the tilt), {DEFAULT_SUBSTEPS} substeps per \
         step. Scene: the paper plate ({side} m square, {MASS} kg, I = {i:.4} kg m², four corner \
         supports with μ = {MU}, equal loads, g = {G}), pushed at the corner (−{HALF}, −{HALF}), \
         starting with the pusher at ω = 0. `avian2d` is the plate seen from above with the \
         Coulomb force −F_i u_i/|u_i| of every support applied in Avian's substep loop from the \
         body's own state; `avian3d` stands the plate on four ball feet on a floor, with Avian's \
         own contact friction (the feet's μ_i calibrated at rest so that μ_i N_i = F_i). ω_engine \
         is the step-weighted mean of ω over the last {tail} % of a run ({T_RUN} s for the \
         tables, {T_MAP} s for the maps), ω* the Coulomb model's steady state. Errors are \
         `|ω − ω_ref| / max(|ω_ref|, 1e-3 v_c/L)` (`pushval_engine::rel_err`, the gate's \
         measure), L = |p_c| = {l:.4} m; where a sign is shown it is that of \
         `(ω − ω_ref) sign(ω_ref)`: + turns faster than the reference.\n\n",
        v2 = version("avian2d"),
        v3 = version("avian3d"),
        side = 2.0 * HALF,
        i = body.inertia_cm(),
        tail = 100.0 * TAIL,
        l = length(),
    )
}

/// The rung of `model` at step `dt` and speed index `v`.
fn rung(rungs: &[Rung], model: Model, dt: f64, v: usize) -> Option<&Rung> {
    rungs
        .iter()
        .find(|r| r.model == model && r.dt == dt && r.v == v)
}

/// `paper_plate.csv` and section 1: the steady ω at φ = π/4 + 0.3, Δt = 1 ms.
fn write_paper(rungs: &[Rung], w: &mut Writer) -> anyhow::Result<String> {
    let mut csv = String::from(
        "speed,phi,dt,substeps,omega_star,omega_avian2d,err_avian2d_vs_star,omega_avian3d,omega_avian3d_predicted,err_avian3d_vs_star,err_avian3d_vs_predicted\n",
    );
    let mut md = String::from(
        "| v_c (m/s) | ω* (Coulomb) | avian2d (error vs ω*) | avian3d (error vs ω*) | avian3d predicted |\n\
         |---:|---:|---:|---:|---:|\n",
    );
    for (v, &speed) in TABLE_SPEEDS.iter().enumerate() {
        let (Some(a), Some(b)) = (
            rung(rungs, Model::Avian2d, FINE_DT, v),
            rung(rungs, Model::Avian3d, FINE_DT, v),
        ) else {
            continue;
        };
        let pred = b.r[6];
        writeln!(
            csv,
            "{speed},{PHI_TABLE},{FINE_DT},{DEFAULT_SUBSTEPS},{},{},{},{},{},{},{}",
            a.star(),
            a.engine(),
            a.err(),
            b.engine(),
            pred,
            b.err(),
            signed_err(b.engine(), pred, speed)
        )?;
        writeln!(
            md,
            "| {speed} | {:.8} | {:.8} ({:+.1e}) | {:.8} ({:+.1e}) | {:.8} |",
            a.star(),
            a.engine(),
            a.err(),
            b.engine(),
            b.err(),
            pred
        )?;
    }
    w.file("paper_plate.csv", csv.as_bytes())?;
    Ok(format!(
        "## 1. The paper plate at φ = π/4 + 0.3 (ω in rad/s, Δt = {FINE_DT:e} s)\n\n{md}\n\
         (`paper_plate.csv`.) The avian3d prediction is `PlateScene::steady` of \
         `pushval_avian::predict` (section 3); with the centre of mass on the floor's plane it is \
         ω* itself.\n\n"
    ))
}

/// The observed order between a rung and the one at twice its step (same
/// model and speed): `log2(e(2Δt)/e(Δt))`, NaN where the errors change sign.
fn order(rungs: &[Rung], r: &Rung) -> f64 {
    match rung(rungs, r.model, 2.0 * r.dt, r.v) {
        Some(c) if c.err() * r.err() > 0.0 => (c.err() / r.err()).log2(),
        _ => f64::NAN,
    }
}

/// Richardson's extrapolation to Δt → 0 at order 1 from the two finest
/// rungs, `2 ω(Δt) − ω(2Δt)`, and its error against ω*.
fn richardson(rungs: &[Rung], model: Model, v: usize, finest: f64) -> Option<(f64, f64)> {
    let (a, b) = (
        rung(rungs, model, finest, v)?,
        rung(rungs, model, 2.0 * finest, v)?,
    );
    let w = 2.0 * a.engine() - b.engine();
    Some((w, signed_err(w, a.star(), a.speed())))
}

/// `dt_ladder.csv`, `dt_ladder.svg` and section 2: avian2d's (and
/// avian3d's) error against Δt.
fn write_ladder(quick: bool, rungs: &[Rung], w: &mut Writer) -> anyhow::Result<String> {
    let dts = ladder(quick);
    let mut csv = String::from(
        "model,dt,substeps,speed,phi,omega_star,omega_engine,omega_model,err_vs_star,observed_order,position_err_max,theta_err_max,joint_drift_max,max_tilt\n",
    );
    for r in rungs {
        writeln!(
            csv,
            "{},{},{DEFAULT_SUBSTEPS},{},{PHI_TABLE},{},{},{},{},{},{},{},{},{}",
            r.model.name(),
            r.dt,
            r.speed(),
            r.star(),
            r.engine(),
            r.r[2],
            r.err(),
            opt(order(rungs, r)),
            r.r[3],
            r.r[4],
            r.r[5],
            opt(r.r[7])
        )?;
    }
    w.file("dt_ladder.csv", csv.as_bytes())?;

    let mut md = String::from("| Δt (s) |");
    let mut rule = String::from("|---:|");
    for m in Model::ALL {
        for s in TABLE_SPEEDS {
            write!(md, " {} {s} m/s |", m.name())?;
            rule.push_str("---:|");
        }
    }
    md = format!("{md}\n{rule}\n");
    for &dt in dts {
        write!(md, "| {dt:e} |")?;
        for m in Model::ALL {
            for v in 0..TABLE_SPEEDS.len() {
                match rung(rungs, m, dt, v) {
                    Some(r) => write!(md, " {:+.2e} |", r.err())?,
                    None => md.push_str(" – |"),
                }
            }
        }
        md.push('\n');
    }
    let orders = |m: Model| {
        min_max(
            rungs
                .iter()
                .filter(|r| r.model == m)
                .map(|r| order(rungs, r)),
        )
    };
    let finest = dts[dts.len() - 1];
    let orders_fine = |m: Model| {
        min_max(
            rungs
                .iter()
                .filter(|r| r.model == m && r.dt == finest)
                .map(|r| order(rungs, r)),
        )
    };
    let (f2, f3) = (orders_fine(Model::Avian2d), orders_fine(Model::Avian3d));
    let extrapolated = |m: Model| {
        (0..TABLE_SPEEDS.len())
            .filter_map(|v| richardson(rungs, m, v, finest))
            .map(|x| x.1.abs())
            .fold(0.0, f64::max)
    };
    let at = |m: Model, k: usize| {
        min_max(
            rungs
                .iter()
                .filter(|r| r.model == m && r.dt == FINE_DT)
                .map(|r| r.r[k]),
        )
    };
    let (o2, o3) = (orders(Model::Avian2d), orders(Model::Avian3d));
    let (p2, t2) = (at(Model::Avian2d, 3), at(Model::Avian2d, 4));
    let (p3, t3) = (at(Model::Avian3d, 3), at(Model::Avian3d, 4));
    let settle = rungs
        .iter()
        .map(|r| err(r.r[2], r.star(), r.speed()))
        .fold(0.0, f64::max);

    // The figure: |error| against Δt, log–log, with a slope-1 guide.
    let mut panel = Panel::new(
        "steady-ω error against the step (paper plate, φ = π/4 + 0.3)",
        Axis::log("time step Δt (s)"),
        Axis::log("|ω − ω*| / |ω*|"),
    )
    .legend(Legend::LowerRight);
    for (k, m) in Model::ALL.iter().enumerate() {
        for v in 0..TABLE_SPEEDS.len() {
            let pts: Vec<(f64, f64)> = rungs
                .iter()
                .filter(|r| r.model == *m && r.v == v && r.err() != 0.0)
                .map(|r| (r.dt, r.err().abs()))
                .collect();
            let stroke = if k == 0 {
                Stroke::Solid
            } else {
                Stroke::Dashed
            };
            panel = panel.series(
                Series::new(
                    format!("{} {} m/s", m.name(), TABLE_SPEEDS[v]),
                    PALETTE[v],
                    stroke,
                )
                .points(pts),
            );
        }
    }
    if let Some(r) = rung(rungs, Model::Avian2d, dts[0], 0) {
        let e0 = r.err().abs();
        let guide: Vec<(f64, f64)> = dts.iter().map(|&dt| (dt, e0 * dt / dts[0])).collect();
        panel = panel.series(Series::new("slope 1", GREY, Stroke::Dotted).points(guide));
    }
    w.figure(
        "dt_ladder.svg",
        &Figure {
            size: (760, 560),
            cols: 1,
            panels: vec![panel],
            key: None,
        },
    )?;

    Ok(format!(
        "## 2. avian2d: Coulomb's law, first order in the step\n\n\
         avian2d applies the model's own law, −F_i u_i/|u_i| per support, but from the state \
         the previous substep left: the force lags the velocity by part of a substep \
         (Δt/{DEFAULT_SUBSTEPS}), and nothing else differs. Its steady ω therefore misses ω* by \
         an error that shrinks with Δt at first order. Signed error of the steady ω against ω* \
         on the paper plate (φ = π/4 + 0.3) over a ladder of steps, both models \
         (`dt_ladder.csv`, `dt_ladder.svg`):\n\n\
         {md}\n\
         * **Observed order** log2(e(2Δt)/e(Δt)) between neighbouring rungs: avian2d \
         {o2a}, avian3d {o3a}; between the two finest steps avian2d {f2a}, avian3d {f3a}. \
         Richardson's extrapolation at order 1 from the two finest steps, 2 ω(Δt) − ω(2Δt) \
         at Δt = {finest:e} s, is ω* to within {x2:.1e} (avian2d) and \
         {x3:.1e} (avian3d): both converge to the Coulomb root.\n\
         * **Trajectory** against the dynamic model over the {T_RUN} s run at Δt = {FINE_DT:e} s: \
         position {p2a} m and angle {t2a} rad (avian2d), {p3a} m and {t3a} rad (avian3d).\n\
         * The dynamic model's own tail mean is ω* to within {settle:.1e} on every rung: the \
         transient has decayed, the error is the engine's.\n\n",
        o2a = range_text(o2.0, o2.1, 2),
        o3a = range_text(o3.0, o3.1, 2),
        f2a = range_text(f2.0, f2.1, 2),
        f3a = range_text(f3.0, f3.1, 2),
        x2 = extrapolated(Model::Avian2d),
        x3 = extrapolated(Model::Avian3d),
        p2a = sci_range(p2),
        t2a = sci_range(t2),
        p3a = sci_range(p3),
        t3a = sci_range(t3),
    ))
}

/// `"a–b"` of a range in scientific notation with two digits.
fn sci_range((lo, hi): (f64, f64)) -> String {
    let (a, b) = (format!("{lo:.1e}"), format!("{hi:.1e}"));
    if a == b {
        a
    } else {
        format!("{a}–{b}")
    }
}

/// `load_transfer.csv` and section 3: avian3d's law in closed form and the
/// raised centre of mass.
fn write_law(rungs: &[Rung], loads: &[LoadRow], w: &mut Writer) -> anyhow::Result<String> {
    let mut csv = String::from(
        "cm_height,speed,phi,dt,omega_star,omega_predicted,omega_engine,err_vs_predicted,err_vs_star,err_predicted_vs_star,N1_engine,N2_engine,N3_engine,N4_engine,N1_predicted,N2_predicted,N3_predicted,N4_predicted,max_tilt,joint_drift_max\n",
    );
    let mut md = String::from(
        "| h_cm (m) | v_c (m/s) | ω* | predicted | engine | engine vs predicted | engine vs ω* | loads N₁…N₄ engine (N) | predicted |\n\
         |---:|---:|---:|---:|---:|---:|---:|---|---|\n",
    );
    let join = |x: &[f64], sep: &str, d: usize| {
        x.iter()
            .map(|v| format!("{v:.d$}"))
            .collect::<Vec<_>>()
            .join(sep)
    };
    for l in loads {
        let speed = TABLE_SPEEDS[l.v];
        let r = &l.r;
        let (star, pred, eng) = (r[0], r[1], r[2]);
        writeln!(
            csv,
            "{},{speed},{PHI_TABLE},{FINE_DT},{star},{pred},{eng},{},{},{},{},{},{},{}",
            l.h,
            signed_err(eng, pred, speed),
            signed_err(eng, star, speed),
            signed_err(pred, star, speed),
            join(&r[3..7], ",", 6),
            join(&r[7..11], ",", 6),
            r[11],
            r[12]
        )?;
        writeln!(
            md,
            "| {} | {speed} | {star:.6} | {pred:.6} | {eng:.6} | {:+.1e} | {:+.1e} | {} | {} |",
            l.h,
            signed_err(eng, pred, speed),
            signed_err(eng, star, speed),
            join(&r[3..7], " ", 3),
            join(&r[7..11], " ", 3)
        )?;
    }
    w.file("load_transfer.csv", csv.as_bytes())?;

    // The numbers the text quotes, from the rows above.
    let flat_pred = rungs
        .iter()
        .filter(|r| r.model == Model::Avian3d)
        .map(|r| err(r.r[6], r.star(), r.speed()))
        .fold(0.0, f64::max);
    let raised: Vec<&LoadRow> = loads.iter().filter(|l| l.h > 0.0).collect();
    let shift = min_max(
        raised
            .iter()
            .map(|l| 100.0 * err(l.r[2], l.r[0], TABLE_SPEEDS[l.v])),
    );
    let miss = loads
        .iter()
        .map(|l| err(l.r[2], l.r[1], TABLE_SPEEDS[l.v]))
        .fold(0.0, f64::max);
    let load_gap = loads
        .iter()
        .flat_map(|l| (0..4).map(move |i| (l.r[3 + i] - l.r[7 + i]).abs()))
        .fold(0.0, f64::max);
    let swing = raised
        .iter()
        .flat_map(|l| (7..11).map(move |i| (l.r[i] - MASS * G / 4.0).abs()))
        .fold(0.0, f64::max);
    let tilt = loads.iter().map(|l| l.r[11]).fold(0.0, f64::max);
    let heights: Vec<String> = {
        let mut h: Vec<f64> = raised.iter().map(|l| l.h).collect();
        h.dedup();
        h.iter().map(|h| h.to_string()).collect()
    };
    Ok(format!(
        "## 3. avian3d: Avian's contact friction in closed form\n\n\
         Avian 0.7 solves the friction of each contact point as one 2-D tangential impulse per \
         substep (`dynamics/solver/contact/tangent_part.rs`), with the update\n\n\
         ```text\n\
         λ ← clamp_disk( λ − (|s|² / sᵀK s) s ,  μ_i λ_n )\n\
         ```\n\n\
         (s the point's tangential slip velocity, K its 2×2 inverse effective mass): the \
         increment is along the slip itself, not along K⁻¹ s as in rapier3d. While the point \
         slides the disk clamp is active and the fixed point needs the increment parallel to λ, \
         so\n\n\
         ```text\n\
         f_i = −μ_i N_i u_i / |u_i|        (Coulomb along −u per contact point)\n\
         N_i = k_i (α + β · r_i),   k_i = 1 / (1/m + |r_i|² / I_t)   (rigid plate on soft contacts)\n\
         Σ N_i = m g,   Σ N_i r_i = −h_cm Σ f_i\n\
         ```\n\n\
         (I_t the plate's tilt inertia; the pushed point sits at the centre of mass's height \
         h_cm, so the push and the friction, h_cm apart, form a couple). At h_cm = 0 the loads \
         stay the rest loads, μ_i N_i = F_i, and the steady ω is the Coulomb root ω* (over the \
         table's runs the prediction is ω* to {flat_pred:.1e}); above 0 it is the fixed point of \
         \"loads from the friction at ω\" and \"ω the root of the moment balance with \
         F_i = μ_i N_i\" (`PlateScene::steady`). Raised centre of mass (h_cm = {hs} m) against \
         the flat plate, Δt = {FINE_DT:e} s (`load_transfer.csv`):\n\n{md}\n\
         * Raising the centre of mass moves ω off ω* by {s_lo:.2}–{s_hi:.2} %: the load moves \
         by up to {swing:.3} N per foot (of m g/4 = {quarter:.4} N).\n\
         * The closed form follows the engine to ≤ {miss:.1e} (target {PRED_TOL:.0e}), and the \
         feet's loads to {load_gap:.1e} N; the plate tilts by at most {tilt:.1e} rad.\n\n",
        hs = heights.join(", "),
        s_lo = shift.0,
        s_hi = shift.1,
        quarter = MASS * G / 4.0,
    ))
}

/// One map's CSV, its panels and its summary line.
fn write_maps(quick: bool, cells: &[Cell], w: &mut Writer) -> anyhow::Result<String> {
    let (frs, phis) = (frs(quick), phis(quick));
    let mut panels = Vec::new();
    let mut extra = Vec::new();
    let mut lines = Vec::new();
    for (k, spec) in MAPS.iter().enumerate() {
        let cs: Vec<&Cell> = cells.iter().filter(|c| c.map == k).collect();
        let mut csv = String::from(
            "froude,phi,speed,dt,cm_height,omega_star,omega_engine,omega_model,omega_predicted,err_vs_star,err_vs_predicted,tau,flags\n",
        );
        for c in &cs {
            writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{},{},{}",
                frs[c.i],
                phis[c.j],
                c.speed,
                spec.dt,
                spec.cm_height,
                c.star,
                c.engine,
                c.model,
                opt(c.pred),
                signed_err(c.engine, c.star, c.speed),
                opt(signed_err(c.engine, c.pred, c.speed)),
                c.tau,
                c.flags()
            )?;
        }
        w.file(&format!("map_{}.csv", spec.stem()), csv.as_bytes())?;
        let map: Vec<ErrorCell> = cs
            .iter()
            .map(|c| ErrorCell {
                i: c.i,
                j: c.j,
                rel_err: c.err_star(),
                flags: c.flags(),
            })
            .collect();
        panels.push(error_panel(&spec.title(), frs, &phis, &map));
        if spec.model == Model::Avian3d && spec.cm_height > 0.0 {
            // The same cells against the closed form instead of ω*.
            let against: Vec<ErrorCell> = cs
                .iter()
                .map(|c| ErrorCell {
                    i: c.i,
                    j: c.j,
                    rel_err: c.err_pred(),
                    flags: c.flags(),
                })
                .collect();
            extra.push(error_panel(
                &format!("{}: against the closed form, not ω*", spec.title()),
                frs,
                &phis,
                &against,
            ));
        }
        let (lo, hi) = min_max(cs.iter().map(|c| c.err_star()));
        let med = median(&cs.iter().map(|c| c.err_star()).collect::<Vec<_>>());
        let flagged = cs.iter().filter(|c| !c.flags().is_empty()).count();
        let mut line = format!(
            "* **{}** (`map_{}.csv`): error against ω* {lo:.1e}–{hi:.1e}, median {med:.1e}",
            spec.title(),
            spec.stem()
        );
        if spec.model == Model::Avian3d {
            let pred = cs.iter().map(|c| c.err_pred()).fold(0.0, f64::max);
            let off = cs
                .iter()
                .map(|c| err(c.pred, c.star, c.speed))
                .fold(0.0, f64::max);
            write!(
                line,
                "; the prediction differs from ω* by ≤ {off:.1e} and from the engine by ≤ {pred:.1e}"
            )?;
        }
        write!(line, "; {flagged} cell(s) flagged.")?;
        lines.push(line);
    }
    // The order of every avian2d cell, from the two avian2d maps.
    let pair = |dt: f64| {
        MAPS.iter()
            .position(|m| m.model == Model::Avian2d && m.dt == dt)
    };
    let orders: Vec<f64> = match (pair(FINE_DT), pair(2.0 * FINE_DT)) {
        (Some(a), Some(b)) => cells
            .iter()
            .filter(|c| c.map == a)
            .filter_map(|c| {
                let d = cells
                    .iter()
                    .find(|d| d.map == b && d.i == c.i && d.j == c.j)?;
                let (e1, e2) = (c.engine - c.model, d.engine - d.model);
                (e1 * e2 > 0.0).then(|| (e2 / e1).log2())
            })
            .collect(),
        _ => Vec::new(),
    };
    let (o_lo, o_hi) = min_max(orders.iter().copied());
    let n_cells = frs.len() * phis.len();
    panels.extend(extra);
    w.figure(
        "map.svg",
        &error_figure(
            panels,
            3,
            &[("U", "model not settled"), ("P", "> 1e-2 off closed form")],
        ),
    )?;
    Ok(format!(
        "## 4. Disagreement maps over (Fr, φ), Δt = {FINE_DT:e} s unless stated\n\n\
         Fr = v_c²/(μ g L), L = |p_c| = {l:.4} m, {nf} Froude numbers from {f0} to {f1} (log), \
         {np} φ in [{p0:.2}, {p1:.2}] rad: {n_cells} cells per map, {maps} maps (`map.svg`; a \
         cell's colour and number are log10 |ω_engine − ω*|/|ω*|, in the last panel log10 of \
         the raised plate's error against the closed form; flags: U the dynamic model's \
         tail mean is more than {SETTLED:.0e} from ω*, P the engine is more than \
         {PRED_TOL:.0e} from the closed form).\n\n{lines}\n\
         * **avian2d's order, cell by cell**: log2 of the ratio of its errors against the \
         dynamic model at Δt = {dt2:e} and {FINE_DT:e} s is {o_lo:.2}–{o_hi:.2} (median \
         {o_med:.2}) over the {n_ord} cells where both errors have one sign.\n\n",
        l = length(),
        nf = frs.len(),
        f0 = frs[0],
        f1 = frs[frs.len() - 1],
        np = phis.len(),
        p0 = phis[0],
        p1 = phis[phis.len() - 1],
        maps = MAPS.len(),
        lines = lines.join("\n"),
        dt2 = 2.0 * FINE_DT,
        o_med = median(&orders),
        n_ord = orders.len(),
    ))
}

/// What the study does not do.
const NOT_COVERED: &str = "## Not covered\n\n\
* avian2d's law is the one pushval applies (a force per support in Avian's substep loop), not a \
friction model of Avian's: a planar body without colliders has none. What it tests is Avian's \
integrator and joint, and they converge to the model at first order.\n\
* avian3d's pusher holds the contact point's horizontal position at the centre of mass's height \
(an XPBD constraint) and never slips, pulls or separates; the pushed point is not lowered below \
the centre of mass (the crate's README: Avian's joint solve after the contacts then biases the \
loads).\n\
* One friction coefficient per foot, four feet, one plate; Avian's restitution, speculative \
contacts and sleeping are left at the crate's settings.\n";
