//! Where rapier3d's own contact friction disagrees with Coulomb support
//! friction, on the paper plate standing on four ball feet (`OUT/rapier3d/`).
//!
//! Writes the paper-plate table (3 speeds × 3 friction set-ups × 2 steps),
//! the load-transfer sweep over (h_cm, h_push), a (Fr, φ) map per friction
//! model (CSV and `map.svg`) and a README with the closed forms that explain
//! each disagreement, every number computed from those files' data.
//!
//! The engine runs through `pushval_rapier3d::Rapier3dSimulator`, the crate's
//! own API, not the `Engine` trait: the study reads the per-foot loads and
//! friction forces, the contact manifolds, the settled rest loads, the step
//! history and the tail-mean ω, none of which a trajectory carries.

use std::fmt::Write as _;
use std::path::Path;

use pushval_model::{DynamicModel, Problem, Push, Simulator};
use pushval_rapier3d::predict::{friction_centre, predict_steady, tangent_k, twist_limit, Law};
use pushval_rapier3d::{
    ContactFriction, FeetColliders, Rapier3dRun, Rapier3dSettings, Rapier3dSimulator,
};

use super::plate::{
    coulomb_star, frs, length, paper_plate, phis, plate, rel, speed_of, G, HALF, MASS, MU,
    PHI_TABLE, TABLE_SPEEDS,
};
use super::{dt_label, error_figure, error_panel, min_max, range_text, ErrorCell};
use crate::report::Writer;

/// Duration of every run (s).
const T_RUN: f64 = 5.0;
/// The steps of the paper table (s): fine first.
const DTS: [f64; 2] = [1e-3, 1.0 / 60.0];
/// Heights of the centre of mass of the load-transfer sweep (m).
const CM_HEIGHTS: [f64; 3] = [0.005, 0.05, 0.1];
/// The quick grid's heights (tests).
const CM_HEIGHTS_QUICK: [f64; 1] = [0.05];
/// Push heights of the load-transfer sweep, in units of h_cm.
const PUSH_HEIGHT_FACTORS: [f64; 3] = [0.0, 1.0, 2.0];

/// The set-ups of the paper table: friction model, feet colliders, name.
const VARIANTS: [(ContactFriction, FeetColliders, &str); 3] = [
    (ContactFriction::Coulomb, FeetColliders::Compound, "coulomb"),
    (
        ContactFriction::Simplified,
        FeetColliders::Compound,
        "simplified",
    ),
    (
        ContactFriction::Simplified,
        FeetColliders::Separate,
        "simplified_separate_feet",
    ),
];

/// The rapier3d study.
#[derive(Debug, Clone, Copy)]
pub struct Rapier3d {
    pub quick: bool,
}

/// One engine run and what it gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// The paper plate at φ = π/4 + 0.3: `[ω*, ω, predicted, max_i
    /// |f_i/(μ_i N_i) − 1|, manifolds, manifold points, min rest load, max
    /// rest load]`.
    Table { dt: usize, v: usize, variant: usize },
    /// Load transfer (Coulomb, a collider per foot, Δt = 1e-3): `[ω*, model
    /// with load transfer, ω, predicted, predicted with rest loads, N₁…N₄
    /// engine, N₁…N₄ predicted, max tilt, lost contact (0/1)]`.
    Load { h: usize, k: usize, v: usize },
    /// A map cell (one compound collider, Δt = 1e-3): `[v_c, ω*, ω,
    /// predicted, jitter, lost contact (0/1), θ error, position error]`.
    Map { f: usize, i: usize, j: usize },
}

fn cm_heights(quick: bool) -> &'static [f64] {
    if quick {
        &CM_HEIGHTS_QUICK
    } else {
        &CM_HEIGHTS
    }
}

fn push(speed: f64, phi: f64) -> Push {
    Push {
        duration: T_RUN,
        speed,
        phi,
    }
}

fn settings(friction: ContactFriction, feet: FeetColliders, dt: f64) -> Rapier3dSettings {
    Rapier3dSettings {
        dt,
        friction,
        feet,
        ..Default::default()
    }
}

fn run(s: Rapier3dSettings, p: &Problem) -> Rapier3dRun {
    Rapier3dSimulator::new(s)
        .run(p)
        .expect("the paper plate runs in rapier3d")
}

/// The law that predicts the engine under `s`.
fn law(s: &Rapier3dSettings) -> Law {
    if s.friction == ContactFriction::Simplified && s.feet == FeetColliders::Compound {
        Law::SimplifiedOneManifold
    } else {
        Law::EffectiveMassDisk
    }
}

fn predicted(s: &Rapier3dSettings, p: &Problem) -> f64 {
    let scene = s.scene(p).expect("the paper plate has a scene");
    predict_steady(&scene, &p.pushes[0], law(s), true).map_or(f64::NAN, |x| x.omega)
}

/// rms step-to-step change of ω over the last 20 % of the steps (rad/s).
fn jitter(run: &Rapier3dRun) -> f64 {
    let steps: Vec<_> = run.history.iter().filter(|r| r.t1 > r.t0).collect();
    let from = (0.8 * steps.len() as f64) as usize;
    let d: Vec<f64> = steps[from..]
        .windows(2)
        .map(|w| w[1].omega - w[0].omega)
        .collect();
    (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt()
}

/// Error against the prediction: relative, absolute where it predicts 0.
fn err_pred(w: f64, pred: f64) -> f64 {
    if pred == 0.0 {
        w.abs()
    } else {
        rel(w, pred)
    }
}

impl super::Study for Rapier3d {
    type Task = Task;

    fn name(&self) -> &'static str {
        "rapier3d"
    }

    fn dir(&self) -> &'static str {
        "rapier3d"
    }

    fn tasks(&self) -> Vec<Task> {
        let mut t = Vec::new();
        for dt in 0..DTS.len() {
            for v in 0..TABLE_SPEEDS.len() {
                for variant in 0..VARIANTS.len() {
                    t.push(Task::Table { dt, v, variant });
                }
            }
        }
        for h in 0..cm_heights(self.quick).len() {
            for k in 0..PUSH_HEIGHT_FACTORS.len() {
                for v in 0..TABLE_SPEEDS.len() {
                    t.push(Task::Load { h, k, v });
                }
            }
        }
        for f in 0..ContactFriction::ALL.len() {
            for i in 0..frs(self.quick).len() {
                for j in 0..phis(self.quick).len() {
                    t.push(Task::Map { f, i, j });
                }
            }
        }
        t
    }

    fn width(&self, task: &Task) -> Option<usize> {
        Some(match task {
            Task::Table { .. } => 8,
            Task::Load { .. } => 15,
            Task::Map { .. } => 8,
        })
    }

    fn eval(&self, task: &Task) -> Vec<f64> {
        let body = plate();
        match *task {
            Task::Table { dt, v, variant } => {
                let (f, feet, _) = VARIANTS[variant];
                let p = paper_plate(TABLE_SPEEDS[v], PHI_TABLE, T_RUN);
                let s = settings(f, feet, DTS[dt]);
                let r = run(s, &p);
                let dev = (0..r.mu.len())
                    .map(|i| {
                        let n = r.segment_tail_loads[0][i];
                        (r.segment_tail_friction[0][i] / (r.mu[i] * n) - 1.0).abs()
                    })
                    .fold(0.0, f64::max);
                let (lo, hi) = min_max(r.rest_loads.iter().copied());
                vec![
                    coulomb_star(&body, &p.pushes[0]),
                    r.segment_tail_omega[0],
                    predicted(&s, &p),
                    dev,
                    r.manifolds as f64,
                    r.manifold_points as f64,
                    lo,
                    hi,
                ]
            }
            Task::Load { h, k, v } => {
                let hcm = cm_heights(self.quick)[h];
                let hp = PUSH_HEIGHT_FACTORS[k] * hcm;
                let p = paper_plate(TABLE_SPEEDS[v], PHI_TABLE, T_RUN);
                let s = Rapier3dSettings {
                    cm_height: hcm,
                    push_height: hp,
                    feet: FeetColliders::Separate,
                    ..Default::default()
                };
                let r = run(s, &p);
                let scene = s.scene(&p).expect("the paper plate has a scene");
                let push = &p.pushes[0];
                let omega =
                    |law, coupled| predict_steady(&scene, push, law, coupled).map(|x| x.omega);
                let pred = predict_steady(&scene, push, Law::EffectiveMassDisk, true);
                let loads = pred.as_ref().map_or(vec![f64::NAN; 4], |x| x.loads.clone());
                let mut row = vec![
                    coulomb_star(&body, push),
                    omega(Law::Coulomb, true).unwrap_or(f64::NAN),
                    r.segment_tail_omega[0],
                    pred.as_ref().map_or(f64::NAN, |x| x.omega),
                    omega(Law::EffectiveMassDisk, false).unwrap_or(f64::NAN),
                ];
                row.extend(&r.segment_tail_loads[0]);
                row.extend(loads);
                row.push(r.max_tilt);
                row.push(if r.lost_contact().iter().any(|&b| b) {
                    1.0
                } else {
                    0.0
                });
                row
            }
            Task::Map { f, i, j } => {
                let f = ContactFriction::ALL[f];
                let speed = speed_of(frs(self.quick)[i]);
                let phi = phis(self.quick)[j];
                let p = paper_plate(speed, phi, T_RUN);
                let s = settings(f, FeetColliders::Compound, DTS[0]);
                let r = run(s, &p);
                let model = DynamicModel::default()
                    .simulate(&p)
                    .expect("the dynamic model runs the paper plate");
                let (mut theta_err, mut pos_err) = (0.0f64, 0.0f64);
                for (a, b) in r.trajectory.samples.iter().zip(&model.samples) {
                    theta_err = theta_err.max((a.theta - b.theta).abs());
                    pos_err = pos_err.max((a.x - b.x).hypot(a.y - b.y));
                }
                vec![
                    speed,
                    coulomb_star(&body, &push(speed, phi)),
                    r.segment_tail_omega[0],
                    predicted(&s, &p),
                    jitter(&r),
                    if r.lost_contact().iter().any(|&b| b) {
                        1.0
                    } else {
                        0.0
                    },
                    theta_err,
                    pos_err,
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
        let mut table = Vec::new();
        let mut loads = Vec::new();
        let mut cells = Vec::new();
        for (t, r) in tasks.iter().zip(rows) {
            match *t {
                Task::Table { dt, v, variant } => table.push((dt, v, variant, r.as_slice())),
                Task::Load { h, k, v } => loads.push((h, k, v, r.as_slice())),
                Task::Map { f, i, j } => cells.push(MapCell::from(f, i, j, r)),
            }
        }
        let mut readme = intro();
        readme.push_str(super::quick_note(self.quick));
        readme.push_str(&write_table(&table, w)?);
        let load_md = write_loads(self.quick, &loads, w)?;
        readme.push_str(&write_map(self.quick, &cells, w)?);
        readme.push_str(&load_md);
        readme.push_str(&findings(self.quick, &table, &loads, &cells));
        w.file("README.md", readme.as_bytes())?;
        Ok(())
    }
}

/// A map cell's row.
#[derive(Debug, Clone, Copy)]
struct MapCell {
    f: usize,
    i: usize,
    j: usize,
    speed: f64,
    star: f64,
    engine: f64,
    pred: f64,
    jitter: f64,
    lost: bool,
    theta_err: f64,
    pos_err: f64,
}

impl MapCell {
    fn from(f: usize, i: usize, j: usize, r: &[f64]) -> Self {
        Self {
            f,
            i,
            j,
            speed: r[0],
            star: r[1],
            engine: r[2],
            pred: r[3],
            jitter: r[4],
            lost: r[5] != 0.0,
            theta_err: r[6],
            pos_err: r[7],
        }
    }

    /// `locks` / `stops` (|ω| < 5 % of |ω*|, locks where the law predicts
    /// 0), `chatters` (jitter > 5 % of |ω*|), `tips` (a foot lost contact)
    /// or `ok`.
    fn status(&self) -> &'static str {
        if self.engine.abs() < 0.05 * self.star.abs() {
            if self.pred == 0.0 {
                "locks"
            } else {
                "stops"
            }
        } else if self.jitter > 0.05 * self.star.abs() {
            "chatters"
        } else if self.lost {
            "tips"
        } else {
            "ok"
        }
    }
}

fn intro() -> String {
    let body = plate();
    let s = Rapier3dSettings::default();
    let engine = crate::registry::engine("rapier3d", &Default::default());
    format!(
        "# rapier3d's own contact friction against Coulomb support friction\n\n\
         Generated by `pushval study rapier3d` ({version}); do not edit by hand. Scene: the paper \
         plate ({side} m square, {MASS} kg, I = {i:.4} kg m², feet at the four corners, μ = {MU}, \
         g = {G}, equal rest loads), pushed at the corner (−{HALF}, −{HALF}), starting with the \
         pusher at ω = 0; ball feet r = {r} m, centre of mass h_cm = {hcm} m, pusher joint at \
         h_push = {hp} m (horizontal force only), plate thickness {t} m for the tilt inertias \
         (I/2 + m t²/12), rapier defaults otherwise ({sub} substeps, soft contacts), contact \
         recycling off, feet in one compound collider unless stated. ω* is the Coulomb model's \
         steady ω with the rest loads; `pred` is the closed-form prediction of the engine (see \
         below). Runs last {T_RUN} s; ω_engine is the mean over the last 20 % of the steps.\n\n",
        version = engine.version(),
        side = 2.0 * HALF,
        i = body.inertia_cm(),
        r = s.foot_radius,
        hcm = s.cm_height,
        hp = s.push_height,
        t = s.plate_thickness,
        sub = s.solver_iterations,
    )
}

type TableRow<'a> = (usize, usize, usize, &'a [f64]);
type LoadRow<'a> = (usize, usize, usize, &'a [f64]);

fn write_table(table: &[TableRow], w: &mut Writer) -> anyhow::Result<String> {
    let mut csv = String::from(
        "dt,speed,friction,omega_star,omega_engine,omega_predicted,rel_err_vs_star,rel_err_vs_predicted,friction_magnitude_dev,manifolds,manifold_points,rest_load_min,rest_load_max\n",
    );
    let mut md = String::from("| Δt | v_c (m/s) | ω* Coulomb | rapier3d Coulomb (pred) | Simplified, one collider (pred) | Simplified, a collider per foot |\n|---|---:|---:|---:|---:|---:|\n");
    for chunk in table.chunks(VARIANTS.len()) {
        for &(dt, v, variant, r) in chunk {
            writeln!(
                csv,
                "{},{},{},{:.6},{:.6},{:.6},{:.4e},{:.4e},{:.3e},{},{},{:.4},{:.4}",
                DTS[dt],
                TABLE_SPEEDS[v],
                VARIANTS[variant].2,
                r[0],
                r[1],
                r[2],
                rel(r[1], r[0]),
                err_pred(r[1], r[2]),
                r[3],
                r[4],
                r[5],
                r[6],
                r[7]
            )?;
        }
        let (dt, v, _, a) = chunk[0];
        let (b, c) = (chunk[1].3, chunk[2].3);
        writeln!(
            md,
            "| {} | {} | {:.6} | {:.6} ({:.6}) | {:.6} ({:.6}) | {:.6} |",
            dt_label(DTS[dt]),
            TABLE_SPEEDS[v],
            a[0],
            a[1],
            a[2],
            b[1],
            b[2],
            c[1]
        )?;
    }
    w.file("paper_table.csv", csv.as_bytes())?;
    Ok(format!(
        "## 1. The paper plate at φ = π/4 + 0.3 (ω in rad/s)\n\n{md}\n(`paper_table.csv`.)\n\n"
    ))
}

fn write_loads(quick: bool, loads: &[LoadRow], w: &mut Writer) -> anyhow::Result<String> {
    let mut csv = String::from("cm_height,push_height,speed,omega_star_rest_loads,omega_model_load_transfer,omega_engine,omega_predicted,omega_predicted_rest_loads,rel_err_vs_predicted,N1_engine,N2_engine,N3_engine,N4_engine,N1_pred,N2_pred,N3_pred,N4_pred,max_tilt,lost_contact\n");
    let mut md = String::from("| h_cm | h_push | v_c | ω* rest loads | model with load transfer | engine | pred (transfer) | pred (rest loads) | engine vs pred | engine loads N₁…N₄ (N) | predicted loads |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|\n");
    let join = |x: &[f64], sep: &str, d: usize| {
        x.iter()
            .map(|v| format!("{v:.d$}"))
            .collect::<Vec<_>>()
            .join(sep)
    };
    for &(h, k, v, r) in loads {
        let hcm = cm_heights(quick)[h];
        let hp = PUSH_HEIGHT_FACTORS[k] * hcm;
        let v = TABLE_SPEEDS[v];
        writeln!(
            csv,
            "{hcm},{hp},{v},{:.6},{:.6},{:.6},{:.6},{:.6},{:.4e},{},{},{:.3e},{}",
            r[0],
            r[1],
            r[2],
            r[3],
            r[4],
            rel(r[2], r[3]),
            join(&r[5..9], ",", 4),
            join(&r[9..13], ",", 4),
            r[13],
            r[14] != 0.0
        )?;
        writeln!(
            md,
            "| {hcm} | {hp} | {v} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.1e} | {} | {} |",
            r[0],
            r[1],
            r[2],
            r[3],
            r[4],
            rel(r[2], r[3]),
            join(&r[5..9], " ", 3),
            join(&r[9..13], " ", 3)
        )?;
    }
    w.file("load_transfer.csv", csv.as_bytes())?;
    Ok(format!(
        "## 3. Load transfer (Coulomb, a collider per foot, Δt = 1e-3; `load_transfer.csv`)\n\n{md}\n"
    ))
}

fn write_map(quick: bool, cells: &[MapCell], w: &mut Writer) -> anyhow::Result<String> {
    let (frs, phis) = (frs(quick), phis(quick));
    let mut panels = Vec::new();
    for (fk, f) in ContactFriction::ALL.iter().enumerate() {
        let mut csv = String::from("froude,phi,speed,omega_star,omega_engine,omega_predicted,rel_err_vs_star,rel_err_vs_predicted,theta_err_max,position_err_max,jitter,status\n");
        let mut map = Vec::new();
        for c in cells.iter().filter(|c| c.f == fk) {
            writeln!(
                csv,
                "{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.4e},{:.4e},{:.4e},{:.4e},{:.3e},{}",
                frs[c.i],
                phis[c.j],
                c.speed,
                c.star,
                c.engine,
                c.pred,
                rel(c.engine, c.star),
                err_pred(c.engine, c.pred),
                c.theta_err,
                c.pos_err,
                c.jitter,
                c.status()
            )?;
            map.push(ErrorCell {
                i: c.i,
                j: c.j,
                rel_err: rel(c.engine, c.star),
                flags: match c.status() {
                    "locks" => "L",
                    "stops" => "S",
                    "chatters" => "C",
                    "tips" => "T",
                    _ => "",
                }
                .to_string(),
            });
        }
        w.file(&format!("map_{}.csv", f.as_str()), csv.as_bytes())?;
        let title = format!("rapier3d {} (Δt = {})", f.as_str(), dt_label(DTS[0]));
        panels.push(error_panel(&title, frs, &phis, &map));
    }
    w.figure(
        "map.svg",
        &error_figure(
            panels,
            ContactFriction::ALL.len(),
            &[
                ("L", "locks orientation"),
                ("S", "stops"),
                ("C", "chatters"),
                ("T", "loses a foot contact"),
            ],
        ),
    )?;
    let summary = |fk: usize| {
        let cs: Vec<&MapCell> = cells.iter().filter(|c| c.f == fk).collect();
        let (lo, hi) = min_max(cs.iter().map(|c| rel(c.engine, c.star)));
        let pred = cs
            .iter()
            .map(|c| err_pred(c.engine, c.pred))
            .fold(0.0, f64::max);
        let th = cs.iter().map(|c| c.theta_err).fold(0.0, f64::max);
        let largest = cs.iter().map(|c| c.engine.abs()).fold(0.0, f64::max);
        let count = |s: &str| cs.iter().filter(|c| c.status() == s).count();
        let st = [
            count("ok"),
            count("locks"),
            count("stops"),
            count("chatters"),
            count("tips"),
        ];
        (lo, hi, pred, th, largest, st)
    };
    let coulomb = ContactFriction::ALL
        .iter()
        .position(|f| *f == ContactFriction::Coulomb)
        .unwrap_or(0);
    let simplified = ContactFriction::ALL
        .iter()
        .position(|f| *f == ContactFriction::Simplified)
        .unwrap_or(1);
    let (c_min, c_max, c_pred, c_th, _, c_st) = summary(coulomb);
    let (_, _, _, s_th, s_w, s_st) = summary(simplified);
    Ok(format!(
        "## 2. Disagreement map over (Fr, φ), Δt = 1e-3\n\n\
         Fr = v_c²/(μ g L), L = |p_c| = {l:.3} m, Fr ∈ {frs:?}, {n} φ in [{p0:.2}, {p1:.2}] \
         (`map_coulomb.csv`, `map_simplified.csv`, `map.svg`).\n\n\
         * **Coulomb**: |ω_engine − ω*|/|ω*| from {c_min:.3} to {c_max:.3}; the prediction below \
         matches the engine to ≤ {c_pred:.1e} (relative) in every cell; largest θ error against \
         the model over {T_RUN} s {c_th:.2} rad. Status ok/locks/stops/chatters/tips: {c_st:?}.\n\
         * **Simplified (one compound collider)**: largest |ω_engine| over the cells {s_w:.1e} \
         rad/s: the plate **locks its orientation** and translates with the pusher; θ error up \
         to {s_th:.2} rad. Status ok/locks/stops/chatters/tips: {s_st:?}.\n\n",
        l = length(),
        n = phis.len(),
        p0 = phis[0],
        p1 = phis[phis.len() - 1],
    ))
}

/// The explanations, each with the numbers that support it computed from
/// this run's data (asserted in `crates/rapier3d/tests/findings.rs`).
fn findings(quick: bool, table: &[TableRow], loads: &[LoadRow], cells: &[MapCell]) -> String {
    let body = plate();
    let at = |dt: usize, v: usize, variant: usize| {
        table
            .iter()
            .find(|r| r.0 == dt && r.1 == v && r.2 == variant)
            .map(|r| r.3)
    };
    let coulomb_rows = |dt: usize| (0..TABLE_SPEEDS.len()).filter_map(move |v| at(dt, v, 0));
    // The magnitude: every foot at μ N_i.
    let fdev = |dt: usize| {
        table
            .iter()
            .filter(|r| r.0 == dt && VARIANTS[r.2].0 == ContactFriction::Coulomb)
            .map(|r| r.3[3])
            .fold(0.0, f64::max)
    };
    // K at a corner foot, in units of 1/m.
    let p = paper_plate(TABLE_SPEEDS[1], PHI_TABLE, T_RUN);
    let scene = Rapier3dSettings::default()
        .scene(&p)
        .expect("the paper plate has a scene");
    let k = tangent_k(&scene, scene.points[0]);
    let (mean, half) = (
        0.5 * (k[0] + k[1]),
        (0.25 * (k[0] - k[1]).powi(2) + k[2] * k[2]).sqrt(),
    );
    let (e_lo, e_hi) = ((mean - half) * scene.mass, (mean + half) * scene.mass);
    // The bias and how little Δt changes it.
    let (b_lo, b_hi) = min_max(coulomb_rows(0).map(|r| 100.0 * rel(r[1], r[0])));
    let dt_change: Vec<String> = (0..TABLE_SPEEDS.len())
        .filter_map(|v| {
            let (a, b) = (at(0, v, 0)?, at(1, v, 0)?);
            Some(format!(
                "{:.1e} at {} m/s",
                rel(b[1], a[1]),
                TABLE_SPEEDS[v]
            ))
        })
        .collect();
    let (p_lo, p_hi) = min_max(
        coulomb_rows(0).map(|r| err_pred(r[1], r[2])).chain(
            cells
                .iter()
                .filter(|c| ContactFriction::ALL[c.f] == ContactFriction::Coulomb)
                .map(|c| err_pred(c.engine, c.pred)),
        ),
    );
    // Manifolds of the two collider set-ups.
    let manifolds = |variant: usize| {
        at(0, 0, variant).map_or("—".to_string(), |r| {
            format!("{} manifold(s), {} contact point(s) in all", r[4], r[5])
        })
    };
    // The twist lock: the friction force's largest moment against the limit.
    let rest = scene.rest_loads();
    let c = friction_centre(&scene.points);
    let pc = body.contact();
    let arm = (c - pc).norm();
    let twist_arm = twist_limit(&scene.points, &rest, MU) / (MU * rest.iter().sum::<f64>());
    // Load transfer.
    let shift = loads
        .iter()
        .map(|r| 100.0 * rel(r.3[1], r.3[0]))
        .fold(0.0, f64::max);
    let heights = cm_heights(quick);
    let load_gap = loads
        .iter()
        .filter(|r| r.0 == 0)
        .flat_map(|r| (0..4).map(move |i| (r.3[5 + i] - r.3[9 + i]).abs()))
        .fold(0.0, f64::max);
    let high = heights.len() - 1;
    let (h_lo, h_hi) = min_max(
        loads
            .iter()
            .filter(|r| r.0 == high && r.1 == 0)
            .map(|r| 100.0 * rel(r.3[2], r.3[0])),
    );
    // Feet the prediction lifts, per (h_cm, h_push): the engine's largest
    // load on them over the speeds.
    let mut lifted: Vec<(usize, usize, usize, f64)> = Vec::new();
    for r in loads {
        for i in (0..4).filter(|&i| r.3[9 + i] <= 0.0) {
            match lifted
                .iter_mut()
                .find(|l| l.0 == r.0 && l.1 == r.1 && l.2 == i)
            {
                Some(l) => l.3 = l.3.max(r.3[5 + i]),
                None => lifted.push((r.0, r.1, i, r.3[5 + i])),
            }
        }
    }
    let lifted: Vec<String> = lifted
        .iter()
        .map(|&(h, k, i, n)| {
            format!(
                "at h_cm = {}, h_push = {} the prediction lifts foot {} and the engine's load on it is at most {n:.3} N",
                heights[h],
                PUSH_HEIGHT_FACTORS[k] * heights[h],
                i + 1
            )
        })
        .collect();
    let rest = |variant: usize| {
        let (lo, hi) = min_max(
            table
                .iter()
                .filter(|r| r.2 == variant)
                .flat_map(|r| [r.3[6], r.3[7]]),
        );
        format!("{lo:.2}–{hi:.2} N {}", VARIANTS[variant].2)
    };
    let rests: Vec<String> = (0..VARIANTS.len()).map(rest).collect();
    let nominal = MASS * G / 4.0;
    format!(
        "## What explains each disagreement\n\n\
* **rapier3d `Coulomb` is not Coulomb in direction.** Every foot slides at the full magnitude μ N_i (measured \
|f_i|/(μ N_i) = 1 within {fdev_f:.1e} at Δt = 1e-3 and {fdev_g:.1e} at 1/60 over the table's runs; `paper_table.csv`, \
`friction_magnitude_dev`), but the \
direction is wrong: each contact's friction is a 2×2 tangent solve `Δλ = −K⁻¹ Δv` whose result is capped to the disk \
|λ| ≤ μ λ_n, so at a sliding fixed point the impulse is along `−K⁻¹ u_i`, not `−u_i`, with `K_i = J M⁻¹ Jᵀ` the \
contact's tangent inverse effective mass (`k_xx = 1/m + h²/I_yy + y²/I_z`, `k_yy = 1/m + h²/I_xx + x²/I_z`, \
`k_xy = −x y/I_z`; at a corner of the plate the eigenvalues are {e_lo:.3}/m and {e_hi:.3}/m, i.e. about 1/m and \
1/m + |r|²/I_z). This is the Box2D friction-joint idiom of the 2-D study (`impulse_disk`), now inside rapier's own \
contact solver. It hardly depends on Δt (Δt = 1/60 instead of 1e-3 changes ω by {dt_change}) and makes ω* \
{bias} % too large at φ = π/4 + 0.3. The root of the moment balance with `f_i = −μ N_i K_i⁻¹u_i/|K_i⁻¹u_i|` \
(`predict::Law::EffectiveMassDisk`), with the normal loads coupled to the forces (below), reproduces the engine to \
{p_lo:.1e}–{p_hi:.1e} (table at Δt = 1e-3, map).\n\
* **rapier3d `Simplified` locks the orientation** when the feet share one contact manifold. rapier builds manifolds \
per collider pair; a compound collider's ball manifolds with the same normal are merged into one cluster manifold \
(measured: {m_one}; a collider per foot gives {m_sep}). `Simplified` replaces that manifold's friction constraints by \
one at the friction centre c (the mean of the points, here the plate's centre) with limit μ ΣN, plus a twist \
constraint about the normal with limit μ Σ N_k |p_k − c|. At ω = 0 the friction force −μ m g n_φ at c has the moment \
μ m g |(c − p_c) × n_φ| about the contact, at most μ m g |c − p_c| = μ m g · {arm:.4} m, and the twist limit is \
μ m g · {twist_arm:.4} m (rest loads): the twist constraint can always cancel it, so ω stays 0 for every push \
direction and speed (`predict::simplified_locks`), and the plate slides without turning. With a collider per foot \
each manifold has one point and no twist, and `Simplified` gives the same ω as `Coulomb` (last column of the table).\n\
* **Load transfer.** The quasi-static tilting balance gives Σ N_i p_i = h_push f_c − h_cm m a_cm (N m); rapier's \
soft contacts spread the load over the four feet like springs ∝ each contact's normal effective mass (equal here), \
i.e. affinely. With these loads the Coulomb model moves by up to {shift:.1} % (column 'model with load transfer'); \
the engine follows the same loads (measured loads within {load_gap:.3} N of the prediction at h_cm = {h0}) and the \
effective-mass law with them predicts its ω. A high centre of mass reduces the direction bias, because the tilt \
terms h²/I_xx enter K: at h_cm = {h1}, h_push = 0 the bias is {hb} % instead of {bias} %. When the predicted load of \
a foot would be negative the foot lifts and the other three carry the weight (statics, `Scene::loads`): {lifted}.\n\
* **Rest loads** are not unique: the four-foot statics is indeterminate and rapier settles to unequal \
loads (settled over the table's runs: {rests}; instead of m g/4 = {nominal:.4} N) that depend on the settle \
history; while sliding, the loads follow the affine prediction.\n",
        dt_change = dt_change.join(", "),
        fdev_f = fdev(0),
        fdev_g = fdev(1),
        rests = rests.join(", "),
        bias = range_text(b_lo, b_hi, 0),
        m_one = manifolds(0),
        m_sep = manifolds(2),
        h0 = heights[0],
        h1 = heights[high],
        hb = range_text(h_lo, h_hi, 0),
        lifted = if lifted.is_empty() {
            "none in this sweep".to_string()
        } else {
            lifted.join("; ")
        },
    )
}
