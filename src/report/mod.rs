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
//!   (rayon) and can be split for a batch scheduler ([`shard`]):
//!   `--shard K/N` computes the K-th of N contiguous parts of the cell list
//!   and writes `OUT/parts/sweep-K-of-N.csv`; `--merge` reads the N parts
//!   and writes exactly the files a single run writes.
//!
//! [`plot`] draws every figure (also those of `pushval study` and
//! `pushval stress`), and the writer, CSV and progress helpers here serve
//! `pushval study` too.
//!
//! Output is deterministic: no time stamps, fixed grids, numbers printed with
//! Rust's shortest round-trip formatting, files written through a temporary
//! file and a rename.

pub mod cells;
pub mod figures;
pub mod paper;
pub mod plot;
pub mod shard;

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use rayon::prelude::*;

use crate::output::write_atomic;
pub use shard::Shard;
use shard::{grid_name, shard_range, Parts};

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
            scenarios: default_scenario_dir(),
            progress: true,
        }
    }
}

/// The scenarios folder the commands read: the project's `scenarios/`
/// (beside the `pushval.toml` in use), else `./scenarios`, else the shipped
/// scenarios written out once ([`crate::shipped::materialized`]).
pub fn default_scenario_dir() -> PathBuf {
    let dirs = [
        crate::registry::project_dir().map(|d| d.join("scenarios")),
        Some(PathBuf::from("scenarios")),
    ];
    dirs.into_iter()
        .flatten()
        .find(|d| d.is_dir())
        .or_else(|| crate::shipped::materialized("scenarios").ok())
        .unwrap_or_else(|| PathBuf::from("scenarios"))
}

/// What a figure shows, for `results/README.md`.
#[derive(Debug, Clone)]
pub struct Entry {
    /// The SVG file name.
    pub figure: String,
    /// The data files beside it.
    pub data: Vec<String>,
    /// One short paragraph: what it shows and the key numbers.
    pub text: String,
}

/// Writes files into the output folder, atomically, and remembers them.
pub struct Writer {
    dir: PathBuf,
    written: Vec<PathBuf>,
    /// Rows of `key_figures.csv`: the figures README.md quotes that are not
    /// a column of a figure's CSV (figure, quantity, value in SI).
    keys: Vec<String>,
}

impl Writer {
    /// A writer into `dir` (created if missing).
    pub fn new(dir: &Path) -> anyhow::Result<Self> {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            written: Vec::new(),
            keys: Vec::new(),
        })
    }
    /// Records a figure that README.md quotes and no CSV column holds
    /// (`value` in SI units), for `key_figures.csv`. Returns `value`.
    pub fn key(&mut self, figure: &str, quantity: &str, value: f64) -> f64 {
        self.keys.push(format!("{figure},{quantity},{value:.6e}\n"));
        value
    }
    /// Writes `name` (relative to the output folder).
    pub fn file(&mut self, name: &str, bytes: &[u8]) -> anyhow::Result<()> {
        let path = self.dir.join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("creating {}", parent.display()))?;
        }
        write_atomic(&path, bytes)?;
        self.written.push(path);
        Ok(())
    }
    /// Renders and writes a figure.
    pub fn figure(&mut self, name: &str, fig: &plot::Figure) -> anyhow::Result<()> {
        let svg = plot::render(fig).with_context(|| format!("drawing {name}"))?;
        self.file(name, svg.as_bytes())
    }
    /// The files written, in order (consumes the writer).
    pub fn into_written(self) -> Vec<PathBuf> {
        self.written
    }
}

/// A CSV table built in memory.
#[derive(Debug, Clone)]
pub struct Csv {
    text: String,
}

impl Csv {
    pub fn new(header: &[&str]) -> Self {
        let mut text = header.join(",");
        text.push('\n');
        Self { text }
    }
    pub fn row(&mut self, fields: &[String]) {
        self.text.push_str(&fields.join(","));
        self.text.push('\n');
    }
    pub fn as_bytes(&self) -> &[u8] {
        self.text.as_bytes()
    }
}

/// A number for a data file: shortest round-trip form (`NaN` where undefined).
pub fn num(v: f64) -> String {
    format!("{v}")
}

/// A number for a trajectory file, rounded to 10 significant digits (keeps
/// the files small; far below any difference the figures show).
pub fn num10(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return format!("{v}");
    }
    let r: f64 = format!("{v:.9e}").parse().unwrap_or(v);
    format!("{r}")
}

/// A progress bar on stderr: hidden when not a terminal, when `CI` is set,
/// or when the caller turned it off.
pub fn progress(len: u64, show: bool, what: &str) -> indicatif::ProgressBar {
    let visible = show && std::io::stderr().is_terminal() && std::env::var_os("CI").is_none();
    if !visible {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{msg:>10} [{bar:40}] {pos}/{len} cells, {elapsed} elapsed, eta {eta}",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(what.to_string());
    bar
}

/// Evaluates `eval` on every item in parallel (rayon), keeping their order,
/// with a [`progress`] bar named `what`.
pub fn par_rows<T: Sync>(
    items: &[T],
    show_progress: bool,
    what: &str,
    eval: impl Fn(&T) -> Vec<f64> + Sync,
) -> Vec<Vec<f64>> {
    let bar = progress(items.len() as u64, show_progress, what);
    let rows: Vec<Vec<f64>> = items
        .par_iter()
        .map(|t| {
            let r = eval(t);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    rows
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
            files: w.written,
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
    if !w.keys.is_empty() {
        let mut csv = String::from("figure,quantity,value\n");
        csv.extend(w.keys.drain(..));
        w.file(KEY_FIGURES, csv.as_bytes())?;
    }
    w.file("README.md", readme(&entries, opts.quick).as_bytes())?;
    Ok(Summary {
        files: w.written,
        cells,
    })
}

/// The file of the figures README.md quotes that no figure's CSV holds.
pub const KEY_FIGURES: &str = "key_figures.csv";

fn readme(entries: &[Entry], quick: bool) -> String {
    let mut s = String::from(
        "# pushval results\n\n\
         Generated by `pushval report` (see the repository README); do not edit by hand.\n\
         Every figure is an SVG with its data beside it (CSV, SI units, one header row);\n\
         figures quoted below that are no column of those CSVs are in `key_figures.csv`.\n\
         The paper plate is the seed paper's 0.25 m, 1 kg square on four corner supports\n\
         (μ 0.5, equal loads), pushed at the corner (−0.125, −0.125) m, with the geometric\n\
         inertia unless a figure says otherwise. Models: `dynamic` (the full model,\n\
         adaptive Dormand–Prince, tolerance 1e-10), `kinematic` (ω = v_c ψ(φ)), `rapier2d`\n\
         (the engine, f64, dt = 1 ms, {} friction velocity). Fr = v_c²/(μ̄ g L) with\n\
         L = |p_c − p_cm| the contact's distance from the centre of mass.\n",
    )
    .replace(
        "{}",
        // The engine's own record of its default mode, through the registry.
        crate::registry::engine("rapier2d", &Default::default()).settings(1e-3)
            ["friction_velocity"]
            .as_str()
            .unwrap_or("default"),
    );
    if quick {
        s.push_str("\n**Quick run: reduced sweep grids (for tests).**\n");
    }
    s.push('\n');
    for e in entries {
        s.push_str(&format!("## `{}`\n\n", e.figure));
        if !e.data.is_empty() {
            let d: Vec<String> = e.data.iter().map(|d| format!("`{d}`")).collect();
            s.push_str(&format!("Data: {}.\n\n", d.join(", ")));
        }
        s.push_str(e.text.trim_end());
        s.push_str("\n\n");
    }
    s
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
