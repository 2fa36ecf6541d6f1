//! `pushval plan`: a push schedule that takes the object to a goal pose on a
//! model.
//!
//! The unknowns are `N` push directions and the total duration, written
//! unconstrained: `φ_k = c + h tanh(u_k)` keeps every direction inside the
//! pushing cone `[c − h, c + h]` ([`push_cone`]) and `T = T_ref e^s` keeps
//! the duration positive. Levenberg–Marquardt on the three residuals (x, y,
//! and the angle times the radius of gyration) takes the minimum-norm step,
//! `δ = −Jᵀ (J Jᵀ + λ I)⁻¹ r`; the Jacobian is taken by forward differences
//! once and then kept by Broyden's rank-one update, taken again only when a
//! step fails. Written here rather than with the `levenberg-marquardt`
//! crate: that crate solves over-determined problems (m ≥ n) by QR, and this
//! one is under-determined (3 residuals, N + 1 unknowns), where the
//! minimum-norm step through the 3 × 3 system is both the right step and
//! the cheap one; the warm-started Broyden Jacobian is what makes an MPC
//! period cost one or two model runs.

use std::time::Instant;

use anyhow::Context;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use pushval_model::{
    cross, perp, DynamicModel, Initial, Integrator, ModelError, Problem, Push, SegmentDynamics,
    Simulator, Switching, Trajectory, Vec2,
};

use super::{gyration_length, pose_errors, push_cone, Goal, Predictor, Reach};

/// The state a plan starts from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// Object angle (rad).
    pub theta: f64,
    /// World position of the centre of mass (m).
    pub position: Vec2,
    /// How it moves when the plan starts.
    pub motion: Motion,
}

/// How the object moves when a plan starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// At rest: the first push is a switch from rest.
    Rest,
    /// Moving: ω (rad/s) and the angular momentum about the world point
    /// under the contact (kg m²/s), which an impulsive switch keeps.
    Moving {
        /// Angular velocity just before the plan's first push (rad/s).
        omega: f64,
        /// `I_cm ω + m (r_cm − r_P) × v_cm` (kg m²/s).
        momentum: f64,
    },
}

impl Start {
    /// The problem's own start.
    pub fn of_problem(problem: &Problem) -> Self {
        let i = &problem.initial;
        Self {
            theta: i.theta,
            position: i.position,
            motion: if i.from_rest {
                Motion::Rest
            } else {
                Motion::Moving {
                    omega: i.omega,
                    momentum: f64::NAN,
                }
            },
        }
    }
}

/// What the plan is asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSpec {
    /// Number of pushes of equal duration.
    pub segments: usize,
    /// Pusher speed (m/s).
    pub speed: f64,
    /// The model the plan is made on.
    pub predictor: Predictor,
}

/// A predictor of final poses for one problem: the model, a working copy of
/// the problem (only its schedule and start change between calls), and the
/// count of model runs.
#[derive(Clone)]
pub struct Predict {
    problem: Problem,
    model: DynamicModel,
    predictor: Predictor,
    /// Model runs so far.
    pub runs: usize,
}

impl Predict {
    /// A predictor on `problem`'s body, contact and switching rule.
    pub fn new(problem: &Problem, predictor: Predictor) -> Self {
        Self {
            problem: problem.clone(),
            // 1e-9 per step: the pose it predicts is good to well under a
            // millimetre, far inside any goal tolerance, at a third of the
            // cost of the default 1e-10.
            model: DynamicModel {
                integrator: Integrator::Dop853 { tol: 1e-9 },
                skip_settled: true,
                check_assumptions: false,
                ..DynamicModel::default()
            },
            predictor,
            runs: 0,
        }
    }

    /// The problem of the plan `pushes` from `start`, sampled at its start
    /// and end only (or every `sample_dt` s when given).
    pub fn problem_of(&self, start: &Start, pushes: &[Push], sample_dt: Option<f64>) -> Problem {
        let mut p = self.problem.clone();
        self.set(&mut p, start, pushes, sample_dt);
        p
    }

    fn set(&self, p: &mut Problem, start: &Start, pushes: &[Push], sample_dt: Option<f64>) {
        p.pushes.clear();
        p.pushes.extend_from_slice(pushes);
        let total: f64 = pushes.iter().map(|q| q.duration).sum();
        p.sample_dt = sample_dt.unwrap_or(total);
        p.initial = match start.motion {
            Motion::Rest => Initial {
                theta: start.theta,
                omega: 0.0,
                position: start.position,
                from_rest: true,
                velocity: pushval_model::Vec2::zeros(),
            },
            Motion::Moving { omega, momentum } => {
                let first = &pushes[0];
                let w = match p.switching {
                    Switching::Impulsive if momentum.is_finite() => {
                        let body = &p.body;
                        (momentum + body.mass() * cross(&body.contact(), &first.velocity()))
                            / body.inertia_contact()
                    }
                    _ => omega,
                };
                Initial {
                    theta: start.theta,
                    omega: w,
                    position: start.position,
                    from_rest: false,
                    velocity: pushval_model::Vec2::zeros(),
                }
            }
        };
    }

    /// The final pose (x, y, θ) of `pushes` from `start`.
    pub fn final_pose(&mut self, start: &Start, pushes: &[Push]) -> Result<[f64; 3], ModelError> {
        let mut p = std::mem::replace(&mut self.problem, placeholder());
        self.set(&mut p, start, pushes, None);
        let out = self.simulate(&p);
        self.problem = p;
        self.runs += 1;
        let s = out?
            .samples
            .last()
            .copied()
            .ok_or(ModelError::EmptySchedule)?;
        if !(s.x.is_finite() && s.y.is_finite() && s.theta.is_finite()) {
            return Err(ModelError::NonFinite { t: s.t, step: 0 });
        }
        Ok([s.x, s.y, s.theta])
    }

    /// The predictor's trajectory of `problem`.
    pub fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        match self.predictor {
            Predictor::Dynamic => self.model.simulate(problem),
            Predictor::Kinematic => pushval_model::KinematicModel.simulate(problem),
            Predictor::LimitSurface => pushval_model::LimitSurfaceModel.simulate(problem),
        }
    }
}

/// An empty stand-in while the working problem is lent out.
fn placeholder() -> Problem {
    Problem {
        body: pushval_model::Body::new(
            1.0,
            1.0,
            Vec2::zeros(),
            &[pushval_model::Support {
                position: Vec2::new(1.0, 0.0),
                friction: 1.0,
            }],
        )
        .expect("a valid body"),
        limits: Default::default(),
        pushes: Vec::new(),
        initial: Initial::default(),
        switching: Switching::default(),
        sample_dt: 1.0,
        release: None,
    }
}

/// The longest plan, in straight-line times.
pub const MAX_TIME: f64 = 4.0;

/// The plan's unknowns and how they map to pushes.
#[derive(Debug, Clone)]
pub struct Params {
    /// `u_k`: φ_k = c + h tanh(u_k).
    pub u: Vec<f64>,
    /// `s`: T = T_ref e^s.
    pub s: f64,
}

/// The solver of one goal: the predictor, the goal, the cone, the scale of
/// the duration, and the Jacobian it carries between calls (warm starts).
#[derive(Clone)]
pub struct Planner {
    /// The model runs.
    pub predict: Predict,
    /// The goal.
    pub goal: Goal,
    spec: PlanSpec,
    cone: (f64, f64),
    t_ref: f64,
    weight: f64,
    jacobian: Option<DMatrix<f64>>,
    /// The stopping rule: position and angle errors on the predictor.
    pub target: Reach,
}

/// What one solve found.
#[derive(Debug, Clone)]
pub struct Solution {
    /// The unknowns.
    pub params: Params,
    /// The pushes.
    pub pushes: Vec<Push>,
    /// The predicted final pose (x, y, θ).
    pub pose: [f64; 3],
    /// Distance of the predicted final position from the goal (m).
    pub position_error: f64,
    /// Predicted angle error (rad).
    pub angle_error: f64,
    /// Whether the predicted final pose meets the planning target.
    pub converged: bool,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// The residual's norm (m; the angle weighed by the radius of gyration).
    pub residual: f64,
}

impl Solution {
    /// How far the plan ends from the goal (the residual's norm; m).
    pub fn score(&self) -> f64 {
        self.residual
    }
}

impl Planner {
    /// A planner for `goal` on `problem` (body, contact, switching rule).
    /// `t_ref`: the duration scale (s), e.g. the straight-line distance over
    /// the speed.
    pub fn new(problem: &Problem, goal: Goal, spec: PlanSpec, t_ref: f64, reach: Reach) -> Self {
        Self {
            predict: Predict::new(problem, spec.predictor),
            goal,
            spec,
            cone: push_cone(problem),
            t_ref: t_ref.max(1e-3),
            weight: gyration_length(problem),
            jacobian: None,
            // A twentieth of the success tolerance on the model, so that a
            // miss in an engine measures the engine, not the planner.
            target: Reach {
                position: reach.position / 20.0,
                angle: reach.angle / 20.0,
            },
        }
    }

    /// The pushes of `params` at the plan's speed.
    pub fn pushes(&self, params: &Params) -> Vec<Push> {
        let (lo, hi) = self.cone;
        let (c, h) = ((lo + hi) / 2.0, (hi - lo) / 2.0);
        let n = params.u.len();
        let duration = self.duration(params) / n as f64;
        params
            .u
            .iter()
            .map(|&u| Push {
                duration,
                speed: self.spec.speed,
                phi: c + h * u.tanh(),
            })
            .collect()
    }

    /// The duration of `params` (s): at most [`MAX_TIME`] times the
    /// straight-line time, so that a plan cannot wander (a plant that does
    /// not turn as predicted would otherwise be sent round ever longer loops).
    pub fn duration(&self, params: &Params) -> f64 {
        self.t_ref * params.s.min(MAX_TIME.ln()).exp()
    }

    /// The unknowns of a total duration `t` (s) with every direction at the
    /// middle of the cone plus `offset` (a share of the half-width, in (−1, 1)).
    pub fn initial_params(&self, t: f64, offset: f64) -> Params {
        Params {
            u: vec![offset.clamp(-0.99, 0.99).atanh(); self.spec.segments],
            s: (t / self.t_ref).ln(),
        }
    }

    /// The unknowns for a total duration `t` (s) that keep the directions of
    /// `params`.
    pub fn with_duration(&self, params: &Params, t: f64) -> Params {
        Params {
            u: params.u.clone(),
            s: (t.max(1e-6) / self.t_ref).ln(),
        }
    }

    fn residual(&mut self, start: &Start, params: &Params) -> Option<(Vector3<f64>, [f64; 3])> {
        let pushes = self.pushes(params);
        let pose = self.predict.final_pose(start, &pushes).ok()?;
        let r = Vector3::new(
            pose[0] - self.goal.x,
            pose[1] - self.goal.y,
            (pose[2] - self.goal.theta) * self.weight,
        );
        r.iter().all(|v| v.is_finite()).then_some((r, pose))
    }

    fn flat(params: &Params) -> DVector<f64> {
        let mut v = DVector::zeros(params.u.len() + 1);
        for (i, u) in params.u.iter().enumerate() {
            v[i] = *u;
        }
        v[params.u.len()] = params.s;
        v
    }

    fn unflat(v: &DVector<f64>) -> Params {
        let n = v.len() - 1;
        Params {
            u: v.as_slice()[..n].to_vec(),
            s: v[n],
        }
    }

    fn fd_jacobian(
        &mut self,
        start: &Start,
        z: &DVector<f64>,
        r0: &Vector3<f64>,
    ) -> Option<DMatrix<f64>> {
        let mut j = DMatrix::zeros(3, z.len());
        for k in 0..z.len() {
            let h = 1e-6 * (1.0 + z[k].abs());
            let mut zk = z.clone();
            zk[k] += h;
            let (rk, _) = self.residual(start, &Self::unflat(&zk))?;
            j.set_column(k, &((rk - r0) / h));
        }
        Some(j)
    }

    fn done(&self, pose: &[f64; 3]) -> bool {
        let (p, a) = pose_errors(pose[0], pose[1], pose[2], &self.goal);
        self.target.holds(p, a)
    }

    fn solution(&self, params: Params, pose: [f64; 3], iterations: usize) -> Solution {
        let (p, a) = pose_errors(pose[0], pose[1], pose[2], &self.goal);
        Solution {
            pushes: self.pushes(&params),
            params,
            pose,
            position_error: p,
            angle_error: a,
            converged: self.target.holds(p, a),
            iterations,
            residual: p.hypot(a * self.weight),
        }
    }

    /// Levenberg–Marquardt from `params`, at most `max_iter` steps. Keeps
    /// its Jacobian for the next call (a warm start).
    pub fn solve(&mut self, start: &Start, params: Params, max_iter: usize) -> Option<Solution> {
        let mut z = Self::flat(&params);
        let (mut r, mut pose) = self.residual(start, &params)?;
        if self.done(&pose) {
            return Some(self.solution(params, pose, 0));
        }
        let mut lambda = 1e-6;
        let mut fresh = false;
        let mut j = match self.jacobian.take() {
            Some(j) if j.ncols() == z.len() => j,
            _ => {
                fresh = true;
                self.fd_jacobian(start, &z, &r)?
            }
        };
        let mut iterations = 0;
        let mut fails = 0;
        while iterations < max_iter {
            iterations += 1;
            let jjt: Matrix3<f64> = (&j * j.transpose()).fixed_view::<3, 3>(0, 0).into_owned();
            let scale = jjt.trace() / 3.0;
            let a = jjt + Matrix3::identity() * (lambda * scale.max(1e-300));
            let Some(y) = a.lu().solve(&r) else {
                lambda *= 10.0;
                continue;
            };
            let mut dz = -(j.transpose() * DVector::from_column_slice(y.as_slice()));
            // Keep a step from throwing the directions far into tanh's flat
            // tails or the duration by more than a factor e.
            let big = dz.amax();
            if big > 1.0 {
                dz /= big;
            }
            let z_new = &z + &dz;
            match self.residual(start, &Self::unflat(&z_new)) {
                Some((r_new, pose_new)) if r_new.norm() < r.norm() => {
                    // Broyden's update of the Jacobian along the step.
                    let dr = r_new - r;
                    let pred = &j * &dz;
                    let corr = DVector::from_column_slice(
                        (dr - Vector3::from_column_slice(pred.as_slice())).as_slice(),
                    );
                    let denom = dz.norm_squared();
                    if denom > 0.0 {
                        j += corr * dz.transpose() / denom;
                    }
                    z = z_new;
                    r = r_new;
                    pose = pose_new;
                    lambda = (lambda / 3.0).max(1e-9);
                    fails = 0;
                    fresh = false;
                    if self.done(&pose) {
                        break;
                    }
                }
                _ => {
                    fails += 1;
                    if !fresh {
                        // A stale Jacobian: take it again where we stand.
                        j = self.fd_jacobian(start, &z, &r)?;
                        fresh = true;
                    } else {
                        lambda *= 8.0;
                    }
                    if fails > 12 {
                        break;
                    }
                }
            }
        }
        self.jacobian = Some(j);
        Some(self.solution(Self::unflat(&z), pose, iterations))
    }

    /// Drops the kept Jacobian (the next solve takes a fresh one).
    pub fn forget(&mut self) {
        self.jacobian = None;
    }

    /// A plan from `start`: Levenberg–Marquardt from a few starting guesses
    /// (the duration at one and at 1.6 times the straight-line time,
    /// directions at the cone's middle and either side), the first that
    /// converges, else the nearest.
    pub fn plan(&mut self, start: &Start) -> Option<Solution> {
        self.plan_with_time(start, self.t_ref, self.spec.segments)
    }

    /// [`Planner::plan`] with `segments` pushes and the starting guesses'
    /// durations scaled from `t0` (s).
    pub fn plan_with_time(&mut self, start: &Start, t0: f64, segments: usize) -> Option<Solution> {
        let mut best: Option<Solution> = None;
        for k in 0..GUESSES.len() {
            if let Some(s) = self.from_guess(start, t0, segments, k, 40) {
                if s.converged {
                    return Some(s);
                }
                if best.as_ref().is_none_or(|b| s.score() < b.score()) {
                    best = Some(s);
                }
            }
        }
        best
    }

    /// Levenberg–Marquardt from the `k`-th starting guess of
    /// [`Planner::plan_with_time`] alone (a fresh Jacobian, at most
    /// `max_iter` steps): one bounded stage of a search the loop spreads
    /// over control periods.
    pub fn from_guess(
        &mut self,
        start: &Start,
        t0: f64,
        segments: usize,
        k: usize,
        max_iter: usize,
    ) -> Option<Solution> {
        let (tm, off) = GUESSES[k % GUESSES.len()];
        self.forget();
        let mut p = self.initial_params(t0 * tm, off);
        p.u.truncate(segments.max(1));
        self.solve(start, p, max_iter)
    }

    /// Why the nearest plan misses: which of its unknowns sit at a limit.
    pub fn why_missed(&self, s: &Solution) -> String {
        let at_edge = s.params.u.iter().filter(|u| u.abs() > 3.0).count();
        let mut why = Vec::new();
        if at_edge > 0 {
            why.push(format!(
                "{at_edge} of {} push directions sit at the edge of the pushing cone [{:.3}, {:.3}] rad: the pusher only pushes, and the goal asks for a turn or a sideways move it cannot give over this distance",
                s.params.u.len(),
                self.cone.0,
                self.cone.1
            ));
        }
        let t = self.duration(&s.params);
        if t < 0.2 * self.t_ref {
            why.push(format!(
                "the duration shrank to {t:.3} s: the goal lies behind the pusher"
            ));
        }
        if why.is_empty() {
            why.push("no push sequence of this length and speed found a better pose (a local minimum: more segments or another speed may reach it)".into());
        }
        why.join("; ")
    }
}

/// The starting guesses of a plan: (duration as a multiple of the
/// reference time, direction offset from the cone's middle as a share of
/// its half-width).
pub const GUESSES: [(f64, f64); 7] = [
    (1.0, 0.0),
    (1.0, 0.5),
    (1.0, -0.5),
    (1.6, 0.0),
    (1.6, 0.5),
    (1.6, -0.5),
    (2.5, 0.0),
];

/// The straight-line time to the goal at `speed` (s), at least 0.1 s.
pub fn straight_time(start: &Start, goal: &Goal, speed: f64) -> f64 {
    let d = (goal.x - start.position.x).hypot(goal.y - start.position.y);
    (d / speed.max(1e-9)).max(0.1)
}

/// One switch's impulse against the contact's friction cone.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SwitchCheck {
    /// Index of the push switched into (0: the start).
    pub segment: usize,
    /// Time of the switch (s).
    pub t: f64,
    /// The pusher's impulse on the object (N s), object frame.
    pub impulse: [f64; 2],
    /// Its angle from the contact's normal cone (rad).
    pub cone_angle_rad: f64,
    /// The contact's friction angle, atan μ_c (rad); None without `[contact] mu`.
    pub friction_angle_rad: Option<f64>,
    /// Whether the impulse stays inside the friction cone.
    pub inside: bool,
    /// The shortest linear ramp of φ (s) over which the pusher's force,
    /// the steady force after the switch plus the impulse spread over the
    /// ramp, stays inside the friction cone; 0 when the impulse already is,
    /// None when no ramp does (the steady force itself is outside).
    pub ramp_s: Option<f64>,
}

/// Every switch of `pushes` from `start` on the dynamic model.
pub fn switch_checks(problem: &Problem, traj: &Trajectory, from_rest: bool) -> Vec<SwitchCheck> {
    let body = &problem.body;
    let pc = body.contact();
    let mu = problem.limits.mu;
    let vcm = |p: Option<&Push>, w: f64| {
        p.map(|p| p.velocity()).unwrap_or_else(Vec2::zeros) - perp(&pc) * w
    };
    let inside = |f: &Vec2| match mu {
        Some(mu) => problem.limits.cone_angle(f) <= mu.atan() + 1e-12,
        None => problem.limits.cone_angle(f) <= std::f64::consts::FRAC_PI_2,
    };
    let mut out = Vec::new();
    for (k, seg) in traj.segments.iter().enumerate() {
        let after = &problem.pushes[k];
        let (before, w0) = if k == 0 {
            if !from_rest {
                continue;
            }
            (None, 0.0)
        } else {
            (Some(&problem.pushes[k - 1]), traj.segments[k - 1].omega_end)
        };
        let w1 = seg.omega_start;
        let j = (vcm(Some(after), w1) - vcm(before, w0)) * body.mass();
        let angle = problem.limits.cone_angle(&j);
        let ok = j.norm() < 1e-12 || inside(&j);
        let ramp = if ok {
            Some(0.0)
        } else {
            let steady = SegmentDynamics::new(body, after).pusher_force(w1);
            if !inside(&steady) {
                None
            } else {
                // Bisection on log τ: inside for long ramps, outside for short.
                let (mut lo, mut hi) = (1e-6_f64.ln(), 100.0_f64.ln());
                if !inside(&(steady + j / hi.exp())) {
                    None
                } else {
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        if inside(&(steady + j / mid.exp())) {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    Some(hi.exp())
                }
            }
        };
        out.push(SwitchCheck {
            segment: k,
            t: seg.t_start,
            impulse: [j.x, j.y],
            cone_angle_rad: angle,
            friction_angle_rad: mu.map(|m| m.atan()),
            inside: ok,
            ramp_s: ramp,
        });
    }
    out
}

/// The scenario text with `pushes` as its schedule and the start set to
/// rest unless the file's `[initial]` says otherwise.
pub fn plan_toml(
    text: &str,
    file: &std::path::Path,
    pushes: &[Push],
    goal: &Goal,
    spec: &PlanSpec,
) -> anyhow::Result<String> {
    let mut doc: toml::Table =
        toml::from_str(text).with_context(|| format!("{}: not TOML", file.display()))?;
    let arr: Vec<toml::Value> = pushes
        .iter()
        .map(|p| {
            let mut t = toml::Table::new();
            t.insert("duration".into(), toml::Value::Float(p.duration));
            t.insert("speed".into(), toml::Value::Float(p.speed));
            t.insert("phi".into(), toml::Value::Float(p.phi));
            toml::Value::Table(t)
        })
        .collect();
    doc.insert("push".into(), toml::Value::Array(arr));
    let initial = doc
        .entry("initial")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    if let toml::Value::Table(t) = initial {
        t.entry("from_rest").or_insert(toml::Value::Boolean(true));
    }
    if let Some(toml::Value::String(d)) = doc.get_mut("description") {
        *d = format!(
            "{d} | plan: {} pushes at {} m/s to {goal}, made on the {} model",
            spec.segments,
            spec.speed,
            spec.predictor.as_str()
        );
    }
    Ok(format!(
        "# Written by `pushval plan`: the goal {goal} ({} predictor).\n{}",
        spec.predictor.as_str(),
        toml::to_string(&doc)?
    ))
}

/// What `pushval plan` reports.
pub struct PlanOutcome {
    /// The nearest plan found.
    pub solution: Solution,
    /// Milliseconds of the solve.
    pub solve_ms: f64,
    /// Model runs of the solve.
    pub runs: usize,
    /// The assumption checks of the dynamic model along the plan.
    pub assumptions: pushval_model::Assumptions,
    /// Each switch's impulse against the friction cone.
    pub switches: Vec<SwitchCheck>,
    /// Why it misses, when it does.
    pub why: Option<String>,
}

/// Plans `goal` on `problem` from its start.
pub fn make_plan(
    problem: &Problem,
    goal: Goal,
    spec: PlanSpec,
    reach: Reach,
) -> anyhow::Result<PlanOutcome> {
    let start = Start::of_problem(problem);
    let t_ref = straight_time(&start, &goal, spec.speed);
    let mut planner = Planner::new(problem, goal, spec, t_ref, reach);
    let clock = Instant::now();
    let solution = planner
        .plan(&start)
        .context("the predictor failed on every starting guess")?;
    let solve_ms = clock.elapsed().as_secs_f64() * 1e3;
    // The checks on the dynamic model, whatever the plan was made on.
    let checked = DynamicModel::default();
    let mut p = planner.predict.problem_of(&start, &solution.pushes, None);
    p.sample_dt = (problem.sample_dt).min(p.duration());
    let traj = checked.simulate(&p)?;
    let from_rest = matches!(start.motion, Motion::Rest);
    let switches = switch_checks(&p, &traj, from_rest);
    let why = (!solution.converged).then(|| planner.why_missed(&solution));
    Ok(PlanOutcome {
        runs: planner.predict.runs,
        solution,
        solve_ms,
        assumptions: traj.assumptions,
        switches,
        why,
    })
}
