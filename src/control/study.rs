//! `pushval control-study`: do plans and MPC made on a model work in each
//! engine, and where do they break?
//!
//! The scene is the seed paper's plate (shipped `paper-square-v1.0.toml`,
//! started from rest). Goals are drawn from a fixed generator (0.3–1 m away,
//! turns up to ±90°) and kept when the dynamic model reaches them at rest
//! at 0.1, 0.5 and 1 m/s; the first 20 (3 with `--quick`, reachable at
//! 1 m/s) are the study's. For every engine, speed (0.5 and 1 m/s; 1 m/s
//! with `--quick`), rule (judged at the release or at rest), goal and plan
//! predictor (dynamic, kinematic) the plan made on the predictor for that
//! rule runs open loop and under MPC, on the nominal plant and on the
//! perturbed one (μ × 0.8, I_cm × 1.2). Every run is one task of the shard
//! list; `runs.csv` has one row per run, `success.csv` the counts,
//! `success.svg` and `paths.svg` the figures, README.md why each engine
//! succeeds or fails, from its friction law, and how its counts move from
//! the release rule to the rest rule.
//!
//! 0.1 m/s is not in the grid: there the slide after the release is at
//! most v²/(2μg) ≈ 1 mm (μ = 0.5), well inside the 20 mm tolerance, so
//! both rules judge alike, and that speed cost 78 % of the wall time of the
//! grid that had it (5,724 of 7,316 s of runs, judged at the release only).

use std::collections::BTreeMap;
use std::f64::consts::FRAC_PI_2;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use pushval_engine::Engine;
use pushval_model::Problem;

use crate::outdir::{num, Csv, Writer as OutDir};
use crate::shard::{grid_hash, grid_name, Parts, Shard};
use pushval_control::mpc::{open_loop, run_loop, LoopSpec, PlantScale};
use pushval_control::plan::{straight_time, PlanSpec, Planner, Solution};
use pushval_control::predict::Start;
use pushval_control::stats::{median, median_p99};
use pushval_control::{At, Goal, ModelKind as Predictor, Reach};

pub use super::grid::{
    AT, GOALS, GRID_SPEEDS, PERIOD, QUICK_GOALS, QUICK_SPEEDS, RULES, SCENE, SEGMENTS, SPEEDS,
};

/// Open loop or MPC.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// The plan as made, replayed in the engine.
    Open,
    /// Re-planned every period from the engine's state.
    Mpc,
}

impl Mode {
    fn as_str(self) -> &'static str {
        match self {
            Mode::Open => "open",
            Mode::Mpc => "mpc",
        }
    }
}

/// One run of the study.
#[derive(Debug, Clone)]
pub struct Task {
    /// The engine model.
    pub engine: String,
    /// Pusher speed (m/s).
    pub speed: f64,
    /// The rule asked: the plan aims for, and the run is judged at, the
    /// release or rest (an engine that cannot release is judged at the
    /// release whatever the rule; its row says so).
    pub at: At,
    /// Index into the goals.
    pub goal: usize,
    /// What the plan (and the MPC) is made on.
    pub predictor: Predictor,
    /// Open loop or MPC.
    pub mode: Mode,
    /// Whether the plant is perturbed.
    pub perturbed: bool,
}

impl Task {
    fn key(&self) -> String {
        format!(
            "{}/{}/{}/{}/{}/{}/{}",
            self.engine,
            self.speed,
            self.at.as_str(),
            self.goal,
            self.predictor.as_str(),
            self.mode.as_str(),
            if self.perturbed {
                "perturbed"
            } else {
                "nominal"
            }
        )
    }
    fn plant(&self) -> PlantScale {
        if self.perturbed {
            PlantScale::PERTURBED
        } else {
            PlantScale::default()
        }
    }
}

/// The numbers of one run: success (0/1), position error (m), angle error
/// (rad), predictor median and p99 (µs; NaN open loop), whether the engine
/// replayed its schedule (0/1), whether the run failed with an error (0/1),
/// whether it was judged at rest (1) or at the release because the engine
/// cannot release (0), the wall time (s).
const ROW: usize = 9;

/// Whether `e` is an engine's refusal to release the plate.
pub(crate) fn cannot_release(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        matches!(
            c.downcast_ref::<pushval_model::ModelError>(),
            Some(pushval_model::ModelError::NoRelease { .. })
        ) || matches!(
            c.downcast_ref::<pushval_control::ControlError>(),
            Some(pushval_control::ControlError::Plant {
                source: pushval_model::ModelError::NoRelease { .. },
                ..
            })
        )
    })
}

/// The study's scene problem, from rest.
pub fn scene() -> anyhow::Result<Problem> {
    let text = crate::shipped::scenario_text(SCENE).context("the shipped scene is missing")?;
    let sc =
        pushval_scenario::Scenario::from_toml(text, &crate::shipped::label("scenarios", SCENE))?;
    let mut p = sc.problem();
    p.initial.from_rest = true;
    Ok(p)
}

/// A small linear congruential generator (Knuth's MMIX constants): the goal
/// list must be the same on every machine and every version of any crate,
/// so it is written here rather than taken from a random-number crate.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The study's goals: drawn 0.3–1 m from the start, in the half-plane the
/// corner push moves the plate into (bearing −30° to 120°), turned by up to
/// ±90°, and kept when the dynamic model's plan reaches each at every speed.
pub fn goals(problem: &Problem, speeds: &[f64], count: usize) -> Vec<Goal> {
    let mut rng = Lcg(0x5_eed0_fc04_7201);
    let mut out = Vec::new();
    let start = Start::of_problem(problem);
    let reach = Reach::default();
    for _ in 0..40 * count {
        if out.len() == count {
            break;
        }
        let d = 0.3 + 0.7 * rng.next();
        let bearing = (-30.0 + 150.0 * rng.next()).to_radians();
        let turn = (rng.next() * 2.0 - 1.0) * FRAC_PI_2;
        let goal = Goal {
            x: start.position.x + d * bearing.cos(),
            y: start.position.y + d * bearing.sin(),
            theta: start.theta + turn,
        };
        let reached = speeds.iter().all(|&v| {
            let spec = PlanSpec {
                segments: SEGMENTS,
                speed: v,
                predictor: Predictor::Dynamic,
                at: AT,
            };
            let mut planner =
                Planner::new(problem, goal, spec, straight_time(&start, &goal, v), reach);
            planner.plan(&start).is_some_and(|s| s.converged)
        });
        if reached {
            out.push(goal);
        }
    }
    out
}

/// Every engine of the build and of the project that this build can run
/// (or those of `only`).
pub fn engines(only: Option<&str>) -> anyhow::Result<Vec<String>> {
    let entries = crate::registry::entries();
    match only {
        None => Ok(entries
            .into_iter()
            .filter(|e| e.default_engine().availability().is_ok())
            .map(|e| e.name)
            .collect()),
        Some(list) => {
            let mut out = Vec::new();
            for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
                if !entries.iter().any(|a| a.name == name) {
                    bail!(
                        "--only: `{name}` is not an engine of this build or of {} (see `pushval engines`)",
                        crate::registry::engines_file()
                    );
                }
                if out.iter().any(|o| o == name) {
                    bail!("--only: `{name}` is named twice");
                }
                out.push(name.to_string());
            }
            if out.is_empty() {
                bail!("--only `{list}` names no engine (a comma-separated list of names from `pushval engines`)");
            }
            Ok(out)
        }
    }
}

/// The engines that run `tasks`, built, each checked available: a shard
/// needs only its own engines (a list may name engines of another build,
/// whose shards run there; `--merge` joins the parts).
fn build_engines(
    names: &[String],
    tasks: &[&Task],
) -> anyhow::Result<BTreeMap<String, Box<dyn Engine>>> {
    let mut built = BTreeMap::new();
    for name in names {
        if !tasks.iter().any(|t| &t.engine == name) {
            continue;
        }
        let e = crate::registry::entry(name).expect("listed by engines()");
        let engine = e.default_engine();
        if let Err(why) = engine.availability() {
            bail!("engine `{name}` is not available in this build: {why}");
        }
        built.insert(name.clone(), engine);
    }
    Ok(built)
}

/// The task list: engines × speeds × rules × goals × predictors × modes ×
/// plants, engine by engine (so with `--only` naming N engines the range
/// shard `K/N` is the K-th engine's runs).
pub fn tasks(engines: &[String], speeds: &[f64], goals: usize) -> Vec<Task> {
    let mut out = Vec::new();
    for e in engines {
        for &speed in speeds {
            for at in RULES {
                for goal in 0..goals {
                    for predictor in [Predictor::Dynamic, Predictor::Kinematic] {
                        for mode in [Mode::Open, Mode::Mpc] {
                            for perturbed in [false, true] {
                                out.push(Task {
                                    engine: e.clone(),
                                    speed,
                                    at,
                                    goal,
                                    predictor,
                                    mode,
                                    perturbed,
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

/// The plans from rest, one per (speed, rule, goal, predictor).
type Plans = BTreeMap<(u64, &'static str, usize, &'static str), Solution>;

fn plans(problem: &Problem, speeds: &[f64], goals: &[Goal]) -> Plans {
    let start = Start::of_problem(problem);
    let mut out = Plans::new();
    for &v in speeds {
        for at in RULES {
            for (i, g) in goals.iter().enumerate() {
                for predictor in [Predictor::Dynamic, Predictor::Kinematic] {
                    let spec = PlanSpec {
                        segments: SEGMENTS,
                        speed: v,
                        predictor,
                        at,
                    };
                    let mut planner = Planner::new(
                        problem,
                        *g,
                        spec,
                        straight_time(&start, g, v),
                        Reach::default(),
                    );
                    if let Some(s) = planner.plan(&start) {
                        out.insert((v.to_bits(), at.as_str(), i, predictor.as_str()), s);
                    }
                }
            }
        }
    }
    out
}

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
    // One run judged by the task's rule; an engine that cannot release is
    // run again judged at the release, and its row says so (column
    // `judged_at`).
    let attempt = |at: At| -> anyhow::Result<Vec<f64>> {
        let spec = PlanSpec {
            segments: SEGMENTS,
            speed: t.speed,
            predictor: t.predictor,
            at,
        };
        let plant = t.plant().apply(problem)?;
        let mut session = engine.start(&plant, dt)?;
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
                let plan = match plans.get(&(
                    t.speed.to_bits(),
                    at.as_str(),
                    t.goal,
                    t.predictor.as_str(),
                )) {
                    Some(p) => p.clone(),
                    None => planner.plan(&start).context("no plan from rest")?,
                };
                // The plan with its time on the engine's step grid,
                // re-solved there: what the engine runs is what was planned.
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
                    0.0,
                    0.0,
                ]
            }
            Mode::Mpc => {
                let spec = LoopSpec {
                    plan: spec,
                    period: PERIOD,
                    reach,
                    adapt: false,
                    sensor: Default::default(),
                };
                let out = run_loop(problem, session.as_mut(), dt, goal, spec, &mut ())?;
                let (med, p99) = median_p99(&out.predictor_us).unwrap_or((f64::NAN, f64::NAN));
                vec![
                    f64::from(u8::from(out.success)),
                    out.position_error,
                    out.angle_error,
                    med,
                    p99,
                    f64::from(u8::from(out.replayed)),
                    0.0,
                ]
            }
        };
        session.finish()?;
        Ok(row)
    };
    let at_rest = |r: anyhow::Result<Vec<f64>>, at: At| {
        r.map(|mut v| {
            v.push(f64::from(u8::from(at == At::Rest)));
            v
        })
    };
    let result = match attempt(t.at) {
        Err(e) if t.at == At::Rest && cannot_release(&e) => {
            at_rest(attempt(At::Release), At::Release)
        }
        r => at_rest(r, t.at),
    };
    let mut row = result.unwrap_or_else(|e| {
        eprintln!("control-study: {}: {e:#}", t.key());
        vec![
            0.0,
            f64::NAN,
            f64::NAN,
            f64::NAN,
            f64::NAN,
            0.0,
            1.0,
            f64::NAN,
        ]
    });
    row.push(clock.elapsed().as_secs_f64());
    row
}

/// `pushval control-study`.
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
    let speeds: &[f64] = if quick { &QUICK_SPEEDS } else { &GRID_SPEEDS };
    let goal_speeds: &[f64] = if quick { &QUICK_SPEEDS } else { &SPEEDS };
    let count = if quick { QUICK_GOALS } else { GOALS };
    let clock = Instant::now();
    let goals = goals(&problem, goal_speeds, count);
    if goals.len() < count {
        bail!(
            "only {} of {count} goals are reachable on the dynamic model at every speed (a bug in the planner or the scene)",
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
        tag: "control-study",
        stem: "control",
        grid: grid_name(quick),
        hash: grid_hash(&keys),
    };
    eprintln!(
        "control-study: {} goals, {} engines, {} runs",
        goals.len(),
        names.len(),
        list.len()
    );
    let rows: Vec<Vec<f64>> = if merge {
        parts.merge(out, list.len(), |_| Some(ROW))?
    } else {
        let indices: Vec<usize> = match shard {
            Some(s) => s.indices(&keys),
            None => (0..list.len()).collect(),
        };
        let mine: Vec<&Task> = indices.iter().map(|&i| &list[i]).collect();
        let built = build_engines(&names, &mine)?;
        let plans = plans(&problem, speeds, &goals);
        let computed = rows_with_progress("control-study", &mine, clock, Task::key, |t| {
            run_task(&problem, built[&t.engine].as_ref(), &goals, &plans, t)
        });
        if let Some(s) = shard {
            write_part(out, &parts, list.len(), &indices, &computed, s, clock)?;
            return Ok(ExitCode::SUCCESS);
        }
        computed
    };
    let failed = rows.iter().filter(|r| r[6] == 1.0).count();
    write_outputs(out, &problem, &names, speeds, &goals, &list, &rows, quick)?;
    println!(
        "control-study: {} runs in {:.1} s; wrote {}",
        rows.len(),
        clock.elapsed().as_secs_f64(),
        out.display()
    );
    if failed > 0 {
        eprintln!(
            "control-study: {failed} of {} runs failed with an engine error and count as misses (runs.csv column `error`; the messages are above)",
            rows.len()
        );
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// Each of `items` through `eval` on every core, with progress on standard
/// error (a bar on a terminal; a line per tenth elsewhere, e.g. in CI logs,
/// tagged `tag` and naming the last run by `key`).
pub(crate) fn rows_with_progress<T: Sync>(
    tag: &str,
    items: &[&T],
    clock: Instant,
    key: impl Fn(&T) -> String + Sync,
    eval: impl Fn(&T) -> Vec<f64> + Sync,
) -> Vec<Vec<f64>> {
    let done = std::sync::atomic::AtomicUsize::new(0);
    let quiet_bar = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    crate::parallel::par_rows(items, true, "runs", |t| {
        let row = eval(t);
        let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        let n = items.len();
        if quiet_bar && (k * 10 / n != (k - 1) * 10 / n || k == n) {
            eprintln!(
                "{tag}: {k}/{n} runs done ({:.0} s; last {})",
                clock.elapsed().as_secs_f64(),
                key(t)
            );
        }
        row
    })
}

/// Writes a shard's rows into `out`'s parts folder and says so.
pub(crate) fn write_part(
    out: &Path,
    parts: &Parts,
    total: usize,
    indices: &[usize],
    rows: &[Vec<f64>],
    s: Shard,
    clock: Instant,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(out.join("parts"))?;
    crate::atomic::write_atomic(
        &out.join(parts.file_name(s)),
        parts.text(total, indices, rows, s).as_bytes(),
    )?;
    eprintln!(
        "{}: part {}/{} ({} runs) in {:.1} s: {}",
        parts.tag,
        s.k,
        s.n,
        rows.len(),
        clock.elapsed().as_secs_f64(),
        out.join(parts.file_name(s)).display()
    );
    Ok(())
}

use super::figures::Group;
pub(crate) use super::write_up::law_line;
use super::write_up::{readme, Counts, Move, PairKey};

/// What judged a run (its row's column 7): `rest`, `release`, or None for
/// a run that ended with an engine error.
fn judged_at(r: &[f64]) -> Option<&'static str> {
    if r[7] == 1.0 {
        Some("rest")
    } else if r[7] == 0.0 {
        Some("release")
    } else {
        None
    }
}

#[allow(clippy::too_many_arguments)]
fn write_outputs(
    out: &Path,
    problem: &Problem,
    names: &[String],
    speeds: &[f64],
    goals: &[Goal],
    list: &[Task],
    rows: &[Vec<f64>],
    quick: bool,
) -> anyhow::Result<()> {
    let mut dir = OutDir::new(out)?;
    // runs.csv
    let mut runs = Csv::new(&[
        "engine",
        "speed",
        "at",
        "goal",
        "goal_x",
        "goal_y",
        "goal_theta",
        "predictor",
        "mode",
        "plant",
        "success",
        "position_error_m",
        "angle_error_rad",
        "predictor_us_median",
        "predictor_us_p99",
        "engine_replayed",
        "error",
        "judged_at",
        "wall_s",
    ]);
    for (t, r) in list.iter().zip(rows) {
        let g = goals[t.goal];
        runs.row(&[
            t.engine.clone(),
            num(t.speed),
            t.at.as_str().into(),
            t.goal.to_string(),
            num(g.x),
            num(g.y),
            num(g.theta),
            t.predictor.as_str().into(),
            t.mode.as_str().into(),
            if t.perturbed { "perturbed" } else { "nominal" }.into(),
            num(r[0]),
            num(r[1]),
            num(r[2]),
            num(r[3]),
            num(r[4]),
            num(r[5]),
            num(r[6]),
            judged_at(r).unwrap_or_default().into(),
            num(r[8]),
        ]);
    }
    dir.file("runs.csv", runs.as_bytes())?;
    // success.csv
    let mut groups: BTreeMap<Group, Vec<&Vec<f64>>> = BTreeMap::new();
    let mut order: Vec<Group> = Vec::new();
    for (t, r) in list.iter().zip(rows) {
        let k: Group = (
            t.engine.clone(),
            t.speed.to_bits(),
            t.at.as_str(),
            t.predictor.as_str(),
            t.mode.as_str(),
            if t.perturbed { "perturbed" } else { "nominal" },
        );
        if !groups.contains_key(&k) {
            order.push(k.clone());
        }
        groups.entry(k).or_default().push(r);
    }
    let mut success = Csv::new(&[
        "engine",
        "speed",
        "at",
        "predictor",
        "mode",
        "plant",
        "successes",
        "goals",
        "median_position_error_m",
        "median_angle_error_rad",
        "failed_runs",
        "judged_at",
    ]);
    // True medians over every run of the group: a run that ended with an
    // engine error has no final pose and counts as an infinite error (a
    // miss), so failures raise the median instead of leaving it.
    let med = |v: Vec<f64>| median(&v).unwrap_or(f64::NAN);
    let mut summary: BTreeMap<Group, (usize, usize, f64, f64)> = BTreeMap::new();
    let mut failed_by_group: BTreeMap<Group, usize> = BTreeMap::new();
    for k in &order {
        let rs = &groups[k];
        let ok = rs.iter().filter(|r| r[0] == 1.0).count();
        let err = |v: f64| if v.is_nan() { f64::INFINITY } else { v };
        let pe = med(rs.iter().map(|r| err(r[1])).collect());
        let ae = med(rs.iter().map(|r| err(r[2])).collect());
        let failed = rs.iter().filter(|r| r[6] == 1.0).count();
        // What judged the group's runs: the rule asked, or the release for
        // an engine that cannot release (`mixed` if both; empty if every
        // run failed).
        let mut judged: Vec<&str> = rs.iter().filter_map(|r| judged_at(r)).collect();
        judged.sort_unstable();
        judged.dedup();
        let judged = match judged.as_slice() {
            [] => "",
            [one] => one,
            _ => "mixed",
        };
        summary.insert(k.clone(), (ok, rs.len(), pe, ae));
        failed_by_group.insert(k.clone(), failed);
        success.row(&[
            k.0.clone(),
            num(f64::from_bits(k.1)),
            k.2.into(),
            k.3.into(),
            k.4.into(),
            k.5.into(),
            ok.to_string(),
            rs.len().to_string(),
            num(pe),
            num(ae),
            failed.to_string(),
            judged.into(),
        ]);
    }
    dir.file("success.csv", success.as_bytes())?;
    let mut goals_csv = Csv::new(&["goal", "x", "y", "theta"]);
    for (i, g) in goals.iter().enumerate() {
        goals_csv.row(&[i.to_string(), num(g.x), num(g.y), num(g.theta)]);
    }
    dir.file("goals.csv", goals_csv.as_bytes())?;
    dir.figure(
        "success.svg",
        &super::figures::success_figure(names, speeds, &summary, &failed_by_group),
    )?;
    let paths = super::figures::paths_figure(problem, SEGMENTS, names, goals, speeds)?;
    dir.figure("paths.svg", &paths)?;
    let mut failed_runs: BTreeMap<String, usize> = BTreeMap::new();
    let mut at_release: BTreeMap<String, usize> = BTreeMap::new();
    // Each goal's outcome by both rules: (release, rest) successes.
    let mut pairs: BTreeMap<PairKey, [Option<bool>; 2]> = BTreeMap::new();
    for (t, r) in list.iter().zip(rows) {
        if r[6] == 1.0 {
            *failed_runs.entry(t.engine.clone()).or_default() += 1;
        }
        if t.at == At::Rest && r[7] == 0.0 {
            *at_release.entry(t.engine.clone()).or_default() += 1;
        }
        let key = (
            t.engine.clone(),
            t.speed.to_bits(),
            t.predictor.as_str(),
            t.mode.as_str(),
            if t.perturbed { "perturbed" } else { "nominal" },
            t.goal,
        );
        pairs.entry(key).or_default()[usize::from(t.at == At::Rest)] = Some(r[0] == 1.0);
    }
    let mut moves: BTreeMap<Move, (usize, usize)> = BTreeMap::new();
    for ((e, v, pr, m, pl, _), [release, rest]) in &pairs {
        let (Some(release), Some(rest)) = (release, rest) else {
            continue;
        };
        let slot = moves.entry((e.clone(), *v, pr, m, pl)).or_default();
        slot.0 += usize::from(*rest && !*release);
        slot.1 += usize::from(*release && !*rest);
    }
    let readme = readme(
        problem,
        &Counts {
            names,
            speeds,
            goals: goals.len(),
            summary: &summary,
            moves,
            failed_runs,
            at_release,
            quick,
        },
    );
    dir.file("README.md", readme.as_bytes())?;
    Ok(())
}
