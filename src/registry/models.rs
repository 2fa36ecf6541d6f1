//! The registry proper: every engine model pushval can run, by name.
//!
//! One row per engine crate ([`ENGINE_CRATES`]): the function returning the
//! crate's [`ModelEntry`] table (model name and constructor) and the root
//! package's cargo feature that brings its engine in, if any. After the
//! crates' rows come the outside engines of the `pushval.toml` the command
//! line loaded ([`use_engines_file`], kept in [`super::project`]): processes
//! speaking the `pushval-problem` protocol (crate `pushval-outside`). Their
//! constructor is the only place they differ from a compiled-in engine.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use pushval_engine::{
    Build, Engine, EngineOptions, FrictionLaw, ModelEntry, OptionError, SceneFrame,
};
use pushval_outside::{Config, OutsideEngine, Spec};
use pushval_scenario::{Scenario, ANALYTIC_MODELS};

use super::project;

/// One engine crate in the registry.
#[derive(Debug, Clone, Copy)]
pub struct CrateRow {
    /// The crate's model table.
    pub models: fn() -> Vec<ModelEntry>,
    /// The root package's cargo feature that compiles the crate's engine in
    /// (its `[features]`); None: always in the build.
    pub feature: Option<&'static str>,
}

/// The engine crates, one row per crate: the only list of them.
pub const ENGINE_CRATES: &[CrateRow] = &[
    CrateRow {
        models: pushval_rapier2d::models,
        feature: None,
    },
    CrateRow {
        models: pushval_rapier3d::models,
        feature: None,
    },
    CrateRow {
        models: pushval_mujoco::models,
        feature: Some("mujoco"),
    },
    CrateRow {
        models: pushval_physx::models,
        feature: Some("physx"),
    },
    CrateRow {
        models: pushval_box2d::models,
        feature: None,
    },
    CrateRow {
        models: pushval_avian::models,
        feature: Some("avian"),
    },
    CrateRow {
        models: pushval_jolt::models,
        feature: Some("jolt"),
    },
];

/// The cargo feature a build needs for the compiled-in model `model`, if any.
pub fn feature_of(model: &str) -> Option<&'static str> {
    ENGINE_CRATES
        .iter()
        .find(|c| (c.models)().iter().any(|e| e.name == model))
        .and_then(|c| c.feature)
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

/// Loads the outside engines: `file` (from `--engines`; it must exist), or
/// the [`project::ENGINES_FILE`] of the current folder or its nearest parent
/// that has one ([`project::find_engines_file`]). A name that is already an
/// analytic model or a compiled-in engine is refused, naming the file and
/// the key, as is a law the catalogue lacks. Replaces what an earlier call
/// loaded.
pub fn use_engines_file(file: Option<&Path>) -> Result<(), pushval_outside::ConfigError> {
    let (searched, required) = match file {
        Some(f) => (f.to_path_buf(), true),
        None => {
            let cwd = std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."));
            let found = project::find_engines_file(&cwd);
            (
                found.unwrap_or_else(|| cwd.join(project::ENGINES_FILE)),
                false,
            )
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
    project::set(searched, config);
    Ok(())
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
pub(super) fn crate_entries() -> Vec<ModelEntry> {
    ENGINE_CRATES.iter().flat_map(|c| (c.models)()).collect()
}

/// Every engine model, in registry order: the crates', then the outside
/// engines loaded by [`use_engines_file`].
pub fn entries() -> Vec<Entry> {
    let crates = crate_entries().into_iter().map(|e| Entry {
        name: e.name.to_string(),
        build: Builder::Crate(e.build),
    });
    let outside = project::outside_engines().into_iter().map(|s| Entry {
        name: s.name.clone(),
        build: Builder::Outside(Arc::new(s)),
    });
    crates.chain(outside).collect()
}

/// The engine model called `name`, if the registry has one.
pub fn entry(name: &str) -> Option<Entry> {
    entries().into_iter().find(|e| e.name == name)
}

/// The engine options of a scenario: its `[engine]` table
/// ([`EngineOptions::from_table`]) with the scene the file describes (its
/// frame, outline, gravity and loads, for adapters that hand the scene to
/// another program).
pub fn engine_options(sc: &Scenario) -> EngineOptions {
    let scene = SceneFrame {
        center_of_mass: [sc.center_of_mass.x, sc.center_of_mass.y],
        polygon: sc.polygon.iter().map(|p| [p.x, p.y]).collect(),
        gravity: sc.gravity,
        normal_forces: sc.supports.iter().map(|s| s.load).collect(),
    };
    EngineOptions::from_table(sc.engine.dt, sc.engine.values.clone(), Some(scene))
}

/// Builds the engine model `name` from a scenario's `[engine]` options.
/// Panics on an unknown name or bad options: [`super::check`] refuses both
/// at load.
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
