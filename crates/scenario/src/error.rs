use std::path::PathBuf;
use thiserror::Error;

/// A scenario that cannot be used: which file, which key, what was wrong.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{}: {key}: {message}", file.display())]
pub struct ScenarioError {
    /// The scenario file (or `<string>` for text not read from a file).
    pub file: PathBuf,
    /// Dotted key path, e.g. `object.mass` or `push[2].duration`; `toml` for
    /// syntax errors.
    pub key: String,
    /// What was wrong, with the offending value.
    pub message: String,
}

impl ScenarioError {
    /// An error about `key` of `file`.
    pub fn new(file: &std::path::Path, key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            file: file.to_path_buf(),
            key: key.into(),
            message: message.into(),
        }
    }
}
