//! The pushing problem of `pushval-model`, run in Box2D v3 through the
//! [`boxdd`] bindings (0.6, Box2D's C source built with `cc`, the
//! `double-precision` feature).
//!
//! This is the only crate of the workspace that imports Box2D. For a
//! [`Problem`] it builds a world seen from above (gravity zero) with:
//!
//! * the **object**, a dynamic body without shapes whose mass and inertia
//!   about its centre of mass are set directly (`b2Body_SetMassData`; the
//!   body origin is the centre of mass);
//! * the **pusher**, a kinematic body joined to the object at the contact
//!   point by a revolute joint. Before every step its velocity is set to the
//!   commanded contact velocity `v_c R(θ) n_φ`, with θ the angle Box2D holds
//!   for the object at the step's start, so Box2D's joint solver produces the
//!   contact force and the impulses at switches and at an impulsive start
//!   (ω is never set after the start).
//!
//! The support friction is one of two laws ([`Friction`]):
//!
//! * [`Friction::Coulomb`] (model `box2d`, gateable): every step each support
//!   `i` receives `−F_i u_i/|u_i|`, with `u_i` the object's velocity at the
//!   support from Box2D's state after the previous step;
//! * [`Friction::MotorJoint`] (model `box2d_motor_joint`, informational):
//!   Box2D's own top-down friction idiom, a motor joint from a static ground
//!   body to the object with zero target velocities whose force and torque
//!   are capped ([`predict`] has its steady state in closed form).
//!
//! Both let go ([`pushval_engine::EngineSession::release`]): the pusher's
//! joint is destroyed; Coulomb slides on the implicit impulses of
//! `pushval_engine::slide`, and the motor joint, which is the idiom's
//! friction, stays and stops the translation at its force cap's
//! deceleration μg and the spin at its torque cap's, each on its own and
//! within a step once the cap can hold it (README, "The release").
//!
//! Box2D stores velocities, rotations, forces, masses and joint data in f32
//! whatever the build; `double-precision` makes only the world positions
//! f64. The adapter works in f64 and rounds where it hands values over.
//!
//! Units are SI throughout (m, s, rad, kg, N, N m).
#![warn(missing_docs)]

use std::time::Duration;

use pushval_engine::stepping::PlateSession;
use pushval_engine::{on_first_push, DetailedRun, EngineRun, FirstPush};
use pushval_model::{ModelError, Problem, Simulator, Trajectory};

pub mod engine;
/// The motor joint's closed form (it lives in `pushval-laws`).
pub use pushval_laws::box2d as predict;
mod world;

pub use engine::{models, Box2dModel, ENGINE_CRATE};
pub use pushval_engine::{tail_mean_omega, DetailedEngine, DetailedSession, StepRecord};

/// Box2D's sub-steps per step (`b2World_Step`'s `subStepCount`) by default:
/// one.
///
/// The adapter's forces (the Coulomb support forces, from the state at the
/// step's start) are set once per step and Box2D applies them unchanged in
/// every sub-step, so sub-steps cannot make the friction more accurate: they
/// only re-solve the joint and re-integrate the rotation. Measured on the
/// paper plate (0.25 m, 1 kg, μ = 0.5, 1 m/s, 4 s) at dt = 1e-3 s, 1, 2, 4
/// and 8 sub-steps give steady-ω errors of 2.2e-3, 3.1e-3, 3.6e-3 and
/// 3.9e-3 (relative) and position errors of 5.5, 5.3, 5.3 and 5.3 mm: the
/// figure the gate is most sensitive to gets worse, the position barely
/// better, and each sub-step costs a joint solve and an f32 renormalisation
/// of the rotation (whose round-off sets the floor described in the README).
pub const DEFAULT_SUBSTEPS: usize = 1;

/// Stiffness (Hz) of the pin joint's soft constraint by default (see
/// [`Box2dSettings::joint_hertz`]): far above what Box2D allows, which
/// clamps it to a quarter of the sub-step rate (`0.25 / h_sub`), so the
/// joint is as stiff as Box2D's soft step permits at every dt. Box2D's
/// default, 60 Hz, corrects the contact's drift slowly: on
/// paper-square-v1.0 at dt = 1/7680 s it lets the contact drift 79 µm
/// (clamped: 10 µm) and the position error grows from 3.0 to 3.8 mm.
/// The relax pass after the position update makes the velocity constraint
/// rigid either way.
pub const JOINT_HERTZ: f64 = 1.0e9;

/// Damping ratio of the pin joint's soft constraint (Box2D's default, 2).
pub const JOINT_DAMPING_RATIO: f64 = 2.0;

/// The support-friction law of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Friction {
    /// Coulomb friction at every support, `−F_i u_i/|u_i|` (N), applied as
    /// forces before every step (the analytic model's law). Default.
    #[default]
    Coulomb,
    /// Box2D's top-down friction idiom: a motor joint from a static ground
    /// body to the object's centre of mass with zero target velocities,
    /// maximum force `F_max = Σ F_i` (N; `μ m g` for one μ) and maximum
    /// torque `T_max = Σ F_i |p_i|` (N m; `μ m g` times the mean support
    /// distance from the centre of mass, for equal loads). These are the
    /// values a Box2D user would pick: the force that stops a sliding object
    /// and the torque that stops it spinning about its centre of mass. No
    /// per-support forces. See [`predict`].
    MotorJoint,
}

impl Friction {
    /// `"coulomb"` or `"motor_joint"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Friction::Coulomb => "coulomb",
            Friction::MotorJoint => "motor_joint",
        }
    }
}

/// How Box2D runs a problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Box2dSettings {
    /// Largest time step (s); default `1e-3`. Each push segment is cut into
    /// `n = ceil(duration / dt)` equal steps of `duration / n`, so steps land
    /// exactly on the switch times. Box2D takes the step as f32.
    pub dt: f64,
    /// Box2D's sub-steps per step (`subStepCount`), ≥ 1; default
    /// [`DEFAULT_SUBSTEPS`] (why: see there).
    pub substeps: usize,
    /// The support-friction law; default [`Friction::Coulomb`].
    pub friction: Friction,
    /// Stiffness (Hz) of the pin joint's soft constraint (Box2D's
    /// `constraintHertz`; Box2D clamps it to `0.25 / h_sub`); default
    /// [`JOINT_HERTZ`].
    pub joint_hertz: f64,
}

impl Default for Box2dSettings {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            substeps: DEFAULT_SUBSTEPS,
            friction: Friction::Coulomb,
            joint_hertz: JOINT_HERTZ,
        }
    }
}

impl Box2dSettings {
    /// A short label naming the variant, e.g. `box2d[coulomb,substeps=1,dt=0.001]`.
    pub fn label(&self) -> String {
        format!(
            "box2d[{},substeps={},dt={}]",
            self.friction.as_str(),
            self.substeps,
            self.dt
        )
    }

    /// Checks the settings; errors name the field.
    pub fn check(&self) -> Result<(), ModelError> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(ModelError::Parameter {
                name: "engine dt",
                requirement: "finite and > 0",
                value: self.dt,
            });
        }
        if !(1..=64).contains(&self.substeps) {
            return Err(ModelError::Parameter {
                name: "engine substeps",
                requirement: "in 1..=64",
                value: self.substeps as f64,
            });
        }
        Ok(())
    }
}

/// A Box2D run: the sampled trajectory and what the engine did.
#[derive(Debug, Clone, PartialEq)]
pub struct Box2dRun {
    /// The trajectory sampled at [`Problem::sample_times`] (model `"box2d"`
    /// or `"box2d_motor_joint"`).
    pub trajectory: Trajectory,
    /// Largest distance (m) between the pusher and the object's contact point
    /// after any step: how far the soft joint let the contact drift.
    pub max_joint_drift: f64,
    /// Number of engine steps taken.
    pub steps: usize,
    /// The settings used.
    pub settings: Box2dSettings,
    /// Wall-clock time of the run (set-up, stepping and sampling).
    pub wall_time: Duration,
    /// The part of `wall_time` spent inside `b2World_Step`.
    pub step_time: Duration,
    /// Per segment, the time-weighted mean angular velocity (rad/s) over the
    /// segment's last 20 % of engine steps: a cheap steady-ω estimate.
    pub segment_tail_omega: Vec<f64>,
    /// Every engine step: time, pose at the step's end, and the angular
    /// velocity Box2D holds after it.
    pub history: Vec<StepRecord>,
}

/// Box2D as a [`Simulator`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Box2dSimulator {
    /// How it runs.
    pub settings: Box2dSettings,
}

impl Box2dSimulator {
    /// A simulator with the given settings.
    pub fn new(settings: Box2dSettings) -> Self {
        Self { settings }
    }

    /// The run of `raw` on `problem` (the pushes applied), started at `start`.
    pub(crate) fn box2d_run(
        &self,
        problem: &Problem,
        raw: world::RawRun,
        start: std::time::Instant,
    ) -> Box2dRun {
        let segment_tail_omega = pushval_engine::step_tail_omega(problem, &raw.history, 0.2);
        let mut trajectory =
            pushval_engine::trajectory_from_steps(&self.name(), problem, &raw.history);
        trajectory.assumptions.min_support_speed = raw.min_support_speed;
        Box2dRun {
            trajectory,
            max_joint_drift: raw.max_drift,
            steps: raw.steps,
            settings: self.settings,
            wall_time: start.elapsed(),
            step_time: raw.step_time,
            segment_tail_omega,
            history: raw.history,
        }
    }
}

/// A Box2D session: the world pushed one push at a time. Not `Send`: the
/// Box2D world is a handle into a C library's memory and stays on the
/// thread that built it (the [`Engine`](pushval_engine::Engine) session
/// builds it on a thread of its own). Built at the first push for an object
/// that starts moving.
pub type Box2dSession = FirstPush<PlateSession<world::Stepper, Box2dRun>>;

/// The crate's one face: a session of the Box2D world, finished into a
/// [`Box2dRun`].
impl DetailedEngine for Box2dSimulator {
    type Session = Box2dSession;

    /// The world of `problem` through the shared stepping loop
    /// ([`pushval_engine::stepping`]), on the calling thread.
    fn start(&self, problem: &Problem) -> Result<Box2dSession, ModelError> {
        self.settings.check()?;
        let sim = *self;
        on_first_push(problem, move |problem| {
            let started = std::time::Instant::now();
            Ok(PlateSession::new(
                world::start(problem, &sim.settings)?,
                Box::new(move |w, stepped, problem| {
                    Ok(sim.box2d_run(problem, world::raw_run(w, &stepped), started))
                }),
            ))
        })
    }
}

impl DetailedRun for Box2dRun {
    fn trajectory_mut(&mut self) -> &mut Trajectory {
        &mut self.trajectory
    }

    /// The run with the joint drift and the step count as diagnostics.
    fn engine_run(self) -> EngineRun {
        EngineRun {
            contact: None,
            dt: self.settings.dt,
            steps: self.steps,
            wall_time: self.wall_time,
            diagnostics: serde_json::json!({
                "max_joint_drift": self.max_joint_drift,
                "steps": self.steps,
            }),
            trajectory: self.trajectory,
        }
    }
}

impl Simulator for Box2dSimulator {
    fn name(&self) -> String {
        match self.settings.friction {
            Friction::Coulomb => "box2d",
            Friction::MotorJoint => "box2d_motor_joint",
        }
        .to_string()
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        self.run(problem).map(|r| r.trajectory)
    }
}
