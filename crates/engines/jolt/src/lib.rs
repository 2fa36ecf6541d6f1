//! The pushing problem of `pushval-model` as a 3-D scene in Jolt Physics
//! 5.6.0 (through `oxijolt-sys` 1.5.0, which vendors Jolt and its C API
//! joltc and builds them with CMake), with **Jolt's own** contact friction.
//!
//! The scene (z up, gravity `(0, 0, −g)`):
//!
//! * **Floor**: a static box whose top face is z = 0, friction μ̄.
//! * **Object**: a dynamic body whose centre of mass is at the problem's
//!   centre of mass **at the height of the ground contacts** (z = 0; an
//!   `OffsetCenterOfMassShape` around the collider), mass `m` and inertia
//!   given directly (`MassAndInertiaProvided`: yaw `I_cm`, the tilt axes
//!   `I_cm/2 + m t²/12`), linear and angular damping 0 (Jolt's default is
//!   0.05), sleeping off, friction μ̄. Jolt combines two frictions by their
//!   geometric mean, `√(μ̄ μ̄) = μ̄` exactly in IEEE arithmetic: μ̄ reaches
//!   the contact unchanged. Its collider is one of ([`Scene`]):
//!   - `jolt_box`: one box spanning the supports' bounding rectangle,
//!     [`JoltSettings::plate_thickness`] thick (one manifold of 4 points);
//!   - `jolt_feet`: a static compound of one sphere per support (radius
//!     [`JoltSettings::foot_radius`], lowest point at the support), manifold
//!     reduction off so every foot keeps its own one-point manifold.
//! * **Pusher**: a kinematic body (a sphere in a layer that collides with
//!   nothing) joined to the object's contact point by a six-DOF constraint
//!   whose only fixed axes are the two horizontal translations (world
//!   axes): it transmits a horizontal force and nothing else. Before every
//!   step it is put back onto the contact point and given the commanded
//!   contact velocity `v_c R(θ_m) n_φ` (θ_m the yaw at mid-step).
//!
//! μ̄ = `Σ F_i / (m g)`, one coefficient for every contact (as the PhysX
//! crate): Jolt decides how the weight is shared between the contacts.
//! [`predict`] holds Jolt's friction law in closed form.
//!
//! **The release** removes the six-DOF constraint and stops the pusher;
//! the plate slides to rest under the same contact friction (pushval's
//! rule: `|v_cm| + |ω| L` below 1e-5 m/s for 10 steps). Jolt's friction
//! rows are velocity constraints solved by sequential impulses and clamped
//! to the disc `μ Σλ`: a slip that an impulse within the disc can remove is
//! removed, so the plate sticks at the stop instead of chattering. In pure
//! translation of a plate square to the world axes (or the box) that is
//! Coulomb's stop, `v²/(2μg)` after `v/(μg)`; the feet of a turned plate
//! have rows of unequal effective masses, so their friction is not against
//! the slip ([`predict`]) and the plate slides farther.
//!
//! Each run builds its own physics system with a single-threaded job
//! system; joltc's global set-up is serialised by a lock.
//!
//! Without the `jolt` feature the crate builds with no Jolt ([`AVAILABLE`]
//! is false) and `JoltSimulator`'s `start` (and so `run`) returns an error.
//!
//! Units are SI throughout (m, s, rad, kg, N).
#![warn(missing_docs)]

use std::time::Duration;

use pushval_engine::FirstPush;
use pushval_model::{ModelError, Problem, Simulator, Trajectory};

mod engine;
/// Jolt's friction law in closed form (it lives in `pushval-laws`).
pub use pushval_laws::jolt as predict;
#[cfg(feature = "jolt")]
#[allow(unsafe_code)]
mod sys;
#[cfg(feature = "jolt")]
mod world;

pub use engine::{models, JoltModel, ENGINE_CRATE, JOLT_VERSION};
pub use pushval_engine::{DetailedEngine, DetailedSession};

/// True when this build has Jolt (feature `jolt`).
pub const AVAILABLE: bool = cfg!(feature = "jolt");

/// The message of the error a build without the `jolt` feature returns.
pub const UNAVAILABLE: &str =
    "pushval was built without the `jolt` feature (needs cmake: apt-get install cmake)";

/// The object's collider.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Scene {
    /// One box: one manifold of four points, friction at their average plus
    /// a twist row.
    #[default]
    Box,
    /// One sphere per support: one-point manifolds, no twist rows.
    Feet,
}

impl Scene {
    /// `"box"` or `"feet"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Scene::Box => "box",
            Scene::Feet => "feet",
        }
    }

    /// The engine model's name: `jolt_box` or `jolt_feet`.
    pub fn model_name(&self) -> &'static str {
        match self {
            Scene::Box => "jolt_box",
            Scene::Feet => "jolt_feet",
        }
    }

    /// Both, box first.
    pub const ALL: [Scene; 2] = [Scene::Box, Scene::Feet];
}

/// How Jolt runs a problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JoltSettings {
    /// Largest time step (s); default `1e-3`. Each push segment is cut into
    /// `ceil(duration / dt)` equal steps.
    pub dt: f64,
    /// The collider; default [`Scene::Box`].
    pub scene: Scene,
    /// Radius of the sphere feet (m); default `0.003`.
    pub foot_radius: f64,
    /// Plate thickness (m): the box's height and the tilt inertias; default
    /// `0.005`.
    pub plate_thickness: f64,
    /// Velocity iterations (`PhysicsSettings::mNumVelocitySteps`); default 10
    /// (Jolt's).
    pub velocity_steps: u32,
    /// Position iterations (`mNumPositionSteps`); default 2 (Jolt's).
    pub position_steps: u32,
    /// Penetration slop (m), Jolt's `mPenetrationSlop` (default 0.02 there):
    /// default `1e-5` here, so the object rests with its contacts at the
    /// height of its centre of mass rather than up to 2 cm below it.
    pub penetration_slop: f64,
    /// Gravity (m/s²); default 9.81.
    pub gravity: f64,
    /// Duration (s) of the settle phase before the push; default 0.3.
    pub settle_time: f64,
    /// Convex radius of the floor box (m): default 0.05, Jolt's
    /// `cDefaultConvexRadius`, as Jolt users build a floor. Radius 0 (sharp
    /// edges and faces) made the foot contacts chatter: per-step loads from
    /// 0 to 25 N on the 9.81 N plate (results/friction_models/jolt_feet).
    pub floor_convex_radius: f64,
}

impl Default for JoltSettings {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            scene: Scene::Box,
            foot_radius: 0.003,
            plate_thickness: 0.005,
            velocity_steps: 10,
            position_steps: 2,
            penetration_slop: 1e-5,
            gravity: 9.81,
            settle_time: 0.3,
            floor_convex_radius: 0.05,
        }
    }
}

impl JoltSettings {
    /// A short label, e.g. `jolt[box,dt=0.001,iters=10/2]`.
    pub fn label(&self) -> String {
        format!(
            "jolt[{},dt={},iters={}/{}]",
            self.scene.as_str(),
            self.dt,
            self.velocity_steps,
            self.position_steps
        )
    }

    /// Checks the settings; errors name the field.
    pub fn check(&self) -> Result<(), ModelError> {
        let positive = ModelError::require_positive;
        let non_negative = ModelError::require_non_negative;
        positive("jolt dt", self.dt)?;
        positive("jolt foot_radius", self.foot_radius)?;
        positive("jolt plate_thickness", self.plate_thickness)?;
        positive("jolt gravity", self.gravity)?;
        non_negative("jolt penetration_slop", self.penetration_slop)?;
        non_negative("jolt settle_time", self.settle_time)?;
        non_negative("jolt floor_convex_radius", self.floor_convex_radius)?;
        // Jolt's box needs every half extent above its convex radius (the
        // floor's smallest is 0.5 m).
        if self.floor_convex_radius >= 0.5 {
            return Err(ModelError::Parameter {
                name: "jolt floor_convex_radius",
                requirement: "< 0.5 m (the floor box's half height)",
                value: self.floor_convex_radius,
            });
        }
        for (name, n) in [
            ("jolt velocity_steps", self.velocity_steps),
            ("jolt position_steps", self.position_steps),
        ] {
            if !(1..=255).contains(&n) {
                return Err(ModelError::Parameter {
                    name,
                    requirement: "in 1..=255",
                    value: n as f64,
                });
            }
        }
        Ok(())
    }
}

/// What Jolt's contact cache says about one support (a foot, or a corner of
/// the box), averaged over a window of steps.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SupportContact {
    /// Normal force (N): the contact point's normal impulse over the step.
    pub normal: f64,
    /// Friction force of its manifold (N, world frame, on the object): the
    /// two linear rows' impulses over the step. For the box the one
    /// manifold's force, the same at every corner.
    pub friction: [f64; 2],
    /// The twist row's torque (N m, about +z, on the object); 0 without one.
    pub twist: f64,
    /// Slip velocity of the manifold's friction point (m/s, world frame).
    pub slip: [f64; 2],
}

/// A Jolt run: the trajectory and what the engine did.
#[derive(Debug, Clone, PartialEq)]
pub struct JoltRun {
    /// The trajectory sampled at [`Problem::sample_times`].
    pub trajectory: Trajectory,
    /// The settings used.
    pub settings: JoltSettings,
    /// Engine steps of the push (settle steps excluded).
    pub steps: usize,
    /// Wall-clock time of the run.
    pub wall_time: Duration,
    /// The friction coefficient of every contact, `μ̄ = Σ F_i / (m g)`.
    pub mu: f64,
    /// Normal force (N) of each support at rest (mean over the last 20 % of
    /// the settle phase): box corners in the order of
    /// [`predict::box_corners`], feet in the problem's order.
    pub rest_loads: Vec<f64>,
    /// The time-weighted mean normal force of each support over the last
    /// fifth of the run (N), in the problem's support order: the engine
    /// diagnostics' `"loads"`. Jolt reports a normal impulse per contact
    /// point, so `jolt_box` has one per corner of its manifold; they are the
    /// supports' loads when every support sits on a corner of the box, and
    /// None otherwise.
    pub loads: Option<Vec<f64>>,
    /// The supports' loads at every sample (empty where the box's corners
    /// are not the supports, as for [`JoltRun::loads`]), the largest rise
    /// and the share of steps with a contact point out of contact.
    pub contact: Option<pushval_engine::ContactRecord>,
    /// Number of manifolds between the object and the floor after the
    /// settle phase, and their sizes (contact points each).
    pub manifold_sizes: Vec<usize>,
    /// Per segment, the mean ω (rad/s) over its last 20 % of steps.
    pub segment_tail_omega: Vec<f64>,
    /// Per segment, the standard deviation of ω over the same steps (rad/s).
    pub segment_tail_omega_std: Vec<f64>,
    /// Per segment, each support's contact over the same steps.
    pub segment_tail_contacts: Vec<Vec<SupportContact>>,
    /// Per segment, the largest angle (rad) between a manifold's friction
    /// force and its point's slip's opposite over the tail (0 for Coulomb).
    pub segment_tail_max_angle: Vec<f64>,
    /// Per segment, the largest difference (rad) over the tail between a
    /// manifold's measured friction–slip angle and the angle of
    /// [`predict::Direction::EffectiveMass`] for the same slip and point.
    pub segment_tail_max_angle_vs_law: Vec<f64>,
    /// Per segment, each support's smallest and largest normal force (N)
    /// over the tail: four rigid feet leave the split undetermined, and
    /// Jolt's solver moves along it while the plate slides.
    pub segment_tail_load_range: Vec<Vec<[f64; 2]>>,
    /// Largest tilt (rad) over the push.
    pub max_tilt: f64,
    /// Largest vertical displacement of the centre of mass from its height
    /// at the end of the settle phase (m).
    pub max_lift: f64,
    /// Largest horizontal distance (m) between the pusher and the contact
    /// point after a step (before the pusher is put back).
    pub max_joint_drift: f64,
    /// Every step of the push, after an initial record at t = 0:
    /// `(segment, t0, t1, x, y, theta, omega)`.
    pub history: Vec<pushval_engine::StepRecord>,
}

/// Jolt as a [`Simulator`] (names `jolt_box`, `jolt_feet`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JoltSimulator {
    /// How it runs.
    pub settings: JoltSettings,
}

impl JoltSimulator {
    /// A simulator with the given settings.
    pub fn new(settings: JoltSettings) -> Self {
        Self { settings }
    }
}

/// A Jolt session: the scene, settled, pushed one push at a time. Not
/// `Send`: Jolt's world is raw pointers into its C API (joltc) and stays on
/// the thread that built it (the [`Engine`](pushval_engine::Engine) session
/// builds it on a thread of its own). Built at the first push for an object
/// that starts moving.
pub type JoltSession = FirstPush<sessions::Jolt>;

/// The crate's one face: a session of the Jolt scene, finished into a
/// [`JoltRun`].
impl DetailedEngine for JoltSimulator {
    type Session = JoltSession;

    /// The scene of `problem`, settled, through the shared stepping loop
    /// ([`pushval_engine::stepping`]), on the calling thread. Without the
    /// `jolt` feature: [`ModelError::Integration`] with [`UNAVAILABLE`] as
    /// the reason.
    fn start(&self, problem: &Problem) -> Result<JoltSession, ModelError> {
        self.settings.check()?;
        #[cfg(feature = "jolt")]
        {
            let sim = *self;
            pushval_engine::on_first_push(problem, move |problem| {
                let started = std::time::Instant::now();
                Ok(pushval_engine::stepping::PlateSession::new(
                    world::start(problem, &sim.settings)?,
                    Box::new(move |w, stepped, problem| {
                        let mut run = world::finish(w, stepped, problem, &sim.settings);
                        run.trajectory.model = sim.name();
                        run.wall_time = started.elapsed();
                        Ok(run)
                    }),
                ))
            })
        }
        #[cfg(not(feature = "jolt"))]
        {
            let _ = problem;
            Err(ModelError::Integration {
                t: 0.0,
                reason: UNAVAILABLE.into(),
            })
        }
    }
}

/// The world of a session, or none in a build without the `jolt` feature.
mod sessions {
    #[cfg(feature = "jolt")]
    pub type Jolt = pushval_engine::stepping::PlateSession<crate::world::Stepper, crate::JoltRun>;
    #[cfg(not(feature = "jolt"))]
    pub type Jolt = pushval_engine::Unavailable<crate::JoltRun>;
}

impl Simulator for JoltSimulator {
    fn name(&self) -> String {
        self.settings.scene.model_name().to_string()
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        self.run(problem).map(|r| r.trajectory)
    }
}
