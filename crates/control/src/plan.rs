//! Plans: a push schedule that takes the object to a goal pose on a
//! predictor.
//!
//! The unknowns are `N` push directions and the total duration, written
//! unconstrained: `φ_k = c + h tanh(u_k)` keeps every direction inside the
//! pushing cone `[c − h, c + h]` ([`push_cone`]) and `T = T_ref e^s` keeps
//! the duration positive. Levenberg–Marquardt on the three residuals (x, y,
//! and the angle times the radius of gyration) takes the minimum-norm step,
//! `δ = −Jᵀ (J Jᵀ + λ I)⁻¹ r`; the Jacobian is taken by forward differences
//! once and then kept by Broyden's rank-one update, taken again only when a
//! step fails. Written here rather than with the `levenberg-marquardt`
//! crate `fit` uses: that crate could take this problem made square (N + 1
//! regularising residuals that pull the unknowns towards the warm start),
//! but it asks its caller for a Jacobian at every iteration, N + 1 model
//! runs by finite differences each time, where Broyden's update here costs
//! none; the warm-started Jacobian carried from one control period to the
//! next is what makes an MPC period cost one or two model runs. The
//! minimum-norm step through the 3 × 3 system `J Jᵀ + λ I` is the
//! regularised least-squares step of the square problem in the limit of
//! small regularising weights.
//!
//! The search is bounded ([`Bounds`]): goals, speeds and durations outside
//! them are refused before any work, and the search for a plan tries more
//! pushes (up to [`MAX_SEGMENTS`]) and more starting guesses within a budget
//! of model runs before it calls a goal unreachable, and says what it
//! tried. A plan whose switch needs a pulling impulse is not a plan.

use std::time::Instant;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use pushval_model::{
    perp, DynamicModel, Problem, Push, SegmentDynamics, Simulator, Trajectory, Vec2,
};

use crate::predict::{ModelKind, ModelPredictor, Motion, Predictor, Start};
use crate::{gyration_length, pose_errors, push_cone, At, ControlError, Goal, Reach};

/// What the plan is asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSpec {
    /// Number of pushes of equal duration.
    pub segments: usize,
    /// Pusher speed (m/s).
    pub speed: f64,
    /// The model the plan is made on.
    pub predictor: ModelKind,
    /// When the plan is judged: at rest after the slide, or at the release.
    pub at: At,
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
    /// The predictor (it counts its model runs).
    pub predict: Box<dyn Predictor>,
    /// The goal.
    pub goal: Goal,
    spec: PlanSpec,
    cone: (f64, f64),
    t_ref: f64,
    weight: f64,
    jacobian: Option<DMatrix<f64>>,
    /// When set, the duration is fixed on a step grid (see
    /// [`Planner::on_grid`]).
    grid: Option<Grid>,
    /// The stopping rule: position and angle errors on the predictor.
    pub target: Reach,
}

/// A step grid for a plan's duration: `steps` steps of `dt` s in all.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Grid {
    dt: f64,
    steps: usize,
}

impl Grid {
    /// The whole steps of push `k` of `n`: the total split as evenly as
    /// whole steps allow (the counts differ by at most one).
    fn segment_steps(&self, k: usize, n: usize) -> usize {
        (k + 1) * self.steps / n - k * self.steps / n
    }
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
        Self::with_predictor(
            Box::new(ModelPredictor::new(problem, spec.predictor).judged_at(spec.at)),
            goal,
            spec,
            t_ref,
            reach,
        )
    }

    /// A planner on any predictor (its problem gives the contact's cone and
    /// the radius of gyration).
    pub fn with_predictor(
        predict: Box<dyn Predictor>,
        goal: Goal,
        spec: PlanSpec,
        t_ref: f64,
        reach: Reach,
    ) -> Self {
        let problem = predict.problem();
        Self {
            cone: push_cone(problem),
            weight: gyration_length(problem),
            predict,
            goal,
            spec,
            t_ref: t_ref.max(1e-3),
            jacobian: None,
            grid: None,
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
        let equal = self.duration(params) / n as f64;
        params
            .u
            .iter()
            .enumerate()
            .map(|(k, &u)| Push {
                duration: match self.grid {
                    Some(g) => g.segment_steps(k, n) as f64 * g.dt,
                    None => equal,
                },
                speed: self.spec.speed,
                phi: c + h * u.tanh(),
            })
            .collect()
    }

    /// The duration of `params` (s): at most [`MAX_TIME`] times the
    /// straight-line time, so that a plan cannot wander (a plant that does
    /// not turn as predicted would otherwise be sent round ever longer loops).
    pub fn duration(&self, params: &Params) -> f64 {
        match self.grid {
            Some(g) => g.steps as f64 * g.dt,
            None => self.t_ref * params.s.min(MAX_TIME.ln()).exp(),
        }
    }

    /// The plan `solution` re-solved with its total time on a step grid of
    /// `dt` (s): the nearest whole number of steps (at least one per push;
    /// fewer pushes when there are fewer steps than pushes), split over the
    /// pushes in whole steps, and the directions solved again for that
    /// fixed time. What the loop applies to a fixed-step plant is then
    /// exactly what it planned. None when the predictor fails.
    pub fn on_grid(&mut self, start: &Start, solution: &Solution, dt: f64) -> Option<Solution> {
        let total = self.duration(&solution.params);
        let steps = ((total / dt).round() as usize).max(1);
        let segments = solution.params.u.len().min(steps);
        let params = resample(&solution.params, segments);
        self.grid = Some(Grid { dt, steps });
        self.forget();
        let out = self.solve(start, params, 12);
        self.forget();
        self.grid = None;
        let mut out = out?;
        // Keep the grid's durations (the solve ran with the grid set).
        let grid = Grid { dt, steps };
        let n = out.pushes.len();
        for (k, p) in out.pushes.iter_mut().enumerate() {
            p.duration = grid.segment_steps(k, n) as f64 * dt;
        }
        out.params.s = (total.max(1e-9) / self.t_ref).ln();
        Some(out)
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
            if self.grid.is_some() {
                // The duration is fixed on the grid.
                let last = dz.len() - 1;
                dz[last] = 0.0;
            }
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

    /// The solution of `params` as it stands (its pose not yet predicted:
    /// NaN, not converged): what [`Planner::on_grid`] starts from.
    pub fn solution_of(&self, params: Params) -> Solution {
        Solution {
            pushes: self.pushes(&params),
            params,
            pose: [f64::NAN; 3],
            position_error: f64::NAN,
            angle_error: f64::NAN,
            converged: false,
            iterations: 0,
            residual: f64::NAN,
        }
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
        let all = GUESSES.len() + MORE_GUESSES.len();
        let k = k % all;
        let (tm, off) = if k < GUESSES.len() {
            GUESSES[k]
        } else {
            MORE_GUESSES[k - GUESSES.len()]
        };
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
                "in the nearest plan, {at_edge} of {} push directions sit at the edge of the pushing cone [{:.3}, {:.3}] rad (the pusher only pushes): the goal may ask for more turn or sideways move than pushes at this speed give over this distance",
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
        if self.grid.is_none() && s.params.s >= MAX_TIME.ln() {
            why.push(format!(
                "the duration reached its cap, {MAX_TIME} times the straight-line time ({t:.3} s)"
            ));
        }
        if why.is_empty() {
            why.push("the search ended in a local minimum (another speed may reach it)".into());
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

/// Starting guesses the search of [`make_plan`] adds once the first
/// number of pushes found no plan (as in [`GUESSES`]).
pub const MORE_GUESSES: [(f64, f64); 4] = [(1.3, 0.25), (1.3, -0.25), (2.0, 0.75), (2.0, -0.75)];

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

/// What a plan may be asked for: refused outside these, before any work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Slowest push (m/s).
    pub min_speed: f64,
    /// Fastest push (m/s).
    pub max_speed: f64,
    /// Longest straight-line time to the goal (s): distance over speed.
    pub max_straight_time: f64,
    /// Largest distance of the goal from the start (m).
    pub max_distance: f64,
    /// Largest turn asked for (rad).
    pub max_turn: f64,
    /// Model runs the whole search may spend before it gives up.
    pub max_runs: usize,
}

impl Default for Bounds {
    /// 1 mm/s to 20 m/s, 60 s of straight-line pushing, 100 m, two full
    /// turns, 20,000 model runs (about a second of the dynamic model).
    fn default() -> Self {
        Self {
            min_speed: 1e-3,
            max_speed: 20.0,
            max_straight_time: 60.0,
            max_distance: 100.0,
            max_turn: 4.0 * std::f64::consts::PI,
            max_runs: 20_000,
        }
    }
}

impl Bounds {
    /// Refuses a speed, a goal or a plan length outside the bounds.
    pub fn check(&self, start: &Start, goal: &Goal, spec: &PlanSpec) -> Result<(), ControlError> {
        let speed = spec.speed;
        if !(speed.is_finite() && speed >= self.min_speed && speed <= self.max_speed) {
            return Err(ControlError::Setting {
                name: "push speed (m/s)",
                requirement: format!("between {} and {}", self.min_speed, self.max_speed),
                value: speed,
            });
        }
        if !(1..=MAX_SEGMENTS).contains(&spec.segments) {
            return Err(ControlError::Setting {
                name: "pushes per plan",
                requirement: format!("1 to {MAX_SEGMENTS}"),
                value: spec.segments as f64,
            });
        }
        if !(goal.x.is_finite() && goal.y.is_finite() && goal.theta.is_finite()) {
            return Err(ControlError::GoalOutOfRange(format!(
                "{goal} is not finite"
            )));
        }
        let d = (goal.x - start.position.x).hypot(goal.y - start.position.y);
        if d > self.max_distance {
            return Err(ControlError::GoalOutOfRange(format!(
                "it is {d:.4e} m from the start; plans reach at most {} m",
                self.max_distance
            )));
        }
        let turn = (goal.theta - start.theta).abs();
        if turn > self.max_turn {
            return Err(ControlError::GoalOutOfRange(format!(
                "it asks for a turn of {turn:.4e} rad; plans turn at most {:.4} rad",
                self.max_turn
            )));
        }
        let t = d / speed;
        if t > self.max_straight_time {
            return Err(ControlError::GoalOutOfRange(format!(
                "at {speed} m/s it is {t:.4e} s of straight pushing away; plans last at most {} s of straight pushing ({} times that in all)",
                self.max_straight_time, MAX_TIME
            )));
        }
        Ok(())
    }
}

/// The most pushes a search tries.
pub const MAX_SEGMENTS: usize = 12;

/// One stage of the search: a number of pushes and the starting guesses
/// tried with it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Attempt {
    /// Pushes per plan.
    pub segments: usize,
    /// Starting guesses solved from.
    pub guesses: usize,
    /// The nearest pose's residual (m; the angle weighed by the radius of
    /// gyration), None when the predictor failed on every guess.
    pub best_residual_m: Option<f64>,
    /// Plans that reached the goal on the predictor but were refused
    /// because a switch needs a pulling impulse.
    pub refused_pulling: usize,
}

/// What a plan search reports.
pub struct PlanOutcome {
    /// The plan found, or the nearest one (see `reached`).
    pub solution: Solution,
    /// Whether the plan reaches the goal on the predictor (within the
    /// tolerance) and needs no pulling impulse.
    pub reached: bool,
    /// Milliseconds of the search.
    pub solve_ms: f64,
    /// Model runs of the search.
    pub runs: usize,
    /// What the search tried, stage by stage.
    pub attempts: Vec<Attempt>,
    /// The assumption checks of the dynamic model along the plan.
    pub assumptions: pushval_model::Assumptions,
    /// Each switch's impulse against the friction cone.
    pub switches: Vec<SwitchCheck>,
    /// The dynamic model's slide after the release (judged at rest): when
    /// it stops, its pivots.
    pub slide: Option<pushval_model::SlideReport>,
    /// The dynamic model's pose at the release (t, x, y, θ).
    pub release_pose: [f64; 4],
    /// The dynamic model's pose at rest (t, x, y, θ; judged at rest).
    pub rest_pose: Option<[f64; 4]>,
    /// Why it misses (None when it reaches the goal).
    pub why: Option<String>,
}

/// The dynamic model's checks of `pushes` from `start` on `problem`: the
/// trajectory (sampled at most 10,000 times) and its switches.
fn checked(
    problem: &Problem,
    start: &Start,
    pushes: &[Push],
    at: At,
) -> Result<(Trajectory, Vec<SwitchCheck>), ControlError> {
    let mut p = crate::predict::problem_of(problem, start, pushes, None);
    p.release = match at {
        At::Rest => Some(problem.release.unwrap_or_default()),
        At::Release => None,
    };
    // At most about 10,000 samples over the pushes and the slide.
    let horizon = p.duration() + p.release.map_or(0.0, |r| r.max_duration);
    p.sample_dt = problem.sample_dt.max(horizon / 10_000.0);
    let traj = DynamicModel::default().simulate(&p)?;
    let from_rest = matches!(start.motion, Motion::Rest);
    let switches = switch_checks(&p, &traj, from_rest);
    Ok((traj, switches))
}

/// Plans `goal` on `problem` from its start: the search of
/// [`Planner::plan_with_time`] with `spec.segments` pushes, then with more
/// (up to [`MAX_SEGMENTS`]) while no plan reaches the goal, within
/// `bounds.max_runs` model runs. A plan that reaches the goal on the
/// predictor but needs a pulling impulse at a switch (the dynamic model's
/// check) is refused and the search goes on.
pub fn make_plan(
    problem: &Problem,
    goal: Goal,
    spec: PlanSpec,
    reach: Reach,
    bounds: &Bounds,
) -> Result<PlanOutcome, ControlError> {
    let start = Start::of_problem(problem);
    bounds.check(&start, &goal, &spec)?;
    let t_ref = straight_time(&start, &goal, spec.speed);
    let clock = Instant::now();
    let mut counts = vec![spec.segments];
    counts.extend(
        [8, 10, MAX_SEGMENTS]
            .into_iter()
            .filter(|&n| n > spec.segments),
    );
    let mut attempts = Vec::new();
    let mut best: Option<(Solution, Trajectory, Vec<SwitchCheck>)> = None;
    let mut found = None;
    let mut runs = 0;
    'search: for &segments in &counts {
        let mut planner = Planner::new(problem, goal, PlanSpec { segments, ..spec }, t_ref, reach);
        let mut attempt = Attempt {
            segments,
            guesses: 0,
            best_residual_m: None,
            refused_pulling: 0,
        };
        let guesses = if segments == spec.segments {
            GUESSES.len()
        } else {
            GUESSES.len() + MORE_GUESSES.len()
        };
        for k in 0..guesses {
            if runs + planner.predict.runs() > bounds.max_runs {
                break;
            }
            attempt.guesses += 1;
            let Some(s) = planner.from_guess(&start, t_ref, segments, k, 40) else {
                continue;
            };
            attempt.best_residual_m = Some(
                attempt
                    .best_residual_m
                    .map_or(s.residual, |r: f64| r.min(s.residual)),
            );
            let (traj, switches) = checked(problem, &start, &s.pushes, spec.at)?;
            let pulls = traj.assumptions.pulling_impulse.is_some();
            let hit = s.converged || reach.holds(s.position_error, s.angle_error);
            if hit && pulls {
                attempt.refused_pulling += 1;
            }
            if hit && !pulls {
                found = Some((s, traj, switches));
                attempts.push(attempt);
                runs += planner.predict.runs();
                break 'search;
            }
            // The nearest so far, preferring plans without a pulling impulse.
            let better = match &best {
                None => true,
                Some((b, bt, _)) => {
                    let b_pulls = bt.assumptions.pulling_impulse.is_some();
                    (b_pulls && !pulls) || (b_pulls == pulls && s.score() < b.score())
                }
            };
            if better {
                best = Some((s, traj, switches));
            }
        }
        runs += planner.predict.runs();
        attempts.push(attempt);
        if runs > bounds.max_runs {
            break;
        }
    }
    let solve_ms = clock.elapsed().as_secs_f64() * 1e3;
    let reached = found.is_some();
    let (solution, traj, switches) = match found.or(best) {
        Some(f) => f,
        None => {
            return Err(ControlError::PredictorFailed(format!(
                "tried {}",
                describe_attempts(&attempts)
            )))
        }
    };
    let why = (!reached).then(|| {
        let planner = Planner::new(
            problem,
            goal,
            PlanSpec {
                segments: solution.params.u.len(),
                ..spec
            },
            t_ref,
            reach,
        );
        let refused: usize = attempts.iter().map(|a| a.refused_pulling).sum();
        let mut why = planner.why_missed(&solution);
        if refused > 0 {
            why = format!(
                "{refused} plans reach the goal on the model but need a pulling impulse at a switch, and a point pusher cannot pull, so none is a plan; the nearest plan without one misses: {why}"
            );
        } else if traj.assumptions.pulling_impulse.is_some() {
            why = format!(
                "the nearest plan needs a pulling impulse at a switch (a point pusher cannot pull); {why}"
            );
        }
        format!("{why} (tried {})", describe_attempts(&attempts))
    });
    let t_release: f64 = solution.pushes.iter().map(|p| p.duration).sum();
    let pose = |s: &pushval_model::Sample| [s.t, s.x, s.y, s.theta];
    let release_pose = traj
        .samples
        .iter()
        .rfind(|s| s.t <= t_release + 1e-9)
        .map(pose)
        .unwrap_or([f64::NAN; 4]);
    let rest_pose = match spec.at {
        At::Rest => traj.samples.last().map(pose),
        At::Release => None,
    };
    Ok(PlanOutcome {
        solution,
        reached,
        solve_ms,
        runs,
        attempts,
        assumptions: traj.assumptions,
        switches,
        slide: traj.slide,
        release_pose,
        rest_pose,
        why,
    })
}

/// `6 pushes × 7 guesses, 8 pushes × 7 guesses, …`.
pub fn describe_attempts(attempts: &[Attempt]) -> String {
    let parts: Vec<String> = attempts
        .iter()
        .map(|a| {
            let mut t = format!("{} pushes × {} starting guesses", a.segments, a.guesses);
            if a.refused_pulling > 0 {
                t.push_str(&format!(
                    " ({} refused for a pulling impulse)",
                    a.refused_pulling
                ));
            }
            t
        })
        .collect();
    parts.join(", ")
}

/// `params` with `segments` pushes: each new push takes the direction of the
/// old push at its middle (the same piecewise-constant schedule, coarser).
pub fn resample(params: &Params, segments: usize) -> Params {
    let old = params.u.len();
    if old == segments {
        return params.clone();
    }
    Params {
        u: (0..segments)
            .map(|k| params.u[(((k as f64 + 0.5) / segments as f64) * old as f64) as usize % old])
            .collect(),
        s: params.s,
    }
}

/// The nearer of two solutions to the goal.
pub fn nearest(a: Option<Solution>, b: Option<Solution>) -> Option<Solution> {
    match (a, b) {
        (Some(a), Some(b)) => Some(if b.score() < a.score() { b } else { a }),
        (a, b) => a.or(b),
    }
}
