//! `pushval study MODEL|all`: one study for every engine model the registry
//! lists (outside engines included): where the engine's friction disagrees
//! with Coulomb support friction, and whether the engine's own friction law
//! in closed form ([`pushval_engine::FrictionLaw`], declared by the engine
//! through [`Engine::law`](pushval_engine::Engine::law)) explains it.
//!
//! For a model, in `results/friction_models/MODEL/` (or `--out DIR`):
//! `paper_plate.csv` (steady ω at v_c 0.2, 0.5, 1 m/s against Coulomb's ω*
//! and the law's), `map.csv` over the (Fr, φ) grid with the law's class and
//! its figure `map.svg` ([`figure`]), `dt_ladder.csv` (observed order,
//! Richardson), `creep.csv` where the law locks, `variants.csv` /
//! `map_NAME.csv`, `sweep_NAME.csv` (one quantity over a list, with engine
//! and law support loads), `rest_moments.csv` where the law is semi-stable,
//! `coulomb_fit.csv` ([`crate::fit::engine`]) and `README.md` from those files ([`readme`]).
//!
//! What a study varies is data, `studies/MODEL.toml` ([`spec`]); nothing
//! here names an engine. `all` runs every model of this build and writes an
//! index, `OUT/README.md`, from the folders' files (`index` writes only it).
//!
//! A study is a fixed list of tasks (engine runs, fits), each keyed and
//! reduced to a row of numbers; the files are written from the rows alone.
//! The tasks run in parallel (rayon) with a progress bar, and split over
//! processes or machines: `--shard K/N`, `--shard hash:K/N`, or a Slurm
//! array's variables; `--merge` rebuilds exactly the single run's files
//! ([`crate::shard`]).

pub mod figure;
mod plan;
pub mod plate;
pub mod readme;
pub mod spec;

use std::path::{Path, PathBuf};

use anyhow::bail;
use pushval_engine::EngineOptions;

use crate::outdir::Writer;
use crate::parallel::par_rows;
use crate::shard::{grid_hash, grid_name, Parts, Shard};
pub use plan::{models, Plan, Setup, SweepPlan, Task};
pub use plate::err;
pub use readme::opt;

/// What `pushval study` does.
#[derive(Debug, Clone)]
pub struct Options {
    /// `--out`: the model's folder (for `all`, the parent of every model's).
    pub out: Option<PathBuf>,
    /// Reduced grids (for tests).
    pub quick: bool,
    /// Compute only this part of the tasks and write a part file.
    pub shard: Option<Shard>,
    /// Build every output from the part files.
    pub merge: bool,
    /// Draw a progress bar (still only on a terminal and when `CI` is unset).
    pub progress: bool,
    /// The folder of the study files.
    pub studies: PathBuf,
}

impl Options {
    pub fn new(out: Option<PathBuf>) -> Self {
        Self {
            out,
            quick: false,
            shard: None,
            merge: false,
            progress: true,
            studies: spec::default_dir(),
        }
    }
}

/// The default output folder of every study.
pub const DEFAULT_OUT: &str = "results/friction_models";

/// What a study run did.
#[derive(Debug, Clone, Default)]
pub struct Summary {
    /// Every file written, in order.
    pub files: Vec<PathBuf>,
    /// Tasks computed by this process (0 for `--merge`).
    pub tasks: usize,
    /// What was skipped and why.
    pub notes: Vec<String>,
}

/// Runs the study of one model into `dir`: its shard, its merge, or all.
pub fn run_model(model: &str, dir: &Path, opts: &Options) -> anyhow::Result<Summary> {
    let plan = Plan::new(model, &opts.studies, opts.quick)?;
    let tasks = plan.tasks();
    let keys: Vec<String> = tasks.iter().map(|t| plan.key(t)).collect();
    let tag = format!("study {model}");
    let parts = Parts {
        tag: &tag,
        stem: model,
        grid: grid_name(opts.quick),
        hash: grid_hash(&keys),
    };
    let shard = match opts.shard {
        None if !opts.merge => Shard::from_env()?,
        given => given,
    };
    if let Some(shard) = shard {
        let idx = shard.indices(&keys);
        let mine: Vec<Task> = idx.iter().map(|&i| tasks[i]).collect();
        let rows = par_rows(&mine, opts.progress, model, |t| plan.eval(t));
        let mut w = Writer::new(dir)?;
        w.file(
            &parts.file_name(shard),
            parts.text(tasks.len(), &idx, &rows, shard).as_bytes(),
        )?;
        return Ok(Summary {
            files: w.into_written(),
            tasks: idx.len(),
            notes: Vec::new(),
        });
    }
    let computed = if opts.merge { 0 } else { tasks.len() };
    let rows = if opts.merge {
        parts.merge(dir, tasks.len(), |i| Some(plan.width(&tasks[i])))?
    } else {
        par_rows(&tasks, opts.progress, model, |t| plan.eval(t))
    };
    let mut w = Writer::new(dir)?;
    readme::write(&plan, &tasks, &rows, &mut w)?;
    let note = plan.failure_note();
    if let Some(n) = &note {
        eprintln!("{n}");
    }
    // Every run failed: nothing was measured, whatever was written.
    let runs = rows
        .iter()
        .zip(&tasks)
        .filter(|(_, t)| !matches!(t, Task::Fit { .. }));
    let measured = runs
        .clone()
        .any(|(r, _)| r.first().is_some_and(|w| !w.is_nan()));
    if runs.count() > 0 && !measured {
        bail!(
            "study {model}: no engine run gave a steady omega; every cell is blank ({})",
            note.unwrap_or_default()
        );
    }
    Ok(Summary {
        files: w.into_written(),
        tasks: computed,
        notes: Vec::new(),
    })
}

/// Runs the study of `name` (a model of `pushval engines`) or `all` of
/// this build's models (and writes the index).
pub fn run(name: &str, opts: &Options) -> anyhow::Result<Summary> {
    let all = models();
    spec::check_names(&opts.studies, &all)?;
    let root = opts
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_OUT));
    if !matches!(name, "all" | "index") {
        if !all.iter().any(|m| m == name) {
            bail!("unknown model `{name}`; known: {}, all", all.join(", "));
        }
        let dir = opts
            .out
            .clone()
            .unwrap_or_else(|| Path::new(DEFAULT_OUT).join(name));
        return run_model(name, &dir, opts);
    }
    let mut sum = Summary::default();
    // `index`: only the index, from the model folders as they are.
    for m in all.iter().filter(|_| name == "all") {
        let e = crate::registry::engine(m, &EngineOptions::default());
        if let Err(why) = e.availability() {
            sum.notes.push(format!(
                "skipped {m}, keeping {} as it is: {why}",
                root.join(m).display()
            ));
            continue;
        }
        let started = std::time::Instant::now();
        let one = run_model(m, &root.join(m), opts)?;
        // Progress of a long `all`: which model took how long.
        eprintln!(
            "study {m}: {} tasks, {:.1} s",
            one.tasks,
            started.elapsed().as_secs_f64()
        );
        sum.files.extend(one.files);
        sum.tasks += one.tasks;
    }
    if name == "index" || (opts.shard.is_none() && (opts.merge || Shard::from_env()?.is_none())) {
        let mut w = Writer::new(&root)?;
        readme::index(&root, &all, opts.quick, &mut w)?;
        sum.files.extend(w.into_written());
    }
    Ok(sum)
}

/// `pushval study`: runs and prints what it wrote and how long it took.
pub fn cli(name: &str, opts: Options) -> anyhow::Result<std::process::ExitCode> {
    let start = std::time::Instant::now();
    if opts.merge && opts.shard.is_some() {
        bail!("--shard and --merge exclude each other");
    }
    let summary = run(name, &opts)?;
    for f in &summary.files {
        println!("wrote {}", f.display());
    }
    for n in &summary.notes {
        println!("note: {n}");
    }
    println!(
        "{} files, {} tasks computed, {:.1} s",
        summary.files.len(),
        summary.tasks,
        start.elapsed().as_secs_f64()
    );
    Ok(std::process::ExitCode::SUCCESS)
}
