//! Running and comparing the models of one scenario.

use std::time::{Duration, Instant};

use pushval_model::{
    kinematic, limit_surface, DynamicModel, Integrator, KinematicModel, LimitSurfaceModel,
    ModelError, Problem, RootKind, SegmentDynamics, Simulator, SteadyState, Trajectory,
};
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

/// The simulator for a model kind, or None for a model this build cannot run.
fn simulator(
    kind: ModelKind,
    sc: &Scenario,
    opts: &RunOptions,
) -> Option<(Box<dyn Simulator>, serde_json::Value)> {
    let _ = sc;
    match kind {
        ModelKind::Dynamic => Some((
            Box::new(DynamicModel {
                integrator: Integrator::Adaptive {
                    tol: opts.model_tol,
                },
                ..Default::default()
            }),
            serde_json::json!({"integrator": "dormand_prince_5_4", "tolerance": opts.model_tol, "skip_settled": true}),
        )),
        ModelKind::Kinematic => Some((Box::new(KinematicModel), serde_json::json!({}))),
        ModelKind::LimitSurface => Some((Box::new(LimitSurfaceModel), serde_json::json!({}))),
        ModelKind::Rapier2d => None,
    }
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
    problem
        .pushes
        .iter()
        .zip(problem.segment_times())
        .enumerate()
        .map(|(j, (push, (t0, t1)))| {
            let seg = SegmentDynamics::new(&problem.body, push);
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
    let tr = &run.trajectory;
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
        let w = match run.kind {
            ModelKind::Dynamic => tr.segments.get(s.index).map(|r| r.omega_end),
            ModelKind::Kinematic | ModelKind::LimitSurface => {
                tr.segments.get(s.index).map(|r| r.omega_end)
            }
            _ => tail_omega(tr, s.t_start, s.t_end),
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
        model: run.kind.name().into(),
        position_max,
        theta_max,
        omega_steady_rel_max: omega_rel,
        pass: gated.then_some(failed.is_empty()),
        failed,
        error: None,
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
    let mut runs = Vec::new();
    let mut missing = Vec::new();
    for kind in kinds {
        let Some((sim, settings)) = simulator(kind, sc, opts) else {
            missing.push(kind);
            continue;
        };
        let t0 = Instant::now();
        let result = sim.simulate(&problem);
        let elapsed = t0.elapsed();
        match result {
            Ok(trajectory) => runs.push(ModelRun {
                kind,
                trajectory,
                settings,
                elapsed,
            }),
            Err(e) if kind == ModelKind::Dynamic => return Err(e),
            Err(e) => missing.push({
                let _ = e;
                kind
            }),
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
    for kind in missing {
        comparisons.push(Comparison {
            model: kind.name().into(),
            position_max: f64::NAN,
            theta_max: f64::NAN,
            omega_steady_rel_max: None,
            pass: None,
            failed: vec![],
            error: Some("not available in this build".into()),
        });
    }
    Ok(ScenarioReport {
        scenario: sc.clone(),
        segments,
        runs,
        comparisons,
    })
}
