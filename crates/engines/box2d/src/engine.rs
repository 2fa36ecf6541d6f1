//! The Box2D models as pushval engine plug-ins: `box2d` (per-support
//! Coulomb forces, gateable) and `box2d_motor_joint` (Box2D's top-down
//! friction idiom, informational).

use pushval_engine::{
    on_thread, Detailed, DetailedEngine, Engine, EngineCrate, EngineInfo, EngineOptions,
    EngineSession, FrictionLaw, ModelEntry, OptionError, OptionKeys, Session, COULOMB,
};
use pushval_model::{ModelError, Problem};

use crate::predict::Box2dMotorJoint;
use crate::{Box2dSettings, Box2dSimulator, Friction};

/// The engine crate and version this adapter is built against (the `boxdd`
/// entry of the workspace's Cargo.toml; a test checks it against
/// Cargo.lock).
pub const ENGINE_CRATE: EngineCrate = EngineCrate {
    name: "boxdd",
    version: "0.6.0",
};

/// The Box2D source boxdd 0.6.0 builds (its README: a pinned Box2D 3.2.0
/// development snapshot).
const BOX2D_SOURCE: &str = "Box2D 3.2.0 snapshot 56edae7";

/// The `[engine]` keys the Box2D models read, besides `dt`.
const OPTION_KEYS: &[&str] = &["substeps"];

/// One Box2D model: a friction law and the scenario's engine settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Box2dModel {
    info: EngineInfo,
    /// The settings of a run (its `dt` is replaced by the run's).
    pub settings: Box2dSettings,
}

impl Box2dModel {
    /// The model of `settings`' friction law.
    pub fn new(settings: Box2dSettings) -> Self {
        let (name, description) = match settings.friction {
            Friction::Coulomb => (
                "box2d",
                "Box2D v3: top-down rigid body, kinematic pusher through a revolute joint, Coulomb force at every support",
            ),
            Friction::MotorJoint => (
                "box2d_motor_joint",
                "Box2D v3 top-down friction idiom: motor joint to the ground capped at mu m g and mu m g r_mean, no per-support forces",
            ),
        };
        // First order: the friction forces are explicit in the step-start
        // state and the pusher is steered at the step-start heading
        // (measured: see the crate's README).
        let info = EngineInfo::new(
            name,
            description,
            "pushval-box2d",
            ENGINE_CRATE,
            1.0,
            settings.dt,
        )
        .with_version(format!(
            "{} {} ({BOX2D_SOURCE}, f64 positions)",
            ENGINE_CRATE.name, ENGINE_CRATE.version
        ))
        .with_options(OptionKeys::Listed(OPTION_KEYS));
        Self { info, settings }
    }
}

/// The settings the `[engine]` table asks for, over the adapter's defaults.
pub fn settings_from(opts: &EngineOptions) -> Result<Box2dSettings, OptionError> {
    let mut s = Box2dSettings::default();
    if let Some(dt) = opts.dt {
        s.dt = dt;
    }
    if let Some(n) = opts.integer("substeps", 1)? {
        if n > 64 {
            return Err(OptionError {
                key: "substeps".into(),
                problem: format!("must be an integer in 1..=64, got {n}"),
            });
        }
        s.substeps = n;
    }
    Ok(s)
}

fn build(friction: Friction, opts: &EngineOptions) -> Result<Box<dyn Engine>, OptionError> {
    let settings = Box2dSettings {
        friction,
        ..settings_from(opts)?
    };
    Ok(Box::new(Box2dModel::new(settings)))
}

/// The Box2D models, one row each: the crate's entries in pushval's engine
/// registry.
pub fn models() -> Vec<ModelEntry> {
    vec![
        ModelEntry {
            name: "box2d",
            build: |o| build(Friction::Coulomb, o),
        },
        ModelEntry {
            name: "box2d_motor_joint",
            build: |o| build(Friction::MotorJoint, o),
        },
    ]
}

impl Engine for Box2dModel {
    fn info(&self) -> &EngineInfo {
        &self.info
    }
    fn settings(&self, dt: f64) -> serde_json::Value {
        let s = Box2dSettings {
            dt,
            ..self.settings
        };
        serde_json::json!({
            "engine": self.info.version,
            "dt": s.dt,
            "substeps": s.substeps,
            "friction_model": s.friction.as_str(),
            "joint_hertz": s.joint_hertz,
            "joint_damping_ratio": crate::JOINT_DAMPING_RATIO,
            "label": s.label(),
        })
    }
    fn law(&self) -> Option<&dyn FrictionLaw> {
        match self.settings.friction {
            Friction::Coulomb => Some(&COULOMB),
            Friction::MotorJoint => Some(&Box2dMotorJoint),
        }
    }
    /// The Box2D world through the shared stepping loop
    /// ([`pushval_engine::stepping`]), on a thread the session owns (the
    /// Box2D world is a handle into a C library's memory: it stays on the
    /// thread that created it); an object not starting at rest starts with
    /// the first push applied.
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        let sim = Box2dSimulator::new(Box2dSettings {
            dt,
            ..self.settings
        });
        sim.settings.check()?;
        let problem = problem.clone();
        on_thread(move || {
            Ok(Box::new(Detailed::new(sim.start(&problem)?)) as Box<dyn EngineSession>)
        })
    }
}
