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
//!   ([`PlateWorld::finite`]; [`ModelError::NonFinite`] otherwise).
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

use std::time::Instant;

use pushval_model::{ModelError, Problem, Push, Sample, SlideReport, SolverStats, Trajectory};

use crate::contact::{ContactRecord, LoadRecorder};
use crate::resample::{resample, StepRecord};

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

/// What an engine's scene does for the loop: drive the pusher, step, read
/// the object and, where it can, the supports' forces and slip.
pub trait PlateWorld {
    /// The engine's reading of the object (pose, velocities, …).
    type State;

    /// The loop's view of a state.
    fn plate(&self, state: &Self::State) -> Plate;

    /// The heading (rad) at which the pusher velocity is set for a step of
    /// length `h` from `state`: by default the yaw at mid-step, `θ + ω h/2`.
    fn heading(&self, state: &Self::State, h: f64) -> f64 {
        let p = self.plate(state);
        p.theta + 0.5 * h * p.omega
    }

    /// The steps of a segment of `push`, where the world lays them out
    /// itself; `n` steps of `h = duration / n` otherwise (None, the
    /// default). The layout depends on the push alone: nothing tells the
    /// world what follows it.
    fn segment_steps(&mut self, _push: &Push, _n: usize, _h: f64) -> Option<StepLayout> {
        None
    }

    /// Drives the pusher for the step `plan` from `state`: by default the
    /// commanded contact velocity `v_c R(ψ) n_φ` at the heading ψ of
    /// [`PlateWorld::heading`], through [`PlateWorld::drive`]. Returns the
    /// pusher's drift (m) as `drive` does.
    fn drive_step(&mut self, state: &Self::State, plan: &StepPlan) -> f64 {
        let vc = plan.push.velocity();
        let (sn, cs) = self.heading(state, plan.h).sin_cos();
        let vel = [cs * vc.x - sn * vc.y, sn * vc.x + cs * vc.y];
        self.drive(state, vel, plan.h)
    }

    /// Re-pins the pusher on the object's contact point and gives it the
    /// world velocity `velocity` (m/s) for a step of length `h`; returns how
    /// far (m, horizontal) it was from the contact point before.
    fn drive(&mut self, state: &Self::State, velocity: [f64; 2], h: f64) -> f64;

    /// One engine step of length `h` (s) ending at time `t1`.
    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError>;

    /// The object after a step; `prev` is the reading before it (to unwrap
    /// the yaw).
    fn state(&mut self, prev: &Self::State) -> Self::State;

    /// Each support's forces over the last step of length `h`, or None where
    /// the engine reads none.
    fn support_forces(
        &mut self,
        state: &Self::State,
        h: f64,
    ) -> Result<Option<SupportForces>, ModelError>;

    /// Whether a state is usable: by default its position and ω are finite.
    fn finite(&self, state: &Self::State) -> bool {
        let p = self.plate(state);
        p.x.is_finite() && p.y.is_finite() && p.z.is_finite() && p.omega.is_finite()
    }

    /// Called after every step once the state is checked, for what the
    /// engine records itself. Nothing by default.
    fn after_step(&mut self, _state: &Self::State) {}

    /// Horizontal slip speed (m/s) of support `i` after the step, where the
    /// engine gives it (read in the segment tails only). None by default.
    fn slip(&self, _state: &Self::State, _i: usize) -> Option<f64> {
        None
    }

    /// Called on every tail step of a segment (after the loop's own tail
    /// sums), for what the engine gathers itself. Nothing by default.
    fn tail_step(&mut self, _state: &Self::State, _h: f64) -> Result<(), ModelError> {
        Ok(())
    }

    /// Called at the end of every segment (time `t`, s) with the total
    /// weight of its tail (its length in s, or its number of steps with
    /// [`TailWeight::Steps`]). Nothing by default.
    fn end_segment(&mut self, _tail_weight: f64, _t: f64) -> Result<(), ModelError> {
        Ok(())
    }

    /// The world velocity (m/s) of the centre of mass in `state`, where the
    /// engine gives it; None (the default) leaves the session to report the
    /// one a rigid contact moving with the last push gives.
    fn cm_velocity(&self, _state: &Self::State) -> Option<[f64; 2]> {
        None
    }

    /// Lets go of the plate ([`Stepping::release`]): the pusher's
    /// constraint goes (the pusher withdraws without an impulse). `throw`,
    /// given when no push was applied, is the velocity to start the slide
    /// with: the centre of mass's (m/s, world) and ω (rad/s). By default the
    /// world cannot release ([`crate::no_release`]).
    fn release(
        &mut self,
        _state: &Self::State,
        _throw: Option<([f64; 2], f64)>,
    ) -> Result<(), ModelError> {
        Err(crate::no_release(
            "its world cannot remove the pusher's constraint",
        ))
    }

    /// Before every step of the slide (the pusher gone) from `state`, of
    /// length `h` (s): what the world applies itself (its supports'
    /// friction where the engine's own contacts do not). Nothing by
    /// default.
    fn slide_step(&mut self, _state: &Self::State, _h: f64) {}
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
    /// fifth (N).
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

/// What the run tails need of one step, kept until [`Stepping::finish`]
/// (the run's last fifth depends on the pushes still to come).
#[derive(Debug, Clone)]
struct StepLog {
    t0: f64,
    t1: f64,
    h: f64,
    rise: f64,
    in_tail: bool,
    normal: Option<Vec<f64>>,
}

/// The loop one push at a time: the world keeps its state
/// between pushes, so the caller decides the next push from the state the
/// last one left (see the module docs for what a push does).
///
/// The problem given to [`Stepping::new`] is the start's; its schedule is
/// never read (a step depends on the pushes applied, not on any announced
/// after them). What depends on the whole run (the run's last fifth, the
/// per-sample loads) is gathered at [`Stepping::finish`], on the pushes
/// applied.
pub struct Stepping<W: PlateWorld> {
    world: W,
    problem: Problem,
    cfg: StepLoop,
    state: W::State,
    out: Stepped,
    log: Vec<StepLog>,
    applied: Vec<Push>,
    t_seg: f64,
    slide: Option<SlideOut>,
}

/// What [`Stepping::release`] gathered: the slide's steps (to the first step
/// of the rest), the rest state (or the state at `max_duration`) and the
/// report.
#[derive(Debug, Clone)]
struct SlideOut {
    release: Sample,
    steps: Vec<Sample>,
    end: crate::EngineState,
    report: SlideReport,
}

fn row(s: &crate::EngineState) -> Sample {
    Sample {
        t: s.t,
        x: s.x,
        y: s.y,
        theta: s.theta,
        omega: s.omega,
    }
}

impl<W: PlateWorld> Stepping<W> {
    /// The loop over `world`, whose object is in `start` (set up, settled and
    /// given its start velocity by the engine), for `problem` (the start's:
    /// see the type's docs).
    pub fn new(world: W, problem: &Problem, cfg: StepLoop, start: W::State) -> Self {
        let mut out = Stepped {
            min_loads: vec![f64::INFINITY; cfg.supports],
            ..Default::default()
        };
        out.history
            .push(PlateStep::new(0, 0.0, 0.0, &world.plate(&start)));
        Self {
            world,
            problem: problem.clone(),
            cfg,
            state: start,
            out,
            log: Vec::new(),
            applied: Vec::new(),
            t_seg: 0.0,
            slide: None,
        }
    }

    /// The world.
    pub fn world(&self) -> &W {
        &self.world
    }

    /// The object as the world last read it.
    pub fn state(&self) -> &W::State {
        &self.state
    }

    /// The pushes applied so far.
    pub fn applied(&self) -> &[Push] {
        &self.applied
    }

    /// Time at the end of the pushes applied so far (s).
    pub fn time(&self) -> f64 {
        self.t_seg
    }

    /// Engine steps taken so far.
    pub fn steps(&self) -> usize {
        self.out.steps
    }

    /// The start's problem with the pushes applied as its schedule.
    pub fn applied_problem(&self) -> Problem {
        crate::session::with_pushes(&self.problem, self.applied.clone())
    }

    /// The object's state for a session: pose and ω from
    /// [`PlateWorld::plate`], the centre of mass's velocity from
    /// [`PlateWorld::cm_velocity`], else the one a rigid contact moving with
    /// the last push gives.
    pub fn engine_state(&self) -> crate::EngineState {
        if let Some(slide) = &self.slide {
            return slide.end;
        }
        let p = self.world.plate(&self.state);
        let v_cm = self.world.cm_velocity(&self.state).unwrap_or_else(|| {
            crate::rigid_cm_velocity(&self.problem, self.applied.last(), p.theta, p.omega)
        });
        crate::EngineState {
            t: self.t_seg,
            x: p.x,
            y: p.y,
            theta: p.theta,
            omega: p.omega,
            v_cm,
        }
    }

    /// What the release found (None before it).
    pub fn slide(&self) -> Option<&SlideReport> {
        self.slide.as_ref().map(|s| &s.report)
    }

    /// Lets go ([`crate::EngineSession::release`]): the world removes the
    /// pusher's constraint ([`PlateWorld::release`]; without a push applied
    /// it throws the plate with the problem's `initial.velocity` and ω),
    /// then steps of the loop's `dt` (the last one ending at
    /// `max_duration`), each after [`PlateWorld::slide_step`], until the
    /// plate is at rest by the rule of [`crate::REST_SPEED`] and
    /// [`crate::REST_STEPS`]. The slide's steps are kept apart from the
    /// pushes' (the tails, loads and extremes stay the pushes'; the largest
    /// tilt and lift take the slide's too).
    pub fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        if self.slide.is_some() {
            return Err(crate::after_release());
        }
        let throw = self.applied.is_empty().then(|| {
            let i = &self.problem.initial;
            ([i.velocity.x, i.velocity.y], i.omega)
        });
        self.world.release(&self.state, throw)?;
        self.state = self.world.state(&self.state);
        let t_rel = self.t_seg;
        let mut prev = self.world.plate(&self.state);
        let v0 = self.world.cm_velocity(&self.state).unwrap_or_else(|| {
            if throw.is_some() {
                throw.map_or([0.0, 0.0], |t| t.0)
            } else {
                crate::rigid_cm_velocity(&self.problem, self.applied.last(), prev.theta, prev.omega)
            }
        });
        let start = crate::EngineState {
            t: t_rel,
            x: prev.x,
            y: prev.y,
            theta: prev.theta,
            omega: prev.omega,
            v_cm: v0,
        };
        let h = self.cfg.dt;
        let n = (max_duration / h * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let mut steps = Vec::new();
        let mut last = start;
        let mut rest: Option<(usize, crate::EngineState)> = None;
        let mut held = 0;
        for k in 0..n {
            let t0 = t_rel + k as f64 * h;
            let t1 = if k + 1 == n {
                t_rel + max_duration
            } else {
                t0 + h
            };
            let hk = t1 - t0;
            self.world.slide_step(&self.state, hk);
            self.world.step(hk, t1)?;
            self.out.steps += 1;
            self.state = self.world.state(&self.state);
            if !self.world.finite(&self.state) {
                return Err(ModelError::NonFinite {
                    t: t1,
                    step: self.out.steps,
                });
            }
            self.world.after_step(&self.state);
            let p = self.world.plate(&self.state);
            self.out.max_tilt = self.out.max_tilt.max(p.tilt);
            self.out.max_lift = self.out.max_lift.max((p.z - self.cfg.z_rest).abs());
            let v_cm = self
                .world
                .cm_velocity(&self.state)
                .unwrap_or([(p.x - prev.x) / hk, (p.y - prev.y) / hk]);
            prev = p;
            last = crate::EngineState {
                t: t1,
                x: p.x,
                y: p.y,
                theta: p.theta,
                omega: p.omega,
                v_cm,
            };
            steps.push(row(&last));
            if crate::rest_speed(&self.problem, v_cm, p.omega) < crate::REST_SPEED {
                if rest.is_none() {
                    rest = Some((steps.len(), last));
                }
                held += 1;
                if held >= crate::REST_STEPS {
                    break;
                }
            } else {
                rest = None;
                held = 0;
            }
        }
        let (end, t_stop) = match rest.filter(|_| held >= crate::REST_STEPS) {
            Some((k, st)) => {
                steps.truncate(k);
                (st, Some(st.t))
            }
            None => (last, None),
        };
        self.t_seg = end.t;
        self.slide = Some(SlideOut {
            release: row(&start),
            steps,
            end,
            report: SlideReport {
                t_release: t_rel,
                t_stop,
                pivots: Vec::new(),
            },
        });
        Ok(())
    }

    /// Runs one push (see the module docs).
    pub fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        if self.slide.is_some() {
            return Err(crate::after_release());
        }
        let j = self.applied.len();
        let cfg = self.cfg;
        let n_sup = cfg.supports;
        let t_seg = self.t_seg;
        let n = (push.duration / cfg.dt * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let nominal_h = push.duration / n as f64;
        let layout = self.world.segment_steps(push, n, nominal_h);
        let n_steps = match &layout {
            None => n,
            Some(StepLayout::Lengths(l)) => l.len(),
            Some(StepLayout::Spans(s)) => s.len(),
        };
        let tail_from = match cfg.tail {
            TailSteps::Floor => ((1.0 - TAIL) * n_steps as f64).floor() as usize,
            TailSteps::LastFifth | TailSteps::ByTime => n_steps - (n_steps / 5).max(1),
        };
        // A tail by time: the steps whose middle is in the segment's last
        // fifth (of its duration, back from the end of its last step).
        let seg_end = match &layout {
            Some(StepLayout::Spans(s)) => s.last().map_or(t_seg, |s| s.1),
            _ => t_seg + push.duration,
        };
        let tail_time = seg_end - TAIL * push.duration;
        let (mut acc_w, mut acc_w2, mut acc_t) = (0.0, 0.0, 0.0);
        let mut acc_n = vec![0.0; n_sup];
        let mut acc_f = vec![0.0; n_sup];
        let mut min_slip = vec![f64::INFINITY; n_sup];
        let mut t_prev = t_seg;
        for k in 0..n_steps {
            let (t0, t1, h) = match &layout {
                None => {
                    let t0 = t_seg + k as f64 * nominal_h;
                    let t1 = if k + 1 == n {
                        t_seg + push.duration
                    } else {
                        match cfg.clock {
                            StepClock::FromStepStart => t0 + nominal_h,
                            StepClock::FromSegmentStart => t_seg + (k + 1) as f64 * nominal_h,
                        }
                    };
                    (t0, t1, nominal_h)
                }
                Some(StepLayout::Spans(spans)) => {
                    let (t0, t1) = spans[k];
                    (t0, t1, t1 - t0)
                }
                Some(StepLayout::Lengths(lengths)) => {
                    let t0 = t_prev;
                    let t1 = if k + 1 == n_steps {
                        t_seg + push.duration
                    } else {
                        t0 + lengths[k]
                    };
                    (t0, t1, t1 - t0)
                }
            };
            t_prev = t1;
            let w = match cfg.tail_weight {
                TailWeight::Time => h,
                TailWeight::Steps => 1.0,
            };
            let plan = StepPlan {
                segment: j,
                index: k,
                steps: n_steps,
                t0,
                t1,
                h,
                nominal_h,
                push: *push,
            };
            let drift = self.world.drive_step(&self.state, &plan);
            if k > 0 || j > 0 {
                self.out.max_joint_drift = self.out.max_joint_drift.max(drift);
            }
            self.world.step(h, t1)?;
            self.out.steps += 1;
            self.state = self.world.state(&self.state);
            if !self.world.finite(&self.state) {
                return Err(ModelError::NonFinite {
                    t: t1,
                    step: self.out.steps,
                });
            }
            self.world.after_step(&self.state);
            let p = self.world.plate(&self.state);
            self.out.max_tilt = self.out.max_tilt.max(p.tilt);
            self.out.max_lift = self.out.max_lift.max((p.z - cfg.z_rest).abs());
            let in_tail = match cfg.tail {
                TailSteps::ByTime => 0.5 * (t0 + t1) >= tail_time,
                _ => k >= tail_from,
            };
            // Forces are read on every step (for the per-sample loads); the
            // run tail and the smallest loads are taken at `finish`.
            let forces = self.world.support_forces(&self.state, h)?;
            if in_tail {
                acc_w += p.omega * w;
                acc_w2 += p.omega * p.omega * w;
                acc_t += w;
                if let Some(f) = &forces {
                    for (a, &l) in acc_n.iter_mut().zip(&f.normal) {
                        *a += l * w;
                    }
                    if let Some(fr) = &f.friction {
                        for (a, &l) in acc_f.iter_mut().zip(fr) {
                            *a += l * w;
                        }
                    }
                }
                for (i, m) in min_slip.iter_mut().enumerate() {
                    if let Some(u) = self.world.slip(&self.state, i) {
                        *m = m.min(u);
                    }
                }
                self.world.tail_step(&self.state, h)?;
            }
            self.log.push(StepLog {
                t0,
                t1,
                h,
                rise: p.z - cfg.z_rest,
                in_tail,
                normal: forces.map(|f| f.normal),
            });
            self.out.history.push(PlateStep::new(j, t0, t1, &p));
        }
        let out = &mut self.out;
        // Only a tail by time can be empty (the others hold a step at least).
        let acc_t = if acc_t > 0.0 {
            acc_t
        } else {
            f64::MIN_POSITIVE
        };
        let mean = acc_w / acc_t;
        out.segment_tail_omega.push(mean);
        out.segment_tail_omega_std
            .push((acc_w2 / acc_t - mean * mean).max(0.0).sqrt());
        out.segment_tail_loads
            .push(acc_n.iter().map(|a| a / acc_t).collect());
        out.segment_tail_friction
            .push(acc_f.iter().map(|a| a / acc_t).collect());
        out.segment_tail_min_slip.push(min_slip);
        self.t_seg += push.duration;
        self.applied.push(*push);
        self.world.end_segment(acc_t, self.t_seg)
    }

    /// Advances by every push of `pushes` in order, then ends the loop
    /// ([`Stepping::finish`]): the one push loop behind an engine crate's
    /// detailed view of a run (its session's `advance` and `finish`, with
    /// what the engine records besides the [`EngineRun`](crate::EngineRun)).
    pub fn run(mut self, pushes: &[Push]) -> Result<(W, Stepped, Problem), ModelError> {
        for push in pushes {
            self.advance(push)?;
        }
        Ok(self.finish())
    }

    /// Ends the loop: the world, what the loop gathered (the run's last fifth
    /// and the per-sample loads over the pushes applied), and the start's
    /// problem with the pushes applied as its schedule (the one to resample
    /// on).
    pub fn finish(self) -> (W, Stepped, Problem) {
        let problem = self.applied_problem();
        let cfg = self.cfg;
        let mut out = self.out;
        // The run's last fifth (steps whose middle is past it), time-weighted.
        let run_from = (1.0 - TAIL) * problem.duration();
        let (mut run_n, mut run_t) = (vec![0.0; cfg.supports], 0.0);
        let mut recorder = LoadRecorder::new(&problem, cfg.supports, pushval_laws::GRAVITY);
        for s in &self.log {
            let in_run_tail = match cfg.clock {
                StepClock::FromStepStart => 0.5 * (s.t0 + s.t1) >= run_from,
                StepClock::FromSegmentStart => s.t1 - 0.5 * s.h >= run_from,
            };
            recorder.step(s.t1, s.h, s.normal.as_deref(), Some(s.rise));
            if let Some(normal) = &s.normal {
                // The smallest loads are taken where the world asks for them.
                if cfg.forces_every_step || s.in_tail || in_run_tail {
                    for (m, &l) in out.min_loads.iter_mut().zip(normal) {
                        *m = m.min(l);
                    }
                }
                if in_run_tail {
                    for (a, &l) in run_n.iter_mut().zip(normal) {
                        *a += l * s.h;
                    }
                    run_t += s.h;
                }
            }
        }
        out.loads = run_n
            .iter()
            .map(|a| a / run_t.max(f64::MIN_POSITIVE))
            .collect();
        out.contact = recorder.finish();
        (self.world, out, problem)
    }
}

/// A world borrowed by the loop is a world.
impl<W: PlateWorld + ?Sized> PlateWorld for &mut W {
    type State = W::State;
    fn plate(&self, state: &Self::State) -> Plate {
        (**self).plate(state)
    }
    fn heading(&self, state: &Self::State, h: f64) -> f64 {
        (**self).heading(state, h)
    }
    fn segment_steps(&mut self, push: &Push, n: usize, h: f64) -> Option<StepLayout> {
        (**self).segment_steps(push, n, h)
    }
    fn drive_step(&mut self, state: &Self::State, plan: &StepPlan) -> f64 {
        (**self).drive_step(state, plan)
    }
    fn drive(&mut self, state: &Self::State, velocity: [f64; 2], h: f64) -> f64 {
        (**self).drive(state, velocity, h)
    }
    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError> {
        (**self).step(h, t1)
    }
    fn state(&mut self, prev: &Self::State) -> Self::State {
        (**self).state(prev)
    }
    fn support_forces(
        &mut self,
        state: &Self::State,
        h: f64,
    ) -> Result<Option<SupportForces>, ModelError> {
        (**self).support_forces(state, h)
    }
    fn finite(&self, state: &Self::State) -> bool {
        (**self).finite(state)
    }
    fn after_step(&mut self, state: &Self::State) {
        (**self).after_step(state)
    }
    fn slip(&self, state: &Self::State, i: usize) -> Option<f64> {
        (**self).slip(state, i)
    }
    fn tail_step(&mut self, state: &Self::State, h: f64) -> Result<(), ModelError> {
        (**self).tail_step(state, h)
    }
    fn end_segment(&mut self, tail_weight: f64, t: f64) -> Result<(), ModelError> {
        (**self).end_segment(tail_weight, t)
    }
    fn cm_velocity(&self, state: &Self::State) -> Option<[f64; 2]> {
        (**self).cm_velocity(state)
    }
    fn release(
        &mut self,
        state: &Self::State,
        throw: Option<([f64; 2], f64)>,
    ) -> Result<(), ModelError> {
        (**self).release(state, throw)
    }
    fn slide_step(&mut self, state: &Self::State, h: f64) {
        (**self).slide_step(state, h)
    }
}

/// An engine's session over the shared loop: a [`Stepping`] and how the
/// engine turns what it gathered into its [`EngineRun`](crate::EngineRun).
/// It owns its world: it is `Send` where the world and its state are.
pub struct PlateSession<W: PlateWorld> {
    stepping: Stepping<W>,
    finish: PlateFinish<W>,
    started: Instant,
}

/// How a [`PlateSession`] ends: the world, what the loop gathered and the
/// problem of the pushes applied in, the engine's run out. It owns what it
/// needs (no borrow of the engine).
pub type PlateFinish<W> =
    Box<dyn FnOnce(W, Stepped, &Problem) -> Result<crate::EngineRun, ModelError> + Send>;

impl<W: PlateWorld> PlateSession<W> {
    /// The session of `stepping`, ended by `finish`.
    pub fn new(stepping: Stepping<W>, finish: PlateFinish<W>) -> Self {
        Self {
            stepping,
            finish,
            started: Instant::now(),
        }
    }
}

impl<W: PlateWorld> crate::EngineSession for PlateSession<W> {
    fn state(&self) -> crate::EngineState {
        self.stepping.engine_state()
    }
    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        self.stepping.advance(push)
    }
    /// The engine's run of the pushes, continued through the slide when
    /// the plate was released ([`crate::extend_through_slide`]); a plate
    /// thrown without pushes gives the slide alone (diagnostics: the steps).
    fn finish(self: Box<Self>) -> Result<crate::EngineRun, ModelError> {
        let mut this = *self;
        let slide = this.stepping.slide.take();
        if this.stepping.applied.is_empty() {
            let Some(slide) = slide else {
                return Err(ModelError::EmptySchedule);
            };
            let problem = this.stepping.applied_problem();
            let steps = this.stepping.out.steps;
            let mut trajectory = Trajectory {
                stats: SolverStats {
                    rhs_evals: steps,
                    steps,
                    rejected: 0,
                },
                ..Default::default()
            };
            crate::extend_through_slide(
                &problem,
                &mut trajectory,
                slide.release,
                &slide.steps,
                row(&slide.end),
                slide.report,
            );
            return Ok(crate::EngineRun {
                trajectory,
                dt: this.stepping.cfg.dt,
                steps,
                wall_time: this.started.elapsed(),
                diagnostics: serde_json::json!({ "steps": steps }),
                contact: None,
            });
        }
        let (world, stepped, problem) = this.stepping.finish();
        let mut run = (this.finish)(world, stepped, &problem)?;
        if let Some(slide) = slide {
            crate::extend_through_slide(
                &problem,
                &mut run.trajectory,
                slide.release,
                &slide.steps,
                row(&slide.end),
                slide.report,
            );
        }
        Ok(run)
    }
    fn steps_taken(&self) -> usize {
        self.stepping.steps()
    }
    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        self.stepping.release(max_duration)
    }
    fn slide(&self) -> Option<SlideReport> {
        self.stepping.slide().cloned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushval_model::{Body, Initial, Push, Support, Switching, Vec2};

    /// The push loop, as a session runs it: [`Stepping`] with one
    /// [`advance`](Stepping::advance) per push.
    fn run_pushes<W: PlateWorld>(
        world: &mut W,
        problem: &Problem,
        cfg: &StepLoop,
        start: W::State,
    ) -> Result<Stepped, ModelError> {
        Ok(Stepping::new(world, problem, *cfg, start)
            .run(&problem.pushes)?
            .1)
    }

    /// An object carried rigidly by the pusher: it moves at the commanded
    /// velocity, turns at a constant rate `w` and rises linearly; every
    /// support carries a fixed load and friction force.
    struct Carried {
        w: f64,
        state: Plate,
        vel: [f64; 2],
        drives: usize,
        nan_at: Option<usize>,
        steps: usize,
        tail_calls: usize,
        segment_ends: Vec<f64>,
    }

    impl PlateWorld for Carried {
        type State = Plate;
        fn plate(&self, s: &Plate) -> Plate {
            *s
        }
        fn drive(&mut self, _: &Plate, velocity: [f64; 2], _h: f64) -> f64 {
            self.vel = velocity;
            self.drives += 1;
            // The first drive (the start) reports a large drift.
            if self.drives == 1 {
                100.0
            } else {
                1e-3 * self.drives as f64
            }
        }
        fn step(&mut self, h: f64, _t1: f64) -> Result<(), ModelError> {
            self.steps += 1;
            let s = &mut self.state;
            s.x += self.vel[0] * h;
            s.y += self.vel[1] * h;
            s.z += 0.5 * h;
            s.theta += self.w * h;
            s.omega = self.w;
            s.tilt = 0.01 * self.steps as f64;
            if self.nan_at == Some(self.steps) {
                s.x = f64::NAN;
            }
            Ok(())
        }
        fn state(&mut self, _: &Plate) -> Plate {
            self.state
        }
        fn support_forces(
            &mut self,
            _: &Plate,
            _h: f64,
        ) -> Result<Option<SupportForces>, ModelError> {
            Ok(Some(SupportForces {
                normal: vec![1.0, 2.0, 3.0],
                friction: Some(vec![0.5, 0.25, 0.0]),
            }))
        }
        fn slip(&self, _: &Plate, i: usize) -> Option<f64> {
            (i == 0).then_some(0.125 * self.steps as f64)
        }
        fn tail_step(&mut self, _: &Plate, _h: f64) -> Result<(), ModelError> {
            self.tail_calls += 1;
            Ok(())
        }
        fn end_segment(&mut self, tail_time: f64, _t: f64) -> Result<(), ModelError> {
            self.segment_ends.push(tail_time);
            Ok(())
        }
    }

    fn problem(pushes: Vec<Push>) -> Problem {
        let supports: Vec<Support> = [[-0.1, -0.1], [0.1, -0.1], [0.0, 0.1]]
            .iter()
            .map(|c| Support {
                position: Vec2::new(c[0], c[1]),
                friction: 1.0,
            })
            .collect();
        Problem {
            body: Body::new(1.0, 0.01, Vec2::new(-0.1, 0.0), &supports).unwrap(),
            limits: Default::default(),
            pushes,
            initial: Initial::default(),
            switching: Switching::Impulsive,
            sample_dt: 0.05,
            release: None,
        }
    }

    fn carried(w: f64, nan_at: Option<usize>) -> Carried {
        Carried {
            w,
            state: Plate {
                omega: w,
                ..Default::default()
            },
            vel: [0.0; 2],
            drives: 0,
            nan_at,
            steps: 0,
            tail_calls: 0,
            segment_ends: Vec::new(),
        }
    }

    const CFG: StepLoop = StepLoop {
        dt: 0.1,
        supports: 3,
        z_rest: 0.0,
        forces_every_step: true,
        tail: TailSteps::Floor,
        tail_weight: TailWeight::Time,
        clock: StepClock::FromStepStart,
    };

    /// 1.1 / 0.1 is 11.000000000000002 in floating point: still 11 steps;
    /// 0.35 / 0.1 gives 4 steps of 0.0875. Times are contiguous and each
    /// segment ends exactly at its end time.
    #[test]
    fn schedule_cuts_segments_into_equal_steps() {
        let p = problem(vec![
            Push {
                duration: 1.1,
                speed: 0.1,
                phi: 0.0,
            },
            Push {
                duration: 0.35,
                speed: 0.1,
                phi: 0.5,
            },
        ]);
        let mut w = carried(0.0, None);
        let start = w.state;
        let run = run_pushes(&mut w, &p, &CFG, start).unwrap();
        assert_eq!(run.steps, 15);
        assert_eq!(run.history.len(), 16);
        let h = &run.history;
        assert_eq!((h[0].t0, h[0].t1), (0.0, 0.0));
        // Contiguous to rounding: t0 = t_seg + k h, the previous t1 = t0' + h.
        assert_eq!(h[1].t0, 0.0);
        for k in 2..h.len() {
            assert!((h[k].t0 - h[k - 1].t1).abs() < 1e-15, "{k}");
        }
        assert_eq!(h[11].t1, 1.1);
        assert_eq!(h[11].segment, 0);
        assert_eq!(h[12].segment, 1);
        assert!((h[12].t1 - h[12].t0 - 0.0875).abs() < 1e-15);
        assert_eq!(h[15].t1, 1.1 + 0.35);
        // Tails: steps 8..11 of the first segment (floor(0.8 · 11) = 8) and
        // step 3 of the second (floor(0.8 · 4) = 3).
        assert_eq!(w.tail_calls, 3 + 1);
        assert_eq!(w.segment_ends.len(), 2);
        assert!((w.segment_ends[0] - 0.3).abs() < 1e-12);
        assert!((w.segment_ends[1] - 0.0875).abs() < 1e-12);
    }

    /// The pusher moves at the contact velocity turned by the mid-step yaw
    /// θ + ω h/2; a carried object follows it exactly.
    #[test]
    fn pusher_velocity_is_set_at_the_mid_step_heading() {
        let (speed, phi, w0) = (0.2, 0.3, 1.5);
        let p = problem(vec![Push {
            duration: 0.1,
            speed,
            phi,
        }]);
        let mut w = carried(w0, None);
        let start = w.state;
        let run = run_pushes(&mut w, &p, &CFG, start).unwrap();
        assert_eq!(run.steps, 1);
        let a = phi + 0.5 * 0.1 * w0;
        let r = run.history[1];
        assert!((r.x - 0.1 * speed * a.cos()).abs() < 1e-15);
        assert!((r.y - 0.1 * speed * a.sin()).abs() < 1e-15);
    }

    /// Tail means of constants are the constants; the drift of the first
    /// drive is left out; the smallest slip is over the tail only; the lift
    /// and tilt are the largest over the run.
    #[test]
    fn tails_and_extremes() {
        let p = problem(vec![Push {
            duration: 1.0,
            speed: 0.1,
            phi: 0.0,
        }]);
        let mut w = carried(0.7, None);
        let start = w.state;
        let run = run_pushes(&mut w, &p, &CFG, start).unwrap();
        assert_eq!(run.steps, 10);
        assert!((run.segment_tail_omega[0] - 0.7).abs() < 1e-12);
        assert!(run.segment_tail_omega_std[0] < 1e-6);
        for (got, want) in run.segment_tail_loads[0].iter().zip([1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-12);
        }
        for (got, want) in run.segment_tail_friction[0].iter().zip([0.5, 0.25, 0.0]) {
            assert!((got - want).abs() < 1e-12);
        }
        for (got, want) in run.loads.iter().zip([1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-12);
        }
        assert_eq!(run.min_loads, vec![1.0, 2.0, 3.0]);
        // Tail steps are 9 and 10 (k = 8, 9): slip 0.125 · 9.
        assert_eq!(run.segment_tail_min_slip[0][0], 0.125 * 9.0);
        assert_eq!(run.segment_tail_min_slip[0][1], f64::INFINITY);
        assert!((run.max_joint_drift - 1e-3 * 10.0).abs() < 1e-15);
        assert!((run.max_lift - 0.5).abs() < 1e-12);
        assert!((run.max_tilt - 0.1).abs() < 1e-12);
    }

    #[test]
    fn a_non_finite_state_stops_the_run() {
        let p = problem(vec![Push {
            duration: 1.0,
            speed: 0.1,
            phi: 0.0,
        }]);
        let mut w = carried(0.0, Some(4));
        let start = w.state;
        match run_pushes(&mut w, &p, &CFG, start) {
            Err(ModelError::NonFinite { t, step }) => {
                assert_eq!(step, 4);
                assert!((t - 0.4).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
    }

    /// The other conventions: the last `max(n / 5, 1)` steps as the tail,
    /// weighted equally, and step ends counted from the segment's start.
    #[test]
    fn last_fifth_by_steps_from_the_segment_start() {
        let p = problem(vec![
            Push {
                duration: 1.1,
                speed: 0.1,
                phi: 0.0,
            },
            Push {
                duration: 0.35,
                speed: 0.1,
                phi: 0.5,
            },
        ]);
        let cfg = StepLoop {
            tail: TailSteps::LastFifth,
            tail_weight: TailWeight::Steps,
            clock: StepClock::FromSegmentStart,
            ..StepLoop::new(0.1, 3, 0.0)
        };
        let mut w = carried(0.7, None);
        let start = w.state;
        let run = run_pushes(&mut w, &p, &cfg, start).unwrap();
        // 11 steps: the last 2; 4 steps: the last 1 (4 / 5 = 0, at least 1).
        assert_eq!(w.segment_ends, vec![2.0, 1.0]);
        assert_eq!(w.tail_calls, 3);
        let h = 1.1 / 11.0;
        for k in 1..11 {
            assert_eq!(run.history[k].t1, 0.0 + k as f64 * h);
        }
        assert_eq!(run.history[11].t1, 1.1);
        assert!((run.segment_tail_omega[0] - 0.7).abs() < 1e-12);
        for (got, want) in run.segment_tail_loads[1].iter().zip([1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-12);
        }
    }

    /// A session that applies fewer pushes than the start's schedule
    /// announced ends with the run of the pushes applied: its run tail,
    /// loads and samples are those of a run of that schedule, bit for bit.
    #[test]
    fn finish_gathers_the_run_of_the_pushes_applied() {
        let one = Push {
            duration: 1.0,
            speed: 0.1,
            phi: 0.0,
        };
        let two = Push {
            duration: 0.5,
            speed: 0.1,
            phi: 0.4,
        };
        let announced = problem(vec![one, two]);
        let mut w = carried(0.7, None);
        let start = w.state;
        let mut s = Stepping::new(&mut w, &announced, CFG, start);
        s.advance(&one).unwrap();
        assert_eq!(s.time(), 1.0);
        assert_eq!(s.steps(), 10);
        let state = s.engine_state();
        assert!((state.theta - 0.7).abs() < 1e-12 && state.omega == 0.7);
        let (_, got, applied) = s.finish();
        assert_eq!(applied.pushes, vec![one]);
        let mut w = carried(0.7, None);
        let start = w.state;
        let want = run_pushes(&mut w, &problem(vec![one]), &CFG, start).unwrap();
        assert_eq!(got, want);
        assert_eq!(
            got.trajectory(&applied),
            want.trajectory(&problem(vec![one]))
        );
    }

    /// A world's own step lengths are kept, the last one ending at the
    /// segment's end; the layout is asked once per push applied.
    #[test]
    fn worlds_lay_out_their_own_steps() {
        struct Laid {
            inner: Carried,
            laid: usize,
        }
        impl PlateWorld for Laid {
            type State = Plate;
            fn plate(&self, s: &Plate) -> Plate {
                *s
            }
            fn segment_steps(&mut self, _: &Push, n: usize, h: f64) -> Option<StepLayout> {
                self.laid += 1;
                let mut l = vec![0.25 * h, 0.75 * h];
                l.extend(std::iter::repeat_n(h, n - 1));
                Some(StepLayout::Lengths(l))
            }
            fn drive(&mut self, s: &Plate, v: [f64; 2], h: f64) -> f64 {
                self.inner.drive(s, v, h)
            }
            fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError> {
                self.inner.step(h, t1)
            }
            fn state(&mut self, s: &Plate) -> Plate {
                self.inner.state(s)
            }
            fn support_forces(
                &mut self,
                _: &Plate,
                _: f64,
            ) -> Result<Option<SupportForces>, ModelError> {
                Ok(None)
            }
        }
        let push = Push {
            duration: 0.3,
            speed: 0.1,
            phi: 0.0,
        };
        let p = problem(vec![push, push]);
        let mut w = Laid {
            inner: carried(0.0, None),
            laid: 0,
        };
        let start = w.inner.state;
        let run = run_pushes(&mut w, &p, &CFG, start).unwrap();
        assert_eq!(w.laid, 2);
        // 3 steps of 0.1 each, the first cut in two: 4 per segment.
        assert_eq!(run.steps, 8);
        let h = &run.history;
        assert!((h[1].t1 - 0.025).abs() < 1e-15 && (h[2].t1 - 0.1).abs() < 1e-15);
        assert_eq!(h[4].t1, 0.3);
        assert_eq!(h[5].t0, 0.3);
        assert_eq!(h[8].t1, 0.6);
        assert!(run.contact.is_none());
    }
}
