//! One push segment as the integrators see it ([`SegmentRun`]) and the
//! record a run builds ([`Recorder`]): what the dynamic model's driver and
//! its integrators (`adaptive`, `rk4`) share, below all three.

use super::checker::Checker;
use super::sampling::{pose_sample, sample_tail, Sampler};
use super::Trajectory;
use crate::dynamic::SegmentDynamics;
use crate::integrate::State;
use crate::tail::ends::EndSeries;
use crate::tail::{SettleRule, Tail, TailPose};
use crate::{ModelError, Problem, Rotor, Vec2};

/// What a run has produced so far: the trajectory (samples, segments,
/// solver work) and the assumption checks.
pub(super) struct Recorder<'p> {
    pub(super) out: Trajectory,
    sampler: Sampler,
    pub(super) checker: Checker<'p>,
    /// Serves `R(θ)` for the samples.
    rotor: Rotor,
    /// Only the run's end is asked for: settling segments end by the series
    /// in `δ` ([`EndSeries`]) instead of the sampled tail.
    pub(super) ends_only: bool,
    /// The contact point in the object frame (m).
    pc: Vec2,
}

impl<'p> Recorder<'p> {
    pub(super) fn new(problem: &'p Problem, model: String, check_assumptions: bool) -> Self {
        Self::with_sampler(problem, model, check_assumptions, Sampler::new(problem))
    }

    /// A record of the samples `sampler` hands out (none: only the segment
    /// reports and the solver work).
    pub(super) fn with_sampler(
        problem: &'p Problem,
        model: String,
        check_assumptions: bool,
        sampler: Sampler,
    ) -> Self {
        Self {
            out: Trajectory {
                model,
                samples: Vec::with_capacity(sampler.times.len()),
                ..Default::default()
            },
            sampler,
            checker: Checker::new(problem, check_assumptions),
            rotor: Rotor::new(),
            pc: problem.body.contact(),
            ends_only: false,
        }
    }

    /// Whether a sample of `seg` falls at or before `t` (s).
    pub(super) fn sample_due(&self, seg: &SegmentRun, t: f64) -> bool {
        self.sampler.due(t, seg.t1, seg.last).is_some()
    }

    /// Records every sample of `seg` due up to `t` (s), with the contact
    /// point, θ and ω at each sample time from `state_at`, and checks the
    /// assumptions there.
    #[inline]
    pub(super) fn samples_until(
        &mut self,
        seg: &SegmentRun,
        t: f64,
        mut state_at: impl FnMut(f64) -> (Vec2, f64, f64),
    ) {
        while let Some(ts) = self.sampler.due(t, seg.t1, seg.last) {
            let (c, theta, omega) = state_at(ts);
            self.out
                .samples
                .push(pose_sample(&mut self.rotor, ts, c, theta, omega, &self.pc));
            self.checker.sample(&seg.dynamics, omega, ts, seg.index);
            self.sampler.next += 1;
        }
    }

    /// The contact point, θ and ω at the end of `seg` from the closed form
    /// `closed`, sampling it on the way if it is a tail.
    pub(super) fn finish_closed(&mut self, seg: &SegmentRun, closed: Closed) -> (Vec2, f64, f64) {
        match closed {
            Closed::Tail(tail) => self.samples_of_tail(seg, tail),
            Closed::End { pose, .. } => (pose.c, pose.theta, pose.omega),
        }
    }

    /// Samples a closed-form tail up to the end of `seg` and returns the
    /// contact point, θ and ω there.
    pub(super) fn samples_of_tail(&mut self, seg: &SegmentRun, tail: Tail) -> (Vec2, f64, f64) {
        let from = self.out.samples.len();
        let p = sample_tail(
            tail,
            &mut self.sampler,
            seg.t1,
            seg.last,
            self.pc,
            &mut self.out.samples,
        );
        if self.checker.enabled {
            for k in from..self.out.samples.len() {
                let smp = self.out.samples[k];
                self.checker
                    .sample(&seg.dynamics, smp.omega, smp.t, seg.index);
            }
        }
        (p.c, p.theta, p.omega)
    }
}

/// The contact point, θ and ω of an integrator state `[θ, ω, c_x, c_y]`.
#[inline]
pub(super) fn pose_of(y: &State) -> (Vec2, f64, f64) {
    (Vec2::new(y[2], y[3]), y[0], y[1])
}

/// Where a segment goes on in closed form: a tail to sample (the series in
/// `E`, or an arc), or, where nothing is sampled, its end state alone.
pub(super) enum Closed {
    Tail(Tail),
    /// The segment's end state from the series in `δ` taken at `t` (s).
    End {
        t: f64,
        pose: TailPose,
    },
}

impl Closed {
    /// When the closed form takes over (s).
    pub(super) fn start(&self) -> f64 {
        match self {
            Closed::Tail(tail) => tail.t,
            Closed::End { t, .. } => *t,
        }
    }
}

/// One push segment as the integrators see it: its dynamics, its span, and
/// where its motion leaves the integrator for a closed form.
pub(super) struct SegmentRun {
    /// Segment index.
    pub(super) index: usize,
    pub(super) dynamics: SegmentDynamics,
    /// Start and end time (s).
    pub(super) t0: f64,
    pub(super) t1: f64,
    /// The last segment owns its end time's sample.
    pub(super) last: bool,
    /// The contact velocity `v_c n_φ` in the object frame (m/s).
    pub(super) vel: Vec2,
    /// The integrator's tolerance (RK4: dt⁴): how close to a pivot counts
    /// as there.
    pub(super) tol: f64,
    /// The hand-over to the series tail, toward a stable root.
    pub(super) settle: Option<SettleRule>,
    /// The end in closed form toward a stable root, for a run that takes
    /// no sample (then `settle` is None).
    pub(super) ends: Option<EndSeries>,
    /// ω at a stable pivot ω tends to (rad/s).
    pub(super) pivot: Option<f64>,
    /// |ω| beyond which the run is a runaway (rad/s).
    pub(super) omega_limit: f64,
}

impl SegmentRun {
    /// The stable root the segment's closed forms tend to (rad/s).
    pub(super) fn root(&self) -> Option<f64> {
        self.settle
            .as_ref()
            .map(|r| r.omega)
            .or_else(|| self.ends.as_ref().map(|e| e.omega))
    }

    /// The closed form from time `t` (s) at contact point `c`, angle `theta`
    /// and ω = `w`, if it holds from there: the segment's end state alone
    /// where nothing is sampled, the series tail otherwise.
    pub(super) fn try_tail(&self, t: f64, c: Vec2, theta: f64, w: f64) -> Option<Closed> {
        if let Some(e) = &self.ends {
            let g_w = self.dynamics.omega_dot(w);
            return e
                .end(self.t1 - t, c, theta, w, g_w, self.vel, self.tol)
                .map(|pose| Closed::End { t, pose });
        }
        self.settle
            .as_ref()
            .and_then(|r| r.tail(&self.dynamics, t, c, theta, w, self.vel, self.t1 - t))
            .map(Closed::Tail)
    }

    /// Whether ω has reached the pivot (or crossed it) going from `w0` to `w1`.
    fn pivot_reached(&self, w0: f64, w1: f64) -> bool {
        self.pivot.is_some_and(|wp| {
            (w1 - wp).abs() <= 10.0 * self.tol * (1.0 + wp.abs())
                || (w1 - wp).signum() != (w0 - wp).signum()
        })
    }

    /// The turn about the sticking support from time `t` (s).
    fn pivot_tail(&self, t: f64, c: Vec2, theta: f64) -> Tail {
        Tail::arc(t, c, theta, self.pivot.unwrap_or(0.0), self.vel)
    }

    /// Where the segment goes on from its start at contact point `c`, angle
    /// `theta` and ω = `omega`: the pivot's arc or the series tail, if either
    /// holds there.
    pub(super) fn closed_form_at_start(&self, c: Vec2, theta: f64, omega: f64) -> Option<Closed> {
        if self.pivot_reached(omega, omega) {
            Some(Closed::Tail(self.pivot_tail(self.t0, c, theta)))
        } else {
            self.try_tail(self.t0, c, theta, omega)
        }
    }

    /// Checks the state `y` an accepted step reached at `t` (s) from ω =
    /// `w_before`: true if the segment goes on as the pivot's arc from there
    /// (the step reached the pivot or, `stalled`, the steps toward it have
    /// shrunk to nothing); an error for a non-finite state or a runaway.
    /// `steps`: accepted so far.
    #[inline]
    pub(super) fn landed(
        &self,
        t: f64,
        y: &State,
        w_before: f64,
        stalled: bool,
        steps: usize,
    ) -> Result<bool, ModelError> {
        if t < self.t1 && (self.pivot_reached(w_before, y[1]) || stalled) {
            return Ok(true);
        }
        if !y.iter().all(|v| v.is_finite()) {
            return Err(ModelError::NonFinite { t, step: steps });
        }
        if y[1].abs() > self.omega_limit {
            return Err(ModelError::Runaway {
                t,
                step: steps,
                omega: y[1],
                limit: self.omega_limit,
            });
        }
        Ok(false)
    }

    /// The pivot's arc from the state `y` at `t` (s).
    pub(super) fn pivot_tail_from(&self, t: f64, y: &State) -> Tail {
        let (c, theta, _) = pose_of(y);
        self.pivot_tail(t, c, theta)
    }

    /// The series tail from the state `y` at `t` (s), inside the segment.
    #[inline]
    pub(super) fn tail_after_step(&self, t: f64, y: &State) -> Option<Closed> {
        if t < self.t1 {
            let (c, theta, w) = pose_of(y);
            self.try_tail(t, c, theta, w)
        } else {
            None
        }
    }
}
