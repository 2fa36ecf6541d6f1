//! The steady-state analysis of a scenario's push segments: the roots of ω̇
//! per segment, the one the dynamic model settles on, and the steady ω read
//! off a trajectory's tail.

use pushval_engine::rel_err;
use pushval_model::{
    kinematic, limit_surface, InertialTerm, Problem, RootKind, SegmentDynamics, SteadyState,
    Trajectory,
};
use pushval_scenario::Scenario;

/// The steady-state analysis of one push segment.
#[derive(Debug, Clone)]
pub struct SegmentInfo {
    pub index: usize,
    pub t_start: f64,
    pub t_end: f64,
    pub speed: f64,
    pub phi: f64,
    pub froude: f64,
    /// `v_c ψ(φ)` (rad/s), None where ψ does not exist.
    pub omega_kinematic: Option<f64>,
    /// The ellipsoidal limit surface's ω (rad/s).
    pub omega_limit_surface: f64,
    /// κ = ω*/ω_kinematic (the steady state reached over the kinematic ω);
    /// None where either is missing or ω_kinematic = 0 (|ω_kinematic| L ≤
    /// 1e-12 v_c, rounding).
    pub kappa: Option<f64>,
    /// dκ/dFr as Fr → 0, in closed form (`pushval_model::kappa`); None where
    /// ω_kinematic = 0 or the kinematic root is a pivot.
    pub kappa_slope: Option<f64>,
    /// All roots of ω̇, sorted, with their stability.
    pub steady_states: Vec<SteadyState>,
    /// The steady state the dynamic run converges to in this segment (None: runaway).
    pub omega_steady: Option<SteadyState>,
    /// ω at the start of the segment, just after the switch (rad/s).
    pub omega_start: f64,
    /// Relative distance of the dynamic model's tail-mean ω (last 20 % of the
    /// segment) from ω*, with the floor of [`rel_err`]; None without a root.
    pub tail_deviation: Option<f64>,
}

impl SegmentInfo {
    /// Relaxation time τ (s) of the steady state reached, if smooth and stable.
    pub fn tau(&self) -> Option<f64> {
        self.omega_steady.and_then(|s| s.tau)
    }
    /// Whether a steady ω can be read off the segment's tail: a smooth stable
    /// root, and the dynamic model's tail mean within 1e-6 (relative) of it.
    pub fn settles(&self) -> bool {
        matches!(
            self.omega_steady,
            Some(SteadyState {
                kind: RootKind::Stable,
                tau: Some(_),
                ..
            })
        ) && self.tail_deviation.is_some_and(|d| d <= SETTLED_REL)
    }
}

/// Largest relative deviation of the dynamic model's tail-mean ω from ω* for
/// a segment to count as settled (100 times below the tightest engine target).
pub const SETTLED_REL: f64 = 1e-6;

/// Steady ω per segment read off a trajectory: the mean ω over the last 20 %
/// of the segment (samples strictly before its end).
pub fn tail_omega(tr: &Trajectory, t_start: f64, t_end: f64) -> Option<f64> {
    let from = t_end - 0.2 * (t_end - t_start);
    let eps = 1e-9 * (t_end - t_start);
    let w: Vec<f64> = tr
        .samples
        .iter()
        .filter(|s| s.t >= from - eps && s.t < t_end - eps)
        .map(|s| s.omega)
        .collect();
    (!w.is_empty()).then(|| w.iter().sum::<f64>() / w.len() as f64)
}

/// The steady-state analysis of every segment, following ω across switches.
pub fn analyse_segments(
    sc: &Scenario,
    problem: &Problem,
    dynamic: &Trajectory,
) -> Vec<SegmentInfo> {
    analyse_segments_with(sc, problem, dynamic, InertialTerm::Derived)
}

/// [`analyse_segments`] for a chosen reading of the inertial term.
pub fn analyse_segments_with(
    sc: &Scenario,
    problem: &Problem,
    dynamic: &Trajectory,
    term: InertialTerm,
) -> Vec<SegmentInfo> {
    problem
        .pushes
        .iter()
        .zip(problem.segment_times())
        .enumerate()
        .map(|(j, (push, (t0, t1)))| {
            let seg = SegmentDynamics::with_inertial_term(&problem.body, push, term);
            let roots = if push.speed > 0.0 {
                seg.steady_states()
            } else {
                vec![]
            };
            let omega_start = dynamic.segments.get(j).map_or(0.0, |s| s.omega_start);
            let omega_steady = if push.speed > 0.0 {
                seg.attractor(&roots, omega_start)
            } else {
                None
            };
            let tail_deviation = omega_steady.and_then(|r| {
                tail_omega(dynamic, t0, t1)
                    .map(|w| rel_err(w, r.omega, push.speed, sc.froude_length()))
            });
            let omega_kinematic = kinematic::omega(&problem.body, push);
            // ω_kinematic = 0 within rounding (a push through the centre of
            // friction): κ is undefined there.
            let has_kinematic =
                omega_kinematic.is_some_and(|w| w.abs() * sc.froude_length() > 1e-12 * push.speed);
            let kappa = match (omega_steady, omega_kinematic) {
                (Some(s), Some(k)) if has_kinematic => Some(s.omega / k),
                _ => None,
            };
            let kappa_slope = has_kinematic
                .then(|| pushval_model::kappa_series(&problem.body, push.phi).map(|k| k.kappa1))
                .flatten();
            SegmentInfo {
                index: j,
                t_start: t0,
                t_end: t1,
                speed: push.speed,
                phi: push.phi,
                froude: sc.froude(push.speed),
                omega_kinematic,
                kappa,
                kappa_slope,
                omega_limit_surface: limit_surface::omega(&problem.body, push),
                omega_steady,
                steady_states: roots,
                omega_start,
                tail_deviation,
            }
        })
        .collect()
}
