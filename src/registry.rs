//! The engine registry: every engine model pushval can run, by name.
//!
//! One row per engine crate: the function returning the crate's
//! [`ModelEntry`] table (model name and constructor). Adding an engine is its
//! crate, one row here, and its Cargo entries (the workspace dependency, the
//! root package's dependency and, for heavy engines, a feature). Nothing else
//! in the harness, the studies or the benches names an engine.

use pushval_engine::{Engine, EngineOptions, ModelEntry};
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

/// Every engine model, in registry order.
pub fn entries() -> Vec<ModelEntry> {
    ENGINE_CRATES.iter().flat_map(|models| models()).collect()
}

/// The engine model called `name`, if the registry has one.
pub fn entry(name: &str) -> Option<ModelEntry> {
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
    (e.build)(options).unwrap_or_else(|e| panic!("engine options were checked at load: {e}"))
}

/// Every model name a scenario may list: the analytic models, then the engines.
pub fn known_models() -> Vec<&'static str> {
    ANALYTIC_MODELS
        .iter()
        .copied()
        .chain(entries().iter().map(|e| e.name))
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
        let Some(e) = engines.iter().find(|e| e.name == g) else {
            return Err(err(
                &key,
                format!(
                    "unknown engine \"{g}\"; a gate names an engine model: {}",
                    engines
                        .iter()
                        .map(|e| e.name)
                        .collect::<Vec<_>>()
                        .join(", ")
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
        if !known.contains(&m.as_str()) {
            return Err(err(
                &format!("run.models[{i}]"),
                format!("unknown model \"{m}\"; known: {}", known.join(", ")),
            ));
        }
    }
    // Every `[engine]` key must be read by some engine; every listed engine
    // must accept the values.
    for key in sc.engine.values.keys() {
        if !engines
            .iter()
            .any(|e| e.default_engine().option_keys().contains(&key.as_str()))
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
        if let Some(e) = engines.iter().find(|e| e.name == m) {
            (e.build)(&sc.engine).map_err(|o| err(&format!("engine.{}", o.key), o.problem))?;
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
                e.name.to_string(),
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
