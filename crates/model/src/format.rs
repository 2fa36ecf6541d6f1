//! The one trajectory format: what `pushval run` writes (`trajectory.csv`),
//! what `compare`, `fit` and `track` read, and what an outside engine writes
//! on its standard output. One reader ([`Reader`], streaming over any
//! [`BufRead`]; [`read`] collects it per model) and one writer ([`write`]).
//!
//! # Format
//!
//! Comma-separated text, no quoting. The first non-blank line is the
//! header: column names, trimmed, in any order.
//!
//! | column  | unit  | presence | meaning |
//! |---------|-------|----------|---------|
//! | `t`     | s     | required | sample time |
//! | `x`,`y` | m     | required | centre of mass in the world frame |
//! | `theta` | rad   | required | the object's angle, unwrapped |
//! | `omega` | rad/s | optional | angular velocity; when absent, derived from θ ([`derive_omega`]) and the reader says so ([`Header::has_omega`]) |
//! | `model` | text  | optional | which run a row belongs to; a file may hold several runs, and a reader of one run must then be told which (`--model NAME`) |
//!
//! Further columns are ignored (a caller may read some of them as optional
//! numbers, e.g. `track`'s `fx,fy`: [`Reader::extra`]). A column named
//! twice is an error. Every further non-blank line is one row with as many
//! fields as the header; the numbers are finite (`1e-3`, `-0.5`, `3`).
//! Blank lines are skipped. Rows of one model are in time order; rows of
//! several models may interleave.
//!
//! Every error is a [`FormatError`] naming the file, the line (1-based, in
//! the whole text) and, where one field is at fault, the column.
//!
//! The writer writes the header `model,t,x,y,theta,omega` and every number
//! in Rust's shortest round-trip form, so reading a written file gives back
//! the same `f64`s.
//!
//! Why the reader is written here rather than on the `csv` crate (which
//! the tables pushval writes use): an outside engine's output arrives as a
//! framed stream, where a line starting with `#` ends one run and belongs
//! to the protocol, not to the table; the `csv` crate reads such a line as
//! a comment to skip or as a record, never as the end of the input. The
//! reader must also stop at a row cap before buffering a runaway engine's
//! output, and name the line of the whole stream in every error. With no
//! quoting in the format, what remains of a CSV parser is the split on `,`.
//!
//! Why one file of a little over 800 lines: 630 of them are the reader, the
//! writer and the ω derivation, which share the column rules and the error
//! type; the rest are their tests.

use std::io::{self, BufRead, Write};

use crate::Sample;

/// The required columns, in the writer's order.
pub const REQUIRED: [&str; 4] = ["t", "x", "y", "theta"];

/// The header the writer writes.
pub const HEADER: &str = "model,t,x,y,theta,omega";

/// A malformed trajectory text: which file, where and what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FormatError {
    /// The file (a path, `<stdin>`, …); empty when the caller names the
    /// source itself.
    pub file: String,
    /// Line number (1-based); 0 when the fault is the whole text's.
    pub line: usize,
    /// The column, when one field or column is at fault.
    pub column: Option<String>,
    /// What is wrong.
    pub problem: String,
}

impl std::fmt::Display for FormatError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if !self.file.is_empty() {
            write!(f, "{}: ", self.file)?;
        }
        if self.line > 0 {
            write!(f, "line {}: ", self.line)?;
        }
        if let Some(c) = &self.column {
            write!(f, "column `{c}`: ")?;
        }
        write!(f, "{}", self.problem)
    }
}

impl std::error::Error for FormatError {}

/// Which rows a [`Reader`] hands out.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Select {
    /// One run: a second value in the `model` column is an error that lists
    /// the models seen and asks for `--model NAME`.
    #[default]
    One,
    /// Only the rows whose `model` is this name (the others are skipped);
    /// the header must have a `model` column.
    Model(String),
    /// Every row (the caller groups them; [`read`] does).
    All,
}

/// The header of a trajectory text: where each column is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    /// The column names, trimmed, in the text's order.
    pub columns: Vec<String>,
    /// The header's line number (1-based).
    pub line: usize,
    t: usize,
    x: usize,
    y: usize,
    theta: usize,
    omega: Option<usize>,
    model: Option<usize>,
    extra: Vec<Option<usize>>,
}

impl Header {
    /// Whether the text has an `omega` column (else ω is derived from θ).
    pub fn has_omega(&self) -> bool {
        self.omega.is_some()
    }
    /// Whether the text has a `model` column.
    pub fn has_model(&self) -> bool {
        self.model.is_some()
    }
    /// Whether the text has the column `name`.
    pub fn has(&self, name: &str) -> bool {
        self.columns.iter().any(|c| c == name)
    }
}

/// One data row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Line number (1-based).
    pub line: usize,
    /// The `model` field; None without a `model` column.
    pub model: Option<String>,
    /// Time (s).
    pub t: f64,
    /// World x of the centre of mass (m).
    pub x: f64,
    /// World y of the centre of mass (m).
    pub y: f64,
    /// Angle, unwrapped (rad).
    pub theta: f64,
    /// ω (rad/s); None without an `omega` column.
    pub omega: Option<f64>,
    /// The columns of [`Reader::extra`], in its order; None where the header
    /// lacks one.
    pub extra: Vec<Option<f64>>,
}

impl Row {
    /// The row as a sample, ω = `omega` where the text has none.
    pub fn sample(&self, omega: f64) -> Sample {
        Sample {
            t: self.t,
            x: self.x,
            y: self.y,
            theta: self.theta,
            omega: self.omega.unwrap_or(omega),
        }
    }
}

/// The error of a file holding several models read without `--model NAME`.
/// `line` is the first row of the second model.
pub fn several_models(file: &str, line: usize, models: &[String]) -> FormatError {
    FormatError {
        file: file.to_string(),
        line,
        column: Some("model".into()),
        problem: format!(
            "the file holds more than one model ({}); choose one with --model NAME",
            models.join(", ")
        ),
    }
}

/// Reads a trajectory text row by row, as it arrives (an outside engine's
/// standard output, `track`'s standard input).
#[derive(Debug)]
pub struct Reader<R> {
    input: R,
    file: String,
    max_rows: usize,
    select: Select,
    extra: Vec<String>,
    framed: bool,
    header: Option<Header>,
    line: usize,
    rows: usize,
    models: Vec<String>,
    marker: Option<String>,
    done: bool,
    buf: String,
}

impl<R: BufRead> Reader<R> {
    /// A reader of `input`, named `file` in its errors, refusing more than
    /// `max_rows` data rows (every model's rows count).
    pub fn new(input: R, file: impl Into<String>, max_rows: usize) -> Self {
        Self {
            input,
            file: file.into(),
            max_rows,
            select: Select::One,
            extra: Vec::new(),
            framed: false,
            header: None,
            line: 0,
            rows: 0,
            models: Vec::new(),
            marker: None,
            done: false,
            buf: String::new(),
        }
    }

    /// Which rows to hand out (default [`Select::One`]).
    #[must_use]
    pub fn select(mut self, select: Select) -> Self {
        self.select = select;
        self
    }

    /// Further columns to read as optional numbers ([`Row::extra`]).
    #[must_use]
    pub fn extra(mut self, names: &[&str]) -> Self {
        self.extra = names.iter().map(|s| s.to_string()).collect();
        self
    }

    /// Framed text (a session's answer): a line starting with `#` ends the
    /// rows; it is kept in [`Reader::marker`] and the input is read no
    /// further.
    #[must_use]
    pub fn framed(mut self) -> Self {
        self.framed = true;
        self
    }

    /// The name errors give the source.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The line that ended framed rows (`#end`, `#error …`), trimmed.
    pub fn marker(&self) -> Option<&str> {
        self.marker.as_deref()
    }

    /// The models seen so far, in order of first appearance.
    pub fn models(&self) -> &[String] {
        &self.models
    }

    /// Data rows read so far (skipped ones included).
    pub fn rows_read(&self) -> usize {
        self.rows
    }

    fn err(&self, line: usize, column: Option<&str>, problem: String) -> FormatError {
        FormatError {
            file: self.file.clone(),
            line,
            column: column.map(str::to_string),
            problem,
        }
    }

    /// The next non-blank line into `self.buf` (trimmed in place), or false
    /// at the end of the input or of a frame.
    fn next_line(&mut self) -> Result<bool, FormatError> {
        loop {
            if self.done {
                return Ok(false);
            }
            self.buf.clear();
            let n = match self.input.read_line(&mut self.buf) {
                Ok(n) => n,
                Err(e) => return Err(self.err(self.line + 1, None, format!("cannot read ({e})"))),
            };
            if n == 0 {
                self.done = true;
                return Ok(false);
            }
            self.line += 1;
            let text = self.buf.trim();
            if text.is_empty() {
                continue;
            }
            if self.framed && text.starts_with('#') {
                self.marker = Some(text.to_string());
                self.done = true;
                return Ok(false);
            }
            let (a, b) = (self.buf.len() - self.buf.trim_start().len(), text.len());
            self.buf.drain(..a);
            self.buf.truncate(b);
            return Ok(true);
        }
    }

    /// Reads the header if it has not been read; an empty text is an error.
    pub fn header(&mut self) -> Result<&Header, FormatError> {
        if self.header.is_none() {
            if !self.next_line()? {
                return Err(match &self.marker {
                    Some(m) => self.err(self.line, None, format!("`{m}` before the header")),
                    None => self.err(0, None, "no header and no rows (empty)".into()),
                });
            }
            let header = self.parse_header()?;
            self.header = Some(header);
        }
        Ok(self.header.as_ref().expect("just read"))
    }

    fn parse_header(&self) -> Result<Header, FormatError> {
        let line = self.line;
        let columns: Vec<String> = self.buf.split(',').map(|c| c.trim().to_string()).collect();
        for (i, c) in columns.iter().enumerate() {
            if columns[..i].contains(c) {
                return Err(self.err(line, Some(c), "the header names this column twice".into()));
            }
        }
        let find = |n: &str| columns.iter().position(|c| c == n);
        let need = |n: &str| {
            find(n).ok_or_else(|| {
                self.err(
                    line,
                    None,
                    format!(
                        "the header lacks the column `{n}` (need t,x,y,theta; omega, model optional)"
                    ),
                )
            })
        };
        let header = Header {
            t: need("t")?,
            x: need("x")?,
            y: need("y")?,
            theta: need("theta")?,
            omega: find("omega"),
            model: find("model"),
            extra: self.extra.iter().map(|n| find(n)).collect(),
            line,
            columns: columns.clone(),
        };
        if let (Select::Model(m), None) = (&self.select, header.model) {
            return Err(self.err(
                line,
                None,
                format!("--model {m}: the header has no `model` column"),
            ));
        }
        Ok(header)
    }

    /// The next row handed out, or None at the end of the rows.
    pub fn next_row(&mut self) -> Result<Option<Row>, FormatError> {
        self.header()?;
        loop {
            if !self.next_line()? {
                return match &self.select {
                    Select::Model(m) if !self.models.contains(m) => Err(self.err(
                        0,
                        Some("model"),
                        if self.models.is_empty() {
                            format!("no rows of model `{m}`")
                        } else {
                            format!(
                                "no rows of model `{m}` (the file holds {})",
                                self.models.join(", ")
                            )
                        },
                    )),
                    _ => Ok(None),
                };
            }
            if self.rows >= self.max_rows {
                return Err(self.err(
                    self.line,
                    None,
                    format!("more than {} data rows", self.max_rows),
                ));
            }
            self.rows += 1;
            if let Some(row) = self.parse_row()? {
                return Ok(Some(row));
            }
        }
    }

    /// The row in `self.buf`, or None when the selection skips it.
    fn parse_row(&mut self) -> Result<Option<Row>, FormatError> {
        let h = self.header.as_ref().expect("header read");
        let line = self.line;
        let f: Vec<&str> = self.buf.split(',').map(str::trim).collect();
        if f.len() != h.columns.len() {
            return Err(self.err(
                line,
                None,
                format!("{} fields, the header has {}", f.len(), h.columns.len()),
            ));
        }
        let model = h.model.map(|i| f[i]);
        if let Some(name) = model {
            let new = !self.models.iter().any(|m| m == name);
            if new {
                self.models.push(name.to_string());
            }
            match &self.select {
                Select::Model(m) if m != name => return Ok(None),
                Select::One if new && self.models.len() > 1 => {
                    return Err(several_models(&self.file, line, &self.models));
                }
                _ => {}
            }
        }
        let num = |i: usize| -> Result<f64, FormatError> {
            let bad = |problem: String| self.err(line, Some(&h.columns[i]), problem);
            let v: f64 = f[i]
                .parse()
                .map_err(|_| bad(format!("`{}` is not a number", f[i])))?;
            if !v.is_finite() {
                return Err(bad(format!("{v} is not finite")));
            }
            Ok(v)
        };
        Ok(Some(Row {
            line,
            model: model.map(str::to_string),
            t: num(h.t)?,
            x: num(h.x)?,
            y: num(h.y)?,
            theta: num(h.theta)?,
            omega: h.omega.map(num).transpose()?,
            extra: h
                .extra
                .iter()
                .map(|i| i.map(num).transpose())
                .collect::<Result<_, _>>()?,
        }))
    }
}

/// One run of a trajectory text.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Its `model` field; None without a `model` column.
    pub model: Option<String>,
    /// Its samples, ω derived from θ where the text has none.
    pub samples: Vec<Sample>,
    /// Each sample's line number.
    pub lines: Vec<usize>,
}

/// A whole trajectory text, per model.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectories {
    /// The file named in errors.
    pub file: String,
    /// Whether ω was read (true) or derived from θ (false).
    pub omega_read: bool,
    /// The runs, in order of first appearance.
    pub runs: Vec<Run>,
    /// The line of the first row of the second run (for errors).
    second_line: usize,
}

impl Trajectories {
    /// The run `model` names, or the only one when `model` is None. A text
    /// holding several runs and no `model` chosen is [`several_models`].
    pub fn select(&self, model: Option<&str>) -> Result<&Run, FormatError> {
        let names = || -> Vec<String> {
            self.runs
                .iter()
                .filter_map(|r| r.model.clone())
                .collect::<Vec<_>>()
        };
        match model {
            Some(m) => {
                if self.runs.iter().all(|r| r.model.is_none()) {
                    return Err(FormatError {
                        file: self.file.clone(),
                        line: 1,
                        column: None,
                        problem: format!("--model {m}: the header has no `model` column"),
                    });
                }
                self.runs
                    .iter()
                    .find(|r| r.model.as_deref() == Some(m))
                    .ok_or_else(|| FormatError {
                        file: self.file.clone(),
                        line: 0,
                        column: Some("model".into()),
                        problem: format!(
                            "no rows of model `{m}` (the file holds {})",
                            names().join(", ")
                        ),
                    })
            }
            None if self.runs.len() == 1 => Ok(&self.runs[0]),
            None => Err(several_models(&self.file, self.second_line, &names())),
        }
    }
}

/// Reads a whole trajectory text (every model), at most `max_rows` data
/// rows, deriving ω from θ per run where the text has no `omega` column.
/// A text with a header and no rows is an error.
pub fn read<R: BufRead>(
    input: R,
    file: &str,
    max_rows: usize,
) -> Result<Trajectories, FormatError> {
    let mut reader = Reader::new(input, file, max_rows).select(Select::All);
    let omega_read = reader.header()?.has_omega();
    let mut runs: Vec<Run> = Vec::new();
    let mut second_line = 0;
    while let Some(row) = reader.next_row()? {
        let k = match runs.iter().position(|r| r.model == row.model) {
            Some(k) => k,
            None => {
                if runs.len() == 1 {
                    second_line = row.line;
                }
                runs.push(Run {
                    model: row.model.clone(),
                    samples: Vec::new(),
                    lines: Vec::new(),
                });
                runs.len() - 1
            }
        };
        runs[k].samples.push(row.sample(f64::NAN));
        runs[k].lines.push(row.line);
    }
    if runs.is_empty() {
        return Err(FormatError {
            file: file.to_string(),
            line: 0,
            column: None,
            problem: "a header and no data rows".into(),
        });
    }
    if !omega_read {
        for r in &mut runs {
            derive_omega(&mut r.samples);
        }
    }
    Ok(Trajectories {
        file: file.to_string(),
        omega_read,
        runs,
        second_line,
    })
}

/// Reads a whole trajectory text and refuses one holding several models
/// ([`several_models`], listing them all), without keeping its rows: the
/// check a streaming reader of a file makes before it starts.
pub fn require_one_model<R: BufRead>(
    input: R,
    file: &str,
    max_rows: usize,
) -> Result<(), FormatError> {
    let mut reader = Reader::new(input, file, max_rows).select(Select::All);
    let mut second_line = 0;
    while let Some(row) = reader.next_row()? {
        if second_line == 0 && reader.models().len() > 1 {
            second_line = row.line;
        }
    }
    match reader.models() {
        [] | [_] => Ok(()),
        m => Err(several_models(file, second_line, m)),
    }
}

/// Sets every sample's ω from θ over the sample times: second-order finite
/// differences of θ (taken as written: unwrapped), exact for θ quadratic in
/// t on any grid.
///
/// Interior samples take the three-point central difference on the
/// non-uniform grid, with `h₋ = tᵢ − tᵢ₋₁`, `h₊ = tᵢ₊₁ − tᵢ`:
/// `ωᵢ = (h₋² θᵢ₊₁ − h₊² θᵢ₋₁ + (h₊² − h₋²) θᵢ) / (h₋ h₊ (h₋ + h₊))`
/// (on a uniform grid `(θᵢ₊₁ − θᵢ₋₁) / 2h`). The first and the last sample
/// take the one-sided three-point differences of the same order (uniform:
/// `(−3θ₀ + 4θ₁ − θ₂) / 2h`, `(3θₙ − 4θₙ₋₁ + θₙ₋₂) / 2h`). Two samples get
/// their one slope; a lone sample ω = 0. Times must increase strictly
/// (the callers check their grid); otherwise the values are not finite.
pub fn derive_omega(samples: &mut [Sample]) {
    let n = samples.len();
    match n {
        0 => return,
        1 => {
            samples[0].omega = 0.0;
            return;
        }
        2 => {
            let w = (samples[1].theta - samples[0].theta) / (samples[1].t - samples[0].t);
            samples[0].omega = w;
            samples[1].omega = w;
            return;
        }
        _ => {}
    }
    // (h₋, h₊, θ₋, θ, θ₊) → dθ/dt at the middle, the left and the right point.
    let mid = |a: f64, b: f64, tm: f64, t0: f64, tp: f64| {
        (a * a * tp - b * b * tm + (b * b - a * a) * t0) / (a * b * (a + b))
    };
    let left = |a: f64, b: f64, t0: f64, t1: f64, t2: f64| {
        -(2.0 * a + b) / (a * (a + b)) * t0 + (a + b) / (a * b) * t1 - a / (b * (a + b)) * t2
    };
    let right = |a: f64, b: f64, t0: f64, t1: f64, t2: f64| {
        b / (a * (a + b)) * t0 - (a + b) / (a * b) * t1 + (a + 2.0 * b) / (b * (a + b)) * t2
    };
    let th: Vec<(f64, f64)> = samples.iter().map(|s| (s.t, s.theta)).collect();
    let h = |i: usize| th[i + 1].0 - th[i].0;
    samples[0].omega = left(h(0), h(1), th[0].1, th[1].1, th[2].1);
    for i in 1..n - 1 {
        samples[i].omega = mid(h(i - 1), h(i), th[i - 1].1, th[i].1, th[i + 1].1);
    }
    samples[n - 1].omega = right(h(n - 3), h(n - 2), th[n - 3].1, th[n - 2].1, th[n - 1].1);
}

/// Writes runs in the format: the header [`HEADER`], then each run's samples
/// in order, one row per sample.
pub fn write<W: Write>(out: &mut W, runs: &[(&str, &[Sample])]) -> io::Result<()> {
    write_with(out, runs, &[], |_| Vec::new())
}

/// [`write`] with further columns `names` after the format's own, their
/// values for each sample from `extra` (one per name, shortest round-trip
/// form): e.g. the push applied at each sample of a closed loop.
pub fn write_with<W: Write>(
    out: &mut W,
    runs: &[(&str, &[Sample])],
    names: &[&str],
    extra: impl Fn(&Sample) -> Vec<f64>,
) -> io::Result<()> {
    write!(out, "{HEADER}")?;
    for n in names {
        write!(out, ",{n}")?;
    }
    writeln!(out)?;
    for (name, samples) in runs {
        for p in *samples {
            write!(
                out,
                "{name},{},{},{},{},{}",
                p.t, p.x, p.y, p.theta, p.omega
            )?;
            for v in extra(p) {
                write!(out, ",{v}")?;
            }
            writeln!(out)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Trajectories, FormatError> {
        read(text.as_bytes(), "f.csv", 100)
    }

    /// θ = a t² has ω = 2 a t; second-order differences are exact for a
    /// quadratic on any grid, so every sample (ends included) matches to
    /// round-off, here on a non-uniform grid.
    #[test]
    fn derived_omega_is_exact_for_a_quadratic() {
        let a = 0.7;
        let times = [0.0, 0.1, 0.25, 0.3, 0.5, 0.55, 0.9, 1.0];
        let mut s: Vec<Sample> = times
            .iter()
            .map(|&t| Sample {
                t,
                theta: a * t * t,
                ..Default::default()
            })
            .collect();
        derive_omega(&mut s);
        for p in &s {
            assert!((p.omega - 2.0 * a * p.t).abs() < 1e-12, "{p:?}");
        }
    }

    /// A cubic is not exact: the error at interior points of a uniform grid
    /// is h² θ'''/6 = h² b for θ = b t³ (Taylor), so halving h quarters it.
    #[test]
    fn derived_omega_is_second_order() {
        let b = 1.3;
        let err = |n: usize| {
            let h = 1.0 / n as f64;
            let mut s: Vec<Sample> = (0..=n)
                .map(|i| {
                    let t = i as f64 * h;
                    Sample {
                        t,
                        theta: b * t.powi(3),
                        ..Default::default()
                    }
                })
                .collect();
            derive_omega(&mut s);
            let i = n / 2;
            let exact = 3.0 * b * s[i].t * s[i].t;
            assert!((s[i].omega - exact - h * h * b).abs() < 1e-9);
            s[i].omega - exact
        };
        assert!((err(20) / err(40) - 4.0).abs() < 1e-6);
    }

    #[test]
    fn omega_and_model_are_optional_and_extra_columns_ignored() {
        let full = parse("model,t,x,y,theta,omega,note\nm,0,1,2,3,4,a\nm,1,1,2,5,6,b\n").unwrap();
        assert!(full.omega_read);
        let r = full.select(None).unwrap();
        assert_eq!(r.model.as_deref(), Some("m"));
        assert_eq!(r.samples[1].omega, 6.0);
        let bare = parse(" theta , t,y,x\n3,0,2,1\n5,1,2,1\n").unwrap();
        assert!(!bare.omega_read);
        let r = bare.select(None).unwrap();
        assert_eq!(r.model, None);
        assert_eq!((r.samples[0].x, r.samples[0].y), (1.0, 2.0));
        assert_eq!(r.samples[0].omega, 2.0);
        assert_eq!(r.lines, vec![2, 3]);
    }

    #[test]
    fn errors_name_the_file_the_line_and_the_column() {
        let e = parse("t,x,y,theta\n0,0,0,0\n\n1,0,abc,0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "f.csv: line 4: column `y`: `abc` is not a number"
        );
        let e = parse("t,x,y,theta\n0,0,0,inf\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "f.csv: line 2: column `theta`: inf is not finite"
        );
        let e = parse("t,x,theta,omega\n0,0,0,0\n").unwrap_err();
        assert!(e
            .to_string()
            .starts_with("f.csv: line 1: the header lacks the column `y`"));
        let e = parse("t,x,y,theta\n0,0,0\n").unwrap_err();
        assert_eq!(e.to_string(), "f.csv: line 2: 3 fields, the header has 4");
        let e = parse("t,x,y,theta,x\n").unwrap_err();
        assert_eq!(e.line, 1);
        assert_eq!(e.column.as_deref(), Some("x"));
        assert!(parse("").unwrap_err().to_string().contains("empty"));
        assert!(parse("t,x,y,theta\n")
            .unwrap_err()
            .to_string()
            .contains("no data rows"));
        let e = read(
            "t,x,y,theta\n0,0,0,0\n1,0,0,0\n2,0,0,0\n".as_bytes(),
            "f",
            2,
        )
        .unwrap_err();
        assert_eq!(e.to_string(), "f: line 4: more than 2 data rows");
    }

    #[test]
    fn several_models_need_a_name() {
        let text = "model,t,x,y,theta\na,0,0,0,0\nb,0,0,0,1\na,1,0,0,0\nc,0,0,0,0\n";
        let all = parse(text).unwrap();
        assert_eq!(all.runs.len(), 3);
        assert_eq!(all.select(Some("a")).unwrap().samples.len(), 2);
        let e = all.select(None).unwrap_err();
        assert_eq!(
            require_one_model(text.as_bytes(), "f.csv", 100),
            Err(e.clone())
        );
        assert_eq!(
            require_one_model(&text.as_bytes()[..28], "f.csv", 100),
            Ok(())
        );
        assert_eq!(
            e.to_string(),
            "f.csv: line 3: column `model`: the file holds more than one model (a, b, c); choose one with --model NAME"
        );
        assert!(all
            .select(Some("z"))
            .unwrap_err()
            .to_string()
            .contains("no rows of model `z` (the file holds a, b, c)"));
        // Streaming: the second model stops the reader at once.
        let mut r = Reader::new(text.as_bytes(), "f.csv", 100);
        assert!(r.next_row().unwrap().is_some());
        assert_eq!(
            r.next_row().unwrap_err(),
            several_models("f.csv", 3, &["a".into(), "b".into()])
        );
        let mut r = Reader::new(text.as_bytes(), "f.csv", 100).select(Select::Model("b".into()));
        assert_eq!(r.next_row().unwrap().unwrap().line, 3);
        assert_eq!(r.next_row().unwrap(), None);
    }

    #[test]
    fn framed_rows_end_at_a_marker() {
        let text = "t,x,y,theta,omega\n0,0,0,0,0\n#end\nt,x,y,theta\n";
        let mut input = text.as_bytes();
        let mut r = Reader::new(&mut input, "", 10).framed();
        assert!(r.next_row().unwrap().is_some());
        assert_eq!(r.next_row().unwrap(), None);
        assert_eq!(r.marker(), Some("#end"));
        drop(r);
        assert_eq!(input, b"t,x,y,theta\n");
    }

    #[test]
    fn extra_columns_are_read_when_asked() {
        let mut r =
            Reader::new("t,x,y,theta,fx\n0,0,0,0,2.5\n".as_bytes(), "f", 10).extra(&["fx", "fy"]);
        assert!(r.header().unwrap().has("fx"));
        assert_eq!(r.next_row().unwrap().unwrap().extra, vec![Some(2.5), None]);
    }

    #[test]
    fn written_text_reads_back_bit_for_bit() {
        let s: Vec<Sample> = (0..5)
            .map(|i| {
                let t = i as f64 * 0.1;
                Sample {
                    t,
                    x: t.sin(),
                    y: -1.0 / 3.0,
                    theta: t * 1e-17,
                    omega: 1e300,
                }
            })
            .collect();
        let mut out = Vec::new();
        write(&mut out, &[("dynamic", &s), ("other", &s[..2])]).unwrap();
        let back = read(out.as_slice(), "f", 100).unwrap();
        assert_eq!(back.select(Some("dynamic")).unwrap().samples, s);
        assert_eq!(back.select(Some("other")).unwrap().samples, s[..2]);
    }
}
