//! `pushval study NAME|all`: regenerates `results/friction_models/`, where
//! each engine's own friction law disagrees with Coulomb support friction
//! and what explains it, in closed form.
//!
//! One module per study, each writing its folder of the output:
//!
//! * [`idioms`] (`OUT/`): the friction idioms of 2-D game engines, run in
//!   rapier2d, against Coulomb; its README also gathers the other studies'
//!   paper-plate numbers and findings, so `all` runs it last;
//! * [`rapier3d`] (`OUT/rapier3d/`): rapier3d's own contact friction;
//! * [`box2d`] (`OUT/box2d/`): Box2D's per-support Coulomb model and its
//!   motor-joint idiom (through the registry's `Engine` trait, with the
//!   idiom's closed form from `pushval_box2d::predict`);
//! * `mujoco` (`OUT/mujoco/`): MuJoCo's friction cones; compiled only with
//!   the root feature `mujoco` (without it `study mujoco` exits 2 naming the
//!   feature and `study all` skips it, keeping `OUT/mujoco/` as it is);
//! * `avian` (`OUT/avian/`): Avian's per-support Coulomb model (avian2d) and
//!   its own contact friction in closed form (avian3d, through the crate's
//!   simulators and `pushval_avian::predict`); compiled only with the root
//!   feature `avian`, gated like `mujoco`;
//! * `physx` (`OUT/physx/`): PhysX's friction types on the feet-on-floor
//!   scene against their closed forms (`pushval_physx::predict`), and which
//!   lock criterion PhysX follows; compiled only with the root feature
//!   `physx`, gated like `mujoco`.
//!
//! A study is a fixed list of tasks (engine runs and the closed forms that
//! need their output), each reduced to a row of numbers ([`Study::eval`]);
//! every file is then written from the rows alone ([`Study::write`]), so the
//! READMEs state no number that is not computed from the data beside them.
//! The tasks run in parallel (rayon) with a progress bar (none when `CI` is
//! set), and split for a batch scheduler like `pushval report`'s sweeps:
//! `--shard K/N` computes the K-th of N parts of each study's task list into
//! `OUT/parts/STUDY-K-of-N.csv`, `--merge` rebuilds from the parts exactly
//! the files a single run writes (see [`crate::report::shard`]).
//!
//! Every study runs the scene of [`plate`]; the figures are drawn by
//! [`crate::report::plot`] (one heat map for every (Fr, φ) map).
//!
//! The engines run through their crates' own simulators, not the
//! [`pushval_engine::Engine`] trait: every task reads what a trajectory does
//! not carry (the engine's step history, per-foot loads and friction,
//! contact manifolds, tail statistics). The registry still names and
//! versions each engine in the READMEs.

#[cfg(feature = "avian")]
pub mod avian;
pub mod box2d;
pub mod fits;
pub mod idioms;
#[cfg(feature = "mujoco")]
pub mod mujoco;
#[cfg(feature = "physx")]
pub mod physx;
pub mod plate;
pub mod rapier3d;

use std::path::{Path, PathBuf};

use anyhow::bail;

use crate::report::plot::{cell_edges, heat_map, Axis, Figure, MapCell, Panel, Scale};
use crate::report::shard::{grid_name, shard_range, Parts, Shard};
use crate::report::{par_rows, Writer};

/// The studies on the command line, in the order `all` runs them.
pub const STUDIES: [&str; 7] = [
    "rapier3d",
    "mujoco",
    "box2d",
    "avian",
    "physx",
    "coulomb_fits",
    "idioms",
];

/// The cargo feature that brings in the MuJoCo study.
pub const MUJOCO_FEATURE: &str =
    "the MuJoCo study needs the cargo feature `mujoco` (build with --features mujoco; scripts/setup-mujoco.sh provides libmujoco.so)";

/// The cargo feature that brings in the Avian study.
pub const AVIAN_FEATURE: &str =
    "the Avian study needs the cargo feature `avian` (build with --features avian)";

/// The cargo feature that brings in the PhysX study.
pub const PHYSX_FEATURE: &str =
    "the PhysX study needs the cargo feature `physx` (build with --features physx; needs clang++: apt-get install clang)";

/// What `pushval study` does.
#[derive(Debug, Clone)]
pub struct Options {
    /// Output folder (created if missing); default `results/friction_models`.
    pub out: PathBuf,
    /// Reduced grids (for tests).
    pub quick: bool,
    /// Compute only this part of each study's tasks and write a part file.
    pub shard: Option<Shard>,
    /// Build every output from the part files in `OUT/parts/`.
    pub merge: bool,
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
            progress: true,
        }
    }
}

/// One study: a fixed task list, the numbers of each task, and the files
/// built from them.
pub trait Study: Sync {
    /// A task: one engine run (with the closed forms that need its output).
    type Task: Sync;
    /// The study's name on the command line and in part files.
    fn name(&self) -> &'static str;
    /// Its folder under the output folder (`""`: the output folder).
    fn dir(&self) -> &'static str;
    /// The task list (fixed by the grid).
    fn tasks(&self) -> Vec<Self::Task>;
    /// How many numbers a task gives, where fixed (checked on merge).
    fn width(&self, task: &Self::Task) -> Option<usize>;
    /// Runs a task.
    fn eval(&self, task: &Self::Task) -> Vec<f64>;
    /// Writes every file of the study from the rows of all tasks; `out` is
    /// the output folder (a study may read another's data there).
    fn write(
        &self,
        tasks: &[Self::Task],
        rows: &[Vec<f64>],
        out: &Path,
        w: &mut Writer,
    ) -> anyhow::Result<()>;
}

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

/// Runs one study: its shard, its merge, or the whole of it.
pub fn run_study<S: Study>(study: &S, opts: &Options) -> anyhow::Result<Summary> {
    let tasks = study.tasks();
    let tag = format!("study {}", study.name());
    let parts = Parts {
        tag: &tag,
        stem: study.name(),
        grid: grid_name(opts.quick),
    };
    if let Some(shard) = opts.shard {
        let range = shard_range(tasks.len(), shard);
        let rows = par_rows(&tasks[range.clone()], opts.progress, study.name(), |t| {
            study.eval(t)
        });
        let mut w = Writer::new(&opts.out)?;
        let text = parts.text(tasks.len(), range.clone(), &rows, shard);
        w.file(&parts.file_name(shard), text.as_bytes())?;
        return Ok(Summary {
            files: w.into_written(),
            tasks: range.len(),
            notes: Vec::new(),
        });
    }
    let (rows, computed) = if opts.merge {
        let width = |i: usize| study.width(&tasks[i]);
        (parts.merge(&opts.out, tasks.len(), width)?, 0)
    } else {
        let rows = par_rows(&tasks, opts.progress, study.name(), |t| study.eval(t));
        (rows, tasks.len())
    };
    let mut w = Writer::new(&opts.out.join(study.dir()))?;
    study.write(&tasks, &rows, &opts.out, &mut w)?;
    Ok(Summary {
        files: w.into_written(),
        tasks: computed,
        notes: Vec::new(),
    })
}

/// Runs the study `name` (one of [`STUDIES`]) or `all` of them.
pub fn run(name: &str, opts: &Options) -> anyhow::Result<Summary> {
    if name == "all" {
        let mut all = Summary::default();
        for s in STUDIES {
            if s == "mujoco" && !cfg!(feature = "mujoco") {
                all.notes.push(format!(
                    "skipped the MuJoCo study, keeping {} as it is: {MUJOCO_FEATURE}",
                    opts.out.join("mujoco").display()
                ));
                continue;
            }
            if s == "avian" && !cfg!(feature = "avian") {
                all.notes.push(format!(
                    "skipped the Avian study, keeping {} as it is: {AVIAN_FEATURE}",
                    opts.out.join("avian").display()
                ));
                continue;
            }
            if s == "physx" && !cfg!(feature = "physx") {
                all.notes.push(format!(
                    "skipped the PhysX study, keeping {} as it is: {PHYSX_FEATURE}",
                    opts.out.join("physx").display()
                ));
                continue;
            }
            let one = run(s, opts)?;
            all.files.extend(one.files);
            all.tasks += one.tasks;
            all.notes.extend(one.notes);
        }
        return Ok(all);
    }
    match name {
        "idioms" => run_study(&idioms::Idioms { quick: opts.quick }, opts),
        "rapier3d" => run_study(&rapier3d::Rapier3d { quick: opts.quick }, opts),
        "box2d" => run_study(&box2d::Box2d { quick: opts.quick }, opts),
        "coulomb_fits" => run_study(&fits::Fits { quick: opts.quick }, opts),
        #[cfg(feature = "mujoco")]
        "mujoco" => run_study(&mujoco::Mujoco { quick: opts.quick }, opts),
        #[cfg(not(feature = "mujoco"))]
        "mujoco" => bail!("{MUJOCO_FEATURE}"),
        #[cfg(feature = "avian")]
        "avian" => run_study(&avian::Avian { quick: opts.quick }, opts),
        #[cfg(not(feature = "avian"))]
        "avian" => bail!("{AVIAN_FEATURE}"),
        #[cfg(feature = "physx")]
        "physx" => run_study(&physx::Physx { quick: opts.quick }, opts),
        #[cfg(not(feature = "physx"))]
        "physx" => bail!("{PHYSX_FEATURE}"),
        _ => bail!("unknown study '{name}'; known: {}, all", STUDIES.join(", ")),
    }
}

/// `pushval study`: runs and prints what it wrote and how long it took.
pub fn cli(
    name: &str,
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

/// The colour scale of every (Fr, φ) disagreement map: log10 of the
/// relative steady-ω error from 1e-6 (blue) to 1 (red).
pub const ERROR_SCALE: Scale = Scale::Log10 { lo: -6.0, hi: 0.0 };

/// One cell of a (Fr, φ) map: `rel_err` its relative steady-ω error,
/// `flags` the letters of its status (empty when ok).
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorCell {
    /// Index into the map's Froude numbers.
    pub i: usize,
    /// Index into the map's push directions.
    pub j: usize,
    pub rel_err: f64,
    pub flags: String,
}

/// One panel of a (Fr, φ) map: the heat map of [`ERROR_SCALE`] over φ
/// (x) and Fr (y, log), each cell marked with `log10` of its error to one
/// decimal and its status letters.
pub fn error_panel(title: &str, frs: &[f64], phis: &[f64], cells: &[ErrorCell]) -> Panel {
    let (fe, pe) = (cell_edges(frs, true), cell_edges(phis, false));
    let map: Vec<MapCell> = cells
        .iter()
        .map(|c| {
            let digits = match format!("{:.1}", c.rel_err.log10()) {
                z if z == "-0.0" => "0.0".to_string(),
                d => d,
            };
            MapCell {
                x: pe[c.j],
                y: fe[c.i],
                value: c.rel_err,
                mark: format!("{digits}{}", c.flags),
            }
        })
        .collect();
    heat_map(
        title,
        Axis::lin("push direction φ (rad)").range(pe[0].0, pe[pe.len() - 1].1),
        Axis::log("Froude number Fr = v_c²/(μ g L)").range(fe[0].0, fe[fe.len() - 1].1),
        &map,
        &ERROR_SCALE,
    )
}

/// A figure of (Fr, φ) error panels on `cols` columns, with the scale's key
/// and what each status letter means (`(letter, meaning)`).
pub fn error_figure(panels: Vec<Panel>, cols: usize, letters: &[(&str, &str)]) -> Figure {
    let rows = panels.len().div_ceil(cols.max(1)) as u32;
    let notes: Vec<String> = std::iter::once("cell: log10 of the error".to_string())
        .chain(letters.iter().map(|(l, m)| format!("{l}: {m}")))
        .collect();
    // Room for every cell's mark: about 38 px a column, 24 px a row.
    let distinct = |v: Vec<f64>| {
        let mut v = v;
        v.sort_by(f64::total_cmp);
        v.dedup();
        v.len() as u32
    };
    let (nx, ny) = panels.iter().fold((0, 0), |(nx, ny), p| {
        (
            distinct(p.cells.iter().map(|c| c.x.0).collect()).max(nx),
            distinct(p.cells.iter().map(|c| c.y.0).collect()).max(ny),
        )
    });
    let (w, h) = ((140 + 38 * nx).max(430), (130 + 24 * ny).max(420));
    Figure {
        size: (w * cols as u32 + 230, (h * rows).max(560)),
        cols,
        panels,
        key: Some(ERROR_SCALE.key("|ω − ω*|/|ω*|", &[], &notes)),
    }
}

/// The line a quick run's README carries (empty for a full run).
pub fn quick_note(quick: bool) -> &'static str {
    if quick {
        "**Quick run: reduced grids (for tests).**\n\n"
    } else {
        ""
    }
}

/// A number for a data file, blank where it is NaN (undefined).
pub fn opt(v: f64) -> String {
    if v.is_nan() {
        String::new()
    } else {
        format!("{v}")
    }
}

/// `(min, max)` of the finite values (`(NaN, NaN)` when there are none).
pub fn min_max(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        (f64::NAN, f64::NAN)
    } else {
        (lo, hi)
    }
}

/// `"a–b"` for a range printed with `digits` decimals (one value when they
/// round alike).
pub fn range_text(lo: f64, hi: f64, digits: usize) -> String {
    let (a, b) = (format!("{lo:.digits$}"), format!("{hi:.digits$}"));
    if a == b {
        a
    } else {
        format!("{a}–{b}")
    }
}

/// The median of the values (the upper one of an even count), NaN when empty.
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// A label for a time step: `1/60` for 1/60 s, else the shortest form.
pub fn dt_label(dt: f64) -> String {
    let inv = 1.0 / dt;
    if (inv - inv.round()).abs() < 1e-9 && inv.round() > 1.0 && inv.round() < 1000.0 {
        format!("1/{}", inv.round())
    } else {
        format!("{dt:e}")
    }
}
