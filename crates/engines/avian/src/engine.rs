//! The Avian models as pushval engine plug-ins: `avian2d` (per-support
//! Coulomb forces in Avian's substep loop) and `avian3d` (the plate on ball
//! feet with Avian's own contact friction). Without the `avian` feature they
//! are listed but not available.

use pushval_engine::{
    Detailed, DetailedEngine, Engine, EngineCrate, EngineInfo, EngineOptions, EngineSession,
    FrictionLaw, ModelEntry, OptionError, OptionKeys, Session, COULOMB,
};
use pushval_model::{ModelError, Problem};

use crate::predict::Avian3dTilt;
use crate::{Avian2dSettings, Avian2dSimulator, Avian3dSettings, Avian3dSimulator, AVAILABLE};

/// The 2-D engine crate and the version this adapter is built against (the
/// `avian2d` entry of the workspace's Cargo.toml; a test checks it against
/// Cargo.lock).
pub const ENGINE_CRATE_2D: EngineCrate = EngineCrate {
    name: "avian2d",
    version: "0.7.0",
};

/// The 3-D engine crate and version (the `avian3d` entry).
pub const ENGINE_CRATE_3D: EngineCrate = EngineCrate {
    name: "avian3d",
    version: "0.7.0",
};

/// The `[engine]` keys the Avian models read, besides `dt`.
const OPTION_KEYS: &[&str] = &["substeps"];

/// Avian's substep count from `[engine] substeps`, if set (1 to 1024).
fn substeps(opts: &EngineOptions) -> Result<Option<u32>, OptionError> {
    match opts.integer("substeps", 1)? {
        Some(n) if n > 1024 => Err(OptionError {
            key: "substeps".into(),
            problem: format!("must be at most 1024, got {n}"),
        }),
        n => Ok(n.map(|n| n as u32)),
    }
}

fn availability() -> Result<(), String> {
    if AVAILABLE {
        Ok(())
    } else {
        Err("build with --features avian".into())
    }
}

/// The `avian2d` model.
#[derive(Debug, Clone, PartialEq)]
pub struct Avian2dModel {
    info: EngineInfo,
    /// The settings of a run (its `dt` is replaced by the run's).
    pub settings: Avian2dSettings,
}

impl Avian2dModel {
    /// The model with `settings`.
    pub fn new(settings: Avian2dSettings) -> Self {
        // First order: the trajectory's error is proportional to the substep
        // (measured: see the crate's README; the steady ω converges faster).
        let info = EngineInfo::new(
            "avian2d",
            "top-down rigid body, kinematic pusher through a revolute joint, Coulomb force at every support in Avian's substep loop",
            "pushval-avian",
            ENGINE_CRATE_2D,
            1.0,
            settings.dt,
        )
        .with_options(OptionKeys::Listed(OPTION_KEYS))
        .with_availability(availability());
        Self { info, settings }
    }
}

impl Default for Avian2dModel {
    fn default() -> Self {
        Self::new(Avian2dSettings::default())
    }
}

/// The `avian3d` model.
#[derive(Debug, Clone, PartialEq)]
pub struct Avian3dModel {
    info: EngineInfo,
    /// The settings of a run (its `dt` is replaced by the run's).
    pub settings: Avian3dSettings,
    /// The law it follows, built from `settings` by [`Avian3dModel::new`].
    law: Avian3dTilt,
}

impl Avian3dModel {
    /// The model with `settings`.
    pub fn new(settings: Avian3dSettings) -> Self {
        // First order in the step (measured: see the crate's README).
        let info = EngineInfo::new(
            "avian3d",
            "plate on ball feet on a floor, Avian's own contact friction (Coulomb along -u per contact point)",
            "pushval-avian",
            ENGINE_CRATE_3D,
            1.0,
            settings.dt,
        )
        .with_options(OptionKeys::Listed(&["substeps", "cm_height"]))
        .with_availability(availability());
        Self {
            info,
            settings,
            law: Avian3dTilt {
                plate: (&settings).into(),
            },
        }
    }
}

impl Default for Avian3dModel {
    fn default() -> Self {
        Self::new(Avian3dSettings::default())
    }
}

/// The Avian models: the crate's entries in pushval's engine registry.
pub fn models() -> Vec<ModelEntry> {
    vec![
        ModelEntry {
            name: "avian2d",
            build: |o| {
                let mut settings = Avian2dSettings::default();
                if let Some(dt) = o.dt {
                    settings.dt = dt;
                }
                if let Some(n) = substeps(o)? {
                    settings.substeps = n;
                }
                Ok(Box::new(Avian2dModel::new(settings)))
            },
        },
        ModelEntry {
            name: "avian3d",
            build: |o| {
                let mut settings = Avian3dSettings::default();
                if let Some(dt) = o.dt {
                    settings.dt = dt;
                }
                if let Some(n) = substeps(o)? {
                    settings.substeps = n;
                }
                if let Some(h) = o.non_negative("cm_height")? {
                    settings.cm_height = h;
                }
                Ok(Box::new(Avian3dModel::new(settings)))
            },
        },
    ]
}

impl Engine for Avian2dModel {
    fn info(&self) -> &EngineInfo {
        &self.info
    }
    fn settings(&self, dt: f64) -> serde_json::Value {
        let s = Avian2dSettings {
            dt,
            ..self.settings
        };
        serde_json::json!({
            "engine": self.info.version,
            "dt": dt,
            "substeps": s.substeps,
            "label": s.label(),
        })
    }
    fn law(&self) -> Option<&dyn FrictionLaw> {
        Some(avian2d_law())
    }
    /// The scene through the shared stepping loop
    /// ([`pushval_engine::stepping`]) on Avian's clock; an object not
    /// starting at rest starts with the first push applied.
    /// Without the `avian` feature: [`ModelError::Integration`] with
    /// [`crate::UNAVAILABLE`].
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        let sim = Avian2dSimulator::new(Avian2dSettings {
            dt,
            ..self.settings
        });
        sim.settings.check()?;
        let problem = problem.clone();
        // Avian's world is a Bevy `App`, which is not `Send`: it stays on
        // the session's own thread.
        pushval_engine::on_thread(move || {
            Ok(Box::new(Detailed::new(sim.start(&problem)?)) as Box<dyn EngineSession>)
        })
    }
}

impl Engine for Avian3dModel {
    fn info(&self) -> &EngineInfo {
        &self.info
    }
    fn settings(&self, dt: f64) -> serde_json::Value {
        let s = Avian3dSettings {
            dt,
            ..self.settings
        };
        serde_json::json!({
            "engine": self.info.version,
            "dt": dt,
            "substeps": s.substeps,
            "foot_radius": s.foot_radius,
            "cm_height": s.cm_height,
            "settle_time": s.settle_time,
            "label": s.label(),
        })
    }
    fn law(&self) -> Option<&dyn FrictionLaw> {
        Some(&self.law)
    }
    /// The scene, settled and calibrated, through the shared stepping loop
    /// ([`pushval_engine::stepping`]) on Avian's clock; an object not
    /// starting at rest starts with the first push applied.
    /// Without the `avian` feature: [`ModelError::Integration`] with
    /// [`crate::UNAVAILABLE`].
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        let sim = Avian3dSimulator::new(Avian3dSettings {
            dt,
            ..self.settings
        });
        sim.settings.check()?;
        let problem = problem.clone();
        // Avian's world is a Bevy `App`, which is not `Send`: it stays on
        // the session's own thread.
        pushval_engine::on_thread(move || {
            Ok(Box::new(Detailed::new(sim.start(&problem)?)) as Box<dyn EngineSession>)
        })
    }
}

/// The 2-D model applies Coulomb's law at every support.
pub(crate) fn avian2d_law() -> &'static dyn FrictionLaw {
    &COULOMB
}
