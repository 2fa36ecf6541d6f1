//! The MuJoCo models as pushval engine plug-ins: `mujoco_pyramidal` and
//! `mujoco_elliptic`, the plate on sphere feet on a floor with MuJoCo's own
//! contact friction. Without the `mujoco` feature they are listed but not
//! available.

use pushval_engine::{
    Detailed, DetailedEngine, DetailedRun, Engine, EngineCrate, EngineInfo, EngineOptions,
    EngineRun, FrictionLaw, ModelEntry, OptionError, OptionKeys, Session,
};
use pushval_model::{ModelError, Problem, Trajectory};

use crate::theory::MujocoElliptic;
use crate::{Cone, MujocoRun, MujocoSettings, MujocoSimulator, AVAILABLE};

/// The engine crate and version this adapter is built against (the
/// `mujoco-rs` entry of the workspace's Cargo.toml, whose build metadata
/// names the MuJoCo library it binds; a test checks it against Cargo.lock).
pub const ENGINE_CRATE: EngineCrate = EngineCrate {
    name: "mujoco-rs",
    version: "7.0.0+mj-3.17.0",
};

/// One MuJoCo model (a friction cone).
#[derive(Debug, Clone, PartialEq)]
pub struct MujocoModel {
    info: EngineInfo,
    /// The settings of a run (its `timestep` is replaced by the run's dt).
    pub settings: MujocoSettings,
    /// The elliptic cone's law, built from `settings` by [`MujocoModel::new`].
    law: MujocoElliptic,
}

impl MujocoModel {
    /// What the model of `settings` is.
    fn info_of(settings: &MujocoSettings) -> EngineInfo {
        let (name, description) = match settings.cone {
            Cone::Pyramidal => (
                "mujoco_pyramidal",
                "plate on sphere feet on a floor, MuJoCo's soft contacts, pyramidal friction cone",
            ),
            Cone::Elliptic => (
                "mujoco_elliptic",
                "plate on sphere feet on a floor, MuJoCo's soft contacts, elliptic friction cone",
            ),
        };
        // Semi-implicit Euler: first order. Options: `cm_height` and
        // `push_height` (m, >= 0; [`MujocoSettings`]).
        EngineInfo::new(
            name,
            description,
            "pushval-mujoco",
            ENGINE_CRATE,
            1.0,
            settings.timestep,
        )
        .with_options(OptionKeys::Listed(&["cm_height", "push_height"]))
        .with_availability(if AVAILABLE {
            Ok(())
        } else {
            Err(
                "build with --features mujoco (it links MuJoCo 3.17's libmujoco.so: MUJOCO_DYNAMIC_LINK_DIR names its folder at build time, LD_LIBRARY_PATH at run time)"
                    .into(),
            )
        })
    }
}

fn build(cone: Cone, opts: &EngineOptions) -> Result<Box<dyn Engine>, OptionError> {
    let mut settings = MujocoSettings {
        cone,
        ..Default::default()
    };
    if let Some(dt) = opts.dt {
        settings.timestep = dt;
    }
    if let Some(h) = opts.non_negative("cm_height")? {
        settings.cm_height = h;
    }
    if let Some(h) = opts.non_negative("push_height")? {
        settings.push_height = h;
    }
    Ok(Box::new(MujocoModel::new(settings)))
}

/// The MuJoCo models: the crate's entries in pushval's engine registry.
pub fn models() -> Vec<ModelEntry> {
    vec![
        ModelEntry {
            name: "mujoco_pyramidal",
            build: |o| build(Cone::Pyramidal, o),
        },
        ModelEntry {
            name: "mujoco_elliptic",
            build: |o| build(Cone::Elliptic, o),
        },
    ]
}

impl Engine for MujocoModel {
    fn info(&self) -> &EngineInfo {
        &self.info
    }
    fn settings(&self, dt: f64) -> serde_json::Value {
        let s = MujocoSettings {
            timestep: dt,
            ..self.settings
        };
        serde_json::json!({
            "engine": self.info.version,
            "dt": dt,
            "timestep": dt,
            "cone": s.cone.as_str(),
            "cm_height": s.cm_height,
            "push_height": s.push_height,
            "label": s.label(),
        })
    }
    /// The elliptic cone follows Coulomb's law (`crate::theory`), with the
    /// loads moved by the tilting balance when the centre of mass or the
    /// pusher is above the floor; the pyramidal cone's lock on its diagonal
    /// has no closed form of ω here.
    fn law(&self) -> Option<&dyn FrictionLaw> {
        match self.settings.cone {
            Cone::Elliptic => Some(&self.law),
            Cone::Pyramidal => None,
        }
    }
    /// The scene, settled and calibrated, through the shared stepping loop
    /// ([`pushval_engine::stepping`]); an object not starting at rest starts
    /// with the first push applied. Without the `mujoco` feature:
    /// [`ModelError::Integration`] with [`crate::UNAVAILABLE`].
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        let sim = MujocoSimulator::new(MujocoSettings {
            timestep: dt,
            ..self.settings
        });
        Ok(Box::new(Detailed::new(sim.start(problem)?)))
    }
}

impl DetailedRun for MujocoRun {
    fn trajectory_mut(&mut self) -> &mut Trajectory {
        &mut self.trajectory
    }

    /// The run with MuJoCo's diagnostics (steps, pusher gap, penetration,
    /// tilt, the feet's loads) and its contact record.
    fn engine_run(self) -> EngineRun {
        let r = self;
        EngineRun {
            dt: r.settings.timestep,
            steps: r.steps,
            wall_time: r.wall_time,
            diagnostics: serde_json::json!({
                "steps": r.steps,
                "max_pusher_gap": r.max_pusher_gap,
                "max_penetration": r.max_penetration,
                "max_tilt": r.max_tilt,
                "loads": r.loads,
            }),
            trajectory: r.trajectory,
            contact: r.contact,
        }
    }
}

impl MujocoModel {
    /// The model with `settings` and the elliptic cone's law at its heights.
    pub fn new(settings: MujocoSettings) -> Self {
        Self {
            info: Self::info_of(&settings),
            settings,
            law: MujocoElliptic {
                cm_height: settings.cm_height,
                push_height: settings.push_height,
                gravity: settings.gravity,
            },
        }
    }

    /// Whether the centre of mass or the pusher is above the floor (the
    /// push then moves load between the feet).
    pub fn raised(&self) -> bool {
        self.law.raised()
    }
}
