//! Model-predictive control with an engine session as the plant.
//!
//! The plan from rest is made first (a [`Planner`] on the predictor). Then,
//! every control period, the plant advances by one period under the first
//! push of the current plan; the loop reads the plant's state (pose, ω and
//! the centre of mass's velocity, which give the angular momentum about the
//! contact that an impulsive switch keeps) and re-plans the remaining time
//! from it, warm-started from the last plan and its Jacobian. When the time
//! left is one period or less, the rest of the plan is re-solved with its
//! time on the plant's step grid and applied.
//!
//! Every duration the loop applies is a whole number of the plant's steps
//! (`dt`): the period is rounded to whole steps (and must be at least one),
//! and the plan's last stretch is re-solved on the grid
//! ([`Planner::on_grid`]), so a fixed-step plant ends its rows exactly where
//! the loop said it would.

use std::time::Instant;

use pushval_engine::{EngineSession, EngineState};
use pushval_model::{Body, ModelError, Problem, Push, Support, Vec2};

use crate::estimate::{EstimateRow, Identified, OnlineEstimator};
use crate::plan::{nearest, resample, straight_time, PlanSpec, Planner, Solution, GUESSES};
use crate::predict::{ModelPredictor, Motion, Predictor, Start};
use crate::sensor::{Sensor, SensorSpec};
use crate::{pose_errors, At, ControlError, Goal, Reach};

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

    /// Whether it changes nothing.
    pub fn is_nominal(&self) -> bool {
        self.mu_scale == 1.0 && self.inertia_scale == 1.0
    }

    /// `problem` with the plant's friction and inertia.
    pub fn apply(&self, problem: &Problem) -> Result<Problem, ModelError> {
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
    /// The control period (s); rounded to whole plant steps.
    pub period: f64,
    /// What counts as reaching the goal.
    pub reach: Reach,
    /// Estimate the plate's friction every period and plan on the estimate
    /// (adaptive MPC); otherwise plan on the scene given.
    pub adapt: bool,
    /// What the controller reads the plant through.
    pub sensor: SensorSpec,
}

impl LoopSpec {
    /// Plain MPC with an exact sensor.
    pub fn new(plan: PlanSpec, period: f64, reach: Reach) -> Self {
        Self {
            plan,
            period,
            reach,
            adapt: false,
            sensor: SensorSpec::default(),
        }
    }
}

/// One applied push of the loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Applied {
    /// Start time (s).
    pub t0: f64,
    /// The push.
    pub push: Push,
}

/// What the loop tells its observer at the end of each control period.
#[derive(Debug, Clone)]
pub struct Period<'a> {
    /// Periods done so far (1 for the first).
    pub index: usize,
    /// What the controller read of the plant (through its sensor) before
    /// the re-plan.
    pub state: EngineState,
    /// The plan after the re-plan (the pushes still to apply).
    pub plan: &'a [Push],
    /// Whether the re-plan converged on the predictor.
    pub converged: bool,
    /// The calling thread's CPU time of the re-plan (µs).
    pub predictor_cpu_us: f64,
}

/// Watches the loop: called once per control period, after its re-plan.
pub trait Observer {
    /// One period done.
    fn period(&mut self, period: &Period<'_>);
}

/// No observer.
impl Observer for () {
    fn period(&mut self, _period: &Period<'_>) {}
}

/// What one closed-loop run did.
#[derive(Debug, Clone)]
pub struct LoopOutcome {
    /// The pushes applied, in order (each a whole number of plant steps).
    pub applied: Vec<Applied>,
    /// When the loop was judged.
    pub at: At,
    /// The plant's state when the last push ended (the release).
    pub release: EngineState,
    /// The plant's state at rest after the release (judged at rest only).
    pub rest: Option<EngineState>,
    /// Distance of the judged pose from the goal (m).
    pub position_error: f64,
    /// Angle error of the judged pose (rad).
    pub angle_error: f64,
    /// Whether the goal was reached.
    pub success: bool,
    /// Whether the loop stopped at twice the first plan's duration (the
    /// re-plans kept growing: the plant does not move as predicted).
    pub gave_up: bool,
    /// Control periods (re-plans).
    pub steps: usize,
    /// The control period applied (s): whole plant steps.
    pub period: f64,
    /// Wall time of each re-plan (µs).
    pub predictor_us: Vec<f64>,
    /// The calling thread's CPU time of each re-plan (µs): what the
    /// predictor computed, without the waits a busy machine adds.
    pub predictor_cpu_us: Vec<f64>,
    /// Whether the plan from rest converged on the predictor.
    pub plan_converged: bool,
    /// Whether the plant re-ran its schedule at every period (it cannot step).
    pub replayed: bool,
    /// The sensor's delay applied (s): whole plant steps.
    pub latency: f64,
    /// The estimate after each period's reading (adaptive only).
    pub estimates: Vec<EstimateRow>,
    /// The calling thread's CPU time of each period's estimator update and
    /// scene rebuild (µs; adaptive only).
    pub estimator_cpu_us: Vec<f64>,
    /// Which parameters the last estimate identified (adaptive only).
    pub identified: Option<Identified>,
    /// Times the readings rejected the estimator's model (adaptive only).
    pub lack_of_fit: usize,
}

/// The plan from rest for `goal` on `problem`.
pub fn plan_from_rest(
    problem: &Problem,
    goal: Goal,
    spec: PlanSpec,
    reach: Reach,
) -> Option<(Planner, Solution)> {
    let start = Start::of_problem(problem);
    let t_ref = straight_time(&start, &goal, spec.speed);
    let mut planner = Planner::new(problem, goal, spec, t_ref, reach);
    let s = planner.plan(&start)?;
    Some((planner, s))
}

/// The calling thread's CPU time (s).
pub fn thread_cpu_time() -> f64 {
    let ts = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// The whole plant steps of `period` (s) at `dt` (s): refused when shorter
/// than one step.
pub fn period_steps(period: f64, dt: f64) -> Result<usize, ControlError> {
    if !(period.is_finite() && period > 0.0) {
        return Err(ControlError::Setting {
            name: "control period (s)",
            requirement: "finite and > 0".into(),
            value: period,
        });
    }
    let k = (period / dt * (1.0 + 1e-12)).round();
    if k < 1.0 || period < dt * (1.0 - 1e-9) {
        return Err(ControlError::Setting {
            name: "control period (s)",
            requirement: format!("at least the plant's step, {dt} s"),
            value: period,
        });
    }
    Ok(k as usize)
}

/// Applies `pushes` to the plant open loop; its state after them.
pub fn open_loop(
    plant: &mut dyn EngineSession,
    pushes: &[Push],
) -> Result<EngineState, ControlError> {
    for p in pushes {
        let t = plant.state().t;
        plant
            .advance(p)
            .map_err(|source| ControlError::Plant { t, source })?;
    }
    Ok(plant.state())
}

/// Levenberg–Marquardt steps of one fallback stage (with its fresh
/// Jacobian). A stage that does not converge hands its nearest plan to the
/// next period's warm start, so the search goes on.
pub const STAGE_STEPS: usize = 6;

/// The start of a re-plan at `now` (s) from a reading `st` taken at
/// `st.t <= now`: the reading itself when it is current, else the reading
/// carried forward over the pushes applied since, on `forward` (the
/// controller's model, judged at the release).
fn start_at(
    scene: &Problem,
    forward: &mut ModelPredictor,
    st: &EngineState,
    applied: &[Applied],
    now: f64,
) -> Result<Start, ControlError> {
    let eps = 1e-9 * now.abs().max(1e-3);
    if st.t >= now - eps {
        return Ok(start_of(scene, st));
    }
    let pushes: Vec<Push> = applied
        .iter()
        .filter_map(|a| {
            let from = a.t0.max(st.t);
            let to = (a.t0 + a.push.duration).min(now);
            (to - from > eps).then_some(Push {
                duration: to - from,
                ..a.push
            })
        })
        .collect();
    let Some(last) = pushes.last().copied() else {
        return Ok(start_of(scene, st));
    };
    let from = if st.t <= eps {
        Start::of_problem(scene)
    } else {
        start_of(scene, st)
    };
    let total: f64 = pushes.iter().map(|p| p.duration).sum();
    let tr = forward.trajectory(&from, &pushes, total)?;
    let end = tr
        .samples
        .last()
        .ok_or(pushval_model::ModelError::EmptySchedule)?;
    let at_end = EngineState {
        t: now,
        x: end.x,
        y: end.y,
        theta: end.theta,
        omega: end.omega,
        v_cm: pushval_engine::rigid_cm_velocity(scene, Some(&last), end.theta, end.omega),
    };
    Ok(start_of(scene, &at_end))
}

fn start_of(problem: &Problem, st: &EngineState) -> Start {
    Start {
        theta: st.theta,
        position: Vec2::new(st.x, st.y),
        motion: Motion::Moving {
            omega: st.omega,
            momentum: st.contact_momentum(problem),
        },
    }
}

/// Model-predictive control of `plant` (a session started on the plant's
/// scene at step `dt`, s) towards `goal`, planned on `problem`'s scene (or,
/// with [`LoopSpec::adapt`], on the scene estimated from the plant's
/// readings, starting from `problem`'s). The controller reads the plant
/// only through [`LoopSpec::sensor`]; success is judged on the plant's true
/// state. The caller owns the plant and finishes it.
pub fn run_loop(
    problem: &Problem,
    plant: &mut dyn EngineSession,
    dt: f64,
    goal: Goal,
    spec: LoopSpec,
    observer: &mut dyn Observer,
) -> Result<LoopOutcome, ControlError> {
    let k = period_steps(spec.period, dt)?;
    let period = k as f64 * dt;
    spec.sensor.check()?;
    // The delay in whole plant steps; each period is split where a later
    // reading will look (the same offset in every period), so the state
    // it reads was recorded exactly there.
    let lag = (spec.sensor.latency / dt).round() as usize;
    let latency = lag as f64 * dt;
    let split = match lag % k {
        0 => None,
        r => Some(k - r),
    };
    let mut sensor = Sensor::new(spec.sensor, latency);
    sensor.record(plant.state());
    let mut estimator = if spec.adapt {
        Some(OnlineEstimator::new(problem, &spec.sensor)?)
    } else {
        None
    };
    // What the controller believes: the file's scene, or the estimate's.
    let mut scene = problem.clone();
    let mut forward = ModelPredictor::new(problem, spec.plan.predictor).judged_at(At::Release);
    let (mut planner, first) = plan_from_rest(problem, goal, spec.plan, spec.reach)
        .ok_or_else(|| ControlError::PredictorFailed("from rest".into()))?;
    let plan_converged = first.converged;
    let advance = |plant: &mut dyn EngineSession, p: &Push| {
        let t = plant.state().t;
        plant
            .advance(p)
            .map_err(|source| ControlError::Plant { t, source })
    };
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
    let mut estimates = Vec::new();
    let mut estimator_cpu_us = Vec::new();
    let mut steps = 0;
    let mut gave_up = false;
    let mut stage = 0usize;
    let mut last_start = Start::of_problem(problem);
    loop {
        if t + remaining > give_up {
            // The plan keeps growing: the plant does not move as predicted.
            let rest = ((give_up - t) / dt).round().max(0.0) * dt;
            if rest > 0.0 {
                let p = Push {
                    duration: rest,
                    ..pushes[0]
                };
                advance(plant, &p)?;
                applied.push(Applied { t0: t, push: p });
            }
            gave_up = true;
            break;
        }
        if remaining <= period * (1.0 + 1e-9) {
            // The last stretch: its time on the plant's grid, re-solved
            // there from the last start the controller had, then applied as
            // it stands.
            let current = planner.solution_of(params.clone());
            let on_grid = planner
                .on_grid(&last_start, &current, dt)
                .map(|s| s.pushes)
                .unwrap_or_else(|| grid_pushes(&pushes, dt));
            for p in &on_grid {
                advance(plant, p)?;
                applied.push(Applied { t0: t, push: *p });
                t += p.duration;
            }
            break;
        }
        let push = Push {
            duration: period,
            ..pushes[0]
        };
        match split {
            Some(o) => {
                advance(
                    plant,
                    &Push {
                        duration: o as f64 * dt,
                        ..push
                    },
                )?;
                sensor.record(plant.state());
                advance(
                    plant,
                    &Push {
                        duration: (k - o) as f64 * dt,
                        ..push
                    },
                )?;
            }
            None => advance(plant, &push)?,
        }
        sensor.record(plant.state());
        applied.push(Applied { t0: t, push });
        t += period;
        remaining -= period;
        steps += 1;
        let st = sensor.read(t);
        if let Some(e) = estimator.as_mut() {
            let cpu = thread_cpu_time();
            e.applied(&push);
            e.measure(&st)?;
            let body = e.body()?;
            planner.predict.set_body(body.clone());
            forward.set_body(body.clone());
            scene.body = body;
            estimator_cpu_us.push((thread_cpu_time() - cpu) * 1e6);
            estimates.push(e.row());
        }
        let clock = Instant::now();
        let cpu = thread_cpu_time();
        let start = start_at(&scene, &mut forward, &st, &applied, t)?;
        last_start = start;
        // As the time left shrinks, so does the number of pushes: each keeps
        // at least one period (down to one push: then the least-squares
        // pose nearest the goal).
        let segments = ((remaining / period * (1.0 + 1e-9)).floor() as usize).clamp(1, n);
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
        let cpu_us = (thread_cpu_time() - cpu) * 1e6;
        predictor_cpu_us.push(cpu_us);
        let converged = solved.as_ref().is_some_and(|s| s.converged);
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
        observer.period(&Period {
            index: steps,
            state: st,
            plan: &pushes,
            converged,
            predictor_cpu_us: cpu_us,
        });
    }
    let release = plant.state();
    let rest = match spec.plan.at {
        At::Release => None,
        At::Rest => {
            // The pusher lets go; the plant slides until it stops.
            let max = problem.release.unwrap_or_default().max_duration;
            plant.release(max).map_err(|source| ControlError::Plant {
                t: release.t,
                source,
            })?;
            Some(plant.state())
        }
    };
    let judged = rest.unwrap_or(release);
    let (pe, ae) = pose_errors(judged.x, judged.y, judged.theta, &goal);
    Ok(LoopOutcome {
        applied,
        at: spec.plan.at,
        release,
        rest,
        position_error: pe,
        angle_error: ae,
        success: spec.reach.holds(pe, ae),
        gave_up,
        steps,
        period,
        predictor_us,
        predictor_cpu_us,
        plan_converged,
        replayed: plant.replays(),
        latency,
        identified: estimator.as_ref().map(|e| e.identified()),
        lack_of_fit: estimator.as_ref().map_or(0, |e| e.lack_of_fit()),
        estimates,
        estimator_cpu_us,
    })
}

/// `pushes` with each duration rounded to whole steps of `dt` (at least
/// one): the fallback when the re-solve on the grid fails.
fn grid_pushes(pushes: &[Push], dt: f64) -> Vec<Push> {
    pushes
        .iter()
        .map(|p| Push {
            duration: (p.duration / dt).round().max(1.0) * dt,
            ..*p
        })
        .collect()
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
