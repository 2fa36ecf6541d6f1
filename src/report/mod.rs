//! `pushval report`: regenerates `results/` — SVG figures, the data beside
//! each one (CSV), and a README with the key numbers, all computed here.
//!
//! Two kinds of figure:
//!
//! * [`paper`]: the seed paper's figures (φ(t), ω(t), x(t), y(t), the path),
//!   each model run once and rapier2d drawn over the dynamic model, plus the
//!   inertia and switching questions;
//! * [`sweeps`]: maps and curves over parameter grids (κ against the Froude
//!   number, τ, the kinematic model's validity map, the assumptions map).
//!   The grid cells run in parallel (rayon) and can be split for a batch
//!   scheduler: `--shard K/N` computes the K-th of N contiguous parts of the
//!   cell list and writes `OUT/parts/sweep-K-of-N.csv`; `--merge` reads the
//!   N parts and writes exactly the files a single run writes.
//!
//! Output is deterministic: no time stamps, fixed grids, numbers printed with
//! Rust's shortest round-trip formatting, files written through a temporary
//! file and a rename.

pub mod paper;
pub mod plot;
pub mod sweeps;

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use anyhow::{bail, Context};

use crate::output::write_atomic;

/// One part of N of the sweep cells: `K/N` with 1 ≤ K ≤ N.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub k: usize,
    pub n: usize,
}

impl FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| format!("expected K/N (e.g. 2/8), got '{s}'"))?;
        let k: usize = k.trim().parse().map_err(|_| format!("bad K in '{s}'"))?;
        let n: usize = n.trim().parse().map_err(|_| format!("bad N in '{s}'"))?;
        if n == 0 || k == 0 || k > n {
            return Err(format!("need 1 <= K <= N, got '{s}'"));
        }
        Ok(Self { k, n })
    }
}

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

/// `./scenarios` when it exists, else the one beside this crate's manifest.
pub fn default_scenario_dir() -> PathBuf {
    let local = PathBuf::from("scenarios");
    if local.is_dir() {
        local
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
    }
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
}

impl Writer {
    fn new(dir: &Path) -> anyhow::Result<Self> {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            written: Vec::new(),
        })
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
    let geoms = sweeps::geometries(&opts.scenarios)?;
    let tasks = sweeps::tasks(&geoms, opts.quick);
    let mut w = Writer::new(&opts.out)?;
    if let Some(shard) = opts.shard {
        let range = sweeps::shard_range(tasks.len(), shard);
        let rows = sweeps::compute(&geoms, &tasks, range.clone(), opts.quick, opts.progress);
        let text = sweeps::part_text(&tasks, range.clone(), &rows, shard, opts.quick);
        w.file(&sweeps::part_name(shard), text.as_bytes())?;
        return Ok(Summary {
            files: w.written,
            cells: range.len(),
        });
    }
    let (rows, cells) = if opts.merge {
        (sweeps::merge_parts(&opts.out, &tasks, opts.quick)?, 0)
    } else {
        let rows = sweeps::compute(&geoms, &tasks, 0..tasks.len(), opts.quick, opts.progress);
        (rows, tasks.len())
    };
    let mut entries = paper::figures(&opts.scenarios, &mut w)?;
    entries.extend(sweeps::figures(&geoms, &tasks, &rows, opts.quick, &mut w)?);
    w.file("README.md", readme(&entries, opts.quick).as_bytes())?;
    Ok(Summary {
        files: w.written,
        cells,
    })
}

fn readme(entries: &[Entry], quick: bool) -> String {
    let mut s = String::from(
        "# pushval results\n\n\
         Generated by `pushval report` (see the repository README); do not edit by hand.\n\
         Every figure is an SVG with its data beside it (CSV, SI units, one header row).\n\
         The paper plate is the seed paper's 0.25 m, 1 kg square on four corner supports\n\
         (μ 0.5, equal loads), pushed at the corner (−0.125, −0.125) m, with the geometric\n\
         inertia unless a figure says otherwise. Models: `dynamic` (the full model,\n\
         adaptive Dormand–Prince, tolerance 1e-10), `kinematic` (ω = v_c ψ(φ)), `rapier2d`\n\
         (the engine, f64, dt = 1 ms, midpoint friction velocity). Fr = v_c²/(μ̄ g L) with\n\
         L = |p_c − p_cm| the contact's distance from the centre of mass.\n",
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
