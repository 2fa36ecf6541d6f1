//! `pushval.toml`: the outside engines a project declares.

use std::path::{Path, PathBuf};

/// The order of accuracy in dt the ladder assumes when `order` is absent.
pub const DEFAULT_ORDER: f64 = 1.0;
/// The step (s) when the engine is not gated and the scenario sets none.
pub const DEFAULT_DT: f64 = 1e-3;
/// The per-run limit (s) when `timeout_s` is absent.
pub const DEFAULT_TIMEOUT_S: f64 = 120.0;

/// The keys an `[engine.NAME]` table may hold.
const KEYS: &[&str] = &[
    "command",
    "order",
    "dt",
    "timeout_s",
    "version",
    "law",
    "law_params",
    "protocol",
    "session",
    "rows",
];

/// The protocol version when `protocol` is absent and `session` is not set.
pub const DEFAULT_PROTOCOL: u32 = 1;
/// The protocol version when `protocol` is absent and `session = true`:
/// stepping (start, advance, finish), so the engine can be a plant.
pub const DEFAULT_SESSION_PROTOCOL: u32 = 3;

/// Which rows a protocol 3 session asks the adapter for (`rows` in
/// `[engine.NAME]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rows {
    /// The rows at the problem's sample times and at each push's end only
    /// (the default): the gate reads poses at the sample times and ω
    /// steady at a segment's end, so it needs no row in between. An adapter
    /// may still write every step (the kit does when its engine writes
    /// load columns, whose per-step values the contact record reads).
    Samples,
    /// One row per engine step.
    Steps,
}

impl Rows {
    /// The document's value: `"samples"` or `"steps"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Rows::Samples => "samples",
            Rows::Steps => "steps",
        }
    }
}

/// One outside engine as `pushval.toml` declares it.
#[derive(Debug, Clone, PartialEq)]
pub struct Spec {
    /// The model name scenarios use (the table's name).
    pub name: String,
    /// The program and its arguments, run from [`Spec::dir`].
    pub command: Vec<String>,
    /// The folder of the file that declared it (the process's working
    /// directory).
    pub dir: PathBuf,
    /// The file that declared it.
    pub file: PathBuf,
    /// The order of accuracy in dt the ladder assumes (> 0).
    pub order: f64,
    /// The step when the engine is not gated and the scenario sets none (s).
    pub dt: f64,
    /// Per run (s); past it the process is killed and the run is an error.
    pub timeout_s: f64,
    /// What `pushval engines` and `summary.json` show as the engine's
    /// version; None when the file gives none.
    pub version: Option<String>,
    /// The friction law in closed form the engine follows, by name (one of
    /// the laws of `pushval::registry::laws`; an unknown name is refused
    /// naming the known ones); None when the file names none.
    pub law: Option<String>,
    /// The `pushval-problem/N` version the process reads: 1 (the default
    /// without `session`), 2 (`switching` and `limits` in the document) or
    /// 3 (stepping: a session of `start`, `advance` and `finish` requests;
    /// the default with `session = true`).
    pub protocol: u32,
    /// One process serves many problems (`session = true`, protocol 2 or
    /// 3): one document per line in, each with a request number, each
    /// answer closed by `#end N`, `#ok N` or `#error N MESSAGE`; default
    /// false (one process per run).
    pub session: bool,
    /// The rows a protocol 3 session asks for (`rows = "samples"`, the
    /// default, or `"steps"`); ignored by protocols 1 and 2, which write
    /// one row per step.
    pub rows: Rows,
    /// The law's parameters (`law_params = { key = value }`: numbers and
    /// strings), checked against the law when the registry loads the file;
    /// empty when the file gives none.
    pub law_params: serde_json::Map<String, serde_json::Value>,
}

impl Spec {
    /// The command as one line, for messages (arguments with spaces quoted).
    pub fn command_line(&self) -> String {
        self.command
            .iter()
            .map(|a| {
                if a.is_empty() || a.contains(char::is_whitespace) {
                    format!("\"{a}\"")
                } else {
                    a.clone()
                }
            })
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// The program to start: a path with a `/` is taken relative to
    /// [`Spec::dir`]; a bare name is looked up on `PATH`.
    pub fn program(&self) -> PathBuf {
        let p = Path::new(&self.command[0]);
        if p.is_relative() && self.command[0].contains('/') {
            self.dir.join(p)
        } else {
            p.to_path_buf()
        }
    }

    /// `Ok` when the program exists (on `PATH` for a bare name), else why
    /// not and how to get it.
    pub fn availability(&self) -> Result<(), String> {
        let program = self.program();
        let found = if self.command[0].contains('/') {
            program.is_file()
        } else {
            std::env::var_os("PATH").is_some_and(|path| {
                std::env::split_paths(&path).any(|d| d.join(&program).is_file())
            })
        };
        if found {
            return Ok(());
        }
        let how = if self.command[0].starts_with("python") {
            "; install Python 3 (e.g. `apt-get install python3`)"
        } else if self.command[0].contains(".venv-adapters")
            // The project's own script (pushval's repository has one), never
            // a path the user's project lacks.
            && self.dir.join("scripts/setup-adapters.sh").is_file()
        {
            "; create it with scripts/setup-adapters.sh"
        } else {
            ""
        };
        Err(format!(
            "`{}` not found ({} [engine.{}] command){how}",
            if self.command[0].contains('/') {
                program.display().to_string()
            } else {
                format!("{} on PATH", self.command[0])
            },
            self.file.display(),
            self.name
        ))
    }
}

/// The engines of one `pushval.toml`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Config {
    /// The file read.
    pub file: PathBuf,
    /// Its engines, in file order.
    pub engines: Vec<Spec>,
}

/// A bad `pushval.toml`: the file, the key and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConfigError {
    /// The file.
    pub file: PathBuf,
    /// The key, e.g. `engine.mysim.command`.
    pub key: String,
    /// What is wrong with it.
    pub problem: String,
}

impl std::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}: {}", self.file.display(), self.key, self.problem)
    }
}

impl std::error::Error for ConfigError {}

impl Config {
    /// Reads and checks a `pushval.toml`.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, ConfigError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError {
            file: path.to_path_buf(),
            key: "file".into(),
            problem: format!("cannot read: {e}"),
        })?;
        Self::from_toml(&text, path)
    }

    /// Parses and checks `pushval.toml` text; `file` names it in errors and
    /// its folder is where the commands run.
    pub fn from_toml(text: &str, file: &Path) -> Result<Self, ConfigError> {
        let err = |key: &str, problem: String| ConfigError {
            file: file.to_path_buf(),
            key: key.into(),
            problem,
        };
        let table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| err("file", format!("not valid TOML: {e}")))?;
        let dir = match file.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let dir = std::path::absolute(&dir).unwrap_or(dir);
        let mut engines = Vec::new();
        for (key, value) in &table {
            if key != "engine" {
                return Err(err(
                    key,
                    "unknown key; pushval.toml holds only [engine.NAME] tables".into(),
                ));
            }
            let Some(tables) = value.as_table() else {
                return Err(err(
                    "engine",
                    "must be a table of [engine.NAME] tables".into(),
                ));
            };
            for (name, t) in tables {
                engines.push(spec(name, t, file, &dir)?);
            }
        }
        Ok(Self {
            file: file.to_path_buf(),
            engines,
        })
    }
}

/// One `[engine.NAME]` table checked.
fn spec(name: &str, value: &toml::Value, file: &Path, dir: &Path) -> Result<Spec, ConfigError> {
    let prefix = format!("engine.{name}");
    let err = |key: &str, problem: String| ConfigError {
        file: file.to_path_buf(),
        key: if key.is_empty() {
            prefix.clone()
        } else {
            format!("{prefix}.{key}")
        },
        problem,
    };
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(err(
            "",
            "an engine name is letters, digits, `_` and `-` only".into(),
        ));
    }
    let Some(t) = value.as_table() else {
        return Err(err("", "must be a table".into()));
    };
    for k in t.keys() {
        if !KEYS.contains(&k.as_str()) {
            return Err(err(k, format!("unknown key; known: {}", KEYS.join(", "))));
        }
    }
    let command: Vec<String> = match t.get("command") {
        None => {
            return Err(err(
                "command",
                "missing: the program and its arguments, e.g. [\"python3\", \"adapter.py\"]".into(),
            ))
        }
        Some(toml::Value::Array(a)) => a
            .iter()
            .map(|v| {
                v.as_str()
                    .map(String::from)
                    .ok_or_else(|| err("command", format!("must be an array of strings, got {v}")))
            })
            .collect::<Result<_, _>>()?,
        Some(v) => {
            return Err(err(
                "command",
                format!("must be an array of strings, got {v}"),
            ))
        }
    };
    if command.first().is_none_or(|p| p.trim().is_empty()) {
        return Err(err("command", "must name a program first".into()));
    }
    let number = |key: &str, default: f64| -> Result<f64, ConfigError> {
        match t.get(key) {
            None => Ok(default),
            Some(v) => {
                let x = v
                    .as_float()
                    .or_else(|| v.as_integer().map(|i| i as f64))
                    .ok_or_else(|| err(key, format!("must be a number, got {v}")))?;
                if x.is_finite() && x > 0.0 {
                    Ok(x)
                } else {
                    Err(err(key, format!("must be finite and > 0, got {x}")))
                }
            }
        }
    };
    let version = match t.get("version") {
        None => None,
        Some(toml::Value::String(s)) => Some(s.clone()),
        Some(v) => return Err(err("version", format!("must be a string, got {v}"))),
    };
    let law = match t.get("law") {
        None => None,
        Some(toml::Value::String(s)) => Some(s.clone()),
        Some(v) => return Err(err("law", format!("must be a string, got {v}"))),
    };
    let law_params = match t.get("law_params") {
        None => serde_json::Map::new(),
        Some(toml::Value::Table(p)) => {
            if law.is_none() {
                return Err(err(
                    "law_params",
                    "parameters of no law: set `law` as well".into(),
                ));
            }
            p.iter()
                .map(|(k, v)| {
                    let json = match v {
                        toml::Value::Float(x) => serde_json::Number::from_f64(*x)
                            .map(serde_json::Value::Number)
                            .ok_or_else(|| {
                                err(
                                    &format!("law_params.{k}"),
                                    format!("must be finite, got {x}"),
                                )
                            })?,
                        toml::Value::Integer(i) => serde_json::Value::from(*i),
                        toml::Value::String(s) => serde_json::Value::from(s.as_str()),
                        other => {
                            return Err(err(
                                &format!("law_params.{k}"),
                                format!("must be a number or a string, got {other}"),
                            ))
                        }
                    };
                    Ok((k.clone(), json))
                })
                .collect::<Result<_, _>>()?
        }
        Some(v) => {
            return Err(err(
                "law_params",
                format!(
                "must be a table of the law's parameters, e.g. {{ slip_speed = 0.01 }}, got {v}"
            ),
            ))
        }
    };
    let session = match t.get("session") {
        None => false,
        Some(toml::Value::Boolean(b)) => *b,
        Some(v) => return Err(err("session", format!("must be true or false, got {v}"))),
    };
    let protocol = match t.get("protocol") {
        None if session => DEFAULT_SESSION_PROTOCOL,
        None => DEFAULT_PROTOCOL,
        Some(toml::Value::Integer(n @ (1..=3))) => *n as u32,
        Some(v) => {
            return Err(err(
                "protocol",
                format!(
                    "must be 1 (pushval-problem/1), 2 (pushval-problem/2) or 3 (stepping sessions), got {v}"
                ),
            ))
        }
    };
    if session && protocol < 2 {
        return Err(err(
            "protocol",
            "session = true needs protocol 2 or 3 (a protocol 1 adapter reads one document to the end of its standard input and never answers a session)".into(),
        ));
    }
    if !session && protocol == 3 {
        return Err(err(
            "protocol",
            "protocol 3 (stepping) runs in a session: set session = true as well".into(),
        ));
    }
    let rows = match t.get("rows") {
        None => Rows::Samples,
        Some(toml::Value::String(s)) if s == "samples" => Rows::Samples,
        Some(toml::Value::String(s)) if s == "steps" => Rows::Steps,
        Some(v) => {
            return Err(err(
                "rows",
                format!("must be \"samples\" or \"steps\", got {v}"),
            ))
        }
    };
    Ok(Spec {
        law,
        law_params,
        protocol,
        session,
        rows,
        name: name.to_string(),
        command,
        dir: dir.to_path_buf(),
        file: file.to_path_buf(),
        order: number("order", DEFAULT_ORDER)?,
        dt: number("dt", DEFAULT_DT)?,
        timeout_s: number("timeout_s", DEFAULT_TIMEOUT_S)?,
        version,
    })
}
