//! An outside engine's standard output, read in pushval's one trajectory
//! format ([`pushval_model::format`], which `compare`, `fit` and `track`
//! read too): header with `t,x,y,theta` required, `omega` optional (derived
//! from θ when absent), `model` optional (one model only), further columns
//! ignored but three: `rise` (m, the centre of mass above its resting
//! height) and `load_1`, …, `load_n` (N, each support's normal force), which
//! an engine that measures them may add and pushval reads ([`Record::rise`],
//! [`Record::loads`]), and `steps` (the engine steps the row's interval
//! took, where rows are not one per step: the kit writes it on rows at the
//! sample times; [`Record::steps`]). Errors name the line and the column.

use std::io::BufRead;

pub use pushval_model::format::FormatError as CsvError;
use pushval_model::format::{derive_omega, Reader};

/// The most rows one run's output may hold (a step per row: 10 s at
/// dt = 1e-6 s); past it the output is refused as malformed.
pub const MAX_ROWS: usize = 10_000_000;

/// One data row of an engine's output.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// Line number in the output (1-based).
    pub line: usize,
    /// `t, x, y, theta, omega`; ω derived from θ when the output has no
    /// `omega` column.
    pub numbers: [f64; 5],
    /// The row's `rise` (m), where the output has the column.
    pub rise: Option<f64>,
    /// The row's `load_1..load_n` (N), where the output has every one of
    /// the problem's supports.
    pub loads: Option<Vec<f64>>,
    /// The engine steps between the row before and this one, where the
    /// output has the column `steps` (rows at the sample times); without
    /// it, a row is one step.
    pub steps: Option<f64>,
}

/// Reads a whole output text (at most [`MAX_ROWS`] rows) of a problem with
/// `supports` supports.
pub fn read(text: &str, supports: usize) -> Result<Vec<Record>, CsvError> {
    read_from(text.as_bytes(), MAX_ROWS, supports)
}

/// Reads an output as it arrives from `input`, at most `max_rows` rows, of
/// a problem with `supports` supports.
pub fn read_from<R: BufRead>(
    input: R,
    max_rows: usize,
    supports: usize,
) -> Result<Vec<Record>, CsvError> {
    let names: Vec<String> = std::iter::once("rise".to_string())
        .chain((1..=supports).map(|i| format!("load_{i}")))
        .chain(std::iter::once("steps".to_string()))
        .collect();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut reader = Reader::new(input, "", max_rows).extra(&refs);
    let has_omega = reader.header()?.has_omega();
    let mut rows = Vec::new();
    let mut samples = Vec::new();
    while let Some(row) = reader.next_row()? {
        samples.push(row.sample(f64::NAN));
        let loads: Option<Vec<f64>> = row.extra[1..=supports].iter().copied().collect();
        rows.push((
            row.line,
            row.extra[0],
            loads.filter(|l| !l.is_empty()),
            row.extra[supports + 1],
        ));
    }
    if !has_omega {
        derive_omega(&mut samples);
    }
    Ok(rows
        .into_iter()
        .zip(samples)
        .map(|((line, rise, loads, steps), s)| Record {
            line,
            numbers: [s.t, s.x, s.y, s.theta, s.omega],
            rise,
            loads,
            steps,
        })
        .collect())
}
