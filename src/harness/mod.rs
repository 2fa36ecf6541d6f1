//! Running and comparing the models of one scenario.

use std::time::{Duration, Instant};

use pushval_engine::{Engine, EngineRun};
use pushval_model::{
    DynamicModel, Integrator, KinematicModel, LimitSurfaceModel, ModelError, Problem, Sample,
    Simulator, Trajectory,
};
use pushval_scenario::Scenario;

use crate::registry;

mod dt;
mod figures;
pub mod law;
pub mod rest;
mod segments;
pub mod tolerance;

pub use dt::{
    choose_engine_dt, dt_estimate, dt_ladder, engine_convergence, trajectory_order, Convergence,
    DtChoice, DtEstimate, DtSource, StopFloor, TrajectoryOrder, DT_FLOOR, DT_FRACTION,
    DT_LADDER_TOP,
};
pub use rest::{paired, rest_of, Rest, RestDiff};
pub use segments::{analyse_segments, analyse_segments_with, tail_omega, SegmentInfo, SETTLED_REL};
pub use tolerance::{Catches, Figures, Resolved, StopTolerance, CATCH_PROBE};

/// Settings of a harness run.
#[derive(Debug, Clone, Copy)]
pub struct RunOptions {
    /// Tolerance of the dynamic model's adaptive integrator. Default 1e-10.
    pub model_tol: f64,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            model_tol: crate::inject::MODEL_TOL,
        }
    }
}

/// What one model produced.
#[derive(Debug, Clone)]
pub struct ModelRun {
    /// The model's name (`"dynamic"`, `"rapier2d"`, …).
    pub name: String,
    /// Whether it is an engine model (from the registry).
    pub engine: bool,
    pub trajectory: Trajectory,
    /// The settings that produced it, for the outputs.
    pub settings: serde_json::Value,
    /// Wall time of the run.
    pub elapsed: Duration,
    /// Engine diagnostics (joint drift, steps, convergence in dt); null for
    /// the analytic models.
    pub diagnostics: serde_json::Value,
}

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
    /// Gated rows: the tolerances asserted and where they came from.
    pub tolerance: Option<Resolved>,
    /// With a `[release]`: the run's rest against the model's.
    pub rest: Option<RestDiff>,
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
            .find(|r| r.name == "dynamic")
            .expect("the dynamic model always runs")
    }
    /// False when a gated comparison failed.
    pub fn pass(&self) -> bool {
        self.comparisons.iter().all(|c| c.pass != Some(false))
    }
}

/// The engine the report's figures draw beside the models: the scenario's
/// first gated engine (the default gate when it gates none), with its
/// `[engine]` settings.
pub fn reference_engine(sc: &Scenario) -> Box<dyn Engine> {
    let name = sc
        .gate
        .first()
        .map_or(pushval_scenario::DEFAULT_GATE[0], String::as_str);
    registry::engine(name, &registry::engine_options(sc))
}

/// The analytic model called `name`, with its settings record; None for an
/// engine model.
fn analytic(name: &str, opts: &RunOptions) -> Option<(Box<dyn Simulator>, serde_json::Value)> {
    match name {
        "dynamic" => Some((
            Box::new(DynamicModel {
                integrator: Integrator::Dop853 {
                    tol: opts.model_tol,
                },
                ..Default::default()
            }),
            serde_json::json!({"integrator": "dop853", "tolerance": opts.model_tol, "skip_settled": true}),
        )),
        "kinematic" => Some((Box::new(KinematicModel), serde_json::json!({}))),
        "limit_surface" => Some((Box::new(LimitSurfaceModel), serde_json::json!({}))),
        _ => None,
    }
}

pub use pushval_engine::rel_err;

/// Compares a model run with the dynamic model.
pub fn compare(
    sc: &Scenario,
    segments: &[SegmentInfo],
    reference: &Trajectory,
    run: &ModelRun,
    tol: Option<&Figures>,
) -> Comparison {
    let steady = if run.engine {
        SteadyRead::TailMean
    } else {
        SteadyRead::SegmentEnd
    };
    compare_trajectory(
        sc,
        segments,
        reference,
        &run.name,
        &run.trajectory,
        steady,
        tol,
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
    tol: Option<&Figures>,
) -> Comparison {
    let problem = sc.problem();
    // Runs through a slide stop at different times: past its stop the
    // shorter one is compared by its rest.
    let pairs = paired(tr, reference).unwrap_or_default();
    let mut position_max: f64 = 0.0;
    let mut theta_max: f64 = 0.0;
    for (a, b) in &pairs {
        position_max = position_max.max(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt());
        theta_max = theta_max.max((a.theta - b.theta).abs());
    }
    if pairs.is_empty() {
        position_max = f64::INFINITY;
        theta_max = f64::INFINITY;
    }
    let rest = rest::rest_diff(&problem, reference, tr);
    let mut omega_rel: Option<f64> = None;
    let mut steady_errors: Vec<(usize, f64)> = Vec::new();
    for s in segments.iter().filter(|s| s.settles()) {
        let ws = s.omega_steady.expect("settles implies a root").omega;
        let w = match steady {
            SteadyRead::SegmentEnd => tr.segments.get(s.index).map(|r| r.omega_end),
            SteadyRead::TailMean => tail_omega(tr, s.t_start, s.t_end),
        };
        if let Some(w) = w {
            let e = rel_err(w, ws, s.speed, sc.froude_length());
            omega_rel = Some(omega_rel.map_or(e, |m: f64| m.max(e)));
            steady_errors.push((s.index, e));
        }
    }
    let gated = tol.is_some();
    let mut failed = Vec::new();
    if let Some(tol) = tol {
        // Where each failing figure first exceeds its tolerance: the first
        // sample time and its segment (a switch time belongs to the segment
        // it starts), or the first settled segment past the steady tolerance.
        let times = problem.segment_times();
        let segment_of = |t: f64| {
            times
                .iter()
                .position(|&(_, t1)| t < t1 - 1e-9 * t1.max(1.0))
                .unwrap_or(times.len().saturating_sub(1))
        };
        let first = |exceeds: &dyn Fn(&Sample, &Sample) -> bool| {
            pairs
                .iter()
                .find(|(a, b)| exceeds(a, b))
                .map_or(String::new(), |(a, _)| {
                    if a.t >= times.last().map_or(0.0, |t| t.1) && problem.release.is_some() {
                        format!(" (first at t = {:.3} s, in the slide)", a.t)
                    } else {
                        format!(" (first at t = {:.3} s, segment {})", a.t, segment_of(a.t))
                    }
                })
        };
        if !(position_max <= tol.position_max) {
            let at = first(&|a, b| {
                !(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt() <= tol.position_max)
            });
            failed.push(format!(
                "position_max {position_max:.3e} m > {:.3e} m{at}",
                tol.position_max
            ));
        }
        if !(theta_max <= tol.theta_max) {
            let at = first(&|a, b| !((a.theta - b.theta).abs() <= tol.theta_max));
            failed.push(format!(
                "theta_max {theta_max:.3e} rad > {:.3e} rad{at}",
                tol.theta_max
            ));
        }
        if let Some(e) = omega_rel {
            if !(e <= tol.omega_steady_rel) {
                let at = steady_errors
                    .iter()
                    .find(|(_, e)| !(*e <= tol.omega_steady_rel))
                    .map_or(String::new(), |(j, _)| format!(" (first in segment {j})"));
                failed.push(format!(
                    "omega_steady_rel_max {e:.3e} > {:.3e}{at}",
                    tol.omega_steady_rel
                ));
            }
        }
    }
    if let (Some(tol), Some(r)) = (tol, &rest) {
        failed.extend(rest_failures(r, tol));
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
        tolerance: None,
        rest,
    }
}

/// Why a run's rest fails the gate: it did not stop where the model did,
/// or its rest pose is farther from the model's than the position and
/// angle tolerances (the stop time is held to its own tolerance in
/// [`run_scenario`]).
fn rest_failures(r: &RestDiff, tol: &Figures) -> Vec<String> {
    match (r.run, r.reference) {
        (None, Some(m)) => vec![format!(
            "the plate did not stop within the release's max_duration; the model stops at t = {:.4} s",
            m.t
        )],
        (Some(a), None) => vec![format!(
            "the plate stopped at t = {:.4} s; the model is still moving at the release's max_duration",
            a.t
        )],
        (None, None) => Vec::new(),
        (Some(_), Some(_)) => {
            let mut out = Vec::new();
            if !(r.position <= tol.position_max) {
                out.push(format!(
                    "rest position {:.3e} m from the model's > {:.3e} m",
                    r.position, tol.position_max
                ));
            }
            if !(r.theta <= tol.theta_max) {
                out.push(format!(
                    "rest angle {:.3e} rad from the model's > {:.3e} rad",
                    r.theta, tol.theta_max
                ));
            }
            out
        }
    }
}

/// [`Catches`] for tolerances `tol` on a scenario whose dynamic-model
/// trajectory is `reference`.
pub fn catchable(
    sc: &Scenario,
    segments: &[SegmentInfo],
    reference: &Trajectory,
    tol: &Figures,
) -> Catches {
    use crate::inject::{inject, ErrorKind};
    let one = |kind: ErrorKind| -> Option<(f64, &'static str)> {
        // Mean of |ΔX| over the two signs, per figure.
        let mut sens = [0.0f64; 3];
        for sign in [1.0, -1.0] {
            let tr = inject(sc, kind, sign * CATCH_PROBE)?;
            let c = compare_trajectory(
                sc,
                segments,
                reference,
                "probe",
                &tr,
                SteadyRead::SegmentEnd,
                None,
            );
            sens[0] += 0.5 * c.position_max / CATCH_PROBE;
            sens[1] += 0.5 * c.theta_max / CATCH_PROBE;
            sens[2] += 0.5 * c.omega_steady_rel_max.unwrap_or(0.0) / CATCH_PROBE;
        }
        let tols = [tol.position_max, tol.theta_max, tol.omega_steady_rel];
        let names = ["position_max", "theta_max", "omega_steady_rel"];
        (0..3)
            .filter(|&i| sens[i] > 0.0 && sens[i].is_finite())
            .map(|i| (tols[i] / sens[i], names[i]))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    };
    Catches {
        inertia_cm: one(ErrorKind::InertiaCm),
        mu_all: one(ErrorKind::MuAll),
    }
}

/// The hint a failing gated row of a `switching = "continuous"` scenario
/// carries when the engine switched impulsively: its trajectory is nearer
/// the model's impulsive switching than the continuous one the scenario
/// asks for. None when the scenario switches impulsively, has no switch, or
/// the engine follows the continuous rule (the adapter kit does).
fn switching_hint(
    sc: &Scenario,
    problem: &Problem,
    continuous: &Trajectory,
    engine: &Trajectory,
) -> Option<String> {
    use pushval_model::Switching;
    if problem.switching != Switching::Continuous
        || !(problem.pushes.len() > 1 || sc.initial.from_rest)
    {
        return None;
    }
    let mut p = problem.clone();
    p.switching = Switching::Impulsive;
    let impulsive = DynamicModel::default().simulate(&p).ok()?;
    let distance = |a: &Trajectory| {
        let d = a
            .samples
            .iter()
            .zip(&engine.samples)
            .map(|(s, r)| (s.theta - r.theta).abs())
            .fold(0.0, f64::max);
        (a.samples.len() == engine.samples.len()).then_some(d)
    };
    let (di, dc) = (distance(&impulsive)?, distance(continuous)?);
    (di < dc).then(|| {
        format!(
            "the engine switched impulsively (its angle is within {di:.2e} rad of the model's impulsive switching, {dc:.2e} rad of the continuous one): switching = \"continuous\" blends pushes over a switch; use \"impulsive\" to gate this engine"
        )
    })
}

/// Runs every model the scenario asks for (the dynamic model always, as the
/// reference) and compares each with the dynamic model. The engines named in
/// `[run] gate` are gated by the scenario's `[tolerance]` at the time step
/// [`choose_engine_dt`] picks, with the convergence check beside them: the
/// order observed on the trajectory over the ladder's runs
/// ([`tolerance::check_order`]) fails a gate whose declared order is higher,
/// and where none is observed the tolerances come from the estimate at the
/// safer order 1; the other engines and the quasi-static models are
/// informational; the dynamic row checks the integrated ω against the roots.
/// The scenario must have passed [`crate::registry::check`].
pub fn run_scenario(sc: &Scenario, opts: &RunOptions) -> Result<ScenarioReport, ModelError> {
    let problem = sc.problem();
    let mut names: Vec<&str> = vec!["dynamic"];
    names.extend(
        sc.models
            .iter()
            .map(String::as_str)
            .filter(|m| *m != "dynamic"),
    );
    let mut runs: Vec<ModelRun> = Vec::new();
    let mut unavailable: Vec<(String, String)> = Vec::new();
    let mut failures: Vec<(String, String)> = Vec::new();
    // Engines that cannot let go, on a problem with a release: not
    // applicable to it (neither a pass nor a failed run).
    let mut no_release: Vec<(String, String)> = Vec::new();
    // Per gated engine: the engine, its time step and the runs its choice made.
    let mut gated_runs: Vec<(Box<dyn Engine>, DtChoice, Vec<EngineRun>)> = Vec::new();
    for name in names {
        let gated = sc.gate.iter().any(|g| g == name);
        if let Some((sim, settings)) = analytic(name, opts) {
            let t0 = Instant::now();
            match sim.simulate(&problem) {
                Ok(trajectory) => runs.push(ModelRun {
                    name: name.to_string(),
                    engine: false,
                    trajectory,
                    settings,
                    elapsed: t0.elapsed(),
                    diagnostics: serde_json::Value::Null,
                }),
                Err(e) if name == "dynamic" => return Err(e),
                Err(e) => failures.push((name.to_string(), e.to_string())),
            }
            continue;
        }
        let engine = registry::engine(name, &registry::engine_options(sc));
        if let Err(why) = engine.availability() {
            unavailable.push((name.to_string(), why));
            continue;
        }
        let result = if gated {
            // The dynamic model ran first: its segments say which ones the
            // gate reads a steady ω from.
            let segments = analyse_segments(sc, &problem, &runs[0].trajectory);
            // A thrown plate: the automatic step must also let the stop
            // time's tolerance stay within its ceiling.
            let stop = tolerance::stop_floor(sc, &problem, &runs[0].trajectory, opts.model_tol);
            choose_engine_dt(sc, engine.as_ref(), &problem, &segments, stop).and_then(
                |(choice, done)| {
                    let run = match done.iter().find(|r| r.dt == choice.dt) {
                        Some(r) => r.clone(),
                        None => engine.run(&problem, choice.dt)?,
                    };
                    let mut settings = engine.settings(choice.dt);
                    settings["dt_source"] = serde_json::json!(match choice.source {
                        DtSource::Scenario => "scenario",
                        DtSource::Automatic => "automatic",
                    });
                    settings["dt_choice"] = choice.json();
                    Ok((run, settings, Some((choice, done))))
                },
            )
        } else {
            // Informational rows keep the adapter's step (or the scenario's):
            // their findings (results/friction_models/) are stated at it.
            let dt = engine.default_dt();
            engine.run(&problem, dt).map(|run| {
                let mut settings = engine.settings(dt);
                settings["dt_source"] = serde_json::json!(if sc.engine.dt.is_some() {
                    "scenario"
                } else {
                    "adapter default"
                });
                (run, settings, None)
            })
        };
        match result {
            Ok((run, settings, done)) => {
                if let Some((choice, done)) = done {
                    gated_runs.push((engine, choice, done));
                }
                runs.push(ModelRun {
                    name: name.to_string(),
                    engine: true,
                    elapsed: run.wall_time,
                    diagnostics: run.diagnostics,
                    trajectory: run.trajectory,
                    settings,
                });
            }
            // An engine that could not run at all (an outside process that
            // failed, timed out or wrote malformed rows) is an input error.
            Err(e @ ModelError::Adapter(_)) => return Err(e),
            Err(e @ ModelError::NoRelease { .. }) => {
                no_release.push((name.to_string(), e.to_string()));
            }
            Err(e) => failures.push((name.to_string(), e.to_string())),
        }
    }
    let reference = runs[0].trajectory.clone();
    let segments = analyse_segments(sc, &problem, &reference);
    let model_error = tolerance::model_error(&problem, &reference, opts.model_tol);
    // Per gated engine: its convergence over the ladder, and the tolerances
    // resolved from its estimate at the order the trajectory confirms.
    let mut gates: Vec<(String, Convergence, Resolved)> = Vec::new();
    for (engine, choice, done) in &gated_runs {
        let run = runs
            .iter()
            .find(|r| r.name == engine.name())
            .expect("a gated run is among the runs");
        let conv = engine_convergence(
            sc,
            engine.as_ref(),
            &problem,
            &segments,
            &run.trajectory,
            &reference,
            choice.dt,
            done,
        )?;
        let order = tolerance::check_order(choice.order, &conv.trajectory);
        let estimate = choice
            .rungs
            .last()
            .map(|e| tolerance::reorder(e, choice.order, order.estimate_order));
        let mut res = tolerance::resolve(sc, estimate.as_ref(), model_error);
        res.dt = Some((choice.dt, choice.source, choice.met));
        res.problems.extend(order.problem.clone());
        if let Some(p) = tolerance::order_problem(&res, &conv) {
            res.problems.push(p);
        }
        res.notes.extend(order.note.clone());
        res.notes
            .extend(tolerance::ladder_note(&res, choice.met, &choice.targets));
        res.order = Some(order);
        res.catches = Some(catchable(sc, &segments, &reference, &res.value));
        let at = |dt: f64| done.iter().find(|r| r.dt == dt).map(|r| &r.trajectory);
        if let (Some(fine), Some(coarse)) = (at(choice.dt), at(2.0 * choice.dt)) {
            let stop_model_error =
                tolerance::stop_model_error(&problem, &reference, opts.model_tol);
            if let Some((stop, problem_text)) = tolerance::stop_tolerance(
                sc,
                &problem,
                &reference,
                choice.dt,
                coarse,
                fine,
                res.order
                    .as_ref()
                    .map_or(choice.order, |o| o.estimate_order),
                stop_model_error,
            ) {
                res.stop_time = Some(stop);
                res.problems.extend(problem_text);
            }
        }
        gates.push((engine.name().to_string(), conv, res));
    }
    let mut comparisons: Vec<Comparison> = runs
        .iter()
        .map(|r| {
            let gate = gates.iter().find(|g| g.0 == r.name);
            let tol = gate.map(|g| &g.2.value);
            let mut c = compare(sc, &segments, &reference, r, tol);
            if let Some((_, conv, res)) = gate {
                // A gate that cannot stand on its tolerances fails, saying why.
                if !res.problems.is_empty() {
                    c.failed.extend(res.problems.iter().cloned());
                    c.pass = Some(false);
                }
                if let (Some(stop), Some(rest)) = (&res.stop_time, &c.rest) {
                    if rest.run.is_some() && rest.reference.is_some()
                        && !(rest.stop_time.abs() <= stop.value)
                    {
                        c.failed.push(format!(
                            "stop time {:+.3e} s from the model's (t = {:.4} s): more than {:.3e} s",
                            rest.stop_time,
                            rest.reference.map_or(f64::NAN, |m| m.t),
                            stop.value
                        ));
                        c.pass = Some(false);
                    }
                }
                c.convergence = Some(conv.clone());
                c.tolerance = Some(res.clone());
                if c.pass == Some(false) {
                    c.failed
                        .extend(switching_hint(sc, &problem, &reference, &r.trajectory));
                }
            }
            c
        })
        .collect();
    for (name, e) in failures {
        // An engine that blows up fails the gate and says where; an
        // informational model's failure is reported without failing it.
        let gated = sc.gate.contains(&name);
        comparisons.push(Comparison {
            model: name,
            position_max: f64::NAN,
            theta_max: f64::NAN,
            omega_steady_rel_max: None,
            pass: gated.then_some(false),
            failed: vec![format!("run failed: {e}")],
            error: Some(e),
            convergence: None,
            tolerance: None,
            rest: None,
        });
    }
    for (name, why) in no_release {
        comparisons.push(Comparison {
            model: name,
            position_max: f64::NAN,
            theta_max: f64::NAN,
            omega_steady_rel_max: None,
            pass: None,
            failed: vec![],
            error: Some(format!(
                "not applicable: the scenario releases the plate and {why}"
            )),
            convergence: None,
            tolerance: None,
            rest: None,
        });
    }
    for (name, why) in unavailable {
        comparisons.push(Comparison {
            model: name,
            position_max: f64::NAN,
            theta_max: f64::NAN,
            omega_steady_rel_max: None,
            pass: None,
            failed: vec![],
            error: Some(format!("not available in this build: {why}")),
            convergence: None,
            tolerance: None,
            rest: None,
        });
    }
    Ok(ScenarioReport {
        scenario: sc.clone(),
        segments,
        runs,
        comparisons,
    })
}
