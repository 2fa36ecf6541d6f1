//! The rapier3d models as pushval engine plug-ins: `rapier3d` (rapier's
//! `FrictionModel::Coulomb`) and `rapier3d_simplified` (its default,
//! `Simplified`), the plate on ball feet on a ground plane.

use pushval_engine::{
    Detailed, DetailedEngine, Engine, EngineCrate, EngineInfo, EngineOptions, FrictionLaw,
    ModelEntry, OptionError, OptionKeys, Session,
};
use pushval_model::{ModelError, Problem};

use crate::predict::{Law, Rapier3dTilt, SceneParams};
use crate::{ContactFriction, FeetColliders, Rapier3dSettings, Rapier3dSimulator};

/// The engine crate and version this adapter is built against (the
/// `rapier3d-f64` entry of the workspace's Cargo.toml; a test checks it
/// against Cargo.lock).
pub const ENGINE_CRATE: EngineCrate = EngineCrate {
    name: "rapier3d-f64",
    version: "0.36.1",
};

/// One rapier3d model.
#[derive(Debug, Clone, PartialEq)]
pub struct Rapier3dModel {
    info: EngineInfo,
    /// The settings of a run (its `dt` is replaced by the run's).
    pub settings: Rapier3dSettings,
    /// The law it follows, built from `settings` by [`Rapier3dModel::new`].
    law: Rapier3dTilt,
}

impl Rapier3dModel {
    /// What the model of `settings` is.
    fn info_of(settings: &Rapier3dSettings) -> EngineInfo {
        let (name, description) = match settings.friction {
            ContactFriction::Coulomb => (
                "rapier3d",
                "plate on ball feet on a ground plane, rapier's own contact friction (FrictionModel::Coulomb)",
            ),
            ContactFriction::Simplified => (
                "rapier3d_simplified",
                "plate on ball feet on a ground plane, rapier's default FrictionModel::Simplified",
            ),
        };
        // Symplectic Euler with the pusher at the mid-step heading: first order.
        EngineInfo::new(
            name,
            description,
            "pushval-rapier3d",
            ENGINE_CRATE,
            1.0,
            settings.dt,
        )
        .with_options(OptionKeys::Listed(&["feet", "cm_height", "push_height"]))
    }
}

fn build(friction: ContactFriction, opts: &EngineOptions) -> Result<Box<dyn Engine>, OptionError> {
    let mut settings = Rapier3dSettings {
        friction,
        ..Default::default()
    };
    if let Some(dt) = opts.dt {
        settings.dt = dt;
    }
    if let Some(f) = opts.choice("feet", &["compound", "separate"])? {
        settings.feet = if f == "separate" {
            FeetColliders::Separate
        } else {
            FeetColliders::Compound
        };
    }
    // The ball feet hang below the centre of mass: it must be above the floor.
    if let Some(h) = opts.positive("cm_height")? {
        settings.cm_height = h;
    }
    if let Some(h) = opts.non_negative("push_height")? {
        settings.push_height = h;
    }
    Ok(Box::new(Rapier3dModel::new(settings)))
}

/// The rapier3d models: the crate's entries in pushval's engine registry.
pub fn models() -> Vec<ModelEntry> {
    vec![
        ModelEntry {
            name: "rapier3d",
            build: |o| build(ContactFriction::Coulomb, o),
        },
        ModelEntry {
            name: "rapier3d_simplified",
            build: |o| build(ContactFriction::Simplified, o),
        },
    ]
}

impl Engine for Rapier3dModel {
    fn info(&self) -> &EngineInfo {
        &self.info
    }
    fn law(&self) -> Option<&dyn FrictionLaw> {
        Some(&self.law)
    }
    fn settings(&self, dt: f64) -> serde_json::Value {
        let s = Rapier3dSettings {
            dt,
            ..self.settings
        };
        serde_json::json!({
            "engine": self.info.version,
            "dt": s.dt,
            "friction_model": s.friction.as_str(),
            "feet": s.feet.as_str(),
            "cm_height": s.cm_height,
            "push_height": s.push_height,
            "label": s.label(),
        })
    }
    /// The scene, settled, through the shared stepping loop
    /// ([`pushval_engine::stepping`]), owned by the session; an object not
    /// starting at rest starts with the first push applied.
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        let sim = Rapier3dSimulator::new(Rapier3dSettings {
            dt,
            ..self.settings
        });
        Ok(Box::new(Detailed::new(sim.start(problem)?)))
    }
}

impl Rapier3dModel {
    /// The closed form that predicts the engine: `Simplified` on one
    /// manifold (compound feet) has the twist limit; otherwise every contact
    /// slides along `−K⁻¹u` (rapier's per-contact solve).
    pub fn predict_law(&self) -> Law {
        if self.settings.friction == ContactFriction::Simplified
            && self.settings.feet == FeetColliders::Compound
        {
            Law::SimplifiedOneManifold
        } else {
            Law::EffectiveMassDisk
        }
    }
}

impl Rapier3dModel {
    /// The model with `settings` and the law they give
    /// ([`Rapier3dModel::predict_law`] on the settings' scene).
    pub fn new(settings: Rapier3dSettings) -> Self {
        let mut m = Self {
            info: Self::info_of(&settings),
            settings,
            law: Rapier3dTilt::contact_disk(SceneParams::from(&settings)),
        };
        m.law.law = m.predict_law();
        m
    }
}
