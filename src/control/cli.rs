//! The `plan` and `loop` commands: argument checks, outputs, exit codes.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use pushval_engine::Engine;
use serde_json::json;

use super::mpc::{median_p99, run_loop, trajectory_csv, LoopSpec, PlantScale};
use super::plan::{make_plan, plan_toml, PlanSpec};
use super::{Goal, Predictor, Reach};
use crate::atomic::write_atomic;
use crate::outdir::json_num;

/// The arguments both commands share.
pub struct Common {
    /// The scenario file.
    pub file: PathBuf,
    /// `--goal X,Y,THETA`.
    pub goal: String,
    /// `--speed V` (default: the file's first push speed).
    pub speed: Option<f64>,
    /// `--segments N`.
    pub segments: usize,
    /// `--predictor`.
    pub predictor: String,
    /// `--tolerance POS,ANGLE`.
    pub tolerance: Option<String>,
    /// `--out DIR`.
    pub out: PathBuf,
}

struct Parsed {
    sc: pushval_scenario::Scenario,
    /// The scenario's problem, at rest at the start unless the file's
    /// `[initial]` sets `from_rest`.
    problem: pushval_model::Problem,
    goal: Goal,
    spec: PlanSpec,
    reach: Reach,
}

fn parse(c: &Common) -> anyhow::Result<Parsed> {
    let sc = crate::registry::load(&c.file)?;
    let text = std::fs::read_to_string(&c.file)
        .with_context(|| format!("{}: cannot read", c.file.display()))?;
    let problem = problem_from_rest(&sc, &text);
    let goal = Goal::parse(&c.goal)?;
    let predictor = Predictor::parse(&c.predictor)?;
    let speed = c.speed.unwrap_or(sc.pushes[0].speed);
    if !(speed.is_finite() && speed > 0.0) {
        bail!("--speed must be finite and > 0, got {speed}");
    }
    if !(1..=64).contains(&c.segments) {
        bail!("--segments must be 1 to 64, got {}", c.segments);
    }
    let reach = match &c.tolerance {
        Some(t) => Reach::parse(t)?,
        None => Reach::default(),
    };
    Ok(Parsed {
        sc,
        problem,
        goal,
        spec: PlanSpec {
            segments: c.segments,
            speed,
            predictor,
        },
        reach,
    })
}

/// The scenario's problem with `from_rest = true` unless the file's
/// `[initial]` sets `from_rest` itself (a plan starts from rest by default).
pub fn problem_from_rest(sc: &pushval_scenario::Scenario, text: &str) -> pushval_model::Problem {
    let mut problem = sc.problem();
    let given = toml::from_str::<toml::Table>(text)
        .ok()
        .and_then(|t| t.get("initial")?.get("from_rest").cloned())
        .is_some();
    if !given {
        problem.initial.from_rest = true;
    }
    problem
}

/// `pushval plan`.
pub fn plan(c: &Common) -> anyhow::Result<ExitCode> {
    let p = parse(c)?;
    let problem = p.problem.clone();
    let outcome = make_plan(&problem, p.goal, p.spec, p.reach)?;
    let s = &outcome.solution;
    let text = std::fs::read_to_string(&c.file)
        .with_context(|| format!("{}: cannot read", c.file.display()))?;
    let toml_text = plan_toml(&text, &c.file, &s.pushes, &p.goal, &p.spec)?;
    // The plan must load as a scenario: the same checks as any file.
    crate::registry::from_toml(&toml_text, &c.out.join("plan.toml"))
        .context("the written plan does not load as a scenario (a bug)")?;
    let a = &outcome.assumptions;
    let violation = |v: &Option<pushval_model::Violation>| {
        v.map(|v| json!({"first_t": v.first_t, "worst": json_num(v.worst), "segment": v.segment}))
    };
    let slipping: Vec<_> = outcome.switches.iter().filter(|w| !w.inside).collect();
    let doc = json!({
        "scenario": c.file.display().to_string(),
        "goal": {"x": p.goal.x, "y": p.goal.y, "theta": p.goal.theta},
        "predictor": p.spec.predictor.as_str(),
        "speed": p.spec.speed,
        "converged": s.converged,
        "reached": p.reach.holds(s.position_error, s.angle_error),
        "position_error_m": json_num(s.position_error),
        "angle_error_rad": json_num(s.angle_error),
        "final_pose": {"x": s.pose[0], "y": s.pose[1], "theta": s.pose[2]},
        "duration_s": s.pushes.iter().map(|q| q.duration).sum::<f64>(),
        "solve_ms": outcome.solve_ms,
        "model_runs": outcome.runs,
        "iterations": s.iterations,
        "segments": s.pushes.iter().map(|q| json!({"duration": q.duration, "speed": q.speed, "phi": q.phi})).collect::<Vec<_>>(),
        "why_missed": outcome.why,
        "checks": {
            "model": "dynamic",
            "all_hold": a.all_hold() && slipping.is_empty(),
            "pulling": violation(&a.pulling),
            "contact_slip": violation(&a.contact_slip),
            "force_limit": violation(&a.force_limit),
            "sticking": violation(&a.sticking),
            "pulling_impulse": violation(&a.pulling_impulse),
            "runaway": violation(&a.runaway),
            "max_force_n": json_num(a.max_force),
            "switches": outcome.switches,
            "switches_outside_friction_cone": slipping.len(),
        },
    });
    std::fs::create_dir_all(&c.out).with_context(|| format!("creating {}", c.out.display()))?;
    write_atomic(&c.out.join("plan.toml"), toml_text.as_bytes())?;
    write_atomic(
        &c.out.join("plan.json"),
        serde_json::to_string_pretty(&doc)?.as_bytes(),
    )?;
    println!(
        "plan ({} model, {} pushes at {} m/s, {:.3} s): final pose {:.4} m, {:.4} m, {:.4} rad; {:.2e} m and {:.2e} rad from the goal; solved in {:.3} ms ({} model runs)",
        p.spec.predictor.as_str(),
        p.spec.segments,
        p.spec.speed,
        s.pushes.iter().map(|q| q.duration).sum::<f64>(),
        s.pose[0],
        s.pose[1],
        s.pose[2],
        s.position_error,
        s.angle_error,
        outcome.solve_ms,
        outcome.runs
    );
    if !a.all_hold() {
        eprintln!(
            "warning: the model's assumptions fail along the plan: see checks in {}",
            c.out.join("plan.json").display()
        );
    }
    for w in &slipping {
        eprintln!(
            "warning: the switch into push {} at t = {:.3} s needs an impulse {:.3} rad outside the contact's normal cone (friction angle {:.3} rad): the pusher slips there unless φ ramps over {}",
            w.segment,
            w.t,
            w.cone_angle_rad,
            w.friction_angle_rad.unwrap_or(f64::NAN),
            w.ramp_s.map_or("no ramp (the steady force is outside the cone too)".to_string(), |r| format!("{:.1} ms", r * 1e3))
        );
    }
    println!(
        "wrote {} and {}",
        c.out.join("plan.toml").display(),
        c.out.join("plan.json").display()
    );
    if s.converged || p.reach.holds(s.position_error, s.angle_error) {
        Ok(ExitCode::SUCCESS)
    } else {
        eprintln!(
            "no plan reaches {}: nearest pose x {:.4} m, y {:.4} m, θ {:.4} rad ({:.4} m, {:.4} rad away): {}",
            p.goal,
            s.pose[0],
            s.pose[1],
            s.pose[2],
            s.position_error,
            s.angle_error,
            outcome.why.as_deref().unwrap_or("")
        );
        Ok(ExitCode::from(1))
    }
}

/// The engine `name` built from the scenario's `[engine]` table, and its step.
pub fn engine_of(
    sc: &pushval_scenario::Scenario,
    name: &str,
) -> anyhow::Result<(Box<dyn Engine>, f64)> {
    let entry = crate::registry::entry(name).with_context(|| {
        format!(
            "--engine: `{name}` is not an engine of this build or of {} (see `pushval engines`)",
            crate::registry::engines_file()
        )
    })?;
    let engine = entry
        .build(&crate::registry::engine_options(sc))
        .map_err(|e| anyhow::anyhow!("{}: [engine]: {e}", sc.path.display()))?;
    if let Err(why) = engine.availability() {
        bail!("--engine {name}: not available in this build: {why}");
    }
    let dt = sc.engine.dt.unwrap_or(engine.default_dt());
    Ok((engine, dt))
}

/// `pushval loop`.
pub fn run(c: &Common, engine: &str, period: f64, plant: Option<&str>) -> anyhow::Result<ExitCode> {
    let p = parse(c)?;
    let plant = match plant {
        Some(t) => PlantScale::parse(t)?,
        None => PlantScale::default(),
    };
    let (engine, dt) = engine_of(&p.sc, engine)?;
    let problem = p.problem.clone();
    let spec = LoopSpec {
        plan: p.spec,
        period,
        plant,
        reach: p.reach,
    };
    let out = run_loop(&problem, engine.as_ref(), dt, p.goal, spec)?;
    let (med, p99) = median_p99(&out.predictor_us);
    let (cpu_med, cpu_p99) = median_p99(&out.predictor_cpu_us);
    let last = out
        .run
        .trajectory
        .samples
        .last()
        .copied()
        .unwrap_or_default();
    let doc = json!({
        "scenario": c.file.display().to_string(),
        "goal": {"x": p.goal.x, "y": p.goal.y, "theta": p.goal.theta},
        "engine": engine.name(),
        "engine_version": engine.version(),
        "dt": dt,
        "predictor": p.spec.predictor.as_str(),
        "period_s": period,
        "speed": p.spec.speed,
        "plant": plant,
        "success": out.success,
        "position_error_m": json_num(out.position_error),
        "angle_error_rad": json_num(out.angle_error),
        "final_pose": {"t": last.t, "x": last.x, "y": last.y, "theta": last.theta},
        "steps": out.steps,
        "gave_up_at_twice_the_plan": out.gave_up,
        "predictor_us_median": json_num(med),
        "predictor_us_p99": json_num(p99),
        "predictor_cpu_us_median": json_num(cpu_med),
        "predictor_cpu_us_p99": json_num(cpu_p99),
        "plan_from_rest_converged": out.plan_converged,
        "engine_replayed_each_period": out.replayed,
        "engine_steps": out.run.steps,
    });
    write_outputs(&c.out, &trajectory_csv(&out, engine.name()), &doc)?;
    println!(
        "loop ({} predictor, {} plant, period {} s): {} after {} periods: {:.4} m and {:.4} rad from the goal; predictor {:.1} µs median, {:.1} µs p99{}",
        p.spec.predictor.as_str(),
        engine.name(),
        period,
        if out.success { "reached" } else { "MISSED" },
        out.steps,
        out.position_error,
        out.angle_error,
        med,
        p99,
        if out.replayed { "; the engine cannot step: it re-ran the schedule applied so far every period" } else { "" }
    );
    println!(
        "wrote {} and {}",
        c.out.join("trajectory.csv").display(),
        c.out.join("loop.json").display()
    );
    Ok(if out.success {
        ExitCode::SUCCESS
    } else {
        eprintln!(
            "miss: {:.4} m and {:.4} rad from {} (tolerance {} m, {:.4} rad)",
            out.position_error, out.angle_error, p.goal, p.reach.position, p.reach.angle
        );
        ExitCode::from(1)
    })
}

fn write_outputs(dir: &Path, csv: &str, doc: &serde_json::Value) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    write_atomic(&dir.join("trajectory.csv"), csv.as_bytes())?;
    write_atomic(
        &dir.join("loop.json"),
        serde_json::to_string_pretty(doc)?.as_bytes(),
    )
}
