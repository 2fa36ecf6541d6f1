//! The dynamic model as a [`Simulator`]. Per segment: the switch, the
//! analysis of ω̇ (the root ω tends to, a runaway, a pivot, the series tail),
//! then the closed form where there is one and an integrator (`adaptive`,
//! `rk4`) where there is not.

use super::checker::Checker;
use super::sampling::{pose_sample, sample_tail, Sampler};
use super::{adaptive, rk4, SegmentReport, Trajectory};
use crate::dynamic::{SegmentDynamics, SteadyState};
use crate::integrate::State;
use crate::tail::{SettleRule, Tail};
use crate::{rotate, Body, ModelError, Problem, Push, RootKind, Rotor, Simulator, Vec2};

/// Which integrator the dynamic model uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integrator {
    /// Dormand–Prince 5(4) with dense output; per-step error ≤ `tol` (m, rad)
    /// in θ and the position, and ≤ `tol (1 + |ω|)` in ω (RMS over the state).
    Adaptive {
        /// Per-step error tolerance (m, rad; relative in ω).
        tol: f64,
    },
    /// Dormand & Prince's 8(5,3) pair (DOP853) with its 7th-order dense
    /// output; the same error measure as `Adaptive`.
    Dop853 {
        /// Per-step error tolerance (m, rad; relative in ω).
        tol: f64,
    },
    /// Classical RK4, fixed step at most `dt` (s), shortened so every switch
    /// falls on a step; samples by cubic Hermite interpolation.
    Rk4 {
        /// Largest step (s).
        dt: f64,
    },
}

/// The dynamic model as a [`Simulator`] (name `"dynamic"`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicModel {
    /// The integrator and its tolerance or step; default DOP853 at 1e-10.
    pub integrator: Integrator,
    /// Once a segment's transient toward a stable steady state can be
    /// written as a converging series in `e^{−t/τ}` to within a share of the
    /// tolerance (often from the switch on), follow that closed form instead
    /// of integrating (module `tail`). Default true.
    pub skip_settled: bool,
    /// Evaluate the pusher force and the assumption checks at every sample.
    /// Default true.
    pub check_assumptions: bool,
    /// Which reading of the inertial term; default the derived one.
    pub inertial_term: crate::InertialTerm,
}

impl Default for DynamicModel {
    fn default() -> Self {
        Self {
            integrator: Integrator::Dop853 { tol: 1e-10 },
            skip_settled: true,
            check_assumptions: true,
            inertial_term: crate::InertialTerm::Derived,
        }
    }
}

/// What a run has produced so far: the trajectory (samples, segments,
/// solver work) and the assumption checks.
pub(super) struct Recorder<'p> {
    pub(super) out: Trajectory,
    sampler: Sampler,
    checker: Checker<'p>,
    /// Serves `R(θ)` for the samples.
    rotor: Rotor,
    /// The contact point in the object frame (m).
    pc: Vec2,
}

impl<'p> Recorder<'p> {
    fn new(problem: &'p Problem, model: String, check_assumptions: bool) -> Self {
        let sampler = Sampler::new(problem);
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

    /// Samples a closed-form tail up to the end of `seg` and returns the
    /// contact point, θ and ω there.
    fn samples_of_tail(&mut self, seg: &SegmentRun, tail: Tail) -> (Vec2, f64, f64) {
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
    tol: f64,
    /// The hand-over to the series tail, toward a stable root.
    pub(super) settle: Option<SettleRule>,
    /// ω at a stable pivot ω tends to (rad/s).
    pub(super) pivot: Option<f64>,
    /// |ω| beyond which the run is a runaway (rad/s).
    omega_limit: f64,
}

impl SegmentRun {
    /// The series tail from time `t` (s) at contact point `c`, angle `theta`
    /// and ω = `w`, if it holds from there.
    pub(super) fn try_tail(&self, t: f64, c: Vec2, theta: f64, w: f64) -> Option<Tail> {
        self.settle
            .as_ref()
            .and_then(|r| r.tail(&self.dynamics, t, c, theta, w, self.vel, self.t1 - t))
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
    fn closed_form_at_start(&self, c: Vec2, theta: f64, omega: f64) -> Option<Tail> {
        if self.pivot_reached(omega, omega) {
            Some(self.pivot_tail(self.t0, c, theta))
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
    pub(super) fn tail_after_step(&self, t: f64, y: &State) -> Option<Tail> {
        if t < self.t1 {
            let (c, theta, w) = pose_of(y);
            self.try_tail(t, c, theta, w)
        } else {
            None
        }
    }
}

impl DynamicModel {
    /// The integrator's tolerance or step must be finite and > 0.
    fn check_integrator(&self) -> Result<(), ModelError> {
        if let Integrator::Adaptive { tol } | Integrator::Dop853 { tol } = self.integrator {
            if !(tol.is_finite() && tol > 0.0) {
                return Err(ModelError::Parameter {
                    name: "tolerance",
                    requirement: "finite and > 0",
                    value: tol,
                });
            }
        }
        if let Integrator::Rk4 { dt } = self.integrator {
            if !(dt.is_finite() && dt > 0.0) {
                return Err(ModelError::Parameter {
                    name: "rk4 dt",
                    requirement: "finite and > 0",
                    value: dt,
                });
            }
        }
        Ok(())
    }

    /// The analysis of segment `index` over `[t0, t1]` (s) starting at ω =
    /// `omega`: the root ω tends to (a runaway or a pivot is recorded in
    /// `checker`), the runaway limit, the series tail's hand-over rule.
    /// `r_min`: the shortest nonzero distance from the contact to a support (m).
    #[allow(clippy::too_many_arguments)]
    fn segment(
        &self,
        body: &Body,
        push: &Push,
        index: usize,
        (t0, t1): (f64, f64),
        last: bool,
        omega: f64,
        r_min: f64,
        checker: &mut Checker,
    ) -> SegmentRun {
        let dynamics = SegmentDynamics::with_inertial_term(body, push, self.inertial_term);
        let target = if push.speed > 0.0 {
            dynamics.attractor_from(omega)
        } else {
            None
        };
        // For a constant input ω is a scalar autonomous ODE: it moves
        // monotonically from ω_start to the root it tends to and never
        // passes it. Far beyond that it is running away (or an integrator
        // is unstable); stop there instead of grinding on ever shorter
        // steps.
        let omega_limit = 1e3
            * target
                .map_or(0.0, |r| r.omega.abs())
                .max(omega.abs())
                .max(push.speed / r_min);
        if push.speed > 0.0 {
            checker.target(target, t0, omega, index);
        }
        let tol = match self.integrator {
            Integrator::Adaptive { tol } | Integrator::Dop853 { tol } => tol,
            Integrator::Rk4 { dt } => dt.powi(4),
        };
        let settle = match target {
            Some(SteadyState {
                kind: RootKind::Stable,
                tau: Some(tau),
                omega: ws,
            }) if self.skip_settled && tau > 0.0 => {
                SettleRule::new(&dynamics, ws, tol, omega, t1 - t0)
            }
            _ => None,
        };
        // A stable pivot is reached in finite time (ω̇ jumps there); past
        // it the support sticks and the object turns about it at the
        // constant ω_p. Integrating across the jump would chatter, so the
        // step is aimed at the pivot and the motion continues as an arc.
        let pivot = match target {
            Some(SteadyState {
                kind: RootKind::Pivot { stable: true, .. },
                omega: wp,
                ..
            }) => Some(wp),
            _ => None,
        };
        SegmentRun {
            index,
            dynamics,
            t0,
            t1,
            last,
            vel: push.velocity(),
            tol,
            settle,
            pivot,
            omega_limit,
        }
    }

    /// Integrates `seg` from `[θ, ω, c_x, c_y]` = `y`: the state where the
    /// integrator stopped, and the closed form the segment continues in if
    /// it stopped before the end. `h_carry`: the adaptive step (s) and the
    /// distance from the steady ω (rad/s) at the end of the last integrated
    /// segment, for the next one's first step.
    fn integrate(
        &self,
        seg: &SegmentRun,
        rec: &mut Recorder,
        h_carry: &mut Option<(f64, f64)>,
        y: State,
    ) -> Result<(State, Option<Tail>), ModelError> {
        let vel = seg.vel;
        let mut rotor = Rotor::new();
        let mut rhs = |y: &State| {
            let (s, co) = rotor.sin_cos(y[0]);
            [
                y[1],
                seg.dynamics.omega_dot(y[1]),
                co * vel.x - s * vel.y,
                s * vel.x + co * vel.y,
            ]
        };
        let k1 = rhs(&y);
        rec.out.stats.rhs_evals += 1;
        match self.integrator {
            Integrator::Adaptive { tol } => {
                adaptive::integrate(seg, rec, &mut rhs, y, k1, tol, false, h_carry)
            }
            Integrator::Dop853 { tol } => {
                adaptive::integrate(seg, rec, &mut rhs, y, k1, tol, true, h_carry)
            }
            Integrator::Rk4 { dt } => rk4::integrate(seg, rec, &mut rhs, y, k1, dt),
        }
    }
}

/// A segment with the contact held (`v_c = 0`) from contact point `c`,
/// angle `theta` and ω = `w0`: the object pivots about the contact and
/// friction (moment −sign(ω) Σ F_i |r_i|) stops it in finite time. Samples
/// the segment; returns θ and ω at its end, and the time (s) it stopped if
/// that is within the segment.
fn hold(
    seg: &SegmentRun,
    rec: &mut Recorder,
    c: Vec2,
    theta: f64,
    w0: f64,
) -> (f64, f64, Option<f64>) {
    let alpha = seg.dynamics.max_moment() / seg.dynamics.inertia_contact();
    let t_stop = if alpha > 0.0 {
        w0.abs() / alpha
    } else {
        f64::INFINITY
    };
    let state_at = |dt: f64| {
        let d = dt.min(t_stop);
        let th = theta + w0 * d - w0.signum() * alpha * d * d / 2.0;
        let w = if dt >= t_stop {
            0.0
        } else {
            w0 - w0.signum() * alpha * dt
        };
        (th, w)
    };
    rec.samples_until(seg, seg.t1, |ts| {
        let (th, w) = state_at(ts - seg.t0);
        (c, th, w)
    });
    let (th, w) = state_at(seg.t1 - seg.t0);
    let stopped = (t_stop.is_finite() && t_stop <= seg.t1 - seg.t0).then_some(seg.t0 + t_stop);
    (th, w, stopped)
}

impl Simulator for DynamicModel {
    fn name(&self) -> String {
        "dynamic".into()
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        problem.check()?;
        self.check_integrator()?;
        let body = &problem.body;
        let pc = body.contact();
        let mut rec = Recorder::new(problem, self.name(), self.check_assumptions);
        let init = problem.initial;
        let mut theta = init.theta;
        let mut c = init.position + rotate(theta, &pc);
        let mut omega = if init.from_rest { 0.0 } else { init.omega };
        let mut prev: Option<Push> = (!init.from_rest).then(|| problem.pushes[0]);
        let mut h_carry: Option<(f64, f64)> = None;
        let r_min = body
            .supports()
            .map(|s| (s.position - pc).norm())
            .filter(|r| *r > 0.0)
            .fold(f64::INFINITY, f64::min);
        let n_seg = problem.pushes.len();
        for (j, (push, span)) in problem
            .pushes
            .iter()
            .zip(problem.segment_times())
            .enumerate()
        {
            if j > 0 || init.from_rest {
                let w1 = problem.omega_after_switch(prev.as_ref(), push, omega);
                rec.checker
                    .switch(prev.as_ref(), omega, push, w1, span.0, j);
                omega = w1;
            }
            prev = Some(*push);
            let seg = self.segment(
                body,
                push,
                j,
                span,
                j + 1 == n_seg,
                omega,
                r_min,
                &mut rec.checker,
            );
            let mut report = SegmentReport {
                index: j,
                t_start: seg.t0,
                t_end: seg.t1,
                omega_start: omega,
                ..Default::default()
            };
            // Segment start: the state just after the switch.
            rec.samples_until(&seg, seg.t0, |_| (c, theta, omega));
            let mut closed_form = seg.closed_form_at_start(c, theta, omega);
            if push.speed == 0.0 {
                (theta, omega, report.settled_at) = hold(&seg, &mut rec, c, theta, omega);
            } else if closed_form.is_none() {
                let (y, tail) =
                    self.integrate(&seg, &mut rec, &mut h_carry, [theta, omega, c.x, c.y])?;
                (c, theta, omega) = pose_of(&y);
                closed_form = tail;
            }
            if let Some(tail) = closed_form {
                report.settled_at = Some(tail.t);
                (c, theta, omega) = rec.samples_of_tail(&seg, tail);
            }
            report.omega_end = omega;
            rec.out.segments.push(report);
        }
        rec.out.assumptions = rec.checker.finish();
        Ok(rec.out)
    }
}
