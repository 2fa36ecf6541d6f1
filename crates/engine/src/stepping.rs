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

use pushval_model::{ModelError, Problem, SolverStats, Trajectory, Vec2};

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
}

/// Which steps of a segment of `n` steps make its tail.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TailSteps {
    /// The steps from index `floor((1 − TAIL) n)` on.
    #[default]
    Floor,
    /// The last `max(n / 5, 1)` steps (integer division).
    LastFifth,
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

/// How [`run_pushes`] runs.
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
    let mut recorder = LoadRecorder::new(problem, n_sup, pushval_laws::GRAVITY);
    for (j, push) in problem.pushes.iter().enumerate() {
        let n = (push.duration / cfg.dt * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let h = push.duration / n as f64;
        let tail_from = match cfg.tail {
            TailSteps::Floor => ((1.0 - TAIL) * n as f64).floor() as usize,
            TailSteps::LastFifth => n - (n / 5).max(1),
        };
        let w = match cfg.tail_weight {
            TailWeight::Time => h,
            TailWeight::Steps => 1.0,
        };
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
                match cfg.clock {
                    StepClock::FromStepStart => t0 + h,
                    StepClock::FromSegmentStart => t_seg + (k + 1) as f64 * h,
                }
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
            if !world.finite(&state) {
                return Err(ModelError::NonFinite {
                    t: t1,
                    step: out.steps,
                });
            }
            world.after_step(&state);
            let p = world.plate(&state);
            out.max_tilt = out.max_tilt.max(p.tilt);
            out.max_lift = out.max_lift.max((p.z - cfg.z_rest).abs());
            let in_tail = k >= tail_from;
            let in_run_tail = match cfg.clock {
                StepClock::FromStepStart => 0.5 * (t0 + t1) >= run_from,
                StepClock::FromSegmentStart => t1 - 0.5 * h >= run_from,
            };
            // Forces are read on every step (for the per-sample loads);
            // the smallest loads are taken where the world asks for them.
            let forces = world.support_forces(&state, h)?;
            recorder.step(
                t1,
                h,
                forces.as_ref().map(|f| f.normal.as_slice()),
                Some(p.z - cfg.z_rest),
            );
            if let Some(f) = &forces {
                if cfg.forces_every_step || in_tail || in_run_tail {
                    for (m, &l) in out.min_loads.iter_mut().zip(&f.normal) {
                        *m = m.min(l);
                    }
                }
                if in_run_tail {
                    for (a, &l) in run_n.iter_mut().zip(&f.normal) {
                        *a += l * h;
                    }
                    run_t += h;
                }
            }
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
        t_seg += push.duration;
        world.end_segment(acc_t, t_seg)?;
    }
    out.loads = run_n
        .iter()
        .map(|a| a / run_t.max(f64::MIN_POSITIVE))
        .collect();
    out.contact = recorder.finish();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushval_model::{Body, Initial, Push, Support, Switching};

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
}
