//! What a study varies, as data: `studies/MODEL.toml` (optional; every key
//! has a default, so a model without a file, an outside engine included,
//! still gets the whole study).
//!
//! ```toml
//! about = "what the study shows, one paragraph of the README"
//! dt = 1e-3               # s: step of the table and the maps (default: the engine's)
//! t_run = 6.0             # s: length of every run
//! tail = 0.2              # share of a run (its end) over which ω is averaged
//! ladder = [4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4]   # s: the step ladder (default: dt × 4 … 1/4)
//! ladder_quick = [2e-3, 1e-3, 5e-4]           # s: the same for --quick (default: dt × 2 … 1/2)
//! fit = true              # fit the Coulomb model to the engine (default true)
//! engine = { substeps = 4 }                   # [engine] options of every run
//!
//! [[variant]]             # a further table (and map) with other options or supports
//! name = "separate"
//! engine = { contacts = "separate" }          # over the study's own options
//! supports_half = 0.05    # m: supports on a square of this half side (default: the plate's corners)
//! phi = 1.585             # rad: direction of its table (default π/4 + 0.3)
//! dt = 0.0166667          # s: its step (default the study's)
//! map = true              # also a (Fr, φ) map, map_NAME.csv (default false)
//!
//! [[sweep]]               # one quantity over a list: sweep_NAME.csv
//! name = "cm_height"
//! over = "engine.cm_height"  # speed (m/s), phi (rad), theta0 (rad: the start), dt (s) or engine.KEY
//! values = [0.0, 0.02, 0.05]
//! speeds = [0.2, 0.5, 1.0]   # m/s: every value at every speed (default [0.5])
//! engine = { feet = "separate" }  # over the study's options, for every run of the sweep
//! phi = 1.0854            # rad, dt (s), t_run (s), tail: as the study's by default
//! stop = 1.0              # s: the pusher then rests this long; ω is the mean |ω| over the
//!                         # rest's tail (0 for a clean stop, not for a chattering one)
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use pushval_engine::EngineOptions;
use serde::Deserialize;

/// One study file.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    pub about: Option<String>,
    pub dt: Option<f64>,
    pub t_run: Option<f64>,
    pub tail: Option<f64>,
    pub ladder: Option<Vec<f64>>,
    pub ladder_quick: Option<Vec<f64>>,
    pub fit: Option<bool>,
    #[serde(default)]
    pub engine: BTreeMap<String, serde_json::Value>,
    #[serde(default)]
    pub variant: Vec<Variant>,
    #[serde(default)]
    pub sweep: Vec<Sweep>,
}

/// One quantity of the runs over a list of values.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    pub name: String,
    /// `speed`, `phi`, `theta0`, `dt` or `engine.KEY`.
    pub over: String,
    pub values: Vec<f64>,
    pub speeds: Option<Vec<f64>>,
    #[serde(default)]
    pub engine: BTreeMap<String, serde_json::Value>,
    pub phi: Option<f64>,
    pub dt: Option<f64>,
    pub t_run: Option<f64>,
    pub tail: Option<f64>,
    pub stop: Option<f64>,
}

impl Sweep {
    /// The `[engine]` key the sweep varies, if it varies one.
    pub fn key(&self) -> Option<&str> {
        self.over.strip_prefix("engine.")
    }
}

/// A further table (and map) of the study.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variant {
    pub name: String,
    #[serde(default)]
    pub engine: BTreeMap<String, serde_json::Value>,
    pub supports_half: Option<f64>,
    pub phi: Option<f64>,
    pub dt: Option<f64>,
    #[serde(default)]
    pub map: bool,
}

/// The folder of the study files: `./studies`, else the shipped study files
/// written out once ([`crate::shipped::materialized`]).
pub fn default_dir() -> PathBuf {
    let local = PathBuf::from("studies");
    if local.is_dir() {
        return local;
    }
    crate::shipped::materialized("studies").unwrap_or(local)
}

impl Spec {
    /// `DIR/MODEL.toml`, or the defaults when there is none. Errors name the
    /// file and the key.
    pub fn load(dir: &Path, model: &str) -> anyhow::Result<Self> {
        let path = dir.join(format!("{model}.toml"));
        let text = if path.exists() {
            std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?
        } else if let (false, Some(text)) = (dir.exists(), crate::shipped::study_text(model)) {
            // No folder at all (the shipped files could not be written out):
            // the binary's own file.
            text.to_string()
        } else {
            return Ok(Self::default());
        };
        let de = toml::Deserializer::parse(&text)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let spec: Spec = serde_path_to_error::deserialize(de).map_err(|e| {
            anyhow::anyhow!("{}: key `{}`: {}", path.display(), e.path(), e.inner())
        })?;
        spec.check()
            .map_err(|(key, why)| anyhow::anyhow!("{}: key `{key}`: {why}", path.display()))?;
        Ok(spec)
    }

    fn check(&self) -> Result<(), (String, String)> {
        let pos = |key: &str, v: Option<f64>| match v {
            Some(x) if !(x.is_finite() && x > 0.0) => Err((
                key.to_string(),
                format!("must be a finite number > 0, got {x}"),
            )),
            _ => Ok(()),
        };
        let share = |key: &str, v: Option<f64>| match v {
            Some(t) if !(t > 0.0 && t <= 1.0) => {
                Err((key.to_string(), format!("must be in (0, 1], got {t}")))
            }
            _ => Ok(()),
        };
        pos("dt", self.dt)?;
        pos("t_run", self.t_run)?;
        share("tail", self.tail)?;
        for (key, l) in [
            ("ladder", &self.ladder),
            ("ladder_quick", &self.ladder_quick),
        ] {
            if let Some(l) = l {
                if l.len() < 3 {
                    return Err((key.into(), "needs at least 3 steps".into()));
                }
                for (i, &h) in l.iter().enumerate() {
                    pos(&format!("{key}[{i}]"), Some(h))?;
                }
            }
        }
        for (i, v) in self.variant.iter().enumerate() {
            name_ok(&format!("variant[{i}].name"), &v.name)?;
            pos(&format!("variant[{i}].supports_half"), v.supports_half)?;
            pos(&format!("variant[{i}].dt"), v.dt)?;
        }
        let mut names = std::collections::BTreeSet::new();
        for (i, w) in self.sweep.iter().enumerate() {
            let at = |k: &str| format!("sweep[{i}].{k}");
            name_ok(&at("name"), &w.name)?;
            if !names.insert(&w.name) {
                return Err((at("name"), format!("\"{}\" is used twice", w.name)));
            }
            if !matches!(w.over.as_str(), "speed" | "phi" | "theta0" | "dt")
                && w.key().is_none_or(|k| k.is_empty())
            {
                let why = format!(
                    "must be speed, phi, theta0, dt or engine.KEY, got \"{}\"",
                    w.over
                );
                return Err((at("over"), why));
            }
            if w.values.is_empty() {
                return Err((at("values"), "needs at least one value".into()));
            }
            // A key the sweep's values replace would be ignored: refused.
            let set = [w.speeds.is_some(), w.phi.is_some(), w.dt.is_some()];
            let fixed = ["speed", "phi", "dt"]
                .iter()
                .zip(["speeds", "phi", "dt"])
                .zip(set);
            if let Some(((_, k), _)) = fixed
                .into_iter()
                .find(|((o, _), set)| *set && w.over == **o)
            {
                return Err((at(k), "is what the sweep varies; remove it".into()));
            }
            for (k, &v) in w.values.iter().enumerate() {
                if w.values[..k].contains(&v) || !v.is_finite() {
                    let why = format!("must be finite and listed once, got {v}");
                    return Err((format!("{}[{k}]", at("values")), why));
                }
                if matches!(w.over.as_str(), "speed" | "dt") {
                    pos(&format!("{}[{k}]", at("values")), Some(v))?;
                }
            }
            for (k, &v) in w.speeds.iter().flatten().enumerate() {
                pos(&format!("{}[{k}]", at("speeds")), Some(v))?;
            }
            pos(&at("dt"), w.dt)?;
            pos(&at("t_run"), w.t_run)?;
            pos(&at("stop"), w.stop)?;
            share(&at("tail"), w.tail)?;
        }
        Ok(())
    }

    /// The `[engine]` options of the study's runs, with `extra` over them.
    pub fn options(&self, extra: &BTreeMap<String, serde_json::Value>) -> EngineOptions {
        let mut values = self.engine.clone();
        values.extend(extra.clone());
        EngineOptions {
            dt: None,
            values,
            ..Default::default()
        }
    }

    /// The step ladder (s), coarse to fine.
    pub fn ladder(&self, dt: f64, quick: bool) -> Vec<f64> {
        let given = if quick {
            &self.ladder_quick
        } else {
            &self.ladder
        };
        given.clone().unwrap_or_else(|| {
            let f: &[f64] = if quick {
                &[2.0, 1.0, 0.5]
            } else {
                &[4.0, 2.0, 1.0, 0.5, 0.25]
            };
            f.iter().map(|k| k * dt).collect()
        })
    }
}

/// A variant's or sweep's name names a file: letters, digits and `_`.
fn name_ok(key: &str, name: &str) -> Result<(), (String, String)> {
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err((
            key.to_string(),
            format!("must be letters, digits and _, got \"{name}\""),
        ));
    }
    Ok(())
}

/// The study files of `dir` named after no model of the registry, less
/// the shipped ones a project holds as `pushval init` wrote them (a
/// project runs its own engines, not every one pushval ships a study
/// for): each is skipped with a note on standard error (a folder of study
/// files serves several registries).
pub fn check_names(dir: &Path, models: &[String]) -> anyhow::Result<()> {
    for p in unused_files(dir, models) {
        eprintln!(
            "note: skipping {}: no engine model `{}` in this registry (`pushval engines`)",
            p.display(),
            p.file_stem().and_then(|s| s.to_str()).unwrap_or_default()
        );
    }
    Ok(())
}

/// What [`check_names`] notes, sorted: the `.toml` files of `dir` whose
/// stem is no model of `models` and whose text is not the shipped study
/// file of that name.
pub fn unused_files(dir: &Path, models: &[String]) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut skipped: Vec<PathBuf> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .filter(|p| {
            let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
            let shipped = crate::shipped::study_text(stem)
                .is_some_and(|t| std::fs::read_to_string(p).is_ok_and(|own| own == t));
            !models.iter().any(|m| m == stem) && !shipped
        })
        .collect();
    skipped.sort();
    skipped
}
