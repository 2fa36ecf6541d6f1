//! Sampled trajectories, the per-run assumption report, and the three analytic
//! models as [`Simulator`]s.

use crate::tail::{SettleRule, Tail, TailCursor, TailPose};
use crate::{
    dynamic::SegmentDynamics, dynamic::SteadyState, integrate, kinematic, limit_surface, perp,
    rotate, Body, ModelError, Problem, Push, Rotor, Simulator, Vec2,
};

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
    pub index: usize,
    /// Start and end time (s).
    pub t_start: f64,
    pub t_end: f64,
    /// ω just after the switch into this segment and at its end (rad/s).
    pub omega_start: f64,
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
}

/// Which integrator the dynamic model uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integrator {
    /// Dormand–Prince 5(4) with dense output; per-step error ≤ `tol` (m, rad)
    /// in θ and the position, and ≤ `tol (1 + |ω|)` in ω (RMS over the state).
    Adaptive { tol: f64 },
    /// Dormand & Prince's 8(5,3) pair (DOP853) with its 7th-order dense
    /// output; the same error measure as `Adaptive`.
    Dop853 { tol: f64 },
    /// Classical RK4, fixed step at most `dt` (s), shortened so every switch
    /// falls on a step; samples by cubic Hermite interpolation.
    Rk4 { dt: f64 },
}

/// Dense output of either adaptive method over one accepted step.
enum AnyDense {
    Five(integrate::Dense),
    Eight(integrate::dop853::Dense),
    /// No sample in the step: nothing built.
    None,
}

impl AnyDense {
    fn eval(&self, t: f64) -> integrate::State {
        match self {
            AnyDense::Five(d) => d.eval(t),
            AnyDense::Eight(d) => d.eval(t),
            AnyDense::None => unreachable!("dense output is built for every step holding a sample"),
        }
    }
}

/// The dynamic model as a [`Simulator`] (name `"dynamic"`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicModel {
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

/// Accumulates the assumption checks over a run.
struct Checker<'a> {
    problem: &'a Problem,
    out: Assumptions,
    enabled: bool,
}

impl<'a> Checker<'a> {
    fn new(problem: &'a Problem, enabled: bool) -> Self {
        Self {
            problem,
            out: Assumptions {
                min_support_speed: f64::INFINITY,
                ..Default::default()
            },
            enabled,
        }
    }

    #[inline(always)]
    fn sample(&mut self, seg: &SegmentDynamics, omega: f64, t: f64, segment: usize) {
        if self.enabled {
            self.check(seg, omega, t, segment);
        }
    }

    fn check(&mut self, seg: &SegmentDynamics, omega: f64, t: f64, segment: usize) {
        let lim = &self.problem.limits;
        let f = seg.pusher_force(omega);
        let fm = f.norm();
        let angle = lim.cone_angle(&f);
        let o = &mut self.out;
        o.max_force = o.max_force.max(fm);
        o.max_cone_angle = o.max_cone_angle.max(angle);
        let gt = |a: f64, b: f64| a > b;
        if angle > std::f64::consts::FRAC_PI_2 + 1e-9 {
            Violation::record(&mut o.pulling, t, angle, segment, None, gt);
        }
        if let Some(mu) = lim.mu {
            if angle > mu.atan() + 1e-9 {
                Violation::record(&mut o.contact_slip, t, angle, segment, None, gt);
            }
        }
        if let Some(fmax) = lim.max_force {
            if fm > fmax {
                Violation::record(&mut o.force_limit, t, fm, segment, None, gt);
            }
        }
        if seg.speed() > 0.0 {
            let (u, i) = seg.min_support_speed(omega);
            o.min_support_speed = o.min_support_speed.min(u);
            if u < 1e-6 * seg.speed() {
                Violation::record(&mut o.sticking, t, u, segment, Some(i), |a, b| a < b);
            }
        }
    }

    fn switch(
        &mut self,
        before: Option<&Push>,
        w0: f64,
        after: &Push,
        w1: f64,
        t: f64,
        segment: usize,
    ) {
        if !self.enabled {
            return;
        }
        let pc = self.problem.body.contact();
        let vcm = |p: Option<&Push>, w: f64| {
            p.map(|p| p.velocity()).unwrap_or_else(Vec2::zeros) - perp(&pc) * w
        };
        let j = (vcm(Some(after), w1) - vcm(before, w0)) * self.problem.body.mass();
        let scale = self.problem.body.mass() * (after.speed + before.map_or(0.0, |p| p.speed));
        if j.norm() > 1e-9 * scale.max(1e-300) {
            let angle = self.problem.limits.cone_angle(&j);
            if angle > std::f64::consts::FRAC_PI_2 + 1e-9 {
                Violation::record(
                    &mut self.out.pulling_impulse,
                    t,
                    angle,
                    segment,
                    None,
                    |a, b| a > b,
                );
            }
        }
    }

    fn finish(mut self) -> Assumptions {
        if !self.out.min_support_speed.is_finite() {
            self.out.min_support_speed = 0.0;
        }
        self.out
    }
}

/// Sample bookkeeping shared by the models: which sample times fall in a segment.
struct Sampler {
    times: Vec<f64>,
    next: usize,
    eps: f64,
}

impl Sampler {
    fn new(problem: &Problem) -> Self {
        Self {
            times: problem.sample_times(),
            next: 0,
            eps: 1e-9 * problem.sample_dt,
        }
    }
    /// The next sample time if it lies at or before `t` and inside the segment
    /// ending at `t_end` (the last segment owns its end time).
    fn due(&self, t: f64, t_end: f64, last: bool) -> Option<f64> {
        let ts = *self.times.get(self.next)?;
        let inside = last || ts < t_end - self.eps;
        (inside && ts <= t + self.eps).then_some(ts)
    }
}

/// The sample at time `t` from the contact point `c` and the angle; `rotor`
/// serves `R(θ)` (samples come in order, so θ moves little between them).
fn pose_sample(rotor: &mut Rotor, t: f64, c: Vec2, theta: f64, omega: f64, pc: &Vec2) -> Sample {
    let (s, co) = rotor.sin_cos(theta);
    let p = c - Vec2::new(co * pc.x - s * pc.y, s * pc.x + co * pc.y);
    Sample {
        t,
        x: p.x,
        y: p.y,
        theta,
        omega,
    }
}

impl Simulator for DynamicModel {
    fn name(&self) -> String {
        "dynamic".into()
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        problem.check()?;
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
        let body = &problem.body;
        let pc = body.contact();
        let mut sampler = Sampler::new(problem);
        let mut out = Trajectory {
            model: self.name(),
            samples: Vec::with_capacity(sampler.times.len()),
            ..Default::default()
        };
        let mut checker = Checker::new(problem, self.check_assumptions);
        let mut sample_rotor = Rotor::new();
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
        for (j, (push, (t0, t1))) in problem
            .pushes
            .iter()
            .zip(problem.segment_times())
            .enumerate()
        {
            let last = j + 1 == n_seg;
            if j > 0 || init.from_rest {
                let w1 = problem.omega_after_switch(prev.as_ref(), push, omega);
                checker.switch(prev.as_ref(), omega, push, w1, t0, j);
                omega = w1;
            }
            prev = Some(*push);
            let seg = SegmentDynamics::with_inertial_term(body, push, self.inertial_term);
            let mut report = SegmentReport {
                index: j,
                t_start: t0,
                t_end: t1,
                omega_start: omega,
                ..Default::default()
            };
            let target = if push.speed > 0.0 {
                seg.attractor_from(omega)
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
                match target {
                    None if checker.enabled => {
                        Violation::record(
                            &mut checker.out.runaway,
                            t0,
                            omega.abs(),
                            j,
                            None,
                            |a, b| a > b,
                        );
                    }
                    Some(SteadyState {
                        kind: crate::RootKind::Pivot { support, .. },
                        ..
                    }) if checker.enabled => {
                        Violation::record(
                            &mut checker.out.sticking,
                            t0,
                            0.0,
                            j,
                            Some(support),
                            |a, b| a < b,
                        );
                    }
                    _ => {}
                }
            }
            let vel = push.velocity();
            let tol = match self.integrator {
                Integrator::Adaptive { tol } | Integrator::Dop853 { tol } => tol,
                Integrator::Rk4 { dt } => dt.powi(4),
            };
            let settle = match target {
                Some(SteadyState {
                    kind: crate::RootKind::Stable,
                    tau: Some(tau),
                    omega: ws,
                }) if self.skip_settled && tau > 0.0 => {
                    SettleRule::new(&seg, ws, tol, omega, t1 - t0)
                }
                _ => None,
            };
            let try_tail = |t: f64, c: Vec2, theta: f64, w: f64| {
                settle
                    .as_ref()
                    .and_then(|r| r.tail(&seg, t, c, theta, w, vel, t1 - t))
            };
            // A stable pivot is reached in finite time (ω̇ jumps there); past
            // it the support sticks and the object turns about it at the
            // constant ω_p. Integrating across the jump would chatter, so the
            // step is aimed at the pivot and the motion continues as an arc.
            let pivot = match target {
                Some(SteadyState {
                    kind: crate::RootKind::Pivot { stable: true, .. },
                    omega: wp,
                    ..
                }) => Some(wp),
                _ => None,
            };
            let pivot_reached = |w0: f64, w1: f64| {
                pivot.is_some_and(|wp| {
                    (w1 - wp).abs() <= 10.0 * tol * (1.0 + wp.abs())
                        || (w1 - wp).signum() != (w0 - wp).signum()
                })
            };
            let pivot_tail =
                |t: f64, c: Vec2, theta: f64| Tail::arc(t, c, theta, pivot.unwrap_or(0.0), vel);

            // Segment start: the state just after the switch.
            while let Some(ts) = sampler.due(t0, t1, last) {
                out.samples
                    .push(pose_sample(&mut sample_rotor, ts, c, theta, omega, &pc));
                checker.sample(&seg, omega, ts, j);
                sampler.next += 1;
            }

            let mut t = t0;
            let mut settle_state: Option<Tail> = if pivot_reached(omega, omega) {
                Some(pivot_tail(t0, c, theta))
            } else {
                try_tail(t0, c, theta, omega)
            };

            if push.speed == 0.0 {
                // The contact point is held: the object pivots about it and
                // friction (moment −sign(ω) Σ F_i |r_i|) stops it in finite time.
                let alpha = seg.max_moment() / seg.inertia_contact();
                let w0 = omega;
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
                while let Some(ts) = sampler.due(t1, t1, last) {
                    let (th, w) = state_at(ts - t0);
                    out.samples
                        .push(pose_sample(&mut sample_rotor, ts, c, th, w, &pc));
                    checker.sample(&seg, w, ts, j);
                    sampler.next += 1;
                }
                let (th, w) = state_at(t1 - t0);
                theta = th;
                omega = w;
                if t_stop.is_finite() && t_stop <= t1 - t0 {
                    report.settled_at = Some(t0 + t_stop);
                }
            } else if settle_state.is_none() {
                let mut rotor = Rotor::new();
                let mut rhs = |y: &integrate::State| {
                    let (s, co) = rotor.sin_cos(y[0]);
                    [
                        y[1],
                        seg.omega_dot(y[1]),
                        co * vel.x - s * vel.y,
                        s * vel.x + co * vel.y,
                    ]
                };
                let mut y = [theta, omega, c.x, c.y];
                let mut k1 = rhs(&y);
                out.stats.rhs_evals += 1;
                match self.integrator {
                    Integrator::Adaptive { tol } | Integrator::Dop853 { tol } => {
                        let eighth = matches!(self.integrator, Integrator::Dop853 { .. });
                        // Relative tolerance on ω only: the angle and the
                        // position depend on the choice of frame, and their
                        // error must not (invariance under rigid motion).
                        let rtol = [0.0, tol, 0.0, 0.0];
                        // A switch changes ω̇ by orders of magnitude: the step
                        // carried over from a settled segment would be
                        // rejected (12 evaluations), a fresh estimate costs one.
                        let order = if eighth { 7 } else { 4 };
                        // On a relaxation the local error is proportional to the
                        // distance from the steady state, so the step carried
                        // over shrinks by (distance then / distance now)^(1/8);
                        // otherwise the usual starting-step estimate.
                        let dev_new = settle.map(|r| (omega - r.omega).abs());
                        let mut h = match (h_carry, dev_new) {
                            (Some((hc, dev_old)), Some(dn)) if dev_old > 0.0 && dn > 0.0 => {
                                hc * (dev_old / dn).powf(1.0 / (order as f64 + 2.0)).min(1.0)
                            }
                            _ => {
                                out.stats.rhs_evals += 1;
                                let h0 = integrate::initial_step(
                                    &mut rhs,
                                    &y,
                                    &k1,
                                    tol,
                                    &rtol,
                                    order,
                                    t1 - t0,
                                );
                                h_carry.map_or(h0, |(hc, _)| hc.min(h0))
                            }
                        };
                        while t < t1 {
                            let mut landing = t + h >= t1 - 1e-12 * t1.abs().max(1.0);
                            let mut hh = if landing { t1 - t } else { h };
                            if let Some(wp) = pivot {
                                // Aim at the pivot by the local ω̇ (smooth on this side).
                                let t_hit = (wp - y[1]) / k1[1];
                                if t_hit > 0.0 && t_hit < hh {
                                    hh = t_hit;
                                    landing = false;
                                }
                            }
                            let (a5, a8) = if eighth {
                                out.stats.rhs_evals += 12;
                                (
                                    None,
                                    Some(integrate::dop853::attempt(
                                        &mut rhs, &y, &k1, hh, tol, &rtol,
                                    )),
                                )
                            } else {
                                out.stats.rhs_evals += 6;
                                (
                                    Some(integrate::dp5_attempt(&mut rhs, &y, &k1, hh, tol, &rtol)),
                                    None,
                                )
                            };
                            let (err, y1, k_next) = match (&a5, &a8) {
                                (Some(a), _) => (a.err, a.y1, a.k7),
                                (_, Some(a)) => (a.err, a.y1, a.k13),
                                _ => unreachable!("one method ran"),
                            };
                            if err <= 1.0 {
                                let t_new = if landing { t1 } else { t + hh };
                                // DOP853's interpolant costs three evaluations:
                                // build it only for steps that hold a sample.
                                let dense = match (&a5, &a8) {
                                    (Some(a), _) => AnyDense::Five(a.dense(t, &y, hh)),
                                    (_, Some(a)) if sampler.due(t_new, t1, last).is_some() => {
                                        out.stats.rhs_evals += 3;
                                        AnyDense::Eight(a.dense(&mut rhs, t, &y, hh))
                                    }
                                    _ => AnyDense::None,
                                };
                                while let Some(ts) = sampler.due(t_new, t1, last) {
                                    let ys = dense.eval(ts);
                                    out.samples.push(pose_sample(
                                        &mut sample_rotor,
                                        ts,
                                        Vec2::new(ys[2], ys[3]),
                                        ys[0],
                                        ys[1],
                                        &pc,
                                    ));
                                    checker.sample(&seg, ys[1], ts, j);
                                    sampler.next += 1;
                                }
                                let w_before = y[1];
                                y = y1;
                                k1 = k_next;
                                t = t_new;
                                out.stats.steps += 1;
                                if t < t1
                                    && (pivot_reached(w_before, y[1])
                                        || (pivot.is_some() && hh < 1e-12 * t.abs().max(1.0)))
                                {
                                    settle_state = Some(pivot_tail(t, Vec2::new(y[2], y[3]), y[0]));
                                    break;
                                }
                                if !y.iter().all(|v| v.is_finite()) {
                                    return Err(ModelError::NonFinite {
                                        t,
                                        step: out.stats.steps,
                                    });
                                }
                                if y[1].abs() > omega_limit {
                                    return Err(ModelError::Runaway {
                                        t,
                                        step: out.stats.steps,
                                        omega: y[1],
                                        limit: omega_limit,
                                    });
                                }
                                let hn = if eighth {
                                    integrate::next_step8(hh, err)
                                } else {
                                    integrate::next_step(hh, err)
                                };
                                if !landing || hn < h {
                                    h = hn;
                                }
                                if t < t1 {
                                    if let Some(tl) = try_tail(t, Vec2::new(y[2], y[3]), y[0], y[1])
                                    {
                                        settle_state = Some(tl);
                                        break;
                                    }
                                }
                            } else {
                                out.stats.rejected += 1;
                                h = if eighth {
                                    integrate::next_step8(hh, err)
                                } else {
                                    integrate::next_step(hh, err)
                                };
                                if !(h > 1e-14 * t.abs().max(1.0)) {
                                    return Err(ModelError::Integration {
                                        t,
                                        reason: format!("step size underflow (h = {h:e} s)"),
                                    });
                                }
                            }
                        }
                        let dev = settle.map_or(f64::NAN, |r| (y[1] - r.omega).abs());
                        h_carry = Some((h, dev));
                    }
                    Integrator::Rk4 { dt } => {
                        let n = ((t1 - t0) / dt - 1e-9).ceil().max(1.0) as usize;
                        let h = (t1 - t0) / n as f64;
                        for step in 0..n {
                            let y1 = integrate::rk4_step(&mut rhs, &y, &k1, h);
                            let k2 = rhs(&y1);
                            out.stats.rhs_evals += 4;
                            let t_new = if step + 1 == n {
                                t1
                            } else {
                                t0 + (step + 1) as f64 * h
                            };
                            while let Some(ts) = sampler.due(t_new, t1, last) {
                                let ys = integrate::hermite(t, t_new - t, &y, &k1, &y1, &k2, ts);
                                out.samples.push(pose_sample(
                                    &mut sample_rotor,
                                    ts,
                                    Vec2::new(ys[2], ys[3]),
                                    ys[0],
                                    ys[1],
                                    &pc,
                                ));
                                checker.sample(&seg, ys[1], ts, j);
                                sampler.next += 1;
                            }
                            let w_before = y[1];
                            y = y1;
                            k1 = k2;
                            t = t_new;
                            out.stats.steps += 1;
                            if t < t1 && pivot_reached(w_before, y[1]) {
                                // First order in h here: RK4 is kept for benchmarks.
                                settle_state = Some(pivot_tail(t, Vec2::new(y[2], y[3]), y[0]));
                                break;
                            }
                            if !y.iter().all(|v| v.is_finite()) {
                                return Err(ModelError::NonFinite {
                                    t,
                                    step: out.stats.steps,
                                });
                            }
                            if y[1].abs() > omega_limit {
                                return Err(ModelError::Runaway {
                                    t,
                                    step: out.stats.steps,
                                    omega: y[1],
                                    limit: omega_limit,
                                });
                            }
                            if t < t1 {
                                if let Some(tl) = try_tail(t, Vec2::new(y[2], y[3]), y[0], y[1]) {
                                    settle_state = Some(tl);
                                    break;
                                }
                            }
                        }
                    }
                }
                theta = y[0];
                omega = y[1];
                c = Vec2::new(y[2], y[3]);
            }
            if let Some(tail) = settle_state {
                report.settled_at = Some(tail.t);
                let from = out.samples.len();
                let p = sample_tail(tail, &mut sampler, t1, last, pc, &mut out.samples);
                if checker.enabled {
                    for k in from..out.samples.len() {
                        let smp = out.samples[k];
                        checker.sample(&seg, smp.omega, smp.t, j);
                    }
                }
                (c, theta, omega) = (p.c, p.theta, p.omega);
            }
            report.omega_end = omega;
            out.segments.push(report);
        }
        out.assumptions = checker.finish();
        Ok(out)
    }
}

/// Samples a closed-form tail at the sample times due up to `t1` (the end of
/// its segment; `last` for the last segment, which owns its end time) and
/// returns its pose at `t1`.
fn sample_tail(
    tail: Tail,
    sampler: &mut Sampler,
    t1: f64,
    last: bool,
    pc: Vec2,
    out: &mut Vec<Sample>,
) -> TailPose {
    let mut cursor = TailCursor::new(tail);
    let first = sampler.next;
    // Every sample `due` would hand out up to t1 (times increase).
    let (eps, times) = (sampler.eps, &sampler.times[first..]);
    sampler.next += times.partition_point(|&ts| (last || ts < t1 - eps) && ts <= t1 + eps);
    cursor.fill(&sampler.times[first..sampler.next], pc, out);
    cursor.eval(t1)
}

/// Runs a model whose ω is constant over each segment: the pose follows
/// closed-form arcs, nothing is integrated.
fn constant_omega_run(
    problem: &Problem,
    name: &str,
    omega_of: impl Fn(&Body, &Push) -> f64,
) -> Result<Trajectory, ModelError> {
    problem.check()?;
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
