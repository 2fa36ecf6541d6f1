//! The PhysX models as pushval engine plug-ins: `physx_patch`,
//! `physx_two_directional` and `physx_one_directional`, the plate on sphere
//! feet on a ground plane with each of PhysX's friction types. Without the
//! `physx` feature they are listed but not available.

use pushval_engine::{
    Detailed, DetailedEngine, DetailedRun, Engine, EngineCrate, EngineInfo, EngineOptions,
    EngineRun, EngineSession, FrictionLaw, ModelEntry, OptionError, OptionKeys, Session,
};
use pushval_model::{ModelError, Problem, Trajectory};

use crate::predict::PhysxClamp;
use crate::{FootContacts, FrictionType, PhysxRun, PhysxSettings, PhysxSimulator, AVAILABLE};

/// The engine crate and version this adapter is built against (the `physx`
/// entry of the workspace's Cargo.toml; a test checks it against Cargo.lock).
pub const ENGINE_CRATE: EngineCrate = EngineCrate {
    name: "physx",
    version: "0.19.0",
};

/// The PhysX SDK the `physx` crate builds (physx-sys 0.11.5 vendors it;
/// `PX_PHYSICS_VERSION` 5.1.3).
pub const PHYSX_SDK_VERSION: &str = "5.1.3";

/// One PhysX model (a friction type).
#[derive(Debug, Clone, PartialEq)]
pub struct PhysxModel {
    info: EngineInfo,
    /// The settings of a run (its `dt` is replaced by the run's).
    pub settings: PhysxSettings,
    /// The law it follows, built from `settings` by [`PhysxModel::new`].
    law: PhysxClamp,
}

impl PhysxModel {
    /// What the model of `settings` is.
    fn info_of(settings: &PhysxSettings) -> EngineInfo {
        let description = match settings.friction {
            FrictionType::Patch => {
                "plate on sphere feet on a ground plane, PhysX 5 PGS, patch friction (ePATCH)"
            }
            FrictionType::TwoDirectional => {
                "plate on sphere feet on a ground plane, PhysX 5 PGS, per-point two-axis friction (eTWO_DIRECTIONAL)"
            }
            FrictionType::OneDirectional => {
                "plate on sphere feet on a ground plane, PhysX 5 PGS, per-point one-axis friction (eONE_DIRECTIONAL)"
            }
        };
        // Symplectic Euler with the pusher at the mid-step heading: first order.
        EngineInfo::new(
            settings.friction.model_name(),
            description,
            "pushval-physx",
            ENGINE_CRATE,
            1.0,
            settings.dt,
        )
        .with_version(format!(
            "{} {} (PhysX {})",
            ENGINE_CRATE.name, ENGINE_CRATE.version, PHYSX_SDK_VERSION
        ))
        .with_options(OptionKeys::Listed(&[
            "contacts",
            "position_iterations",
            "velocity_iterations",
        ]))
        .with_availability(if AVAILABLE {
            Ok(())
        } else {
            Err("build with --features physx (needs clang++: apt-get install clang)".into())
        })
    }
}

fn build(friction: FrictionType, opts: &EngineOptions) -> Result<Box<dyn Engine>, OptionError> {
    let mut settings = PhysxSettings {
        friction,
        ..Default::default()
    };
    if let Some(dt) = opts.dt {
        settings.dt = dt;
    }
    if let Some(c) = opts.choice("contacts", &["welded", "separate"])? {
        settings.contacts = if c == "separate" {
            FootContacts::Separate
        } else {
            FootContacts::Welded
        };
    }
    if let Some(n) = opts.integer("position_iterations", 1)? {
        settings.position_iterations = n.min(255) as u32;
    }
    if let Some(n) = opts.integer("velocity_iterations", 1)? {
        settings.velocity_iterations = n.min(255) as u32;
    }
    Ok(Box::new(PhysxModel::new(settings)))
}

/// The PhysX models: the crate's entries in pushval's engine registry.
pub fn models() -> Vec<ModelEntry> {
    vec![
        ModelEntry {
            name: "physx_patch",
            build: |o| build(FrictionType::Patch, o),
        },
        ModelEntry {
            name: "physx_two_directional",
            build: |o| build(FrictionType::TwoDirectional, o),
        },
        ModelEntry {
            name: "physx_one_directional",
            build: |o| build(FrictionType::OneDirectional, o),
        },
    ]
}

impl Engine for PhysxModel {
    fn info(&self) -> &EngineInfo {
        &self.info
    }
    fn law(&self) -> Option<&dyn FrictionLaw> {
        Some(&self.law)
    }
    fn settings(&self, dt: f64) -> serde_json::Value {
        let s = PhysxSettings {
            dt,
            ..self.settings
        };
        serde_json::json!({
            "engine": self.info.version,
            "dt": dt,
            "friction_type": s.friction.physx_name(),
            "contacts": s.contacts.as_str(),
            "position_iterations": s.position_iterations,
            "velocity_iterations": s.velocity_iterations,
            "precision": "f32",
            "label": s.label(),
        })
    }
    /// The scene, settled, through the shared stepping loop
    /// ([`pushval_engine::stepping`]); an object not starting at rest starts
    /// with the first push applied. The session holds
    /// PhysX's turn (one foundation per process) until it ends. Without the
    /// `physx` feature: [`ModelError::Integration`] with
    /// [`crate::UNAVAILABLE`].
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        let sim = PhysxSimulator::new(PhysxSettings {
            dt,
            ..self.settings
        });
        sim.settings.check()?;
        let problem = problem.clone();
        // PhysX's objects are raw pointers into the SDK, and the session
        // holds PhysX's turn (a `MutexGuard`, released on the thread that
        // took it): the world stays on the session's own thread.
        pushval_engine::on_thread(move || {
            Ok(Box::new(Detailed::new(sim.start(&problem)?)) as Box<dyn EngineSession>)
        })
    }
}

impl DetailedRun for PhysxRun {
    fn trajectory_mut(&mut self) -> &mut Trajectory {
        &mut self.trajectory
    }

    /// The run with PhysX's diagnostics (steps, drift, tilt, lift, rest
    /// loads, μ, the feet's loads) and its contact record.
    fn engine_run(self) -> EngineRun {
        let r = self;
        EngineRun {
            dt: r.settings.dt,
            steps: r.steps,
            wall_time: r.wall_time,
            diagnostics: serde_json::json!({
                "steps": r.steps,
                "max_joint_drift": r.max_joint_drift,
                "max_tilt": r.max_tilt,
                "max_lift": r.max_lift,
                "rest_loads": r.rest_loads,
                "mu": r.mu,
                "loads": r.loads,
            }),
            trajectory: r.trajectory,
            contact: r.contact,
        }
    }
}

impl PhysxModel {
    /// The model with `settings` and the law of its friction type and feet
    /// ([`PhysxClamp`]).
    pub fn new(settings: PhysxSettings) -> Self {
        Self {
            info: Self::info_of(&settings),
            settings,
            law: PhysxClamp {
                friction: settings.friction,
                contacts: settings.contacts,
                plate_thickness: settings.plate_thickness,
                gravity: settings.gravity,
            },
        }
    }

    /// The closed form of PhysX's rest loads for `problem` (N, support
    /// order; [`PhysxClamp::rest_loads`]).
    pub fn rest_loads(&self, problem: &Problem) -> Vec<f64> {
        self.law.rest_loads(problem)
    }
}
