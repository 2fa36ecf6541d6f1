//! The `plan` and `loop` commands: argument checks, outputs, exit codes.
//!
//! Each writes its folder whole ([`FreshDir`]): a fresh temporary folder
//! renamed into place at the end, so an output folder never mixes files of
//! two runs. `plan` writes `plan.toml` only when the plan reaches the goal;
//! `loop` writes `loop.json` (success or not, with the reason of a failure),
//! `trajectory.csv` and `applied.toml` (the scenario the plant ran).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use pushval_control::mpc::{push_at, run_loop, LoopOutcome, LoopSpec, PlantScale};
use pushval_control::plan::{describe_attempts, make_plan, Bounds, PlanSpec};
use pushval_control::sensor::SensorSpec;
use pushval_control::stats::median_p99;
use pushval_control::{At, ControlError, Goal, Reach};
use pushval_engine::Engine;
use pushval_model::Push;
use serde_json::json;

use super::{parse_goal, parse_model, parse_plant_scale, parse_reach};
use crate::atomic::FreshDir;
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
    /// `--at rest|release`.
    pub at: String,
    /// `--out DIR`.
    pub out: PathBuf,
}

struct Parsed {
    sc: pushval_scenario::Scenario,
    text: String,
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
    let goal = parse_goal(&c.goal)?;
    let predictor = parse_model(&c.predictor)?;
    let speed = match (c.speed, sc.pushes.first()) {
        (Some(v), _) => v,
        (None, Some(p)) => p.speed,
        (None, None) => anyhow::bail!(
            "{}: the file has no [[push]] to take a speed from: give --speed",
            c.file.display()
        ),
    };
    let reach = match &c.tolerance {
        Some(t) => parse_reach(t)?,
        None => Reach::default(),
    };
    let at = At::from_name(&c.at)
        .with_context(|| format!("--at: `{}` is not one of rest, release", c.at))?;
    let spec = PlanSpec {
        segments: c.segments,
        speed,
        predictor,
        at,
    };
    // Refused here, before any work: speeds, goals and plan lengths out of
    // range.
    Bounds::default()
        .check(
            &pushval_control::predict::Start::of_problem(&problem),
            &goal,
            &spec,
        )
        .map_err(|e| flag_error(e, c))?;
    Ok(Parsed {
        sc,
        text,
        problem,
        goal,
        spec,
        reach,
    })
}

/// A setting error worded with the flag a user gave.
fn flag_error(e: ControlError, c: &Common) -> anyhow::Error {
    match e {
        ControlError::Setting { name, .. } if name.starts_with("push speed") => {
            anyhow::anyhow!("--speed: {e}")
        }
        ControlError::Setting { name, .. } if name.starts_with("pushes per plan") => {
            anyhow::anyhow!("--segments: {e}")
        }
        ControlError::Setting { name, .. } if name.starts_with("control period") => {
            anyhow::anyhow!("--period: {e}")
        }
        ControlError::GoalOutOfRange(_) => anyhow::anyhow!("--goal {}: {e}", c.goal),
        e => anyhow::Error::new(e),
    }
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

/// `text` (a scenario) with `pushes` as its schedule, the start set to
/// rest unless the file's `[initial]` says otherwise, and `note` appended to
/// its description.
pub fn with_schedule(
    text: &str,
    file: &std::path::Path,
    pushes: &[Push],
    note: &str,
    release: Option<pushval_model::Release>,
) -> anyhow::Result<toml::Table> {
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
        *d = format!("{d} | {note}");
    }
    // Judged at rest: the pusher lets go after the last push and the plate
    // slides to a stop; judged at the release, the run ends there.
    match release {
        Some(r) => {
            let mut t = toml::Table::new();
            t.insert("max_duration".into(), toml::Value::Float(r.max_duration));
            doc.insert("release".into(), toml::Value::Table(t));
        }
        None => {
            doc.remove("release");
        }
    }
    Ok(doc)
}

/// The `[release]` a written scenario carries: judged at rest, the file's
/// own (or the default); judged at the release, none.
fn release_of(p: &Parsed) -> Option<pushval_model::Release> {
    match p.spec.at {
        At::Rest => Some(p.problem.release.unwrap_or_default()),
        At::Release => None,
    }
}

fn pose_json(v: Option<[f64; 4]>) -> serde_json::Value {
    match v {
        Some([t, x, y, theta]) => json!({"t": t, "x": x, "y": y, "theta": theta}),
        None => serde_json::Value::Null,
    }
}

/// `pushval plan`.
pub fn plan(c: &Common) -> anyhow::Result<ExitCode> {
    let p = parse(c)?;
    let outcome = match make_plan(&p.problem, p.goal, p.spec, p.reach, &Bounds::default()) {
        Ok(o) => o,
        Err(e @ ControlError::PredictorFailed(_)) => {
            let dir = FreshDir::new(&c.out)?;
            let doc = json!({
                "scenario": c.file.display().to_string(),
                "goal": {"x": p.goal.x, "y": p.goal.y, "theta": p.goal.theta},
                "reached": false,
                "error": e.to_string(),
            });
            dir.write("plan.json", serde_json::to_string_pretty(&doc)?.as_bytes())?;
            dir.commit()?;
            eprintln!("no plan: {e}");
            return Ok(ExitCode::from(1));
        }
        Err(e) => return Err(flag_error(e, c)),
    };
    let s = &outcome.solution;
    let a = &outcome.assumptions;
    let violation = |v: &Option<pushval_model::Violation>| {
        v.map(|v| json!({"first_t": v.first_t, "worst": json_num(v.worst), "segment": v.segment}))
    };
    let slipping: Vec<_> = outcome.switches.iter().filter(|w| !w.inside).collect();
    let duration: f64 = s.pushes.iter().map(|q| q.duration).sum();
    let doc = json!({
        "scenario": c.file.display().to_string(),
        "goal": {"x": p.goal.x, "y": p.goal.y, "theta": p.goal.theta},
        "tolerance": {"position_m": p.reach.position, "angle_rad": p.reach.angle},
        "predictor": p.spec.predictor.as_str(),
        "speed": p.spec.speed,
        "at": p.spec.at.as_str(),
        "reached": outcome.reached,
        "release_pose": pose_json(Some(outcome.release_pose)),
        "rest_pose": pose_json(outcome.rest_pose),
        "slide": outcome.slide.as_ref().map(|sl| json!({
            "t_release": sl.t_release,
            "t_stop": sl.t_stop,
            "pivots": sl.pivots.iter().map(|pv| json!({"support": pv.support, "t_start": pv.t_start, "t_end": pv.t_end})).collect::<Vec<_>>(),
        })),
        "converged": s.converged,
        "position_error_m": json_num(s.position_error),
        "angle_error_rad": json_num(s.angle_error),
        "final_pose": {"x": s.pose[0], "y": s.pose[1], "theta": s.pose[2]},
        "duration_s": duration,
        "solve_ms": outcome.solve_ms,
        "model_runs": outcome.runs,
        "iterations": s.iterations,
        "attempts": outcome.attempts,
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
    let dir = FreshDir::new(&c.out)?;
    if outcome.reached {
        let note = format!(
            "plan: {} pushes at {} m/s to {}, made on the {} model",
            s.pushes.len(),
            p.spec.speed,
            p.goal,
            p.spec.predictor.as_str()
        );
        let doc = with_schedule(&p.text, &c.file, &s.pushes, &note, release_of(&p))?;
        let toml_text = format!(
            "# Written by `pushval plan`: the goal {} ({} predictor).\n{}",
            p.goal,
            p.spec.predictor.as_str(),
            toml::to_string(&doc)?
        );
        // The plan must load as a scenario: the same checks as any file.
        crate::registry::from_toml(&toml_text, &c.out.join("plan.toml"))
            .context("the written plan does not load as a scenario (a bug)")?;
        dir.write("plan.toml", toml_text.as_bytes())?;
    }
    dir.write("plan.json", serde_json::to_string_pretty(&doc)?.as_bytes())?;
    dir.commit()?;
    println!(
        "plan ({} model, {} pushes at {} m/s, {:.3} s): final pose {:.4} m, {:.4} m, {:.4} rad; {:.2e} m and {:.2e} rad from the goal; solved in {:.3} ms ({} model runs; tried {})",
        p.spec.predictor.as_str(),
        s.pushes.len(),
        p.spec.speed,
        duration,
        s.pose[0],
        s.pose[1],
        s.pose[2],
        s.position_error,
        s.angle_error,
        outcome.solve_ms,
        outcome.runs,
        describe_attempts(&outcome.attempts),
    );
    if !a.all_hold() {
        eprintln!(
            "warning: the model's assumptions fail along the plan: see checks in {}",
            c.out.join("plan.json").display()
        );
    }
    for w in slipping.iter().filter(|_| outcome.reached) {
        eprintln!(
            "warning: the switch into push {} at t = {:.3} s needs an impulse {:.3} rad outside the contact's normal cone{}: the pusher slips there unless φ ramps over {}",
            w.segment,
            w.t,
            w.cone_angle_rad,
            w.friction_angle_rad
                .map_or(String::new(), |f| format!(" (friction angle {f:.3} rad)")),
            w.ramp_s.map_or("no ramp (the steady force is outside the cone too)".to_string(), |r| format!("{:.1} ms", r * 1e3))
        );
    }
    if outcome.reached {
        println!(
            "wrote {} and {}",
            c.out.join("plan.toml").display(),
            c.out.join("plan.json").display()
        );
        Ok(ExitCode::SUCCESS)
    } else {
        println!(
            "wrote {} (no plan.toml: no plan reaches the goal)",
            c.out.join("plan.json").display()
        );
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
        anyhow::bail!("--engine {name}: not available in this build: {why}");
    }
    let dt = sc.engine.dt.unwrap_or(engine.default_dt());
    Ok((engine, dt))
}

/// `text` (the scenario the loop read) as the scenario its plant ran: the
/// plant's friction and inertia, `engine` at `dt`, and the pushes applied.
fn applied_toml(
    p: &Parsed,
    file: &std::path::Path,
    plant: &Plant,
    plant_problem: &pushval_model::Problem,
    engine: &str,
    dt: f64,
    pushes: &[Push],
) -> anyhow::Result<String> {
    let note = format!("what `pushval loop` applied to {engine} (goal {})", p.goal);
    let mut doc = with_schedule(&p.text, file, pushes, &note, release_of(p))?;
    let table = |doc: &mut toml::Table, key: &str| -> anyhow::Result<toml::Table> {
        match doc.remove(key) {
            Some(toml::Value::Table(t)) => Ok(t),
            None => Ok(toml::Table::new()),
            Some(_) => anyhow::bail!("{}: `{key}` is not a table", file.display()),
        }
    };
    if let Plant::File { text, path, .. } = plant {
        // The plant's own scene: its object and supports tables as its file
        // gives them (the outline and contact are the same as the loop's).
        let theirs: toml::Table =
            toml::from_str(text).with_context(|| format!("{}: not TOML", path.display()))?;
        for key in ["object", "supports"] {
            match theirs.get(key) {
                Some(v) => {
                    doc.insert(key.into(), v.clone());
                }
                None => {
                    doc.remove(key);
                }
            }
        }
    }
    if let Some(plant) = plant.filter(|s| !s.is_nominal()) {
        // The plant's own scene: friction scaled at every support, the
        // inertia about the centre of mass given outright.
        let mut supports = table(&mut doc, "supports")?;
        let scale = |v: &toml::Value| -> toml::Value {
            match v {
                toml::Value::Float(x) => toml::Value::Float(x * plant.mu_scale),
                toml::Value::Integer(x) => toml::Value::Float(*x as f64 * plant.mu_scale),
                toml::Value::Array(a) => toml::Value::Array(
                    a.iter()
                        .map(|x| match x {
                            toml::Value::Float(x) => toml::Value::Float(x * plant.mu_scale),
                            toml::Value::Integer(x) => {
                                toml::Value::Float(*x as f64 * plant.mu_scale)
                            }
                            other => other.clone(),
                        })
                        .collect(),
                ),
                other => other.clone(),
            }
        };
        let mu = supports
            .get("mu")
            .map(scale)
            .with_context(|| format!("{}: [supports] has no mu to scale", file.display()))?;
        supports.insert("mu".into(), mu);
        doc.insert("supports".into(), toml::Value::Table(supports));
        let mut object = table(&mut doc, "object")?;
        object.remove("inertia_contact");
        object.insert(
            "inertia_cm".into(),
            toml::Value::Float(plant_problem.body.inertia_cm()),
        );
        doc.insert("object".into(), toml::Value::Table(object));
    }
    let mut run = table(&mut doc, "run")?;
    run.insert(
        "models".into(),
        toml::Value::Array(vec![toml::Value::String(engine.into())]),
    );
    // The default gate: the plant engine is gated against the dynamic
    // model on the plant's scene when it is the default gated engine.
    run.remove("gate");
    doc.insert("run".into(), toml::Value::Table(run));
    let mut eng = table(&mut doc, "engine")?;
    eng.insert("dt".into(), toml::Value::Float(dt));
    doc.insert("engine".into(), toml::Value::Table(eng));
    doc.remove("tolerance");
    Ok(format!(
        "# Written by `pushval loop`: the scenario its plant ran ({engine}, dt {dt} s); `pushval run` on this file reproduces the plant's trajectory.\n{}",
        toml::to_string(&doc)?
    ))
}

/// The plant's scene: the file's scaled, or another file's.
#[derive(Debug, Clone)]
pub enum Plant {
    /// `--plant mu_scale=A,inertia_scale=B` (or none: the file's scene).
    Scale(PlantScale),
    /// `--plant FILE`: the object and supports of another scenario.
    File {
        /// Its path.
        path: PathBuf,
        /// Its text.
        text: String,
        /// It, loaded.
        sc: Box<pushval_scenario::Scenario>,
    },
}

impl Plant {
    /// `--plant`: `KEY=VALUE,…` scales the file's scene; anything else is a
    /// scenario file whose outline, contact and centre of mass must equal
    /// the loop file's (`file`, loaded as `sc`).
    pub fn parse(
        text: Option<&str>,
        file: &std::path::Path,
        sc: &pushval_scenario::Scenario,
    ) -> anyhow::Result<Self> {
        let Some(text) = text else {
            return Ok(Plant::Scale(PlantScale::default()));
        };
        if text.contains('=') {
            return Ok(Plant::Scale(parse_plant_scale(text)?));
        }
        let path = PathBuf::from(text);
        let theirs = crate::registry::load(&path)?;
        let body = std::fs::read_to_string(&path)
            .with_context(|| format!("{}: cannot read", path.display()))?;
        let same = |a: &[pushval_model::Vec2], b: &[pushval_model::Vec2]| {
            a.len() == b.len() && a.iter().zip(b).all(|(p, q)| (p - q).norm() <= 1e-12)
        };
        let differs = |key: &str, mine: String, other: String| {
            anyhow::anyhow!(
                "{}: {key}: the plant's must equal {}'s (the plant is another plate with the same outline and contact): {other} against {mine}",
                path.display(),
                file.display()
            )
        };
        if !same(&theirs.polygon, &sc.polygon) {
            return Err(differs(
                "object.polygon",
                format!(
                    "{:?}",
                    sc.polygon.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>()
                ),
                format!(
                    "{:?}",
                    theirs
                        .polygon
                        .iter()
                        .map(|p| [p.x, p.y])
                        .collect::<Vec<_>>()
                ),
            ));
        }
        if !same(&[theirs.contact], &[sc.contact]) {
            return Err(differs(
                "contact.point",
                format!("[{}, {}]", sc.contact.x, sc.contact.y),
                format!("[{}, {}]", theirs.contact.x, theirs.contact.y),
            ));
        }
        if !same(&[theirs.center_of_mass], &[sc.center_of_mass]) {
            return Err(differs(
                "object.center_of_mass",
                format!("[{}, {}]", sc.center_of_mass.x, sc.center_of_mass.y),
                format!("[{}, {}]", theirs.center_of_mass.x, theirs.center_of_mass.y),
            ));
        }
        Ok(Plant::File {
            path,
            text: body,
            sc: Box::new(theirs),
        })
    }

    /// The scale, when the plant is the file's scene scaled.
    fn filter(&self, keep: impl Fn(&PlantScale) -> bool) -> Option<&PlantScale> {
        match self {
            Plant::Scale(s) if keep(s) => Some(s),
            _ => None,
        }
    }

    /// The plant's problem: `problem` (the loop's schedule, start and
    /// release) on the plant's scene.
    pub fn problem(
        &self,
        problem: &pushval_model::Problem,
    ) -> anyhow::Result<pushval_model::Problem> {
        match self {
            Plant::Scale(s) => Ok(s.apply(problem)?),
            Plant::File { sc, .. } => Ok(pushval_model::Problem {
                body: sc.problem().body,
                ..problem.clone()
            }),
        }
    }

    /// As `loop.json` gives it.
    pub fn json(&self) -> serde_json::Value {
        match self {
            Plant::Scale(s) => json!(s),
            Plant::File { path, sc, .. } => {
                json!({"file": path.display().to_string(), "name": sc.name})
            }
        }
    }
}

/// `pushval loop`: `plant` is `--plant`, `adapt` `--adapt`, `sensor`
/// `--sensor`.
pub fn run(
    c: &Common,
    engine: &str,
    period: f64,
    plant: Option<&str>,
    adapt: bool,
    sensor: Option<&str>,
) -> anyhow::Result<ExitCode> {
    let p = parse(c)?;
    let plant = Plant::parse(plant, &c.file, &p.sc)?;
    let sensor = match sensor {
        Some(t) => SensorSpec::parse(t).map_err(|e| anyhow::anyhow!("--sensor: {e}"))?,
        None => SensorSpec::default(),
    };
    let (engine, dt) = engine_of(&p.sc, engine)?;
    pushval_control::mpc::period_steps(period, dt).map_err(|e| flag_error(e, c))?;
    let spec = LoopSpec {
        plan: p.spec,
        period,
        reach: p.reach,
        adapt,
        sensor,
    };
    let plant_problem = plant
        .problem(&p.problem)
        .with_context(|| format!("--plant: the plant's scene of {}", c.file.display()))?;
    let base = json!({
        "scenario": c.file.display().to_string(),
        "goal": {"x": p.goal.x, "y": p.goal.y, "theta": p.goal.theta},
        "tolerance": {"position_m": p.reach.position, "angle_rad": p.reach.angle},
        "engine": engine.name(),
        "engine_version": engine.version(),
        "dt": dt,
        "predictor": p.spec.predictor.as_str(),
        "speed": p.spec.speed,
        "at": p.spec.at.as_str(),
        "plant": plant.json(),
        "adapt": adapt,
        "sensor": sensor,
    });
    let outcome = (|| -> anyhow::Result<(LoopOutcome, pushval_engine::EngineRun)> {
        let mut session = engine
            .start(&plant_problem, dt)
            .with_context(|| format!("{}: starting a session", engine.name()))?;
        let out = run_loop(&p.problem, session.as_mut(), dt, p.goal, spec, &mut ())
            .map_err(|e| flag_error(e, c))?;
        let run = session
            .finish()
            .with_context(|| format!("{}: finishing the session", engine.name()))?;
        Ok((out, run))
    })();
    let (out, run) = match outcome {
        Ok(o) => o,
        Err(e) => {
            // The folder says the loop failed and why; nothing of an
            // earlier run stays in it.
            let mut doc = base;
            doc["success"] = json!(false);
            doc["error"] = json!(format!("{e:#}"));
            let dir = FreshDir::new(&c.out)?;
            dir.write("loop.json", serde_json::to_string_pretty(&doc)?.as_bytes())?;
            dir.commit()?;
            return Err(e);
        }
    };
    let timing = median_p99(&out.predictor_us);
    let cpu = median_p99(&out.predictor_cpu_us);
    let est_cpu = median_p99(&out.estimator_cpu_us);
    let pushes: Vec<Push> = out.applied.iter().map(|a| a.push).collect();
    let l = &out.release;
    let judged = out.rest.unwrap_or(out.release);
    let mut doc = base;
    let extra = json!({
        "period_s": out.period,
        "success": out.success,
        "position_error_m": json_num(out.position_error),
        "angle_error_rad": json_num(out.angle_error),
        "final_pose": {"t": judged.t, "x": judged.x, "y": judged.y, "theta": judged.theta},
        "release_pose": {"t": l.t, "x": l.x, "y": l.y, "theta": l.theta},
        "release_state": {"t": l.t, "x": l.x, "y": l.y, "theta": l.theta, "omega": l.omega, "vx": l.v_cm[0], "vy": l.v_cm[1]},
        "rest_pose": out.rest.map(|r| json!({"t": r.t, "x": r.x, "y": r.y, "theta": r.theta})),
        "steps": out.steps,
        "gave_up_at_twice_the_plan": out.gave_up,
        "predictor_us_median": timing.map(|t| t.0),
        "predictor_us_p99": timing.map(|t| t.1),
        "predictor_cpu_us_median": cpu.map(|t| t.0),
        "predictor_cpu_us_p99": cpu.map(|t| t.1),
        "plan_from_rest_converged": out.plan_converged,
        "engine_replayed_each_period": out.replayed,
        "engine_steps": run.steps,
        "sensor_latency_s": out.latency,
        "estimate": estimate_json(&out),
        "estimator_cpu_us_median": est_cpu.map(|t| t.0),
        "estimator_cpu_us_p99": est_cpu.map(|t| t.1),
    });
    if let (Some(d), serde_json::Value::Object(e)) = (doc.as_object_mut(), extra) {
        d.extend(e);
    }
    let dir = FreshDir::new(&c.out)?;
    dir.write(
        "trajectory.csv",
        trajectory_csv(&out, &run, engine.name()).as_bytes(),
    )?;
    dir.write("loop.json", serde_json::to_string_pretty(&doc)?.as_bytes())?;
    if adapt {
        dir.write("estimate.csv", &estimate_csv(&out)?)?;
    }
    let applied = applied_toml(
        &p,
        &c.out.join("applied.toml"),
        &plant,
        &plant_problem,
        engine.name(),
        dt,
        &pushes,
    )?;
    dir.write("applied.toml", applied.as_bytes())?;
    dir.commit()?;
    let timing_text = match timing {
        Some((m, p99)) => format!("predictor {m:.1} µs median, {p99:.1} µs p99"),
        None => "no re-plan (the plan lasted one period)".into(),
    };
    println!(
        "loop ({} predictor, {} plant, period {} s, judged at {}): {} after {} periods: {:.4} m and {:.4} rad from the goal; {}{}",
        p.spec.predictor.as_str(),
        engine.name(),
        out.period,
        p.spec.at.as_str(),
        if out.success { "reached" } else { "MISSED" },
        out.steps,
        out.position_error,
        out.angle_error,
        timing_text,
        if out.replayed { "; the engine cannot step: it re-ran the schedule applied so far every period" } else { "" }
    );
    if let (Some(row), Some(id)) = (out.estimates.last(), out.identified) {
        let [mu, cx, cy, i] = row.value;
        let [smu, scx, scy, si] = row.std;
        let not = |ok: bool| if ok { "" } else { " (not identified)" };
        println!(
            "estimate at {t:.3} s: mu_scale {mu:.4} ± {smu:.4}{a}, centre of friction ({x:.1}, {y:.1}) ± ({sx:.1}, {sy:.1}) mm{b}, I_cm {i:.5} ± {si:.5} kg m²{c}; {n} lack-of-fit episodes; estimator {cost} CPU median",
            t = row.t,
            x = cx * 1e3,
            y = cy * 1e3,
            sx = scx * 1e3,
            sy = scy * 1e3,
            a = not(id.mu_scale),
            b = not(id.center_of_friction),
            c = not(id.inertia_cm),
            n = out.lack_of_fit,
            cost = est_cpu.map_or("n/a".into(), |t| format!("{:.1} µs", t.0)),
        );
    }
    println!(
        "wrote {}, {}{} and {}",
        c.out.join("trajectory.csv").display(),
        c.out.join("loop.json").display(),
        if adapt {
            format!(", {}", c.out.join("estimate.csv").display())
        } else {
            String::new()
        },
        c.out.join("applied.toml").display()
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

/// `loop.json`'s `estimate`: the last estimate with its std, which
/// parameters the readings identified, and what no reading can tell.
fn estimate_json(out: &LoopOutcome) -> serde_json::Value {
    let (Some(row), Some(id)) = (out.estimates.last(), out.identified) else {
        return serde_json::Value::Null;
    };
    json!({
        "t": row.t,
        "mu_scale": {"value": row.value[0], "std": row.std[0], "identified": id.mu_scale},
        "center_of_friction": {"value": [row.value[1], row.value[2]], "std": [row.std[1], row.std[2]], "identified": id.center_of_friction},
        "inertia_cm": {"value": row.value[3], "std": row.std[3], "identified": id.inertia_cm},
        "lack_of_fit": out.lack_of_fit,
        "not_identifiable": "how the friction is split among the supports beyond its total, centre and moment about the contact: pushing does not reveal it, yet the slide after the release depends on it",
    })
}

/// `estimate.csv`: `t`, then each parameter and its std (the order of
/// `pushval track`'s rows: centre of friction, I_cm, mu_scale).
fn estimate_csv(out: &LoopOutcome) -> anyhow::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "t",
        "center_of_friction_x",
        "center_of_friction_x_std",
        "center_of_friction_y",
        "center_of_friction_y_std",
        "inertia_cm",
        "inertia_cm_std",
        "mu_scale",
        "mu_scale_std",
    ])?;
    for r in &out.estimates {
        let order = [(1, 1), (2, 2), (3, 3), (0, 0)];
        let mut row = vec![format!("{}", r.t)];
        for (v, sd) in order {
            row.push(format!("{}", r.value[v]));
            row.push(format!("{}", r.std[sd]));
        }
        w.write_record(&row)?;
    }
    Ok(w.into_inner()?)
}

/// The plant's trajectory rows with the applied push (columns `speed`,
/// `phi`), through the trajectory format's writer.
pub fn trajectory_csv(out: &LoopOutcome, run: &pushval_engine::EngineRun, model: &str) -> String {
    let mut bytes = Vec::new();
    pushval_model::format::write_with(
        &mut bytes,
        &[(model, run.trajectory.samples.as_slice())],
        &["speed", "phi"],
        |smp| {
            // After the release the pusher is gone: speed 0.
            let p = push_at(&out.applied, smp.t).filter(|_| smp.t <= out.release.t + 1e-12);
            vec![p.map_or(0.0, |p| p.speed), p.map_or(0.0, |p| p.phi)]
        },
    )
    .expect("writing to memory");
    String::from_utf8(bytes).expect("the format is ASCII")
}
