//! The pushing problem of `pushval-model` as a feet-on-floor scene in MuJoCo.
//!
//! The object is a free body (mass m, vertical-axis inertia I about its centre
//! of mass, tilt inertias I/2 about the two horizontal axes: a thin plate by
//! the perpendicular-axis theorem) with its centre of mass at height
//! [`MujocoSettings::cm_height`]. Each support point is a small sphere geom
//! ("foot", radius [`MujocoSettings::foot_radius`], no mass: the body's
//! inertia is set explicitly) touching a floor plane. Contacts have
//! `condim = 3`: sliding friction only, no torsional or rolling friction.
//!
//! **Friction.** The floor has friction 0 and each foot has priority 1 and
//! friction μ_i, so the contact uses the foot's μ_i (MuJoCo would also take
//! the larger of the two). MuJoCo, not the scenario, decides how the weight
//! spreads over the feet (more than three feet are statically indeterminate),
//! so μ_i is calibrated: the scene first settles at rest, the normal force N_i
//! of each foot is read, and μ_i = F_i / N_i, with F_i = μ_i N_i the problem's
//! friction magnitude. At rest the friction bound of every foot is then the
//! problem's F_i; while the object moves, N_i may shift (load transfer), and
//! that is a finding, not an input.
//!
//! **The pusher** is a kinematic slider pair: a carriage on two horizontal
//! slide joints (x, y), 10⁶ times heavier than the object, carrying a light
//! gravity-compensated tip on a vertical slide joint. An equality `connect`
//! holds the tip on the object's contact point p_c at height
//! [`MujocoSettings::push_height`]. Before every step the carriage's velocity
//! is set to the commanded contact velocity `v_c R(θ) n_φ` (θ the object's
//! yaw, taken at the step's middle); its position integrates that velocity.
//! The vertical slide lets the tip follow the object up and down, so the
//! connect transmits only horizontal force. The object's state is written
//! once, at the start (its initial velocity); after that only the pusher is
//! driven, so the object's momentum — the mass term of the model — is the
//! engine's own.
//!
//! **The release** turns the `connect` off (`eq_active`) and stops the
//! carriage; the plate slides on its feet under MuJoCo's own contact
//! friction until at rest (pushval's rule: `|v_cm| + |ω| L` below 1e-5 m/s
//! for 10 steps). Sliding, a foot's friction is its cone's bound: `μN`
//! against the slip (elliptic), or within the diamond `|f₁| + |f₂| ≤ μN` of
//! the contact frame (pyramidal: `μN` along the world axes, down to
//! `μN/√2` on the diagonals). It stops without chattering because friction
//! is a soft constraint: once the force that would stop the slip fits in
//! the cone, the slip follows MuJoCo's reference acceleration `u̇ = −u/τ`,
//! `τ = d_max·timeconst/(2d)` (10–10.6 ms at the default `solref` and
//! `solimp`), and decays geometrically without reversing. The price is a
//! tail: from the crossover speed `μgτ` the rest rule holds about 70 ms
//! after Coulomb's stop, and the plate slides up to `μgτ²` (0.55 mm)
//! farther.
//!
//! Without the `mujoco` feature the crate builds with no MuJoCo at all
//! ([`AVAILABLE`] is false) and [`MujocoSimulator`] returns an error.
//!
//! Units are SI throughout (m, s, rad, kg, N).
#![warn(missing_docs)]

use std::time::Duration;

use pushval_engine::FirstPush;
use pushval_model::{ModelError, Problem, Simulator, Trajectory};

pub mod creep;
mod engine;
pub mod scene;
#[cfg(feature = "mujoco")]
mod sim;
/// The closed forms of MuJoCo's friction (they live in `pushval-laws`).
pub use pushval_laws::mujoco as theory;

pub use engine::{models, MujocoModel, ENGINE_CRATE};
pub use pushval_engine::{DetailedEngine, DetailedSession};

/// True when this build links MuJoCo (feature `mujoco`).
pub const AVAILABLE: bool = cfg!(feature = "mujoco");

/// The message of the error a build without the `mujoco` feature returns.
pub const UNAVAILABLE: &str =
    "pushval was built without the `mujoco` feature (build with --features mujoco; it links MuJoCo 3.17's libmujoco.so)";

/// MuJoCo's friction cone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Cone {
    /// The pyramid of `2 (condim − 1)` edges (MuJoCo's default).
    #[default]
    Pyramidal,
    /// The exact (elliptic, here circular) cone.
    Elliptic,
}

impl Cone {
    /// `"pyramidal"` or `"elliptic"` (MuJoCo's MJCF names).
    pub fn as_str(&self) -> &'static str {
        match self {
            Cone::Pyramidal => "pyramidal",
            Cone::Elliptic => "elliptic",
        }
    }

    /// Both cones, pyramidal first.
    pub const ALL: [Cone; 2] = [Cone::Pyramidal, Cone::Elliptic];
}

/// MuJoCo's time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum MjIntegrator {
    /// Semi-implicit Euler (MuJoCo's default).
    #[default]
    Euler,
    /// Implicit in the velocity-dependent forces (none here but the solver's).
    ImplicitFast,
    /// Classical fourth-order Runge–Kutta.
    Rk4,
}

impl MjIntegrator {
    /// The MJCF name: `"Euler"`, `"implicitfast"` or `"RK4"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            MjIntegrator::Euler => "Euler",
            MjIntegrator::ImplicitFast => "implicitfast",
            MjIntegrator::Rk4 => "RK4",
        }
    }
}

/// How MuJoCo runs a problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MujocoSettings {
    /// Largest time step (s); default `1e-3`. Each push segment is cut into
    /// `ceil(duration / timestep)` equal steps, so steps land on switch times.
    pub timestep: f64,
    /// Friction cone; default pyramidal (MuJoCo's default).
    pub cone: Cone,
    /// Ratio of frictional to normal constraint impedance (dimensionless);
    /// default 1 (MuJoCo's). Larger values make friction stiffer (less
    /// soft-contact slip).
    pub impratio: f64,
    /// Post-processing iterations of the noslip solver, which removes the
    /// soft-constraint slip of friction; default 0 (MuJoCo's: off).
    pub noslip_iterations: usize,
    /// Main constraint-solver iterations (Newton); default 100 (MuJoCo's).
    pub iterations: usize,
    /// Time integrator; default Euler (MuJoCo's).
    pub integrator: MjIntegrator,
    /// Radius of the sphere feet (m); default 0.005.
    pub foot_radius: f64,
    /// Height of the centre of mass above the floor (m); default 0: the
    /// friction, the push and the centre of mass act in one horizontal plane,
    /// so horizontal forces shift no load between the feet (the planar
    /// model's assumption). Above 0, the feet hang below the body.
    pub cm_height: f64,
    /// Height of the pushed point above the floor (m); default 0.
    pub push_height: f64,
    /// Gravity (m/s²); default 9.81. Only `Σ μ_i N_i` enters the model, so g
    /// sets the normal loads and, through the calibration, the μ_i.
    pub gravity: f64,
    /// Contact `solref` (time constant in s, damping ratio); default
    /// MuJoCo's `[0.02, 1]`.
    pub contact_solref: [f64; 2],
    /// Contact `solimp` (d0, d_width, width in m, midpoint, power); default
    /// MuJoCo's `[0.9, 0.95, 0.001, 0.5, 2]`.
    pub contact_solimp: [f64; 5],
    /// Settling time at rest before the push starts (s); default 0.3. The
    /// feet sink into the floor to their soft-contact depth and the normal
    /// loads are read for the μ calibration.
    pub settle_time: f64,
}

impl Default for MujocoSettings {
    fn default() -> Self {
        Self {
            timestep: 1e-3,
            cone: Cone::Pyramidal,
            impratio: 1.0,
            noslip_iterations: 0,
            iterations: 100,
            integrator: MjIntegrator::Euler,
            foot_radius: 0.005,
            cm_height: 0.0,
            push_height: 0.0,
            gravity: 9.81,
            contact_solref: [0.02, 1.0],
            contact_solimp: [0.9, 0.95, 0.001, 0.5, 2.0],
            settle_time: 0.3,
        }
    }
}

impl MujocoSettings {
    /// A short label naming the variant, e.g.
    /// `mujoco[pyramidal,dt=0.001,impratio=1,noslip=0]`, with the heights
    /// appended when they are not 0.
    pub fn label(&self) -> String {
        let mut s = format!(
            "mujoco[{},dt={},impratio={},noslip={}",
            self.cone.as_str(),
            self.timestep,
            self.impratio,
            self.noslip_iterations
        );
        if self.integrator != MjIntegrator::Euler {
            s += &format!(",{}", self.integrator.as_str());
        }
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
        positive("mujoco timestep", self.timestep)?;
        positive("mujoco impratio", self.impratio)?;
        positive("mujoco foot_radius", self.foot_radius)?;
        positive("mujoco gravity", self.gravity)?;
        non_negative("mujoco cm_height", self.cm_height)?;
        non_negative("mujoco push_height", self.push_height)?;
        non_negative("mujoco settle_time", self.settle_time)?;
        positive("mujoco contact_solref[0]", self.contact_solref[0])?;
        positive("mujoco contact_solref[1]", self.contact_solref[1])?;
        if self.iterations == 0 {
            return Err(ModelError::Parameter {
                name: "mujoco iterations",
                requirement: ">= 1",
                value: 0.0,
            });
        }
        Ok(())
    }
}

/// One MuJoCo step: the object's pose at the step's end and its angular
/// velocity after the step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MjStep {
    /// Push segment of the step.
    pub segment: usize,
    /// End time of the step (s).
    pub t: f64,
    /// World x of the centre of mass (m).
    pub x: f64,
    /// World y of the centre of mass (m).
    pub y: f64,
    /// Yaw, unwrapped (rad).
    pub theta: f64,
    /// Vertical angular velocity (rad/s).
    pub omega: f64,
    /// Tilt: angle between the body's vertical axis and the world's (rad).
    pub tilt: f64,
    /// Smallest horizontal sliding speed over the feet (m/s).
    pub min_foot_speed: f64,
}

/// A MuJoCo run: the sampled trajectory and what the engine did.
#[derive(Debug, Clone, PartialEq)]
pub struct MujocoRun {
    /// The trajectory sampled at [`Problem::sample_times`].
    pub trajectory: Trajectory,
    /// The settings used.
    pub settings: MujocoSettings,
    /// Every step after the start (the first record is the state at t = 0).
    pub history: Vec<MjStep>,
    /// Normal force of each foot at rest, after settling (N), in support order.
    pub rest_loads: Vec<f64>,
    /// The calibrated friction coefficient of each foot, `F_i / N_i`.
    pub mu: Vec<f64>,
    /// Per segment, the time-weighted mean normal force of each foot over the
    /// segment's last 20 % (N).
    pub tail_loads: Vec<Vec<f64>>,
    /// The time-weighted mean normal force of each foot over the last fifth
    /// of the run (N), in support order: the engine diagnostics' `"loads"`.
    pub loads: Vec<f64>,
    /// The supports' loads at every sample, the largest rise and the share
    /// of steps with a foot out of contact (the engine run's `contact`).
    pub contact: Option<pushval_engine::ContactRecord>,
    /// Per segment, the mean ω over the segment's last 20 % of steps (rad/s).
    pub segment_tail_omega: Vec<f64>,
    /// Per segment, the standard deviation of ω over the same steps (rad/s).
    pub segment_tail_omega_std: Vec<f64>,
    /// Largest distance between the pusher tip and the object's contact point
    /// after any step (m): the softness of the connect constraint.
    pub max_pusher_gap: f64,
    /// Largest penetration of a foot into the floor (m).
    pub max_penetration: f64,
    /// Largest tilt of the body (rad).
    pub max_tilt: f64,
    /// Number of steps after the start.
    pub steps: usize,
    /// Wall-clock time of the run (s).
    pub wall_time: Duration,
}

/// MuJoCo as a [`Simulator`] (names `mujoco_pyramidal`, `mujoco_elliptic`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MujocoSimulator {
    /// How it runs.
    pub settings: MujocoSettings,
}

impl MujocoSimulator {
    /// A simulator with the given settings.
    pub fn new(settings: MujocoSettings) -> Self {
        Self { settings }
    }
}

/// A MuJoCo session: the scene, settled and calibrated, pushed one push at
/// a time; owned and `Send`. Built at the first push for an object that
/// starts moving.
pub type MujocoSession = FirstPush<sessions::Mujoco>;

/// The crate's one face: a session of the MuJoCo scene, finished into a
/// [`MujocoRun`].
impl DetailedEngine for MujocoSimulator {
    type Session = MujocoSession;

    /// The scene of `problem`, settled and calibrated, through the shared
    /// stepping loop ([`pushval_engine::stepping`]). Without the `mujoco`
    /// feature: [`ModelError::Integration`] with [`UNAVAILABLE`] as the
    /// reason.
    fn start(&self, problem: &Problem) -> Result<MujocoSession, ModelError> {
        self.settings.check()?;
        #[cfg(feature = "mujoco")]
        {
            let sim = *self;
            pushval_engine::on_first_push(problem, move |problem| {
                let started = std::time::Instant::now();
                Ok(pushval_engine::stepping::PlateSession::new(
                    sim::start(problem, &sim.settings)?,
                    Box::new(move |w, stepped, problem| {
                        let mut run = sim::finish(w, stepped, problem, &sim.settings, started);
                        run.trajectory.model = sim.name();
                        Ok(run)
                    }),
                ))
            })
        }
        #[cfg(not(feature = "mujoco"))]
        {
            let _ = problem;
            Err(ModelError::Integration {
                t: 0.0,
                reason: UNAVAILABLE.into(),
            })
        }
    }
}

/// The world of a session, or none in a build without the `mujoco` feature.
mod sessions {
    #[cfg(feature = "mujoco")]
    pub type Mujoco = pushval_engine::stepping::PlateSession<crate::sim::Stepper, crate::MujocoRun>;
    #[cfg(not(feature = "mujoco"))]
    pub type Mujoco = pushval_engine::Unavailable<crate::MujocoRun>;
}

impl Simulator for MujocoSimulator {
    fn name(&self) -> String {
        format!("mujoco_{}", self.settings.cone.as_str())
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        self.run(problem).map(|r| r.trajectory)
    }
}
