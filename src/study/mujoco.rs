//! Where MuJoCo's contact friction disagrees with Coulomb support friction,
//! on the paper plate standing on four sphere feet (`OUT/mujoco/`).
//! Compiled only with the root feature `mujoco`.
//!
//! Writes the paper-plate table (3 speeds × 2 cones × solver settings), the
//! load-transfer runs, the (Fr, φ) grid, the disagreement map
//! (`disagreement_map.svg`) and a README with the closed forms of
//! `pushval_mujoco::theory`, every number computed from those files' data.
//!
//! The engine runs through `pushval_mujoco::MujocoSimulator`, the crate's own
//! API, not the `Engine` trait: the study reads the feet's tail-mean loads,
//! the calibrated μ_i and rest loads, the step history (final angle, slowest
//! foot) and the tail statistics of ω, none of which a trajectory carries.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use std::fmt::Write as _;
use std::path::Path;

use pushval_model::{kinematic, DynamicModel, Problem, Push, SegmentDynamics, Simulator};
use pushval_mujoco::theory::{
    coulomb_steady, steady_omega, steady_omega_load_transfer, Coulomb, Regularised,
};
use pushval_mujoco::{Cone, MujocoRun, MujocoSettings, MujocoSimulator};

use super::plate::{
    frs, paper_plate, phis, plate, rel, speed_of, G, HALF, MASS, MU, PHI_TABLE, TABLE_SPEEDS,
};
use super::{error_figure, error_panel, median, min_max, range_text, ErrorCell};
use crate::report::Writer;

/// Duration of every run (s).
const T_RUN: f64 = 4.0;
/// The load-transfer runs: (h_cm, h_push) (m).
const HEIGHTS: [(f64, f64); 4] = [(0.0, 0.0), (0.05, 0.05), (0.05, 0.0), (0.05, 0.1)];
/// The load-transfer runs' speeds (m/s).
const LOAD_SPEEDS: [f64; 2] = [0.5, 1.0];
/// |ω*| below which a cell's error is read as absolute (rad/s): pushes
/// through the centre of mass.
const SMALL_STAR: f64 = 0.02;

/// The solver settings of the paper table, by name.
fn variants() -> Vec<(&'static str, MujocoSettings)> {
    let d = MujocoSettings::default();
    vec![
        ("default", d),
        (
            "impratio=10",
            MujocoSettings {
                impratio: 10.0,
                ..d
            },
        ),
        (
            "impratio=100",
            MujocoSettings {
                impratio: 100.0,
                ..d
            },
        ),
        (
            "noslip=10",
            MujocoSettings {
                noslip_iterations: 10,
                ..d
            },
        ),
        (
            "dt=2e-3",
            MujocoSettings {
                timestep: 2e-3,
                ..d
            },
        ),
        (
            "dt=5e-3",
            MujocoSettings {
                timestep: 5e-3,
                ..d
            },
        ),
    ]
}

/// The MuJoCo study.
#[derive(Debug, Clone, Copy)]
pub struct Mujoco {
    pub quick: bool,
}

/// One engine run and what it gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// The paper plate at φ = π/4 + 0.3: `[ω, ω std, θ_end, tail loads N₁…N₄,
    /// rest loads min, max, μ_i min, max]`.
    Paper {
        cone: usize,
        variant: usize,
        v: usize,
    },
    /// Load transfer (elliptic): `[ω, μ₁…μ₄, rest loads N₁…N₄, tail loads N₁…N₄]`.
    Load { h: usize, v: usize },
    /// A grid cell: `[ω, ω std, θ error, position error, θ_end, slowest foot
    /// over the last 20 % of the steps (m/s)]`.
    Grid { cone: usize, i: usize, j: usize },
}

fn push(speed: f64, phi: f64) -> Push {
    Push {
        duration: T_RUN,
        speed,
        phi,
    }
}

fn run(s: MujocoSettings, p: &Problem) -> MujocoRun {
    MujocoSimulator::new(s)
        .run(p)
        .expect("the paper plate runs in MuJoCo")
}

/// Angle wrapped into (−π/4, π/4]: distance from the nearest multiple of π/2.
fn quarter(a: f64) -> f64 {
    (a + FRAC_PI_4).rem_euclid(FRAC_PI_2) - FRAC_PI_4
}

/// Pyramid face law: at the lock every foot slides with the pusher velocity
/// at world angle α; the face force is `−(μN/2)[(1,1) + s(1,−1)]` with
/// `s = (u_1 − u_2)/w`. The lock needs that force along the object's
/// diagonal, `θ + π/4`, so `s = (1 − t)/(1 + t)` with `t = tan(θ + π/4)`,
/// and `w = v_c (cos α − sin α)/s` (m/s).
fn face_width(v: f64, theta: f64, phi: f64) -> f64 {
    let t = (quarter(theta) + FRAC_PI_4).tan();
    let s = (1.0 - t) / (1.0 + t);
    let alpha = quarter(theta) + phi;
    v * (alpha.cos() - alpha.sin()) / s
}

fn froude(v: f64) -> f64 {
    v * v / (MU * G * (2.0f64).sqrt() * HALF)
}

fn star(p: &Push) -> f64 {
    coulomb_steady(&plate(), p, 0.0).unwrap_or(f64::NAN)
}

/// The Coulomb model's ω with the support loads `loads` (N).
fn omega_with_loads(p: &Push, loads: &[f64], guess: f64) -> f64 {
    let forces: Vec<f64> = loads.iter().map(|n| MU * n).collect();
    steady_omega(&plate(), p, &Coulomb, &forces, guess).unwrap_or(f64::NAN)
}

impl super::Study for Mujoco {
    type Task = Task;

    fn name(&self) -> &'static str {
        "mujoco"
    }

    fn dir(&self) -> &'static str {
        "mujoco"
    }

    fn tasks(&self) -> Vec<Task> {
        let mut t = Vec::new();
        for cone in 0..Cone::ALL.len() {
            for variant in 0..variants().len() {
                for v in 0..TABLE_SPEEDS.len() {
                    t.push(Task::Paper { cone, variant, v });
                }
            }
        }
        for h in 0..HEIGHTS.len() {
            for v in 0..LOAD_SPEEDS.len() {
                t.push(Task::Load { h, v });
            }
        }
        for cone in 0..Cone::ALL.len() {
            for i in 0..frs(self.quick).len() {
                for j in 0..phis(self.quick).len() {
                    t.push(Task::Grid { cone, i, j });
                }
            }
        }
        t
    }

    fn width(&self, task: &Task) -> Option<usize> {
        Some(match task {
            Task::Paper { .. } => 11,
            Task::Load { .. } => 13,
            Task::Grid { .. } => 6,
        })
    }

    fn eval(&self, task: &Task) -> Vec<f64> {
        match *task {
            Task::Paper { cone, variant, v } => {
                let s = MujocoSettings {
                    cone: Cone::ALL[cone],
                    ..variants()[variant].1
                };
                let r = run(s, &paper_plate(TABLE_SPEEDS[v], PHI_TABLE, T_RUN));
                let (nlo, nhi) = min_max(r.rest_loads.iter().copied());
                let (mlo, mhi) = min_max(r.mu.iter().copied());
                let mut row = vec![
                    r.segment_tail_omega[0],
                    r.segment_tail_omega_std[0],
                    r.history[r.history.len() - 1].theta,
                ];
                row.extend(&r.tail_loads[0]);
                row.extend([nlo, nhi, mlo, mhi]);
                row
            }
            Task::Load { h, v } => {
                let (hc, hp) = HEIGHTS[h];
                let s = MujocoSettings {
                    cone: Cone::Elliptic,
                    cm_height: hc,
                    push_height: hp,
                    ..Default::default()
                };
                let r = run(s, &paper_plate(LOAD_SPEEDS[v], PHI_TABLE, T_RUN));
                let mut row = vec![r.segment_tail_omega[0]];
                row.extend(&r.mu);
                row.extend(&r.rest_loads);
                row.extend(&r.tail_loads[0]);
                row
            }
            Task::Grid { cone, i, j } => {
                let v = speed_of(frs(self.quick)[i]);
                let phi = phis(self.quick)[j];
                let prob = paper_plate(v, phi, T_RUN);
                let r = run(
                    MujocoSettings {
                        cone: Cone::ALL[cone],
                        ..Default::default()
                    },
                    &prob,
                );
                let model = DynamicModel::default()
                    .simulate(&prob)
                    .expect("the dynamic model runs the paper plate");
                let (mut te, mut pe) = (0.0f64, 0.0f64);
                for (a, b) in r.trajectory.samples.iter().zip(&model.samples) {
                    te = te.max((a.theta - b.theta).abs());
                    pe = pe.max(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt());
                }
                let tail_min = r
                    .history
                    .iter()
                    .rev()
                    .take(r.steps / 5)
                    .map(|s| s.min_foot_speed)
                    .fold(f64::INFINITY, f64::min);
                vec![
                    r.segment_tail_omega[0],
                    r.segment_tail_omega_std[0],
                    te,
                    pe,
                    r.history[r.history.len() - 1].theta,
                    tail_min,
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
        let mut paper = Vec::new();
        let mut loads = Vec::new();
        let mut cells = Vec::new();
        for (t, r) in tasks.iter().zip(rows) {
            match *t {
                Task::Paper { cone, variant, v } => paper.push(PaperRow::from(cone, variant, v, r)),
                Task::Load { h, v } => loads.push(LoadRow::from(h, v, r)),
                Task::Grid { cone, i, j } => cells.push(GridCell::from(self.quick, cone, i, j, r)),
            }
        }
        write_paper(&paper, w)?;
        write_loads(&loads, w)?;
        write_grid(self.quick, &cells, w)?;
        let readme = readme(&paper, &loads, &cells).replacen(
            "\n\n",
            &format!("\n\n{}", super::quick_note(self.quick)),
            1,
        );
        w.file("README.md", readme.as_bytes())?;
        Ok(())
    }
}

/// A paper-table run with the closed forms that go with it.
#[derive(Debug, Clone)]
struct PaperRow {
    cone: Cone,
    variant: &'static str,
    v: f64,
    omega: f64,
    std: f64,
    theta_end: f64,
    loads: Vec<f64>,
    rest: (f64, f64),
    mu: (f64, f64),
    star: f64,
    kinematic: f64,
    with_loads: f64,
}

impl PaperRow {
    fn from(cone: usize, variant: usize, v: usize, r: &[f64]) -> Self {
        let v = TABLE_SPEEDS[v];
        let p = push(v, PHI_TABLE);
        let star = star(&p);
        let loads = r[3..7].to_vec();
        Self {
            cone: Cone::ALL[cone],
            variant: variants()[variant].0,
            v,
            omega: r[0],
            std: r[1],
            theta_end: r[2],
            with_loads: omega_with_loads(&p, &loads, star),
            loads,
            rest: (r[7], r[8]),
            mu: (r[9], r[10]),
            star,
            kinematic: kinematic::omega(&plate(), &p).unwrap_or(f64::NAN),
        }
    }
    fn face_width(&self) -> f64 {
        if self.cone == Cone::Pyramidal {
            face_width(self.v, self.theta_end, PHI_TABLE)
        } else {
            f64::NAN
        }
    }
}

/// A load-transfer run with its closed forms.
#[derive(Debug, Clone)]
struct LoadRow {
    hc: f64,
    hp: f64,
    v: f64,
    omega: f64,
    star: f64,
    transfer: f64,
    with_loads: f64,
}

impl LoadRow {
    fn from(h: usize, v: usize, r: &[f64]) -> Self {
        let (hc, hp) = HEIGHTS[h];
        let v = LOAD_SPEEDS[v];
        let p = push(v, PHI_TABLE);
        let star = star(&p);
        let transfer = steady_omega_load_transfer(&plate(), &p, &r[1..5], &r[5..9], hc, hp)
            .map_or(f64::NAN, |x| x.0);
        Self {
            hc,
            hp,
            v,
            omega: r[0],
            star,
            transfer,
            with_loads: omega_with_loads(&p, &r[9..13], star),
        }
    }
}

/// A grid cell with its flags.
#[derive(Debug, Clone)]
struct GridCell {
    cone: Cone,
    i: usize,
    j: usize,
    fr: f64,
    phi: f64,
    v: f64,
    omega: f64,
    std: f64,
    star: f64,
    theta_err: f64,
    pos_err: f64,
    flags: Vec<&'static str>,
}

impl GridCell {
    fn from(quick: bool, cone: usize, i: usize, j: usize, r: &[f64]) -> Self {
        let fr = frs(quick)[i];
        let phi = phis(quick)[j];
        let v = speed_of(fr);
        let p = push(v, phi);
        let star = star(&p);
        let (omega, std, theta_end, tail_min) = (r[0], r[1], r[4], r[5]);
        let mut flags = Vec::new();
        if omega.abs() < 0.1 * star.abs() {
            flags.push("stops_turning");
            if quarter(theta_end + phi - FRAC_PI_4).abs() < 0.15 {
                flags.push("locks_orientation");
            }
        }
        if std > 0.05 * star.abs() {
            flags.push("chatters");
        }
        let model_min = SegmentDynamics::new(&plate(), &p).min_support_speed(star).0;
        if model_min < 1e-3 * v && tail_min > 0.0 {
            flags.push("creeps");
        }
        if model_min > 0.1 * v && tail_min < 0.01 * v {
            flags.push("sticks");
        }
        Self {
            cone: Cone::ALL[cone],
            i,
            j,
            fr,
            phi,
            v,
            omega,
            std,
            star,
            theta_err: r[2],
            pos_err: r[3],
            flags,
        }
    }
}

fn write_paper(rows: &[PaperRow], w: &mut Writer) -> anyhow::Result<()> {
    let mut csv = String::from(
        "cone,variant,v_c,froude,omega_mujoco,omega_std,omega_star,rel_err,omega_kinematic,theta_end,omega_model_measured_loads,load_0,load_1,load_2,load_3,face_width,rest_load_min,rest_load_max,mu_min,mu_max\n",
    );
    for r in rows {
        writeln!(
            csv,
            "{},{},{},{:.4},{:.6},{:.2e},{:.6},{:.4e},{:.6},{:.5},{:.6},{:.4},{:.4},{:.4},{:.4},{:.4e},{:.4},{:.4},{:.4},{:.4}",
            r.cone.as_str(),
            r.variant,
            r.v,
            froude(r.v),
            r.omega,
            r.std,
            r.star,
            rel(r.omega, r.star),
            r.kinematic,
            r.theta_end,
            r.with_loads,
            r.loads[0],
            r.loads[1],
            r.loads[2],
            r.loads[3],
            r.face_width(),
            r.rest.0,
            r.rest.1,
            r.mu.0,
            r.mu.1
        )?;
    }
    w.file("paper_plate.csv", csv.as_bytes())
}

fn write_loads(rows: &[LoadRow], w: &mut Writer) -> anyhow::Result<()> {
    let mut csv = String::from(
        "h_cm,h_push,v_c,omega_mujoco,omega_star,omega_load_transfer,omega_model_measured_loads,rel_err_coulomb,rel_err_load_transfer\n",
    );
    for r in rows {
        writeln!(
            csv,
            "{},{},{},{:.6},{:.6},{:.6},{:.6},{:.4e},{:.4e}",
            r.hc,
            r.hp,
            r.v,
            r.omega,
            r.star,
            r.transfer,
            r.with_loads,
            rel(r.omega, r.star),
            rel(r.omega, r.transfer)
        )?;
    }
    w.file("load_transfer.csv", csv.as_bytes())
}

fn write_grid(quick: bool, cells: &[GridCell], w: &mut Writer) -> anyhow::Result<()> {
    let mut csv = String::from(
        "cone,froude,phi,v_c,omega_mujoco,omega_std,omega_star,rel_err,theta_err_max,position_err_max,flags\n",
    );
    for c in cells {
        writeln!(
            csv,
            "{},{},{:.5},{:.5},{:.6},{:.2e},{:.6},{:.4e},{:.4e},{:.4e},{}",
            c.cone.as_str(),
            c.fr,
            c.phi,
            c.v,
            c.omega,
            c.std,
            c.star,
            rel(c.omega, c.star),
            c.theta_err,
            c.pos_err,
            c.flags.join("|")
        )?;
    }
    w.file("grid.csv", csv.as_bytes())?;
    let panels = Cone::ALL
        .iter()
        .map(|&cone| {
            let map: Vec<ErrorCell> = cells
                .iter()
                .filter(|c| c.cone == cone)
                .map(|c| {
                    let mut flags = String::new();
                    for (f, m) in [
                        ("locks_orientation", "L"),
                        ("chatters", "C"),
                        ("creeps", "R"),
                        ("sticks", "K"),
                    ] {
                        if c.flags.contains(&f) {
                            flags.push_str(m);
                        }
                    }
                    if flags.is_empty() && c.flags.contains(&"stops_turning") {
                        flags.push('S');
                    }
                    ErrorCell {
                        i: c.i,
                        j: c.j,
                        rel_err: rel(c.omega, c.star),
                        flags,
                    }
                })
                .collect();
            error_panel(
                &format!("mujoco_{}", cone.as_str()),
                frs(quick),
                &phis(quick),
                &map,
            )
        })
        .collect();
    w.figure(
        "disagreement_map.svg",
        &error_figure(
            panels,
            Cone::ALL.len(),
            &[
                ("L", "locks orientation"),
                ("S", "stops turning"),
                ("C", "chatters"),
                ("R", "creeps"),
                ("K", "sticks"),
            ],
        ),
    )
}

fn pct(x: f64) -> f64 {
    100.0 * x
}

fn readme(rows: &[PaperRow], lt: &[LoadRow], cells: &[GridCell]) -> String {
    let engine = crate::registry::engine("mujoco_elliptic", &Default::default());
    let s = MujocoSettings::default();
    let mut r = String::new();
    let (rest_lo, rest_hi) = min_max(rows.iter().flat_map(|x| [x.rest.0, x.rest.1]));
    let (mu_lo, mu_hi) = min_max(rows.iter().flat_map(|x| [x.mu.0, x.mu.1]));
    let _ = writeln!(r, "# MuJoCo against Coulomb support friction\n");
    let _ = writeln!(
        r,
        "Generated by `pushval study mujoco` ({version}; build with `--features mujoco`, environment: \
         `eval \"$(scripts/setup-mujoco.sh)\"`); do not edit by hand. Scene: the paper plate ({side} m \
         square, {MASS} kg, four corner feet, μ {MU}, equal loads, g {G}) as a free body on four \
         sphere feet (radius {radius} m, condim 3: no torsional or rolling friction) on a plane; the \
         feet's μ_i are calibrated on MuJoCo's own rest loads ({rest} N over the table's runs, μ_i = \
         {mu}); the pusher is a kinematic slider pair joined to the corner (−{HALF}, −{HALF}) by a \
         `connect` that carries horizontal force only; the object's state is written only at t = 0 \
         (moving with the pusher, ω = 0). Centre of mass and push at floor height unless stated. \
         φ = π/4 + 0.3, runs of {T_RUN} s, steady ω = mean over the last 20 % of the steps.\n",
        version = engine.version(),
        side = 2.0 * HALF,
        radius = s.foot_radius,
        rest = range_text(rest_lo, rest_hi, 4),
        mu = range_text(mu_lo, mu_hi, 4),
    );
    let _ = writeln!(r, "## Steady ω on the paper plate (rad/s)\n");
    let head: Vec<String> = TABLE_SPEEDS
        .iter()
        .enumerate()
        .map(|(k, v)| {
            if k == 0 {
                format!("v_c = {v}")
            } else {
                format!("{v:.1}")
            }
        })
        .collect();
    let _ = writeln!(
        r,
        "| cone | setting | {} |\n|---|---|{}",
        head.join(" | "),
        "---|".repeat(TABLE_SPEEDS.len())
    );
    let first: Vec<&PaperRow> = rows.iter().take(TABLE_SPEEDS.len()).collect();
    let line = |f: &dyn Fn(&PaperRow) -> f64| -> String {
        first
            .iter()
            .map(|x| format!("{:.4}", f(x)))
            .collect::<Vec<_>>()
            .join(" | ")
    };
    let _ = writeln!(r, "| Coulomb model ω* | | {} |", line(&|x| x.star));
    let _ = writeln!(r, "| kinematic v_c ψ | | {} |", line(&|x| x.kinematic));
    for chunk in rows.chunks(TABLE_SPEEDS.len()) {
        let cells: Vec<String> = chunk
            .iter()
            .map(|x| format!("{:.4} ({:+.1} %)", x.omega, pct(x.omega / x.star - 1.0)))
            .collect();
        let _ = writeln!(
            r,
            "| {} | {} | {} |",
            chunk[0].cone.as_str(),
            chunk[0].variant,
            cells.join(" | ")
        );
    }
    let _ = writeln!(
        r,
        "\n(percent: ω/ω* − 1.) Per-run details, the foot loads and the pyramid face width: `paper_plate.csv`.\n"
    );

    // Pyramid lock.
    let pyr: Vec<&PaperRow> = rows
        .iter()
        .filter(|x| x.cone == Cone::Pyramidal && x.variant == "default")
        .collect();
    let _ = writeln!(
        r,
        "## Pyramidal cone: the plate stops turning (orientation lock)\n"
    );
    let _ = writeln!(
        r,
        "With MuJoCo's default pyramidal cone the plate turns briefly, then **locks its orientation** and \
         translates with the pusher: the final angle θ_end and the push direction in the world α = θ_end + φ are\n"
    );
    let _ = writeln!(r, "| v_c | ω (rad/s) | θ_end (rad) | α − π/4 (rad) | face width w (m/s) |\n|---|---|---|---|---|");
    for x in &pyr {
        let _ = writeln!(
            r,
            "| {} | {:.4} | {:.4} | {:.4} | {:.4} |",
            x.v,
            x.omega,
            x.theta_end,
            x.theta_end + PHI_TABLE - FRAC_PI_4,
            x.face_width()
        );
    }
    let (th_lo, th_hi) = min_max(pyr.iter().map(|x| x.theta_end));
    let pyr_all = rows
        .iter()
        .filter(|x| x.cone == Cone::Pyramidal)
        .map(|x| (x.omega / x.star).abs())
        .fold(0.0, f64::max);
    let _ = writeln!(
        r,
        "\n**Why.** MuJoCo's pyramid has four edges `n ± μ t_j` per contact, and for a plane contact the \
tangents t_1, t_2 are fixed in the **world** (built from the floor's normal), not in the plate. Its friction set is \
the L1 diamond `|f_1| + |f_2| ≤ μN` in those axes. A foot sliding fast loads only the two edges that oppose its \
velocity; their sum carries the foot's weight and only their split, driven by `u_1 − u_2`, is free, so the force sits \
on the diamond's **face** and hardly turns as the velocity turns near the diagonal. Once all feet slide with the \
pusher (ω = 0) they get parallel forces ∝ N_i, the friction moment about the contact is \
`(Σ F_i)(p_cof − p_c) × f̂`, and a small offset of α from the diagonal swings f̂ onto the plate's diagonal \
`θ + π/4`: a stable balance. Closed form of the lock, in the limit of a sharp face: the push runs along the pyramid's \
diagonal, `α = π/4 (mod π/2)`, i.e. **θ_lock = π/4 − φ** = {lock:.3} rad here; measured {th_lo:.3} to {th_hi:.3} rad \
(`crates/mujoco/tests/findings.rs` asserts the lock). No setting tried (impratio up to {imp_max}, noslip up to \
{noslip_max} iterations, Δt up to {dt_max}) removes the lock: |ω| stays within {pyr_all:.1} % of |ω*| in every pyramidal run. A face of fixed velocity width \
`w = N R_py/(μ b)` (R_py = 2μ²R_n/impratio, MuJoCo's pyramid regulariser) is **not** what MuJoCo does: the width \
inferred from each lock (`w` column, from `s = (1 − t)/(1 + t)`, `t = tan(θ + π/4)`, `w = v_c(cos α − sin α)/s`) \
grows with v_c and does not fall as 1/impratio (below), so the force split scales with the sliding speed, not with \
a fixed regularisation speed.\n",
        lock = FRAC_PI_4 - PHI_TABLE,
        pyr_all = pct(pyr_all),
        imp_max = variants().iter().map(|v| v.1.impratio).fold(0.0, f64::max),
        noslip_max = variants()
            .iter()
            .map(|v| v.1.noslip_iterations)
            .max()
            .unwrap_or(0),
        dt_max = variants().iter().map(|v| v.1.timestep).fold(0.0, f64::max),
    );
    for (name, _) in variants().iter().skip(1) {
        let ws: Vec<String> = rows
            .iter()
            .filter(|x| x.cone == Cone::Pyramidal && x.variant == *name)
            .map(|x| format!("{:.4}", x.face_width()))
            .collect();
        let speeds: Vec<String> = TABLE_SPEEDS.iter().map(|v| format!("{v:.1}")).collect();
        let _ = writeln!(
            r,
            "* {name}: w = {} m/s at v_c = {}",
            ws.join(", "),
            speeds.join(", ")
        );
    }

    // Elliptic.
    let ell: Vec<&PaperRow> = rows
        .iter()
        .filter(|x| x.cone == Cone::Elliptic && x.variant == "default")
        .collect();
    let _ = writeln!(
        r,
        "\n## Elliptic cone: close to ω*, with loads MuJoCo chooses\n"
    );
    let _ = writeln!(r, "| v_c | ω MuJoCo | ω* | ω std (chatter) | foot loads, tail mean (N) | model ω with those loads |\n|---|---|---|---|---|---|");
    for x in &ell {
        let _ = writeln!(
            r,
            "| {} | {:.4} | {:.4} | {:.3} | {:.3}, {:.3}, {:.3}, {:.3} | {:.4} |",
            x.v,
            x.omega,
            x.star,
            x.std,
            x.loads[0],
            x.loads[1],
            x.loads[2],
            x.loads[3],
            x.with_loads
        );
    }
    // What the elliptic cone's numbers say.
    let v_fast = TABLE_SPEEDS[1];
    let fast = |x: &PaperRow| x.v >= v_fast;
    let (e_lo, e_hi) = min_max(
        ell.iter()
            .filter(|x| fast(x))
            .map(|x| pct(rel(x.omega, x.star))),
    );
    let others = rows
        .iter()
        .filter(|x| {
            x.cone == Cone::Elliptic
                && (x.variant == "impratio=100" || x.variant == "noslip=10")
                && fast(x)
        })
        .map(|x| pct(rel(x.omega, x.star)))
        .fold(0.0, f64::max);
    // Soft-contact slip speed v_s = μ N R_f / b, R_f = R_n / impratio,
    // R_n = (1 − d)/d · A with A ≈ 1/m, b = 2/(d_max t_c); d ∈ [d0, d_width].
    let n = MASS * G / 4.0;
    let a = 1.0 / MASS;
    let b = 2.0 / (s.contact_solimp[1] * s.contact_solref[0]);
    let vs_of = |d: f64| MU * n * ((1.0 - d) / d * a / s.impratio) / b;
    let (vs_lo, vs_hi) = min_max([vs_of(s.contact_solimp[0]), vs_of(s.contact_solimp[1])]);
    let body = plate();
    let forces: Vec<f64> = body.supports().map(|x| x.friction).collect();
    let soft_shift = TABLE_SPEEDS
        .iter()
        .map(|&v| {
            let p = push(v, PHI_TABLE);
            let w0 = star(&p);
            let w1 = steady_omega(&body, &p, &Regularised { slip_speed: vs_hi }, &forces, w0)
                .unwrap_or(f64::NAN);
            rel(w1, w0)
        })
        .fold(0.0, f64::max);
    let slowest = TABLE_SPEEDS
        .iter()
        .map(|&v| {
            let p = push(v, PHI_TABLE);
            SegmentDynamics::new(&body, &p)
                .min_support_speed(star(&p))
                .0
        })
        .fold(f64::INFINITY, f64::min);
    let (sd_lo, sd_hi) = min_max(ell.iter().map(|x| x.std));
    let (sr_lo, sr_hi) = min_max(ell.iter().map(|x| pct(x.std / x.star.abs())));
    let other_way: Vec<String> = ell
        .iter()
        .filter(|x| (x.with_loads - x.star).signum() != (x.omega - x.star).signum())
        .map(|x| x.v.to_string())
        .collect();
    let ell_cells: Vec<&GridCell> = cells.iter().filter(|c| c.cone == Cone::Elliptic).collect();
    let centre_abs = ell_cells
        .iter()
        .filter(|c| c.star.abs() <= SMALL_STAR)
        .map(|c| (c.omega - c.star).abs())
        .fold(0.0, f64::max);
    let centre_phis: Vec<String> = {
        let mut v: Vec<f64> = ell_cells
            .iter()
            .filter(|c| c.star.abs() <= SMALL_STAR)
            .map(|c| c.phi)
            .collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v.iter().map(|p| format!("{p:.3}")).collect()
    };
    let fr_min = ell_cells.iter().map(|c| c.fr).fold(f64::INFINITY, f64::min);
    let slow: Vec<&&GridCell> = ell_cells
        .iter()
        .filter(|c| c.fr == fr_min && c.star.abs() > SMALL_STAR)
        .collect();
    let (ch_lo, ch_hi) = min_max(slow.iter().map(|c| pct(c.std / c.star.abs())));
    let v_min = slow.first().map_or(f64::NAN, |c| c.v);
    let _ = writeln!(
        r,
        "\n**Why.** The elliptic cone is isotropic and follows ω* within {ell_fast} % at v_c ≥ {v_fast} m/s \
(within {others:.1} % with impratio=100 and noslip=10), so the inertial term survives. What is left: (1) soft-contact \
regularisation makes friction viscous below `v_s ≈ μ N R_f / b` (`R_f = R_n/impratio`, `R_n = (1 − d)/d · A`, \
`b = 2/(d_max t_c)`; MuJoCo's defaults t_c = {tc} s, d = {d0}–{d1}, A ≈ 1/m give v_s = {vs} mm/s), far below the \
feet's sliding speeds (at least {slowest:.3} m/s at ω* in the table), so it moves ω* by at most {soft_shift:.1e} relative \
(`theory::Regularised` at the larger v_s): not the cause. (2) The feet rock: ω chatters with a standard deviation of \
{sd} rad/s ({sr} % of |ω*|), and MuJoCo's solver shifts weight onto one diagonal pair (the twist mode (+,−,+,−) a \
rigid plate on springs cannot have; four feet are statically indeterminate and the convex contact solver, not \
elasticity, picks the split). Feeding the time-mean loads into the Coulomb model does **not** reproduce MuJoCo (last \
column: it moves ω the other way at v_c = {other_way} m/s), so the mean load split is not the explanation; the \
residual goes with the rocking and is not explained by a closed form here. (3) The large relative errors of the grid \
are at φ = {centre} (push through the centre of mass, |ω*| ≤ {SMALL_STAR} rad/s; absolute error up to \
{centre_abs:.4} rad/s) and at the smallest Fr = {fr_min} (v_c = {v_min:.2} m/s), where the chatter is {chatter} % \
of |ω*|.\n",
        ell_fast = range_text(e_lo, e_hi, 1),
        tc = s.contact_solref[0],
        d0 = s.contact_solimp[0],
        d1 = s.contact_solimp[1],
        vs = range_text(1e3 * vs_lo, 1e3 * vs_hi, 2),
        sd = range_text(sd_lo, sd_hi, 3),
        sr = range_text(sr_lo, sr_hi, 0),
        other_way = if other_way.is_empty() {
            "none".to_string()
        } else {
            other_way.join(", ")
        },
        centre = centre_phis.join(", "),
        chatter = range_text(ch_lo, ch_hi, 0),
    );

    let _ = writeln!(r, "## Load transfer (elliptic cone)\n");
    let _ = writeln!(r, "| h_cm (m) | h_push (m) | v_c | ω MuJoCo | ω* (no transfer) | ω with load transfer | ω with MuJoCo's loads |\n|---|---|---|---|---|---|---|");
    for x in lt {
        let _ = writeln!(
            r,
            "| {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.4} |",
            x.hc, x.hp, x.v, x.omega, x.star, x.transfer, x.with_loads
        );
    }
    let best = lt
        .iter()
        .filter(|x| x.hc > 0.0)
        .min_by(|a, b| rel(a.omega, a.transfer).total_cmp(&rel(b.omega, b.transfer)));
    // Elsewhere: the predicted shift against MuJoCo's.
    let shares: Vec<f64> = lt
        .iter()
        .filter(|x| x.hc > 0.0)
        .filter(|x| best.is_none_or(|b| !std::ptr::eq(*x, b)))
        .map(|x| (x.transfer - x.star) / (x.omega - x.star))
        .collect();
    let same_sign = shares.iter().filter(|s| **s > 0.0).count();
    let (sh_lo, sh_hi) = min_max(shares.iter().copied());
    let best_text = best.map_or(String::new(), |x| {
        format!(
            " At {} m/s with h_cm = {}, h_push = {} the prediction lands within {:.1} % of MuJoCo where ω* is \
{:.1} % off (`load_transfer.csv`).",
            x.v,
            x.hc,
            x.hp,
            pct(rel(x.omega, x.transfer)),
            pct(rel(x.omega, x.star))
        )
    });
    let _ = writeln!(
        r,
        "\n**Why.** With the centre of mass at height h_cm and the push at h_push, tilt balance gives \
`Σ p_i ΔN_i = (h_push − h_cm) f_c − h_cm Σ f_i` (object frame, f_i the feet's friction forces, f_c the pusher force); \
spreading it by the least-norm (elastic-foundation) rule `ΔN_i = c_0 + c · p_i` and iterating with the Coulomb model \
gives the 'load transfer' column (`theory::steady_omega_load_transfer`). Pushing at the height of the centre of mass \
still transfers load, through the friction at the floor (`−h_cm Σ f_i`).{best_text} In the other {n} runs with \
h_cm > 0 the predicted shift ω_transfer − ω* has the sign of MuJoCo's in {same_sign} and is {share} times its size: \
the rocking of (2) above adds to it.\n",
        n = shares.len(),
        share = range_text(sh_lo, sh_hi, 1),
    );

    let _ = writeln!(r, "## The (Fr, φ) grid\n");
    let (fr_lo, fr_hi) = min_max(cells.iter().map(|c| c.fr));
    let (ph_lo, ph_hi) = min_max(cells.iter().map(|c| c.phi));
    for cone in Cone::ALL {
        let cs: Vec<&GridCell> = cells.iter().filter(|c| c.cone == cone).collect();
        // Relative error where ω* is not ≈ 0 (φ ≈ π/4 pushes through the centre of mass).
        let errs: Vec<f64> = cs
            .iter()
            .filter(|c| c.star.abs() > SMALL_STAR)
            .map(|c| rel(c.omega, c.star))
            .collect();
        let abs_small = cs
            .iter()
            .filter(|c| c.star.abs() <= SMALL_STAR)
            .map(|c| (c.omega - c.star).abs())
            .fold(0.0, f64::max);
        let count = |f: &str| cs.iter().filter(|c| c.flags.contains(&f)).count();
        let te = cs.iter().map(|c| c.theta_err).fold(0.0, f64::max);
        let pe = cs.iter().map(|c| c.pos_err).fold(0.0, f64::max);
        let _ = writeln!(
            r,
            "* **{}** ({} cells, Fr {fr_lo}–{fr_hi}, φ {ph_lo:.2}–{ph_hi:.2}): steady-ω relative error (cells with |ω*| > {SMALL_STAR} rad/s) median {:.3}, max {:.3}, absolute error where |ω*| ≤ {SMALL_STAR}: {:.4} rad/s; \
             trajectory error over {T_RUN} s: θ up to {:.3} rad, position up to {:.3} m; flags: stops turning {}, \
             locks orientation {}, chatters {}, creeps {}, sticks {}.",
            cone.as_str(),
            cs.len(),
            median(&errs),
            min_max(errs.iter().copied()).1,
            abs_small,
            te,
            pe,
            count("stops_turning"),
            count("locks_orientation"),
            count("chatters"),
            count("creeps"),
            count("sticks")
        );
    }
    let frs_low: Vec<f64> = {
        let mut v: Vec<f64> = cells.iter().map(|c| c.fr).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v.into_iter().take(2).collect()
    };
    let fr_cut = frs_low.last().copied().unwrap_or(f64::NAN);
    let ell_low = cells
        .iter()
        .filter(|c| c.cone == Cone::Elliptic && c.fr <= fr_cut && c.star.abs() > SMALL_STAR)
        .map(|c| rel(c.omega, c.star))
        .fold(0.0, f64::max);
    let _ = writeln!(
        r,
        "* elliptic at Fr ≤ {fr_cut}: relative error up to {ell_low:.3} (|ω*| > {SMALL_STAR}; slow pushes chatter most)."
    );
    let _ = writeln!(r, "\nPer cell: `grid.csv`; map: `disagreement_map.svg`.\n");
    r
}
