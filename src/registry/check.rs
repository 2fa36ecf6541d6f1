//! The scenario checks only the registry can make: model and gate names,
//! that every gated engine is in this build, and the `[engine]` keys and
//! values. The scenario crate checks everything else ([`Scenario::from_toml`]).

use pushval_engine::Engine;
use pushval_scenario::{Scenario, ScenarioError};

use super::models::{engine_options, entries, known_models, Entry};
use super::project::engines_file;

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
    let options = engine_options(sc);
    for m in &sc.models {
        if let Some(e) = engines.iter().find(|e| e.name == *m) {
            e.build(&options)
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

/// Parses scenario text and checks it against the registry; `file` names it
/// in errors.
pub fn from_toml(text: &str, file: &std::path::Path) -> Result<Scenario, ScenarioError> {
    let sc = Scenario::from_toml(text, file)?;
    check(&sc)?;
    Ok(sc)
}
