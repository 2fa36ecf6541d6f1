//! Running and comparing the models of one scenario.

use std::time::{Duration, Instant};

use pushval_model::{
    kinematic, limit_surface, DynamicModel, InertialTerm, Integrator, KinematicModel,
    LimitSurfaceModel, ModelError, Problem, RootKind, SegmentDynamics, Simulator, SteadyState,
    Trajectory,
};
use pushval_rapier::{EngineRun, EngineSettings, FrictionModel, RapierSimulator};
use pushval_scenario::{ModelKind, Scenario};

/// Settings of a harness run.
#[derive(Debug, Clone, Copy)]
pub struct RunOptions {
    /// Tolerance of the dynamic model's adaptive integrator. Default 1e-10.
    pub model_tol: f64,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self { model_tol: 1e-10 }
    }
}

/// What one model produced.
#[derive(Debug, Clone)]
pub struct ModelRun {
    pub kind: ModelKind,
    pub trajectory: Trajectory,
    /// The settings that produced it, for the outputs.
    pub settings: serde_json::Value,
    /// Wall time of the run.
    pub elapsed: Duration,
    /// Engine diagnostics (joint drift, steps, convergence in dt); null for
    /// the analytic models.
    pub diagnostics: serde_json::Value,
}

/// The steady-state analysis of one push segment.
#[derive(Debug, Clone)]
pub struct SegmentInfo {
    pub index: usize,
    pub t_start: f64,
    pub t_end: f64,
    pub speed: f64,
    pub phi: f64,
    pub froude: f64,
    /// `v_c ψ(φ)` (rad/s), None where ψ does not exist.
    pub omega_kinematic: Option<f64>,
    /// The ellipsoidal limit surface's ω (rad/s).
    pub omega_limit_surface: f64,
    /// All roots of ω̇, sorted, with their stability.
    pub steady_states: Vec<SteadyState>,
    /// The steady state the dynamic run converges to in this segment (None: runaway).
    pub omega_steady: Option<SteadyState>,
    /// ω at the start of the segment, just after the switch (rad/s).
    pub omega_start: f64,
    /// Relative distance of the dynamic model's tail-mean ω (last 20 % of the
    /// segment) from ω*, with the floor of [`rel_err`]; None without a root.
    pub tail_deviation: Option<f64>,
}

impl SegmentInfo {
    /// Relaxation time τ (s) of the steady state reached, if smooth and stable.
    pub fn tau(&self) -> Option<f64> {
        self.omega_steady.and_then(|s| s.tau)
    }
    /// Whether a steady ω can be read off the segment's tail: a smooth stable
    /// root, and the dynamic model's tail mean within 1e-6 (relative) of it.
    pub fn settles(&self) -> bool {
        matches!(
            self.omega_steady,
            Some(SteadyState {
                kind: RootKind::Stable,
                tau: Some(_),
                ..
            })
        ) && self.tail_deviation.is_some_and(|d| d <= SETTLED_REL)
    }
}

/// Largest relative deviation of the dynamic model's tail-mean ω from ω* for
/// a segment to count as settled (100 times below the tightest engine target).
pub const SETTLED_REL: f64 = 1e-6;

/// One model measured against the dynamic model.
#[derive(Debug, Clone)]
pub struct Comparison {
    pub model: String,
    /// Largest centre-of-mass distance at the common samples (m).
    pub position_max: f64,
    /// Largest angle difference (rad).
    pub theta_max: f64,
    /// Largest relative steady-ω error over the settling segments (None when
    /// no segment settles).
    pub omega_steady_rel_max: Option<f64>,
    /// Some(pass) when gated by the scenario's tolerance; None when informational.
    pub pass: Option<bool>,
    /// The figures that exceeded their tolerance.
    pub failed: Vec<String>,
    /// Why there is no comparison (the model failed to run), if so.
    pub error: Option<String>,
    /// Engine runs only: the steady ω extrapolated to dt → 0.
    pub convergence: Option<Convergence>,
}

/// How an engine's steady ω converges as its time step shrinks: runs at 4h,
/// 2h and h (h the gated run's step; runs the time-step search made are
/// reused), the observed order `p = log2(|ω(4h) − ω(2h)| / |ω(2h) − ω(h)|)`, and Richardson extrapolations
/// to dt → 0 with the scheme's expected order p: `ω(h) + (ω(h) − ω(2h)) / (2^p − 1)`,
/// and the same applied again for the order p + 1 term.
#[derive(Debug, Clone)]
pub struct Convergence {
    /// The order the friction-velocity scheme should show (1, or 2 for leapfrog).
    pub expected_order: f64,
    /// The three time steps (s), largest first.
    pub dts: [f64; 3],
    /// Observed order per settled segment.
    pub orders: Vec<(usize, f64)>,
    /// Largest relative error of the extrapolation at the expected order,
    /// against the dynamic model's tail-mean ω (within 1e-6 of ω*).
    pub richardson1_rel_max: f64,
    /// The same after removing the next order as well.
    pub richardson2_rel_max: f64,
    /// The same for the plain run at h.
    pub plain_rel_max: f64,
}

impl Convergence {
    /// Median observed order over the settled segments.
    pub fn order(&self) -> Option<f64> {
        let mut o: Vec<f64> = self
            .orders
            .iter()
            .map(|p| p.1)
            .filter(|p| p.is_finite())
            .collect();
        o.sort_by(f64::total_cmp);
        (!o.is_empty()).then(|| o[o.len() / 2])
    }
}

/// Everything a scenario run produced.
#[derive(Debug, Clone)]
pub struct ScenarioReport {
    pub scenario: Scenario,
    pub segments: Vec<SegmentInfo>,
    pub runs: Vec<ModelRun>,
    pub comparisons: Vec<Comparison>,
}

impl ScenarioReport {
    /// The dynamic model's run (always present).
    pub fn dynamic(&self) -> &ModelRun {
        self.runs
            .iter()
            .find(|r| r.kind == ModelKind::Dynamic)
            .expect("the dynamic model always runs")
    }
    /// False when a gated comparison failed.
    pub fn pass(&self) -> bool {
        self.comparisons.iter().all(|c| c.pass != Some(false))
    }
}

/// The engine settings a scenario asks for: its `[engine]` table over the
/// adapter's defaults. Without `[engine] dt` this is the adapter's default
/// step; the gated `rapier2d` run of [`run_scenario`] chooses its own with
/// [`choose_engine_dt`].
pub fn engine_settings(sc: &Scenario) -> EngineSettings {
    let mut s = EngineSettings::default();
    let e = &sc.engine;
    if let Some(dt) = e.dt {
        s.dt = dt;
    }
    if let Some(n) = e.solver_iterations {
        s.solver_iterations = n;
    }
    if let Some(p) = e.precision {
        s.precision = match p {
            pushval_scenario::Precision::F64 => pushval_rapier::Precision::F64,
            pushval_scenario::Precision::F32 => pushval_rapier::Precision::F32,
        };
    }
    if let Some(f) = e.friction_velocity {
        s.friction_velocity = match f {
            pushval_scenario::FrictionVelocity::Body => pushval_rapier::FrictionVelocity::Body,
            pushval_scenario::FrictionVelocity::Constraint => {
                pushval_rapier::FrictionVelocity::Constraint
            }
            pushval_scenario::FrictionVelocity::Midpoint => {
                pushval_rapier::FrictionVelocity::Midpoint
            }
            pushval_scenario::FrictionVelocity::Leapfrog => {
                pushval_rapier::FrictionVelocity::Leapfrog
            }
        };
    }
    s
}

/// The settings record written beside an engine's figures.
pub fn engine_settings_json(s: &EngineSettings) -> serde_json::Value {
    serde_json::json!({
        "engine": "rapier2d 0.36",
        "dt": s.dt,
        "solver_iterations": s.solver_iterations,
        "pgs_iterations": s.pgs_iterations,
        "precision": s.precision.as_str(),
        "friction_velocity": s.friction_velocity.as_str(),
        "switch_step_fraction": s.switch_step_fraction,
        "colliders": s.colliders,
        "label": s.label(),
    })
}

/// The simulator for a model kind, or None for a model this build cannot run.
fn simulator(
    kind: ModelKind,
    sc: &Scenario,
    opts: &RunOptions,
) -> Option<(Box<dyn Simulator>, serde_json::Value)> {
    match kind {
        ModelKind::Dynamic => Some((
            Box::new(DynamicModel {
                integrator: Integrator::Dop853 {
                    tol: opts.model_tol,
                },
                ..Default::default()
            }),
            serde_json::json!({"integrator": "dop853", "tolerance": opts.model_tol, "skip_settled": true}),
        )),
        ModelKind::Kinematic => Some((Box::new(KinematicModel), serde_json::json!({}))),
        ModelKind::LimitSurface => Some((Box::new(LimitSurfaceModel), serde_json::json!({}))),
        ModelKind::Rapier2d => {
            let settings = engine_settings(sc);
            Some((
                Box::new(RapierSimulator { settings }),
                engine_settings_json(&settings),
            ))
        }
        ModelKind::Rapier3d | ModelKind::Rapier3dSimplified => {
            // rapier3d ground contact (informational): its own defaults, the
            // scenario's time step when `[engine]` sets one.
            let mut settings = pushval_rapier3d::Rapier3dSettings {
                friction: if kind == ModelKind::Rapier3d {
                    pushval_rapier3d::ContactFriction::Coulomb
                } else {
                    pushval_rapier3d::ContactFriction::Simplified
                },
                ..Default::default()
            };
            if let Some(dt) = sc.engine.dt {
                settings.dt = dt;
            }
            let json = serde_json::json!({
                "engine": "rapier3d-f64 0.36",
                "dt": settings.dt,
                "friction_model": settings.friction.as_str(),
                "label": settings.label(),
            });
            Some((
                Box::new(pushval_rapier3d::Rapier3dSimulator { settings }),
                json,
            ))
        }
        ModelKind::MujocoPyramidal | ModelKind::MujocoElliptic => {
            if !pushval_mujoco::AVAILABLE {
                return None;
            }
            let mut settings = pushval_mujoco::MujocoSettings {
                cone: if kind == ModelKind::MujocoPyramidal {
                    pushval_mujoco::Cone::Pyramidal
                } else {
                    pushval_mujoco::Cone::Elliptic
                },
                ..Default::default()
            };
            if let Some(dt) = sc.engine.dt {
                settings.timestep = dt;
            }
            let json = serde_json::json!({
                "engine": "mujoco 3.17.0",
                "timestep": settings.timestep,
                "cone": settings.cone.as_str(),
                "label": settings.label(),
            });
            Some((Box::new(pushval_mujoco::MujocoSimulator { settings }), json))
        }
        idiom => {
            // The 2-D friction idioms (informational): the scenario's engine
            // settings with the idiom's friction law; slip speed 0.01 m/s for
            // the regularised laws (see results/friction_models/).
            let friction_model = match idiom {
                ModelKind::Rapier2dImpulseDisk => FrictionModel::ImpulseDisk,
                ModelKind::Rapier2dImpulseBox => FrictionModel::ImpulseBox,
                ModelKind::Rapier2dRegularisedLinear => {
                    FrictionModel::RegularisedLinear { slip_speed: 0.01 }
                }
                _ => FrictionModel::RegularisedTanh { slip_speed: 0.01 },
            };
            let settings = EngineSettings {
                friction_model,
                ..engine_settings(sc)
            };
            let mut json = engine_settings_json(&settings);
            json["friction_model"] = serde_json::json!(friction_model.as_str());
            // Informational rows keep the adapter's step: their findings
            // (results/friction_models/) are stated at it.
            json["dt_source"] = serde_json::json!(if sc.engine.dt.is_some() {
                "scenario"
            } else {
                "adapter default"
            });
            Some((Box::new(RapierSimulator { settings }), json))
        }
    }
}

/// The convergence order a friction-velocity scheme shows (measured: see
/// the engine crate's README).
pub fn expected_order(s: &EngineSettings) -> f64 {
    match s.friction_velocity {
        pushval_rapier::FrictionVelocity::Leapfrog => 2.0,
        _ => 1.0,
    }
}

fn engine_run(problem: &Problem, settings: EngineSettings) -> Result<EngineRun, ModelError> {
    RapierSimulator { settings }.run(problem)
}

/// The largest engine time step the automatic choice tries (s): 1/60 s,
/// rapier's own default step and the usual game-engine frame. Coarser steps
/// would put several 0.01 s samples inside one step and stop resolving the
/// relaxation times of the shipped scenes (τ ≈ 0.05–0.3 s).
pub const DT_LADDER_TOP: f64 = 1.0 / 60.0;

/// No rung of the automatic ladder is below this (s). Eight rungs, 1/60 s to
/// 1/7680 s ≈ 1.3e-4 s: at the bottom a second-order step is 16 000 times
/// more accurate than at the top and a 10 s scene takes 77 000 steps (about
/// 0.2 s); a scene that needs less than that has a problem worth seeing
/// rather than a step to shrink.
pub const DT_FLOOR: f64 = 1e-4;

/// The share of each `[tolerance]` figure the engine's own discretisation
/// error may use up at the automatic step. The gate compares engine and
/// model, so the engine's error eats into the tolerance a model error must
/// exceed to be caught: at 1/4 a model error of 5/4 of the tolerance always
/// fails the gate, and at most 1/4 is hidden. The margin also covers the
/// estimate itself, which assumes the asymptotic order: at the coarse rungs
/// the observed order can be off (the convergence check reports it) and the
/// estimate off by a factor of 2 or so.
pub const DT_FRACTION: f64 = 0.25;

/// The rungs of the automatic time-step ladder, largest first:
/// `DT_LADDER_TOP / 2^k` down to [`DT_FLOOR`].
pub fn dt_ladder() -> Vec<f64> {
    std::iter::successors(Some(DT_LADDER_TOP), |h| Some(h / 2.0))
        .take_while(|h| *h >= DT_FLOOR)
        .collect()
}

/// Where the engine's time step came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DtSource {
    /// `[engine] dt` in the scenario, kept exactly.
    Scenario,
    /// Chosen by [`choose_engine_dt`].
    Automatic,
}

/// The engine's self-convergence error estimate at one time step h, from
/// the runs at h and h/2 alone (never against the model): Richardson's
/// `|X(h) − X(h/2)| · 2^p / (2^p − 1)` for the scheme's order p, for each
/// gated figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DtEstimate {
    /// The time step h (s).
    pub dt: f64,
    /// Largest centre-of-mass distance over the samples (m).
    pub position_max: f64,
    /// Largest angle difference over the samples (rad).
    pub theta_max: f64,
    /// Largest relative steady-ω difference over the segments the gate
    /// reads a steady ω from (tail means; denominator the run at h/2 with
    /// [`rel_err`]'s floor); None when no segment settles.
    pub omega_steady_rel_max: Option<f64>,
    /// Whether every figure is within [`DT_FRACTION`] of its tolerance.
    pub meets: bool,
}

/// How the engine's time step was chosen, for the outputs.
#[derive(Debug, Clone)]
pub struct DtChoice {
    /// The time step the gated engine run uses (s).
    pub dt: f64,
    pub source: DtSource,
    /// Automatic only: every rung tried, largest first; the last one is the
    /// chosen one.
    pub rungs: Vec<DtEstimate>,
    /// Automatic only: false when not even the ladder's floor met the
    /// criterion (the floor is used then).
    pub met: bool,
    /// The scheme's order used in the estimate.
    pub order: f64,
    /// Wall time of the search's engine runs (the chosen run and its h/2
    /// partner included).
    pub search_time: Duration,
}

impl DtChoice {
    /// One line saying which dt and why.
    pub fn reason(&self, sc: &Scenario) -> String {
        let t = &sc.tolerance;
        let f = DT_FRACTION;
        let figures = |e: &DtEstimate| {
            format!(
                "position {:.2e} m, theta {:.2e} rad, steady omega {} (targets {:.2e} m, {:.2e} rad, {:.2e})",
                e.position_max,
                e.theta_max,
                e.omega_steady_rel_max.map_or("-".into(), |w| format!("{w:.2e}")),
                f * t.position_max,
                f * t.theta_max,
                f * t.omega_steady_rel
            )
        };
        match (self.source, self.rungs.last()) {
            (DtSource::Scenario, _) | (_, None) => {
                format!("dt = {} s set by the scenario's [engine] dt", self.dt)
            }
            (DtSource::Automatic, Some(last)) => {
                let mut s = if self.met {
                    format!(
                        "dt = {:.4e} s: the largest ladder rung whose self-convergence estimate is within {f} of the tolerances: {}",
                        self.dt,
                        figures(last)
                    )
                } else {
                    format!(
                        "dt = {:.4e} s (the ladder's floor) although its estimate misses {f} of the tolerances: {}",
                        self.dt,
                        figures(last)
                    )
                };
                if self.rungs.len() >= 2 {
                    let prev = &self.rungs[self.rungs.len() - 2];
                    s.push_str(&format!("; {:.4e} s misses: {}", prev.dt, figures(prev)));
                }
                s
            }
        }
    }

    /// The record written into the engine's settings in `summary.json`.
    pub fn json(&self, sc: &Scenario) -> serde_json::Value {
        use crate::output::num;
        let rungs: Vec<serde_json::Value> = self
            .rungs
            .iter()
            .map(|e| {
                serde_json::json!({
                    "dt": num(e.dt),
                    "position_max_estimate": num(e.position_max),
                    "theta_max_estimate": num(e.theta_max),
                    "omega_steady_rel_max_estimate": e.omega_steady_rel_max.map_or(serde_json::Value::Null, num),
                    "meets": e.meets,
                })
            })
            .collect();
        let t = &sc.tolerance;
        serde_json::json!({
            "source": match self.source {
                DtSource::Scenario => "scenario",
                DtSource::Automatic => "automatic",
            },
            "reason": self.reason(sc),
            "criterion": "Richardson self-convergence estimate |X(h) - X(h/2)| 2^p / (2^p - 1) of each gated figure within fraction x [tolerance]",
            "fraction": DT_FRACTION,
            "order": self.order,
            "ladder": dt_ladder(),
            "targets": {
                "position_max": num(DT_FRACTION * t.position_max),
                "theta_max": num(DT_FRACTION * t.theta_max),
                "omega_steady_rel": num(DT_FRACTION * t.omega_steady_rel),
            },
            "met": self.met,
            "rungs": rungs,
            "search_wall_time_s": num(self.search_time.as_secs_f64()),
        })
    }
}

/// The self-convergence estimate at h from the runs at h (`coarse`) and
/// h/2 (`fine`) of a scheme of order `order`.
pub fn dt_estimate(
    sc: &Scenario,
    segments: &[SegmentInfo],
    h: f64,
    coarse: &Trajectory,
    fine: &Trajectory,
    order: f64,
) -> DtEstimate {
    let k = 2f64.powf(order) / (2f64.powf(order) - 1.0);
    let mut position_max: f64 = 0.0;
    let mut theta_max: f64 = 0.0;
    for (a, b) in coarse.samples.iter().zip(&fine.samples) {
        position_max = position_max.max(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt());
        theta_max = theta_max.max((a.theta - b.theta).abs());
    }
    if coarse.samples.len() != fine.samples.len() {
        position_max = f64::INFINITY;
        theta_max = f64::INFINITY;
    }
    let mut omega: Option<f64> = None;
    for s in segments.iter().filter(|s| s.settles()) {
        let (Some(wc), Some(wf)) = (
            tail_omega(coarse, s.t_start, s.t_end),
            tail_omega(fine, s.t_start, s.t_end),
        ) else {
            continue;
        };
        let e = rel_err(wc, wf, s.speed, sc.froude_length());
        omega = Some(omega.map_or(e, |m: f64| m.max(e)));
    }
    let (position_max, theta_max) = (k * position_max, k * theta_max);
    let omega_steady_rel_max = omega.map(|e| k * e);
    let t = &sc.tolerance;
    let meets = position_max <= DT_FRACTION * t.position_max
        && theta_max <= DT_FRACTION * t.theta_max
        && omega_steady_rel_max.is_none_or(|e| e <= DT_FRACTION * t.omega_steady_rel);
    DtEstimate {
        dt: h,
        position_max,
        theta_max,
        omega_steady_rel_max,
        meets,
    }
}

/// The engine's time step for the gate: the scenario's `[engine] dt` when
/// set, otherwise the largest rung of [`dt_ladder`] whose self-convergence
/// estimate ([`dt_estimate`], engine runs at h and h/2 only) is within
/// [`DT_FRACTION`] of every `[tolerance]` figure, or the floor when none is.
/// `segments` (from the dynamic model's run) only say which segments the
/// gate reads a steady ω from. Returns the settings, the choice and every
/// engine run made, for reuse.
pub fn choose_engine_dt(
    sc: &Scenario,
    problem: &Problem,
    segments: &[SegmentInfo],
) -> Result<(EngineSettings, DtChoice, Vec<EngineRun>), ModelError> {
    let base = engine_settings(sc);
    let order = expected_order(&base);
    let start = Instant::now();
    if sc.engine.dt.is_some() {
        return Ok((
            base,
            DtChoice {
                dt: base.dt,
                source: DtSource::Scenario,
                rungs: Vec::new(),
                met: true,
                order,
                search_time: Duration::ZERO,
            },
            Vec::new(),
        ));
    }
    let ladder = dt_ladder();
    let mut runs: Vec<EngineRun> = Vec::new();
    let mut rungs = Vec::new();
    let run_at = |dt: f64, runs: &mut Vec<EngineRun>| -> Result<usize, ModelError> {
        if let Some(i) = runs.iter().position(|r| r.settings.dt == dt) {
            return Ok(i);
        }
        runs.push(engine_run(problem, EngineSettings { dt, ..base })?);
        Ok(runs.len() - 1)
    };
    let mut last_err = None;
    let mut announced = false;
    for (i, &h) in ladder.iter().enumerate() {
        if !announced && start.elapsed() > Duration::from_secs(2) {
            eprintln!(
                "pushval: {}: choosing the engine time step (trying dt = {h:.3e} s, rung {} of {})",
                sc.name,
                i + 1,
                ladder.len()
            );
            announced = true;
        }
        // A rung whose runs fail (blow up) does not meet the criterion.
        let pair = run_at(h, &mut runs).and_then(|a| Ok((a, run_at(h / 2.0, &mut runs)?)));
        let (a, b) = match pair {
            Ok(p) => p,
            Err(e) => {
                last_err = Some(e);
                continue;
            }
        };
        let est = dt_estimate(
            sc,
            segments,
            h,
            &runs[a].trajectory,
            &runs[b].trajectory,
            order,
        );
        rungs.push(est);
        if est.meets || i + 1 == ladder.len() {
            let settings = EngineSettings { dt: h, ..base };
            return Ok((
                settings,
                DtChoice {
                    dt: h,
                    source: DtSource::Automatic,
                    rungs,
                    met: est.meets,
                    order,
                    search_time: start.elapsed(),
                },
                runs,
            ));
        }
    }
    Err(last_err.expect("the ladder's floor either returns or fails"))
}

/// Runs the engine at 2h and 4h beside the run at h and measures how its
/// steady ω converges.
fn engine_convergence(
    sc: &Scenario,
    problem: &Problem,
    segments: &[SegmentInfo],
    fine: &Trajectory,
    reference: &Trajectory,
    settings: EngineSettings,
    done: &[EngineRun],
) -> Result<Convergence, ModelError> {
    let h = settings.dt;
    // Runs the search already made at 2h or 4h are reused (same settings,
    // deterministic: the same trajectory).
    let at = |dt: f64| -> Result<Trajectory, ModelError> {
        match done
            .iter()
            .find(|r| r.settings == EngineSettings { dt, ..settings })
        {
            Some(r) => Ok(r.trajectory.clone()),
            None => engine_run(problem, EngineSettings { dt, ..settings }).map(|r| r.trajectory),
        }
    };
    let mid = at(2.0 * h)?;
    let coarse = at(4.0 * h)?;
    let order = expected_order(&settings);
    let mut out = Convergence {
        expected_order: order,
        dts: [4.0 * h, 2.0 * h, h],
        orders: Vec::new(),
        richardson1_rel_max: 0.0,
        richardson2_rel_max: 0.0,
        plain_rel_max: 0.0,
    };
    for s in segments.iter().filter(|s| s.settles()) {
        // The same reading (tail mean) of the dynamic model: within 1e-6 of ω*
        // on a settled segment, and free of the residual transient.
        let Some(ws) = tail_omega(reference, s.t_start, s.t_end) else {
            continue;
        };
        let w = |tr: &Trajectory| tail_omega(tr, s.t_start, s.t_end);
        let (Some(w1), Some(w2), Some(w4)) = (w(fine), w(&mid), w(&coarse)) else {
            continue;
        };
        let p = ((w4 - w2).abs() / (w2 - w1).abs()).log2();
        out.orders.push((s.index, p));
        // Richardson with the scheme's order p, then once more for p + 1.
        let k1 = 2f64.powf(order) - 1.0;
        let k2 = 2f64.powf(order + 1.0) - 1.0;
        let r1 = w1 + (w1 - w2) / k1;
        let r1_coarse = w2 + (w2 - w4) / k1;
        let r2 = r1 + (r1 - r1_coarse) / k2;
        let e = |x: f64| rel_err(x, ws, s.speed, sc.froude_length());
        out.richardson1_rel_max = out.richardson1_rel_max.max(e(r1));
        out.richardson2_rel_max = out.richardson2_rel_max.max(e(r2));
        out.plain_rel_max = out.plain_rel_max.max(e(w1));
    }
    Ok(out)
}

/// Steady ω per segment read off a trajectory: the mean ω over the last 20 %
/// of the segment (samples strictly before its end).
pub fn tail_omega(tr: &Trajectory, t_start: f64, t_end: f64) -> Option<f64> {
    let from = t_end - 0.2 * (t_end - t_start);
    let eps = 1e-9 * (t_end - t_start);
    let w: Vec<f64> = tr
        .samples
        .iter()
        .filter(|s| s.t >= from - eps && s.t < t_end - eps)
        .map(|s| s.omega)
        .collect();
    (!w.is_empty()).then(|| w.iter().sum::<f64>() / w.len() as f64)
}

/// The steady-state analysis of every segment, following ω across switches.
pub fn analyse_segments(
    sc: &Scenario,
    problem: &Problem,
    dynamic: &Trajectory,
) -> Vec<SegmentInfo> {
    analyse_segments_with(sc, problem, dynamic, InertialTerm::Derived)
}

/// [`analyse_segments`] for a chosen reading of the inertial term.
pub fn analyse_segments_with(
    sc: &Scenario,
    problem: &Problem,
    dynamic: &Trajectory,
    term: InertialTerm,
) -> Vec<SegmentInfo> {
    problem
        .pushes
        .iter()
        .zip(problem.segment_times())
        .enumerate()
        .map(|(j, (push, (t0, t1)))| {
            let seg = SegmentDynamics::with_inertial_term(&problem.body, push, term);
            let roots = if push.speed > 0.0 {
                seg.steady_states()
            } else {
                vec![]
            };
            let omega_start = dynamic.segments.get(j).map_or(0.0, |s| s.omega_start);
            let omega_steady = if push.speed > 0.0 {
                seg.attractor(&roots, omega_start)
            } else {
                None
            };
            let tail_deviation = omega_steady.and_then(|r| {
                tail_omega(dynamic, t0, t1)
                    .map(|w| rel_err(w, r.omega, push.speed, sc.froude_length()))
            });
            SegmentInfo {
                index: j,
                t_start: t0,
                t_end: t1,
                speed: push.speed,
                phi: push.phi,
                froude: sc.froude(push.speed),
                omega_kinematic: kinematic::omega(&problem.body, push),
                omega_limit_surface: limit_surface::omega(&problem.body, push),
                omega_steady,
                steady_states: roots,
                omega_start,
                tail_deviation,
            }
        })
        .collect()
}

/// Relative steady-ω error with a floor for segments whose ω* is (near) zero:
/// the denominator is at least 1e-3 v_c / L.
pub fn rel_err(w: f64, reference: f64, speed: f64, length: f64) -> f64 {
    (w - reference).abs() / reference.abs().max(1e-3 * speed / length)
}

/// Compares a model run with the dynamic model.
pub fn compare(
    sc: &Scenario,
    segments: &[SegmentInfo],
    reference: &Trajectory,
    run: &ModelRun,
    gated: bool,
) -> Comparison {
    let steady = match run.kind {
        ModelKind::Dynamic | ModelKind::Kinematic | ModelKind::LimitSurface => {
            SteadyRead::SegmentEnd
        }
        _ => SteadyRead::TailMean,
    };
    compare_trajectory(
        sc,
        segments,
        reference,
        run.kind.name(),
        &run.trajectory,
        steady,
        gated,
    )
}

/// How a trajectory's steady ω per segment is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SteadyRead {
    /// ω at the segment's end (analytic models: exact).
    SegmentEnd,
    /// Mean ω over the segment's last 20 % (engines, outside trajectories).
    TailMean,
}

/// Compares any trajectory, named `name`, with a reference at common sample
/// times, and its steady ω with the roots ω* of the settled segments.
pub fn compare_trajectory(
    sc: &Scenario,
    segments: &[SegmentInfo],
    reference: &Trajectory,
    name: &str,
    tr: &Trajectory,
    steady: SteadyRead,
    gated: bool,
) -> Comparison {
    let mut position_max: f64 = 0.0;
    let mut theta_max: f64 = 0.0;
    for (a, b) in tr.samples.iter().zip(&reference.samples) {
        position_max = position_max.max(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt());
        theta_max = theta_max.max((a.theta - b.theta).abs());
    }
    if tr.samples.len() != reference.samples.len() {
        position_max = f64::INFINITY;
        theta_max = f64::INFINITY;
    }
    let mut omega_rel: Option<f64> = None;
    for s in segments.iter().filter(|s| s.settles()) {
        let ws = s.omega_steady.expect("settles implies a root").omega;
        let w = match steady {
            SteadyRead::SegmentEnd => tr.segments.get(s.index).map(|r| r.omega_end),
            SteadyRead::TailMean => tail_omega(tr, s.t_start, s.t_end),
        };
        if let Some(w) = w {
            let e = rel_err(w, ws, s.speed, sc.froude_length());
            omega_rel = Some(omega_rel.map_or(e, |m: f64| m.max(e)));
        }
    }
    let tol = &sc.tolerance;
    let mut failed = Vec::new();
    if gated {
        if !(position_max <= tol.position_max) {
            failed.push(format!(
                "position_max {position_max:.3e} m > {:.3e} m",
                tol.position_max
            ));
        }
        if !(theta_max <= tol.theta_max) {
            failed.push(format!(
                "theta_max {theta_max:.3e} rad > {:.3e} rad",
                tol.theta_max
            ));
        }
        if let Some(e) = omega_rel {
            if !(e <= tol.omega_steady_rel) {
                failed.push(format!(
                    "omega_steady_rel_max {e:.3e} > {:.3e}",
                    tol.omega_steady_rel
                ));
            }
        }
    }
    Comparison {
        model: name.into(),
        position_max,
        theta_max,
        omega_steady_rel_max: omega_rel,
        pass: gated.then_some(failed.is_empty()),
        failed,
        error: None,
        convergence: None,
    }
}

/// Runs every model the scenario asks for (the dynamic model always, as the
/// reference) and compares each with the dynamic model. Engine models are
/// gated by the scenario's `[tolerance]`; the quasi-static models are
/// informational; the dynamic row checks the integrated ω against the roots.
pub fn run_scenario(sc: &Scenario, opts: &RunOptions) -> Result<ScenarioReport, ModelError> {
    let problem = sc.problem();
    let mut kinds: Vec<ModelKind> = vec![ModelKind::Dynamic];
    kinds.extend(
        sc.models
            .iter()
            .copied()
            .filter(|k| *k != ModelKind::Dynamic),
    );
    let mut runs: Vec<ModelRun> = Vec::new();
    let mut missing = Vec::new();
    let mut failures: Vec<(ModelKind, String)> = Vec::new();
    // The gated engine's time step and the engine runs its choice made.
    let mut gate_engine: Option<(EngineSettings, Vec<EngineRun>)> = None;
    for kind in kinds {
        let Some((sim, mut settings)) = simulator(kind, sc, opts) else {
            missing.push(kind);
            continue;
        };
        let t0 = Instant::now();
        let (result, diagnostics, elapsed) = if kind == ModelKind::Rapier2d {
            // The dynamic model ran first: its segments say which ones the
            // gate reads a steady ω from.
            let segments = analyse_segments(sc, &problem, &runs[0].trajectory);
            let chosen = choose_engine_dt(sc, &problem, &segments).and_then(|(s, choice, done)| {
                let run = match done.iter().find(|r| r.settings == s) {
                    Some(r) => r.clone(),
                    None => engine_run(&problem, s)?,
                };
                Ok((s, choice, done, run))
            });
            match chosen {
                Ok((s, choice, done, r)) => {
                    settings = engine_settings_json(&s);
                    settings["dt_source"] = serde_json::json!(match choice.source {
                        DtSource::Scenario => "scenario",
                        DtSource::Automatic => "automatic",
                    });
                    settings["dt_choice"] = choice.json(sc);
                    let elapsed = r.wall_time;
                    gate_engine = Some((s, done));
                    (
                        Ok(r.trajectory),
                        serde_json::json!({"max_joint_drift": r.max_joint_drift, "steps": r.steps}),
                        elapsed,
                    )
                }
                Err(e) => (Err(e), serde_json::Value::Null, t0.elapsed()),
            }
        } else {
            let result = sim.simulate(&problem);
            (result, serde_json::Value::Null, t0.elapsed())
        };
        match result {
            Ok(trajectory) => runs.push(ModelRun {
                kind,
                trajectory,
                settings,
                elapsed,
                diagnostics,
            }),
            Err(e) if kind == ModelKind::Dynamic => return Err(e),
            Err(e) => failures.push((kind, e.to_string())),
        }
    }
    let reference = runs[0].trajectory.clone();
    let segments = analyse_segments(sc, &problem, &reference);
    let mut comparisons: Vec<Comparison> = runs
        .iter()
        .map(|r| {
            let gated = matches!(r.kind, ModelKind::Rapier2d);
            compare(sc, &segments, &reference, r, gated)
        })
        .collect();
    for c in comparisons.iter_mut().filter(|c| c.model == "rapier2d") {
        let run = runs
            .iter()
            .find(|r| r.kind == ModelKind::Rapier2d)
            .expect("compared runs exist");
        let (settings, done) = gate_engine
            .as_ref()
            .expect("a rapier2d run has its settings");
        c.convergence = Some(engine_convergence(
            sc,
            &problem,
            &segments,
            &run.trajectory,
            &reference,
            *settings,
            done,
        )?);
    }
    for (kind, e) in failures {
        // An engine that blows up fails the gate and says where; an
        // informational model's failure is reported without failing it.
        let gated = kind == ModelKind::Rapier2d;
        comparisons.push(Comparison {
            model: kind.name().into(),
            position_max: f64::NAN,
            theta_max: f64::NAN,
            omega_steady_rel_max: None,
            pass: gated.then_some(false),
            failed: vec![format!("run failed: {e}")],
            error: Some(e),
            convergence: None,
        });
    }
    for kind in missing {
        comparisons.push(Comparison {
            model: kind.name().into(),
            position_max: f64::NAN,
            theta_max: f64::NAN,
            omega_steady_rel_max: None,
            pass: None,
            failed: vec![],
            error: Some("not available in this build".into()),
            convergence: None,
        });
    }
    Ok(ScenarioReport {
        scenario: sc.clone(),
        segments,
        runs,
        comparisons,
    })
}
