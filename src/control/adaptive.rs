//! `pushval control-study --adaptive`: does estimating the plate's friction
//! online bring MPC to where a controller that knows the plate gets?
//!
//! The scene and goals are the control study's (the seed's plate from rest,
//! its goals 0.3–1 m away). Each plant is that plate or another with the
//! same outline and contact ([`PlantKind`]): uniform changes (μ × 0.8, I_cm ×
//! 1.2), loads shifted to one side, one slippery foot. Each is driven by the
//! plan made on the file's values open loop, by MPC on the file's values,
//! by adaptive MPC (planning on the estimate of every period) and by the
//! oracle (MPC planned on the plant's true scene: the bound), with an exact
//! sensor and with a noisy one, judged at the release and at rest, at 0.5
//! and 1 m/s. `runs.csv` has every run, `success.csv` the counts and
//! `README.md` what they say, every sentence from the numbers beside it.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use pushval_control::mpc::{open_loop, run_loop, LoopSpec, PlantScale};
use pushval_control::plan::{straight_time, PlanSpec, Planner, Solution};
use pushval_control::predict::Start;
use pushval_control::sensor::SensorSpec;
use pushval_control::stats::{median, median_p99};
use pushval_control::{At, Goal, ModelKind, Reach};
use pushval_engine::Engine;
use pushval_model::{Body, Problem, Support};

use super::study::{
    cannot_release, engines, goals, law_line, rows_with_progress, scene, write_part, PERIOD,
    SEGMENTS, SPEEDS,
};
use crate::outdir::{num, Csv, Writer as OutDir};
use crate::shard::{grid_hash, grid_name, Parts, Shard};

/// Speeds of the full grid (m/s).
pub const SPEEDS_ADAPTIVE: [f64; 2] = [0.5, 1.0];
/// Goals of the full grid (the control study's first 20).
pub const GOALS: usize = 20;
/// Goals of the quick grid (at 1 m/s).
pub const QUICK_GOALS: usize = 3;
/// The noisy sensor: 0.5 mm, 0.2°, 0.05 rad/s, 5 mm/s (seeded per goal).
pub const NOISE: SensorSpec = SensorSpec {
    sigma_position: 5e-4,
    sigma_theta: 3.490_658_503_988_659e-3,
    sigma_omega: 0.05,
    sigma_velocity: 5e-3,
    latency: 0.0,
    seed: 0,
};

/// The plants: the file's plate and plates that differ from it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum PlantKind {
    /// The file's plate.
    Nominal,
    /// μ × 0.8 at every support, I_cm × 1.2: a uniform change.
    Perturbed,
    /// Loads shifted toward +x (1.5, 3.405, 3.405, 1.5 N): the centre of
    /// friction 48.5 mm off the line through the contact and the centre of
    /// mass.
    LoadsSide,
    /// Loads shifted toward the far corner (1.2, 2.4525, 3.705, 2.4525 N):
    /// the centre of friction moves along that line.
    LoadsDiagonal,
    /// The support at (+, −) five times as slippery: friction split off
    /// the line.
    SlipperyNear,
    /// The far corner's support five times as slippery: on the line.
    SlipperyFar,
}

impl PlantKind {
    /// Every plant, in table order.
    pub const ALL: [PlantKind; 6] = [
        PlantKind::Nominal,
        PlantKind::Perturbed,
        PlantKind::LoadsSide,
        PlantKind::LoadsDiagonal,
        PlantKind::SlipperyNear,
        PlantKind::SlipperyFar,
    ];

    /// Its name in the outputs.
    pub fn as_str(self) -> &'static str {
        match self {
            PlantKind::Nominal => "nominal",
            PlantKind::Perturbed => "perturbed",
            PlantKind::LoadsSide => "loads_side",
            PlantKind::LoadsDiagonal => "loads_diagonal",
            PlantKind::SlipperyNear => "slippery_near",
            PlantKind::SlipperyFar => "slippery_far",
        }
    }

    /// Whether it moves or splits the friction (not a uniform change).
    pub fn moves_friction(self) -> bool {
        !matches!(self, PlantKind::Nominal | PlantKind::Perturbed)
    }

    /// The plant's scene: `problem` with its supports' friction and inertia.
    /// The scene's supports are the seed plate's four corners in order
    /// (−,−), (+,−), (+,+), (−,+) with equal loads.
    pub fn apply(self, problem: &Problem) -> anyhow::Result<Problem> {
        let b = &problem.body;
        let share = |loads: [f64; 4]| -> Vec<f64> {
            let total: f64 = loads.iter().sum();
            loads.iter().map(|l| 4.0 * l / total).collect()
        };
        let factor: Vec<f64> = match self {
            PlantKind::Nominal => return Ok(problem.clone()),
            PlantKind::Perturbed => return Ok(PlantScale::PERTURBED.apply(problem)?),
            PlantKind::LoadsSide => share([1.5, 3.405, 3.405, 1.5]),
            PlantKind::LoadsDiagonal => share([1.2, 2.4525, 3.705, 2.4525]),
            PlantKind::SlipperyNear => vec![1.0, 0.2, 1.0, 1.0],
            PlantKind::SlipperyFar => vec![1.0, 1.0, 0.2, 1.0],
        };
        if b.len() != factor.len() {
            bail!("the adaptive study's plants need the seed plate's four supports");
        }
        let supports: Vec<Support> = b
            .supports()
            .zip(&factor)
            .map(|(s, f)| Support {
                friction: s.friction * f,
                ..s
            })
            .collect();
        Ok(Problem {
            body: Body::new(b.mass(), b.inertia_cm(), b.contact(), &supports)?,
            ..problem.clone()
        })
    }
}

/// How the plant is driven.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Mode {
    /// The plan made on the file's values, replayed.
    Open,
    /// MPC on the file's values.
    Mpc,
    /// MPC on the estimate of every period.
    Adaptive,
    /// MPC on the plant's true scene: the bound.
    Oracle,
}

impl Mode {
    /// Its name in the outputs.
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Open => "open",
            Mode::Mpc => "mpc",
            Mode::Adaptive => "adaptive",
            Mode::Oracle => "oracle",
        }
    }
}

/// One run.
#[derive(Debug, Clone)]
pub struct Task {
    /// The engine model.
    pub engine: String,
    /// Pusher speed (m/s).
    pub speed: f64,
    /// Index into the goals.
    pub goal: usize,
    /// When it is judged.
    pub at: At,
    /// How it is driven.
    pub mode: Mode,
    /// The plant.
    pub plant: PlantKind,
    /// Whether the sensor is noisy.
    pub noise: bool,
}

impl Task {
    fn key(&self) -> String {
        format!(
            "adaptive/{}/{}/{}/{}/{}/{}/{}",
            self.engine,
            self.speed,
            self.goal,
            self.at.as_str(),
            self.mode.as_str(),
            self.plant.as_str(),
            if self.noise { "noisy" } else { "exact" }
        )
    }
}

/// The task list: engines × speeds × goals × judged at × modes × plants ×
/// sensors; open loop reads no sensor (exact only), the oracle on the
/// nominal plant is MPC (left out).
pub fn tasks(engines: &[String], speeds: &[f64], goals: usize) -> Vec<Task> {
    let mut out = Vec::new();
    for e in engines {
        for &speed in speeds {
            for goal in 0..goals {
                for at in [At::Release, At::Rest] {
                    for mode in [Mode::Open, Mode::Mpc, Mode::Adaptive, Mode::Oracle] {
                        for plant in PlantKind::ALL {
                            for noise in [false, true] {
                                if (mode == Mode::Open && noise)
                                    || (mode == Mode::Oracle && plant == PlantKind::Nominal)
                                {
                                    continue;
                                }
                                out.push(Task {
                                    engine: e.clone(),
                                    speed,
                                    goal,
                                    at,
                                    mode,
                                    plant,
                                    noise,
                                });
                            }
                        }
                    }
                }
            }
        }
    }
    out
}

/// success (0/1), position error (m), angle error (rad), median and p99 of
/// the controller's CPU per period (estimator + re-plan, µs; NaN open loop),
/// median estimator CPU (µs; NaN unless adaptive), error (0/1), judged at
/// rest (1) or at the release (0: the engine cannot release), wall time (s).
const ROW: usize = 8;

/// Column `error` of a run whose plant the engine's scene cannot hold
/// (refused when its session started): not applicable, not a failure.
const UNSUPPORTED: f64 = 2.0;

/// The engine refused the plant's scene at the start.
#[derive(Debug)]
struct Unsupported(String);

impl std::fmt::Display for Unsupported {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the engine cannot hold this plant's scene: {}", self.0)
    }
}

impl std::error::Error for Unsupported {}

type Plans = BTreeMap<(u64, usize, At), Solution>;

fn run_task(
    problem: &Problem,
    engine: &dyn Engine,
    goals: &[Goal],
    plans: &Plans,
    t: &Task,
) -> Vec<f64> {
    let clock = Instant::now();
    let dt = engine.default_dt();
    let goal = goals[t.goal];
    let reach = Reach::default();
    let attempt = |at: At| -> anyhow::Result<Vec<f64>> {
        let spec = PlanSpec {
            segments: SEGMENTS,
            speed: t.speed,
            predictor: ModelKind::Dynamic,
            at,
        };
        let plant = t.plant.apply(problem)?;
        let mut session = match engine.start(&plant, dt) {
            Ok(s) => s,
            // An engine whose scene cannot hold this plate (one friction
            // coefficient per body, say): not a run of this engine.
            Err(e) if t.plant != PlantKind::Nominal => {
                return Err(anyhow::Error::new(Unsupported(e.to_string())))
            }
            Err(e) => return Err(e.into()),
        };
        let max_slide = problem.release.unwrap_or_default().max_duration;
        let row = match t.mode {
            Mode::Open => {
                let start = Start::of_problem(problem);
                let mut planner = Planner::new(
                    problem,
                    goal,
                    spec,
                    straight_time(&start, &goal, t.speed),
                    reach,
                );
                let plan = match plans.get(&(t.speed.to_bits(), t.goal, at)) {
                    Some(p) => p.clone(),
                    None => planner.plan(&start).context("no plan from rest")?,
                };
                let pushes = planner
                    .on_grid(&start, &plan, dt)
                    .context("re-solving the plan on the engine's step grid")?
                    .pushes;
                let mut st = open_loop(session.as_mut(), &pushes)?;
                if at == At::Rest {
                    session.release(max_slide)?;
                    st = session.state();
                }
                let (pe, ae) = pushval_control::pose_errors(st.x, st.y, st.theta, &goal);
                vec![
                    f64::from(u8::from(reach.holds(pe, ae))),
                    pe,
                    ae,
                    f64::NAN,
                    f64::NAN,
                    f64::NAN,
                ]
            }
            mode => {
                let sensor = if t.noise {
                    SensorSpec {
                        seed: t.goal as u64 + 1,
                        ..NOISE
                    }
                } else {
                    SensorSpec::default()
                };
                let spec = LoopSpec {
                    plan: spec,
                    period: PERIOD,
                    reach,
                    adapt: mode == Mode::Adaptive,
                    sensor,
                };
                let believed = if mode == Mode::Oracle {
                    &plant
                } else {
                    problem
                };
                let out = run_loop(believed, session.as_mut(), dt, goal, spec, &mut ())?;
                // The controller's CPU per period: estimator and re-plan.
                let per: Vec<f64> = out
                    .predictor_cpu_us
                    .iter()
                    .enumerate()
                    .map(|(i, p)| p + out.estimator_cpu_us.get(i).copied().unwrap_or(0.0))
                    .collect();
                let (med, p99) = median_p99(&per).unwrap_or((f64::NAN, f64::NAN));
                let est = median(&out.estimator_cpu_us).unwrap_or(f64::NAN);
                vec![
                    f64::from(u8::from(out.success)),
                    out.position_error,
                    out.angle_error,
                    med,
                    p99,
                    est,
                ]
            }
        };
        session.finish()?;
        Ok(row)
    };
    let finish = |r: anyhow::Result<Vec<f64>>, at: At| {
        r.map(|mut v| {
            v.push(0.0);
            v.push(f64::from(u8::from(at == At::Rest)));
            v
        })
    };
    let result = match attempt(t.at) {
        Err(e) if t.at == At::Rest && cannot_release(&e) => {
            finish(attempt(At::Release), At::Release)
        }
        r => finish(r, t.at),
    };
    let mut row = result.unwrap_or_else(|e| {
        let unsupported = e.downcast_ref::<Unsupported>().is_some();
        if !unsupported || t.goal == 0 {
            eprintln!("control-study --adaptive: {}: {e:#}", t.key());
        }
        let flag = if unsupported { UNSUPPORTED } else { 1.0 };
        vec![
            0.0,
            f64::NAN,
            f64::NAN,
            f64::NAN,
            f64::NAN,
            f64::NAN,
            flag,
            f64::NAN,
        ]
    });
    row.push(clock.elapsed().as_secs_f64());
    row
}

/// `pushval control-study --adaptive`.
pub fn cli(
    out: &Path,
    quick: bool,
    shard: Option<Shard>,
    merge: bool,
    only: Option<&str>,
) -> anyhow::Result<ExitCode> {
    let shard = match shard {
        Some(s) => Some(s),
        None if merge => None,
        None => Shard::from_env()?,
    };
    let problem = scene()?;
    let speeds: &[f64] = if quick { &[1.0] } else { &SPEEDS_ADAPTIVE };
    let count = if quick { QUICK_GOALS } else { GOALS };
    let clock = Instant::now();
    // The control study's goals (reachable at each of its speeds).
    let goals = goals(&problem, &SPEEDS, count);
    if goals.len() < count {
        bail!(
            "only {} of {count} goals are reachable on the dynamic model",
            goals.len()
        );
    }
    let names = engines(only)?;
    if names.is_empty() {
        bail!("no engine to study (every engine of this build is unavailable)");
    }
    let list = tasks(&names, speeds, goals.len());
    let keys: Vec<String> = list.iter().map(Task::key).collect();
    let parts = Parts {
        tag: "control-study --adaptive",
        stem: "adaptive",
        grid: grid_name(quick),
        hash: grid_hash(&keys),
    };
    eprintln!(
        "control-study --adaptive: {} goals, {} engines, {} runs",
        goals.len(),
        names.len(),
        list.len()
    );
    let rows: Vec<Vec<f64>> = if merge {
        parts.merge(out, list.len(), |_| Some(ROW + 1))?
    } else {
        let indices: Vec<usize> = match shard {
            Some(s) => s.indices(&keys),
            None => (0..list.len()).collect(),
        };
        let mine: Vec<&Task> = indices.iter().map(|&i| &list[i]).collect();
        let mut built: BTreeMap<String, Box<dyn Engine>> = BTreeMap::new();
        for t in &mine {
            if !built.contains_key(&t.engine) {
                let e = crate::registry::entry(&t.engine)
                    .expect("listed")
                    .default_engine();
                if let Err(why) = e.availability() {
                    bail!(
                        "engine `{}` is not available in this build: {why}",
                        t.engine
                    );
                }
                built.insert(t.engine.clone(), e);
            }
        }
        let mut plans = Plans::new();
        let start = Start::of_problem(&problem);
        for &v in speeds {
            for (i, g) in goals.iter().enumerate() {
                for at in [At::Release, At::Rest] {
                    let spec = PlanSpec {
                        segments: SEGMENTS,
                        speed: v,
                        predictor: ModelKind::Dynamic,
                        at,
                    };
                    let mut planner = Planner::new(
                        &problem,
                        *g,
                        spec,
                        straight_time(&start, g, v),
                        Reach::default(),
                    );
                    if let Some(s) = planner.plan(&start) {
                        plans.insert((v.to_bits(), i, at), s);
                    }
                }
            }
        }
        let computed =
            rows_with_progress("control-study --adaptive", &mine, clock, Task::key, |t| {
                run_task(&problem, built[&t.engine].as_ref(), &goals, &plans, t)
            });
        if let Some(s) = shard {
            write_part(out, &parts, list.len(), &indices, &computed, s, clock)?;
            return Ok(ExitCode::SUCCESS);
        }
        computed
    };
    let failed = rows.iter().filter(|r| r[6] == 1.0).count();
    write_outputs(out, &problem, &names, speeds, &list, &rows, quick)?;
    println!(
        "control-study --adaptive: {} runs in {:.1} s; wrote {}",
        rows.len(),
        clock.elapsed().as_secs_f64(),
        out.display()
    );
    if failed > 0 {
        eprintln!(
            "control-study --adaptive: {failed} of {} runs failed with an engine error and count as misses (runs.csv column `error`)",
            rows.len()
        );
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// A success.csv group: engine, speed, judged at, mode, plant, noisy.
type Group = (String, u64, At, Mode, PlantKind, bool);

fn write_outputs(
    out: &Path,
    problem: &Problem,
    names: &[String],
    speeds: &[f64],
    list: &[Task],
    rows: &[Vec<f64>],
    quick: bool,
) -> anyhow::Result<()> {
    let mut dir = OutDir::new(out)?;
    let mut runs = Csv::new(&[
        "engine",
        "speed",
        "goal",
        "at",
        "mode",
        "plant",
        "sensor",
        "success",
        "position_error_m",
        "angle_error_rad",
        "controller_cpu_us_median",
        "controller_cpu_us_p99",
        "estimator_cpu_us_median",
        "error",
        "judged_at",
        "wall_s",
    ]);
    let mut groups: BTreeMap<Group, Vec<&Vec<f64>>> = BTreeMap::new();
    for (t, r) in list.iter().zip(rows) {
        runs.row(&[
            t.engine.clone(),
            num(t.speed),
            t.goal.to_string(),
            t.at.as_str().into(),
            t.mode.as_str().into(),
            t.plant.as_str().into(),
            if t.noise { "noisy" } else { "exact" }.into(),
            num(r[0]),
            num(r[1]),
            num(r[2]),
            num(r[3]),
            num(r[4]),
            num(r[5]),
            num(r[6]),
            if r[7] == 1.0 {
                "rest".to_string()
            } else if r[7] == 0.0 {
                "release".to_string()
            } else {
                String::new()
            },
            num(r[8]),
        ]);
        if r[6] != UNSUPPORTED {
            groups
                .entry((
                    t.engine.clone(),
                    t.speed.to_bits(),
                    t.at,
                    t.mode,
                    t.plant,
                    t.noise,
                ))
                .or_default()
                .push(r);
        }
    }
    dir.file("runs.csv", runs.as_bytes())?;
    let mut success = Csv::new(&[
        "engine",
        "speed",
        "at",
        "mode",
        "plant",
        "sensor",
        "successes",
        "goals",
        "median_position_error_m",
        "failed_runs",
    ]);
    let mut counts: BTreeMap<Group, (usize, usize)> = BTreeMap::new();
    for (k, rs) in &groups {
        let ok = rs.iter().filter(|r| r[0] == 1.0).count();
        let pe = median(
            &rs.iter()
                .map(|r| if r[1].is_nan() { f64::INFINITY } else { r[1] })
                .collect::<Vec<_>>(),
        )
        .unwrap_or(f64::NAN);
        let failed = rs.iter().filter(|r| r[6] == 1.0).count();
        counts.insert(k.clone(), (ok, rs.len()));
        success.row(&[
            k.0.clone(),
            num(f64::from_bits(k.1)),
            k.2.as_str().into(),
            k.3.as_str().into(),
            k.4.as_str().into(),
            if k.5 { "noisy" } else { "exact" }.into(),
            ok.to_string(),
            rs.len().to_string(),
            num(pe),
            failed.to_string(),
        ]);
    }
    dir.file("success.csv", success.as_bytes())?;
    // The controller's cost per period, over every adaptive run.
    let cost: Vec<(f64, f64, f64)> = list
        .iter()
        .zip(rows)
        .filter(|(t, r)| t.mode == Mode::Adaptive && r[3].is_finite())
        .map(|(_, r)| (r[3], r[4], r[5]))
        .collect();
    let unsupported: std::collections::BTreeSet<(String, PlantKind)> = list
        .iter()
        .zip(rows)
        .filter(|(_, r)| r[6] == UNSUPPORTED)
        .map(|(t, _)| (t.engine.clone(), t.plant))
        .collect();
    let readme = readme(
        problem,
        names,
        speeds,
        &counts,
        &cost,
        rows,
        &unsupported,
        quick,
    );
    dir.file("README.md", readme.as_bytes())?;
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn readme(
    problem: &Problem,
    names: &[String],
    speeds: &[f64],
    counts: &BTreeMap<Group, (usize, usize)>,
    cost: &[(f64, f64, f64)],
    rows: &[Vec<f64>],
    unsupported: &std::collections::BTreeSet<(String, PlantKind)>,
    quick: bool,
) -> String {
    let get = |n: &str, v: f64, at: At, m: Mode, p: PlantKind, noise: bool| {
        counts
            .get(&(n.to_string(), v.to_bits(), at, m, p, noise))
            .copied()
    };
    let mut s = String::new();
    s.push_str("# Adaptive MPC: the plate's friction estimated online, in every engine\n\n");
    s.push_str(&format!(
        "Written by `pushval control-study --adaptive{}` (docs/closed-loop.md); do not edit.\n\n",
        if quick { " --quick" } else { "" }
    ));
    s.push_str(&format!(
        "The control study's plate and goals, at {}. Plants: `nominal` (the file), `perturbed` (μ × 0.8, I_cm × 1.2), `loads_side` (loads shifted toward +x: the centre of friction 48.5 mm off the line through the contact and the centre of mass), `loads_diagonal` (toward the far corner: along that line), `slippery_near` (the support at (+, −) five times as slippery), `slippery_far` (the far corner's). Modes: `open` (the plan made on the file's values), `mpc` (re-planned every {PERIOD} s on the file's values), `adaptive` (re-planned on the estimate of μ scale, centre of friction and I_cm from the readings so far), `oracle` (re-planned on the plant's true scene: the bound). Sensors: `exact`, and `noisy` (0.5 mm, 0.2°, 0.05 rad/s, 5 mm/s; the estimator weighs the declared noise). Success: within 20 mm and 5° of the goal, judged at the release or at rest (an engine that cannot release is judged at the release; `runs.csv` column `judged_at`).\n\n",
        speeds.iter().map(|v| format!("{v} m/s")).collect::<Vec<_>>().join(" and ")
    ));
    let failed = rows.iter().filter(|r| r[6] == 1.0).count();
    if failed > 0 {
        s.push_str(&format!(
            "{failed} of {} runs ended with an engine error and count as misses (`runs.csv`, column `error`).\n\n",
            rows.len()
        ));
    }
    if let (Some(m), Some(p)) = (
        median(&cost.iter().map(|c| c.0).collect::<Vec<_>>()),
        median(&cost.iter().map(|c| c.1).collect::<Vec<_>>()),
    ) {
        let est = median(&cost.iter().map(|c| c.2).collect::<Vec<_>>()).unwrap_or(f64::NAN);
        let worst = cost.iter().map(|c| c.1).fold(0.0, f64::max);
        s.push_str(&format!(
            "The controller's CPU per period (estimator and re-plan, thread CPU time) over the {} adaptive runs: median of the runs' medians {m:.1} µs (the estimator alone {est:.1} µs), median of their 99th percentiles {p:.1} µs, the worst run's 99th percentile {worst:.1} µs; targets 100 µs and 1 ms ({}).\n\n",
            cost.len(),
            if m <= 100.0 && p <= 1000.0 { "met by the medians" } else { "not met" }
        ));
    }
    for n in names {
        s.push_str(&format!("## {n}\n\n"));
        let refused: Vec<&str> = PlantKind::ALL
            .into_iter()
            .filter(|p| unsupported.contains(&(n.clone(), *p)))
            .map(PlantKind::as_str)
            .collect();
        if !refused.is_empty() {
            s.push_str(&format!(
                "Its scene cannot hold the plants {} (its session refused them at the start; the study prints why): they are left out of its table (n/a).\n\n",
                refused.join(", ")
            ));
        }
        if let Some(l) = crate::registry::entry(n)
            .and_then(|e| law_line(problem, e.default_engine().as_ref(), 1.0))
        {
            s.push_str(&format!("At 1 m/s {l}.\n\n"));
        }
        for &v in speeds {
            for at in [At::Release, At::Rest] {
                s.push_str(&format!(
                    "{v} m/s, judged at {}: goals reached of each plant's runs (exact sensor / noisy).\n\n| plant | open | mpc | adaptive | oracle |\n|---|---|---|---|---|\n",
                    at.as_str()
                ));
                for p in PlantKind::ALL {
                    let cell = |m: Mode| {
                        let c = |noise| match get(n, v, at, m, p, noise) {
                            Some((ok, tot)) => format!("{ok}/{tot}"),
                            None if unsupported.contains(&(n.clone(), p)) => "n/a".into(),
                            None => "–".into(),
                        };
                        if m == Mode::Open {
                            c(false)
                        } else {
                            format!("{} / {}", c(false), c(true))
                        }
                    };
                    s.push_str(&format!(
                        "| {} | {} | {} | {} | {} |\n",
                        p.as_str(),
                        cell(Mode::Open),
                        cell(Mode::Mpc),
                        cell(Mode::Adaptive),
                        cell(Mode::Oracle)
                    ));
                }
                s.push('\n');
            }
        }
        // The targets, each stated from the counts.
        let mut lines = Vec::new();
        for &v in speeds {
            let ok = |at, m, p, noise| get(n, v, at, m, p, noise).map_or(0, |c| c.0) as i64;
            let gap = |at, noise| {
                PlantKind::ALL
                    .into_iter()
                    .filter(|p| {
                        p.moves_friction()
                            && get(n, v, at, Mode::Adaptive, *p, noise).is_some()
                            && get(n, v, at, Mode::Oracle, *p, noise).is_some()
                    })
                    .map(|p| {
                        (
                            p,
                            ok(at, Mode::Adaptive, p, noise) - ok(at, Mode::Oracle, p, noise),
                        )
                    })
                    .min_by_key(|x| x.1)
            };
            // How far adaptive MPC falls short of the oracle (0: nowhere).
            let short = |g: i64, p: PlantKind| {
                if g >= 0 {
                    "it reaches at least as many goals as the oracle on each".to_string()
                } else {
                    format!(
                        "it falls at most {} goals short of the oracle (`{}`)",
                        -g,
                        p.as_str()
                    )
                }
            };
            if let Some((p, g)) = gap(At::Release, false) {
                lines.push(format!(
                    "{v} m/s, judged at the release, plants that move or split the friction: {}; the target (within 2) is {}",
                    short(g, p),
                    if g >= -2 { "met" } else { "missed" }
                ));
            }
            let (a, m) = (
                ok(At::Release, Mode::Adaptive, PlantKind::Nominal, false),
                ok(At::Release, Mode::Mpc, PlantKind::Nominal, false),
            );
            lines.push(format!(
                "{v} m/s, the nominal plate at the release: adaptive MPC reaches {a}, plain MPC {m}{}",
                if a >= m {
                    ""
                } else {
                    ": fewer, the target is missed"
                }
            ));
            let (a, m, o) = (
                ok(At::Rest, Mode::Adaptive, PlantKind::Perturbed, false),
                ok(At::Rest, Mode::Mpc, PlantKind::Perturbed, false),
                ok(At::Rest, Mode::Oracle, PlantKind::Perturbed, false),
            );
            lines.push(format!(
                "{v} m/s, the uniform change judged at rest: adaptive MPC reaches {a}, plain MPC {m}, the oracle {o}"
            ));
            if let Some((p, g)) = gap(At::Release, true) {
                lines.push(format!(
                    "{v} m/s, noisy sensor, at the release: {}; the target (within 4) is {}",
                    short(g, p),
                    if g >= -4 { "met" } else { "missed" }
                ));
            }
            if let Some((p, g)) = gap(At::Rest, false) {
                lines.push(if g >= -2 {
                    format!("{v} m/s, judged at rest, plants that move or split the friction: {}", short(g, p))
                } else {
                    format!(
                        "{v} m/s, judged at rest, plants that move or split the friction: {}; the estimate explains the pushed motion but not how the friction is split among the supports beyond its total, centre and moment, and the slide after the release depends on that split",
                        short(g, p)
                    )
                });
            }
        }
        for &v in speeds {
            let c = |m, p| get(n, v, At::Release, m, p, false).map_or(0, |c| c.0);
            let tot =
                get(n, v, At::Release, Mode::Mpc, PlantKind::Nominal, false).map_or(0, |c| c.1);
            let (mpc, oracle) = (
                c(Mode::Mpc, PlantKind::Nominal),
                c(Mode::Oracle, PlantKind::Perturbed),
            );
            if tot > 0 && 2 * mpc < tot {
                lines.push(format!(
                    "at {v} m/s MPC on the nominal plate reaches only {mpc}/{tot} and the oracle {oracle}/{tot} on the perturbed one: this engine's friction has another shape than Coulomb's at the supports, so no value of the parameters the estimator fits makes the model move the plate as it does, and adaptation cannot recover it"
                ));
            }
        }
        for l in lines {
            s.push_str(&format!("- {l}.\n"));
        }
        s.push('\n');
    }
    s
}
