//! `pushval loop`: model-predictive control with an engine as the plant.
//!
//! The plan from rest is made first (a [`Planner`] on the predictor). Then,
//! every control period, the engine's session advances by one period under
//! the first push of the current plan; pushval reads the engine's state
//! (pose, ω and the centre of mass's velocity, which give the angular
//! momentum about the contact that an impulsive switch keeps) and re-plans
//! the remaining time from it, warm-started from the last plan and its
//! Jacobian. When the time left is shorter than one period per segment,
//! the rest of the plan is applied as it stands.

use std::time::Instant;

use anyhow::{bail, Context};
use pushval_engine::{Engine, EngineRun};
use pushval_model::{Body, Problem, Push, Support};

use super::plan::{straight_time, Motion, PlanSpec, Planner, Start, GUESSES};
use super::{pose_errors, Goal, Predictor, Reach};

/// How the plant differs from the predictor's scene.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PlantScale {
    /// Every support's friction force times this.
    pub mu_scale: f64,
    /// The inertia about the centre of mass times this.
    pub inertia_scale: f64,
}

impl Default for PlantScale {
    fn default() -> Self {
        Self {
            mu_scale: 1.0,
            inertia_scale: 1.0,
        }
    }
}

impl PlantScale {
    /// The perturbed plant of the closed-loop study: μ × 0.8, I_cm × 1.2.
    pub const PERTURBED: PlantScale = PlantScale {
        mu_scale: 0.8,
        inertia_scale: 1.2,
    };

    /// Parses `mu_scale=A,inertia_scale=B` (either may be left out).
    pub fn parse(text: &str) -> anyhow::Result<Self> {
        let mut out = Self::default();
        for part in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (k, v) = part
                .split_once('=')
                .with_context(|| format!("--plant: `{part}` is not KEY=VALUE"))?;
            let v: f64 = v
                .trim()
                .parse()
                .with_context(|| format!("--plant: `{}` is not a number", v.trim()))?;
            if !(v.is_finite() && v > 0.0) {
                bail!("--plant: {k} must be finite and > 0, got {v}");
            }
            match k.trim() {
                "mu_scale" => out.mu_scale = v,
                "inertia_scale" => out.inertia_scale = v,
                other => bail!("--plant: unknown key `{other}` (mu_scale, inertia_scale)"),
            }
        }
        Ok(out)
    }

    /// Whether it changes nothing.
    pub fn is_nominal(&self) -> bool {
        self.mu_scale == 1.0 && self.inertia_scale == 1.0
    }

    /// `problem` with the plant's friction and inertia.
    pub fn apply(&self, problem: &Problem) -> anyhow::Result<Problem> {
        if self.is_nominal() {
            return Ok(problem.clone());
        }
        let b = &problem.body;
        let supports: Vec<Support> = b
            .supports()
            .map(|s| Support {
                position: s.position,
                friction: s.friction * self.mu_scale,
            })
            .collect();
        let body = Body::new(
            b.mass(),
            b.inertia_cm() * self.inertia_scale,
            b.contact(),
            &supports,
        )?;
        Ok(Problem {
            body,
            ..problem.clone()
        })
    }
}

/// What the loop is asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopSpec {
    /// The plan's shape and predictor.
    pub plan: PlanSpec,
    /// The control period (s).
    pub period: f64,
    /// The plant's perturbation.
    pub plant: PlantScale,
    /// What counts as reaching the goal.
    pub reach: Reach,
}

/// One applied push of the loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Applied {
    /// Start time (s).
    pub t0: f64,
    /// The push.
    pub push: Push,
}

/// What one closed-loop run did.
pub struct LoopOutcome {
    /// The engine's run of the applied pushes.
    pub run: EngineRun,
    /// The pushes applied, in order.
    pub applied: Vec<Applied>,
    /// Final distance from the goal (m).
    pub position_error: f64,
    /// Final angle error (rad).
    pub angle_error: f64,
    /// Whether the goal was reached.
    pub success: bool,
    /// Whether the loop stopped at twice the first plan's duration (the
    /// re-plans kept growing: the plant does not move as predicted).
    pub gave_up: bool,
    /// Control periods (re-plans).
    pub steps: usize,
    /// Wall time of each re-plan (µs).
    pub predictor_us: Vec<f64>,
    /// The calling thread's CPU time of each re-plan (µs): what the
    /// predictor computed, without the waits a busy machine adds.
    pub predictor_cpu_us: Vec<f64>,
    /// Whether the plan from rest converged on the predictor.
    pub plan_converged: bool,
    /// Whether the engine re-ran its schedule at every period (it cannot step).
    pub replayed: bool,
}

/// The plan from rest for `goal` on `problem`.
pub fn plan_from_rest(
    problem: &Problem,
    goal: Goal,
    spec: PlanSpec,
    reach: Reach,
) -> Option<(Planner, super::plan::Solution)> {
    let start = Start::of_problem(problem);
    let t_ref = straight_time(&start, &goal, spec.speed);
    let mut planner = Planner::new(problem, goal, spec, t_ref, reach);
    let s = planner.plan(&start)?;
    Some((planner, s))
}

/// Runs `pushes` open loop in `engine` on the plant, returning the final
/// errors and the run.
pub fn open_loop(
    problem: &Problem,
    engine: &dyn Engine,
    dt: f64,
    pushes: &[Push],
    plant: PlantScale,
    goal: &Goal,
) -> anyhow::Result<(EngineRun, f64, f64)> {
    let mut p = plant.apply(problem)?;
    p.pushes = pushes.to_vec();
    let run = engine.run(&p, dt)?;
    let s = run
        .trajectory
        .samples
        .last()
        .copied()
        .context("an empty run")?;
    let (pe, ae) = pose_errors(s.x, s.y, s.theta, goal);
    Ok((run, pe, ae))
}

/// Levenberg–Marquardt steps of one fallback stage (with its fresh
/// Jacobian). A stage that does not converge hands its nearest plan to the
/// next period's warm start, so the search goes on.
pub const STAGE_STEPS: usize = 6;

/// Model-predictive control of `engine` towards `goal`.
pub fn run_loop(
    problem: &Problem,
    engine: &dyn Engine,
    dt: f64,
    goal: Goal,
    spec: LoopSpec,
) -> anyhow::Result<LoopOutcome> {
    if !(spec.period.is_finite() && spec.period > 0.0) {
        bail!("--period must be finite and > 0, got {}", spec.period);
    }
    let (mut planner, first) = plan_from_rest(problem, goal, spec.plan, spec.reach)
        .context("the predictor failed on every starting guess from rest")?;
    let plan_converged = first.converged;
    // The session starts on the first plan's schedule: what an engine reads
    // of the schedule at `start` (a push following a segment) is the best
    // guess there is of what the loop will apply.
    let mut plant = spec.plant.apply(problem)?;
    plant.pushes = first.pushes.clone();
    let mut session = engine
        .start(&plant, dt)
        .with_context(|| format!("{}: starting a session", engine.name()))?;
    let n = spec.plan.segments;
    let mut params = first.params.clone();
    let mut pushes = first.pushes.clone();
    let mut remaining = planner.duration(&params);
    // The loop gives up (a miss) at twice the first plan's duration.
    let give_up = 2.0 * remaining;
    let mut applied: Vec<Applied> = Vec::new();
    let mut t = 0.0;
    let mut predictor_us = Vec::new();
    let mut predictor_cpu_us = Vec::new();
    let mut steps = 0;
    let mut gave_up = false;
    let mut stage = 0usize;
    loop {
        if t + remaining > give_up {
            // The plan keeps growing: the plant does not move as predicted.
            let rest = (give_up - t).max(0.0);
            if rest > 0.0 {
                let p = Push {
                    duration: rest,
                    ..pushes[0]
                };
                session.advance(&p)?;
                applied.push(Applied { t0: t, push: p });
            }
            gave_up = true;
            break;
        }
        if remaining <= spec.period * (1.0 + 1e-9) {
            // The last period: the rest as planned.
            for p in &pushes {
                session.advance(p)?;
                applied.push(Applied { t0: t, push: *p });
                t += p.duration;
            }
            break;
        }
        let push = Push {
            duration: spec.period,
            ..pushes[0]
        };
        session
            .advance(&push)
            .with_context(|| format!("{}: advancing at t = {t:.3} s", engine.name()))?;
        applied.push(Applied { t0: t, push });
        t += spec.period;
        remaining -= spec.period;
        steps += 1;
        let st = session.state();
        let start = Start {
            theta: st.theta,
            position: pushval_model::Vec2::new(st.x, st.y),
            motion: Motion::Moving {
                omega: st.omega,
                momentum: st.contact_momentum(problem),
            },
        };
        let clock = Instant::now();
        let cpu = crate::track::thread_cpu_time();
        // As the time left shrinks, so does the number of pushes: each keeps
        // at least one period (down to one push: then the least-squares
        // pose nearest the goal).
        let segments = ((remaining / spec.period * (1.0 + 1e-9)).floor() as usize).clamp(1, n);
        let warm = planner.with_duration(&resample(&params, segments), remaining);
        let mut solved = planner.solve(&start, warm.clone(), 4);
        if solved.as_ref().is_some_and(|s| s.converged) {
            stage = 0;
        } else {
            // The warm start stalled: one stage of the fallback search per
            // period, so no period pays for the whole search (stage 0 a
            // fresh Jacobian and more steps from the warm start, stage k
            // the k-th starting guess from scratch); the nearest plan is
            // applied meanwhile, and the search goes on next period from
            // the next stage until a plan converges.
            let stage_solved = if stage == 0 {
                planner.forget();
                planner.solve(&start, warm, STAGE_STEPS)
            } else {
                planner.from_guess(&start, remaining, segments, stage - 1, STAGE_STEPS)
            };
            solved = nearest(solved, stage_solved);
            stage = if solved.as_ref().is_some_and(|s| s.converged) {
                0
            } else {
                (stage + 1) % (GUESSES.len() + 1)
            };
        }
        predictor_us.push(clock.elapsed().as_secs_f64() * 1e6);
        predictor_cpu_us.push((crate::track::thread_cpu_time() - cpu) * 1e6);
        match solved {
            Some(s) => {
                params = s.params;
                remaining = planner.duration(&params);
                pushes = s.pushes;
            }
            None => {
                // The predictor failed from this state: keep the last plan,
                // shortened by the period, and take a fresh Jacobian next time.
                planner.forget();
                params = planner.with_duration(&params, remaining);
                pushes = planner.pushes(&params);
            }
        }
    }
    let replayed = session.replays();
    let st = session.state();
    let run = session.finish()?;
    let (pe, ae) = pose_errors(st.x, st.y, st.theta, &goal);
    Ok(LoopOutcome {
        run,
        applied,
        position_error: pe,
        angle_error: ae,
        success: spec.reach.holds(pe, ae),
        gave_up,
        steps,
        predictor_us,
        predictor_cpu_us,
        plan_converged,
        replayed,
    })
}

/// `params` with `segments` pushes: each new push takes the direction of the
/// old push at its middle (the same piecewise-constant schedule, coarser).
fn resample(params: &super::plan::Params, segments: usize) -> super::plan::Params {
    let old = params.u.len();
    if old == segments {
        return params.clone();
    }
    super::plan::Params {
        u: (0..segments)
            .map(|k| params.u[(((k as f64 + 0.5) / segments as f64) * old as f64) as usize % old])
            .collect(),
        s: params.s,
    }
}

/// The nearer of two solutions to the goal.
fn nearest(
    a: Option<super::plan::Solution>,
    b: Option<super::plan::Solution>,
) -> Option<super::plan::Solution> {
    match (a, b) {
        (Some(a), Some(b)) => Some(if b.score() < a.score() { b } else { a }),
        (a, b) => a.or(b),
    }
}

/// The median and the 99th percentile of `v` (nearest rank), NaN when empty.
pub fn median_p99(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let rank = |q: f64| s[((q * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1];
    (rank(0.5), rank(0.99))
}

/// The push applied at time `t` (s): the one whose interval holds it, the
/// later one at a switch.
pub fn push_at(applied: &[Applied], t: f64) -> Option<&Push> {
    applied
        .iter()
        .rev()
        .find(|a| a.t0 <= t + 1e-12)
        .map(|a| &a.push)
}

/// `predictor` name and the trajectory rows with the applied push, as CSV.
pub fn trajectory_csv(out: &LoopOutcome, model: &str) -> String {
    let mut s = format!("{},speed,phi\n", pushval_model::format::HEADER);
    for smp in &out.run.trajectory.samples {
        let p = push_at(&out.applied, smp.t);
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{}\n",
            model,
            smp.t,
            smp.x,
            smp.y,
            smp.theta,
            smp.omega,
            p.map_or(0.0, |p| p.speed),
            p.map_or(0.0, |p| p.phi)
        ));
    }
    s
}

/// The predictor's name as outputs give it.
pub fn predictor_name(p: Predictor) -> &'static str {
    p.as_str()
}
