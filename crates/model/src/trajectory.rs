//! Sampled trajectories, the per-run assumption report, and the three analytic
//! models as [`Simulator`]s.
//!
//! The dynamic model's run is split by stage: `dynamic_model` walks the
//! segments (switch, analysis of ω̇, closed forms), `adaptive` and `rk4`
//! integrate a segment where there is no closed form, `checker` accumulates
//! the assumption checks and `sampling` hands out the sample times;
//! `final_state` asks the same run for its end state alone, or for samples
//! at the caller's times.

mod adaptive;
mod checker;
mod dynamic_model;
mod final_state;
mod push_cache;
mod rk4;
mod sampling;
mod segment;

pub use dynamic_model::{DynamicModel, Integrator};
pub use final_state::FinalState;
pub use push_cache::PushCache;

use crate::tail::Tail;
use crate::{kinematic, limit_surface, rotate, Body, ModelError, Problem, Push, Simulator};
use sampling::{sample_tail, Sampler};

/// One output sample. At a switch time, the state just after the switch.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// World x of the centre of mass (m).
    pub x: f64,
    /// World y of the centre of mass (m).
    pub y: f64,
    /// Object angle, unwrapped (rad).
    pub theta: f64,
    /// Angular velocity (rad/s).
    pub omega: f64,
}

/// What a model did over one push segment.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SegmentReport {
    /// Segment index (0 for the first push).
    pub index: usize,
    /// Start time (s).
    pub t_start: f64,
    /// End time (s).
    pub t_end: f64,
    /// ω just after the switch into this segment (rad/s).
    pub omega_start: f64,
    /// ω at the segment's end (rad/s).
    pub omega_end: f64,
    /// Time (s) from which the pose followed the closed-form steady arc, if it did.
    pub settled_at: Option<f64>,
}

/// Where one of the model's assumptions failed: first time, and the worst value seen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// First time it was seen (s).
    pub first_t: f64,
    /// Time of the worst value (s).
    pub worst_t: f64,
    /// The worst value (its meaning depends on the check; see [`Assumptions`]).
    pub worst: f64,
    /// Segment index of the first occurrence.
    pub segment: usize,
    /// Support index, for sticking supports.
    pub support: Option<usize>,
}

impl Violation {
    fn record(
        slot: &mut Option<Violation>,
        t: f64,
        value: f64,
        segment: usize,
        support: Option<usize>,
        worse: impl Fn(f64, f64) -> bool,
    ) {
        match slot {
            None => {
                *slot = Some(Violation {
                    first_t: t,
                    worst_t: t,
                    worst: value,
                    segment,
                    support,
                })
            }
            Some(v) => {
                if worse(value, v.worst) {
                    v.worst = value;
                    v.worst_t = t;
                    if support.is_some() {
                        v.support = support;
                    }
                }
            }
        }
    }
}

/// The checks of the model's assumptions over one run. Every field that is
/// `Some` is a failure that outputs must report.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Assumptions {
    /// The pusher would have to pull: the pusher force points more than 90°
    /// away from every inward normal at the contact. `worst`: that angle (rad).
    pub pulling: Option<Violation>,
    /// The pusher force leaves the contact friction cone (`[contact] mu`):
    /// `worst`: the angle (rad) between the force and the normal cone.
    pub contact_slip: Option<Violation>,
    /// The pusher force exceeds `max_force`. `worst`: the force (N).
    pub force_limit: Option<Violation>,
    /// A support stops sliding (|u_i| below 1e-6 of the pusher speed scale):
    /// friction there is set-valued and the model's law does not hold.
    /// `worst`: the smallest |u_i| (m/s).
    pub sticking: Option<Violation>,
    /// A switch needs the pusher to deliver a pulling impulse. `worst`: angle (rad).
    pub pulling_impulse: Option<Violation>,
    /// ω ran away (no stable steady state attracts it). `worst`: |ω| (rad/s).
    pub runaway: Option<Violation>,
    /// Largest pusher force magnitude seen at the samples (N).
    pub max_force: f64,
    /// Largest angle between the pusher force and the inward normal cone (rad).
    pub max_cone_angle: f64,
    /// Smallest support sliding speed seen (m/s).
    pub min_support_speed: f64,
}

impl Assumptions {
    /// True when no check failed.
    pub fn all_hold(&self) -> bool {
        self.pulling.is_none()
            && self.contact_slip.is_none()
            && self.force_limit.is_none()
            && self.sticking.is_none()
            && self.pulling_impulse.is_none()
            && self.runaway.is_none()
    }
}

/// Integrator work over one run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SolverStats {
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps.
    pub rejected: usize,
}

/// A sampled run of one model.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trajectory {
    /// Model name.
    pub model: String,
    /// Samples at [`Problem::sample_times`].
    pub samples: Vec<Sample>,
    /// One report per push segment.
    pub segments: Vec<SegmentReport>,
    /// Assumption checks (the analytic models fill these; engines may not).
    pub assumptions: Assumptions,
    /// Integrator work.
    pub stats: SolverStats,
    /// The free slide after the release (None: the problem has no release,
    /// or the model does not report one).
    pub slide: Option<crate::SlideReport>,
}

/// Runs a model whose ω is constant over each segment: the pose follows
/// closed-form arcs, nothing is integrated.
fn constant_omega_run(
    problem: &Problem,
    name: &str,
    omega_of: impl Fn(&Body, &Push) -> f64,
) -> Result<Trajectory, ModelError> {
    problem.check()?;
    if problem.release.is_some() {
        return Err(ModelError::NoSlide { model: name.into() });
    }
    let pc = problem.body.contact();
    let mut sampler = Sampler::new(problem);
    let mut out = Trajectory {
        model: name.into(),
        samples: Vec::with_capacity(sampler.times.len()),
        ..Default::default()
    };
    let mut theta = problem.initial.theta;
    let mut c = problem.initial.position + rotate(theta, &pc);
    let n_seg = problem.pushes.len();
    for (j, (push, (t0, t1))) in problem
        .pushes
        .iter()
        .zip(problem.segment_times())
        .enumerate()
    {
        let last = j + 1 == n_seg;
        let w = omega_of(&problem.body, push);
        let vel = push.velocity();
        let arc = Tail::arc(t0, c, theta, w, vel);
        let p = sample_tail(arc, &mut sampler, t1, last, pc, &mut out.samples);
        (c, theta) = (p.c, p.theta);
        out.segments.push(SegmentReport {
            index: j,
            t_start: t0,
            t_end: t1,
            omega_start: w,
            omega_end: w,
            settled_at: Some(t0),
        });
    }
    Ok(out)
}

/// Kurisu & Yoshikawa's kinematic model as a [`Simulator`] (name `"kinematic"`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct KinematicModel;

impl Simulator for KinematicModel {
    fn name(&self) -> String {
        "kinematic".into()
    }
    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        constant_omega_run(problem, "kinematic", |b, p| {
            kinematic::omega(b, p).unwrap_or(0.0)
        })
    }
}

/// The ellipsoidal limit-surface model as a [`Simulator`] (name `"limit_surface"`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LimitSurfaceModel;

impl Simulator for LimitSurfaceModel {
    fn name(&self) -> String {
        "limit_surface".into()
    }
    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        constant_omega_run(problem, "limit_surface", limit_surface::omega)
    }
}
