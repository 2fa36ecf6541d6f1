//! The parameter sweeps behind the maps and the scaling curves.
//!
//! Every sweep cell is one [`Task`]; the list of tasks is fixed by the grid
//! (`--quick` or full), so a part of it can be computed anywhere and merged.
//! Each cell is evaluated from the dynamic model's steady-state analysis
//! ([`SegmentDynamics`]) and, for the validity map, a fixed-step RK4
//! integration of the scalar ODE `I_P ω̇ = G(ω)`.
//!
//! Definitions (also in `results/README.md`):
//!
//! * κ = ω* / (v_c ψ(φ)): ω* the steady state a segment starting at ω = 0
//!   reaches, v_c ψ the kinematic model's ω.
//! * Validity error ε(Fr, φ): the object moves straight with the pusher
//!   (ω = 0, the paper's start) when a segment of push length
//!   `d = SEGMENT_LENGTH · L` begins; ε = |Δθ_dynamic − Δθ_kinematic| / |Δθ_kinematic|,
//!   the relative error of the angle the kinematic model says the object
//!   turns over that segment.
//! * Required contact friction μ_req(v_c, φ): over the same segment's transient
//!   (ω relaxes monotonically from 0 to ω*, and the pusher force depends on ω
//!   alone), the largest angle α between the pusher force and the cone of
//!   inward normals at the contact; μ_req = tan α, and α > 90° means the
//!   pusher would have to pull.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use std::ops::Range;
use std::path::Path;

use anyhow::{bail, Context};
use plotters::style::RGBColor;
use pushval_model::{Body, ContactLimits, Push, SegmentDynamics};
use pushval_scenario::Scenario;
use rayon::prelude::*;

use super::plot::{
    Axis, Cell, Figure, Key, Legend, Panel, Series, Stroke, BLUE_, DARK, PALETTE, PURPLE,
};
use super::{num, Csv, Entry, Shard, Writer};

/// Push length of the validity map's segment, in units of L = |p_c − p_cm|.
pub const SEGMENT_LENGTH: f64 = 10.0;

/// The paper schedule's push directions (rad).
pub const SCHEDULE_PHIS: [f64; 5] = [
    FRAC_PI_4 + 0.3,
    FRAC_PI_4,
    FRAC_PI_4 - 0.3,
    FRAC_PI_4 + 0.5,
    FRAC_PI_4 + 0.15,
];

/// Contact friction of the paper scenarios (`[contact] mu`).
pub const CONTACT_MU: f64 = 0.8;

/// A body with what the sweeps need to turn a Froude number into a speed.
#[derive(Debug, Clone)]
pub struct Geometry {
    pub name: &'static str,
    pub body: Body,
    /// Σ μ_i N_i / (m g).
    pub mu_bar: f64,
    /// m/s².
    pub gravity: f64,
    /// L = |p_c − p_cm| (m).
    pub length: f64,
    pub limits: ContactLimits,
    /// The push directions of its κ curves (rad).
    pub phis: Vec<f64>,
}

impl Geometry {
    fn from_scenario(name: &'static str, sc: &Scenario, phis: Vec<f64>) -> Self {
        Self {
            name,
            body: sc.body(),
            mu_bar: sc.effective_mu(),
            gravity: sc.gravity,
            length: sc.froude_length(),
            limits: sc.contact_limits,
            phis,
        }
    }
    /// Pusher speed (m/s) for a Froude number.
    pub fn speed(&self, fr: f64) -> f64 {
        (fr * self.mu_bar * self.gravity * self.length).sqrt()
    }
    /// Froude number for a pusher speed (m/s).
    pub fn froude(&self, speed: f64) -> f64 {
        speed * speed / (self.mu_bar * self.gravity * self.length)
    }
}

/// A 3:1 rectangle (0.375 m × 0.125 m, 1 kg) on its four corners, pushed at a corner.
const RECTANGLE: &str = r#"
name = "rectangle-3to1"
description = "3:1 plate on four corner supports, pushed at a corner"
[object]
mass = 1.0
polygon = [[-0.1875, -0.0625], [0.1875, -0.0625], [0.1875, 0.0625], [-0.1875, 0.0625]]
[supports]
points = [[-0.1875, -0.0625], [0.1875, -0.0625], [0.1875, 0.0625], [-0.1875, 0.0625]]
mu = 0.5
load = "equal"
[contact]
point = [-0.1875, -0.0625]
mu = 0.8
[[push]]
duration = 1.0
speed = 0.2
phi = 0.8
"#;

/// The paper plate pushed at the middle of its bottom edge (assumptions map only).
const EDGE: &str = r#"
name = "square-edge"
description = "The paper plate pushed at the middle of an edge"
[object]
mass = 1.0
polygon = [[-0.125, -0.125], [0.125, -0.125], [0.125, 0.125], [-0.125, 0.125]]
[supports]
points = [[-0.125, -0.125], [0.125, -0.125], [0.125, 0.125], [-0.125, 0.125]]
mu = 0.5
load = "equal"
[contact]
point = [0.0, -0.125]
mu = 0.8
[[push]]
duration = 1.0
speed = 0.2
phi = 1.5
"#;

/// Lower end of the push directions of the two assumptions maps (rad): the
/// corner contact and the edge contact; each map spans π.
pub const ASSUME_PHI_LO: [f64; 2] = [-FRAC_PI_4, 0.0];

/// The geometry of assumptions map `k` (0: corner, 1: edge middle).
pub fn assume_geometry(geoms: &[Geometry], k: usize) -> &Geometry {
    if k == 0 {
        &geoms[0]
    } else {
        &geoms[geoms.len() - 1]
    }
}

/// The geometries of the κ plot, then the edge-pushed plate (no κ curves);
/// the first is the paper plate (the maps use it).
pub fn geometries(dir: &Path) -> anyhow::Result<Vec<Geometry>> {
    let load = |n: &str| Scenario::from_path(dir.join(n)).map_err(anyhow::Error::from);
    let square = load("paper-square-v1.0.toml")?;
    let triangle = load("triangle-statics.toml")?;
    let uniform = load("uniform-pressure-square.toml")?;
    let rect = Scenario::from_toml(RECTANGLE, Path::new("<report: rectangle-3to1>"))?;
    let edge = Scenario::from_toml(EDGE, Path::new("<report: square-edge>"))?;
    let corner = vec![FRAC_PI_4 - 0.3, FRAC_PI_4 + 0.15, FRAC_PI_4 + 0.5];
    Ok(vec![
        Geometry::from_scenario("square corner", &square, corner.clone()),
        Geometry::from_scenario("triangle edge", &triangle, vec![1.3, FRAC_PI_2, 1.9]),
        Geometry::from_scenario("square uniform pressure", &uniform, corner),
        Geometry::from_scenario("3:1 rectangle corner", &rect, vec![0.7, 1.0, 1.3]),
        Geometry::from_scenario("square edge middle", &edge, Vec::new()),
    ])
}

/// The sweep grids.
#[derive(Debug, Clone)]
pub struct Grids {
    /// Froude numbers of the κ curves and the validity map (10⁻³ … 10, log).
    pub fr: Vec<f64>,
    /// Decades per grid step of `fr`.
    pub fr_step: f64,
    /// Speeds of the τ curves (m/s, log, 0.02 … 2).
    pub tau_v: Vec<f64>,
    /// Push directions of the validity map (rad, cell centres in (0, π/2)).
    pub val_phi: Vec<f64>,
    /// Speeds of the assumptions map (m/s, cell centres in (0, 2]).
    pub as_v: Vec<f64>,
    /// Push directions of the assumptions maps (rad, cell centres), per
    /// contact: `[ASSUME_PHI_LO[k], ASSUME_PHI_LO[k] + π)`.
    pub as_phi: [Vec<f64>; 2],
}

impl Grids {
    pub fn new(quick: bool) -> Self {
        let per_decade = if quick { 2 } else { 10 };
        let fr_step = 1.0 / per_decade as f64;
        let fr = (0..=4 * per_decade)
            .map(|i| 10f64.powf(-3.0 + i as f64 * fr_step))
            .collect();
        let n_tau = if quick { 9 } else { 41 };
        let tau_v = (0..n_tau)
            .map(|i| 0.02 * 10f64.powf(2.0 * i as f64 / (n_tau - 1) as f64))
            .collect();
        let centres = |lo: f64, hi: f64, n: usize| -> Vec<f64> {
            (0..n)
                .map(|j| lo + (j as f64 + 0.5) * (hi - lo) / n as f64)
                .collect()
        };
        let (nv, np) = if quick { (6, 6) } else { (36, 36) };
        let (av, ap) = if quick { (8, 8) } else { (40, 48) };
        Self {
            fr,
            fr_step,
            tau_v,
            val_phi: centres(0.0, FRAC_PI_2, np.max(nv)),
            as_v: centres(0.0, 2.0, av),
            as_phi: ASSUME_PHI_LO.map(|lo| centres(lo, lo + PI, ap)),
        }
    }
}

/// One sweep cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// κ of geometry `geom`, direction `geoms[geom].phis[phi]`, at `fr[i]`.
    Kappa { geom: usize, phi: usize, i: usize },
    /// τ of the paper plate at `SCHEDULE_PHIS[phi]` and `tau_v[i]`.
    Tau { phi: usize, i: usize },
    /// Validity error of the paper plate at `fr[i]`, `val_phi[j]`.
    Validity { i: usize, j: usize },
    /// Required contact friction of the paper plate pushed at contact `k`
    /// (0 the corner, 1 the middle of an edge) at `as_v[i]`, `as_phi[k][j]`.
    Assume { k: usize, i: usize, j: usize },
}

/// Number of values each task kind produces.
pub fn width(t: &Task) -> usize {
    match t {
        Task::Kappa { .. } => 5,
        Task::Tau { .. } => 4,
        Task::Validity { .. } => 8,
        Task::Assume { .. } => 4,
    }
}

/// The fixed task list.
pub fn tasks(geoms: &[Geometry], quick: bool) -> Vec<Task> {
    let g = Grids::new(quick);
    let mut out = Vec::new();
    for (gi, geom) in geoms.iter().enumerate() {
        for phi in 0..geom.phis.len() {
            for i in 0..g.fr.len() {
                out.push(Task::Kappa { geom: gi, phi, i });
            }
        }
    }
    for phi in 0..SCHEDULE_PHIS.len() {
        for i in 0..g.tau_v.len() {
            out.push(Task::Tau { phi, i });
        }
    }
    for j in 0..g.val_phi.len() {
        for i in 0..g.fr.len() {
            out.push(Task::Validity { i, j });
        }
    }
    for k in 0..2 {
        for j in 0..g.as_phi[k].len() {
            for i in 0..g.as_v.len() {
                out.push(Task::Assume { k, i, j });
            }
        }
    }
    out
}

fn segment(body: &Body, speed: f64, phi: f64) -> SegmentDynamics {
    SegmentDynamics::new(
        body,
        &Push {
            duration: 1.0,
            speed,
            phi,
        },
    )
}

/// ω* (the steady state reached from ω = 0) and τ; NaN where there is none.
pub fn steady(seg: &SegmentDynamics) -> (f64, f64) {
    let roots = seg.steady_states();
    match seg.attractor(&roots, 0.0) {
        Some(s) => (s.omega, s.tau.unwrap_or(f64::NAN)),
        None => (f64::NAN, f64::NAN),
    }
}

/// `[v, ψ, ω*, κ, τ]` for a geometry, direction and Froude number.
pub fn kappa_cell(g: &Geometry, phi: f64, fr: f64) -> [f64; 5] {
    let v = g.speed(fr);
    let seg = segment(&g.body, v, phi);
    let psi = pushval_model::kinematic::psi_of(&seg).unwrap_or(f64::NAN);
    let (w, tau) = steady(&seg);
    [v, psi, w, w / (v * psi), tau]
}

/// Angle (rad) the dynamic model turns over `t_end` seconds from `omega0`,
/// by RK4 on `ω̇ = G(ω)/I_P` with steps of τ/40 (or t_end/4000 when τ is
/// undefined); once ω has settled onto ω* the rest is `ω* · (time left)`.
pub fn turned_angle(seg: &SegmentDynamics, omega0: f64, t_end: f64, w_star: f64, tau: f64) -> f64 {
    let h0 = if tau.is_finite() && tau > 0.0 {
        (tau / 40.0).min(t_end / 200.0)
    } else {
        t_end / 4000.0
    };
    let scale = w_star.abs() + seg.speed() * 1e-3;
    let (mut t, mut w, mut th) = (0.0, omega0, 0.0);
    while t < t_end {
        if tau.is_finite() && t > 60.0 * tau && (w - w_star).abs() <= 1e-14 * scale {
            return th + w * (t_end - t);
        }
        let h = h0.min(t_end - t);
        let f = |w: f64| seg.omega_dot(w);
        let k1 = f(w);
        let k2 = f(w + 0.5 * h * k1);
        let k3 = f(w + 0.5 * h * k2);
        let k4 = f(w + h * k3);
        // θ̇ = ω: the RK4 stages of θ are the stage values of ω.
        let w2 = w + 0.5 * h * k1;
        let w3 = w + 0.5 * h * k2;
        let w4 = w + h * k3;
        th += h / 6.0 * (w + 2.0 * w2 + 2.0 * w3 + w4);
        w += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        t += h;
    }
    th
}

/// `[v, ψ, ω*, τ, T, Δθ_dynamic, Δθ_kinematic, ε]` for the validity map.
pub fn validity_cell(g: &Geometry, phi: f64, fr: f64) -> [f64; 8] {
    let v = g.speed(fr);
    let seg = segment(&g.body, v, phi);
    let psi = pushval_model::kinematic::psi_of(&seg).unwrap_or(f64::NAN);
    let (w, tau) = steady(&seg);
    let t_end = SEGMENT_LENGTH * g.length / v;
    let th_dyn = turned_angle(&seg, 0.0, t_end, w, tau);
    let th_kin = v * psi * t_end;
    let eps = (th_dyn - th_kin).abs() / th_kin.abs();
    [v, psi, w, tau, t_end, th_dyn, th_kin, eps]
}

/// Samples of ω along the transient from 0 to ω* for the force check.
const FORCE_SAMPLES: usize = 64;

/// `[ω*, α_max (rad), μ_req = tan α_max (∞ when α ≥ 90°), |f_c| max (N)]`.
pub fn assume_cell(g: &Geometry, phi: f64, v: f64) -> [f64; 4] {
    let seg = segment(&g.body, v, phi);
    let (w, _) = steady(&seg);
    let mut alpha = 0.0f64;
    let mut fmax = 0.0f64;
    if w.is_finite() {
        for k in 0..=FORCE_SAMPLES {
            let om = w * k as f64 / FORCE_SAMPLES as f64;
            let f = seg.pusher_force(om);
            alpha = alpha.max(g.limits.cone_angle(&f));
            fmax = fmax.max(f.norm());
        }
    }
    let mu = if alpha >= FRAC_PI_2 {
        f64::INFINITY
    } else {
        alpha.tan()
    };
    [w, alpha, mu, fmax]
}

/// Evaluates one task.
pub fn eval(geoms: &[Geometry], grids: &Grids, t: &Task) -> Vec<f64> {
    let square = &geoms[0];
    match *t {
        Task::Kappa { geom, phi, i } => {
            let g = &geoms[geom];
            kappa_cell(g, g.phis[phi], grids.fr[i]).to_vec()
        }
        Task::Tau { phi, i } => {
            let v = grids.tau_v[i];
            let seg = segment(&square.body, v, SCHEDULE_PHIS[phi]);
            let (w, tau) = steady(&seg);
            vec![w, tau, v * tau, square.froude(v)]
        }
        Task::Validity { i, j } => validity_cell(square, grids.val_phi[j], grids.fr[i]).to_vec(),
        Task::Assume { k, i, j } => {
            assume_cell(assume_geometry(geoms, k), grids.as_phi[k][j], grids.as_v[i]).to_vec()
        }
    }
}

/// Evaluates `tasks[range]` in parallel, in order, with a progress bar.
pub fn compute(
    geoms: &[Geometry],
    tasks: &[Task],
    range: Range<usize>,
    quick: bool,
    progress: bool,
) -> Vec<Vec<f64>> {
    let grids = Grids::new(quick);
    let bar = super::progress(range.len() as u64, progress, "sweeps");
    let rows: Vec<Vec<f64>> = tasks[range]
        .par_iter()
        .map(|t| {
            let r = eval(geoms, &grids, t);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    rows
}

/// The part `shard` of `n` tasks: contiguous, sizes differing by at most one.
pub fn shard_range(n: usize, shard: Shard) -> Range<usize> {
    let lo = (shard.k - 1) * n / shard.n;
    let hi = shard.k * n / shard.n;
    lo..hi
}

/// File name of a part, relative to the output folder.
pub fn part_name(shard: Shard) -> String {
    format!("parts/sweep-{}-of-{}.csv", shard.k, shard.n)
}

fn grid_name(quick: bool) -> &'static str {
    if quick {
        "quick"
    } else {
        "full"
    }
}

/// The part file: a header naming the part, the grid and the task count,
/// then one line per task, `index,value,...` (shortest round-trip numbers).
pub fn part_text(
    tasks: &[Task],
    range: Range<usize>,
    rows: &[Vec<f64>],
    shard: Shard,
    quick: bool,
) -> String {
    let mut s = format!(
        "# pushval report sweep part {}/{} grid={} tasks={}\n",
        shard.k,
        shard.n,
        grid_name(quick),
        tasks.len()
    );
    for (idx, row) in range.zip(rows) {
        s.push_str(&idx.to_string());
        for v in row {
            s.push(',');
            s.push_str(&num(*v));
        }
        s.push('\n');
    }
    s
}

/// Reads every part in `OUT/parts/` and returns the rows of all tasks.
pub fn merge_parts(out: &Path, tasks: &[Task], quick: bool) -> anyhow::Result<Vec<Vec<f64>>> {
    let dir = out.join("parts");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .with_context(|| format!("reading {} (run the shards first)", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("sweep-") && n.ends_with(".csv"))
        })
        .collect();
    files.sort();
    if files.is_empty() {
        bail!("no part files (sweep-K-of-N.csv) in {}", dir.display());
    }
    let mut rows: Vec<Option<Vec<f64>>> = vec![None; tasks.len()];
    let mut seen: Vec<(usize, usize)> = Vec::new();
    for f in &files {
        let text =
            std::fs::read_to_string(f).with_context(|| format!("reading {}", f.display()))?;
        let mut lines = text.lines();
        let head = lines.next().unwrap_or_default();
        let bad = || anyhow::anyhow!("{}: not a sweep part file", f.display());
        let rest = head
            .strip_prefix("# pushval report sweep part ")
            .ok_or_else(bad)?;
        let mut it = rest.split_whitespace();
        let kn: Shard = it
            .next()
            .ok_or_else(bad)?
            .parse()
            .map_err(|e: String| anyhow::anyhow!("{}: {e}", f.display()))?;
        let grid = it
            .next()
            .and_then(|s| s.strip_prefix("grid="))
            .ok_or_else(bad)?;
        let total: usize = it
            .next()
            .and_then(|s| s.strip_prefix("tasks="))
            .and_then(|s| s.parse().ok())
            .ok_or_else(bad)?;
        if grid != grid_name(quick) || total != tasks.len() {
            bail!(
                "{}: computed on the {grid} grid ({total} tasks), but this merge wants the {} grid ({} tasks); pass --quick consistently",
                f.display(),
                grid_name(quick),
                tasks.len()
            );
        }
        seen.push((kn.k, kn.n));
        for (ln, line) in lines.enumerate() {
            let mut fields = line.split(',');
            let idx: usize = fields
                .next()
                .and_then(|s| s.parse().ok())
                .with_context(|| format!("{}: line {}: bad index", f.display(), ln + 2))?;
            let vals: Vec<f64> = fields
                .map(|s| s.parse::<f64>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("{}: line {}: bad number", f.display(), ln + 2))?;
            let slot = rows
                .get_mut(idx)
                .with_context(|| format!("{}: task {idx} out of range", f.display()))?;
            if vals.len() != width(&tasks[idx]) {
                bail!("{}: task {idx} has {} values", f.display(), vals.len());
            }
            if slot.is_some() {
                bail!("{}: task {idx} appears in two parts", f.display());
            }
            *slot = Some(vals);
        }
    }
    let n = seen[0].1;
    if seen.iter().any(|&(_, m)| m != n) {
        bail!(
            "{} holds parts of different splits ({:?}); remove the stale ones",
            dir.display(),
            seen
        );
    }
    let missing: Vec<usize> = (1..=n)
        .filter(|k| !seen.iter().any(|s| s.0 == *k))
        .collect();
    if !missing.is_empty() {
        bail!("missing parts {missing:?} of {n} in {}", dir.display());
    }
    rows.into_iter()
        .enumerate()
        .map(|(i, r)| r.with_context(|| format!("task {i} is in no part")))
        .collect()
}

fn stroke_for(k: usize) -> Stroke {
    match k % 3 {
        0 => Stroke::Solid,
        1 => Stroke::Dashed,
        _ => Stroke::Dots,
    }
}

/// Value of `y` at `x` by linear interpolation in log x (points sorted by x).
fn interp_log(points: &[(f64, f64)], x: f64) -> f64 {
    for w in points.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x >= x0 && x <= x1 {
            let s = (x.ln() - x0.ln()) / (x1.ln() - x0.ln());
            return y0 + s * (y1 - y0);
        }
    }
    f64::NAN
}

/// Smallest x at which y first reaches `level` (log-linear interpolation), if any.
pub fn first_crossing(points: &[(f64, f64)], level: f64) -> Option<f64> {
    if points.first().is_some_and(|p| p.1 >= level) {
        return points.first().map(|p| p.0);
    }
    points.windows(2).find_map(|w| {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        (y0 < level && y1 >= level).then(|| {
            let s = (level - y0) / (y1 - y0);
            (x0.ln() + s * (x1.ln() - x0.ln())).exp()
        })
    })
}

/// Every sweep figure; returns their README entries.
pub fn figures(
    geoms: &[Geometry],
    tasks: &[Task],
    rows: &[Vec<f64>],
    quick: bool,
    w: &mut Writer,
) -> anyhow::Result<Vec<Entry>> {
    let grids = Grids::new(quick);
    Ok(vec![
        kappa_figure(geoms, &grids, tasks, rows, w)?,
        tau_figure(geoms, &grids, tasks, rows, w)?,
        validity_figure(geoms, &grids, tasks, rows, w)?,
        assumptions_figure(geoms, &grids, tasks, rows, w)?,
    ])
}

fn kappa_figure(
    geoms: &[Geometry],
    grids: &Grids,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let mut csv = Csv::new(&[
        "geometry",
        "phi",
        "froude",
        "speed",
        "psi",
        "omega_steady",
        "kappa",
        "tau",
    ]);
    // curves[geom][phi] = [(Fr, κ)]
    let mut curves: Vec<Vec<Vec<(f64, f64)>>> = geoms
        .iter()
        .map(|g| vec![Vec::new(); g.phis.len()])
        .collect();
    for (t, r) in tasks.iter().zip(rows) {
        if let Task::Kappa { geom, phi, i } = *t {
            let g = &geoms[geom];
            csv.row(&[
                g.name.to_string(),
                num(g.phis[phi]),
                num(grids.fr[i]),
                num(r[0]),
                num(r[1]),
                num(r[2]),
                num(r[3]),
                num(r[4]),
            ]);
            curves[geom][phi].push((grids.fr[i], r[3]));
        }
    }
    let mut left = Panel::new(
        "κ = ω* / (v_c ψ) against the Froude number",
        Axis::log("Froude number Fr = v_c² / (μ̄ g L)"),
        Axis::lin("κ = ω* / (v_c ψ(φ))"),
    )
    .legend(Legend::LowerLeft);
    let mut right = Panel::new(
        "|1 − κ| (log–log): the departure from the kinematic model",
        Axis::log("Froude number Fr = v_c² / (μ̄ g L)"),
        Axis::log("|1 − κ|"),
    )
    .legend(Legend::None);
    for (gi, g) in geoms.iter().enumerate() {
        for (pi, phi) in g.phis.iter().enumerate() {
            let pts = &curves[gi][pi];
            let s = Series::new(
                format!("{}, φ = {phi:.3}", g.name),
                PALETTE[gi],
                stroke_for(pi),
            )
            .width(if stroke_for(pi) == Stroke::Dots { 3 } else { 2 });
            left = left.series(s.clone().points(pts.clone()));
            right = right.series(
                s.points(
                    pts.iter()
                        .map(|&(x, k)| (x, (1.0 - k).abs()))
                        .filter(|p| p.1 > 0.0)
                        .collect(),
                ),
            );
        }
    }
    w.file("kappa.csv", csv.as_bytes())?;
    w.figure(
        "kappa.svg",
        &Figure {
            size: (1600, 700),
            cols: 2,
            panels: vec![left, right],
            key: None,
        },
    )?;
    let all: Vec<&Vec<(f64, f64)>> = curves.iter().flatten().collect();
    let spread_at = |fr: f64| {
        let ks: Vec<f64> = all.iter().map(|c| interp_log(c, fr)).collect();
        let lo = ks.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = ks.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    };
    let fr_lo = grids.fr[0];
    let levels = [fr_lo, 0.01, 0.1, 1.0, 10.0];
    let table: Vec<String> = levels
        .iter()
        .map(|&fr| {
            let (lo, hi) = spread_at(fr);
            format!("| {fr} | {lo:.4} | {hi:.4} | {:.4} |", hi - lo)
        })
        .collect();
    // Small-Fr slope of |1 − κ| on log–log axes, per curve (first two grid points).
    let mut slopes: Vec<f64> = all
        .iter()
        .filter(|c| c.len() >= 2)
        .map(|c| {
            let (a, b) = (c[0], c[1]);
            ((1.0 - b.1).abs().ln() - (1.0 - a.1).abs().ln()) / (b.0.ln() - a.0.ln())
        })
        .collect();
    slopes.sort_by(f64::total_cmp);
    let (smin, smax) = (
        slopes.first().copied().unwrap_or(f64::NAN),
        slopes.last().copied().unwrap_or(f64::NAN),
    );
    // The prefactor c of κ ≈ 1 − c Fr at the smallest Fr.
    let mut cs: Vec<f64> = all
        .iter()
        .filter_map(|c| c.first().map(|p| (1.0 - p.1) / p.0))
        .collect();
    cs.sort_by(f64::total_cmp);
    let (cmin, cmax) = (
        cs.first().copied().unwrap_or(f64::NAN),
        cs.last().copied().unwrap_or(f64::NAN),
    );
    Ok(Entry {
        figure: "kappa.svg".into(),
        data: vec!["kappa.csv".into()],
        text: format!(
            "κ = ω*/(v_c ψ), the paper's missing scaling factor between the dynamic and the \
             quasi-static model, against Fr (log x) for {} curves: four geometries (colours; the \
             paper plate pushed at a corner on four supports, a triangle pushed on an edge, the \
             same square on a uniform pressure, a 3:1 rectangle pushed at a corner) and three \
             push directions each (line styles). Every curve starts at κ = 1 as Fr → 0, and \
             |1 − κ| grows like Fr^p with p between {smin:.2} and {smax:.2} at the smallest Fr, \
             i.e. κ ≈ 1 − c Fr with a prefactor c between {cmin:.3} and {cmax:.3} that depends on \
             the geometry and φ. So the curves do not collapse on Fr alone: c varies by a factor \
             {:.1} over the curves, and the spread (max − min κ) peaks near Fr ≈ 1; a geometry factor c would rescale the small-Fr part onto one line.\n\n\
             | Fr | min κ | max κ | spread |\n|---|---|---|---|\n{}",
            all.len(),
            cmax / cmin,
            table.join("\n")
        ),
    })
}

fn tau_figure(
    geoms: &[Geometry],
    grids: &Grids,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let mut csv = Csv::new(&[
        "phi",
        "speed",
        "froude",
        "omega_steady",
        "tau",
        "relaxation_length",
    ]);
    let mut tau_c: Vec<Vec<(f64, f64)>> = vec![Vec::new(); SCHEDULE_PHIS.len()];
    let mut len_c: Vec<Vec<(f64, f64)>> = vec![Vec::new(); SCHEDULE_PHIS.len()];
    for (t, r) in tasks.iter().zip(rows) {
        if let Task::Tau { phi, i } = *t {
            let v = grids.tau_v[i];
            csv.row(&[
                num(SCHEDULE_PHIS[phi]),
                num(v),
                num(r[3]),
                num(r[0]),
                num(r[1]),
                num(r[2]),
            ]);
            tau_c[phi].push((v, r[1]));
            len_c[phi].push((v, r[2]));
        }
    }
    let label = |phi: f64| {
        let d = phi - FRAC_PI_4;
        if d.abs() < 1e-12 {
            "φ = π/4".to_string()
        } else {
            format!("φ = π/4 {} {:.2}", if d > 0.0 { "+" } else { "−" }, d.abs())
        }
    };
    let mut p1 = Panel::new(
        "Relaxation time τ of the paper plate",
        Axis::log("pusher speed v_c (m/s)"),
        Axis::log("relaxation time τ (s)"),
    )
    .legend(Legend::UpperLeft);
    let mut p2 = Panel::new(
        "Relaxation length v_c τ",
        Axis::log("pusher speed v_c (m/s)"),
        Axis::log("relaxation length v_c τ (m)"),
    )
    .legend(Legend::UpperLeft);
    for (k, &phi) in SCHEDULE_PHIS.iter().enumerate() {
        p1 = p1.series(Series::new(label(phi), PALETTE[k], Stroke::Solid).points(tau_c[k].clone()));
        p2 = p2.series(Series::new(label(phi), PALETTE[k], Stroke::Solid).points(len_c[k].clone()));
    }
    let sq = &geoms[0];
    let l = sq.length;
    p2 = p2.series(
        Series::new(format!("L = |p_c − p_cm| = {l:.3} m"), DARK, Stroke::Dashed)
            .width(1)
            .points(vec![
                (grids.tau_v[0], l),
                (*grids.tau_v.last().unwrap_or(&2.0), l),
            ]),
    );
    w.file("tau.csv", csv.as_bytes())?;
    w.figure(
        "tau.svg",
        &Figure {
            size: (1500, 620),
            cols: 2,
            panels: vec![p1, p2],
            key: None,
        },
    )?;
    let slope = |c: &[(f64, f64)]| {
        let (a, b) = (c[0], c[1]);
        (b.1.ln() - a.1.ln()) / (b.0.ln() - a.0.ln())
    };
    let mut facts = Vec::new();
    for v in [0.2, 1.0] {
        let seg = segment(&sq.body, v, SCHEDULE_PHIS[0]);
        let (_, tau) = steady(&seg);
        facts.push(format!(
            "at v_c = {v} m/s τ = {tau:.3} s and v_c τ = {:.3} m ({:.2} L)",
            v * tau,
            v * tau / l
        ));
    }
    Ok(Entry {
        figure: "tau.svg".into(),
        data: vec!["tau.csv".into()],
        text: format!(
            "τ = −I_P/G'(ω*) and the relaxation length v_c τ (the push distance over which a \
             transient decays by 1/e) against v_c, for the five directions of the paper \
             schedule. At low speed τ ∝ v_c^{:.2} and v_c τ ∝ v_c^{:.2} (log–log slopes at the \
             slowest grid points, φ = π/4 + 0.3): the quasi-static limit is approached \
             quadratically in distance. For φ = π/4 + 0.3, {}.",
            slope(&tau_c[0]),
            slope(&len_c[0]),
            facts.join("; ")
        ),
    })
}

const CLASS_COLORS: [RGBColor; 5] = [
    RGBColor(199, 233, 192),
    RGBColor(255, 237, 160),
    RGBColor(253, 174, 97),
    RGBColor(215, 48, 39),
    RGBColor(120, 0, 30),
];

fn log_cell(x: f64, half: f64) -> (f64, f64) {
    (x * 10f64.powf(-half), x * 10f64.powf(half))
}

fn validity_figure(
    geoms: &[Geometry],
    grids: &Grids,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let sq = &geoms[0];
    let levels = [0.01, 0.05, 0.10];
    let mut csv = Csv::new(&[
        "froude",
        "phi",
        "speed",
        "psi",
        "omega_steady",
        "tau",
        "duration",
        "theta_dynamic",
        "theta_kinematic",
        "error",
    ]);
    let dphi = FRAC_PI_2 / grids.val_phi.len() as f64;
    let mut cells = Vec::new();
    let mut by_phi: Vec<Vec<(f64, f64)>> = vec![Vec::new(); grids.val_phi.len()];
    for (t, r) in tasks.iter().zip(rows) {
        if let Task::Validity { i, j } = *t {
            let (fr, phi) = (grids.fr[i], grids.val_phi[j]);
            let mut row = vec![num(fr), num(phi)];
            row.extend(r.iter().map(|v| num(*v)));
            csv.row(&row);
            let eps = r[7];
            let class = levels.iter().filter(|&&l| eps >= l).count();
            cells.push(Cell {
                x: log_cell(fr, grids.fr_step / 2.0),
                y: (phi - dphi / 2.0, phi + dphi / 2.0),
                color: CLASS_COLORS[class],
            });
            by_phi[j].push((fr, eps));
        }
    }
    let mut panel = Panel::new(
        format!(
            "Kinematic model's angle error over a {SEGMENT_LENGTH} L push from ω = 0 (paper plate)"
        ),
        Axis::log("Froude number Fr = v_c² / (μ̄ g L)"),
        Axis::lin("push direction φ (rad)").range(0.0, FRAC_PI_2),
    )
    .legend(Legend::UpperLeft);
    let fr_hi = *grids.fr.last().unwrap_or(&10.0);
    let (xlo, xhi) = (
        log_cell(grids.fr[0], grids.fr_step / 2.0).0,
        log_cell(fr_hi, grids.fr_step / 2.0).1,
    );
    panel.x.range = Some((xlo, xhi));
    panel.cells = cells;
    let line_colors = [BLUE_, PURPLE, DARK];
    let mut crossings = Vec::new();
    for (k, &lvl) in levels.iter().enumerate() {
        let pts: Vec<(f64, f64)> = by_phi
            .iter()
            .zip(&grids.val_phi)
            .filter_map(|(c, &phi)| first_crossing(c, lvl).map(|x| (x, phi)))
            .collect();
        crossings.push(pts.clone());
        panel = panel.series(
            Series::new(
                format!("ε = {:.0} %", lvl * 100.0),
                line_colors[k],
                Stroke::Solid,
            )
            .width(3)
            .points(pts),
        );
    }
    panel = panel.series(
        Series::new("φ = π/4 (ψ = 0)", DARK, Stroke::Dashed)
            .width(1)
            .points(vec![(xlo, FRAC_PI_4), (xhi, FRAC_PI_4)]),
    );
    w.file("validity.csv", csv.as_bytes())?;
    w.figure(
        "validity.svg",
        &Figure {
            size: (1250, 750),
            cols: 1,
            panels: vec![panel],
            key: Some(Key {
                title: "error ε".into(),
                entries: vec![
                    ("ε < 1 %".into(), CLASS_COLORS[0]),
                    ("1 % ≤ ε < 5 %".into(), CLASS_COLORS[1]),
                    ("5 % ≤ ε < 10 %".into(), CLASS_COLORS[2]),
                    ("ε ≥ 10 %".into(), CLASS_COLORS[3]),
                ],
            }),
        },
    )?;
    let mut lines = Vec::new();
    for (k, &lvl) in levels.iter().enumerate() {
        let pts = &crossings[k];
        let worst = pts.iter().copied().min_by(|a, b| a.0.total_cmp(&b.0));
        let best = pts.iter().copied().max_by(|a, b| a.0.total_cmp(&b.0));
        match (worst, best) {
            (Some(wst), Some(bst)) => lines.push(format!(
                "| {:.0} % | {:.3} (v_c = {:.2} m/s, φ = {:.2}) | {:.3} (φ = {:.2}) | {}/{} |",
                lvl * 100.0,
                wst.0,
                sq.speed(wst.0),
                wst.1,
                bst.0,
                bst.1,
                pts.len(),
                grids.val_phi.len()
            )),
            _ => lines.push(format!("| {:.0} % | not reached | – | 0 |", lvl * 100.0)),
        }
    }
    Ok(Entry {
        figure: "validity.svg".into(),
        data: vec!["validity.csv".into()],
        text: format!(
            "Where the kinematic model is good enough, over (Fr, φ) for the paper plate. Error \
             definition: the object moves straight with the pusher (ω = 0) when a push of length \
             d = {SEGMENT_LENGTH} L = {:.2} m starts (duration d/v_c); ε = |Δθ_dynamic − \
             Δθ_kinematic| / |Δθ_kinematic| is the relative error of the angle the kinematic model \
             says the object turns over it (Δθ_dynamic by RK4 on the scalar ODE, steps τ/40). It \
             combines the steady mismatch (κ − 1) and the transient lag (≈ τ/duration ∝ Fr). \
             Colours: the classes; lines: the smallest Fr at which ε reaches 1 %, 5 %, 10 % for \
             each φ. Boundary Fr:\n\n\
             | ε | smallest Fr over φ (worst direction) | largest Fr over φ | directions that reach it |\n\
             |---|---|---|---|\n{}",
            SEGMENT_LENGTH * sq.length,
            lines.join("\n")
        ),
    })
}

fn assumptions_figure(
    geoms: &[Geometry],
    grids: &Grids,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let bounds = [0.2, 0.5, CONTACT_MU];
    let mut csv = Csv::new(&[
        "contact",
        "speed",
        "phi",
        "froude",
        "omega_steady",
        "cone_angle_max",
        "mu_required",
        "force_max",
    ]);
    let names = ["corner", "edge_middle"];
    let dv = 2.0 / grids.as_v.len() as f64;
    let mut panels = Vec::new();
    let mut texts = Vec::new();
    for k in 0..2 {
        let g = assume_geometry(geoms, k);
        let dphi = PI / grids.as_phi[k].len() as f64;
        let mut cells = Vec::new();
        let mut counts = [0usize; 5];
        let mut pulling: Vec<f64> = Vec::new();
        // Directions that do not slip at the slowest and at the fastest speed.
        let mut hold_slow: Vec<f64> = Vec::new();
        let mut hold_fast: Vec<f64> = Vec::new();
        for (t, r) in tasks.iter().zip(rows) {
            let Task::Assume { k: kk, i, j } = *t else {
                continue;
            };
            if kk != k {
                continue;
            }
            let (v, phi) = (grids.as_v[i], grids.as_phi[k][j]);
            csv.row(&[
                names[k].to_string(),
                num(v),
                num(phi),
                num(g.froude(v)),
                num(r[0]),
                num(r[1]),
                num(r[2]),
                num(r[3]),
            ]);
            let class = if r[1] > FRAC_PI_2 {
                4
            } else {
                bounds.iter().filter(|&&b| r[2] > b).count()
            };
            counts[class] += 1;
            if class == 4 {
                pulling.push(phi);
            }
            if class < 3 && i == 0 {
                hold_slow.push(phi);
            }
            if class < 3 && i + 1 == grids.as_v.len() {
                hold_fast.push(phi);
            }
            cells.push(Cell {
                x: (v - dv / 2.0, v + dv / 2.0),
                y: (phi - dphi / 2.0, phi + dphi / 2.0),
                color: CLASS_COLORS[class],
            });
        }
        let lo = ASSUME_PHI_LO[k];
        let title = if k == 0 {
            "Pushed at the corner (−0.125, −0.125) m"
        } else {
            "Pushed at the middle of the bottom edge (0, −0.125) m"
        };
        let mut panel = Panel::new(
            title,
            Axis::lin("pusher speed v_c (m/s)").range(0.0, 2.0),
            Axis::lin("push direction φ (rad)").range(lo, lo + PI),
        )
        .legend(Legend::LowerRight);
        panel.cells = cells;
        if k == 0 {
            for (n, &phi) in SCHEDULE_PHIS.iter().enumerate() {
                let label = if n == 0 { "paper schedule φ" } else { "" };
                panel = panel.series(
                    Series::new(label, DARK, Stroke::Dashed)
                        .width(1)
                        .points(vec![(0.0, phi), (2.0, phi)]),
                );
            }
        }
        panels.push(panel);
        let total: usize = counts.iter().sum();
        let pct = |c: usize| 100.0 * c as f64 / total.max(1) as f64;
        let range = |v: &[f64]| match (v.first(), v.last()) {
            (Some(a), Some(b)) => format!("{a:.2} to {b:.2} rad"),
            _ => "none".to_string(),
        };
        texts.push(format!(
            "{} contact: {:.0} % of the cells need μ ≤ 0.2, {:.0} % 0.2–0.5, {:.0} % 0.5–0.8, \
             {:.0} % slip at μ_c = {CONTACT_MU}, {:.0} % pull (pulling directions: {}); the \
             contact holds at μ_c = {CONTACT_MU} for φ in {} at {} m/s and in {} at {} m/s (cell \
             centres)",
            if k == 0 { "Corner" } else { "Edge-middle" },
            pct(counts[0]),
            pct(counts[1]),
            pct(counts[2]),
            pct(counts[3]),
            pct(counts[4]),
            range(&pulling),
            range(&hold_slow),
            grids.as_v[0],
            range(&hold_fast),
            grids.as_v[grids.as_v.len() - 1],
        ));
    }
    w.file("assumptions.csv", csv.as_bytes())?;
    w.figure(
        "assumptions.svg",
        &Figure {
            size: (1700, 720),
            cols: 2,
            panels,
            key: Some(Key {
                title: "needed contact μ".into(),
                entries: vec![
                    ("μ_req ≤ 0.2".into(), CLASS_COLORS[0]),
                    ("0.2 < μ_req ≤ 0.5".into(), CLASS_COLORS[1]),
                    ("0.5 < μ_req ≤ 0.8".into(), CLASS_COLORS[2]),
                    ("μ_req > 0.8: slips".into(), CLASS_COLORS[3]),
                    ("pusher would pull".into(), CLASS_COLORS[4]),
                ],
            }),
        },
    )?;
    let sq = &geoms[0];
    let sched: Vec<String> = SCHEDULE_PHIS
        .iter()
        .map(|&phi| format!("{:.2}", assume_cell(sq, phi, 1.0)[2]))
        .collect();
    Ok(Entry {
        figure: "assumptions.svg".into(),
        data: vec!["assumptions.csv".into()],
        text: format!(
            "Where the model's contact assumptions fail, over (v_c, φ) for the paper plate pushed \
             at its corner (left, the paper's contact) and at the middle of an edge (right). For \
             each cell the dynamic model's pusher force f_c(ω) is evaluated along the segment's \
             transient from ω = 0 to ω* ({FORCE_SAMPLES} steps; ω relaxes monotonically and f_c \
             depends on ω alone); α is its largest angle from the cone of inward normals at the \
             contact (at a corner, the quadrant between the two edges' normals), μ_req = tan α \
             the contact friction needed not to slip, and α > 90° means the pusher would have to \
             pull. {}. Along the paper schedule at 1 m/s the corner needs μ_req = {}: the paper's \
             inputs never slip or pull.",
            texts.join(". "),
            sched.join(", ")
        ),
    })
}
