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
    /// Takes the rows recorded by [`Writer::key`] so far.
    pub fn take_keys(&mut self) -> Vec<String> {
        std::mem::take(&mut self.keys)
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

/// A number for a JSON document: a finite number, or null (no NaN or
/// infinity is ever written).
pub fn json_num(v: f64) -> Value {
    if v.is_finite() {
        serde_json::json!(v)
    } else {
        Value::Null
    }
}
