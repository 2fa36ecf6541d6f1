//! An output folder: files written into it atomically (through
//! [`crate::atomic`]) and remembered, figures rendered into it, CSV tables
//! built in memory, and the number formats of its data files. Used by every
//! command that writes a folder of results (`report`, `study`, `stress`,
//! `power`, `fit`, `track`).

use std::path::{Path, PathBuf};

use anyhow::Context;
use serde_json::Value;

use crate::atomic::write_atomic;
use crate::plot;

/// Writes files into the output folder, atomically, and remembers them.
pub struct Writer {
    dir: PathBuf,
    written: Vec<PathBuf>,
    /// Rows of `key_figures.csv`: the figures README.md quotes that are not
    /// a column of a figure's CSV (figure, quantity, value in SI).
    keys: Vec<[String; 3]>,
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
        self.keys
            .push([figure.into(), quantity.into(), format!("{value:.6e}")]);
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
    /// Takes the rows recorded by [`Writer::key`] so far.
    pub fn take_keys(&mut self) -> Vec<[String; 3]> {
        std::mem::take(&mut self.keys)
    }
    /// The files written, in order (consumes the writer).
    pub fn into_written(self) -> Vec<PathBuf> {
        self.written
    }
}

/// A CSV table built in memory with the `csv` crate: one header row, then
/// rows of already formatted fields (each table keeps its own number
/// format); a field is quoted only where it holds a comma, a quote or a
/// line break.
#[derive(Debug)]
pub struct Csv {
    w: csv::Writer<Vec<u8>>,
}

impl Csv {
    pub fn new<S: AsRef<str>>(header: &[S]) -> Self {
        let mut csv = Self {
            w: csv::Writer::from_writer(Vec::new()),
        };
        csv.row(header);
        csv
    }
    pub fn row<S: AsRef<str>>(&mut self, fields: &[S]) {
        // Writing into memory fails only on a full heap.
        self.w
            .write_record(fields.iter().map(|f| f.as_ref()))
            .and_then(|()| self.w.flush().map_err(csv::Error::from))
            .expect("writing CSV into memory");
    }
    pub fn as_bytes(&self) -> &[u8] {
        self.w.get_ref()
    }
    /// The table's text (every field was a `str`).
    pub fn text(&self) -> &str {
        std::str::from_utf8(self.w.get_ref()).expect("CSV of str fields is UTF-8")
    }
}

/// One CSV record as a line of text, quoted as [`Csv`] quotes (for a file
/// that mixes records with `#` comment lines).
pub fn csv_line<S: AsRef<str>>(fields: &[S]) -> String {
    let mut line = Csv {
        w: csv::Writer::from_writer(Vec::new()),
    };
    line.row(fields);
    line.text().to_string()
}

/// One CSV table's rows by column name, as read back from its text.
pub type Records = Vec<std::collections::BTreeMap<String, String>>;

/// Parses CSV text with a header row into [`Records`]; an error names the
/// record that does not parse (a row with another number of fields than
/// the header included).
pub fn records(text: &str) -> anyhow::Result<Records> {
    csv::Reader::from_reader(text.as_bytes())
        .deserialize()
        .map(|r| r.context("reading CSV"))
        .collect()
}

/// The number in column `key` of a record (NaN where blank or absent).
pub fn field_num(r: &std::collections::BTreeMap<String, String>, key: &str) -> f64 {
    r.get(key).and_then(|v| v.parse().ok()).unwrap_or(f64::NAN)
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

/// A number for a JSON document: a finite number, or null (no NaN or
/// infinity is ever written).
pub fn json_num(v: f64) -> Value {
    if v.is_finite() {
        serde_json::json!(v)
    } else {
        Value::Null
    }
}
