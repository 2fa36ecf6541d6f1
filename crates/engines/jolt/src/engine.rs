//! The Jolt models as pushval engine plug-ins: `jolt_box` (the plate as one
//! box collider) and `jolt_feet` (the plate on sphere feet), both on a
//! floor with Jolt 5.6's own friction. Without the `jolt` feature they are
//! listed but not available.

use pushval_engine::{
    Detailed, DetailedEngine, DetailedRun, Engine, EngineCrate, EngineInfo, EngineOptions,
    EngineRun, EngineSession, FrictionLaw, ModelEntry, OptionError, OptionKeys, Session,
};
use pushval_model::{ModelError, Problem, Trajectory};

use crate::predict::{JoltBox, JoltFeet};
use crate::{JoltRun, JoltSettings, JoltSimulator, Scene, AVAILABLE};

/// The engine crate and version this adapter is built against (the
/// `oxijolt-sys` entry of the workspace's Cargo.toml).
pub const ENGINE_CRATE: EngineCrate = EngineCrate {
    name: "oxijolt-sys",
    version: "1.5.0+jolt-5.6.0",
};

/// The Jolt Physics release oxijolt-sys vendors.
pub const JOLT_VERSION: &str = "5.6.0";

/// One Jolt model (a collider).
#[derive(Debug, Clone, PartialEq)]
pub struct JoltModel {
    info: EngineInfo,
    /// The settings of a run (its `dt` is replaced by the run's).
    pub settings: JoltSettings,
}

impl JoltModel {
    /// The model of `settings`' scene.
    pub fn new(settings: JoltSettings) -> Self {
        let description = match settings.scene {
            Scene::Box => {
                "plate as one box collider on a floor, Jolt 5.6 (one 4-point manifold: friction disc at the points' average plus a twist row)"
            }
            Scene::Feet => {
                "plate on sphere feet on a floor, Jolt 5.6 (one-point manifolds, manifold reduction off: a friction disc per foot)"
            }
        };
        // Symplectic Euler with the pusher at the mid-step heading: first order.
        let info = EngineInfo::new(
            settings.scene.model_name(),
            description,
            "pushval-jolt",
            ENGINE_CRATE,
            1.0,
            settings.dt,
        )
        .with_version(format!(
            "Jolt {JOLT_VERSION} ({} {})",
            ENGINE_CRATE.name, ENGINE_CRATE.version
        ))
        .with_options(OptionKeys::Listed(&["floor_convex_radius"]))
        .with_availability(if AVAILABLE {
            Ok(())
        } else {
            Err("build with --features jolt (needs cmake: apt-get install cmake)".into())
        });
        Self { info, settings }
    }
}

fn build(scene: Scene, opts: &EngineOptions) -> Result<Box<dyn Engine>, OptionError> {
    let mut settings = JoltSettings {
        scene,
        ..Default::default()
    };
    if let Some(dt) = opts.dt {
        settings.dt = dt;
    }
    if let Some(r) = opts.non_negative("floor_convex_radius")? {
        if r >= 0.5 {
            return Err(OptionError {
                key: "floor_convex_radius".into(),
                problem: format!("{r} m is not below the floor box's half height, 0.5 m"),
            });
        }
        settings.floor_convex_radius = r;
    }
    Ok(Box::new(JoltModel::new(settings)))
}

/// The Jolt models: the crate's entries in pushval's engine registry.
pub fn models() -> Vec<ModelEntry> {
    vec![
        ModelEntry {
            name: "jolt_box",
            build: |o| build(Scene::Box, o),
        },
        ModelEntry {
            name: "jolt_feet",
            build: |o| build(Scene::Feet, o),
        },
    ]
}

impl Engine for JoltModel {
    fn info(&self) -> &EngineInfo {
        &self.info
    }
    fn law(&self) -> Option<&dyn FrictionLaw> {
        match self.settings.scene {
            Scene::Box => Some(&JoltBox),
            Scene::Feet => Some(&JoltFeet),
        }
    }
    fn settings(&self, dt: f64) -> serde_json::Value {
        let s = JoltSettings {
            dt,
            ..self.settings
        };
        serde_json::json!({
            "engine": self.info.version,
            "dt": dt,
            "scene": s.scene.as_str(),
            "velocity_steps": s.velocity_steps,
            "position_steps": s.position_steps,
            "penetration_slop": s.penetration_slop,
            "floor_convex_radius": s.floor_convex_radius,
            "precision": "f64 positions, f32 solver",
            "label": s.label(),
        })
    }
    /// The scene, settled, through the shared stepping loop
    /// ([`pushval_engine::stepping`]); an object not starting at rest starts
    /// with the first push applied. Without the `jolt`
    /// feature: [`ModelError::Integration`] with [`crate::UNAVAILABLE`].
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        let sim = JoltSimulator::new(JoltSettings {
            dt,
            ..self.settings
        });
        sim.settings.check()?;
        let problem = problem.clone();
        // Jolt's world is raw pointers into the C API (joltc): it stays on
        // the session's own thread.
        pushval_engine::on_thread(move || {
            Ok(Box::new(Detailed::new(sim.start(&problem)?)) as Box<dyn EngineSession>)
        })
    }
}

impl DetailedRun for JoltRun {
    fn trajectory_mut(&mut self) -> &mut Trajectory {
        &mut self.trajectory
    }

    /// The run with Jolt's diagnostics (steps, drift, tilt, lift, rest
    /// loads, manifold sizes, μ; `loads` where the supports are the corners
    /// of the box's manifold) and its contact record.
    fn engine_run(self) -> EngineRun {
        let r = self;
        let mut diagnostics = serde_json::json!({
            "steps": r.steps,
            "max_joint_drift": r.max_joint_drift,
            "max_tilt": r.max_tilt,
            "max_lift": r.max_lift,
            "rest_loads": r.rest_loads,
            "manifold_sizes": r.manifold_sizes,
            "mu": r.mu,
        });
        // `jolt_box`: per corner of its manifold, reported only when the
        // corners are the supports (crate::JoltRun::loads).
        if let Some(loads) = &r.loads {
            diagnostics["loads"] = serde_json::json!(loads);
        }
        EngineRun {
            dt: r.settings.dt,
            steps: r.steps,
            wall_time: r.wall_time,
            diagnostics,
            trajectory: r.trajectory,
            contact: r.contact,
        }
    }
}
