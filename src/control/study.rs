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
use pushval_model::{Problem, Push};

use crate::outdir::{num, Csv, Writer as OutDir};
use crate::shard::{grid_hash, grid_name, Parts, Shard};
use pushval_control::mpc::{open_loop, run_loop, LoopSpec, PlantScale};
use pushval_control::plan::{straight_time, PlanSpec, Planner, Solution};
use pushval_control::predict::Start;
use pushval_control::stats::{median, median_p99};
use pushval_control::{At, Goal, ModelKind as Predictor, Reach};
use pushval_engine::FrictionLaw;

/// The study's scene: a shipped scenario.
pub const SCENE: &str = "paper-square-v1.0.toml";
/// The speeds every goal of the full grid is reachable at on the dynamic
/// model (m/s): the goal list is the one the study has always had (and the
/// adaptive study shares), though the grid runs [`GRID_SPEEDS`] only.
pub const SPEEDS: [f64; 3] = [0.1, 0.5, 1.0];
/// The speeds of the full grid (m/s). 0.1 m/s is left out: its slide is
/// at most v²/(2μg) ≈ 1 mm, so both rules judge alike there (module doc).
pub const GRID_SPEEDS: [f64; 2] = [0.5, 1.0];
/// The speed of the quick grid (m/s).
pub const QUICK_SPEEDS: [f64; 1] = [1.0];
/// Goals of the full grid.
pub const GOALS: usize = 20;
/// Goals of the quick grid.
pub const QUICK_GOALS: usize = 3;
/// Pushes per plan.
pub const SEGMENTS: usize = 6;
/// The MPC's control period (s).
pub const PERIOD: f64 = 0.02;
/// The rule the goals are chosen by, and the default of `plan` and `loop`:
/// at rest, after the slide.
pub const AT: pushval_control::At = pushval_control::At::Rest;
/// The rules of the grid: judged at the release (the plan aimed at the
/// release pose, as `--at release`) and at rest (aimed at rest).
pub const RULES: [At; 2] = [At::Release, At::Rest];

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

/// The law's steady ω against Coulomb's for the scene's middle push at
/// `speed`: (law name, law ω, Coulomb ω, class).
pub(crate) fn law_line(problem: &Problem, engine: &dyn Engine, speed: f64) -> Option<String> {
    let law = engine.law()?;
    let mut p = problem.clone();
    p.pushes = vec![Push {
        duration: 2.0,
        speed,
        phi: std::f64::consts::FRAC_PI_4 + 0.3,
    }];
    let dt = engine.default_dt();
    let w_law = law.steady(&p, 0, dt)?;
    let w_c = pushval_engine::COULOMB.steady(&p, 0, dt)?;
    Some(format!(
        "its law ({}) turns at {:.3} rad/s where Coulomb's turns at {:.3} rad/s (φ = π/4 + 0.3, {speed} m/s; ω = 0 {})",
        law.law_name(),
        w_law.omega,
        w_c.omega,
        match w_law.class {
            pushval_engine::LawClass::Turns => "is not held".to_string(),
            other => format!("is {}", other.as_str()),
        }
    ))
}

/// One goal's runs by both rules: engine, speed (bits), predictor, mode,
/// plant, goal.
type PairKey = (String, u64, &'static str, &'static str, &'static str, usize);

/// One (engine, speed, predictor, mode, plant) cell, both rules.
type Move = (String, u64, &'static str, &'static str, &'static str);

/// The old grid's wall time (s of runs, summed over `runs.csv`'s `wall_s`,
/// judged at the release only, 28 engines): at 0.1 m/s and in all
/// (results/closed_loop/runs.csv of commit 32437d4).
const OLD_SLOW_WALL_S: f64 = 5724.0;
const OLD_TOTAL_WALL_S: f64 = 7316.0;

/// What the README is written from.
struct Counts<'a> {
    names: &'a [String],
    speeds: &'a [f64],
    goals: usize,
    summary: &'a BTreeMap<Group, (usize, usize, f64, f64)>,
    /// Per cell: goals reached at rest and not at the release (gained),
    /// and reached at the release and not at rest (lost).
    moves: BTreeMap<Move, (usize, usize)>,
    /// Runs that ended with an engine error, per engine.
    failed_runs: BTreeMap<String, usize>,
    /// Rest runs judged at the release (the engine cannot release), per
    /// engine.
    at_release: BTreeMap<String, usize>,
    quick: bool,
}

/// A count moved from the release rule to the rest rule: `(=)`, `(+2)`,
/// `(−3)` or `(+1 −2)` (goals gained and lost).
fn moved(gained: usize, lost: usize) -> String {
    match (gained, lost) {
        (0, 0) => "(=)".into(),
        (g, 0) => format!("(+{g})"),
        (0, l) => format!("(−{l})"),
        (g, l) => format!("(+{g} −{l})"),
    }
}

/// `a, b and c`.
fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

fn readme(problem: &Problem, c: &Counts) -> String {
    let (names, speeds, goals) = (c.names, c.speeds, c.goals);
    let vmax = speeds.iter().copied().fold(f64::MIN, f64::max);
    let get =
        |n: &str, v: f64, at: &'static str, pr: &'static str, m: &'static str, pl: &'static str| {
            c.summary
                .get(&(n.to_string(), v.to_bits(), at, pr, m, pl))
                .copied()
                .unwrap_or((0, 0, f64::NAN, f64::NAN))
        };
    let mv = |n: &str, v: f64, pr: &'static str, m: &'static str, pl: &'static str| {
        c.moves
            .get(&(n.to_string(), v.to_bits(), pr, m, pl))
            .copied()
            .unwrap_or((0, 0))
    };
    let released = |n: &str| c.at_release.get(n).copied().unwrap_or(0) == 0;
    let errors = |n: &str| c.failed_runs.get(n).copied().unwrap_or(0);
    let coulomb = |e: &dyn Engine| {
        e.law()
            .is_some_and(|l| l.law_name() == pushval_engine::COULOMB.law_name())
    };
    let engine = |n: &str| crate::registry::entry(n).expect("listed").default_engine();
    let mut s = String::new();
    s.push_str("# Closed loop: plans and MPC made on the model, in every engine\n\n");
    s.push_str("Written by `pushval control-study");
    if c.quick {
        s.push_str(" --quick");
    }
    s.push_str("` (docs/closed-loop.md); do not edit.\n\n");
    let goal_speeds: &[f64] = if c.quick { &QUICK_SPEEDS } else { &SPEEDS };
    let list_speeds =
        |v: &[f64]| and_list(&v.iter().map(|v| format!("{v} m/s")).collect::<Vec<_>>());
    s.push_str(&format!(
        "The seed paper's plate (`{SCENE}`, from rest), {goals} goals 0.3–1 m away with turns up to ±90° (`goals.csv`), each reachable at rest by the dynamic model at {}. The grid runs {}, every run by two rules (column `at`): judged at the release, when the last push ends and the plate still moves (the plan aims at that pose, as `--at release`), and judged at rest, after the pusher lets go and the plate slides to a stop (the plan aims at that pose; the default of `plan` and `loop`). A plan is {SEGMENTS} pushes of equal duration; success is the centre of mass within 20 mm of the goal and the angle within 5°. MPC re-plans every {PERIOD} s from the engine's state until the last push ends; at rest its plant then slides with no feedback. The perturbed plant has μ × 0.8 and I_cm × 1.2; the predictor keeps the nominal values. An engine that cannot release the plate is judged at the release in its rest runs too (column `judged_at` of `runs.csv` and `success.csv`).\n\n",
        list_speeds(goal_speeds),
        list_speeds(speeds),
    ));
    // The slide of a plate released in pure translation at v under the
    // scene's supports: deceleration Σ μᵢNᵢ / m, distance v² m / (2 Σ μᵢNᵢ).
    let decel = problem.body.total_friction() / problem.body.mass();
    let slow = 0.1;
    let slide = slow * slow / (2.0 * decel);
    if !speeds.contains(&slow) {
        s.push_str(&format!(
            "{slow} m/s is not in the grid. A plate released at {slow} m/s slides about v²/(2μg) = {:.1} mm (μg = Σ μᵢNᵢ / m = {decel:.2} m/s² on this scene), {:.0} times less than the 20 mm tolerance, so the two rules judge alike there; and that speed took {OLD_SLOW_WALL_S:.0} of the {OLD_TOTAL_WALL_S:.0} s of runs ({:.0} %) of the grid that had it (28 engines judged at the release; `runs.csv` column `wall_s` of commit 32437d4).\n\n",
            slide * 1e3,
            0.02 / slide,
            100.0 * OLD_SLOW_WALL_S / OLD_TOTAL_WALL_S,
        ));
    }
    s.push_str("Files: `success.csv` (one row per engine, speed, rule, plan predictor, mode and plant), `runs.csv` (every run), `success.svg` (a panel per speed and rule), `paths.svg` (goal 0 at rest in every engine).\n\n");

    // Per engine, at rest, with the move from the release rule.
    use super::figures::COLUMNS;
    s.push_str("## Per engine, at rest\n\n");
    s.push_str("Goals reached at rest, and in brackets how that moved against the release rule: goals gained at rest (+) and lost (−), `(=)` none. dyn/kin: the plan made on the dynamic / kinematic model; open loop or MPC; nom/pert: the nominal or the perturbed plant.\n\n");
    let mut cannot: Vec<String> = Vec::new();
    for &v in speeds {
        s.push_str(&format!("### {v} m/s\n\n| engine |"));
        for col in COLUMNS.iter() {
            s.push_str(&format!(" {} |", super::figures::short(col)));
        }
        s.push_str("\n|---|");
        s.push_str(&"---|".repeat(COLUMNS.len()));
        s.push('\n');
        for n in names {
            let mark = if released(n) { "" } else { " †" };
            s.push_str(&format!("| {n}{mark} |"));
            for &(pr, m, pl) in COLUMNS.iter() {
                let (ok, tot, _, _) = get(n, v, "rest", pr, m, pl);
                let (g, l) = mv(n, v, pr, m, pl);
                s.push_str(&format!(" {ok}/{tot} {} |", moved(g, l)));
            }
            s.push('\n');
        }
        s.push('\n');
    }
    for n in names {
        if !released(n) {
            cannot.push(n.clone());
        }
    }
    if !cannot.is_empty() {
        s.push_str(&format!(
            "† cannot release the plate ({}): its rest runs are judged at the release, so its counts cannot move.\n\n",
            and_list(&cannot)
        ));
    }

    // Across engines.
    s.push_str("## At rest against the release rule, across engines\n\n");
    let able: Vec<&String> = names
        .iter()
        .filter(|n| released(n) && errors(n) * 2 < 2 * 8 * goals * speeds.len())
        .collect();
    s.push_str(&format!(
        "{} of {} engines release the plate{}.",
        able.len(),
        names.len(),
        if cannot.is_empty() {
            String::new()
        } else {
            format!(
                "; {} cannot and {} judged at the release by both rules",
                and_list(&cannot),
                if cannot.len() == 1 { "is" } else { "are" }
            )
        }
    ));
    let (mut gained, mut lost, mut pairs) = (0, 0, 0);
    for n in &able {
        for &v in speeds {
            for &(pr, m, pl) in COLUMNS.iter() {
                let (g, l) = mv(n, v, pr, m, pl);
                gained += g;
                lost += l;
                pairs += get(n, v, "rest", pr, m, pl).1;
            }
        }
    }
    if !able.is_empty() {
        s.push_str(&format!(
            " Over their {pairs} goals run by both rules (every speed, predictor, mode and plant), {gained} are reached at rest and not at the release, and {lost} at the release and not at rest."
        ));
    }
    s.push_str("\n\n");
    for &v in speeds {
        for (m, what) in [("open", "open loop"), ("mpc", "under MPC")] {
            let (mut more, mut fewer, mut same) = (Vec::new(), Vec::new(), 0);
            for n in &able {
                let (rel, tot, _, _) = get(n, v, "release", "dynamic", m, "nominal");
                let (rest, _, _, _) = get(n, v, "rest", "dynamic", m, "nominal");
                let cell = format!("{n} {rel}/{tot} → {rest}/{tot}");
                match rest.cmp(&rel) {
                    std::cmp::Ordering::Greater => more.push(cell),
                    std::cmp::Ordering::Less => fewer.push(cell),
                    std::cmp::Ordering::Equal => same += 1,
                }
            }
            if able.is_empty() {
                continue;
            }
            s.push_str(&format!(
                "- {v} m/s, the dynamic plan {what} on the nominal plant: as many goals at rest as at the release in {same} of {} engines",
                able.len()
            ));
            if !fewer.is_empty() {
                s.push_str(&format!(
                    "; fewer in {} ({})",
                    fewer.len(),
                    fewer.join(", ")
                ));
            }
            if !more.is_empty() {
                s.push_str(&format!("; more in {} ({})", more.len(), more.join(", ")));
            }
            s.push_str(".\n");
        }
    }
    s.push('\n');
    // The perturbed plant's slide: μ × 0.8 makes it 1/0.8 times as long as
    // the predictor's, which no feedback corrects once the pusher has let go.
    let mu_scale = PlantScale::PERTURBED.mu_scale;
    let extra = |v: f64| v * v / (2.0 * decel) * (1.0 / mu_scale - 1.0);
    let mut pert = Vec::new();
    for n in &able {
        let (rel, tot, _, _) = get(n, vmax, "release", "dynamic", "mpc", "perturbed");
        let (rest, _, _, _) = get(n, vmax, "rest", "dynamic", "mpc", "perturbed");
        if rel >= rest + 2 {
            pert.push(format!("{n} {rel}/{tot} → {rest}/{tot}"));
        }
    }
    if !pert.is_empty() {
        s.push_str(&format!(
            "On the perturbed plant (μ × {mu_scale}) a plate released at the pusher's speed slides 1/{mu_scale} times as far as the predictor expects: about {:.1} mm further at {vmax} m/s{}, and no feedback acts once the pusher has let go. MPC on the perturbed plant loses two or more goals at rest against the release rule at {vmax} m/s in {} of {} engines that release ({}).\n\n",
            extra(vmax) * 1e3,
            speeds
                .iter()
                .filter(|&&v| v < vmax)
                .map(|&v| format!(" ({:.1} mm at {v} m/s)", extra(v) * 1e3))
                .collect::<String>(),
            pert.len(),
            able.len(),
            pert.join(", ")
        ));
    }
    // Where the goals lost at rest (dynamic plan, open loop, nominal plant,
    // at least two at some speed) come from, from what each engine declares.
    let (mut slide, mut integ, mut push, mut nolaw) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for n in &able {
        let e = engine(n);
        let mut worst: Option<(f64, usize, usize, usize)> = None;
        for &v in speeds {
            let (rel, tot, _, _) = get(n, v, "release", "dynamic", "open", "nominal");
            let (rest, _, _, _) = get(n, v, "rest", "dynamic", "open", "nominal");
            if rel >= rest + 2 && worst.is_none_or(|w| rel - rest > w.1 - w.2) {
                worst = Some((v, rel, rest, tot));
            }
        }
        let Some((v, rel, rest, tot)) = worst else {
            continue;
        };
        let cell = format!("{n} ({rel}/{tot} at the release, {rest}/{tot} at rest at {v} m/s)");
        if coulomb(e.as_ref()) {
            integ.push(cell);
        } else if e.law().is_none() {
            nolaw.push(cell);
        } else if rel as f64 >= 0.95 * tot as f64 {
            slide.push(format!(
                "{n} ({}; {rel}/{tot} at the release, {rest}/{tot} at rest at {v} m/s)",
                e.law().map(|l| l.law_name()).unwrap_or_default()
            ));
        } else {
            push.push(cell);
        }
    }
    if slide.is_empty() && integ.is_empty() && push.is_empty() && nolaw.is_empty() {
        s.push_str("No engine that releases loses two or more goals at rest with the dynamic plan open loop on the nominal plant.\n\n");
    } else {
        s.push_str("Engines that lose two or more goals at rest with the dynamic plan open loop on the nominal plant (at their worst speed):\n\n");
        if !slide.is_empty() {
            s.push_str(&format!(
                "- the push moves the plate as the model predicts (at least 95 % of the goals at the release), so the goals are lost in the slide, and the engine declares a law other than Coulomb's, whose slide the plans aim through: {}.\n",
                slide.join("; ")
            ));
        }
        if !integ.is_empty() {
            s.push_str(&format!(
                "- the engine declares Coulomb's law, the model's, so the difference is not its law but how it integrates the push or the slide (its step, its solver): {}.\n",
                integ.join("; ")
            ));
        }
        if !push.is_empty() {
            s.push_str(&format!(
                "- the engine declares a law other than Coulomb's and misses at the release too (below 95 %): these counts do not separate its slide from its push: {}.\n",
                push.join("; ")
            ));
        }
        if !nolaw.is_empty() {
            s.push_str(&format!(
                "- the engine declares no law in closed form, so nothing here says why: {}.\n",
                nolaw.join("; ")
            ));
        }
        s.push('\n');
    }

    s.push_str(&format!(
        "## Why each engine succeeds or fails, at rest at {vmax} m/s\n\n"
    ));
    for n in names {
        let e = engine(n);
        let (ok_open, tot, pe_open, ae_open) = get(n, vmax, "rest", "dynamic", "open", "nominal");
        let (ok_mpc, _, _, _) = get(n, vmax, "rest", "dynamic", "mpc", "nominal");
        let (ok_mpc_p, _, _, _) = get(n, vmax, "rest", "dynamic", "mpc", "perturbed");
        let share = |k: usize| if tot == 0 { 0.0 } else { k as f64 / tot as f64 };
        let law = law_line(problem, e.as_ref(), vmax);
        let coulomb = coulomb(e.as_ref());
        let errors_n = errors(n);
        let mm = |v: f64| {
            if v.is_finite() {
                format!("{:.1} mm", v * 1e3)
            } else {
                "no final pose".to_string()
            }
        };
        // Every clause below is chosen by the numbers it states.
        let why = if tot == 0 {
            "no runs".to_string()
        } else if errors_n * 2 >= 2 * 8 * goals * speeds.len() {
            format!(
                "{errors_n} of its runs ended with an engine error, so its counts say nothing of its friction"
            )
        } else if share(ok_open) >= 0.95 {
            if coulomb {
                "it applies Coulomb friction at every support, the model's law, so the plan made on the dynamic model works as it is".to_string()
            } else {
                format!(
                    "the plan works as it is: on this scene its friction moves the plate as Coulomb's does{}",
                    law.as_ref().map(|l| format!(" ({l})")).unwrap_or_default()
                )
            }
        } else if share(ok_mpc) >= 0.95 {
            let cause = if coulomb {
                "its declared law is Coulomb's, the model's, so the open-loop misses come from how it integrates the scene (its step, its solver), not from its friction law".to_string()
            } else {
                law.clone().unwrap_or_else(|| {
                    "it declares no law in closed form, and its turn rate differs from the model's"
                        .into()
                })
            };
            format!(
                "open loop reaches {ok_open}/{tot} (median final error {}, the tolerance 20 mm): {cause}; feedback every {PERIOD} s corrects the drift",
                mm(pe_open)
            )
        } else {
            let cause = if coulomb {
                "its declared law is Coulomb's, the model's, so the misses come from how it integrates the scene, not from its friction law".to_string()
            } else if e.law().is_some_and(|l| l.coulomb_on_run_loads()) {
                format!(
                    "{}; its friction is Coulomb's on the loads it carries, so the misses come from those loads or from how it integrates the scene, not from the shape of its law",
                    law.clone().unwrap_or_default()
                )
            } else {
                format!(
                    "{}; a controller whose predictor has the model's law cannot steer a plate that turns otherwise",
                    law.clone()
                        .unwrap_or_else(|| "it declares no law in closed form".into())
                )
            };
            format!(
                "open loop reaches {ok_open}/{tot} (median final error {}, {:.3} rad) and MPC {ok_mpc}/{tot}: {cause}",
                mm(pe_open),
                ae_open
            )
        };
        let errors = match errors_n {
            0 => String::new(),
            k => format!(
                " {k} of its runs ended with an engine error and count as misses (`runs.csv`, column `error`; the study prints the message)."
            ),
        };
        let against = if released(n) {
            let parts: Vec<String> = speeds
                .iter()
                .map(|&v| {
                    let o = |m| {
                        let (rel, t, _, _) = get(n, v, "release", "dynamic", m, "nominal");
                        let (rest, _, _, _) = get(n, v, "rest", "dynamic", m, "nominal");
                        format!("{rel}/{t} → {rest}/{t}")
                    };
                    format!("open loop {}, MPC {} at {v} m/s", o("open"), o("mpc"))
                })
                .collect();
            format!(
                " From the release rule to the rest rule (dynamic plan, nominal plant): {}.",
                parts.join("; ")
            )
        } else {
            format!(
                " {} of its rest runs were judged at the release: it cannot release the plate.",
                c.at_release.get(n.as_str()).copied().unwrap_or(0)
            )
        };
        s.push_str(&format!(
            "- **{n}** ({ok_open}/{tot} open, {ok_mpc}/{tot} MPC, {ok_mpc_p}/{tot} MPC on the perturbed plant): {why}.{errors}{against}\n"
        ));
    }
    s.push_str("\n## The kinematic plan against speed, at rest\n\n| engine | ");
    s.push_str(
        &speeds
            .iter()
            .map(|v| format!("{v} m/s"))
            .collect::<Vec<_>>()
            .join(" | "),
    );
    s.push_str(" |\n|---|");
    s.push_str(&"---|".repeat(speeds.len()));
    s.push('\n');
    let (mut grows, mut other) = (Vec::new(), Vec::new());
    for n in names {
        s.push_str(&format!("| {n} |"));
        let mut errs = Vec::new();
        for &v in speeds {
            let (ok, tot, pe, _) = get(n, v, "rest", "kinematic", "open", "nominal");
            let cell = if pe.is_finite() {
                format!("{:.1} mm", pe * 1e3)
            } else {
                "no final pose".into()
            };
            s.push_str(&format!(" {ok}/{tot} ({cell}) |"));
            errs.push(pe);
        }
        s.push('\n');
        if errs.len() > 1 {
            if errs.windows(2).all(|w| w[1] > w[0]) {
                grows.push(n.as_str());
            } else {
                other.push(n.as_str());
            }
        }
    }
    s.push_str("\nA plan made on the quasi-static model ignores the plate's inertia, its slide included (median final position error in brackets, failed runs counted as infinite).");
    if speeds.len() > 1 {
        s.push_str(&format!(
            " The median miss grows with every step up in speed in {} of {} engines{}",
            grows.len(),
            names.len(),
            if other.is_empty() {
                ".".to_string()
            } else {
                format!("; it does not in {}.", other.join(", "))
            }
        ));
    }
    s.push('\n');
    s
}
