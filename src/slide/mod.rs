//! `pushval slide-study`: the plate thrown on a grid of throws (speed, spin,
//! direction) in every engine of the build that can let go, each engine's
//! rest pose and stop time against the dynamic model's; writes
//! `results/slide/` (or `--out DIR`): `throws.csv` (one row per engine, step
//! and throw), `engines.csv` (one row per engine: its declared law, whether
//! it released), `disc.csv` (the thrown disc's ratio v/(Rω) near the stop,
//! one row per engine: see the `disc` module), `rest.svg` and a generated
//! `README.md`.
//!
//! The scene is the shipped `thrown-square` scenario's plate (the seed's
//! 0.25 m square, 1 kg, μ 0.5 on its four corners); each throw replaces its
//! `[initial]` velocity and spin. Every engine runs at its default step h
//! and at h/2: a gap to the model that halves with the step is the step's
//! (first order, as the slide's friction is integrated once per step); a gap
//! that stays is the engine's friction law's.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::outdir::Writer;

mod disc;
mod measure;
mod write_up;

pub use disc::*;
pub use measure::*;

/// `pushval slide-study`: measures and writes the folder whole (into a
/// fresh folder renamed into place: a failed run leaves the old one).
pub fn cli(out: &Path, quick: bool) -> anyhow::Result<ExitCode> {
    let study = measure(quick)?;
    let fresh = crate::atomic::FreshDir::new(out)?;
    let mut w = Writer::new(fresh.path())?;
    let throws = throws_csv(&study);
    w.file("throws.csv", throws.as_bytes())?;
    w.file("engines.csv", engines_csv(&study).as_bytes())?;
    w.file("disc.csv", disc_csv(&study.disc).as_bytes())?;
    w.figure("rest.svg", &write_up::figure(&study))?;
    w.file("README.md", write_up::readme(&study).as_bytes())?;
    let names: Vec<PathBuf> = w
        .into_written()
        .iter()
        .filter_map(|p| p.file_name().map(|n| out.join(n)))
        .collect();
    fresh.commit()?;
    for p in names {
        println!("wrote {}", p.display());
    }
    Ok(ExitCode::SUCCESS)
}
