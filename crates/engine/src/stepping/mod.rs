//! The one stepping loop of the plate engines (rapier3d, Jolt, PhysX, …).
//!
//! An engine that puts the object on supports in a 3-D scene and drives it
//! with a kinematic pusher builds its world, settles it and sets the start
//! velocity itself; then [`Stepping`] runs the pushes the caller applies,
//! one [`advance`](Stepping::advance) at a time, through the small
//! [`PlateWorld`] trait and gathers what every such engine reports:
//!
//! * **Schedule.** Each segment of duration `T` is cut into
//!   `n = ceil(T / dt)` equal steps of `h = T / n` (a relative `1e-12` off
//!   the quotient, so that a whole number of steps is not rounded up); the
//!   last step of a segment ends exactly at the segment's end time
//!   ([`StepClock`] says how the others' end times are computed).
//! * **Pusher.** Before every step the pusher is re-pinned on the object's
//!   contact point and moves at the commanded contact velocity `v_c R(ψ)
//!   n_φ`, ψ the heading [`PlateWorld::heading`] gives (by default the yaw at
//!   mid-step, `θ + ω h/2`).
//! * **Checks.** After every step the state must be finite
//!   ([`PlateWorld::finite`];
//!   [`ModelError::NonFinite`](pushval_model::ModelError::NonFinite)
//!   otherwise).
//! * **Records.** Every step is one [`PlateStep`] (pose at its end, ω over
//!   it, height and tilt), after an initial record at t = 0.
//! * **Tails.** Per segment, over its last fifth of steps ([`TAIL`],
//!   [`TailSteps`]): the means ([`TailWeight`]: time-weighted by default) of
//!   ω, of ω² (its spread), of each support's normal load and friction
//!   force, and each support's smallest slip speed. Over the run's last fifth
//!   (the steps whose middle is past it), each support's time-weighted mean
//!   load.
//! * **Extremes.** The largest tilt, the largest vertical displacement of the
//!   centre of mass from the height it is given, the largest pusher drift
//!   (after the first step), and each support's smallest load.
//!
//! The arithmetic is written once here, in a fixed order, so that every
//! engine using it gets the same numbers it got from its own copy of the loop.

mod pushes;
mod session;
mod slide;
#[cfg(test)]
mod tests;
mod world;

use pushval_model::{Problem, Push, SolverStats, Trajectory};

use crate::contact::ContactRecord;
use crate::resample::{resample, StepRecord};

pub use pushes::Stepping;
pub use session::{PlateFinish, PlateSession};
pub use world::PlateWorld;

/// Fraction of a segment's steps (and of the run), at its end, over which
/// the tail means are taken.
pub const TAIL: f64 = 0.2;

/// The object's pose and velocity as the loop needs them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Plate {
    /// World x of the centre of mass (m).
    pub x: f64,
    /// World y of the centre of mass (m).
    pub y: f64,
    /// World z (up) of the centre of mass (m).
    pub z: f64,
    /// Yaw, unwrapped (rad).
    pub theta: f64,
    /// Vertical angular velocity (rad/s).
    pub omega: f64,
    /// Tilt of the body's vertical axis from the world's (rad).
    pub tilt: f64,
}

/// One engine step: time, pose at its end, the angular velocity held over it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlateStep {
    /// Push segment of the step.
    pub segment: usize,
    /// Start time (s); equal to `t1` for the initial record.
    pub t0: f64,
    /// End time (s).
    pub t1: f64,
    /// World x of the centre of mass at `t1` (m).
    pub x: f64,
    /// World y of the centre of mass at `t1` (m).
    pub y: f64,
    /// World z (up) of the centre of mass at `t1` (m).
    pub z: f64,
    /// Yaw at `t1`, unwrapped (rad).
    pub theta: f64,
    /// Vertical angular velocity over the step (rad/s).
    pub omega: f64,
    /// Tilt of the body's vertical axis from the vertical at `t1` (rad).
    pub tilt: f64,
}

impl PlateStep {
    fn new(segment: usize, t0: f64, t1: f64, p: &Plate) -> Self {
        Self {
            segment,
            t0,
            t1,
            x: p.x,
            y: p.y,
            z: p.z,
            theta: p.theta,
            omega: p.omega,
            tilt: p.tilt,
        }
    }

    /// The resampler's view of the step.
    pub fn record(&self) -> StepRecord {
        StepRecord {
            segment: self.segment,
            t0: self.t0,
            t1: self.t1,
            x: self.x,
            y: self.y,
            theta: self.theta,
            omega: self.omega,
        }
    }
}

/// Each support's forces over the last step (N), in support order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SupportForces {
    /// Normal force of each support.
    pub normal: Vec<f64>,
    /// Friction force magnitude of each support, where the engine gives it.
    pub friction: Option<Vec<f64>>,
}

/// Which steps of a segment of `n` steps make its tail.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TailSteps {
    /// The steps from index `floor((1 − TAIL) n)` on.
    #[default]
    Floor,
    /// The last `max(n / 5, 1)` steps (integer division).
    LastFifth,
    /// The steps whose middle `(t0 + t1) / 2` is in the segment's last
    /// fifth of time (possibly none: the tail means are then zero).
    ByTime,
}

/// How the steps of a tail are weighted in its means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TailWeight {
    /// By their length (time-weighted means).
    #[default]
    Time,
    /// Equally (means over the steps).
    Steps,
}

/// How the end time of a step (not the last of its segment, which ends at
/// the segment's end) is computed, and with it the run-tail test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StepClock {
    /// `t1 = t0 + h`, `t0 = t_seg + k h`; a step is in the run tail when its
    /// middle `(t0 + t1) / 2` is.
    #[default]
    FromStepStart,
    /// `t1 = t_seg + (k + 1) h`; a step is in the run tail when `t1 − h/2` is.
    FromSegmentStart,
}

/// How [`Stepping`] runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepLoop {
    /// Largest time step (s).
    pub dt: f64,
    /// Number of supports (length of the per-support vectors).
    pub supports: usize,
    /// Height of the centre of mass the lift is measured from (m).
    pub z_rest: f64,
    /// Take the smallest loads over every step; otherwise only over the
    /// steps of the segment tails and the run tail. (The forces themselves
    /// are read on every step, for the per-sample loads.)
    pub forces_every_step: bool,
    /// Which steps make a segment's tail.
    pub tail: TailSteps,
    /// How tail steps are weighted.
    pub tail_weight: TailWeight,
    /// How step end times are computed.
    pub clock: StepClock,
}

impl StepLoop {
    /// Steps of at most `dt` (s) for `supports` supports, the lift measured
    /// from `z_rest` (m); forces read on every step; the default tail and
    /// clock.
    pub fn new(dt: f64, supports: usize, z_rest: f64) -> Self {
        Self {
            dt,
            supports,
            z_rest,
            forces_every_step: true,
            tail: TailSteps::Floor,
            tail_weight: TailWeight::Time,
            clock: StepClock::FromStepStart,
        }
    }
}

/// What [`Stepping`] gathered.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Stepped {
    /// Every step of the push, after an initial record at t = 0.
    pub history: Vec<PlateStep>,
    /// Engine steps taken.
    pub steps: usize,
    /// Largest tilt (rad) over the push.
    pub max_tilt: f64,
    /// Largest `|z − z_rest|` (m) over the push.
    pub max_lift: f64,
    /// Largest pusher drift (m) before a step, the first step excluded.
    pub max_joint_drift: f64,
    /// Smallest normal force (N) of each support over the steps its forces
    /// were read on (infinite where never read).
    pub min_loads: Vec<f64>,
    /// Per segment, the time-weighted mean ω (rad/s) over its tail.
    pub segment_tail_omega: Vec<f64>,
    /// Per segment, the time-weighted standard deviation of ω over its tail.
    pub segment_tail_omega_std: Vec<f64>,
    /// Per segment, each support's time-weighted mean normal force (N) over
    /// its tail.
    pub segment_tail_loads: Vec<Vec<f64>>,
    /// Per segment, each support's time-weighted mean friction force
    /// magnitude (N) over its tail (zero where the engine gives none).
    pub segment_tail_friction: Vec<Vec<f64>>,
    /// Per segment, each support's smallest slip speed (m/s) over its tail
    /// (infinite where the engine gives none).
    pub segment_tail_min_slip: Vec<Vec<f64>>,
    /// Each support's time-weighted mean normal force over the run's last
    /// fifth (N); NaN without pushes.
    pub loads: Vec<f64>,
    /// The loads at every sample, the largest rise above `z_rest` and the
    /// share of steps with a support out of contact (None where the world
    /// reports no support forces).
    pub contact: Option<ContactRecord>,
}

impl Stepped {
    /// The resampler's view of the history.
    pub fn records(&self) -> Vec<StepRecord> {
        self.history.iter().map(PlateStep::record).collect()
    }

    /// The trajectory at the problem's sample times (unnamed; steps as
    /// solver statistics).
    pub fn trajectory(&self, problem: &Problem) -> Trajectory {
        let (samples, segments) = resample(problem, &self.records());
        Trajectory {
            model: String::new(),
            samples,
            segments,
            stats: SolverStats {
                rhs_evals: self.steps,
                steps: self.steps,
                rejected: 0,
            },
            ..Default::default()
        }
    }
}

/// A segment's steps as a world lays them out ([`PlateWorld::segment_steps`]).
#[derive(Debug, Clone, PartialEq)]
pub enum StepLayout {
    /// Step lengths (s): each step starts where the last ended (the first
    /// at the segment's start) and ends its length later, the last one
    /// exactly at the segment's end.
    Lengths(Vec<f64>),
    /// Each step's start and end times (s), verbatim (an engine whose clock
    /// keeps its own time, e.g. in whole nanoseconds).
    Spans(Vec<(f64, f64)>),
}

/// One step as the loop plans it, handed to [`PlateWorld::drive_step`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepPlan {
    /// Index of the push segment (in the order the pushes were applied).
    pub segment: usize,
    /// Index of the step in its segment.
    pub index: usize,
    /// Number of steps of the segment.
    pub steps: usize,
    /// Start time (s).
    pub t0: f64,
    /// End time (s).
    pub t1: f64,
    /// The step length passed to [`PlateWorld::step`] (s): the segment's
    /// nominal step `duration / n` for equal steps, `t1 − t0` for the steps
    /// of [`PlateWorld::segment_steps`].
    pub h: f64,
    /// The segment's nominal step `duration / n` (s), `n = ceil(duration / dt)`.
    pub nominal_h: f64,
    /// The push of the segment.
    pub push: Push,
}
