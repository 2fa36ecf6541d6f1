//! The dynamic model as a [`Simulator`]. Per segment: the switch, the
//! analysis of ω̇ (the root ω tends to, a runaway, a pivot, the series tail),
//! then the closed form where there is one and an integrator (`adaptive`,
//! `rk4`) where there is not.

use super::checker::Checker;
use super::push_cache::PushCache;
use super::segment::{pose_of, Closed, Recorder, SegmentRun};
use super::{adaptive, rk4, SegmentReport, Trajectory};
use crate::dynamic::{SegmentDynamics, SteadyState};
use crate::integrate::State;
use crate::tail::ends::EndSeries;
use crate::tail::SettleRule;
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

impl DynamicModel {
    /// The integrator's tolerance or step must be finite and > 0.
    pub(super) fn check_integrator(&self) -> Result<(), ModelError> {
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
    /// `spare`: the previous segment's dynamics on the same `body` and
    /// inertial term, of which only the push's part is redone;
    /// `dir`: the push direction `n_φ`; `cache`: what is kept per push
    /// between runs (the same analysis, spared).
    #[allow(clippy::too_many_arguments)]
    fn segment(
        &self,
        cache: Option<&mut PushCache>,
        spare: Option<SegmentDynamics>,
        body: &Body,
        push: &Push,
        dir: Vec2,
        index: usize,
        (t0, t1): (f64, f64),
        last: bool,
        omega: f64,
        r_min: f64,
        ends_only: bool,
        checker: &mut Checker,
    ) -> SegmentRun {
        let dynamics = match spare {
            // The previous segment's, on the same body: only the push changes.
            Some(mut d) => {
                d.repush(push, dir, self.inertial_term);
                d
            }
            None => SegmentDynamics::with_inertial_term(body, push, self.inertial_term),
        };
        let mut cached = cache.map(|c| (c.entry(push), c));
        let target = match &mut cached {
            _ if push.speed <= 0.0 => None,
            Some((i, c)) => c.attractor(*i, &dynamics, omega),
            None => dynamics.attractor_from(omega),
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
        let stable = match target {
            Some(SteadyState {
                kind: RootKind::Stable,
                tau: Some(tau),
                omega: ws,
            }) if self.skip_settled && tau > 0.0 => Some(ws),
            _ => None,
        };
        // A run that samples follows the series in E; one that wants the
        // end alone, the series in δ (the same closed form, cheaper).
        let (settle, ends) = match stable {
            Some(ws) if ends_only => {
                // As many terms as the check at the segment's start asks for
                // (with the bound 1.25 |δ₀|); that check decides.
                let reach = (omega - ws).abs();
                let fresh = || EndSeries::new(&dynamics, ws, reach, push.speed, t1 - t0, tol);
                let ends: Option<EndSeries> = match cached {
                    Some((i, c)) => {
                        c.memo(i, ws, |s| s.cut(reach, push.speed, t1 - t0, tol), fresh)
                    }
                    None => fresh(),
                };
                (None, ends)
            }
            Some(ws) => (SettleRule::new(&dynamics, ws, tol, omega, t1 - t0), None),
            None => (None, None),
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
            vel: dir * push.speed,
            tol,
            settle,
            ends,
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
    ) -> Result<(State, Option<Closed>), ModelError> {
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

/// Where a run of the dynamic model ended: the contact point (world, m),
/// θ (rad) and ω (rad/s) at the end of the schedule, and the contact
/// velocity of the last push (object frame, m/s).
#[derive(Debug, Clone, Copy)]
pub(super) struct RunEnd {
    pub(super) c: Vec2,
    pub(super) theta: f64,
    pub(super) omega: f64,
    pub(super) vel: Vec2,
}

impl DynamicModel {
    /// Walks `problem`'s segments (switch, analysis of ω̇, closed form or
    /// integrator), recording into `rec` the samples its sampler hands out
    /// and, with `reports`, one [`SegmentReport`] per segment. `problem`
    /// and the integrator have been checked. `cache`: kept per push between
    /// runs (bound to the problem's body here).
    pub(super) fn run(
        &self,
        problem: &Problem,
        rec: &mut Recorder,
        reports: bool,
        mut cache: Option<&mut PushCache>,
    ) -> Result<RunEnd, ModelError> {
        if let Some(c) = cache.as_deref_mut() {
            c.bind(&problem.body, self.inertial_term);
        }
        let body = &problem.body;
        let pc = body.contact();
        let init = problem.initial;
        let mut theta = init.theta;
        let mut c = init.position + rotate(theta, &pc);
        let mut omega = if init.from_rest { 0.0 } else { init.omega };
        let mut prev: Option<Push> = problem.pushes.first().copied().filter(|_| !init.from_rest);
        // The contact velocity of `prev` (object frame, m/s): each push's
        // direction is computed once.
        let mut prev_vel: Option<Vec2> = prev.as_ref().map(Push::velocity);
        let mut h_carry: Option<(f64, f64)> = None;
        let r_min = body
            .supports()
            .map(|s| (s.position - pc).norm())
            .filter(|r| *r > 0.0)
            .fold(f64::INFINITY, f64::min);
        let n_seg = problem.pushes.len();
        let ends_only = rec.ends_only;
        if reports {
            rec.out.segments.reserve_exact(n_seg);
        }
        // One set of per-support arrays for the whole run.
        let mut spare: Option<SegmentDynamics> = None;
        let mut vel = Vec2::zeros();
        // Segment spans as `Problem::segment_times` gives them (the same
        // running sum), without collecting them.
        let mut t_end = 0.0;
        for (j, push) in problem.pushes.iter().enumerate() {
            let span = (t_end, t_end + push.duration);
            t_end = span.1;
            let dir = push.direction();
            vel = dir * push.speed;
            if j > 0 || init.from_rest {
                let w1 = problem.omega_after_switch_at(prev_vel, vel, omega);
                rec.checker
                    .switch(prev.as_ref(), omega, push, w1, span.0, j);
                omega = w1;
            }
            prev = Some(*push);
            prev_vel = Some(vel);
            let seg = self.segment(
                cache.as_deref_mut(),
                spare.take(),
                body,
                push,
                dir,
                j,
                span,
                j + 1 == n_seg,
                omega,
                r_min,
                ends_only,
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
                (theta, omega, report.settled_at) = hold(&seg, rec, c, theta, omega);
            } else if closed_form.is_none() {
                let (y, tail) =
                    self.integrate(&seg, rec, &mut h_carry, [theta, omega, c.x, c.y])?;
                (c, theta, omega) = pose_of(&y);
                closed_form = tail;
            }
            if let Some(closed) = closed_form {
                report.settled_at = Some(closed.start());
                (c, theta, omega) = rec.finish_closed(&seg, closed);
            }
            report.omega_end = omega;
            if reports {
                rec.out.segments.push(report);
            }
            spare = Some(seg.dynamics);
        }
        Ok(RunEnd {
            c,
            theta,
            omega,
            vel,
        })
    }
}

impl Simulator for DynamicModel {
    fn name(&self) -> String {
        "dynamic".into()
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        problem.check()?;
        self.check_integrator()?;
        let mut rec = Recorder::new(problem, self.name(), self.check_assumptions);
        let end = self.run(problem, &mut rec, true, None)?;
        rec.out.assumptions = rec.checker.finish();
        if let Some(release) = &problem.release {
            let vel = (!problem.pushes.is_empty()).then_some(end.vel);
            let start = crate::slide::release_state(problem, end.c, end.theta, end.omega, vel);
            crate::slide::continue_run(problem, release, start, &mut rec.out)?;
        }
        Ok(rec.out)
    }
}
