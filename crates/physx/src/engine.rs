//! The PhysX models as pushval engine plug-ins: `physx_patch`,
//! `physx_two_directional` and `physx_one_directional`, the plate on sphere
//! feet on a ground plane with each of PhysX's friction types. Without the
//! `physx` feature they are listed but not available.

use pushval_engine::{
    Engine, EngineCrate, EngineInfo, EngineOptions, EngineRun, FrictionLaw, LawClass, LawSteady,
    ModelEntry, OptionError, OptionKeys,
};
use pushval_model::{ModelError, Problem};

use pushval_model::{Body, Support};

use crate::predict::{
    at_rest, lock_moments, pgs_rest_loads, rest_moments, steady_from_rest, AtRest,
};
use crate::{FootContacts, FrictionType, PhysxSettings, PhysxSimulator, AVAILABLE};

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
}

impl PhysxModel {
    /// The model of `settings`' friction type.
    pub fn new(settings: PhysxSettings) -> Self {
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
        let info = EngineInfo::new(
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
        });
        Self { info, settings }
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
        Some(self)
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
    fn run(&self, problem: &Problem, dt: f64) -> Result<EngineRun, ModelError> {
        let r = PhysxSimulator::new(PhysxSettings {
            dt,
            ..self.settings
        })
        .run(problem)?;
        Ok(EngineRun {
            dt,
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
        })
    }
}

/// PhysX's friction rows in closed form (`crate::predict`), capped by the
/// friction PhysX gives the feet at rest (`μ̄ N_i`, N_i the PGS split of
/// [`pgs_rest_loads`]): the law of the friction type on welded or separate
/// feet, the class of ω = 0 from the
/// lock (`|M₀| ≤ H`) and hold (`|M₀| ≤ S`) criteria, and the steady ω a run
/// from rest reaches. PhysX's contact order is taken as the supports' order
/// (on the paper plate it gives feet 0 and 2 the `t0` rows, as PhysX does).
impl FrictionLaw for PhysxModel {
    fn law_name(&self) -> &'static str {
        match (self.settings.contacts, self.settings.friction) {
            (FootContacts::Welded, FrictionType::Patch) => {
                "one welded patch: t0/t1 rows at two anchors, each capped at half of μΣN (pushval_physx::predict)"
            }
            (FootContacts::Welded, FrictionType::OneDirectional) => {
                "one welded patch: one row per foot, t0 and t1 alternating, cap μN (pushval_physx::predict)"
            }
            (FootContacts::Separate, FrictionType::OneDirectional) => {
                "a t0 row per foot along the centre of mass's velocity, cap μN (pushval_physx::predict)"
            }
            _ => "a t0 and a t1 row per foot, each capped at μN: a box (pushval_physx::predict)",
        }
    }
    fn steady(&self, problem: &Problem, segment: usize, _dt: f64) -> Option<LawSteady> {
        let push = problem.pushes.get(segment)?;
        let body = &self.engine_body(problem)?;
        let points: Vec<[f64; 2]> = body
            .supports()
            .map(|s| [s.position.x, s.position.y])
            .collect();
        let order: Vec<usize> = (0..points.len()).collect();
        let law = self
            .settings
            .friction
            .law(self.settings.contacts, &order, &points);
        let class = match at_rest(body, push, law) {
            AtRest::Locked => LawClass::Locked,
            AtRest::Turns => LawClass::Turns,
            AtRest::SemiStable => {
                let (moment, lock) = lock_moments(body, push, law);
                LawClass::SemiStable {
                    moment,
                    lock,
                    hold: rest_moments(body, push, law).1,
                }
            }
        };
        Some(LawSteady {
            omega: steady_from_rest(body, push, law).omega,
            class,
        })
    }
    /// PhysX's loads at rest ([`pgs_rest_loads`]: the PGS split of `m g`
    /// over the feet, in the supports' order). The centre of mass and the
    /// pusher are on the floor's plane, so the push moves no load.
    fn loads(&self, problem: &Problem, _segment: usize, _dt: f64) -> Option<Vec<f64>> {
        Some(self.rest_loads(problem))
    }
}

impl PhysxModel {
    /// The closed form of PhysX's rest loads for `problem` (N, support
    /// order; [`pgs_rest_loads`] with the scene's mass, tilt inertia and
    /// gravity, contacts visited in the supports' order).
    pub fn rest_loads(&self, problem: &Problem) -> Vec<f64> {
        let body = &problem.body;
        let s = &self.settings;
        let points: Vec<[f64; 2]> = body
            .supports()
            .map(|p| [p.position.x, p.position.y])
            .collect();
        let order: Vec<usize> = (0..points.len()).collect();
        let t = s.plate_thickness;
        let tilt = 0.5 * body.inertia_cm() + body.mass() * t * t / 12.0;
        pgs_rest_loads(&points, body.mass(), tilt, body.mass() * s.gravity, &order)
    }

    /// The body the law's rows see: every foot's cap `μ̄ N_i` with PhysX's
    /// one coefficient `μ̄ = Σ F_i / (m g)` and its rest loads
    /// ([`Self::rest_loads`]), as the engine has them.
    fn engine_body(&self, problem: &Problem) -> Option<Body> {
        let body = &problem.body;
        let mu = body.total_friction() / (body.mass() * self.settings.gravity);
        let supports: Vec<Support> = body
            .supports()
            .zip(self.rest_loads(problem))
            .map(|(s, n)| Support {
                position: s.position,
                friction: mu * n,
            })
            .collect();
        Body::new(body.mass(), body.inertia_cm(), body.contact(), &supports).ok()
    }
}
