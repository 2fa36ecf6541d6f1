//! `pushval track-study`: what online friction estimation costs and how
//! well it does, on the seed paper's pushes (`scenarios/paper-square-v*.toml`:
//! the 0.25 m plate, five 2 s segments at 0.2, 0.6 and 1.0 m/s).
//!
//! Truth: the scenario with μ × 1.1 and I_cm × 0.95 (centre of friction as
//! in the file), the dynamic model's DOP853 trajectory at tolerance 1e-11
//! sampled at the study's rate, plus Gaussian noise (fixed seeds) on x, y
//! and θ. The estimators start from the file's values. Writes into OUT:
//!
//! * `track_cost.csv`: thread CPU time per update (median, 99th
//!   percentile) of each method at 1 kHz, and of the clock call pair itself;
//! * `track_convergence.csv`: per scenario, method, rate (30 Hz to 1 kHz)
//!   and noise (0.1 to 3 mm with as many mrad): the time after which each
//!   estimate stays within 1 % (μ), 1 mm (centre of friction, both
//!   components) or 2 % (I_cm) of the truth, the median over the seeds
//!   (empty when a seed never gets there);
//! * `track_efficiency.csv`: the final estimates' empirical std over
//!   [`SEEDS_EFFICIENCY`] seeds against the Cramér–Rao bound of `pushval
//!   fit`'s Fisher information at the truth, `efficiency = (σ_CRB / σ)²`;
//! * `track_step.csv`: μ stepping by +20 % at t = 5 s (mid-segment) on the
//!   1 m/s push: when the lack-of-fit test fires and when the estimate is
//!   back within 1 % of the new μ, with and without re-opening;
//! * `track_engines.csv`: the filter run on every engine of the build (and
//!   on the dynamic model) on `paper-square-v1.0`: lack-of-fit episodes and
//!   the apparent parameters at each segment's end;
//! * `track.svg` and `track.md` (every number from these files).
//!
//! The study is one pipeline: this module holds what every stage shares
//! (the truth, the methods, the settings grid) and runs the stages in order
//! ([`cli`]); [`measure`] times and scores the estimators on the truth (cost,
//! convergence, efficiency), [`step`] follows a step in μ, [`engines`]
//! tracks every engine, and [`write_up`] draws `track.svg` and writes
//! `track.md` from the stages' rows.

use std::path::{Path, PathBuf};

mod engines;
mod measure;
mod setup;
mod step;
mod write_up;

use anyhow::Context;

use crate::atomic::write_atomic;
use crate::plot;
use engines::engines;
use measure::{convergence, cost, efficiency};
use setup::load;
pub use setup::{
    Grid, Method, BROAD_PRIOR, INERTIA_FACTOR, MU_FACTOR, SCENARIOS, SEEDS_CONVERGENCE,
    SEEDS_EFFICIENCY, STEP, STEP_AT,
};
use step::step;
use write_up::{figure, figure_run, md_text};

/// `pushval track-study`.
pub fn cli(out: &Path, quick: bool) -> anyhow::Result<std::process::ExitCode> {
    let grid = Grid::new(quick);
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    // Timing first, alone.
    let cost_csv = cost(&grid)?;
    let (conv, conv_csv) = convergence(&grid)?;
    let (eff, eff_csv) = efficiency(&grid)?;
    let (steps, step_csv) = step(&grid)?;
    let (eng, eng_csv) = engines()?;
    let sc = load(SCENARIOS[2])?;
    let (hist, points, tr) = figure_run(&sc);
    let step_fig = steps
        .iter()
        .filter(|r| r.reopen)
        .min_by(|a, b| (a.rate - 100.0).abs().total_cmp(&(b.rate - 100.0).abs()))
        .expect("a step row");
    let svg = plot::render(&figure(&sc, &hist, &points, tr, step_fig))?;
    let files: Vec<(PathBuf, String)> = vec![
        (out.join("track_cost.csv"), cost_csv.text().into()),
        (out.join("track_convergence.csv"), conv_csv.text().into()),
        (out.join("track_efficiency.csv"), eff_csv.text().into()),
        (out.join("track_step.csv"), step_csv.text().into()),
        (out.join("track_engines.csv"), eng_csv.text().into()),
        (out.join("track.svg"), svg),
        (
            out.join("track.md"),
            md_text(
                quick,
                grid.seeds_efficiency,
                cost_csv.text(),
                &conv,
                &eff,
                &steps,
                &eng,
            ),
        ),
    ];
    for (p, text) in &files {
        write_atomic(p, text.as_bytes())?;
        println!("wrote {}", p.display());
    }
    Ok(std::process::ExitCode::SUCCESS)
}
