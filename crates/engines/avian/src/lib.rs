//! The pushing problem of `pushval-model` in the Avian physics engine
//! (avian2d / avian3d 0.7 on bevy 0.19, f64 and parry-f64, no default
//! features), as two pushval engine plug-ins:
//!
//! * **`avian2d`** — the planar scene of `pushval-rapier2d` (gravity zero,
//!   seen from above): the object is a dynamic body with no collider, the
//!   pusher a kinematic body pinned to the object's contact point by a
//!   revolute joint; the Coulomb force
//!   `−F_i u_i/|u_i|` of every support acts on the object, with `u_i` the
//!   velocity of the support point as the body has it. See [`Avian2dSettings`].
//! * **`avian3d`** — the object as a plate on ball feet on a floor, pushed by a
//!   kinematic body that holds only the horizontal position of the contact
//!   point; the friction is Avian's own contact friction (nothing applied by
//!   hand). [`predict`] gives its law in closed form. See [`Avian3dSettings`].
//!
//! Both run a headless bevy `App` holding only Avian's `PhysicsPlugins` (and
//! bevy's task pools), with Avian's physics schedule stepped by hand: the
//! generic clock is advanced by one step, then the schedule runs once. Avian
//! measures time in whole nanoseconds (`Duration`), so steps are planned on a
//! nanosecond grid ([`clock`]) that lands every step sequence exactly on the
//! switch times; the recorded times are the ones the engine integrated.
//!
//! **The release** despawns the pusher's joint (avian2d's revolute joint,
//! avian3d's pin) and stops the pusher; the plate slides until at rest
//! (pushval's rule: `|v_cm| + |ω| L` below 1e-5 m/s for 10 steps). In
//! avian2d the supports' friction, applied by hand in the substep loop,
//! becomes the free slide's implicit Coulomb impulses
//! (`pushval_engine::slide::coulomb_impulses`, each within its disc
//! `μᵢNᵢ h_s` and capped at what stops its slip within the substep): a
//! fixed force would reverse a slip smaller than one substep's friction
//! removes, every substep, and never rest. avian3d slides on Avian's own
//! contact friction, which is already implicit (each contact's impulse
//! clamped to its disc, see [`predict`]), so the plate sticks at the stop.
//!
//! Avian is behind the cargo feature `avian`: Avian and bevy add about six
//! minutes to a clean release build on a 2-core machine. Without it the crate still builds: [`AVAILABLE`] is false,
//! the models are listed but report themselves unavailable, and the
//! simulators return an error naming the feature. [`clock`] and [`predict`]
//! never need Avian.
//!
//! Units are SI throughout (m, s, rad, kg, N).
#![warn(missing_docs)]

use std::time::Duration;

#[cfg(feature = "avian")]
use pushval_engine::on_first_push;
use pushval_engine::{DetailedRun, EngineRun, FirstPush, StepRecord};
use pushval_model::{ModelError, Problem, Simulator, Trajectory};

pub mod clock;
mod engine;
/// The `avian3d` plate's law in closed form (it lives in `pushval-laws`).
pub use pushval_laws::avian as predict;
#[cfg(feature = "avian")]
mod world2d;
#[cfg(feature = "avian")]
mod world3d;

pub use engine::{models, Avian2dModel, Avian3dModel, ENGINE_CRATE_2D, ENGINE_CRATE_3D};
pub use pushval_engine::{DetailedEngine, DetailedSession};

/// True when this build has Avian (feature `avian`).
pub const AVAILABLE: bool = cfg!(feature = "avian");

/// The message of the error a build without the `avian` feature returns.
pub const UNAVAILABLE: &str =
    "pushval was built without the `avian` feature; build with --features avian";

/// Avian's substep count used by default in both scenes (Avian's own
/// default is 6): every physics step runs the solver loop (velocity
/// integration, contact solve, position integration, relaxation, joints)
/// this many times. Chosen for accuracy per unit of run time: the error of
/// both scenes is first order in the *substep* `dt / substeps` (the friction
/// of a substep sees the velocity the previous one left, half a substep
/// late), while a 2-D step costs a fixed ~12 µs (Avian's schedule) plus
/// ~1.8 µs per substep (measured). At 16 the substeps are already 70 % of a
/// step's cost, so more of them buy little over smaller steps; fewer make
/// each step's fixed cost dominate. In 3-D the substep error falls below the
/// per-step one at about 16 (steady ω on the paper plate at dt = 1 ms:
/// −1.9e-3, −3.9e-4, +5.8e-5, +7.4e-5 relative at 4, 8, 16, 32 substeps).
/// A power of two, so a step of whole nanoseconds divides into
/// whole-nanosecond substeps ([`clock`]).
pub const DEFAULT_SUBSTEPS: u32 = 16;

fn check_common(dt: f64, substeps: u32, what: &'static str) -> Result<(), ModelError> {
    ModelError::require_positive(what, dt)?;
    if substeps == 0 {
        return Err(ModelError::Parameter {
            name: "avian substeps",
            requirement: ">= 1",
            value: 0.0,
        });
    }
    Ok(())
}

#[cfg(not(feature = "avian"))]
fn unavailable() -> ModelError {
    ModelError::Integration {
        t: 0.0,
        reason: UNAVAILABLE.into(),
    }
}

/// How the `avian2d` model runs a problem.
///
/// The scene: gravity zero; the object a dynamic body with its mass and
/// inertia set exactly (no collider, so nothing collides); the pusher a
/// kinematic body joined to the object's contact point by a revolute joint
/// (Avian's XPBD joint, rigid). Before each step the pusher's velocity is
/// set, as a user would, to the commanded contact velocity `v_c R(θ_m) n_φ`,
/// θ_m the object's angle at the step's middle as the engine's angle and
/// angular velocity predict it (`θ + ω h/2`). The joint delivers the contact
/// force, and the impulses at switches and at an impulsive start (ω is never
/// written after the start).
///
/// The support friction is a system in Avian's substep loop, run just
/// before Avian integrates the velocities: from the body's own state at that
/// substep (velocity and angle) it takes each support's velocity `u_i` and
/// adds the impulse of `−F_i u_i/|u_i|` over the substep (none where
/// `|u_i| ≤ 1e-12 m/s`).
///
/// Steps land exactly on switch times (each segment is cut into
/// `ceil(duration / dt)` steps of whole nanoseconds). `Problem::switching`
/// is not read: the engine shows what a rigid body does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Avian2dSettings {
    /// Largest time step (s); default `1e-3`.
    pub dt: f64,
    /// Avian's `SubstepCount`, ≥ 1; default [`DEFAULT_SUBSTEPS`].
    pub substeps: u32,
}

impl Default for Avian2dSettings {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            substeps: DEFAULT_SUBSTEPS,
        }
    }
}

impl Avian2dSettings {
    /// A short label, e.g. `avian2d[dt=0.001,substeps=16]`.
    pub fn label(&self) -> String {
        format!("avian2d[dt={},substeps={}]", self.dt, self.substeps)
    }

    /// Checks the settings; errors name the field.
    pub fn check(&self) -> Result<(), ModelError> {
        check_common(self.dt, self.substeps, "avian2d dt")
    }
}

/// What an `avian2d` run produced.
#[derive(Debug, Clone, PartialEq)]
pub struct Avian2dRun {
    /// The trajectory sampled at [`Problem::sample_times`].
    pub trajectory: Trajectory,
    /// The settings used.
    pub settings: Avian2dSettings,
    /// The first record is the initial state, then one per step. A step's ω
    /// is its rotation over its length (the mean angular velocity it held).
    pub history: Vec<StepRecord>,
    /// Number of steps.
    pub steps: usize,
    /// Largest distance between the pusher and the object's contact point
    /// after a step (m): how far the joint lets them apart.
    pub max_joint_drift: f64,
    /// Wall-clock time of the run.
    pub wall_time: Duration,
}

/// Avian 2-D as a [`Simulator`] (name `avian2d`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Avian2dSimulator {
    /// How it runs.
    pub settings: Avian2dSettings,
}

impl Avian2dSimulator {
    /// A simulator with the given settings.
    pub fn new(settings: Avian2dSettings) -> Self {
        Self { settings }
    }
}

/// An `avian2d` session: the world pushed one push at a time. Not
/// `Send`: Avian's world is a Bevy `App` and stays on the thread that built
/// it (the [`Engine`](pushval_engine::Engine) session builds it on a thread
/// of its own). Built at the first push for an object that starts moving.
pub type Avian2dSession = FirstPush<sessions::Avian2d>;

/// The crate's one face: a session of the `avian2d` world, finished into
/// an [`Avian2dRun`].
impl DetailedEngine for Avian2dSimulator {
    type Session = Avian2dSession;

    /// The scene of `problem` through the shared stepping loop
    /// ([`pushval_engine::stepping`]) on Avian's clock, on the calling
    /// thread. Without the `avian` feature: [`ModelError::Integration`] with
    /// [`UNAVAILABLE`] as the reason.
    fn start(&self, problem: &Problem) -> Result<Avian2dSession, ModelError> {
        self.settings.check()?;
        #[cfg(feature = "avian")]
        {
            let s = self.settings;
            on_first_push(problem, move |problem| {
                let started = std::time::Instant::now();
                Ok(pushval_engine::stepping::PlateSession::new(
                    world2d::start(problem, &s)?,
                    Box::new(move |w, stepped, problem| {
                        Ok(world2d::finish(&w, stepped, problem, &s, started))
                    }),
                ))
            })
        }
        #[cfg(not(feature = "avian"))]
        {
            let _ = problem;
            Err(unavailable())
        }
    }
}

impl Simulator for Avian2dSimulator {
    fn name(&self) -> String {
        "avian2d".into()
    }
    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        self.run(problem).map(|r| r.trajectory)
    }
}

/// How the `avian3d` model runs a problem.
///
/// The scene (z up, gravity `(0, 0, −g)`):
///
/// * **Floor**: a static half-space `z ≤ 0`, friction 1 combined by
///   multiplication, restitution 0.
/// * **Object**: a dynamic body, origin at the centre of mass, at height
///   `cm_height`. Mass `m` and the vertical-axis inertia `I_cm` are the
///   problem's; the two tilt inertias are `I_cm/2 + m t²/12`
///   (`t = plate_thickness`, a thin plate by the perpendicular-axis
///   theorem). One ball collider ("foot", radius `foot_radius`) per support,
///   a child of the object, its lowest point at the support's `(x_i, y_i)` on
///   the floor. Foot `i` has friction μ_i (combined by multiplication, so the
///   pair's coefficient is μ_i) and restitution 0; the feet add no mass.
/// * **Pusher**: a kinematic body joined to the object by a custom XPBD
///   constraint (Avian's documented extension point) that holds only the
///   *horizontal* position of the contact point `p_c`: it carries no
///   weight and leaves the object free to rise, tilt and turn. It holds the
///   point at the centre of mass's height, where a horizontal correction
///   turns the body about the vertical only: Avian solves joints after its
///   contact solver in every substep, and a joint holding a point below the
///   centre of mass tilts the plate each substep, which the contacts then
///   push back on with a biased load (at 2 cm below, two feet lifted off).
///   Its velocity is set each step as in the 2-D scene.
///
/// **Start**: the object first settles at rest for `settle_time` (the feet
/// sink to their soft-contact depth); the normal force `N_i` of each foot is
/// read and μ_i = F_i / N_i (F_i the problem's friction magnitude), so at
/// rest each foot has the friction the problem asks for. Then the clock is
/// reset and the push starts as in 2-D (moving with the first push, or from
/// rest).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Avian3dSettings {
    /// Largest time step (s); default `1e-3`.
    pub dt: f64,
    /// Avian's `SubstepCount`, ≥ 1; default [`DEFAULT_SUBSTEPS`].
    pub substeps: u32,
    /// Radius of the ball feet (m); default `0.003`.
    pub foot_radius: f64,
    /// Height of the centre of mass above the floor (m); default 0: the
    /// friction, the push and the centre of mass act in one horizontal
    /// plane, so horizontal forces shift no load between the feet (the planar
    /// model's assumption). Above 0 the pusher's force and the friction form
    /// a couple that moves load between the feet ([`predict`] includes it).
    pub cm_height: f64,
    /// Plate thickness for the tilt inertias (m); default `0.005`.
    pub plate_thickness: f64,
    /// Gravity (m/s²); default 9.81. Only `μ_i N_i` enters the model, so g
    /// sets the normal loads and, through the calibration, the μ_i.
    pub gravity: f64,
    /// Settling time at rest before the push starts (s); default 0.3.
    pub settle_time: f64,
}

impl Default for Avian3dSettings {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            substeps: DEFAULT_SUBSTEPS,
            foot_radius: 0.003,
            cm_height: 0.0,
            plate_thickness: 0.005,
            gravity: 9.81,
            settle_time: 0.3,
        }
    }
}

/// The settings' plain parameters of the closed forms' plate.
impl From<&Avian3dSettings> for predict::PlateParams {
    fn from(s: &Avian3dSettings) -> Self {
        Self {
            plate_thickness: s.plate_thickness,
            gravity: s.gravity,
            cm_height: s.cm_height,
        }
    }
}

impl Avian3dSettings {
    /// A short label, e.g. `avian3d[dt=0.001,substeps=16]`, with the centre
    /// of mass's height appended when it is not 0.
    pub fn label(&self) -> String {
        let mut s = format!("avian3d[dt={},substeps={}", self.dt, self.substeps);
        if self.cm_height != 0.0 {
            s += &format!(",h_cm={}", self.cm_height);
        }
        s.push(']');
        s
    }

    /// Checks the settings; errors name the field.
    pub fn check(&self) -> Result<(), ModelError> {
        check_common(self.dt, self.substeps, "avian3d dt")?;
        ModelError::require_positive("avian3d foot_radius", self.foot_radius)?;
        ModelError::require_positive("avian3d plate_thickness", self.plate_thickness)?;
        ModelError::require_positive("avian3d gravity", self.gravity)?;
        ModelError::require_non_negative("avian3d cm_height", self.cm_height)?;
        ModelError::require_non_negative("avian3d settle_time", self.settle_time)
    }
}

/// What an `avian3d` run produced.
#[derive(Debug, Clone, PartialEq)]
pub struct Avian3dRun {
    /// The trajectory sampled at [`Problem::sample_times`].
    pub trajectory: Trajectory,
    /// The settings used.
    pub settings: Avian3dSettings,
    /// The first record is the state at t = 0 (after settling), then one
    /// per step; a step's ω is its yaw change over its length.
    pub history: Vec<StepRecord>,
    /// Normal force of each foot at the end of the settle phase (N), in
    /// support order.
    pub rest_loads: Vec<f64>,
    /// The calibrated friction coefficient of each foot, `F_i / N_i`.
    pub mu: Vec<f64>,
    /// Per segment, the time-weighted mean normal force of each foot over
    /// the segment's last 20 % (N).
    pub segment_tail_loads: Vec<Vec<f64>>,
    /// The time-weighted mean normal force of each foot over the last fifth
    /// of the run (N), in support order: the engine diagnostics' `"loads"`.
    pub loads: Vec<f64>,
    /// The feet's loads at every sample, the largest rise and the share of
    /// steps with a foot out of contact (the engine run's `contact`).
    pub contact: Option<pushval_engine::ContactRecord>,
    /// Largest tilt of the object (rad): angle between its vertical axis and
    /// the world's.
    pub max_tilt: f64,
    /// Largest distance between the pusher and the object's contact point in
    /// the horizontal plane after a step (m).
    pub max_joint_drift: f64,
    /// Number of steps after the settle phase.
    pub steps: usize,
    /// Wall-clock time of the run (settling included).
    pub wall_time: Duration,
}

/// Avian 3-D as a [`Simulator`] (name `avian3d`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Avian3dSimulator {
    /// How it runs.
    pub settings: Avian3dSettings,
}

impl Avian3dSimulator {
    /// A simulator with the given settings.
    pub fn new(settings: Avian3dSettings) -> Self {
        Self { settings }
    }
}

/// An `avian3d` session: the world pushed one push at a time. Not
/// `Send`: Avian's world is a Bevy `App` and stays on the thread that built
/// it (the [`Engine`](pushval_engine::Engine) session builds it on a thread
/// of its own). Built at the first push for an object that starts moving.
pub type Avian3dSession = FirstPush<sessions::Avian3d>;

/// The crate's one face: a session of the `avian3d` world, finished into
/// an [`Avian3dRun`].
impl DetailedEngine for Avian3dSimulator {
    type Session = Avian3dSession;

    /// The scene of `problem` through the shared stepping loop
    /// ([`pushval_engine::stepping`]) on Avian's clock, on the calling
    /// thread. Without the `avian` feature: [`ModelError::Integration`] with
    /// [`UNAVAILABLE`] as the reason.
    fn start(&self, problem: &Problem) -> Result<Avian3dSession, ModelError> {
        self.settings.check()?;
        #[cfg(feature = "avian")]
        {
            let s = self.settings;
            on_first_push(problem, move |problem| {
                let started = std::time::Instant::now();
                Ok(pushval_engine::stepping::PlateSession::new(
                    world3d::start(problem, &s)?,
                    Box::new(move |w, stepped, problem| {
                        Ok(world3d::finish(w, stepped, problem, &s, started))
                    }),
                ))
            })
        }
        #[cfg(not(feature = "avian"))]
        {
            let _ = problem;
            Err(unavailable())
        }
    }
}

impl Simulator for Avian3dSimulator {
    fn name(&self) -> String {
        "avian3d".into()
    }
    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        self.run(problem).map(|r| r.trajectory)
    }
}

impl DetailedRun for Avian2dRun {
    fn trajectory_mut(&mut self) -> &mut Trajectory {
        &mut self.trajectory
    }

    /// The run with the step count and the joint drift as diagnostics.
    fn engine_run(self) -> EngineRun {
        EngineRun {
            dt: self.settings.dt,
            steps: self.steps,
            wall_time: self.wall_time,
            diagnostics: serde_json::json!({
                "steps": self.steps,
                "max_joint_drift": self.max_joint_drift,
            }),
            trajectory: self.trajectory,
            contact: None,
        }
    }
}

impl DetailedRun for Avian3dRun {
    fn trajectory_mut(&mut self) -> &mut Trajectory {
        &mut self.trajectory
    }

    /// The run with the step count, the joint drift, the tilt, the feet's
    /// rest loads, calibrated μ and loads as diagnostics, and its contact
    /// record.
    fn engine_run(self) -> EngineRun {
        EngineRun {
            dt: self.settings.dt,
            steps: self.steps,
            wall_time: self.wall_time,
            diagnostics: serde_json::json!({
                "steps": self.steps,
                "max_joint_drift": self.max_joint_drift,
                "max_tilt": self.max_tilt,
                "rest_loads": self.rest_loads,
                "mu": self.mu,
                "loads": self.loads,
            }),
            trajectory: self.trajectory,
            contact: self.contact,
        }
    }
}

/// The worlds of the sessions, or none in a build without the `avian`
/// feature.
mod sessions {
    #[cfg(feature = "avian")]
    pub type Avian2d =
        pushval_engine::stepping::PlateSession<crate::world2d::World2d, crate::Avian2dRun>;
    #[cfg(feature = "avian")]
    pub type Avian3d =
        pushval_engine::stepping::PlateSession<crate::world3d::World3d, crate::Avian3dRun>;
    #[cfg(not(feature = "avian"))]
    pub type Avian2d = pushval_engine::Unavailable<crate::Avian2dRun>;
    #[cfg(not(feature = "avian"))]
    pub type Avian3d = pushval_engine::Unavailable<crate::Avian3dRun>;
}
