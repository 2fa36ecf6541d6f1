//! The engine registry: every engine model pushval can run, by name.
//!
//! One row per engine crate: the function returning the crate's
//! [`ModelEntry`] table (model name and constructor). Adding an engine is its
//! crate, one row here, and its Cargo entries (the workspace dependency, the
//! root package's dependency and, for heavy engines, a feature). Nothing else
//! in the harness, the studies or the benches names an engine.
//!
//! After the crates' rows come the outside engines of the `pushval.toml` the
//! command line loaded ([`use_engines_file`]): processes speaking the
//! `pushval-problem/1` protocol (crate `pushval-outside`). Their constructor
//! is the only place they differ from a compiled-in engine.

use std::path::{Path, PathBuf};
use std::sync::{Arc, RwLock};

use pushval_engine::{Build, Engine, EngineOptions, FrictionLaw, ModelEntry, OptionError};
pub use pushval_outside::{csv, problem_document, DEFAULT_DT as OUTSIDE_DEFAULT_DT};
use pushval_outside::{Config, OutsideEngine, Spec};
use pushval_scenario::{Scenario, ScenarioError, ANALYTIC_MODELS};

/// The engine crates' model tables, one row per crate.
pub const ENGINE_CRATES: &[fn() -> Vec<ModelEntry>] = &[
    pushval_rapier2d::models,
    pushval_rapier3d::models,
    pushval_mujoco::models,
    pushval_physx::models,
    pushval_box2d::models,
    pushval_avian::models,
    pushval_jolt::models,
];

/// The friction laws an outside engine may declare (`law = "NAME"` in
/// `pushval.toml`), with their default parameters: every law of
/// [`pushval_laws::catalog`].
pub fn laws() -> Vec<(&'static str, Arc<dyn FrictionLaw>)> {
    pushval_laws::catalog()
        .into_iter()
        .map(|e| (e.name, Arc::from(e.default_law())))
        .collect()
}

/// The law an outside engine declares (`law = "NAME"` and `law_params`
/// in its `pushval.toml` table), built from the catalogue: None when it
/// declares none; an unknown name is an error naming `engine.NAME.law` and
/// listing the known laws, a parameter the law refuses one naming
/// `engine.NAME.law_params.KEY`.
pub fn outside_law(
    spec: &Spec,
) -> Result<Option<Arc<dyn FrictionLaw>>, pushval_outside::ConfigError> {
    let Some(name) = spec.law.as_deref() else {
        return Ok(None);
    };
    let err = |key: String, problem: String| pushval_outside::ConfigError {
        file: spec.file.clone(),
        key,
        problem,
    };
    let Some(entry) = pushval_laws::law_entry(name) else {
        let known: Vec<&str> = pushval_laws::catalog().iter().map(|e| e.name).collect();
        return Err(err(
            format!("engine.{}.law", spec.name),
            format!("unknown law \"{name}\"; known: {}", known.join(", ")),
        ));
    };
    entry
        .build(&spec.law_params)
        .map(|l| Some(Arc::from(l)))
        .map_err(|e| {
            err(
                format!("engine.{}.law_params.{}", spec.name, e.key),
                e.problem,
            )
        })
}

/// The file outside engines are declared in when `--engines` names none:
/// `pushval.toml`, found as cargo finds `Cargo.toml` ([`find_engines_file`]).
pub const ENGINES_FILE: &str = "pushval.toml";

/// The `pushval.toml` that applies in `dir`: the one in `dir`, else in its
/// nearest parent that has one; None when no folder up to the root has one.
pub fn find_engines_file(dir: &Path) -> Option<PathBuf> {
    dir.ancestors()
        .map(|d| d.join(ENGINES_FILE))
        .find(|f| f.is_file())
}

/// The folder of the `pushval.toml` in use (the project's root, whose
/// `scenarios/` the main job validates), or None when none was found.
pub fn project_dir() -> Option<PathBuf> {
    OUTSIDE
        .read()
        .expect("not poisoned")
        .as_ref()
        .filter(|o| o.config.is_some())
        .and_then(|o| o.searched.parent().map(Path::to_path_buf))
}

/// The outside engines in use: the file searched and what it declared
/// (None: the file does not exist).
#[derive(Debug, Clone)]
struct Outside {
    searched: PathBuf,
    config: Option<Config>,
}

static OUTSIDE: RwLock<Option<Outside>> = RwLock::new(None);

/// Loads the outside engines: `file` (from `--engines`; it must exist), or
/// the [`ENGINES_FILE`] of the current folder or its nearest parent that has
/// one ([`find_engines_file`]). A name that is
/// already an analytic model or a compiled-in engine is refused, naming the
/// file and the key. Replaces what an earlier call loaded.
pub fn use_engines_file(file: Option<&Path>) -> Result<(), pushval_outside::ConfigError> {
    let (searched, required) = match file {
        Some(f) => (f.to_path_buf(), true),
        None => {
            let cwd = std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."));
            let found = find_engines_file(&cwd);
            (found.unwrap_or_else(|| cwd.join(ENGINES_FILE)), false)
        }
    };
    let searched = std::path::absolute(&searched).unwrap_or(searched);
    let config = if required || searched.is_file() {
        let c = Config::from_path(&searched)?;
        let crates = crate_entries();
        for spec in &c.engines {
            if ANALYTIC_MODELS.contains(&spec.name.as_str())
                || crates.iter().any(|e| e.name == spec.name)
            {
                return Err(pushval_outside::ConfigError {
                    file: c.file.clone(),
                    key: format!("engine.{}", spec.name),
                    problem: "this name is already a built-in model; choose another".into(),
                });
            }
            outside_law(spec)?;
        }
        Some(c)
    } else {
        None
    };
    *OUTSIDE.write().expect("not poisoned") = Some(Outside { searched, config });
    Ok(())
}

/// Where outside engines were looked for, for messages: the file and
/// whether it exists.
pub fn engines_file() -> String {
    match OUTSIDE.read().expect("not poisoned").as_ref() {
        Some(Outside {
            searched,
            config: Some(_),
        }) => searched.display().to_string(),
        Some(Outside {
            searched,
            config: None,
        }) => format!("{} (not found)", searched.display()),
        None => "none loaded".to_string(),
    }
}

/// One engine model the registry can build: a crate's row or an outside
/// engine.
#[derive(Clone)]
pub struct Entry {
    /// The model name.
    pub name: String,
    build: Builder,
}

#[derive(Clone)]
enum Builder {
    Crate(Build),
    Outside(Arc<Spec>),
}

impl std::fmt::Debug for Entry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Entry").field("name", &self.name).finish()
    }
}

impl Entry {
    /// The model built from a scenario's `[engine]` options.
    pub fn build(&self, options: &EngineOptions) -> Result<Box<dyn Engine>, OptionError> {
        match &self.build {
            Builder::Crate(b) => b(options),
            Builder::Outside(spec) => Ok(Box::new(
                OutsideEngine::new(spec.clone(), options)
                    .with_law(outside_law(spec).ok().flatten()),
            )),
        }
    }
    /// The model with default options (for listings).
    pub fn default_engine(&self) -> Box<dyn Engine> {
        self.build(&EngineOptions::default())
            .expect("default options are valid for every engine")
    }
}

/// The compiled-in engine models, in registry order.
fn crate_entries() -> Vec<ModelEntry> {
    ENGINE_CRATES.iter().flat_map(|models| models()).collect()
}

/// Every engine model, in registry order: the crates', then the outside
/// engines loaded by [`use_engines_file`].
pub fn entries() -> Vec<Entry> {
    let mut out: Vec<Entry> = crate_entries()
        .into_iter()
        .map(|e| Entry {
            name: e.name.to_string(),
            build: Builder::Crate(e.build),
        })
        .collect();
    if let Some(Outside {
        config: Some(c), ..
    }) = OUTSIDE.read().expect("not poisoned").as_ref()
    {
        out.extend(c.engines.iter().map(|s| Entry {
            name: s.name.clone(),
            build: Builder::Outside(Arc::new(s.clone())),
        }));
    }
    out
}

/// The engine model called `name`, if the registry has one.
pub fn entry(name: &str) -> Option<Entry> {
    entries().into_iter().find(|e| e.name == name)
}

/// Whether `name` is an engine model (not an analytic one).
pub fn is_engine(name: &str) -> bool {
    entry(name).is_some()
}

/// Builds the engine model `name` from a scenario's `[engine]` options.
/// Panics on an unknown name or bad options: [`check`] refuses both at load.
pub fn engine(name: &str, options: &EngineOptions) -> Box<dyn Engine> {
    let e = entry(name).unwrap_or_else(|| panic!("`{name}` is not in the engine registry"));
    e.build(options)
        .unwrap_or_else(|e| panic!("engine options were checked at load: {e}"))
}

/// Every model name a scenario may list: the analytic models, then the engines.
pub fn known_models() -> Vec<String> {
    ANALYTIC_MODELS
        .iter()
        .map(|m| m.to_string())
        .chain(entries().into_iter().map(|e| e.name))
        .collect()
}

/// Checks what only the registry can: the model and gate names, that every
/// gated engine is in this build, and the `[engine]` keys. Errors name the
/// file and the key, like the loader's.
pub fn check(sc: &Scenario) -> Result<(), ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(&sc.path, key, msg);
    let engines = entries();
    for (i, g) in sc.gate.iter().enumerate() {
        let key = format!("run.gate[{i}]");
        let Some(e) = engines.iter().find(|e| e.name == *g) else {
            return Err(err(
                &key,
                format!(
                    "unknown engine \"{g}\"; a gate names an engine model: {}; outside engines are declared in pushval.toml or the --engines file, never in a scenario (searched: {})",
                    engines
                        .iter()
                        .map(|e| e.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                    engines_file()
                ),
            ));
        };
        let engine = e.default_engine();
        if let Err(why) = engine.availability() {
            return Err(err(
                &key,
                format!("the gated engine \"{g}\" is not in this build: {why}"),
            ));
        }
        if !engine.gateable() {
            return Err(err(&key, format!("the engine \"{g}\" cannot be gated")));
        }
    }
    let known = known_models();
    for (i, m) in sc.models.iter().enumerate() {
        if !known.contains(m) {
            return Err(err(
                &format!("run.models[{i}]"),
                format!(
                    "unknown model \"{m}\"; known: {}; outside engines are declared in pushval.toml or the --engines file, never in a scenario (searched: {})",
                    known.join(", "),
                    engines_file()
                ),
            ));
        }
    }
    // Every `[engine]` key must be read by some compiled-in engine or by an
    // engine the scenario lists; every listed engine must accept the values.
    let listed: Vec<Box<dyn Engine>> = engines
        .iter()
        .filter(|e| sc.models.contains(&e.name) || sc.gate.contains(&e.name))
        .map(Entry::default_engine)
        .collect();
    for key in sc.engine.values.keys() {
        if !engines
            .iter()
            .any(|e| e.default_engine().option_keys().contains(&key.as_str()))
            && !listed.iter().any(|e| e.accepts_option(key))
        {
            let mut all: Vec<&str> = vec!["dt"];
            for e in &engines {
                for k in e.default_engine().option_keys() {
                    if !all.contains(k) {
                        all.push(k);
                    }
                }
            }
            return Err(err(
                &format!("engine.{key}"),
                format!("no engine reads this key; known: {}", all.join(", ")),
            ));
        }
    }
    for m in &sc.models {
        if let Some(e) = engines.iter().find(|e| e.name == *m) {
            e.build(&sc.engine)
                .map_err(|o| err(&format!("engine.{}", o.key), o.problem))?;
        }
    }
    Ok(())
}

/// Loads a scenario and checks it against the registry.
pub fn load(path: impl AsRef<std::path::Path>) -> Result<Scenario, ScenarioError> {
    let sc = Scenario::from_path(path)?;
    check(&sc)?;
    Ok(sc)
}

/// The `pushval engines` table: one row per engine model.
pub fn engines_table() -> String {
    let rows: Vec<[String; 6]> = entries()
        .iter()
        .map(|e| {
            let engine = e.default_engine();
            [
                e.name.clone(),
                engine.adapter().to_string(),
                engine.version(),
                format!("{}", engine.order()),
                if engine.gateable() { "yes" } else { "no" }.to_string(),
                match engine.availability() {
                    Ok(()) => "yes".to_string(),
                    Err(why) => format!("no: {why}"),
                },
            ]
        })
        .collect();
    let header = [
        "model",
        "crate",
        "engine",
        "order",
        "gateable",
        "in this build",
    ];
    let mut width = header.map(str::len);
    for r in &rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: &[String]| {
        let mut s = String::new();
        for (i, (c, w)) in cells.iter().zip(width).enumerate() {
            if i + 1 == cells.len() {
                s.push_str(c);
            } else {
                s.push_str(&format!("{c:<w$}  "));
            }
        }
        s.trim_end().to_string() + "\n"
    };
    let mut out = line(&header.map(String::from));
    for r in &rows {
        out.push_str(&line(r));
    }
    out.push_str(&format!(
        "\norder: of accuracy in dt of the steady ω and trajectory. Analytic models (always in the build): {}.\n",
        ANALYTIC_MODELS.join(", ")
    ));
    out
}

/// Parses scenario text and checks it against the registry; `file` names it
/// in errors.
pub fn from_toml(text: &str, file: &std::path::Path) -> Result<Scenario, ScenarioError> {
    let sc = Scenario::from_toml(text, file)?;
    check(&sc)?;
    Ok(sc)
}

/// The scenarios folder the commands read: the project's `scenarios/`
/// (beside the `pushval.toml` in use), else `./scenarios`, else the shipped
/// scenarios written out once ([`crate::shipped::materialized`]).
pub fn default_scenario_dir() -> PathBuf {
    let dirs = [
        project_dir().map(|d| d.join("scenarios")),
        Some(PathBuf::from("scenarios")),
    ];
    dirs.into_iter()
        .flatten()
        .find(|d| d.is_dir())
        .or_else(|| crate::shipped::materialized("scenarios").ok())
        .unwrap_or_else(|| PathBuf::from("scenarios"))
}

/// The engines that declare the catalogue law `entry`: its compiled-in
/// models, then the outside engines of the loaded `pushval.toml` that name it.
fn declaring(entry: &pushval_laws::LawEntry) -> Vec<String> {
    let mut out: Vec<String> = entry.engines.iter().map(|e| e.to_string()).collect();
    if let Some(Outside {
        config: Some(c), ..
    }) = OUTSIDE.read().expect("not poisoned").as_ref()
    {
        out.extend(
            c.engines
                .iter()
                .filter(|s| s.law.as_deref() == Some(entry.name))
                .map(|s| s.name.clone()),
        );
    }
    out
}

/// A parameter's default as `pushval laws` shows it (`0.01 m/s`, `"welded"`).
fn param_text(p: &pushval_laws::ParamSpec) -> String {
    let default = match (&p.default, p.kind) {
        (serde_json::Value::String(s), pushval_laws::ParamKind::Choice(all)) => {
            format!("{s} (of {})", all.join("|"))
        }
        (v, _) => v.to_string(),
    };
    if p.unit.is_empty() {
        format!("{}={default}", p.name)
    } else {
        format!("{}={default} {}", p.name, p.unit)
    }
}

/// The `pushval laws` table: one row per catalogue law (name, the engines
/// that declare it, its parameters with defaults, where its loads come
/// from), each followed by its one-sentence description.
pub fn laws_table() -> String {
    let catalog = pushval_laws::catalog();
    let rows: Vec<[String; 4]> = catalog
        .iter()
        .map(|e| {
            let engines = declaring(e);
            let params: Vec<String> = e.params.iter().map(param_text).collect();
            [
                e.name.to_string(),
                if engines.is_empty() {
                    "-".into()
                } else {
                    engines.join(",")
                },
                if params.is_empty() {
                    "-".into()
                } else {
                    params.join(", ")
                },
                e.loads.as_str().to_string(),
            ]
        })
        .collect();
    let header = ["law", "engines", "parameters (defaults)", "loads"];
    let mut width = header.map(|h| h.chars().count());
    for r in &rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: &[String]| {
        let mut s = String::new();
        for (c, w) in cells.iter().zip(width) {
            s.push_str(c);
            s.push_str(&" ".repeat(w - c.chars().count() + 2));
        }
        s.trim_end().to_string() + "\n"
    };
    let mut out = line(&header.map(String::from));
    for (r, e) in rows.iter().zip(&catalog) {
        out.push_str(&line(r));
        out.push_str(&format!("    {}\n", e.about));
    }
    out.push_str(
        "\nloads: problem = the problem's support loads (its statics); law = the law's own prediction from the problem's geometry and mass.\nAn engine in pushval.toml declares one with law = \"NAME\" and, optionally, law_params = { key = value }.\n",
    );
    out
}

/// `pushval laws --json`: an array with one object per catalogue law:
/// `name`, `engines`, `params` (`name`, `default`, `unit`, `meaning`),
/// `loads` and `about`.
pub fn laws_json() -> serde_json::Value {
    pushval_laws::catalog()
        .iter()
        .map(|e| {
            serde_json::json!({
                "name": e.name,
                "engines": declaring(e),
                "params": e.params.iter().map(|p| serde_json::json!({
                    "name": p.name,
                    "default": p.default,
                    "unit": p.unit,
                    "meaning": p.meaning,
                })).collect::<Vec<_>>(),
                "loads": e.loads.as_str(),
                "about": e.about,
            })
        })
        .collect()
}
