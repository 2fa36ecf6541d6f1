//! The pushval command line.
//!
//! Exit codes: 0 every gated tolerance holds, 1 a tolerance failed, 2 unusable
//! input or an error (nothing is written then), 141 the reader of standard
//! output went away before pushval finished printing (see [`closed`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use clap::{Parser, Subcommand};
use pushval::{output, run_scenario, RunOptions, ScenarioReport};
use pushval_scenario::Scenario;

#[derive(Parser)]
#[command(
    name = "pushval",
    version,
    about = "Cross-validates an analytic model of single-point pushing against physics engines.\n\nWith no command: validate every scenario of the project (the scenarios/ folder beside the pushval.toml in use, else ./scenarios, else the scenarios shipped inside pushval)."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Outside engines: the pushval.toml-format file declaring them (default:
    /// the pushval.toml of the current folder, else of its nearest parent
    /// folder that has one; none when no folder up to the root has one).
    /// Trusted like a build script: its commands run.
    #[arg(long, global = true, value_name = "FILE")]
    engines: Option<PathBuf>,
}

#[derive(Subcommand)]
enum Command {
    /// Run every model of the given scenarios, compare them with the dynamic
    /// model and print a table; exit 1 when a gated tolerance fails.
    Validate {
        /// Scenario files (TOML; default: every *.toml of the project's
        /// scenarios/ beside the pushval.toml in use, else of ./scenarios,
        /// else the scenarios shipped inside pushval).
        files: Vec<PathBuf>,
        /// Print the table as JSON instead (one summary.json document per scenario).
        #[arg(long)]
        json: bool,
        /// Also write a JUnit XML report to this file (for CI systems);
        /// default: none.
        #[arg(long, value_name = "FILE")]
        junit: Option<PathBuf>,
        /// Refuse (exit 2) any [tolerance] number above the default auto
        /// ceiling whose file gives no `reason` (for CI that runs scenarios
        /// it did not write).
        #[arg(long)]
        deny_loose: bool,
    },
    /// Measure an outside trajectory (trajectory.csv columns) against the
    /// dynamic model and rapier2d with the scenario's tolerances; exit 1 when
    /// one fails.
    Compare {
        /// The scenario file (TOML).
        file: PathBuf,
        /// The outside trajectory (t,x,y,theta; omega, model optional) on the scenario's time grid.
        #[arg(long, value_name = "CSV")]
        trajectory: PathBuf,
        /// Which run of the CSV's `model` column (default: the only one).
        #[arg(long, value_name = "NAME")]
        model: Option<String>,
    },
    /// Sweep dt, speed, friction, supports, aspect ratio and horizon for the
    /// adaptive integrator, RK4 and rapier2d; write DIR/stress.csv and
    /// DIR/stability.csv (ok / degraded / unstable per case).
    Stress {
        /// Output folder (created if missing).
        #[arg(long, default_value = "results/stress")]
        out: PathBuf,
        /// Run the small test grid instead of the full one.
        #[arg(long)]
        quick: bool,
    },
    /// Regenerate the figures (SVG), their data (CSV) and README.md in OUT.
    Report {
        /// Output folder (created if missing).
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Reduced sweep grids (for tests).
        #[arg(long)]
        quick: bool,
        /// Compute only part K of N of the sweeps into OUT/parts/ (batch
        /// schedulers); default: every sweep, no parts.
        #[arg(long, value_name = "K/N", conflicts_with = "merge")]
        shard: Option<pushval::shard::Shard>,
        /// Build the outputs from the parts in OUT/parts/ instead of computing the sweeps.
        #[arg(long)]
        merge: bool,
    },
    /// One engine model's friction against Coulomb and against the engine's
    /// own law in closed form: results/friction_models/MODEL/ (or --out DIR).
    Study {
        /// A model of `pushval engines`, or all (every model of this build,
        /// each into OUT/MODEL/, and OUT/README.md).
        name: String,
        /// Output folder (created if missing); default
        /// results/friction_models/MODEL (for all: results/friction_models).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Reduced grids (for tests): a 5-by-5 map of the base setup only
        /// (no variant's map), the study file's quick ladder, one fit
        /// schedule.
        #[arg(long)]
        quick: bool,
        /// Compute only part K of N of the tasks (K/N contiguous, hash:K/N by
        /// each task's key) into parts/; default: a Slurm array task
        /// (SLURM_ARRAY_TASK_ID/COUNT) computes its own part, any other run
        /// every task.
        #[arg(long, value_name = "[hash:]K/N", conflicts_with = "merge")]
        shard: Option<pushval::shard::Shard>,
        /// Build the outputs from the part files instead of running the engines.
        #[arg(long)]
        merge: bool,
        /// Folder of the study files (MODEL.toml); default ./studies when it
        /// exists, else the study files shipped inside pushval.
        #[arg(long, value_name = "DIR")]
        studies: Option<PathBuf>,
    },
    /// List every engine model: crate, engine version, order, whether it can
    /// be gated and whether this build has it.
    Engines,
    /// List every friction law in closed form: its name, the engines that
    /// declare it, its parameters with defaults, where its loads come from.
    Laws {
        /// Print the catalogue as JSON instead.
        #[arg(long)]
        json: bool,
    },
    /// Estimate parameters of the scenario (μ scale, I_cm, centre of
    /// friction, contact offset) from a trajectory by Levenberg–Marquardt;
    /// write DIR/fit.json. Exit 1 when the fit does not converge or a
    /// parameter is unidentifiable.
    Fit {
        /// The scenario file (TOML).
        file: PathBuf,
        /// The trajectory (t,x,y,theta; omega, model optional) on the scenario's time grid.
        #[arg(long, value_name = "CSV")]
        trajectory: PathBuf,
        /// What to estimate: mu_scale, inertia_cm, center_of_friction, contact.
        #[arg(long, value_name = "NAME[,NAME...]")]
        params: String,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Which run of the CSV's `model` column (default: the only one).
        #[arg(long, value_name = "NAME")]
        model: Option<String>,
        /// Noise level of x and y (m): weighs the position residuals.
        #[arg(long, default_value_t = 1e-3, value_name = "M")]
        sigma_position: f64,
        /// Noise level of theta (rad): weighs the angle residuals.
        #[arg(long, default_value_t = 1e-3, value_name = "RAD")]
        sigma_theta: f64,
    },
    /// How well a push determines μ, I_cm and the centre of friction (Fisher
    /// information, checked by repeated noisy fits); write
    /// OUT/identifiability.{csv,svg} and OUT/fit.md.
    FitStudy {
        /// Output folder (created if missing).
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Reduced grids (for tests).
        #[arg(long)]
        quick: bool,
    },
    /// Estimate μ scale, the centre of friction and I_cm online, sample by
    /// sample (`--trajectory -`: from standard input as rows arrive, each
    /// estimate printed as it is made), and the resultant friction force;
    /// write DIR/track.csv and DIR/track.json. Exit 1 when an estimate does
    /// not converge or the model does not explain the data.
    Track {
        /// The scenario file (TOML).
        file: PathBuf,
        /// The trajectory (t,x,y,theta; omega, model, fx, fy optional), or `-` for standard input.
        #[arg(long, value_name = "CSV|-")]
        trajectory: PathBuf,
        /// What to estimate: mu_scale, center_of_friction, inertia_cm.
        #[arg(
            long,
            value_name = "NAME[,NAME...]",
            default_value = "mu_scale,center_of_friction,inertia_cm"
        )]
        params: String,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Which run of the CSV's `model` column (default: the only one).
        #[arg(long, value_name = "NAME")]
        model: Option<String>,
        /// Noise level of x and y (m).
        #[arg(long, default_value_t = 1e-3, value_name = "M")]
        sigma_position: f64,
        /// Noise level of theta (rad).
        #[arg(long, default_value_t = 1e-3, value_name = "RAD")]
        sigma_theta: f64,
        /// Use the omega column as a measurement with this noise level
        /// (rad/s); default: the omega column is not used.
        #[arg(long, value_name = "RAD/S")]
        sigma_omega: Option<f64>,
        /// Noise level of each pusher force component when the CSV has fx, fy (N).
        #[arg(long, default_value_t = 0.05, value_name = "N")]
        sigma_force: f64,
    },
    /// Measure online friction estimation (cost per update, convergence
    /// against noise and sample rate, efficiency against the Cramér–Rao
    /// bound, a μ step, every engine tracked); write OUT/track_*.csv,
    /// OUT/track.svg and OUT/track.md.
    TrackStudy {
        /// Output folder (created if missing).
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Reduced grids (for tests).
        #[arg(long)]
        quick: bool,
    },
    /// Throw the plate on a grid of throws (speed, spin, direction) in every
    /// engine of the build that can let go, and measure where and when each
    /// comes to rest against the dynamic model, at its default step and at
    /// half of it; write OUT/throws.csv, OUT/engines.csv, OUT/rest.svg and
    /// OUT/README.md.
    SlideStudy {
        /// Output folder (replaced whole when the study succeeds).
        #[arg(long, default_value = "results/slide")]
        out: PathBuf,
        /// Reduced grid (for tests): 1 speed, 2 spins, 2 directions.
        #[arg(long)]
        quick: bool,
    },
    /// Measure the gate's power: the smallest model error of each kind the
    /// gate of every scenario in scenarios/ (and `compare`) catches, for the
    /// engines those scenarios gate (a project's own, from the pushval.toml
    /// found or named by --engines); write OUT/gate_power.{csv,svg}. Exit 1
    /// when nothing could be measured.
    Power {
        /// Output folder (created if missing).
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// One scenario (the paper's where scenarios/ has it, else the first
        /// that gates an engine), coarser bisection.
        #[arg(long)]
        quick: bool,
        /// Draw OUT/gate_power.svg again from OUT/gate_power.csv (nothing
        /// measured).
        #[arg(long, conflicts_with = "quick")]
        replot: bool,
    },
    /// Print the pushval-problem JSON document an outside engine receives
    /// for this scenario (its JSON schema, pushval-problem-1.schema.json or
    /// -2 with --protocol 2, is one of those `pushval shipped` writes).
    Problem {
        /// The scenario file (TOML).
        file: PathBuf,
        /// The time step written into the document (s); default the
        /// scenario's [engine] dt, else 1e-3.
        #[arg(long, value_name = "H")]
        dt: Option<f64>,
        /// The engine name written into the document; default the
        /// scenario's first gated engine.
        #[arg(long, value_name = "NAME")]
        engine: Option<String>,
        /// The protocol version of the document: 1, or 2 (adds the
        /// switching rule and the output limits).
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
        protocol: u8,
    },
    /// Start a project in the current folder that gates your own engine:
    /// pushval.toml (one Python engine), adapter.py (written with the
    /// adapter kit pushval.adapter, Coulomb forces per support) and
    /// scenarios/my_engine.toml; `pushval` right after gates it.
    Init {
        /// Overwrite files that exist.
        #[arg(long)]
        force: bool,
    },
    /// Write what pushval ships inside its binary (the scenarios, the study
    /// files and the protocol's JSON schemas) into OUT/scenarios,
    /// OUT/studies and OUT/schemas, to read or to start from.
    Shipped {
        /// Output folder (created if missing).
        #[arg(long, default_value = ".")]
        out: PathBuf,
        /// Overwrite files that exist.
        #[arg(long)]
        force: bool,
    },
    /// Write results/MANIFEST.csv: every file of results/ and the one
    /// command that regenerates it, from the rules built into pushval (for
    /// pushval's own repository).
    Manifest {
        /// Write nothing; exit 1 listing every difference between the
        /// committed MANIFEST.csv and the rules, every file no rule matches
        /// and every file two rules match.
        #[arg(long)]
        check: bool,
        /// The repository root (the folder holding results/).
        #[arg(long, default_value = ".", value_name = "DIR")]
        root: PathBuf,
    },
    /// Run one scenario and write DIR/summary.json and DIR/trajectory.csv.
    Run {
        /// The scenario file (TOML).
        file: PathBuf,
        /// Output folder (created if missing).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
    /// A push schedule that takes the object from the scenario's start to a
    /// goal pose on a model: DIR/plan.toml (a scenario: `run`, `validate`
    /// and `study` take it) and DIR/plan.json (errors, solve time, what the
    /// search tried, the model's assumption checks along the plan, each
    /// switch's impulse against the contact's friction cone). Exit 1 when
    /// no plan reaches the goal (then no plan.toml; the nearest pose and
    /// why are printed), 2 when the goal or speed is out of range.
    Plan {
        /// The scenario file: the plate, its supports, the contact and the
        /// start (its pushes are replaced by the plan's).
        #[arg(value_name = "FILE")]
        file: PathBuf,
        #[command(flatten)]
        goal: GoalArgs,
    },
    /// Model-predictive control: every period, re-plan from the engine's
    /// measured state (pose, ω, the centre of mass's velocity) and apply
    /// the next period in the engine. Writes DIR/trajectory.csv (with the
    /// applied push), DIR/loop.json and DIR/applied.toml (the scenario the
    /// plant ran: `pushval run` on it reproduces the plant's trajectory).
    /// Exit 1 on a miss.
    Loop {
        /// The scenario file: the plate, its supports, the contact, the
        /// start and the engine settings (its pushes are not used).
        #[arg(value_name = "FILE")]
        file: PathBuf,
        #[command(flatten)]
        goal: GoalArgs,
        /// The plant: an engine of `pushval engines`.
        #[arg(long, value_name = "NAME")]
        engine: String,
        /// Control period (s): rounded to whole steps of the plant, and at
        /// least one step.
        #[arg(
            long,
            default_value_t = 0.02,
            value_name = "S",
            allow_negative_numbers = true
        )]
        period: f64,
        /// The plant's scene when it differs from FILE's:
        /// mu_scale=A,inertia_scale=B scales FILE's, or a scenario file
        /// gives its own object and supports (positions, mu, loads, mass,
        /// I_cm; its outline, contact and centre of mass must equal FILE's)
        /// [default: FILE's scene].
        #[arg(long, value_name = "mu_scale=A,inertia_scale=B|FILE")]
        plant: Option<String>,
        /// Adaptive MPC: every period estimate the plate's friction
        /// (mu_scale, centre of friction, I_cm) from the readings and the
        /// pushes applied, and plan on the estimate; writes
        /// DIR/estimate.csv.
        #[arg(long)]
        adapt: bool,
        /// What the controller reads the plant through: seeded Gaussian
        /// noise and a delay, keys sigma_position=M, sigma_theta=RAD,
        /// sigma_omega=RAD_S, sigma_velocity=M_S, latency=S, seed=N (each
        /// optional) [default: exact and immediate].
        #[arg(long, value_name = "KEY=VALUE,...")]
        sensor: Option<String>,
    },
    /// Plans and MPC in every engine of the build and of the project:
    /// goals x speeds x engines x plan predictor x open loop or MPC x
    /// nominal or perturbed plant; writes results/closed_loop/.
    ControlStudy {
        /// Output folder (created if missing) [default: results/closed_loop,
        /// with --adaptive results/closed_loop/adaptive].
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// The adaptive study: plants that move or split the friction,
        /// driven open loop, by MPC, by adaptive MPC and by the oracle
        /// (MPC on the plant's true scene), exact and noisy sensors, judged
        /// at the release and at rest, 0.5 and 1 m/s.
        #[arg(long)]
        adaptive: bool,
        /// A few goals, one speed (for CI).
        #[arg(long)]
        quick: bool,
        /// Compute only part K of N of the runs into parts/.
        #[arg(long, value_name = "[hash:]K/N", conflicts_with = "merge")]
        shard: Option<pushval::shard::Shard>,
        /// Build the outputs from the part files.
        #[arg(long)]
        merge: bool,
        /// Only these engines (comma-separated; default every available one).
        #[arg(long = "only", value_name = "NAME[,NAME...]")]
        only: Option<String>,
    },
}

/// The goal and the plan's shape.
#[derive(clap::Args)]
struct GoalArgs {
    /// The goal: the centre of mass's world position and the angle (m, m, rad).
    #[arg(long, value_name = "X,Y,THETA", allow_hyphen_values = true)]
    goal: String,
    /// Pusher speed (m/s), 0.001 to 20 [default: the file's first push speed].
    #[arg(long, value_name = "V", allow_negative_numbers = true)]
    speed: Option<f64>,
    /// Number of pushes of equal duration (1 to 12); when no plan of this
    /// many reaches the goal, the search tries more, up to 12.
    #[arg(long, default_value_t = 6, value_name = "N")]
    segments: usize,
    /// The model the plan is made on: dynamic, kinematic or limit_surface.
    #[arg(long, default_value = "dynamic", value_name = "MODEL")]
    predictor: String,
    /// Success: final position and angle within POS (m) and ANGLE (rad)
    /// [default: 0.02,0.0872664626 (20 mm, 5°)].
    #[arg(long, value_name = "POS,ANGLE")]
    tolerance: Option<String>,
    /// When success is judged: `rest` (the pusher lets go after the last
    /// push and the plate slides to a stop; the plan aims for that pose) or
    /// `release` (when the last push ends, the plate still moving).
    #[arg(long, default_value = "rest", value_name = "RULE")]
    at: String,
    /// Output folder: written whole into a fresh folder and renamed into
    /// place (what was there before is replaced).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

impl GoalArgs {
    fn common(self, file: PathBuf) -> pushval::control::cli::Common {
        pushval::control::cli::Common {
            file,
            goal: self.goal,
            speed: self.speed,
            segments: self.segments,
            predictor: self.predictor,
            tolerance: self.tolerance,
            at: self.at,
            out: self.out,
        }
    }
}

/// The scenarios the main job validates when no file is named: every
/// `*.toml` of the project's `scenarios/` (beside the `pushval.toml` in use),
/// else of `./scenarios`, else the shipped ones. Shipped scenarios that name
/// a model this registry lacks (an outside engine of pushval's own
/// repository) are skipped with a note.
fn default_scenarios() -> anyhow::Result<Vec<Scenario>> {
    let dirs = [
        pushval::registry::project_dir().map(|d| d.join("scenarios")),
        Some(PathBuf::from("scenarios")),
    ];
    if let Some(dir) = dirs.into_iter().flatten().find(|d| d.is_dir()) {
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .with_context(|| format!("reading {}", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        files.sort();
        if files.is_empty() {
            bail!("no scenario files in {}", dir.display());
        }
        return load_all(&files);
    }
    let mut out = Vec::new();
    for (name, text) in pushval::shipped::SCENARIOS {
        let label = pushval::shipped::label("scenarios", name);
        let raw = Scenario::from_toml(text, &label)?;
        let missing: Vec<&String> = raw
            .models
            .iter()
            .chain(&raw.gate)
            .filter(|m| {
                !pushval_scenario::ANALYTIC_MODELS.contains(&m.as_str())
                    && pushval::registry::entry(m).is_none()
            })
            .collect();
        if let Some(m) = missing.first() {
            eprintln!(
                "note: skipping {}: model `{m}` is not in this registry ({})",
                label.display(),
                pushval::registry::engines_file()
            );
            continue;
        }
        out.push(pushval::registry::from_toml(text, &label)?);
    }
    Ok(out)
}

/// Loads every file first, so that unusable input stops the run before any work.
fn load_all(files: &[PathBuf]) -> anyhow::Result<Vec<Scenario>> {
    files
        .iter()
        .map(|f| pushval::registry::load(f).map_err(anyhow::Error::from))
        .collect()
}

fn validate(
    files: Vec<PathBuf>,
    as_json: bool,
    junit: Option<PathBuf>,
    deny_loose: bool,
) -> anyhow::Result<ExitCode> {
    let scenarios = if files.is_empty() {
        default_scenarios()?
    } else {
        load_all(&files)?
    };
    if deny_loose {
        for sc in scenarios.iter().filter(|sc| sc.tolerance.reason.is_none()) {
            if let Some(l) = sc.tolerance.loosened().first() {
                bail!(
                    "{}: key `{}`: {} is above the default auto ceiling {} and the file gives no [tolerance] reason (--deny-loose)",
                    sc.path.display(),
                    l.key,
                    l.value,
                    l.ceiling
                );
            }
        }
    }
    let opts = RunOptions::default();
    // Scenarios are independent: run them side by side (rayon keeps the
    // order of the table; outside engines share the session pool).
    use rayon::prelude::*;
    let reports: Vec<ScenarioReport> = scenarios
        .par_iter()
        .map(|sc| {
            run_scenario(sc, &opts)
                .with_context(|| format!("{}: running the models", sc.path.display()))
        })
        .collect::<anyhow::Result<_>>()?;
    if let Some(path) = &junit {
        pushval::atomic::write_atomic(path, output::junit(&reports).as_bytes())?;
    }
    if as_json {
        let rows: Vec<serde_json::Value> = reports.iter().map(output::summary).collect();
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        print!("{}", output::table(&reports));
    }
    let failed: Vec<String> = reports
        .iter()
        .flat_map(|r| {
            r.comparisons
                .iter()
                .filter(|c| c.pass == Some(false))
                .map(move |c| format!("{} / {}: {}", r.scenario.name, c.model, c.failed.join("; ")))
        })
        .collect();
    if failed.is_empty() {
        if !as_json {
            println!("\n{} scenarios: every gated tolerance holds", reports.len());
        }
        Ok(ExitCode::SUCCESS)
    } else {
        for f in &failed {
            eprintln!("FAIL {f}");
        }
        Ok(ExitCode::from(1))
    }
}

fn run(file: PathBuf, out: PathBuf) -> anyhow::Result<ExitCode> {
    let sc = pushval::registry::load(&file)?;
    let report = run_scenario(&sc, &RunOptions::default())
        .with_context(|| format!("{}: running the models", file.display()))?;
    let summary = serde_json::to_string_pretty(&output::summary(&report))?;
    let csv = output::trajectory_csv(&report);
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    pushval::atomic::write_atomic(&out.join("trajectory.csv"), csv.as_bytes())?;
    pushval::atomic::write_atomic(&out.join("summary.json"), summary.as_bytes())?;
    print!("{}", output::table(std::slice::from_ref(&report)));
    println!(
        "wrote {} and {}",
        out.join("summary.json").display(),
        out.join("trajectory.csv").display()
    );
    Ok(if report.pass() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn compare(file: PathBuf, csv: PathBuf, model: Option<String>) -> anyhow::Result<ExitCode> {
    let sc = pushval::registry::load(&file)?;
    let outside = pushval::compare::read_trajectory(&csv, model.as_deref())?;
    let (mut report, comparisons) = pushval::compare::compare_outside(&sc, &outside)?;
    report.comparisons = comparisons;
    print!("{}", output::table(std::slice::from_ref(&report)));
    if let Some(note) = outside.omega_note() {
        println!("{note}");
    }
    let failed: Vec<_> = report
        .comparisons
        .iter()
        .filter(|c| c.pass == Some(false))
        .collect();
    for c in &failed {
        eprintln!("FAIL {} / {}: {}", sc.name, c.model, c.failed.join("; "));
    }
    Ok(if failed.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn problem(
    file: PathBuf,
    dt: Option<f64>,
    engine: Option<String>,
    protocol: u8,
) -> anyhow::Result<ExitCode> {
    let sc = pushval::registry::load(&file)?;
    let dt = dt
        .or(sc.engine.dt)
        .unwrap_or(pushval::registry::OUTSIDE_DEFAULT_DT);
    if !(dt.is_finite() && dt > 0.0) {
        bail!("--dt must be a finite number > 0, got {dt}");
    }
    let engine = engine
        .or_else(|| sc.gate.first().cloned())
        .unwrap_or_default();
    let problem = sc.problem();
    let options = pushval::registry::engine_options(&sc);
    let doc = if protocol == 2 {
        let limits = pushval::registry::Limits::for_problem(&problem, dt);
        pushval::registry::problem_document_v2(&engine, &problem, &options, dt, limits)
    } else {
        pushval::registry::problem_document(&engine, &problem, &options, dt)
    };
    println!("{}", serde_json::to_string_pretty(&doc)?);
    Ok(ExitCode::SUCCESS)
}

fn stress(out: PathBuf, quick: bool) -> anyhow::Result<ExitCode> {
    let cases = if quick {
        pushval::stress::quick_grid()
    } else {
        pushval::stress::full_grid()
    };
    let start = std::time::Instant::now();
    let (outcomes, limits) = pushval::stress::write_sweep(&cases, &out)?;
    print!("{}", pushval::stress::summary_text(&outcomes, &limits));
    println!(
        "{} runs in {:.1} s; wrote {}, {} and {}",
        outcomes.len(),
        start.elapsed().as_secs_f64(),
        out.join("stress.csv").display(),
        out.join("stability.csv").display(),
        out.join("stress_map.svg").display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Ending quietly when the reader of standard output (or standard error)
/// goes away: `pushval engines | head -1`.
///
/// A C program is killed by SIGPIPE there, which a shell reports as status
/// 141 (128 + 13) and says nothing about. Rust ignores SIGPIPE, so a write
/// fails with `EPIPE` instead and `println!` panics; restoring the signal's
/// default needs `unsafe`, which the workspace forbids. So pushval ends the
/// same way by hand: no message, status 141. Not 0: pushval's 0 means
/// "every gated tolerance holds", which a run whose table nobody read to the
/// end has not shown (under `set -o pipefail` a shell sees what it sees
/// from `cat`). Every print of pushval goes through `print!`/`println!` (or
/// returns the write's error to [`main`]), so one panic hook covers them
/// all, in any thread.
mod closed {
    use std::os::fd::AsFd;

    /// The status of a command cut off by its reader: 128 + SIGPIPE.
    pub const STATUS: u8 = 141;

    /// Whether `fd` is a pipe or socket whose reader has gone: `poll(2)`
    /// reports an error or a hang-up on its writing end.
    pub fn reader_gone(fd: impl AsFd) -> bool {
        use rustix::event::{poll, PollFd, PollFlags};
        let mut fds = [PollFd::new(&fd, PollFlags::OUT)];
        let now = rustix::time::Timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        matches!(poll(&mut fds, Some(&now)), Ok(n) if n > 0)
            && fds[0].revents().intersects(PollFlags::ERR | PollFlags::HUP)
    }

    /// Whether standard output or standard error has lost its reader.
    pub fn output_closed() -> bool {
        reader_gone(std::io::stdout()) || reader_gone(std::io::stderr())
    }

    /// Makes a failed `print!` or `eprint!` to a closed pipe end pushval
    /// with [`STATUS`] and no message (after ending the outside engines'
    /// sessions); every other panic is reported as before.
    pub fn install() {
        let report = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let payload = info.payload();
            let message = payload
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| payload.downcast_ref::<&str>().copied())
                .unwrap_or("");
            // std's words for a failed `print!`/`eprint!`.
            let closed = (message.starts_with("failed printing to stdout")
                && reader_gone(std::io::stdout()))
                || (message.starts_with("failed printing to stderr")
                    && reader_gone(std::io::stderr()));
            if closed {
                pushval::registry::shutdown_sessions();
                std::process::exit(STATUS.into());
            }
            report(info);
        }));
    }

    /// Whether `e` is a write that failed because the reader went away.
    pub fn is_closed_pipe(e: &anyhow::Error) -> bool {
        e.chain().any(|c| {
            c.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
        }) && output_closed()
    }
}

/// The command line's grammar: [`Cli`], where every option or argument
/// that takes a number takes a negative one the same way (`--dt -1`,
/// `--sigma-theta -1e-3` reach the command, which refuses them naming the
/// option, as `--goal -0.5,0,0` reaches `plan`). Without this clap takes
/// `-1` for an unknown flag; its own negative-number rule misses `-1e-3`
/// and `-.5`, so a numeric value may start with a hyphen (a flag given by
/// mistake is then a value that does not parse, named as such). Other
/// values take what clap reads as a negative number. One rule for every
/// command, applied here so no argument can miss it.
fn grammar() -> clap::Command {
    use std::any::TypeId;
    let numeric = [
        TypeId::of::<f64>(),
        TypeId::of::<f32>(),
        TypeId::of::<i64>(),
        TypeId::of::<i32>(),
        TypeId::of::<u64>(),
        TypeId::of::<u32>(),
        TypeId::of::<u16>(),
        TypeId::of::<u8>(),
        TypeId::of::<usize>(),
    ];
    fn negatives(command: clap::Command, numeric: &[std::any::TypeId]) -> clap::Command {
        command
            .mut_args(|a| {
                if !a.get_action().takes_values() {
                    a
                } else if numeric.iter().any(|t| a.get_value_parser().type_id() == *t) {
                    a.allow_hyphen_values(true)
                } else {
                    a.allow_negative_numbers(true)
                }
            })
            .mut_subcommands(|c| negatives(c, numeric))
    }
    negatives(<Cli as clap::CommandFactory>::command(), &numeric)
}

fn main() -> ExitCode {
    closed::install();
    let parsed = grammar()
        .try_get_matches()
        .and_then(|m| <Cli as clap::FromArgMatches>::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        // Help, version or a usage error: clap's text and status, or 141
        // when the text could not be written for want of a reader.
        Err(e) => {
            if e.print().is_err() && closed::output_closed() {
                return ExitCode::from(closed::STATUS);
            }
            return ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
        }
    };
    if let Err(e) = pushval::registry::use_engines_file(cli.engines.as_deref()) {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    let result = match cli.command {
        None => validate(Vec::new(), false, None, false),
        Some(Command::Validate {
            files,
            json,
            junit,
            deny_loose,
        }) => validate(files, json, junit, deny_loose),
        Some(Command::Run { file, out }) => run(file, out),
        Some(Command::Plan { file, goal }) => pushval::control::cli::plan(&goal.common(file)),
        Some(Command::Loop {
            file,
            goal,
            engine,
            period,
            plant,
            adapt,
            sensor,
        }) => pushval::control::cli::run(
            &goal.common(file),
            &engine,
            period,
            plant.as_deref(),
            adapt,
            sensor.as_deref(),
        ),
        Some(Command::ControlStudy {
            out,
            adaptive,
            quick,
            shard,
            merge,
            only,
        }) => {
            if adaptive {
                let out = out.unwrap_or_else(|| PathBuf::from("results/closed_loop/adaptive"));
                pushval::control::adaptive::cli(&out, quick, shard, merge, only.as_deref())
            } else {
                let out = out.unwrap_or_else(|| PathBuf::from("results/closed_loop"));
                pushval::control::study::cli(&out, quick, shard, merge, only.as_deref())
            }
        }
        Some(Command::Manifest { check, root }) => pushval::manifest::cli(&root, check),
        Some(Command::Init { force }) => pushval::init::cli(Path::new("."), force),
        Some(Command::Shipped { out, force }) => {
            pushval::shipped::write_out(&out, force).map(|files| {
                println!("wrote {} files under {}", files.len(), out.display());
                ExitCode::SUCCESS
            })
        }
        Some(Command::Problem {
            file,
            dt,
            engine,
            protocol,
        }) => problem(file, dt, engine, protocol),
        Some(Command::Power {
            out, replot: true, ..
        }) => pushval::power::replot(&out),
        Some(Command::Power { out, quick, .. }) => pushval::power::cli(&out, quick),
        Some(Command::Fit {
            file,
            trajectory,
            params,
            out,
            model,
            sigma_position,
            sigma_theta,
        }) => pushval::fit::cli(&pushval::fit::Request {
            scenario: file,
            trajectory,
            params,
            out,
            model,
            settings: pushval::fit::Settings {
                sigma_position,
                sigma_theta,
                ..Default::default()
            },
        }),
        Some(Command::FitStudy { out, quick }) => pushval::fit::study::cli(&out, quick),
        Some(Command::Track {
            file,
            trajectory,
            params,
            out,
            model,
            sigma_position,
            sigma_theta,
            sigma_omega,
            sigma_force,
        }) => pushval::track::cli(&pushval::track::Request {
            scenario: file,
            trajectory: pushval::track::Source::parse(&trajectory),
            params,
            out,
            model,
            settings: pushval_model::track::EkfSettings {
                sigma_position,
                sigma_theta,
                sigma_omega,
                sigma_force: Some(sigma_force),
                initial_std: [sigma_position, sigma_theta, 1e-2],
                ..Default::default()
            },
        }),
        Some(Command::TrackStudy { out, quick }) => pushval::track::study::cli(&out, quick),
        Some(Command::SlideStudy { out, quick }) => pushval::slide::cli(&out, quick),
        Some(Command::Engines) => {
            print!("{}", pushval::engines_table());
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Laws { json }) => {
            if json {
                println!("{:#}", pushval::registry::laws_json());
            } else {
                print!("{}", pushval::registry::laws_table());
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Compare {
            file,
            trajectory,
            model,
        }) => compare(file, trajectory, model),
        Some(Command::Stress { out, quick }) => stress(out, quick),
        Some(Command::Report {
            out,
            quick,
            shard,
            merge,
        }) => pushval::report::cli(out, quick, shard, merge),
        Some(Command::Study {
            name,
            out,
            quick,
            shard,
            merge,
            studies,
        }) => match studies {
            // A folder the user named that is not there is a mistake, not
            // a request for the shipped study files.
            Some(dir) if !dir.is_dir() => Err(anyhow::anyhow!(
                "--studies {}: no such folder (the study files, MODEL.toml, live in one)",
                dir.display()
            )),
            studies => pushval::study::cli(
                &name,
                pushval::study::Options {
                    quick,
                    shard,
                    merge,
                    studies: studies.unwrap_or_else(pushval::study::spec::default_dir),
                    ..pushval::study::Options::new(out)
                },
            ),
        },
    };
    pushval::registry::shutdown_sessions();
    match result {
        Ok(code) => code,
        Err(e) if closed::is_closed_pipe(&e) => ExitCode::from(closed::STATUS),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
