//! The pushing problem of `pushval-model` as a 3-D scene in PhysX 5 (the
//! `physx` crate 0.19, which builds PhysX 5.1.3 from source), with PhysX's
//! **own** contact friction: no friction force is applied by hand.
//!
//! The scene (z up, gravity `(0, 0, −g)`, g = [`PhysxSettings::gravity`]):
//!
//! * **Ground**: a static plane z = 0, material friction 1 (static and
//!   dynamic) with combine mode `eMULTIPLY`, restitution 0.
//! * **Object**: a `PxRigidDynamic` with its centre of mass at height
//!   [`PhysxSettings::cm_height`]; mass `m` and the inertia diagonal are set
//!   explicitly: the vertical axis has the problem's `I_cm`, the two tilt axes
//!   `I_cm/2 + m t²/12` (a thin plate of thickness
//!   [`PhysxSettings::plate_thickness`]). One sphere shape ("foot", radius
//!   [`PhysxSettings::foot_radius`]) per support, its lowest point at the
//!   support's `(x_i, y_i)` on the ground, all with one material (μ̄ static
//!   and dynamic, `eMULTIPLY`, restitution 0, see below). Every foot is its
//!   own shape and its own contact pair. No damping, no sleeping.
//! * **Pusher**: a kinematic actor without shapes, held on the object's
//!   contact point `p_c` at height [`PhysxSettings::push_height`] by a
//!   `PxD6Joint` whose X and Y are locked in the pusher's (world-aligned)
//!   frame and whose Z and three rotations are free: it transmits only a
//!   horizontal force and leaves the object free to rise, tilt and turn.
//!   Before every step the pusher is put back onto the object's contact point
//!   (so the joint has no position error to correct) and given the kinematic
//!   target that moves it at the commanded contact velocity
//!   `v_c R(θ_m) n_φ`, θ_m the object's yaw at mid-step (`θ + ω h/2`).
//!
//! The friction comes from PhysX's PGS solver in one of the three friction
//! types PhysX 5.1 has (`PxSceneDesc::frictionType`, [`FrictionType`]).
//! PhysX welds the feet's contact pairs into one constraint, one friction
//! patch of n points ([`FootContacts::Welded`], the default), unless they are
//! kept apart ([`FootContacts::Separate`]: one patch per foot); [`predict`]
//! gives the closed form of what each combination does to the steady ω.
//!
//! **Friction coefficient.** Every foot has the same coefficient,
//! `μ̄ = Σ F_i / (m g)` (F_i the problem's friction magnitudes): the feet's
//! friction adds up to the problem's, and for equal coefficients (the usual
//! scene) it is the problem's μ. The split between the feet is PhysX's: its
//! PGS shares the weight of four or more rigid feet in a way that depends on
//! the order it visits them (2.80 / 2.10 N on the diagonals of the paper
//! plate, not 2.45 N each); [`PhysxRun::rest_loads`] records it. Per-foot
//! coefficients (one material per foot, `μ_i = F_i / N_i`) were tried and
//! dropped: welded feet of different coefficients fall into different
//! patches of one constraint, and PhysX 5.1.3 then reported the contact
//! impulses against the wrong feet and the steady ω depended on the length
//! of the settle phase.
//!
//! **Start.** The object is placed with its feet touching the ground and
//! settles for [`PhysxSettings::settle_time`] with the pusher at rest. Then
//! the clock is reset to 0 and the push starts: unless
//! `initial.from_rest`, the object is given the velocity of a body moving with
//! the first push at ω = `initial.omega` (the seed paper's start); with
//! `from_rest` the joint delivers the start impulse. `Problem::switching` is
//! ignored (the engine shows which reading a rigid body obeys).
//!
//! **The release** releases the D6 joint; the plate slides on its feet
//! under the same friction rows until at rest (pushval's rule: `|v_cm| +
//! |ω| L` below 1e-5 m/s for 10 steps). A friction row is a velocity
//! constraint whose impulse is capped by `μ λ`: a slip that one step's
//! capped impulse can remove is removed, so the plate sticks instead of
//! chattering. In pure translation `eTWO_DIRECTIONAL` and `ePATCH` put the
//! whole `μ m g` against the motion (Coulomb's stop); `eONE_DIRECTIONAL`
//! only the `t0` feet's share, so it slides farther. With PhysX's single
//! velocity iteration `ePATCH` keeps a solver residual of about 1e-5 m/s at
//! the stop: it is seen a few steps late, or (after a turned push, or at
//! dt 5e-4) never below the rest rule, the pose still: reported as not
//! stopped.
//!
//! PhysX keeps one foundation per process, so runs are serialised by a lock.
//! PhysX computes in f32.
//!
//! Without the `physx` feature the crate builds with no PhysX at all
//! ([`AVAILABLE`] is false) and `PhysxSimulator`'s `start` (and so `run`) returns an error.
//!
//! Units are SI throughout (m, s, rad, kg, N).
#![warn(missing_docs)]

use std::time::Duration;

use pushval_engine::FirstPush;
use pushval_model::{ModelError, Problem, Simulator, Trajectory};

mod engine;
/// PhysX's friction laws in closed form (they live in `pushval-laws`).
pub use pushval_laws::physx as predict;
pub use pushval_laws::physx::{FootContacts, FrictionType};
#[cfg(feature = "physx")]
#[allow(unsafe_code)]
mod sys;
#[cfg(feature = "physx")]
mod world;

pub use engine::{models, PhysxModel, ENGINE_CRATE, PHYSX_SDK_VERSION};
pub use pushval_engine::{DetailedEngine, DetailedSession};

/// True when this build has PhysX (feature `physx`).
pub const AVAILABLE: bool = cfg!(feature = "physx");

/// The message of the error a build without the `physx` feature returns.
pub const UNAVAILABLE: &str =
    "pushval was built without the `physx` feature (needs clang++: apt-get install clang)";

/// How PhysX runs a problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysxSettings {
    /// Largest time step (s); default `1e-3`. Each push segment is cut into
    /// `ceil(duration / dt)` equal steps, so steps land on the switch times.
    pub dt: f64,
    /// The scene's friction type; default [`FrictionType::Patch`] (PhysX's).
    pub friction: FrictionType,
    /// How the feet's contacts reach the solver; default
    /// [`FootContacts::Welded`] (PhysX's).
    pub contacts: FootContacts,
    /// Radius of the sphere feet (m); default `0.003`.
    pub foot_radius: f64,
    /// Height of the centre of mass above the ground (m); default 0: the
    /// friction, the push and the centre of mass act in one horizontal plane,
    /// so horizontal forces shift no load between the feet (the planar
    /// model's assumption). Above 0 the feet hang below the centre of mass.
    pub cm_height: f64,
    /// Height above the ground at which the pusher joint holds the object
    /// (m); default 0.
    pub push_height: f64,
    /// PGS position iterations of the object (`setSolverIterationCounts`),
    /// ≥ 1; default 4 (PhysX's).
    pub position_iterations: u32,
    /// PGS velocity iterations, ≥ 1; default 1 (PhysX's).
    pub velocity_iterations: u32,
    /// Gravity (m/s²); default 9.81.
    pub gravity: f64,
    /// Plate thickness (m) for the tilt inertias; default `0.005`.
    pub plate_thickness: f64,
    /// Duration (s) of the settle phase before the push starts; default 0.3.
    pub settle_time: f64,
}

impl Default for PhysxSettings {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            friction: FrictionType::Patch,
            contacts: FootContacts::Welded,
            foot_radius: 0.003,
            cm_height: 0.0,
            push_height: 0.0,
            position_iterations: 4,
            velocity_iterations: 1,
            gravity: 9.81,
            plate_thickness: 0.005,
            settle_time: 0.3,
        }
    }
}

impl PhysxSettings {
    /// A short label, e.g. `physx[patch,welded,dt=0.001,iters=4/1]`, with
    /// the heights appended when they are not 0.
    pub fn label(&self) -> String {
        let mut s = format!(
            "physx[{},{},dt={},iters={}/{}",
            self.friction.as_str(),
            self.contacts.as_str(),
            self.dt,
            self.position_iterations,
            self.velocity_iterations
        );
        if self.cm_height != 0.0 || self.push_height != 0.0 {
            s += &format!(",h_cm={},h_push={}", self.cm_height, self.push_height);
        }
        s.push(']');
        s
    }

    /// Checks the settings; errors name the field.
    pub fn check(&self) -> Result<(), ModelError> {
        let positive = ModelError::require_positive;
        let non_negative = ModelError::require_non_negative;
        positive("physx dt", self.dt)?;
        positive("physx foot_radius", self.foot_radius)?;
        positive("physx gravity", self.gravity)?;
        positive("physx plate_thickness", self.plate_thickness)?;
        non_negative("physx cm_height", self.cm_height)?;
        non_negative("physx push_height", self.push_height)?;
        non_negative("physx settle_time", self.settle_time)?;
        for (name, n) in [
            ("physx position_iterations", self.position_iterations),
            ("physx velocity_iterations", self.velocity_iterations),
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

/// One PhysX step: time, pose at its end, the angular velocity after it,
/// height and tilt (the shared stepping loop's record).
pub use pushval_engine::stepping::PlateStep as PxStep;

/// A PhysX run: the sampled trajectory and what the engine did.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysxRun {
    /// The trajectory sampled at [`Problem::sample_times`].
    pub trajectory: Trajectory,
    /// The settings used.
    pub settings: PhysxSettings,
    /// Engine steps of the push (settle steps excluded).
    pub steps: usize,
    /// Wall-clock time of the run (set-up, settling, stepping, sampling).
    pub wall_time: Duration,
    /// The friction coefficient every foot has, `μ̄ = Σ F_i / (m g)`.
    pub mu: f64,
    /// Normal force (N) of each foot at rest: the mean over the last 20 % of
    /// the settle phase, from PhysX's contact reports. PhysX's PGS, not the
    /// problem, decides how four or more rigid feet share the weight.
    pub rest_loads: Vec<f64>,
    /// The friction magnitude each foot has in PhysX at rest, `μ̄ N_i` (N):
    /// the problem's `F_i` in total, not foot by foot unless PhysX shares the
    /// weight as the problem does.
    pub engine_friction: Vec<f64>,
    /// Per segment, the mean ω (rad/s) over its last 20 % of steps.
    pub segment_tail_omega: Vec<f64>,
    /// Per segment, the standard deviation of ω over the same steps (rad/s).
    pub segment_tail_omega_std: Vec<f64>,
    /// Per segment, each foot's mean normal force (N) over the last 20 %.
    pub segment_tail_loads: Vec<Vec<f64>>,
    /// The time-weighted mean normal force of each foot over the last fifth
    /// of the run (N), in support order: the engine diagnostics' `"loads"`.
    pub loads: Vec<f64>,
    /// The supports' loads at every sample, the largest rise and the share
    /// of steps with a foot out of contact (the engine run's `contact`).
    pub contact: Option<pushval_engine::ContactRecord>,
    /// Per segment, the mean pusher force over the last 20 % (N, object
    /// frame, the force the pusher applies to the object), from the joint's
    /// constraint force.
    pub segment_tail_pusher_force: Vec<[f64; 2]>,
    /// Smallest normal force (N) of each foot over the push.
    pub min_loads: Vec<f64>,
    /// Largest tilt (rad) over the push.
    pub max_tilt: f64,
    /// Largest vertical displacement of the centre of mass from its height at
    /// the end of the settle phase (m).
    pub max_lift: f64,
    /// Largest horizontal distance (m) between the pusher and the object's
    /// contact point after a step (before the pusher is put back).
    pub max_joint_drift: f64,
    /// Every step of the push, after an initial record at t = 0.
    pub history: Vec<PxStep>,
}

/// PhysX as a [`Simulator`] (names `physx_patch`, `physx_two_directional`,
/// `physx_one_directional`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PhysxSimulator {
    /// How it runs.
    pub settings: PhysxSettings,
}

impl PhysxSimulator {
    /// A simulator with the given settings.
    pub fn new(settings: PhysxSettings) -> Self {
        Self { settings }
    }
}

/// A PhysX session: the scene, settled, pushed one push at a time. It holds
/// PhysX's turn (one foundation per process) until it ends. Not `Send`:
/// PhysX's objects are raw pointers into the SDK and the turn is a guard
/// released on the thread that took it (the
/// [`Engine`](pushval_engine::Engine) session builds it on a thread of its
/// own). Built at the first push for an object that starts moving.
pub type PhysxSession = FirstPush<sessions::Physx>;

/// The crate's one face: a session of the PhysX scene, finished into a
/// [`PhysxRun`].
impl DetailedEngine for PhysxSimulator {
    type Session = PhysxSession;

    /// The scene of `problem`, settled, through the shared stepping loop
    /// ([`pushval_engine::stepping`]), on the calling thread. Without the
    /// `physx` feature: [`ModelError::Integration`] with [`UNAVAILABLE`] as
    /// the reason.
    fn start(&self, problem: &Problem) -> Result<PhysxSession, ModelError> {
        self.settings.check()?;
        #[cfg(feature = "physx")]
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
        #[cfg(not(feature = "physx"))]
        {
            let _ = problem;
            Err(ModelError::Integration {
                t: 0.0,
                reason: UNAVAILABLE.into(),
            })
        }
    }
}

/// The world of a session, or none in a build without the `physx` feature.
mod sessions {
    #[cfg(feature = "physx")]
    pub type Physx = pushval_engine::stepping::PlateSession<crate::world::Stepper, crate::PhysxRun>;
    #[cfg(not(feature = "physx"))]
    pub type Physx = pushval_engine::Unavailable<crate::PhysxRun>;
}

impl Simulator for PhysxSimulator {
    fn name(&self) -> String {
        self.settings.friction.model_name().to_string()
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        self.run(problem).map(|r| r.trajectory)
    }
}
