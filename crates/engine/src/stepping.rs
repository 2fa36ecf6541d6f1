//! The one stepping loop of the plate engines (rapier3d, Jolt, PhysX, …).
//!
//! An engine that puts the object on supports in a 3-D scene and drives it
//! with a kinematic pusher builds its world, settles it and sets the start
//! velocity itself; then [`run_pushes`] runs the push schedule through the
//! small [`PlateWorld`] trait and gathers what every such engine reports:
//!
//! * **Schedule.** Each segment of duration `T` is cut into
//!   `n = ceil(T / dt)` equal steps of `h = T / n` (a relative `1e-12` off
//!   the quotient, so that a whole number of steps is not rounded up); the
//!   last step of a segment ends exactly at the segment's end time.
//! * **Pusher.** Before every step the pusher is re-pinned on the object's
//!   contact point and moves at the commanded contact velocity `v_c R(ψ)
//!   n_φ`, ψ the heading [`PlateWorld::heading`] gives (by default the yaw at
//!   mid-step, `θ + ω h/2`).
//! * **Checks.** After every step the position and ω must be finite
//!   ([`ModelError::NonFinite`] otherwise).
//! * **Records.** Every step is one [`PlateStep`] (pose at its end, ω over
//!   it, height and tilt), after an initial record at t = 0.
//! * **Tails.** Per segment, over its steps from index `floor(0.8 n)` on
//!   ([`TAIL`]): the time-weighted means of ω, of ω² (its spread), of each
//!   support's normal load and friction force, and each support's smallest
//!   slip speed. Over the run's last fifth (the steps whose middle is past
//!   it), each support's time-weighted mean load.
//! * **Extremes.** The largest tilt, the largest vertical displacement of the
//!   centre of mass from its height at the start, the largest pusher drift
//!   (after the first step), and each support's smallest load.
//!
//! The arithmetic is written once here, in a fixed order, so that every
//! engine using it gets the same numbers it got from its own copy of the loop.

use pushval_model::{ModelError, Problem, SolverStats, Trajectory, Vec2};

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

    /// Re-pins the pusher on the object's contact point and gives it the
    /// world velocity `velocity` (m/s) for a step of length `h`; returns how
    /// far (m, horizontal) it was from the contact point before.
    fn drive(&mut self, state: &Self::State, velocity: [f64; 2], h: f64) -> f64;

    /// One engine step of length `h` (s) ending at time `t1`.
    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError>;

    /// The object after a step; `prev` is the reading before it (to unwrap
    /// the yaw).
    fn state(&self, prev: &Self::State) -> Self::State;

    /// Each support's forces over the last step of length `h`, or None where
    /// the engine reads none.
    fn support_forces(
        &mut self,
        state: &Self::State,
        h: f64,
    ) -> Result<Option<SupportForces>, ModelError>;

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

    /// Called at the end of every segment with the length of its tail (s).
    /// Nothing by default.
    fn end_segment(&mut self, _tail_time: f64) {}
}

/// How [`run_pushes`] runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepLoop {
    /// Largest time step (s).
    pub dt: f64,
    /// Number of supports (length of the per-support vectors).
    pub supports: usize,
    /// Height of the centre of mass the lift is measured from (m).
    pub z_rest: f64,
    /// Read the support forces after every step (for the smallest loads);
    /// otherwise only on the steps of the segment tails and the run tail.
    pub forces_every_step: bool,
}

/// What [`run_pushes`] gathered.
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

/// Runs the push schedule of `problem` from `start` (see the module docs).
pub fn run_pushes<W: PlateWorld>(
    world: &mut W,
    problem: &Problem,
    cfg: &StepLoop,
    start: W::State,
) -> Result<Stepped, ModelError> {
    let n_sup = cfg.supports;
    let mut state = start;
    let mut out = Stepped {
        min_loads: vec![f64::INFINITY; n_sup],
        ..Default::default()
    };
    out.history
        .push(PlateStep::new(0, 0.0, 0.0, &world.plate(&state)));
    // The run's last fifth (steps whose middle is past it), time-weighted.
    let run_from = (1.0 - TAIL) * problem.duration();
    let (mut run_n, mut run_t) = (vec![0.0; n_sup], 0.0);
    let mut t_seg = 0.0;
    for (j, push) in problem.pushes.iter().enumerate() {
        let n = (push.duration / cfg.dt * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let h = push.duration / n as f64;
        let tail_from = ((1.0 - TAIL) * n as f64).floor() as usize;
        let (mut acc_w, mut acc_w2, mut acc_t) = (0.0, 0.0, 0.0);
        let mut acc_n = vec![0.0; n_sup];
        let mut acc_f = vec![0.0; n_sup];
        let mut min_slip = vec![f64::INFINITY; n_sup];
        let vc: Vec2 = push.velocity();
        for k in 0..n {
            let t0 = t_seg + k as f64 * h;
            let t1 = if k + 1 == n {
                t_seg + push.duration
            } else {
                t0 + h
            };
            let (sn, cs) = world.heading(&state, h).sin_cos();
            let vel = [cs * vc.x - sn * vc.y, sn * vc.x + cs * vc.y];
            let drift = world.drive(&state, vel, h);
            if k > 0 || j > 0 {
                out.max_joint_drift = out.max_joint_drift.max(drift);
            }
            world.step(h, t1)?;
            out.steps += 1;
            state = world.state(&state);
            let p = world.plate(&state);
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite() && p.omega.is_finite()) {
                return Err(ModelError::NonFinite {
                    t: t1,
                    step: out.steps,
                });
            }
            out.max_tilt = out.max_tilt.max(p.tilt);
            out.max_lift = out.max_lift.max((p.z - cfg.z_rest).abs());
            let in_tail = k >= tail_from;
            let in_run_tail = 0.5 * (t0 + t1) >= run_from;
            let forces = if cfg.forces_every_step || in_tail || in_run_tail {
                world.support_forces(&state, h)?
            } else {
                None
            };
            if let Some(f) = &forces {
                for (m, &l) in out.min_loads.iter_mut().zip(&f.normal) {
                    *m = m.min(l);
                }
                if in_run_tail {
                    for (a, &l) in run_n.iter_mut().zip(&f.normal) {
                        *a += l * h;
                    }
                    run_t += h;
                }
            }
            if in_tail {
                acc_w += p.omega * h;
                acc_w2 += p.omega * p.omega * h;
                acc_t += h;
                if let Some(f) = &forces {
                    for (a, &l) in acc_n.iter_mut().zip(&f.normal) {
                        *a += l * h;
                    }
                    if let Some(fr) = &f.friction {
                        for (a, &l) in acc_f.iter_mut().zip(fr) {
                            *a += l * h;
                        }
                    }
                }
                for (i, m) in min_slip.iter_mut().enumerate() {
                    if let Some(u) = world.slip(&state, i) {
                        *m = m.min(u);
                    }
                }
                world.tail_step(&state, h)?;
            }
            out.history.push(PlateStep::new(j, t0, t1, &p));
        }
        let mean = acc_w / acc_t;
        out.segment_tail_omega.push(mean);
        out.segment_tail_omega_std
            .push((acc_w2 / acc_t - mean * mean).max(0.0).sqrt());
        out.segment_tail_loads
            .push(acc_n.iter().map(|a| a / acc_t).collect());
        out.segment_tail_friction
            .push(acc_f.iter().map(|a| a / acc_t).collect());
        out.segment_tail_min_slip.push(min_slip);
        world.end_segment(acc_t);
        t_seg += push.duration;
    }
    out.loads = run_n
        .iter()
        .map(|a| a / run_t.max(f64::MIN_POSITIVE))
        .collect();
    Ok(out)
}
