//! `pushval report`: regenerates `results/` — SVG figures, the data beside
//! each one (CSV), and a README with the key numbers, all computed here.
//!
//! Two kinds of figure:
//!
//! * [`paper`]: the seed paper's figures (φ(t), ω(t), x(t), y(t), the path),
//!   each model run once and rapier2d drawn over the dynamic model, plus the
//!   inertia and switching questions;
//! * the sweeps: maps and curves over parameter grids (κ against the Froude
//!   number, τ, the kinematic model's validity map, the assumptions map);
//!   [`cells`] holds the grids and what each cell computes, [`figures`] what
//!   is drawn and said from the cells' rows. The cells run in parallel
//!   (rayon) and can be split for a batch scheduler ([`crate::shard`]):
//!   `--shard K/N` computes the K-th of N contiguous parts of the cell list
//!   and writes `OUT/parts/sweep-K-of-N.csv`; `--merge` reads the N parts
//!   and writes exactly the files a single run writes.
//!
//! The toolkit it shares with the other commands: [`crate::plot`] draws the
//! figures, [`crate::outdir`] writes the folder (atomically, through
//! [`crate::atomic`]) and formats its numbers, [`crate::shard`] splits the
//! cells over processes and [`crate::parallel`] over threads.
//!
//! Output is deterministic: no time stamps, fixed grids, numbers printed with
//! Rust's shortest round-trip formatting, files written through a temporary
//! file and a rename.

pub mod cells;
pub mod creep_law;
pub mod figures;
pub mod paper;
mod readme;

use std::path::PathBuf;

use anyhow::bail;

use crate::outdir::Writer;
use crate::shard::{self, grid_name, shard_range, Parts, Shard};
use readme::readme;
pub use readme::{Entry, KEY_FIGURES};

/// What `pushval report` does.
#[derive(Debug, Clone)]
pub struct Options {
    /// Output folder (created if missing).
    pub out: PathBuf,
    /// Reduced grids (for tests); the paper figures are the same.
    pub quick: bool,
    /// Compute only this part of the sweep cells and write a part file.
    pub shard: Option<Shard>,
    /// Build every output from the part files in `OUT/parts/` instead of
    /// computing the sweeps.
    pub merge: bool,
    /// Folder of the shipped scenarios (the paper plate and its variants).
    pub scenarios: PathBuf,
    /// Draw a progress bar (still only on a terminal and when `CI` is unset).
    pub progress: bool,
}

impl Options {
    pub fn new(out: impl Into<PathBuf>) -> Self {
        Self {
            out: out.into(),
            quick: false,
            shard: None,
            merge: false,
            scenarios: crate::scenario_dir::default_scenario_dir(),
            progress: true,
        }
    }
}

/// The part files of the report's sweeps.
fn sweep_parts(quick: bool, total: usize) -> Parts<'static> {
    let keys: Vec<String> = (0..total).map(|i| i.to_string()).collect();
    Parts {
        tag: "report sweep",
        stem: "sweep",
        grid: grid_name(quick),
        hash: shard::grid_hash(&keys),
    }
}

/// What a report run did.
#[derive(Debug, Clone)]
pub struct Summary {
    /// Every file written, in order.
    pub files: Vec<PathBuf>,
    /// Number of sweep cells computed by this process (0 for `--merge`).
    pub cells: usize,
}

/// Runs the report.
pub fn run(opts: &Options) -> anyhow::Result<Summary> {
    if opts.merge && opts.shard.is_some() {
        bail!("--shard and --merge exclude each other");
    }
    let geoms = cells::geometries(&opts.scenarios)?;
    let tasks = cells::tasks(&geoms, opts.quick);
    let parts = sweep_parts(opts.quick, tasks.len());
    let mut w = Writer::new(&opts.out)?;
    let from_env = if opts.merge { None } else { Shard::from_env()? };
    let env_shard = from_env.map(|s| Shard {
        by_hash: false,
        ..s
    });
    if let Some(shard) = opts.shard.or(env_shard) {
        if shard.by_hash {
            bail!("pushval report splits its sweeps by position only: --shard K/N, not hash:K/N");
        }
        let range = shard_range(tasks.len(), shard);
        let rows = cells::compute(&geoms, &tasks, range.clone(), opts.quick, opts.progress);
        let idx: Vec<usize> = range.clone().collect();
        let text = parts.text(tasks.len(), &idx, &rows, shard);
        w.file(&parts.file_name(shard), text.as_bytes())?;
        return Ok(Summary {
            files: w.into_written(),
            cells: range.len(),
        });
    }
    let (rows, cells) = if opts.merge {
        let width = |i: usize| Some(cells::width(&tasks[i]));
        (parts.merge(&opts.out, tasks.len(), width)?, 0)
    } else {
        let rows = cells::compute(&geoms, &tasks, 0..tasks.len(), opts.quick, opts.progress);
        (rows, tasks.len())
    };
    let mut entries = paper::figures(&opts.scenarios, &mut w)?;
    entries.extend(figures::figures(&geoms, &tasks, &rows, opts.quick, &mut w)?);
    let keys = w.take_keys();
    if !keys.is_empty() {
        let mut csv = crate::outdir::Csv::new(&["figure", "quantity", "value"]);
        keys.iter().for_each(|k| csv.row(k));
        w.file(KEY_FIGURES, csv.as_bytes())?;
    }
    w.file("README.md", readme(&entries, opts.quick).as_bytes())?;
    Ok(Summary {
        files: w.into_written(),
        cells,
    })
}

/// `pushval report`: runs and prints what it wrote and how long it took.
pub fn cli(
    out: PathBuf,
    quick: bool,
    shard: Option<Shard>,
    merge: bool,
) -> anyhow::Result<std::process::ExitCode> {
    let start = std::time::Instant::now();
    let opts = Options {
        quick,
        shard,
        merge,
        ..Options::new(out)
    };
    let summary = run(&opts)?;
    for f in &summary.files {
        println!("wrote {}", f.display());
    }
    println!(
        "{} files, {} sweep cells computed, {:.1} s",
        summary.files.len(),
        summary.cells,
        start.elapsed().as_secs_f64()
    );
    Ok(std::process::ExitCode::SUCCESS)
}
