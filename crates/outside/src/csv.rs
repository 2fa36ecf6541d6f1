//! An outside engine's standard output, read in pushval's one trajectory
//! format ([`pushval_model::format`], which `compare`, `fit` and `track`
//! read too): header with `t,x,y,theta` required, `omega` optional (derived
//! from θ when absent), `model` optional (one model only), further columns
//! ignored. Errors name the line and the column.

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
}

/// Reads a whole output text (at most [`MAX_ROWS`] rows).
pub fn read(text: &str) -> Result<Vec<Record>, CsvError> {
    read_from(text.as_bytes(), MAX_ROWS)
}

/// Reads an output as it arrives from `input`, at most `max_rows` rows.
pub fn read_from<R: BufRead>(input: R, max_rows: usize) -> Result<Vec<Record>, CsvError> {
    let mut reader = Reader::new(input, "", max_rows);
    let has_omega = reader.header()?.has_omega();
    let mut lines = Vec::new();
    let mut samples = Vec::new();
    while let Some(row) = reader.next_row()? {
        lines.push(row.line);
        samples.push(row.sample(f64::NAN));
    }
    if !has_omega {
        derive_omega(&mut samples);
    }
    Ok(lines
        .into_iter()
        .zip(samples)
        .map(|(line, s)| Record {
            line,
            numbers: [s.t, s.x, s.y, s.theta, s.omega],
        })
        .collect())
}
