//! The physics of one sweep cell: the parameter grids behind the maps and
//! the scaling curves of `pushval report`, and what each cell computes.
//!
//! Every sweep cell is one [`Task`]; the list of tasks is fixed by the grid
//! (`--quick` or full), so a part of it can be computed anywhere and merged
//! (see [`crate::shard`]). Each cell is evaluated from the dynamic model's
//! steady-state analysis ([`SegmentDynamics`]) and, for the validity map, a
//! fixed-step RK4 integration of the scalar ODE `I_P ω̇ = G(ω)`. The figures
//! built from the cells are in [`super::figures`].
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

use pushval_model::{Body, ContactLimits, Push, SegmentDynamics};
use pushval_scenario::Scenario;

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

/// The segment dynamics of one push of the body (duration irrelevant: 1 s).
pub fn segment(body: &Body, speed: f64, phi: f64) -> SegmentDynamics {
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
pub const FORCE_SAMPLES: usize = 64;

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
    crate::parallel::par_rows(&tasks[range], progress, "sweeps", |t| {
        eval(geoms, &grids, t)
    })
}
