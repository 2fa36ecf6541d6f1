//! Every engine's cost against its accuracy. For each engine model in this
//! build (through the registry and the `Engine` trait; nothing here names an
//! engine) and each time step of a ladder, the scene of
//! `scenarios/friction-engines.toml` (the paper plate pushed at a corner,
//! 0.5 m/s, φ = π/4 + 0.3, 6 s) is run repeatedly and measured side by side
//! in one process:
//!
//! * cost: the median thread CPU time of the run, per simulated second;
//! * accuracy against the dynamic model: the relative steady-ω error (mean
//!   ω over the last 20 % of the push against the root ω*) and the largest
//!   centre-of-mass distance over the samples (m).
//!
//! Every engine model whose `[engine]` options include `friction_velocity`
//! also runs as `NAME[body]` (`friction_velocity = "body"`): its default
//! mode reads the model's contact kinematics (each support's sliding
//! velocity from the commanded contact velocity plus `ω × (p_i − p_c)`, the
//! pusher re-pinned onto the contact point every step), while `body` takes
//! the engine body's own velocities, as every other engine does: the
//! like-for-like row. The `kinematics` column says which (`model` or
//! `engine`).
//!
//! Writes `results/engine_work_precision.csv` (one row per engine, mode and
//! dt), `results/engine_work_precision.svg` and
//! `results/engine_work_precision_summary.csv`: per engine, the cheapest
//! row at ≤ 1e-3 relative steady-ω error (if any), its cost over the
//! cheapest engine's, and the exponent b of cost ∝ dt^(−b) fitted over the
//! ladder.
//!
//! `cargo bench --bench engine_work_precision` (add `-- --quick` for one
//! repeat and a shorter ladder; `-- --replot` redraws the SVG from the CSV
//! without running anything). With `--features mujoco,avian,physx` those
//! engines' rows are measured too. `-- --only A,B` measures only the named
//! rows (e.g. `rapier2d,rapier2d[body]`), and `-- --merge` keeps the
//! committed CSV's rows of every engine this run does not measure: each row
//! carries the number of the run that measured it (`run`), and the
//! summary's `# run N:` lines say what each run was, so rows measured side
//! by side are those with the same run number.

use std::time::Duration;

use pushval::harness::{analyse_segments, rel_err, tail_omega};
use pushval::outdir::{records, Csv};
use pushval::registry;
use pushval_model::{DynamicModel, Simulator};

/// The steady-ω error at which the summary names the cheapest engine.
const TARGET: f64 = 1e-3;

/// CPU time of the calling thread (`CLOCK_THREAD_CPUTIME_ID`): not inflated
/// by other processes waiting for the same cores.
fn thread_cpu_time() -> Duration {
    let ts = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// CPU time (s) process `pid` has used, user and system, from
/// `/proc/PID/stat` (fields 14 and 15, in USER_HZ ticks, which Linux's
/// /proc ABI fixes at 100 a second); None where it cannot be read.
fn process_cpu_time(pid: u64) -> Option<f64> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // Fields after the command name, which is in parentheses and may hold
    // spaces: the state is field 3, utime field 14.
    let rest = &text[text.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// The pid of the session process that served an outside engine's run.
fn session_pid(run: &pushval_engine::EngineRun) -> Option<u64> {
    run.diagnostics.get("session")?.get("pid")?.as_u64()
}

struct Row {
    engine: String,
    version: String,
    dt: f64,
    cpu_per_sim_s: f64,
    omega_rel: f64,
    position: f64,
    steps: usize,
    /// `model` when the engine reads the model's contact kinematics,
    /// `engine` when it uses its own body velocities.
    kinematics: String,
    /// The run that measured the row (1, 2, …; see the summary).
    run: u32,
    /// What the cost counts: `thread_cpu` (the engine runs in this
    /// process's thread) or `process_cpu` (an outside engine: its session
    /// process's CPU time over the run, from /proc, plus this thread's).
    clock: String,
}

/// The rows of a written `engine_work_precision.csv` (for `--replot` and
/// `--merge`); a row without a number it needs is left out.
fn read_rows(text: &str) -> Vec<Row> {
    let recs = records(text).expect("engine_work_precision.csv is CSV");
    recs.iter()
        .filter_map(|r| {
            let f = |k: &str| r.get(k).map(String::as_str);
            let engine = f("engine")?;
            Some(Row {
                engine: engine.to_string(),
                version: f("version")?.to_string(),
                dt: f("dt_s")?.parse().ok()?,
                cpu_per_sim_s: f("cpu_s_per_simulated_s")?.parse().ok()?,
                omega_rel: f("omega_steady_rel_err")?.parse().ok()?,
                position: f("position_err_m")?.parse().ok()?,
                steps: f("steps")?.parse().ok()?,
                // Columns added with the `[body]` rows; rows written before
                // them come from run 1, by engines without a
                // `friction_velocity` option (theirs is the default mode).
                kinematics: f("kinematics")
                    .map_or_else(|| default_kinematics(engine), str::to_string),
                run: f("run").and_then(|r| r.parse().ok()).unwrap_or(1),
                clock: f("clock").unwrap_or("thread_cpu").to_string(),
            })
        })
        .collect()
}

/// What a row written without a `kinematics` column reads: the registry's
/// answer when this build has the engine, else `engine` (only an engine
/// with a `friction_velocity` option reads the model's kinematics, and every
/// such engine is in the default build).
fn default_kinematics(name: &str) -> String {
    registry::entry(name).map_or("engine".into(), |e| {
        kinematics(&*e.default_engine()).to_string()
    })
}

/// `model` when the engine's settings take the sliding velocities from the
/// model's contact kinematics (a `friction_velocity` mode other than
/// `body`), else `engine`.
fn kinematics(engine: &dyn pushval_engine::Engine) -> &'static str {
    let settings = engine.settings(engine.default_dt());
    match settings.get("friction_velocity").and_then(|v| v.as_str()) {
        Some(mode) if mode != "body" => "model",
        _ => "engine",
    }
}

/// The value after `flag` on the command line.
fn arg_value(flag: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == flag)
        .and_then(|i| args.get(i + 1).cloned())
}

/// The engine models this build runs: each registry entry, and `NAME[body]`
/// for each whose options include `friction_velocity`.
fn variants() -> Vec<(String, Box<dyn pushval_engine::Engine>)> {
    let mut out = Vec::new();
    for entry in registry::entries() {
        let engine = entry.build(&Default::default()).expect("default options");
        if let Err(why) = engine.availability() {
            eprintln!("{}: skipped ({why})", entry.name);
            continue;
        }
        let body = engine.option_keys().contains(&"friction_velocity");
        out.push((entry.name.to_string(), engine));
        if body {
            let mut opts = pushval_engine::EngineOptions::default();
            opts.values
                .insert("friction_velocity".into(), serde_json::json!("body"));
            let e = entry
                .build(&opts)
                .expect("body is a friction_velocity mode");
            out.push((format!("{}[body]", entry.name), e));
        }
    }
    out
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let merge = std::env::args().any(|a| a == "--merge");
    let only: Option<Vec<String>> =
        arg_value("--only").map(|l| l.split(',').map(|s| s.trim().to_string()).collect());
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    if std::env::args().any(|a| a == "--replot") {
        let csv = root.join("results/engine_work_precision.csv");
        let rows = read_rows(&std::fs::read_to_string(&csv).expect("read the CSV"));
        let mut names: Vec<&str> = rows.iter().map(|r| r.engine.as_str()).collect();
        names.dedup();
        pushval::atomic::write_atomic(
            &root.join("results/engine_work_precision.svg"),
            figure(&rows, &names).as_bytes(),
        )
        .expect("write svg");
        return;
    }
    // The outside engines of the repository's pushval.toml (those whose
    // adapters are installed) are measured too, by wall time.
    registry::use_engines_file(Some(&root.join("pushval.toml"))).expect("pushval.toml loads");
    let sc = registry::load(root.join("scenarios/friction-engines.toml")).expect("scenario loads");
    let problem = sc.problem();
    let duration = problem.duration();
    let reference = DynamicModel::default()
        .simulate(&problem)
        .expect("model runs");
    let segments = analyse_segments(&sc, &problem, &reference);
    let seg = &segments[0];
    let w_star = seg.omega_steady.expect("the push settles").omega;
    let ladder: Vec<f64> = if quick {
        vec![1.0 / 60.0, 1.0 / 240.0]
    } else {
        vec![
            1.0 / 60.0,
            1.0 / 120.0,
            1.0 / 240.0,
            1.0 / 480.0,
            1.0 / 960.0,
            1.0 / 1920.0,
        ]
    };
    let repeats = if quick { 1 } else { 5 };
    let out = root.join("results");
    let csv_path = out.join("engine_work_precision.csv");
    let summary_path = out.join("engine_work_precision_summary.csv");
    // With --merge: the committed rows, and the run descriptions.
    let (old_rows, mut runs) = if merge {
        let rows =
            read_rows(&std::fs::read_to_string(&csv_path).expect("read the CSV to merge into"));
        let mut runs: Vec<String> = std::fs::read_to_string(&summary_path)
            .unwrap_or_default()
            .lines()
            .filter(|l| l.starts_with("# run "))
            .map(str::to_string)
            .collect();
        if runs.is_empty() {
            runs.push(
                "# run 1: `cargo bench --features mujoco,avian,physx --bench engine_work_precision` (every engine model, side by side)"
                    .to_string(),
            );
        }
        (rows, runs)
    } else {
        (Vec::new(), Vec::new())
    };
    let run = old_rows.iter().map(|r| r.run).max().unwrap_or(0) + 1;
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    runs.push(format!(
        "# run {run}: `cargo bench --bench engine_work_precision{}{}` (these rows side by side)",
        if args.is_empty() { "" } else { " -- " },
        args.join(" ")
    ));
    let mut rows = Vec::new();
    for (name, engine) in variants() {
        if only.as_ref().is_some_and(|o| !o.contains(&name)) {
            continue;
        }
        let outside = engine.adapter().starts_with("outside");
        for &dt in &ladder {
            let mut times = Vec::new();
            let mut last = None;
            // An outside engine's session starts on its first run: one run
            // ahead, untimed, which names the session's process.
            let pid = if outside {
                engine.run(&problem, dt).ok().as_ref().and_then(session_pid)
            } else {
                None
            };
            for _ in 0..repeats {
                let t0 = thread_cpu_time();
                let c0 = pid.and_then(process_cpu_time);
                let r = engine.run(&problem, dt);
                let own = (thread_cpu_time() - t0).as_secs_f64();
                // Counted only when the same session served the run.
                let same = r.as_ref().ok().and_then(session_pid) == pid;
                let child = match (c0, pid.and_then(process_cpu_time)) {
                    (Some(a), Some(b)) if same => b - a,
                    _ => f64::NAN,
                };
                times.push(if outside { own + child } else { own });
                last = Some(r);
            }
            let result = match last.expect("ran") {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("{name} at dt = {dt:.3e}: {e}");
                    continue;
                }
            };
            times.sort_by(f64::total_cmp);
            let tr = &result.trajectory;
            let w = tail_omega(tr, seg.t_start, seg.t_end).unwrap_or(f64::NAN);
            let position = tr
                .samples
                .iter()
                .zip(&reference.samples)
                .map(|(p, q)| ((p.x - q.x).powi(2) + (p.y - q.y).powi(2)).sqrt())
                .fold(0.0, f64::max);
            let row = Row {
                engine: name.clone(),
                version: engine.version(),
                dt,
                cpu_per_sim_s: times[times.len() / 2] / duration,
                omega_rel: rel_err(w, w_star, seg.speed, sc.froude_length()),
                position,
                steps: result.steps,
                kinematics: kinematics(&*engine).to_string(),
                run,
                clock: if outside { "process_cpu" } else { "thread_cpu" }.to_string(),
            };
            eprintln!(
                "{:28} dt {:.3e}  {:.3e} s/s  omega {:.2e}  position {:.2e} m",
                row.engine, row.dt, row.cpu_per_sim_s, row.omega_rel, row.position
            );
            rows.push(row);
        }
    }
    if quick {
        return;
    }
    let rows = if merge { merged(old_rows, rows) } else { rows };
    let mut csv = Csv::new(&[
        "engine",
        "version",
        "dt_s",
        "cpu_s_per_simulated_s",
        "omega_steady_rel_err",
        "position_err_m",
        "steps",
        "kinematics",
        "run",
        "clock",
    ]);
    for r in &rows {
        csv.row(&[
            r.engine.clone(),
            r.version.clone(),
            format!("{:.6e}", r.dt),
            format!("{:.4e}", r.cpu_per_sim_s),
            format!("{:.4e}", r.omega_rel),
            format!("{:.4e}", r.position),
            r.steps.to_string(),
            r.kinematics.clone(),
            r.run.to_string(),
            r.clock.clone(),
        ]);
    }
    let mut names: Vec<&str> = rows.iter().map(|r| r.engine.as_str()).collect();
    names.dedup();
    let cheapest = rows
        .iter()
        .filter(|r| r.omega_rel <= TARGET)
        .min_by(|a, b| a.cpu_per_sim_s.total_cmp(&b.cpu_per_sim_s));
    let mut table = Csv::new(&[
        "engine",
        "kinematics",
        "run",
        "cheapest_dt_at_1e-3_s",
        "cheapest_cpu_s_per_simulated_s_at_1e-3",
        "cpu_ratio_to_cheapest",
        "cost_exponent_b",
    ]);
    for name in &names {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.engine == *name).collect();
        let best = mine
            .iter()
            .filter(|r| r.omega_rel <= TARGET)
            .min_by(|a, b| a.cpu_per_sim_s.total_cmp(&b.cpu_per_sim_s));
        // Least-squares slope of ln(cost) against ln(1/dt).
        let pts: Vec<(f64, f64)> = mine
            .iter()
            .map(|r| ((1.0 / r.dt).ln(), r.cpu_per_sim_s.ln()))
            .collect();
        let n = pts.len() as f64;
        let (mx, my) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let b = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
            / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
        let first = mine[0];
        table.row(&[
            name.to_string(),
            first.kinematics.clone(),
            first.run.to_string(),
            best.map_or("".into(), |r| format!("{:.6e}", r.dt)),
            best.map_or("".into(), |r| format!("{:.4e}", r.cpu_per_sim_s)),
            best.zip(cheapest).map_or("".into(), |(r, c)| {
                format!("{:.1}", r.cpu_per_sim_s / c.cpu_per_sim_s)
            }),
            format!("{b:.3}"),
        ]);
    }
    // The rows, then `#` comment lines: what the columns mean, the runs.
    let mut summary = table.text().to_string();
    summary.push_str(
        "# kinematics: model = the engine reads the model's contact kinematics (support velocities from the commanded \
         contact velocity plus omega x (p_i - p_c), pusher re-pinned onto the contact point), engine = its own body velocities\n",
    );
    for line in &runs {
        summary.push_str(line);
        summary.push('\n');
    }
    if let Some(best) = cheapest {
        summary.push_str(&format!(
            "# cheapest at {TARGET:e} relative steady-omega error: {} at dt = {:.4e} s, {:.4e} s CPU per simulated second (run {})\n",
            best.engine, best.dt, best.cpu_per_sim_s, best.run
        ));
    }
    pushval::atomic::write_atomic(&csv_path, csv.as_bytes()).expect("write csv");
    pushval::atomic::write_atomic(&summary_path, summary.as_bytes()).expect("write summary");
    pushval::atomic::write_atomic(
        &out.join("engine_work_precision.svg"),
        figure(&rows, &names).as_bytes(),
    )
    .expect("write svg");
    print!("{summary}");
}

/// The committed rows with this run's in place of the same engines' (a new
/// `NAME[mode]` right after `NAME`'s rows), in the committed order.
fn merged(old: Vec<Row>, new: Vec<Row>) -> Vec<Row> {
    let measured: Vec<String> = new.iter().map(|r| r.engine.clone()).collect();
    let mut out: Vec<Row> = Vec::new();
    let mut new = new;
    for r in old {
        if measured.contains(&r.engine) {
            // Replaced: this run's rows of the engine go where its first was.
            let mine: Vec<Row>;
            (mine, new) = new.into_iter().partition(|n| n.engine == r.engine);
            out.extend(mine);
        } else {
            out.push(r);
        }
    }
    for r in new {
        let base = r.engine.split('[').next().unwrap_or("").to_string();
        let at = out
            .iter()
            .rposition(|o| {
                o.engine == r.engine || o.engine.split('[').next() == Some(base.as_str())
            })
            .map_or(out.len(), |i| i + 1);
        out.insert(at, r);
    }
    out
}

/// Log–log figure: steady-ω error (left) and position error (right)
/// against CPU time per simulated second, one line per engine model.
fn figure(rows: &[Row], names: &[&str]) -> String {
    use pushval::plot::{family_styles, Axis, Figure, Legend, Panel, Series, Stroke, GREY};
    // One colour per engine family, its members by dash or marker.
    let styles = family_styles(names);
    let panel = |title: &str, ylabel: &str, pick: &dyn Fn(&Row) -> f64, target: Option<f64>| {
        let mut p = Panel::new(
            title,
            Axis::log("CPU time per simulated second (s/s)"),
            Axis::log(ylabel),
        )
        .legend(Legend::Outside);
        for (k, name) in names.iter().enumerate() {
            let mut pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.engine == *name)
                .map(|r| (r.cpu_per_sim_s, pick(r).max(1e-12)))
                .filter(|p| p.1.is_finite())
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (color, stroke) = styles[k];
            p = p.series(Series::new(*name, color, stroke).points(pts));
        }
        if let Some(t) = target {
            // The summary's target, across the cost range of the data.
            let xs = rows.iter().map(|r| r.cpu_per_sim_s).filter(|x| *x > 0.0);
            let (lo, hi) = xs.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
            if lo < hi {
                p = p.series(
                    Series::new(format!("target {t:.0e}"), GREY, Stroke::Dashed)
                        .points(vec![(lo, t), (hi, t)]),
                );
            }
        }
        p
    };
    let fig = Figure {
        size: (1700, 720),
        cols: 2,
        panels: vec![
            panel(
                "Engines: steady-ω error against cost (paper plate, 0.5 m/s, 6 s)",
                "relative steady-ω error vs the dynamic model",
                &|r| r.omega_rel,
                Some(TARGET),
            ),
            panel(
                "Engines: position error against cost",
                "max CM position error vs the dynamic model (m)",
                &|r| r.position,
                None,
            ),
        ],
        key: None,
    };
    pushval::plot::render(&fig).expect("figure renders")
}
