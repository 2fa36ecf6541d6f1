//! Where Box2D's friction disagrees with Coulomb support friction, on the
//! paper plate (`OUT/box2d/`).
//!
//! Two models of the crate `pushval-box2d`:
//!
//! * `box2d`: a Coulomb force at every support from the body's own
//!   velocity, explicit in the step-start state, so first order in Δt: its
//!   steady-ω and trajectory error against the dynamic model over a ladder
//!   of steps (Δt halved from 16 ms to 0.125 ms), and its order from them;
//! * `box2d_motor_joint`: Box2D's top-down friction idiom (a motor joint
//!   from the ground, force capped at `Σ F_i`, torque at `Σ F_i |p_i|`), a
//!   different law, whose steady ω is in closed form
//!   (`pushval_box2d::predict`). On the paper plate the torque cap holds the
//!   plate (closed form ω = 0 exactly, checked absolutely); with the supports
//!   moved in to (±0.05, ±0.05) m it turns (checked relatively).
//!
//! Writes `paper_plate.csv` (the steady ω at φ = π/4 + 0.3 beside the
//! Coulomb ω*), `steady.csv` (every table run), `dt_ladder.csv`, one
//! `map_*.csv` per (Fr, φ) map, `map.svg` and a README whose numbers are
//! computed from those files' data.
//!
//! The engine runs through the registry (`crate::registry::engine`,
//! `Engine::run`): the tail-mean ω and the pose are in the trajectory, the
//! joint drift in the run's diagnostics. Only the closed form comes from the
//! crate's own API (`pushval_box2d::predict`), which the trait does not
//! carry.

use std::f64::consts::FRAC_PI_4;
use std::fmt::Write as _;
use std::path::Path;

use pushval_box2d::predict::{motor_joint_limits, motor_joint_steady};
use pushval_engine::{rel_err, tail_mean_omega, EngineOptions};
use pushval_model::{cross, Body, DynamicModel, Problem, Simulator, Support};

use super::plate::{
    coulomb_star, frs, length, paper_plate, phis, plate, speed_of, G, HALF, MASS, MU, PHI_TABLE,
    TABLE_SPEEDS,
};
use super::{dt_label, error_figure, error_panel, median, min_max, opt, range_text, ErrorCell};
use crate::report::Writer;

/// Duration of every run (s).
const T_RUN: f64 = 6.0;
/// The share of a run over which the steady ω is averaged (its end).
const TAIL: f64 = 0.2;
/// A game engine's step (s).
const GAME_DT: f64 = 1.0 / 60.0;
/// The fine step of the tables and maps (s).
const FINE_DT: f64 = 1e-3;
/// The steps of `box2d`'s convergence ladder (s): 16 ms halved 7 times.
const LADDER: [f64; 8] = [1.6e-2, 8e-3, 4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4];
/// The quick ladder (tests).
const LADDER_QUICK: [f64; 3] = [4e-3, 2e-3, 1e-3];
/// Half the side of the square the supports sit on in the "inner"
/// geometry (m): closer to the centre than the pushed corner, so the motor
/// joint's torque cap does not hold the plate.
const INNER_HALF: f64 = 0.05;
/// The push direction of the inner geometry's table (rad).
const PHI_INNER: f64 = FRAC_PI_4 + 0.8;
/// Where the Coulomb model's own tail mean differs from ω* by more than
/// this (in the measure of [`err`]), the run has not settled (flag `U`).
const SETTLED: f64 = 1e-3;
/// The closed form's target: engine within this of it (measure of [`err`]).
const CLOSED_FORM_TOL: f64 = 1e-2;

/// The two Box2D models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Model {
    /// `box2d`: Coulomb force at every support.
    Coulomb,
    /// `box2d_motor_joint`: the capped motor joint.
    MotorJoint,
}

impl Model {
    /// The registry's name.
    fn name(self) -> &'static str {
        match self {
            Model::Coulomb => "box2d",
            Model::MotorJoint => "box2d_motor_joint",
        }
    }
}

/// Where the supports sit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Geometry {
    /// The paper plate: the four corners (±HALF, ±HALF).
    Paper,
    /// The same plate on supports at (±INNER_HALF, ±INNER_HALF).
    Inner,
}

impl Geometry {
    fn name(self) -> &'static str {
        match self {
            Geometry::Paper => "paper",
            Geometry::Inner => "inner",
        }
    }

    /// The push direction of the tables (rad).
    fn table_phi(self) -> f64 {
        match self {
            Geometry::Paper => PHI_TABLE,
            Geometry::Inner => PHI_INNER,
        }
    }

    /// The problem: one push of T_RUN from ω = 0 moving with the pusher.
    fn problem(self, speed: f64, phi: f64) -> Problem {
        let mut p = paper_plate(speed, phi, T_RUN);
        if self == Geometry::Inner {
            let b = &p.body;
            let supports: Vec<Support> = b
                .supports()
                .map(|s| Support {
                    position: s.position * (INNER_HALF / HALF),
                    friction: s.friction,
                })
                .collect();
            p.body = Body::new(b.mass(), b.inertia_cm(), b.contact(), &supports)
                .expect("the plate on inner supports is a valid body");
        }
        p
    }
}

/// The steady-ω table runs: model, geometry, Δt, at every table speed.
fn steady_cases(quick: bool) -> Vec<(Model, Geometry, f64)> {
    let ladder: &[f64] = if quick { &LADDER_QUICK } else { &LADDER };
    let mut c: Vec<_> = ladder
        .iter()
        .map(|&dt| (Model::Coulomb, Geometry::Paper, dt))
        .collect();
    for geo in [Geometry::Paper, Geometry::Inner] {
        for dt in [GAME_DT, FINE_DT] {
            c.push((Model::MotorJoint, geo, dt));
        }
    }
    c
}

/// The (Fr, φ) maps: model, geometry, Δt.
const MAPS: [(Model, Geometry, f64); 4] = [
    (Model::Coulomb, Geometry::Paper, GAME_DT),
    (Model::Coulomb, Geometry::Paper, FINE_DT),
    (Model::MotorJoint, Geometry::Paper, FINE_DT),
    (Model::MotorJoint, Geometry::Inner, FINE_DT),
];

/// The Box2D study.
#[derive(Debug, Clone, Copy)]
pub struct Box2d {
    pub quick: bool,
}

/// One engine run; its row is [`Run`]'s fields in order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// A table run: case `c` of [`steady_cases`] at `TABLE_SPEEDS[v]`, at
    /// the geometry's table direction.
    Steady { c: usize, v: usize },
    /// A map cell: map `m` of [`MAPS`] at `frs[i]`, `phis[j]`.
    Map { m: usize, i: usize, j: usize },
}

/// Width of a task's row.
const WIDTH: usize = 12;

/// What one run gives.
#[derive(Debug, Clone, Copy)]
struct Run {
    /// v_c (m/s).
    speed: f64,
    /// The Coulomb model's steady ω (rad/s; NaN where it has none).
    star: f64,
    /// The engine's mean ω over the last TAIL of the run (rad/s).
    engine: f64,
    /// The dynamic (Coulomb) model's mean ω over the same window (rad/s).
    model: f64,
    /// The motor joint's closed-form steady ω from ω = 0 (rad/s; NaN for
    /// `box2d` and where ω runs away).
    pred: f64,
    /// The closed form locks (1), turns (0), NaN for `box2d`.
    locked: f64,
    /// Largest CM distance from the dynamic model over the run (m).
    pos_err: f64,
    /// Largest θ difference from the dynamic model over the run (rad).
    theta_err: f64,
    /// Largest contact drift of the pusher joint (m).
    drift: f64,
    /// The motor joint's caps F_max (N) and T_max (N m).
    f_max: f64,
    t_max: f64,
    /// The contact's moment arm `c = p_c × n_φ` (m).
    arm: f64,
}

impl Run {
    fn from(r: &[f64]) -> Self {
        Self {
            speed: r[0],
            star: r[1],
            engine: r[2],
            model: r[3],
            pred: r[4],
            locked: r[5],
            pos_err: r[6],
            theta_err: r[7],
            drift: r[8],
            f_max: r[9],
            t_max: r[10],
            arm: r[11],
        }
    }

    fn row(&self) -> Vec<f64> {
        vec![
            self.speed,
            self.star,
            self.engine,
            self.model,
            self.pred,
            self.locked,
            self.pos_err,
            self.theta_err,
            self.drift,
            self.f_max,
            self.t_max,
            self.arm,
        ]
    }

    /// Engine against the Coulomb ω*.
    fn err_star(&self) -> f64 {
        err(self.engine, self.star, self.speed)
    }

    /// Engine against the dynamic model over the same window.
    fn err_model(&self) -> f64 {
        err(self.engine, self.model, self.speed)
    }

    /// Engine against the closed form (motor joint).
    fn err_pred(&self) -> f64 {
        err(self.engine, self.pred, self.speed)
    }

    /// The error against the model per step in units of the push's time
    /// scale, `err_model / (v_c Δt / L)`.
    fn err_per_step(&self, dt: f64) -> f64 {
        self.err_model() / (self.speed * dt / length())
    }

    /// The Coulomb model has settled within the run.
    fn settled(&self) -> bool {
        err(self.model, self.star, self.speed) <= SETTLED
    }

    fn is_locked(&self) -> bool {
        self.locked == 1.0
    }
}

/// `|ω − ω_ref| / max(|ω_ref|, 1e-3 v_c/L)`: relative, and absolute in
/// units of 1e-3 v_c/L where the reference is 0 (`pushval_engine::rel_err`,
/// the gate's measure). NaN where the reference is.
fn err(w: f64, reference: f64, speed: f64) -> f64 {
    rel_err(w, reference, speed, length())
}

/// Runs `model` on `geo` at `speed`, `phi`, `dt`.
fn measure(model: Model, geo: Geometry, speed: f64, phi: f64, dt: f64) -> Run {
    let p = geo.problem(speed, phi);
    let push = p.pushes[0];
    let engine = crate::registry::engine(model.name(), &EngineOptions::default());
    let run = engine.run(&p, dt).expect("the paper plate runs in Box2D");
    let reference = DynamicModel::default()
        .simulate(&p)
        .expect("the dynamic model runs the paper plate");
    let tail = |t| tail_mean_omega(&p, t, TAIL)[0].unwrap_or(f64::NAN);
    let (mut pos_err, mut theta_err) = (0.0f64, 0.0f64);
    for (a, b) in run.trajectory.samples.iter().zip(&reference.samples) {
        pos_err = pos_err.max((a.x - b.x).hypot(a.y - b.y));
        theta_err = theta_err.max((a.theta - b.theta).abs());
    }
    let (pred, locked) = match model {
        Model::Coulomb => (f64::NAN, f64::NAN),
        Model::MotorJoint => motor_joint_steady(&p.body, &push, 0.0)
            .map_or((f64::NAN, f64::NAN), |s| {
                (s.omega, if s.locked { 1.0 } else { 0.0 })
            }),
    };
    let (f_max, t_max) = motor_joint_limits(&p.body);
    Run {
        speed,
        star: coulomb_star(&p.body, &push),
        engine: tail(&run.trajectory),
        model: tail(&reference),
        pred,
        locked,
        pos_err,
        theta_err,
        drift: run.diagnostics["max_joint_drift"]
            .as_f64()
            .unwrap_or(f64::NAN),
        f_max,
        t_max,
        arm: cross(&p.body.contact(), &push.direction()),
    }
}

impl super::Study for Box2d {
    type Task = Task;

    fn name(&self) -> &'static str {
        "box2d"
    }

    fn dir(&self) -> &'static str {
        "box2d"
    }

    fn tasks(&self) -> Vec<Task> {
        let mut t = Vec::new();
        for c in 0..steady_cases(self.quick).len() {
            for v in 0..TABLE_SPEEDS.len() {
                t.push(Task::Steady { c, v });
            }
        }
        for m in 0..MAPS.len() {
            for i in 0..frs(self.quick).len() {
                for j in 0..phis(self.quick).len() {
                    t.push(Task::Map { m, i, j });
                }
            }
        }
        t
    }

    fn width(&self, _task: &Task) -> Option<usize> {
        Some(WIDTH)
    }

    fn eval(&self, task: &Task) -> Vec<f64> {
        match *task {
            Task::Steady { c, v } => {
                let (model, geo, dt) = steady_cases(self.quick)[c];
                measure(model, geo, TABLE_SPEEDS[v], geo.table_phi(), dt).row()
            }
            Task::Map { m, i, j } => {
                let (model, geo, dt) = MAPS[m];
                let speed = speed_of(frs(self.quick)[i]);
                measure(model, geo, speed, phis(self.quick)[j], dt).row()
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
        let cases = steady_cases(self.quick);
        let mut steady = Vec::new();
        let mut cells = Vec::new();
        for (t, r) in tasks.iter().zip(rows) {
            match *t {
                Task::Steady { c, v } => steady.push(Steady {
                    case: cases[c],
                    v,
                    run: Run::from(r),
                }),
                Task::Map { m, i, j } => cells.push(Cell {
                    m,
                    i,
                    j,
                    run: Run::from(r),
                }),
            }
        }
        let mut readme = intro();
        readme.push_str(super::quick_note(self.quick));
        readme.push_str(&write_steady(&steady, w)?);
        readme.push_str(&write_paper_table(&steady, w)?);
        readme.push_str(&write_ladder(&steady, w)?);
        readme.push_str(&motor_joint(&steady));
        readme.push_str(&write_maps(self.quick, &cells, w)?);
        w.file("README.md", readme.as_bytes())?;
        Ok(())
    }
}

/// A table run with its case.
#[derive(Debug, Clone, Copy)]
struct Steady {
    case: (Model, Geometry, f64),
    v: usize,
    run: Run,
}

/// A map cell.
#[derive(Debug, Clone, Copy)]
struct Cell {
    m: usize,
    i: usize,
    j: usize,
    run: Run,
}

fn intro() -> String {
    let engine = crate::registry::engine("box2d", &EngineOptions::default());
    let body = plate();
    format!(
        "# Box2D's friction against Coulomb support friction\n\n\
         Generated by `pushval study box2d` (`pushval study all` regenerates every study in \
         `results/friction_models/`); do not edit by hand. Engine: {version}, through the \
         registry's models `box2d` and `box2d_motor_joint` (crate `pushval-box2d`: a body without \
         shapes seen from above, a kinematic pusher pinned to it at the contact by a revolute \
         joint). Scene: the paper plate ({side} m square, {MASS} kg, I = {i:.4} kg m², four corner \
         supports with μ = {MU}, equal loads, g = {G}), pushed at the corner (−{HALF}, −{HALF}), \
         starting with the pusher at ω = 0; 'inner' is the same plate on supports moved in to \
         (±{INNER_HALF}, ±{INNER_HALF}) m. Every run lasts {T_RUN} s; ω_engine is the mean of ω \
         over its last {tail} % (the trajectory's samples), ω_model the dynamic (Coulomb) model's \
         mean over the same window, ω* the Coulomb model's steady state. Errors are \
         `|ω − ω_ref| / max(|ω_ref|, 1e-3 v_c/L)` (`pushval_engine::rel_err`, the gate's \
         measure: relative, absolute in units of 1e-3 v_c/L where ω_ref = 0), L = |p_c| = \
         {l:.4} m.\n\n",
        version = engine.version(),
        side = 2.0 * HALF,
        i = body.inertia_cm(),
        tail = 100.0 * TAIL,
        l = length(),
    )
}

/// `steady.csv`: every table run.
fn write_steady(steady: &[Steady], w: &mut Writer) -> anyhow::Result<String> {
    let mut csv = String::from(
        "model,geometry,dt,speed,phi,omega_star,omega_engine,omega_model,omega_closed_form,locked,err_vs_star,err_vs_model,err_vs_closed_form,position_err_max,theta_err_max,joint_drift_max,f_max,t_max,moment_arm\n",
    );
    for s in steady {
        let (model, geo, dt) = s.case;
        let r = &s.run;
        writeln!(
            csv,
            "{},{},{dt},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            model.name(),
            geo.name(),
            r.speed,
            geo.table_phi(),
            opt(r.star),
            r.engine,
            r.model,
            opt(r.pred),
            opt(r.locked),
            opt(r.err_star()),
            r.err_model(),
            opt(r.err_pred()),
            r.pos_err,
            r.theta_err,
            r.drift,
            r.f_max,
            r.t_max,
            r.arm,
        )?;
    }
    w.file("steady.csv", csv.as_bytes())?;
    Ok(String::new())
}

fn find(steady: &[Steady], model: Model, geo: Geometry, dt: f64, v: usize) -> Option<&Run> {
    steady
        .iter()
        .find(|s| s.case == (model, geo, dt) && s.v == v)
        .map(|s| &s.run)
}

/// `paper_plate.csv` and its table: the steady ω at φ = π/4 + 0.3, Δt = 1e-3.
fn write_paper_table(steady: &[Steady], w: &mut Writer) -> anyhow::Result<String> {
    let mut csv = String::from(
        "speed,omega_star,omega_model,omega_box2d,box2d_err_vs_star,omega_motor_joint,omega_motor_joint_closed_form,motor_joint_locked,motor_joint_err_vs_closed_form,motor_joint_err_vs_star\n",
    );
    let mut md = String::from(
        "| v_c (m/s) | Coulomb ω* | `box2d` (error vs ω*) | `box2d_motor_joint` | its closed form |\n|---:|---:|---:|---:|---:|\n",
    );
    for v in 0..TABLE_SPEEDS.len() {
        let (Some(c), Some(m)) = (
            find(steady, Model::Coulomb, Geometry::Paper, FINE_DT, v),
            find(steady, Model::MotorJoint, Geometry::Paper, FINE_DT, v),
        ) else {
            continue;
        };
        writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{}",
            c.speed,
            c.star,
            c.model,
            c.engine,
            c.err_star(),
            m.engine,
            opt(m.pred),
            opt(m.locked),
            opt(m.err_pred()),
            m.err_star()
        )?;
        writeln!(
            md,
            "| {} | {:.4} | {:.4} ({:.1e}) | {} | {} |",
            c.speed,
            c.star,
            c.engine,
            c.err_star(),
            omega_text(m.engine),
            if m.is_locked() {
                format!("{} (locked)", m.pred)
            } else {
                format!("{:.4}", m.pred)
            }
        )?;
    }
    w.file("paper_plate.csv", csv.as_bytes())?;
    Ok(format!(
        "## 1. The paper plate at φ = π/4 + 0.3, Δt = {} (ω in rad/s; `paper_plate.csv`)\n\n{md}\n",
        dt_label(FINE_DT)
    ))
}

/// `dt_ladder.csv` and the finding on `box2d`'s accuracy.
fn write_ladder(steady: &[Steady], w: &mut Writer) -> anyhow::Result<String> {
    let rungs: Vec<(f64, usize, &Run)> = steady
        .iter()
        .filter(|s| s.case.0 == Model::Coulomb)
        .map(|s| (s.case.2, s.v, &s.run))
        .collect();
    let mut dts: Vec<f64> = rungs.iter().map(|r| r.0).collect();
    dts.sort_by(|a, b| b.total_cmp(a));
    dts.dedup();
    let at = |dt: f64, v: usize| rungs.iter().find(|r| r.0 == dt && r.1 == v).map(|r| r.2);
    // Observed order of the steady-ω error between a rung and the next finer.
    let order = |k: usize, v: usize| -> f64 {
        match (at(dts[k - 1], v), at(dts[k], v)) {
            (Some(a), Some(b)) => (a.err_model() / b.err_model()).ln() / (dts[k - 1] / dts[k]).ln(),
            _ => f64::NAN,
        }
    };
    let mut csv = String::from(
        "dt,speed,omega_model,omega_engine,err_vs_model,err_over_dt,observed_order,position_err_max,theta_err_max,joint_drift_max\n",
    );
    let mut md = String::from("| Δt (s) |");
    for v in TABLE_SPEEDS {
        write!(md, " v_c = {v}: ω error (order) | position (m) |")?;
    }
    md.push_str("\n|---:|");
    md.push_str(&"---:|---:|".repeat(TABLE_SPEEDS.len()));
    md.push('\n');
    let (mut orders, mut consts, mut pos_consts, mut ks) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (k, &dt) in dts.iter().enumerate() {
        write!(md, "| {dt:e} |")?;
        for v in 0..TABLE_SPEEDS.len() {
            let Some(r) = at(dt, v) else {
                md.push_str(" — | — |");
                continue;
            };
            let p = if k == 0 { f64::NAN } else { order(k, v) };
            if !p.is_nan() {
                orders.push(p);
            }
            consts.push(r.err_model() / dt);
            pos_consts.push(r.pos_err / dt);
            ks.push(r.err_per_step(dt));
            writeln!(
                csv,
                "{dt},{},{},{},{},{},{},{},{},{}",
                r.speed,
                r.model,
                r.engine,
                r.err_model(),
                r.err_model() / dt,
                opt(p),
                r.pos_err,
                r.theta_err,
                r.drift
            )?;
            write!(
                md,
                " {:.2e}{} | {:.2e} |",
                r.err_model(),
                if p.is_nan() {
                    String::new()
                } else {
                    format!(" ({p:.2})")
                },
                r.pos_err
            )?;
        }
        md.push('\n');
    }
    w.file("dt_ladder.csv", csv.as_bytes())?;
    let (o_lo, o_hi) = min_max(orders.iter().copied());
    let (c_lo, c_hi) = min_max(consts.iter().copied());
    let (p_lo, p_hi) = min_max(pos_consts.iter().copied());
    let (k_lo, k_hi) = min_max(ks.iter().copied());
    let fine: Vec<&Run> = (0..TABLE_SPEEDS.len())
        .filter_map(|v| at(FINE_DT, v))
        .collect();
    let (s_lo, s_hi) = min_max(fine.iter().map(|r| r.err_star()));
    let (u_lo, u_hi) = min_max(fine.iter().map(|r| err(r.model, r.star, r.speed)));
    Ok(format!(
        "## 2. `box2d`: Coulomb at every support, first order in Δt (`dt_ladder.csv`)\n\n\
         The paper plate at φ = π/4 + 0.3; 'ω error' is the engine's tail-mean ω against the \
         dynamic model's over the same window (in brackets the observed order against the next \
         coarser step), 'position' the largest CM distance from the model over the run.\n\n{md}\n\
         **Finding.** `box2d` is Coulomb support friction up to a first-order time-stepping \
         error: the support forces are explicit in the step-start velocities and the pusher is \
         steered at the step-start heading. The steady-ω error is proportional to Δt (observed \
         order {o} between successive steps; error/Δt = {c} s⁻¹ over the ladder and the three \
         speeds, or {k} times the step in units of the push's time scale, v_c Δt/L), and so \
         is the position error (position error/Δt = {pc} m/s). At Δt = {fine} its steady ω is \
         {s} off the Coulomb ω* (the model itself is {u} off ω* over the same window: the \
         run has settled). It converges to the model; it does not follow another law.\n\n",
        o = range_text(o_lo, o_hi, 2),
        c = range_text(c_lo, c_hi, 2),
        pc = range_text(p_lo, p_hi, 2),
        k = range_text(k_lo, k_hi, 2),
        fine = dt_label(FINE_DT),
        s = range_text_e(s_lo, s_hi),
        u = range_text_e(u_lo, u_hi),
    ))
}

/// `"a–b"` in `{:.1e}` form (one value when they print alike).
fn range_text_e(lo: f64, hi: f64) -> String {
    let (a, b) = (format!("{lo:.1e}"), format!("{hi:.1e}"));
    if a == b {
        a
    } else {
        format!("{a}–{b}")
    }
}

/// The motor joint's law and its check against the engine.
fn motor_joint(steady: &[Steady]) -> String {
    let runs = |geo: Geometry| -> Vec<(f64, &Run)> {
        steady
            .iter()
            .filter(|s| s.case.0 == Model::MotorJoint && s.case.1 == geo)
            .map(|s| (s.case.2, &s.run))
            .collect()
    };
    let (paper, inner) = (runs(Geometry::Paper), runs(Geometry::Inner));
    let first = |v: &[(f64, &Run)]| v.first().map(|x| *x.1);
    let mut md = String::from(
        "| geometry | Δt | v_c (m/s) | engine ω | closed form | engine vs closed form | Coulomb ω* | engine vs ω* |\n|---|---|---:|---:|---:|---:|---:|---:|\n",
    );
    for (geo, rs) in [(Geometry::Paper, &paper), (Geometry::Inner, &inner)] {
        for (dt, r) in rs.iter() {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.1e} | {:.4} | {:.2} |",
                geo.name(),
                dt_label(*dt),
                r.speed,
                omega_text(r.engine),
                if r.is_locked() {
                    format!("{} (locked)", r.pred)
                } else {
                    format!("{:.4}", r.pred)
                },
                r.err_pred(),
                r.star,
                r.err_star()
            );
        }
    }
    let at_dt = |v: &[(f64, &Run)], dt: f64| -> Vec<Run> {
        v.iter().filter(|x| x.0 == dt).map(|x| *x.1).collect()
    };
    let max_of = |v: &[Run], f: &dyn Fn(&Run) -> f64| v.iter().map(f).fold(0.0, f64::max);
    let (paper_fine, inner_fine) = (at_dt(&paper, FINE_DT), at_dt(&inner, FINE_DT));
    let inner_game = at_dt(&inner, GAME_DT);
    let max_abs = max_of(&at_dt(&paper, FINE_DT), &|r| r.engine.abs())
        .max(max_of(&at_dt(&paper, GAME_DT), &|r| r.engine.abs()));
    let paper_err = max_of(&paper_fine, &|r| r.err_pred());
    let all_locked = paper.iter().all(|x| x.1.is_locked());
    let inner_err = max_of(&inner_fine, &|r| r.err_pred());
    let inner_err_game = max_of(&inner_game, &|r| r.err_pred());
    let none_locked = inner.iter().all(|x| x.1.locked == 0.0);
    let (ic_lo, ic_hi) = min_max(inner_fine.iter().map(|r| 100.0 * r.err_star()));
    let lock_line = |r: Option<Run>, geo: Geometry| {
        r.map_or(String::new(), |r| {
            format!(
                "{}: F_max |c| = {:.4} N m against T_max = {:.4} N m",
                geo.name(),
                r.f_max * r.arm.abs(),
                r.t_max
            )
        })
    };
    format!(
        "## 3. `box2d_motor_joint`: a box law, in closed form\n\n\
         Box2D's top-down friction idiom is a motor joint from a static ground body to the \
         object's centre of mass with zero target velocities; Box2D caps its linear impulse to \
         a disk of radius h F_max and its angular impulse to h T_max, each on its own, with \
         `F_max = Σ F_i` = {f:.4} N (μ m g) and `T_max = Σ F_i |p_i|` (μ m g times the mean \
         support distance). While the object slides and turns both caps hold, so the law is a \
         friction force at the centre of mass against its velocity and a separate friction \
         torque against ω:\n\n\
         ```text\n\
         f = −F_max v_cm/|v_cm|,   τ = −T_max sgn ω\n\
         I_P ω̇ = F_max (v_c c − ω L²)/|v_cm| − T_max sgn ω + m v_c a ω\n\
         |v_cm|² = v_c² − 2 v_c c ω + ω² L²,   c = p_c × n_φ,   a = p_c · n_φ,   L = |p_c|\n\
         ```\n\n\
         The first term is non-increasing in ω, the torque term steps down at 0. So the joint \
         **locks the orientation** (ω* = 0 exactly, at every speed and mass) when \
         `F_max |c| ≤ T_max`: with equal loads, when the contact's moment arm is at most the \
         mean support distance (`predict::motor_joint_locks`); every corner push of the paper \
         plate locks. Otherwise ω* is the root of the balance on the side of `F_max c` \
         (`predict::motor_joint_steady`; quasi-static, with x = ω L/v_c, γ = c/L, \
         ρ = T_max/(F_max L): `x = γ − sgn(γ) ρ √((1 − γ²)/(1 − ρ²))`). Coulomb support \
         friction never locks: each support's force turns with its own velocity.\n\n\
         At the tables' pushes ({lp}; {li}):\n\n{md}\n\
         **Check.** On the paper plate the closed form locks ({lk}) and the engine's |ω| is at \
         most {max_abs:.1e} rad/s at either step (at Δt = {fine} an error of {paper_err:.1e} in \
         the measure above, absolute since ω_ref = 0), where Coulomb turns the plate. On the \
         inner supports the closed form turns ({nl}) and at Δt = {fine} the engine is within \
         {inner_err:.1e} of it (relative; target {CLOSED_FORM_TOL:.0e}), {ic} % off Coulomb's \
         ω*. The closed form is the law of the joint's sliding state as Δt → 0: at Δt = {game} \
         the engine is {inner_err_game:.1e} from it. (`steady.csv`.)\n\n",
        f = MU * MASS * G,
        lp = lock_line(first(&paper), Geometry::Paper),
        li = lock_line(first(&inner), Geometry::Inner),
        fine = dt_label(FINE_DT),
        game = dt_label(GAME_DT),
        lk = if all_locked {
            "every run"
        } else {
            "not every run"
        },
        nl = if none_locked {
            "every run"
        } else {
            "not every run"
        },
        ic = range_text(ic_lo, ic_hi, 0),
    )
}

/// The maps' CSVs, `map.svg` and their summary.
fn write_maps(quick: bool, cells: &[Cell], w: &mut Writer) -> anyhow::Result<String> {
    let (frs, phis) = (frs(quick), phis(quick));
    let mut panels = Vec::new();
    let mut summary = String::new();
    for (m, &(model, geo, dt)) in MAPS.iter().enumerate() {
        let cs: Vec<&Cell> = cells.iter().filter(|c| c.m == m).collect();
        let mut csv = String::from(
            "froude,phi,speed,omega_star,omega_model,omega_engine,omega_closed_form,locked,err_vs_star,err_vs_model,err_vs_closed_form,settled,position_err_max,theta_err_max,joint_drift_max\n",
        );
        for c in &cs {
            let r = &c.run;
            writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                frs[c.i],
                phis[c.j],
                r.speed,
                opt(r.star),
                r.model,
                r.engine,
                opt(r.pred),
                opt(r.locked),
                opt(r.err_star()),
                r.err_model(),
                opt(r.err_pred()),
                r.settled(),
                r.pos_err,
                r.theta_err,
                r.drift
            )?;
        }
        let name = format!("map_{}_{}_{}.csv", model.name(), geo.name(), dt_text(dt));
        w.file(&name, csv.as_bytes())?;
        let flags = |r: &Run| {
            let mut f = String::new();
            if r.is_locked() {
                f.push('L');
            }
            if model == Model::MotorJoint && r.pred.is_nan() {
                f.push('R');
            }
            if !r.settled() {
                f.push('U');
            }
            f
        };
        let panel = |title: String, e: &dyn Fn(&Run) -> f64| {
            let map: Vec<ErrorCell> = cs
                .iter()
                .map(|c| ErrorCell {
                    i: c.i,
                    j: c.j,
                    rel_err: e(&c.run),
                    flags: flags(&c.run),
                })
                .collect();
            error_panel(&title, frs, &phis, &map)
        };
        let where_ = format!("{}{}, Δt = {}", model.name(), geo_tag(geo), dt_label(dt));
        panels.push(panel(format!("{where_}: vs Coulomb ω*"), &|r| {
            r.err_star()
        }));
        let errs_star: Vec<f64> = cs.iter().map(|c| c.run.err_star()).collect();
        let settled: Vec<&&Cell> = cs.iter().filter(|c| c.run.settled()).collect();
        let count = |f: &dyn Fn(&Run) -> bool| cs.iter().filter(|c| f(&c.run)).count();
        let (th, pe) = (
            cs.iter().map(|c| c.run.theta_err).fold(0.0, f64::max),
            cs.iter().map(|c| c.run.pos_err).fold(0.0, f64::max),
        );
        match model {
            Model::Coulomb => {
                let em: Vec<f64> = settled.iter().map(|c| c.run.err_model()).collect();
                let (k_lo, k_hi) = min_max(settled.iter().map(|c| c.run.err_per_step(dt)));
                let _ = writeln!(
                    summary,
                    "* **`{}`{}, Δt = {}** ({} cells, `{name}`): against ω*, median {:.1e}, max \
                     {:.1e}; against the model over the same window (the engine's own error), \
                     median {:.1e}, max {:.1e} over the {} settled cells, i.e. {} times v_c Δt/L \
                     in every one of them; largest θ error over the run {th:.2e} rad, position \
                     {pe:.2e} m; not settled in {T_RUN} s (U): {}.",
                    model.name(),
                    geo_tag(geo),
                    dt_label(dt),
                    cs.len(),
                    median(&errs_star),
                    min_max(errs_star.iter().copied()).1,
                    median(&em),
                    min_max(em.iter().copied()).1,
                    settled.len(),
                    range_text(k_lo, k_hi, 2),
                    count(&|r| !r.settled()),
                );
            }
            Model::MotorJoint => {
                panels.push(panel(format!("{where_}: vs closed form"), &|r| {
                    r.err_pred()
                }));
                let ep: Vec<f64> = cs
                    .iter()
                    .filter(|c| !c.run.pred.is_nan())
                    .map(|c| c.run.err_pred())
                    .collect();
                let turning: Vec<&Run> = cs
                    .iter()
                    .filter(|c| c.run.locked == 0.0)
                    .map(|c| &c.run)
                    .collect();
                let turning_text = if turning.is_empty() {
                    String::new()
                } else {
                    let e: Vec<f64> = turning.iter().map(|r| r.err_pred()).collect();
                    let (s_lo, s_hi) = min_max(turning.iter().map(|r| 100.0 * r.err_star()));
                    format!(
                        "; where it turns, against the closed form median {:.1e}, max {:.1e}, \
                         and {} % off Coulomb's ω*",
                        median(&e),
                        min_max(e.iter().copied()).1,
                        range_text(s_lo, s_hi, 0)
                    )
                };
                let locked_abs = cs
                    .iter()
                    .filter(|c| c.run.is_locked())
                    .map(|c| c.run.engine.abs())
                    .fold(0.0, f64::max);
                let within = ep.iter().filter(|e| **e <= CLOSED_FORM_TOL).count();
                let _ = writeln!(
                    summary,
                    "* **`{}`{}, Δt = {}** ({} cells, `{name}`): the closed form locks (L) in {} \
                     cells (engine |ω| at most {locked_abs:.1e} rad/s there), turns in {}, has no steady state (R) in {}; engine within \
                     {CLOSED_FORM_TOL:.0e} of the closed form in {within} of {} cells (median \
                     {:.1e}, max {:.1e}){turning_text}.",
                    model.name(),
                    geo_tag(geo),
                    dt_label(dt),
                    cs.len(),
                    count(&|r| r.is_locked()),
                    count(&|r| r.locked == 0.0),
                    count(&|r| r.pred.is_nan()),
                    ep.len(),
                    median(&ep),
                    min_max(ep.iter().copied()).1,
                );
            }
        }
    }
    w.figure(
        "map.svg",
        &error_figure(
            panels,
            2,
            &[
                ("L", "closed form locks (ω = 0)"),
                ("R", "closed form: no steady state"),
                ("U", "Coulomb model not settled"),
            ],
        ),
    )?;
    Ok(format!(
        "## 4. Over the (Fr, φ) grid (`map_*.csv`, `map.svg`)\n\n\
         Fr = v_c²/(μ g L) ∈ {frs:?}, φ ∈ {n} values in [{p0:.2}, {p1:.2}] rad, {cells} cells per \
         map; each cell one run of {T_RUN} s from ω = 0. The panels show the error of the \
         engine's steady ω against the Coulomb ω* (and, for the motor joint, against its closed \
         form) in the measure above. U: the Coulomb model's own tail mean is more than \
         {SETTLED:.0e} from ω* (not settled in {T_RUN} s, or no steady state).\n\n{summary}\n",
        n = phis.len(),
        p0 = phis[0],
        p1 = phis[phis.len() - 1],
        cells = frs.len() * phis.len(),
    ))
}

/// An angular velocity (rad/s) for a table: 4 decimals, or 2 significant
/// digits where it is below 1e-3 in size.
fn omega_text(w: f64) -> String {
    if w.abs() < 1e-3 {
        format!("{w:.1e}")
    } else {
        format!("{w:.4}")
    }
}

/// `""` for the paper plate, `" (inner supports)"` otherwise.
fn geo_tag(geo: Geometry) -> &'static str {
    match geo {
        Geometry::Paper => "",
        Geometry::Inner => " (inner supports)",
    }
}

/// A step for a file name: `1-60` for 1/60 s, `1e-3` for 1 ms.
fn dt_text(dt: f64) -> String {
    dt_label(dt).replace('/', "-")
}
