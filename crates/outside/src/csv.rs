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

/// The first character of a compact line (protocol 3): the rows that
/// follow it as hexadecimal little-endian IEEE 754 binary64 numbers.
pub const COMPACT: char = '!';

/// Where the columns pushval reads sit in a header.
#[derive(Debug, Clone)]
pub struct Columns {
    count: usize,
    at: [usize; 5],
    rise: Option<usize>,
    loads: Option<Vec<usize>>,
    steps: Option<usize>,
}

impl Columns {
    /// The columns of `header` (comma-separated names) for a problem with
    /// `supports` supports: `t,x,y,theta,omega` required (compact rows
    /// carry ω), `rise`, every `load_i` and `steps` read where present.
    pub fn of(header: &str, supports: usize) -> Result<Self, String> {
        // Split as the text rows' header is ([`pushval_model::format`]:
        // names between commas, trimmed, never quoted), not with a CSV
        // reader: an answer is a stream of lines (text rows, compact lines,
        // `#end N`) read as it arrives under a cap, and one header must mean
        // the same columns to both kinds of row.
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        for (i, n) in names.iter().enumerate() {
            if names[..i].contains(n) {
                return Err(format!("the header names the column `{n}` twice"));
            }
        }
        let find = |n: &str| names.iter().position(|c| *c == n);
        let mut at = [0; 5];
        for (slot, n) in at.iter_mut().zip(["t", "x", "y", "theta", "omega"]) {
            *slot = find(n).ok_or_else(|| {
                format!("the header lacks the column `{n}` (compact rows need t,x,y,theta,omega)")
            })?;
        }
        let loads: Option<Vec<usize>> =
            (1..=supports).map(|i| find(&format!("load_{i}"))).collect();
        Ok(Self {
            count: names.len(),
            at,
            rise: find("rise"),
            loads: loads.filter(|l| !l.is_empty()),
            steps: find("steps"),
        })
    }
}

/// Reads one compact line (after its [`COMPACT`] mark: hexadecimal digits,
/// 16 per number, whole rows of `columns.count` numbers), numbering its
/// rows' `line` as `line`. Every number must be finite.
pub fn read_compact(hex: &str, columns: &Columns, line: usize) -> Result<Vec<Record>, String> {
    let hex = hex.trim().as_bytes();
    let width = 16 * columns.count;
    if hex.len() % width != 0 {
        return Err(format!(
            "line {line}: a compact line of {} hexadecimal digits is not whole rows of {} numbers (16 digits each)",
            hex.len(),
            columns.count
        ));
    }
    let digit = |b: u8| match b {
        b'0'..=b'9' => Some(b - b'0'),
        b'a'..=b'f' => Some(b - b'a' + 10),
        b'A'..=b'F' => Some(b - b'A' + 10),
        _ => None,
    };
    let mut values = Vec::with_capacity(hex.len() / 16);
    for (k, chunk) in hex.chunks_exact(16).enumerate() {
        let mut bytes = [0u8; 8];
        for (i, b) in bytes.iter_mut().enumerate() {
            let (hi, lo) = (digit(chunk[2 * i]), digit(chunk[2 * i + 1]));
            *b = match (hi, lo) {
                (Some(h), Some(l)) => h << 4 | l,
                _ => {
                    return Err(format!(
                        "line {line}: number {} of the compact line is not hexadecimal",
                        k + 1
                    ))
                }
            };
        }
        values.push(f64::from_le_bytes(bytes));
    }
    let names = ["t", "x", "y", "theta", "omega"];
    values
        .chunks_exact(columns.count)
        .enumerate()
        .map(|(r, row)| {
            if let Some(c) = row.iter().position(|v| !v.is_finite()) {
                let name = columns.at.iter().position(|&a| a == c).map_or_else(
                    || format!("column {}", c + 1),
                    |i| format!("column `{}`", names[i]),
                );
                return Err(format!(
                    "line {line}, row {} of the compact line: {name}: {} is not finite",
                    r + 1,
                    row[c]
                ));
            }
            Ok(Record {
                line,
                numbers: columns.at.map(|i| row[i]),
                rise: columns.rise.map(|i| row[i]),
                loads: columns
                    .loads
                    .as_ref()
                    .map(|l| l.iter().map(|&i| row[i]).collect()),
                steps: columns.steps.map(|i| row[i]),
            })
        })
        .collect()
}
