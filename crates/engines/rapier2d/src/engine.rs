//! The rapier2d models as pushval engine plug-ins: `rapier2d` (per-support
//! Coulomb forces, gated by default) and the four 2-D friction idioms.

use pushval_engine::{
    Detailed, DetailedEngine, Engine, EngineCrate, EngineInfo, EngineOptions, FrictionLaw,
    ModelEntry, OptionError, OptionKeys, Session, COULOMB,
};
use pushval_laws::idioms::{
    ImpulseBox, ImpulseDisk, RegularisedLinear, RegularisedTanh, RowsDisk, DEFAULT_SLIP_SPEED,
};
use pushval_model::{ModelError, Problem};

use crate::{EngineSettings, FrictionModel, FrictionVelocity, Precision, RapierSimulator};

/// The engine crate and version this adapter is built against (the
/// `rapier2d-f64` and `rapier2d` entries of the workspace's Cargo.toml; a
/// test checks it against Cargo.lock).
pub const ENGINE_CRATE: EngineCrate = EngineCrate {
    name: "rapier2d-f64",
    version: "0.36.1",
};

/// Slip speed (m/s) below which the regularised idioms go linear / tanh
/// (see results/friction_models/).
const IDIOM_SLIP_SPEED: f64 = DEFAULT_SLIP_SPEED;

/// One rapier2d model: a friction law and the scenario's engine settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Rapier2dModel {
    info: EngineInfo,
    /// The settings of a run (its `dt` is replaced by the run's).
    pub settings: EngineSettings,
}

impl Rapier2dModel {
    /// The model with the given name and settings.
    pub fn new(name: &'static str, description: &'static str, settings: EngineSettings) -> Self {
        let engine_crate = match settings.precision {
            Precision::F64 => ENGINE_CRATE,
            Precision::F32 => EngineCrate {
                name: "rapier2d",
                ..ENGINE_CRATE
            },
        };
        // Second order in leapfrog mode, first in the others (measured: see
        // the crate's README).
        let order = match settings.friction_velocity {
            FrictionVelocity::Leapfrog => 2.0,
            _ => 1.0,
        };
        let keys = if matches!(
            settings.friction_model,
            FrictionModel::RegularisedLinear { .. } | FrictionModel::RegularisedTanh { .. }
        ) {
            REGULARISED_KEYS
        } else {
            OPTION_KEYS
        };
        Self {
            info: EngineInfo::new(
                name,
                description,
                "pushval-rapier2d",
                engine_crate,
                order,
                settings.dt,
            )
            .with_options(OptionKeys::Listed(keys))
            // The slide's implicit Coulomb impulses take each support's slip
            // direction at the step's end and the stop is read at a step's
            // end: first order whatever the push's mode (README, "The slide").
            .with_release_order(1.0),
            settings,
        }
    }
}

/// The `[engine]` keys the rapier2d models read, besides `dt`.
const OPTION_KEYS: &[&str] = &["solver_iterations", "precision", "friction_velocity"];
/// The regularised idioms' keys: the common ones and `slip_speed` (m/s).
const REGULARISED_KEYS: &[&str] = &[
    "solver_iterations",
    "precision",
    "friction_velocity",
    "slip_speed",
];

/// The settings the `[engine]` table asks for, over the adapter's defaults.
pub fn settings_from(opts: &EngineOptions) -> Result<EngineSettings, OptionError> {
    let mut s = EngineSettings::default();
    if let Some(dt) = opts.dt {
        s.dt = dt;
    }
    if let Some(n) = opts.integer("solver_iterations", 1)? {
        s.solver_iterations = n;
    }
    if let Some(p) = opts.choice("precision", &["f64", "f32"])? {
        s.precision = if p == "f32" {
            Precision::F32
        } else {
            Precision::F64
        };
    }
    let modes = FrictionVelocity::ALL.map(|m| m.as_str());
    if let Some(m) = opts.choice("friction_velocity", &modes)? {
        s.friction_velocity = FrictionVelocity::ALL
            .into_iter()
            .find(|f| f.as_str() == m)
            .expect("choice is one of ALL");
    }
    Ok(s)
}

fn build(
    name: &'static str,
    description: &'static str,
    friction_model: FrictionModel,
    opts: &EngineOptions,
) -> Result<Box<dyn Engine>, OptionError> {
    let friction_model = match (friction_model, opts.positive("slip_speed")?) {
        (FrictionModel::RegularisedLinear { .. }, Some(v)) => {
            FrictionModel::RegularisedLinear { slip_speed: v }
        }
        (FrictionModel::RegularisedTanh { .. }, Some(v)) => {
            FrictionModel::RegularisedTanh { slip_speed: v }
        }
        (m, _) => m,
    };
    let settings = EngineSettings {
        friction_model,
        ..settings_from(opts)?
    };
    Ok(Box::new(Rapier2dModel::new(name, description, settings)))
}

/// The rapier2d models, one row each: the crate's entries in pushval's
/// engine registry.
pub fn models() -> Vec<ModelEntry> {
    vec![
        ModelEntry {
            name: "rapier2d",
            build: |o| {
                build(
                    "rapier2d",
                    "top-down rigid body, kinematic pusher through a revolute joint, Coulomb force at every support",
                    FrictionModel::Coulomb,
                    o,
                )
            },
        },
        ModelEntry {
            name: "rapier2d_impulse_disk",
            build: |o| {
                build(
                    "rapier2d_impulse_disk",
                    "2-D friction-joint idiom: per-support impulse capped in length at mu N dt",
                    FrictionModel::ImpulseDisk,
                    o,
                )
            },
        },
        ModelEntry {
            name: "rapier2d_impulse_box",
            build: |o| {
                build(
                    "rapier2d_impulse_box",
                    "2-D friction-joint idiom: per-support impulse capped per world axis",
                    FrictionModel::ImpulseBox,
                    o,
                )
            },
        },
        ModelEntry {
            name: "rapier2d_regularised_linear",
            build: |o| {
                build(
                    "rapier2d_regularised_linear",
                    "Coulomb regularised linearly below the slip speed ([engine] slip_speed, default 0.01 m/s)",
                    FrictionModel::RegularisedLinear {
                        slip_speed: IDIOM_SLIP_SPEED,
                    },
                    o,
                )
            },
        },
        ModelEntry {
            name: "rapier2d_regularised_tanh",
            build: |o| {
                build(
                    "rapier2d_regularised_tanh",
                    "Coulomb regularised by tanh(|u| / v_s) ([engine] slip_speed v_s, default 0.01 m/s)",
                    FrictionModel::RegularisedTanh {
                        slip_speed: IDIOM_SLIP_SPEED,
                    },
                    o,
                )
            },
        },
    ]
}

impl Engine for Rapier2dModel {
    fn info(&self) -> &EngineInfo {
        &self.info
    }
    fn settings(&self, dt: f64) -> serde_json::Value {
        let s = EngineSettings {
            dt,
            ..self.settings
        };
        serde_json::json!({
            "engine": self.info.version,
            "dt": s.dt,
            "solver_iterations": s.solver_iterations,
            "pgs_iterations": s.pgs_iterations,
            "precision": s.precision.as_str(),
            "friction_velocity": s.friction_velocity.as_str(),
            "friction_model": s.friction_model.as_str(),
            "slip_speed": match s.friction_model {
                FrictionModel::RegularisedLinear { slip_speed }
                | FrictionModel::RegularisedTanh { slip_speed } => Some(slip_speed),
                _ => None,
            },
            "switch_step_fraction": s.switch_step_fraction,
            "colliders": s.colliders,
            "label": s.label(),
        })
    }
    fn law(&self) -> Option<&dyn FrictionLaw> {
        match self.settings.friction_model {
            FrictionModel::Coulomb => Some(&COULOMB),
            // The idiom with its parameters is the law (`crate::idioms`).
            _ => Some(&self.settings.friction_model),
        }
    }
    /// The rapier world through the shared stepping loop
    /// ([`pushval_engine::stepping`]), owned by the session; an object not
    /// starting at rest starts with the first push applied, and in leapfrog
    /// mode every segment closes with a half kick.
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        let sim = RapierSimulator::new(EngineSettings {
            dt,
            ..self.settings
        });
        Ok(Box::new(
            Detailed::new(sim.start(problem)?).named(self.info.name.clone()),
        ))
    }
}

/// The idioms' laws by name, with the idioms' default slip speed: the
/// entries of `pushval_laws::catalog()` these models' laws come from.
pub fn laws() -> Vec<(&'static str, Box<dyn FrictionLaw>)> {
    let slip_speed = IDIOM_SLIP_SPEED;
    vec![
        ("impulse_disk", Box::new(ImpulseDisk)),
        ("impulse_box", Box::new(ImpulseBox)),
        ("impulse_rows_disk", Box::new(RowsDisk)),
        (
            "regularised_linear",
            Box::new(RegularisedLinear { slip_speed }),
        ),
        ("regularised_tanh", Box::new(RegularisedTanh { slip_speed })),
    ]
}
