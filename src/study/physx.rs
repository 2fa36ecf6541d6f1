//! Where PhysX's friction disagrees with Coulomb support friction, on the
//! paper plate (`OUT/physx/`). Compiled only with the root feature `physx`.
//!
//! The crate `pushval-physx` stands the plate on four sphere feet on a
//! ground plane with PhysX's own contact friction, in each of PhysX 5.1.3's
//! friction types (patch, two-directional, one-directional) and with the
//! feet's contacts welded into one patch (PhysX's default, the registered
//! models) or kept apart (one patch per foot). `pushval_physx::predict`
//! gives each combination's law in closed form: rows along the
//! centre-of-mass velocity (`t0`) and across it (`t1`), each clamped on its
//! own. Two criteria decide whether a run started at ω = 0 stays there:
//!
//! * Filippov's (`predict::locks`, `|M₀| ≤ H`): the moment `G(ω)` jumps
//!   across zero at ω = 0, so ω = 0 attracts from both sides in continuous
//!   time;
//! * the static balance (`predict::holds_at_rest`, `|M₀| ≤ S`): sticking
//!   `t1` rows can balance the `t0` rows' moment at ω = 0, the condition for
//!   a velocity-level step to end at ω = 0 from ω = 0, whatever the side of
//!   the centre of mass a `t1` row is on.
//!
//! The study records both beside the engine, over the paper table, a ladder
//! of steps and six (Fr, φ) maps of 400 cells, and says from the data which
//! one PhysX follows. Writes `paper_plate.csv`, `dt_ladder.csv`, one
//! `map_*.csv` per map, `map.svg` and a README whose numbers are computed
//! from those files' data.
//!
//! The runs go through the crate's own simulator (`PhysxSimulator`), not the
//! `Engine` trait: the study reads the feet's rest loads (the closed forms
//! use PhysX's friction magnitudes `μ̄ N_i`), the tail spread of ω, the
//! pusher force, the tilt and the joint drift. PhysX keeps one foundation
//! per process, so the crate runs one simulation at a time: `--shard K/N`
//! in N processes is the way to use more cores.

use std::fmt::Write as _;
use std::path::Path;

use pushval_engine::{rel_err, EngineOptions};
use pushval_model::{Body, Problem, Support};
use pushval_physx::predict::{
    holds_at_rest, lock_moments, locks, rest_moments, steady_omega, AtRest, Law, Steady,
};
use pushval_physx::{FootContacts, FrictionType, PhysxRun, PhysxSettings, PhysxSimulator};

use super::plate::{
    coulomb_star, frs, length, paper_plate, phis, plate, G, HALF, MASS, MU, PHI_TABLE, TABLE_SPEEDS,
};
use super::{error_figure, error_panel, median, min_max, range_text, ErrorCell};
use crate::report::Writer;

/// Duration of the paper-table runs (s).
const T_RUN: f64 = 4.0;
/// Duration of a map cell's run (s); ω is averaged over its last fifth.
const T_MAP: f64 = 2.5;
/// The step of the table and the maps (s).
const FINE_DT: f64 = 1e-3;
/// The ladder of the paper table (s).
const LADDER: [f64; 3] = [2e-3, 1e-3, 5e-4];
/// The quick ladder (tests).
const LADDER_QUICK: [f64; 1] = [1e-3];
/// The target: a closed form within this of the engine (see [`pred_err`]);
/// a map cell beyond it is flagged `P`.
const PRED_TOL: f64 = 1e-2;
/// The engine holds the plate still when its steady |ω| is below this share
/// of the Coulomb |ω*|.
const STILL: f64 = 1e-2;
/// PhysX's default solver iterations (position, velocity) and the
/// converged ones of the second set of maps.
const DEFAULT_ITERS: (u32, u32) = (4, 1);
const CONVERGED_ITERS: (u32, u32) = (32, 32);
/// The creep ladder: push direction (rad, a grid value), Froude numbers
/// and steps (s); each also at Δt = FINE_DT with [`CONVERGED_ITERS`].
const CREEP_PHI: f64 = 0.15 + 6.0 * (1.42 - 0.15) / 19.0;
const CREEP_FRS: [f64; 2] = [0.02, 0.5];
const CREEP_DTS: [f64; 4] = [2e-3, 1e-3, 5e-4, 2.5e-4];
/// The combinations of the creep ladder (indices into [`combos`]): the
/// ones whose runs leave the closed form at the default settings.
const CREEP_COMBOS: [usize; 3] = [1, 2, 3];
/// The contact order PhysX gives the welded patch on these scenes (support
/// indices): the first and third points get the `t0` rows of
/// one-directional friction, and patch friction anchors the diagonal (0, 2).
const ORDER: [usize; 4] = [0, 1, 2, 3];

/// A friction type and how the feet's contacts reach the solver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Combo {
    pub friction: FrictionType,
    pub contacts: FootContacts,
}

/// The six combinations: the registered models (welded) first.
fn combos() -> Vec<Combo> {
    FootContacts::ALL
        .iter()
        .flat_map(|&contacts| {
            FrictionType::ALL
                .iter()
                .map(move |&friction| Combo { friction, contacts })
        })
        .collect()
}

impl Combo {
    /// `physx_patch` for the registered (welded) models,
    /// `physx_patch/separate` otherwise.
    fn name(&self) -> String {
        match self.contacts {
            FootContacts::Welded => self.friction.model_name().to_string(),
            FootContacts::Separate => format!("{}/separate", self.friction.model_name()),
        }
    }

    fn stem(&self) -> String {
        format!("{}_{}", self.friction.as_str(), self.contacts.as_str())
    }

    fn law(&self) -> Law {
        let corners: Vec<[f64; 2]> = plate()
            .supports()
            .map(|s| [s.position.x, s.position.y])
            .collect();
        self.friction.law(self.contacts, &ORDER, &corners)
    }

    fn settings(&self, dt: f64, iters: (u32, u32)) -> PhysxSettings {
        PhysxSettings {
            friction: self.friction,
            contacts: self.contacts,
            dt,
            position_iterations: iters.0,
            velocity_iterations: iters.1,
            ..Default::default()
        }
    }
}

/// One (Fr, φ) map: a combination (index into [`combos`]) and the solver
/// iterations (position, velocity).
#[derive(Debug, Clone, Copy, PartialEq)]
struct MapSpec {
    combo: usize,
    iters: (u32, u32),
}

/// The maps: every combination at PhysX's default iterations, then the
/// three registered (welded) models with converged iterations.
fn maps() -> Vec<MapSpec> {
    let n = combos().len();
    (0..n)
        .map(|combo| MapSpec {
            combo,
            iters: DEFAULT_ITERS,
        })
        .chain(
            (0..n)
                .filter(|&k| combos()[k].contacts == FootContacts::Welded)
                .map(|combo| MapSpec {
                    combo,
                    iters: CONVERGED_ITERS,
                }),
        )
        .collect()
}

impl MapSpec {
    fn stem(&self) -> String {
        let c = combos()[self.combo];
        if self.iters == DEFAULT_ITERS {
            c.stem()
        } else {
            format!("{}_iters{}-{}", c.stem(), self.iters.0, self.iters.1)
        }
    }

    fn title(&self) -> String {
        let c = combos()[self.combo];
        format!(
            "{} ({} feet, {}/{} iterations)",
            c.friction.model_name(),
            c.contacts.as_str(),
            self.iters.0,
            self.iters.1
        )
    }
}

/// The PhysX study.
#[derive(Debug, Clone, Copy)]
pub struct Physx {
    pub quick: bool,
}

/// One engine run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// The paper plate at φ = π/4 + 0.3 for [`T_RUN`] s, default iterations.
    Table { combo: usize, dt: usize, v: usize },
    /// A map cell at [`FINE_DT`] for [`T_MAP`] s.
    Map { map: usize, i: usize, j: usize },
    /// The creep ladder at φ = [`CREEP_PHI`] for [`T_MAP`] s: step `dt`
    /// (index into [`CREEP_DTS`]) at the default iterations, or
    /// `dt == CREEP_DTS.len()`: Δt = FINE_DT with converged iterations.
    Creep { combo: usize, fr: usize, dt: usize },
}

fn ladder(quick: bool) -> &'static [f64] {
    if quick {
        &LADDER_QUICK
    } else {
        &LADDER
    }
}

fn creep_frs(quick: bool) -> &'static [f64] {
    if quick {
        &CREEP_FRS[..1]
    } else {
        &CREEP_FRS
    }
}

fn creep_dts(quick: bool) -> &'static [f64] {
    if quick {
        &CREEP_DTS[1..2]
    } else {
        &CREEP_DTS
    }
}

/// The numbers of a run, in the order of [`Row`]'s fields.
const WIDTH: usize = 19;

/// A run's numbers.
#[derive(Debug, Clone, Copy)]
struct Row {
    speed: f64,
    /// The Coulomb model's steady ω (rad/s).
    star: f64,
    /// PhysX's tail mean (rad/s) and its spread.
    engine: f64,
    engine_std: f64,
    /// The law's root reached from ω = 0 (`steady_omega`): where ω = 0 is
    /// semi-stable, the root a disturbance escapes to.
    law: f64,
    /// Filippov's lock and the static balance at ω = 0.
    locks: bool,
    holds: bool,
    /// M₀, H, S (N m).
    m0: f64,
    h: f64,
    s: f64,
    /// The pusher force along n_φ (N), the friction coefficient μ̄.
    pusher: f64,
    mu: f64,
    tilt: f64,
    drift: f64,
    loads: [f64; 4],
}

impl Row {
    fn from(r: &[f64]) -> Self {
        let b = |x: f64| x != 0.0;
        Self {
            speed: r[0],
            star: r[1],
            engine: r[2],
            engine_std: r[3],
            law: r[4],
            locks: b(r[5]),
            holds: b(r[6]),
            m0: r[7],
            h: r[8],
            s: r[9],
            pusher: r[10],
            mu: r[11],
            tilt: r[12],
            drift: r[13],
            loads: [r[14], r[15], r[16], r[17]],
        }
    }

    /// The engine against the Coulomb ω* (the gate's measure).
    fn err_star(&self) -> f64 {
        rel_err(self.engine, self.star, self.speed, length())
    }

    /// The engine held the plate still.
    fn still(&self) -> bool {
        self.engine.abs() <= STILL * self.star.abs()
    }

    /// The class of ω = 0 (`predict::at_rest`).
    fn class(&self) -> AtRest {
        if self.locks {
            AtRest::Locked
        } else if self.holds {
            AtRest::SemiStable
        } else {
            AtRest::Turns
        }
    }

    /// The closed form's outcomes: 0 (locked), 0 or the escape root
    /// (semi-stable), the root (turns).
    fn outcomes(&self) -> Vec<f64> {
        match self.class() {
            AtRest::Locked => vec![0.0],
            AtRest::SemiStable => vec![0.0, self.law],
            AtRest::Turns => vec![self.law],
        }
    }

    /// The outcome the engine is nearest to, and its error.
    fn closed_form(&self) -> (f64, f64) {
        self.outcomes()
            .into_iter()
            .map(|w| (w, pred_err(self.engine, w, self.star, self.speed)))
            .fold(
                (f64::NAN, f64::INFINITY),
                |a, b| if b.1 < a.1 { b } else { a },
            )
    }

    fn err_pred(&self) -> f64 {
        self.closed_form().1
    }

    /// A semi-stable run that left 0 for the escape root.
    fn escaped(&self) -> bool {
        self.class() == AtRest::SemiStable && self.closed_form().0 != 0.0
    }
}

/// The engine against a closed form: relative to the prediction where it
/// turns (`rel_err`, the gate's measure), and, where the prediction is a lock
/// (ω = 0), |ω| against the Coulomb |ω*|, the size of what a lock removes.
fn pred_err(engine: f64, pred: f64, star: f64, speed: f64) -> f64 {
    if pred == 0.0 {
        engine.abs() / star.abs().max(1e-3 * speed / length())
    } else {
        rel_err(engine, pred, speed, length())
    }
}

/// The body the closed forms see: the plate with PhysX's friction
/// magnitudes at rest (`μ̄ N_i`).
fn engine_body(body: &Body, run: &PhysxRun) -> Body {
    let feet: Vec<Support> = body
        .supports()
        .zip(&run.engine_friction)
        .map(|(s, &friction)| Support { friction, ..s })
        .collect();
    Body::new(body.mass(), body.inertia_cm(), body.contact(), &feet)
        .expect("the plate with PhysX's friction magnitudes is a valid body")
}

fn eval_run(settings: PhysxSettings, law: Law, p: &Problem) -> Vec<f64> {
    let body = plate();
    let r = PhysxSimulator::new(settings)
        .run(p)
        .expect("PhysX runs the paper plate");
    let eb = engine_body(&body, &r);
    let push = &p.pushes[0];
    let root: Steady = steady_omega(&eb, push, law, 0.0);
    let (m0, h) = lock_moments(&eb, push, law);
    let (_, s) = rest_moments(&eb, push, law);
    let n = push.direction();
    let f = r.segment_tail_pusher_force[0];
    let b = |x: bool| if x { 1.0 } else { 0.0 };
    let mut row = vec![
        push.speed,
        coulomb_star(&body, push),
        r.segment_tail_omega[0],
        r.segment_tail_omega_std[0],
        root.omega,
        b(locks(&eb, push, law)),
        b(holds_at_rest(&eb, push, law)),
        m0,
        h,
        s,
        f[0] * n.x + f[1] * n.y,
        r.mu,
        r.max_tilt,
        r.max_joint_drift,
    ];
    row.extend(
        r.rest_loads
            .iter()
            .copied()
            .chain(std::iter::repeat(f64::NAN))
            .take(4),
    );
    row.push(r.steps as f64);
    row
}

impl super::Study for Physx {
    type Task = Task;

    fn name(&self) -> &'static str {
        "physx"
    }

    fn dir(&self) -> &'static str {
        "physx"
    }

    fn tasks(&self) -> Vec<Task> {
        let mut t = Vec::new();
        for combo in 0..combos().len() {
            for dt in 0..ladder(self.quick).len() {
                for v in 0..TABLE_SPEEDS.len() {
                    t.push(Task::Table { combo, dt, v });
                }
            }
        }
        for map in 0..maps().len() {
            for i in 0..frs(self.quick).len() {
                for j in 0..phis(self.quick).len() {
                    t.push(Task::Map { map, i, j });
                }
            }
        }
        for combo in CREEP_COMBOS {
            for fr in 0..creep_frs(self.quick).len() {
                for dt in 0..=creep_dts(self.quick).len() {
                    t.push(Task::Creep { combo, fr, dt });
                }
            }
        }
        t
    }

    fn width(&self, _task: &Task) -> Option<usize> {
        Some(WIDTH)
    }

    fn eval(&self, task: &Task) -> Vec<f64> {
        let all = combos();
        match *task {
            Task::Table { combo, dt, v } => {
                let c = all[combo];
                let p = paper_plate(TABLE_SPEEDS[v], PHI_TABLE, T_RUN);
                eval_run(
                    c.settings(ladder(self.quick)[dt], DEFAULT_ITERS),
                    c.law(),
                    &p,
                )
            }
            Task::Map { map, i, j } => {
                let spec = maps()[map];
                let c = all[spec.combo];
                let speed = super::plate::speed_of(frs(self.quick)[i]);
                let p = paper_plate(speed, phis(self.quick)[j], T_MAP);
                eval_run(c.settings(FINE_DT, spec.iters), c.law(), &p)
            }
            Task::Creep { combo, fr, dt } => {
                let c = all[combo];
                let speed = super::plate::speed_of(creep_frs(self.quick)[fr]);
                let p = paper_plate(speed, CREEP_PHI, T_MAP);
                let dts = creep_dts(self.quick);
                let settings = match dts.get(dt) {
                    Some(&h) => c.settings(h, DEFAULT_ITERS),
                    None => c.settings(FINE_DT, CONVERGED_ITERS),
                };
                eval_run(settings, c.law(), &p)
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
        let mut table = Vec::new();
        let mut cells = Vec::new();
        let mut creep = Vec::new();
        for (t, r) in tasks.iter().zip(rows) {
            match *t {
                Task::Table { combo, dt, v } => table.push(Rung {
                    combo,
                    dt: ladder(self.quick)[dt],
                    v,
                    r: Row::from(r),
                }),
                Task::Map { map, i, j } => cells.push(Cell {
                    map,
                    i,
                    j,
                    r: Row::from(r),
                }),
                Task::Creep { combo, fr, dt } => {
                    let dts = creep_dts(self.quick);
                    creep.push(CreepRun {
                        combo,
                        fr: creep_frs(self.quick)[fr],
                        dt: dts.get(dt).copied().unwrap_or(FINE_DT),
                        iters: if dt < dts.len() {
                            DEFAULT_ITERS
                        } else {
                            CONVERGED_ITERS
                        },
                        r: Row::from(r),
                    })
                }
            }
        }
        let mut readme = intro();
        readme.push_str(super::quick_note(self.quick));
        readme.push_str(&write_paper(&table, w)?);
        readme.push_str(LAW);
        readme.push_str(&write_ladder(self.quick, &table, w)?);
        readme.push_str(&write_maps(self.quick, &cells, w)?);
        readme.push_str(&write_creep(&creep, w)?);
        readme.push_str(NOT_COVERED);
        w.file("README.md", readme.as_bytes())?;
        Ok(())
    }
}

/// A paper-table run.
#[derive(Debug, Clone, Copy)]
struct Rung {
    combo: usize,
    dt: f64,
    v: usize,
    r: Row,
}

/// A map cell.
#[derive(Debug, Clone, Copy)]
struct Cell {
    map: usize,
    i: usize,
    j: usize,
    r: Row,
}

/// A creep-ladder run.
#[derive(Debug, Clone, Copy)]
struct CreepRun {
    combo: usize,
    fr: f64,
    dt: f64,
    iters: (u32, u32),
    r: Row,
}

fn flags(r: &Row) -> String {
    let mut f = String::new();
    if r.class() == AtRest::SemiStable {
        f.push(if r.escaped() { 'E' } else { 'S' });
    }
    if r.err_pred() > PRED_TOL {
        f.push('P');
    }
    f
}

fn class_name(c: AtRest) -> &'static str {
    match c {
        AtRest::Locked => "locked",
        AtRest::SemiStable => "semi-stable",
        AtRest::Turns => "turns",
    }
}

fn intro() -> String {
    let version = crate::registry::engine("physx_patch", &EngineOptions::default()).version();
    let body = plate();
    let d = PhysxSettings::default();
    format!(
        "# PhysX's friction against Coulomb support friction\n\n\
         Generated by `pushval study physx` (needs `--features physx`; `pushval study all` \
         regenerates every study in `results/friction_models/`); do not edit by hand. Engine: \
         {version}, through the crate `pushval-physx`'s own simulator, PGS with \
         {pi}/{vi} position/velocity iterations, f32. Scene: the paper plate ({side} m square, \
         {MASS} kg, I = {i:.4} kg m², pushed at the corner (−{HALF}, −{HALF})) standing on four \
         sphere feet of radius {r} m at its corners on a ground plane, every foot with the \
         friction coefficient μ̄ = Σ F_i/(m g) = {MU} (g = {G}); the pusher is a kinematic actor \
         holding the corner through a joint that locks only the two horizontal axes, and the \
         plate starts moving with it at ω = 0 after a {settle} s settle. ω_engine is the mean ω \
         over the last 20 % of a run's steps ({T_RUN} s for the table, {T_MAP} s for the maps), \
         ω* the Coulomb model's steady state. The closed forms use PhysX's own friction \
         magnitudes μ̄ N_i, N_i the feet's loads at rest (PhysX's PGS does not share the \
         weight equally: `rest_load_*` below). Errors against ω* are \
         `|ω − ω*| / max(|ω*|, 1e-3 v_c/L)` (`pushval_engine::rel_err`, the gate's measure), \
         L = |p_c| = {l:.4} m.\n\n",
        pi = d.position_iterations,
        vi = d.velocity_iterations,
        side = 2.0 * HALF,
        i = body.inertia_cm(),
        r = d.foot_radius,
        settle = d.settle_time,
        l = length(),
    )
}

/// `paper_plate.csv` (every rung) and section 1 (Δt = FINE_DT).
fn write_paper(rungs: &[Rung], w: &mut Writer) -> anyhow::Result<String> {
    let all = combos();
    let mut csv = String::from(
        "model,friction,contacts,dt,speed,phi,omega_star,omega_engine,omega_engine_std,err_vs_star,omega_root_from_0,filippov_lock,static_hold,at_rest,M0,H,S,omega_closed_form,err_vs_closed_form,pusher_force_along_n,mu,max_tilt,joint_drift_max,rest_load_0,rest_load_1,rest_load_2,rest_load_3\n",
    );
    for g in rungs {
        let c = all[g.combo];
        let r = &g.r;
        let (cf, cf_err) = r.closed_form();
        writeln!(
            csv,
            "{},{},{},{},{},{PHI_TABLE},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            c.name(),
            c.friction.as_str(),
            c.contacts.as_str(),
            g.dt,
            r.speed,
            r.star,
            r.engine,
            r.engine_std,
            r.err_star(),
            r.law,
            r.locks as u8,
            r.holds as u8,
            class_name(r.class()),
            r.m0,
            r.h,
            r.s,
            cf,
            cf_err,
            r.pusher,
            r.mu,
            r.tilt,
            r.drift,
            r.loads[0],
            r.loads[1],
            r.loads[2],
            r.loads[3],
        )?;
    }
    w.file("paper_plate.csv", csv.as_bytes())?;

    let mut md = String::from(
        "| model (contacts) | v_c (m/s) | ω* (Coulomb) | ω PhysX | ω = 0 is | closed form | M₀, H, S (N m) | PhysX vs closed form |\n\
         |---|---:|---:|---:|---|---:|---|---:|\n",
    );
    let fine: Vec<&Rung> = rungs.iter().filter(|g| g.dt == FINE_DT).collect();
    for g in &fine {
        let c = all[g.combo];
        let r = &g.r;
        let outcomes: Vec<String> = r.outcomes().iter().map(|w| format!("{w:.5}")).collect();
        writeln!(
            md,
            "| {} ({}) | {} | {:.4} | {:.5} | {} | {} | {:.3}, {:.3}, {:.3} | {:.1e} |",
            c.friction.model_name(),
            c.contacts.as_str(),
            r.speed,
            r.star,
            r.engine,
            class_name(r.class()),
            outcomes.join(" or "),
            r.m0,
            r.h,
            r.s,
            r.err_pred()
        )?;
    }
    let worst = fine.iter().map(|g| g.r.err_pred()).fold(0.0, f64::max);
    let still: Vec<String> = all
        .iter()
        .enumerate()
        .filter(|(k, _)| fine.iter().filter(|g| g.combo == *k).all(|g| g.r.still()))
        .map(|(_, c)| format!("{} ({})", c.friction.model_name(), c.contacts.as_str()))
        .collect();
    let max_still = fine
        .iter()
        .filter(|g| g.r.still())
        .map(|g| g.r.engine.abs())
        .fold(0.0, f64::max);
    let loads = min_max(fine.iter().flat_map(|g| g.r.loads));
    let tilt = fine.iter().map(|g| g.r.tilt).fold(0.0, f64::max);
    let drift = fine.iter().map(|g| g.r.drift).fold(0.0, f64::max);
    // Welded one-directional: the pusher force is μ̄ times the load of the
    // feet with a `t0` row (0 and 2), not μ̄ m g.
    let pull = fine
        .iter()
        .find(|g| {
            let c = all[g.combo];
            c.friction == FrictionType::OneDirectional && c.contacts == FootContacts::Welded
        })
        .map(|g| {
            let r = &g.r;
            format!(
                "{:.3} N at {} m/s (μ̄ (N₀ + N₂) = {:.3} N, μ̄ m g = {:.3} N)",
                r.pusher,
                r.speed,
                r.mu * (r.loads[0] + r.loads[2]),
                r.mu * MASS * G
            )
        })
        .unwrap_or_else(|| "—".into());
    Ok(format!(
        "## 1. The paper plate at φ = π/4 + 0.3 (ω in rad/s, Δt = {FINE_DT:e} s, PhysX's \
         default iterations)\n\n{md}\n\
         (`paper_plate.csv`, every step of the ladder.) \"ω = 0 is\" and the closed form are \
         section 2's: locked (0), semi-stable (0 or the root a disturbance escapes to; the \
         error is against the nearer) or turns (the law's root from 0). The error is relative \
         where the closed form turns and |ω|/|ω*| where it is 0; the largest here is \
         {worst:.1e} (target {PRED_TOL:.0e}).\n\n\
         * Held still (|ω| ≤ {STILL} |ω*| at every speed): {still}; the largest |ω| among the \
         still runs is {max_still:.1e} rad/s.\n\
         * PhysX's PGS shares the weight of the four rigid feet as {l0:.3}–{l1:.3} N (m g/4 = \
         {quarter:.4} N): the feet's friction magnitudes μ̄ N_i follow, and so do the closed \
         forms.\n\
         * Welded one-directional friction pushes back with {pull}: only feet 0 and 2 have a \
         row along the motion.\n\
         * The plate tilts by at most {tilt:.1e} rad; the pusher joint drifts by at most \
         {drift:.1e} m in a step.\n\n",
        still = if still.is_empty() {
            "none".to_string()
        } else {
            still.join(", ")
        },
        l0 = loads.0,
        l1 = loads.1,
        quarter = MASS * G / 4.0,
    ))
}

/// The laws, from the PhysX source (section 2).
const LAW: &str = "## 2. PhysX's friction laws in closed form\n\n\
PhysX 5.1.3's PGS gives every friction patch two axes, `t0` along the body's **centre-of-mass** \
velocity (not the foot's) and `t1 = n × t0`, and solves each axis as its own row clamped to \
`±cap` (a box, not Coulomb's disk). PhysX **welds** the contact pairs of two bodies into one \
constraint, so the four feet are one patch of four points unless their contacts are kept apart \
(`eMODIFY_CONTACTS`). Per combination (`FrictionType::law`):\n\n\
| friction type | welded feet (PhysX's default, the registered model) | separate feet |\n\
|---|---|---|\n\
| patch | `t0`, `t1` at two anchors (the diagonal 0–2), cap Σ F_i / 2 each | `t0`, `t1` at every foot, cap F_i |\n\
| two-directional | `t0`, `t1` at every foot, cap F_i | the same |\n\
| one-directional | one row per foot, `t0`, `t1`, `t0`, `t1` in patch order, cap F_i | `t0` at every foot, cap F_i |\n\n\
In steady sliding a row at `p` on axis `t` gives `−c sgn(u_p·t) t`, and the steady ω is a root of \
`G(ω) = Σ (p − p_c) × f + m v_c ω (p_c·n_φ)` (`predict::moment`). At ω = 0 every foot slides \
along `t0 = n_φ` and every `t1` row has zero velocity (`u·t1 = ω p·n_φ`, p from the centre of \
mass), so `G` jumps there: `G(0±) = M₀ ∓ H` with `M₀ = −Σ_{t0} c (p − p_c) × n_φ` and \
`H = Σ_{t1} c sgn(p·n_φ) (p − p_c)·n_φ`. Each sticking row may take any force in its box on its \
own, so at ω = 0 the rows can hold any moment up to `S = Σ_{t1} c |(p − p_c)·n_φ|` ≥ H. Three \
cases (`predict::at_rest`) for a run that starts at ω = 0, as these do:\n\n\
* **locked**, `|M₀| ≤ H`: ω = 0 attracts from both sides; the plate does not turn.\n\
* **semi-stable**, `H < |M₀| ≤ S` (a `t1` row behind the centre of mass, `p·n_φ < 0`, counts \
against H but for S): the rows hold ω = 0, and ω returns to 0 from the side opposite to M₀, \
but a disturbance to the side of M₀ grows until ω reaches the law's root on that side. Both \
0 and that root are outcomes of the law; which one a run shows is decided by the solver's \
disturbances.\n\
* **turns**, `|M₀| > S`: ω leaves 0 for the law's root.\n\n";

/// The observed order between a rung and the one at twice its step.
fn order(rungs: &[Rung], g: &Rung) -> f64 {
    let e = |x: &Rung| x.r.engine - x.r.law;
    match rungs
        .iter()
        .find(|c| c.combo == g.combo && c.v == g.v && c.dt == 2.0 * g.dt)
    {
        Some(c) if e(c) * e(g) > 0.0 => (e(c) / e(g)).log2(),
        _ => f64::NAN,
    }
}

/// `dt_ladder.csv` and section 3: the turning combinations against Δt.
fn write_ladder(quick: bool, rungs: &[Rung], w: &mut Writer) -> anyhow::Result<String> {
    let all = combos();
    let dts = ladder(quick);
    let mut csv = String::from(
        "model,dt,speed,omega_engine,omega_closed_form,err_vs_closed_form,observed_order\n",
    );
    for g in rungs {
        let o = order(rungs, g);
        writeln!(
            csv,
            "{},{},{},{},{},{},{}",
            all[g.combo].name(),
            g.dt,
            g.r.speed,
            g.r.engine,
            g.r.closed_form().0,
            g.r.err_pred(),
            super::opt(o)
        )?;
    }
    w.file("dt_ladder.csv", csv.as_bytes())?;
    let turning: Vec<&Rung> = rungs
        .iter()
        .filter(|g| g.r.class() == AtRest::Turns)
        .collect();
    if turning.is_empty() || dts.len() < 2 {
        return Ok(String::from(
            "## 3. Step ladder\n\n(Not on the quick grid.)\n\n",
        ));
    }
    let mut md = String::from("| model | v_c (m/s) |");
    let mut rule = String::from("|---|---:|");
    for dt in dts {
        write!(md, " Δt = {dt:e} s |")?;
        rule.push_str("---:|");
    }
    md.push_str(" Richardson (order 1) |\n");
    rule.push_str("---:|\n");
    md.push_str(&rule);
    let mut extrapolated = Vec::new();
    for g in turning.iter().filter(|g| g.dt == dts[0]) {
        write!(md, "| {} | {} |", all[g.combo].name(), g.r.speed)?;
        let mut last = Vec::new();
        for &dt in dts {
            match turning
                .iter()
                .find(|x| x.combo == g.combo && x.v == g.v && x.dt == dt)
            {
                Some(x) => {
                    write!(
                        md,
                        " {:.5} ({:+.1e}) |",
                        x.r.engine,
                        x.r.engine - x.r.closed_form().0
                    )?;
                    last.push(x.r);
                }
                None => md.push_str(" – |"),
            }
        }
        if let [.., a, b] = last[..] {
            let x = 2.0 * b.engine - a.engine;
            let e = pred_err(x, b.closed_form().0, b.star, b.speed);
            extrapolated.push(e);
            writeln!(md, " {x:.5} ({e:.1e}) |")?;
        } else {
            md.push_str(" – |\n");
        }
    }
    let orders = min_max(turning.iter().map(|g| order(rungs, g)));
    let finest = dts[dts.len() - 1];
    let fine_err = min_max(
        turning
            .iter()
            .filter(|g| g.dt == FINE_DT)
            .map(|g| g.r.err_pred()),
    );
    Ok(format!(
        "## 3. Step ladder of the runs that turn (paper plate)\n\n\
         ω in rad/s, in brackets ω − closed form (`dt_ladder.csv`):\n\n{md}\n\
         * Observed order log2(e(2Δt)/e(Δt)) against the closed form: {o}.\n\
         * At Δt = {FINE_DT:e} s PhysX is {f0:.1e}–{f1:.1e} off the closed form; Richardson's \
         extrapolation at order 1 from Δt = {d2:e} and {finest:e} s is within {x:.1e}: the \
         engine converges to the closed form, at first order.\n\n",
        o = range_text(orders.0, orders.1, 2),
        f0 = fine_err.0,
        f1 = fine_err.1,
        d2 = 2.0 * finest,
        x = extrapolated.iter().copied().fold(0.0, f64::max),
    ))
}

/// One map's CSV and panels, and section 4.
fn write_maps(quick: bool, cells: &[Cell], w: &mut Writer) -> anyhow::Result<String> {
    let (frs, phis) = (frs(quick), phis(quick));
    let specs = maps();
    let mut star_panels = Vec::new();
    let mut pred_panels = Vec::new();
    let mut md = String::from(
        "| model (contacts, iterations) | error vs ω*: range (median) | locked / semi-stable / turns | PhysX still | semi-stable: held / escaped | within 1e-2 of the closed form | largest error vs the closed form |\n\
         |---|---|---|---:|---|---:|---:|\n",
    );
    let mut misses: Vec<(usize, String)> = Vec::new();
    let mut escapes: Vec<String> = Vec::new();
    for (k, spec) in specs.iter().enumerate() {
        let c = combos()[spec.combo];
        let cs: Vec<&Cell> = cells.iter().filter(|x| x.map == k).collect();
        let mut csv = String::from(
            "froude,phi,speed,dt,position_iterations,velocity_iterations,omega_star,omega_engine,omega_engine_std,err_vs_star,omega_root_from_0,filippov_lock,static_hold,at_rest,M0,H,S,omega_closed_form,err_vs_closed_form,rest_load_0,rest_load_1,rest_load_2,rest_load_3,flags\n",
        );
        for x in &cs {
            let r = &x.r;
            let (cf, cf_err) = r.closed_form();
            writeln!(
                csv,
                "{},{},{},{FINE_DT},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                frs[x.i],
                phis[x.j],
                r.speed,
                spec.iters.0,
                spec.iters.1,
                r.star,
                r.engine,
                r.engine_std,
                r.err_star(),
                r.law,
                r.locks as u8,
                r.holds as u8,
                class_name(r.class()),
                r.m0,
                r.h,
                r.s,
                cf,
                cf_err,
                r.loads[0],
                r.loads[1],
                r.loads[2],
                r.loads[3],
                flags(r)
            )?;
        }
        w.file(&format!("map_{}.csv", spec.stem()), csv.as_bytes())?;
        let panel = |f: &dyn Fn(&Row) -> f64, title: String| {
            let m: Vec<ErrorCell> = cs
                .iter()
                .map(|x| ErrorCell {
                    i: x.i,
                    j: x.j,
                    rel_err: f(&x.r),
                    flags: flags(&x.r),
                })
                .collect();
            error_panel(&title, frs, &phis, &m)
        };
        star_panels.push(panel(
            &|r| r.err_star(),
            format!("{}: against ω*", spec.title()),
        ));
        pred_panels.push(panel(
            &|r| r.err_pred(),
            format!("{}: against the closed form", spec.title()),
        ));

        let count = |f: &dyn Fn(&Row) -> bool| cs.iter().filter(|x| f(&x.r)).count();
        let errs: Vec<f64> = cs.iter().map(|x| x.r.err_star()).collect();
        let (lo, hi) = min_max(errs.iter().copied());
        let semi = count(&|r| r.class() == AtRest::SemiStable);
        let escaped = count(&|r| r.escaped());
        writeln!(
            md,
            "| {} ({}, {}/{}) | {lo:.1e}–{hi:.1e} ({:.1e}) | {} / {semi} / {} | {} | {} / {escaped} | {} | {:.1e} |",
            c.friction.model_name(),
            c.contacts.as_str(),
            spec.iters.0,
            spec.iters.1,
            median(&errs),
            count(&|r| r.class() == AtRest::Locked),
            count(&|r| r.class() == AtRest::Turns),
            count(&|r| r.still()),
            semi - escaped,
            count(&|r| r.err_pred() <= PRED_TOL),
            cs.iter().map(|x| x.r.err_pred()).fold(0.0, f64::max),
        )?;
        if semi > 0 {
            let esc: Vec<f64> = cs
                .iter()
                .filter(|x| x.r.escaped())
                .map(|x| x.r.err_pred())
                .collect();
            let (e0, e1) = min_max(esc.iter().copied());
            escapes.push(format!(
                "{}: {escaped} of {semi} semi-stable cells escaped, to {e0:.1e}–{e1:.1e} (median {:.1e}) of the escape root",
                spec.title(),
                median(&esc)
            ));
        }
        for x in cs.iter().filter(|x| x.r.err_pred() > PRED_TOL) {
            misses.push((
                k,
                format!(
                    "Fr {}, φ {:.3}: ω {:.4} against {:.4} ({})",
                    frs[x.i],
                    phis[x.j],
                    x.r.engine,
                    x.r.closed_form().0,
                    class_name(x.r.class())
                ),
            ));
        }
    }
    let n_cells = frs.len() * phis.len();
    let mut panels = star_panels;
    panels.extend(pred_panels);
    w.figure(
        "map.svg",
        &error_figure(
            panels,
            3,
            &[
                ("S", "semi-stable, held"),
                ("E", "semi-stable, escaped"),
                ("P", "> 1e-2 off the closed form"),
            ],
        ),
    )?;
    let mut miss_text = String::new();
    for (k, spec) in specs.iter().enumerate() {
        let mine: Vec<&String> = misses.iter().filter(|m| m.0 == k).map(|m| &m.1).collect();
        if mine.is_empty() {
            continue;
        }
        let phi_range = min_max(
            cells
                .iter()
                .filter(|x| x.map == k && x.r.err_pred() > PRED_TOL)
                .map(|x| phis[x.j]),
        );
        writeln!(
            miss_text,
            "* {}: {} cell(s) more than {PRED_TOL:.0e} off, at φ {:.3}–{:.3}; e.g. {}.",
            spec.title(),
            mine.len(),
            phi_range.0,
            phi_range.1,
            mine[0]
        )?;
    }
    if miss_text.is_empty() {
        miss_text = "* Every cell of every map is within 1e-2 of its closed form.\n".into();
    }
    Ok(format!(
        "## 4. Disagreement maps over (Fr, φ), Δt = {FINE_DT:e} s\n\n\
         Fr = v_c²/(μ g L), {nf} Froude numbers from {f0} to {f1} (log), {np} φ in \
         [{p0:.2}, {p1:.2}] rad: {n_cells} cells per map, {nm} maps: every combination at \
         PhysX's default iterations ({d0}/{d1}) and the three registered models at \
         {c0}/{c1} (`map_*.csv`; `map.svg`: the first {nm} panels log10 of the error against \
         ω*, the last {nm} against the closed form; flags: S semi-stable and held, E \
         semi-stable and escaped, P more than {PRED_TOL:.0e} off the closed form). \
         \"Still\": |ω| ≤ {STILL} |ω*|.\n\n{md}\n\
         Semi-stable cells (welded one-directional friction): which outcome a run shows is \
         not decided by the law, and more iterations do not decide it either:\n\n{esc}\n\n\
         Cells more than {PRED_TOL:.0e} off their closed form:\n\n{miss_text}\n",
        esc = escapes
            .iter()
            .map(|e| format!("* {e}."))
            .collect::<Vec<_>>()
            .join("\n"),
        nf = frs.len(),
        f0 = frs[0],
        f1 = frs[frs.len() - 1],
        np = phis.len(),
        p0 = phis[0],
        p1 = phis[phis.len() - 1],
        nm = specs.len(),
        d0 = DEFAULT_ITERS.0,
        d1 = DEFAULT_ITERS.1,
        c0 = CONVERGED_ITERS.0,
        c1 = CONVERGED_ITERS.1,
    ))
}

/// `creep.csv` and section 5: the runs that leave the closed form at the
/// default settings, against the step and the iterations.
fn write_creep(runs: &[CreepRun], w: &mut Writer) -> anyhow::Result<String> {
    let all = combos();
    let mut csv = String::from(
        "model,froude,phi,speed,dt,position_iterations,velocity_iterations,omega_star,omega_engine,omega_engine_std,at_rest,omega_closed_form,err_vs_closed_form\n",
    );
    for c in runs {
        let (cf, e) = c.r.closed_form();
        writeln!(
            csv,
            "{},{},{CREEP_PHI},{},{},{},{},{},{},{},{},{},{}",
            all[c.combo].name(),
            c.fr,
            c.r.speed,
            c.dt,
            c.iters.0,
            c.iters.1,
            c.r.star,
            c.r.engine,
            c.r.engine_std,
            class_name(c.r.class()),
            cf,
            e
        )?;
    }
    w.file("creep.csv", csv.as_bytes())?;
    let mut dts: Vec<f64> = runs
        .iter()
        .filter(|c| c.iters == DEFAULT_ITERS)
        .map(|c| c.dt)
        .collect();
    dts.sort_by(|a, b| b.total_cmp(a));
    dts.dedup();
    let mut md = String::from("| model | Fr | ω = 0 is |");
    let mut rule = String::from("|---|---:|---|");
    for dt in &dts {
        write!(md, " Δt = {dt:e} s |")?;
        rule.push_str("---:|");
    }
    writeln!(
        md,
        " Δt = {FINE_DT:e} s, {}/{} iterations |",
        CONVERGED_ITERS.0, CONVERGED_ITERS.1
    )?;
    rule.push_str("---:|\n");
    md.push_str(&rule);
    let mut keys: Vec<(usize, f64)> = runs.iter().map(|c| (c.combo, c.fr)).collect();
    keys.dedup();
    let mut orders: Vec<(usize, f64)> = Vec::new();
    let mut converged: Vec<(usize, f64)> = Vec::new();
    for (combo, fr) in keys {
        let mine: Vec<&CreepRun> = runs
            .iter()
            .filter(|c| c.combo == combo && c.fr == fr)
            .collect();
        let Some(first) = mine.first() else { continue };
        write!(
            md,
            "| {} | {fr} | {} |",
            all[combo].name(),
            class_name(first.r.class())
        )?;
        let mut prev: Option<f64> = None;
        for dt in &dts {
            match mine
                .iter()
                .find(|c| c.iters == DEFAULT_ITERS && c.dt == *dt)
            {
                Some(c) => {
                    write!(md, " {:.5} |", c.r.engine)?;
                    if let Some(p) = prev {
                        if p * c.r.engine > 0.0 && first.r.class() == AtRest::Locked {
                            orders.push((combo, (p / c.r.engine).log2()));
                        }
                    }
                    prev = Some(c.r.engine);
                }
                None => md.push_str(" – |"),
            }
        }
        match mine.iter().find(|c| c.iters == CONVERGED_ITERS) {
            Some(c) => {
                converged.push((combo, c.r.err_pred()));
                writeln!(md, " {:.5} ({:.1e}) |", c.r.engine, c.r.err_pred())?
            }
            None => md.push_str(" – |\n"),
        }
    }
    let mut bullets = String::new();
    let mut seen: Vec<usize> = runs.iter().map(|c| c.combo).collect();
    seen.dedup();
    for combo in seen {
        let Some(first) = runs.iter().find(|c| c.combo == combo) else {
            continue;
        };
        let (o0, o1) = min_max(orders.iter().filter(|o| o.0 == combo).map(|o| o.1));
        let conv = converged
            .iter()
            .filter(|c| c.0 == combo)
            .map(|c| c.1)
            .fold(0.0, f64::max);
        let pairs = orders.iter().filter(|o| o.0 == combo).count();
        let steps = dts.len().saturating_sub(1) * 2;
        let order_text = if first.r.class() != AtRest::Locked {
            "it leaves 0 for the escape root at every step".to_string()
        } else if pairs == 0 {
            "no pair of one sign".to_string()
        } else {
            format!(
                "observed order {} over {pairs} of {steps} step pairs of one sign",
                range_text(o0, o1, 2)
            )
        };
        writeln!(
            bullets,
            "* {} ({}): against the step, {order_text}; with {}/{} iterations within {conv:.1e} \
             of the closed form.",
            all[combo].name(),
            class_name(first.r.class()),
            CONVERGED_ITERS.0,
            CONVERGED_ITERS.1
        )?;
    }
    Ok(format!(
        "## 5. What is left: solver creep and escapes\n\n\
         Runs off the closed form at PhysX's default settings, at one direction φ = \
         {CREEP_PHI:.3} rad from the map grid, against the step (default iterations) and with \
         converged iterations (ω in rad/s; in brackets the error against the closed form; \
         `creep.csv`):\n\n{md}\n{bullets}\n\
         Where the closed form locks the plate, what PhysX adds is a creep of the unconverged \
         PGS: where it halves with the step (order near 1) and vanishes with the iterations it \
         is discretisation, not law. Where ω = 0 is semi-stable the run may escape at any \
         setting (section 4).\n\n",
    ))
}

/// What the study does not do.
const NOT_COVERED: &str = "## Not covered\n\n\
* TGS (PhysX's other solver) and PhysX 5.4's single remaining friction type: physx-sys 0.11.5 \
vendors PhysX 5.1.3, and the crate runs PGS.\n\
* Per-foot coefficients: PhysX's welding puts feet of different coefficients in different \
patches and reported their impulses against the wrong feet (crates/physx/README.md), so every \
foot has μ̄.\n\
* Sticking of the whole plate (pusher at rest) and PhysX's static coefficient above the dynamic \
one: both coefficients are μ̄ here.\n";
