//! The pushing problem of `pushval-model` as a 3-D scene in rapier3d (f64),
//! with rapier's **own** contact friction: no friction force is applied by hand.
//!
//! The scene (z up, gravity `(0, 0, −g)`, g = [`Rapier3dSettings::gravity`]):
//!
//! * **Ground**: a fixed body with a large cuboid collider whose top face is
//!   the plane z = 0; friction coefficient 1 with
//!   [`CoefficientCombineRule::Multiply`](rapier3d_f64::prelude::CoefficientCombineRule),
//!   restitution 0.
//! * **Object**: a dynamic body with its origin at the centre of mass, at
//!   height `cm_height` above the ground. Mass `m` and inertia are set
//!   explicitly: the vertical-axis inertia is the problem's `I_cm`, the two
//!   tilt inertias are `I_cm/2 + m t²/12` (a thin plate of thickness
//!   `plate_thickness` t, perpendicular-axis theorem;
//!   [`predict::tilt_inertia`]). One small ball ("foot", radius
//!   `foot_radius`) per support, its lowest point at the support's `(x_i, y_i)`
//!   on the ground; the feet have density 0 (no mass of their own). Each
//!   foot's friction is `μ_i` with `Multiply`, so the effective coefficient
//!   against the ground is `μ_i · 1 = μ_i`; restitution 0.
//! * **Pusher**: a kinematic velocity-based body without collider, joined to
//!   the object at the contact point `p_c`, at height `push_height` above the
//!   ground, by a [`GenericJoint`](rapier3d_f64::prelude::GenericJoint) that
//!   locks only `LIN_X` and `LIN_Y` of the pusher's (world-aligned) frame: it
//!   transmits only a horizontal force, carries no weight, and leaves the
//!   object free to rise, tilt and turn. Every step the pusher is re-pinned
//!   onto the object's contact point and given the commanded contact velocity
//!   `v_c R(θ_m) n_φ`, θ_m the object's yaw at mid-step (`θ + ω h/2`).
//!
//! The friction comes from rapier's contact solver, in one of its two 3-D
//! friction models ([`ContactFriction`]). How the feet are grouped into
//! colliders decides what `Simplified` does ([`FeetColliders`]): rapier builds
//! contact manifolds per *collider pair* (and merges a compound collider's
//! per-ball manifolds that share a normal into one "cluster" manifold of at
//! most 4 points), and `Simplified` replaces a manifold's per-point friction
//! by one friction constraint at the manifold's friction centre plus a twist
//! constraint — see [`predict`] for the closed forms.
//!
//! **Start.** The object is placed with its feet exactly touching the ground
//! and first settles for `settle_time` with the pusher at rest (the normal
//! loads build up in rapier's soft contacts). Then the clock is reset to 0 and
//! the push schedule starts: unless `initial.from_rest`, the object is given
//! the velocity of a body moving with the first push at ω = `initial.omega`
//! (the seed paper's start); with `from_rest` it is left at rest and the joint
//! delivers the start impulse. Switches between push segments need nothing
//! special: the pusher velocity changes and the joint delivers the impulse.
//! `Problem::switching` is ignored (the engine is what shows which reading a
//! rigid body obeys), as in the 2-D adapter.
//!
//! **Friction coefficients.** The model's supports carry only `F_i = μ_i N_i`;
//! in 3-D the loads come out of the contact solver. The adapter takes the
//! loads the scene has at rest ([`predict::Scene::rest_loads`]: statics for
//! up to three supports, springs ∝ effective mass for more — equal loads for
//! symmetric layouts) and sets `μ_i = F_i / N_i^rest`, so that at rest each
//! support has the friction the problem asks for. A problem whose loads the
//! rest loads cannot give (a non-positive rest load where `F_i > 0`) is
//! refused.
//!
//! Units are SI throughout (m, s, rad, kg, N).
#![warn(missing_docs)]

use std::time::{Duration, Instant};

use pushval_engine::stepping::PlateSession;
use pushval_engine::{on_first_push, DetailedRun, EngineRun, FirstPush};
use pushval_model::{ModelError, Problem, Simulator, Trajectory};

mod engine;
/// The 3-D scene's closed forms (they live in `pushval-laws`).
pub use pushval_laws::rapier3d as predict;
mod world;

pub use engine::{models, Rapier3dModel, ENGINE_CRATE};
pub use pushval_engine::{DetailedEngine, DetailedSession};

/// Which of rapier3d's friction models the contact solver uses
/// (`IntegrationParameters::friction_model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ContactFriction {
    /// `FrictionModel::Coulomb`: one friction constraint (a 2-D impulse capped
    /// by a disk of radius `μ λ_n`) per contact point. The default here.
    #[default]
    Coulomb,
    /// `FrictionModel::Simplified` (rapier's default): per contact manifold,
    /// one friction constraint at the friction centre (mean of the points),
    /// capped by `μ Σ λ_n`, plus one twist constraint about the normal capped
    /// by `μ Σ λ_n,k |p_k − c|`. A manifold with one point gets no twist.
    Simplified,
}

impl ContactFriction {
    /// `"coulomb"` or `"simplified"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            ContactFriction::Coulomb => "coulomb",
            ContactFriction::Simplified => "simplified",
        }
    }

    /// Both, Coulomb first.
    pub const ALL: [ContactFriction; 2] = [ContactFriction::Coulomb, ContactFriction::Simplified];
}

/// How the feet are made into colliders. This decides how many contact
/// manifolds rapier builds, and so what [`ContactFriction::Simplified`] does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum FeetColliders {
    /// One compound collider holding every foot (one collider per body, as a
    /// game would build it): rapier clusters the feet's manifolds (same normal)
    /// into **one** manifold of up to 4 points, so `Simplified` friction acts
    /// on the feet together. Needs at most 4 supports (rapier keeps at most 4
    /// points of a cluster) and one friction coefficient (friction is per
    /// collider pair). The default.
    #[default]
    Compound,
    /// One ball collider per foot: one manifold of one point per foot, so
    /// `Simplified` has no twist and acts like `Coulomb`. Any number of
    /// supports and a coefficient per support.
    Separate,
}

impl FeetColliders {
    /// `"compound"` or `"separate"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            FeetColliders::Compound => "compound",
            FeetColliders::Separate => "separate",
        }
    }
}

/// How the 3-D engine runs a problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rapier3dSettings {
    /// Largest time step (s); default `1e-3`. Each push segment is cut into
    /// `ceil(duration / dt)` equal steps, so steps land on the switch times.
    pub dt: f64,
    /// rapier's friction model; default [`ContactFriction::Coulomb`].
    pub friction: ContactFriction,
    /// Radius of the ball feet (m); default `0.003`.
    pub foot_radius: f64,
    /// Height of the centre of mass above the ground (m); default `0.01`.
    pub cm_height: f64,
    /// Height above the ground at which the pusher joint holds the object (m);
    /// default `0.01` (the centre of mass's height).
    pub push_height: f64,
    /// rapier's `num_solver_iterations` (substeps per step), ≥ 1; default 4
    /// (rapier's).
    pub solver_iterations: usize,
    /// rapier's `num_internal_pgs_iterations`, ≥ 1; default 1 (rapier's).
    pub pgs_iterations: usize,
    /// Gravity (m/s²); default 9.81. The problem's friction magnitudes are
    /// divided by the rest loads under this gravity to give the μ_i.
    pub gravity: f64,
    /// Plate thickness (m) for the tilt inertias; default `0.005`.
    pub plate_thickness: f64,
    /// How the feet are made into colliders; default [`FeetColliders::Compound`].
    pub feet: FeetColliders,
    /// rapier's `contact_recycling` (rapier's default: true). When on, a
    /// contact pair that moved less than 5 cm (translation plus rotation
    /// chord) since its last full update keeps its points **and the solver's
    /// world-space lever arms** (`ContactData::solver_dp1`) frozen. Default
    /// false here: the lever arms then follow the turning body every step.
    pub contact_recycling: bool,
    /// Duration (s) of the settle phase before the push starts; default 0.3
    /// (the soft contacts' slow time constant is about 0.05 s).
    pub settle_time: f64,
}

impl Default for Rapier3dSettings {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            friction: ContactFriction::Coulomb,
            foot_radius: 0.003,
            cm_height: 0.01,
            push_height: 0.01,
            solver_iterations: 4,
            pgs_iterations: 1,
            gravity: 9.81,
            plate_thickness: 0.005,
            feet: FeetColliders::Compound,
            contact_recycling: false,
            settle_time: 0.3,
        }
    }
}

impl Rapier3dSettings {
    /// A short description, e.g.
    /// `rapier3d[coulomb,compound,dt=0.001,h_cm=0.01,h_push=0.01]`
    /// (`,recycling` appended when contact recycling is on).
    pub fn label(&self) -> String {
        format!(
            "rapier3d[{},{},dt={},h_cm={},h_push={}{}]",
            self.friction.as_str(),
            self.feet.as_str(),
            self.dt,
            self.cm_height,
            self.push_height,
            if self.contact_recycling {
                ",recycling"
            } else {
                ""
            }
        )
    }

    /// Checks the settings; errors name the field.
    pub fn check(&self) -> Result<(), ModelError> {
        let positive = ModelError::require_positive;
        positive("rapier3d dt", self.dt)?;
        positive("rapier3d foot_radius", self.foot_radius)?;
        positive("rapier3d cm_height", self.cm_height)?;
        positive("rapier3d gravity", self.gravity)?;
        positive("rapier3d plate_thickness", self.plate_thickness)?;
        ModelError::require_non_negative("rapier3d push_height", self.push_height)?;
        ModelError::require_non_negative("rapier3d settle_time", self.settle_time)?;
        if self.solver_iterations == 0 {
            return Err(ModelError::Parameter {
                name: "rapier3d solver_iterations",
                requirement: ">= 1",
                value: 0.0,
            });
        }
        if self.pgs_iterations == 0 {
            return Err(ModelError::Parameter {
                name: "rapier3d pgs_iterations",
                requirement: ">= 1",
                value: 0.0,
            });
        }
        Ok(())
    }

    /// The [`predict::Scene`] of `problem` under these settings (μ_i from the
    /// rest loads, see the crate docs).
    pub fn scene(&self, problem: &Problem) -> Result<predict::Scene, ModelError> {
        world::scene_of(problem, self)
    }
}

/// The settings' plain parameters of the prediction scene.
impl From<&Rapier3dSettings> for predict::SceneParams {
    fn from(s: &Rapier3dSettings) -> Self {
        Self {
            cm_height: s.cm_height,
            push_height: s.push_height,
            plate_thickness: s.plate_thickness,
            gravity: s.gravity,
            compound_feet: s.feet == FeetColliders::Compound,
        }
    }
}

/// One engine step: time, pose at its end, the angular velocity held over
/// it, height and tilt (the shared stepping loop's record).
pub use pushval_engine::stepping::PlateStep as Step3d;

/// A 3-D run: the sampled trajectory and what the engine did.
#[derive(Debug, Clone, PartialEq)]
pub struct Rapier3dRun {
    /// The trajectory sampled at [`Problem::sample_times`].
    pub trajectory: Trajectory,
    /// The settings used.
    pub settings: Rapier3dSettings,
    /// Engine steps of the push (settle steps excluded).
    pub steps: usize,
    /// Wall-clock time of the run (set-up, settling, stepping, sampling).
    pub wall_time: Duration,
    /// Friction coefficient given to each foot.
    pub mu: Vec<f64>,
    /// The loads (N) μ_i was computed from ([`predict::Scene::rest_loads`]).
    pub nominal_loads: Vec<f64>,
    /// Measured normal force (N) of each foot at the end of the settle phase.
    pub rest_loads: Vec<f64>,
    /// Per segment, the mean ω (rad/s) over its last 20 % of steps.
    pub segment_tail_omega: Vec<f64>,
    /// Per segment, each foot's mean normal force (N) over the last 20 %.
    pub segment_tail_loads: Vec<Vec<f64>>,
    /// The time-weighted mean normal force of each foot over the last fifth
    /// of the run (N), in support order: the engine diagnostics' `"loads"`.
    pub loads: Vec<f64>,
    /// The supports' loads at every sample, the largest rise and the share
    /// of steps with a foot out of contact (the engine run's `contact`).
    pub contact: Option<pushval_engine::ContactRecord>,
    /// Per segment, each foot's mean friction force magnitude (N) over the
    /// last 20 % (compare with `μ_i N_i`: below it, the foot sticks).
    pub segment_tail_friction: Vec<Vec<f64>>,
    /// Per segment, each foot's smallest horizontal slip speed (m/s) over the
    /// last 20 %.
    pub segment_tail_min_slip: Vec<Vec<f64>>,
    /// Smallest normal force (N) of each foot over the push.
    pub min_loads: Vec<f64>,
    /// Largest tilt (rad) over the push.
    pub max_tilt: f64,
    /// Largest vertical displacement of the centre of mass from its height at
    /// the end of the settle phase (m).
    pub max_lift: f64,
    /// Largest horizontal distance (m) between the pusher and the object's
    /// contact point after a step (before re-pinning).
    pub max_joint_drift: f64,
    /// Contact manifolds the solver saw between the object and the ground at
    /// the end of the settle phase.
    pub manifolds: usize,
    /// Contact points in those manifolds.
    pub manifold_points: usize,
    /// Every step of the push, after an initial record at t = 0.
    pub history: Vec<Step3d>,
}

impl Rapier3dRun {
    /// Whether a foot lost its contact (normal force below 1e-3 of its rest
    /// load at some step): the object tipped or hopped.
    pub fn lost_contact(&self) -> Vec<bool> {
        self.min_loads
            .iter()
            .zip(&self.nominal_loads)
            .map(|(&n, &n0)| n < 1e-3 * n0)
            .collect()
    }
}

/// The rapier3d engine as a [`Simulator`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rapier3dSimulator {
    /// How it runs.
    pub settings: Rapier3dSettings,
}

impl Rapier3dSimulator {
    /// A simulator with the given settings.
    pub fn new(settings: Rapier3dSettings) -> Self {
        Self { settings }
    }
}

/// A rapier3d session: the scene, settled, pushed one push at a time;
/// owned and `Send`. Built at the first push for an object that starts
/// moving.
pub type Rapier3dSession = FirstPush<PlateSession<world::Scene3d, Rapier3dRun>>;

/// The crate's one face: a session of the scene, finished into a
/// [`Rapier3dRun`].
impl DetailedEngine for Rapier3dSimulator {
    type Session = Rapier3dSession;

    /// The scene of `problem`, settled, through the shared stepping loop
    /// ([`pushval_engine::stepping`]).
    fn start(&self, problem: &Problem) -> Result<Rapier3dSession, ModelError> {
        self.settings.check()?;
        let sim = *self;
        on_first_push(problem, move |problem| {
            let started = Instant::now();
            let (stepping, set_up) = world::start(problem, &sim.settings)?;
            Ok(PlateSession::new(
                stepping,
                Box::new(move |_, stepped, problem| {
                    let mut run = world::finish(set_up, stepped, problem);
                    run.trajectory.model = sim.name();
                    run.wall_time = started.elapsed();
                    Ok(run)
                }),
            ))
        })
    }
}

impl DetailedRun for Rapier3dRun {
    fn trajectory_mut(&mut self) -> &mut Trajectory {
        &mut self.trajectory
    }

    /// The run with the joint drift, tilt, lift and the feet's loads as
    /// diagnostics, and its contact record.
    fn engine_run(self) -> EngineRun {
        EngineRun {
            dt: self.settings.dt,
            steps: self.steps,
            wall_time: self.wall_time,
            diagnostics: serde_json::json!({
                "steps": self.steps,
                "max_joint_drift": self.max_joint_drift,
                "max_tilt": self.max_tilt,
                "max_lift": self.max_lift,
                "loads": self.loads,
            }),
            trajectory: self.trajectory,
            contact: self.contact,
        }
    }
}

impl Simulator for Rapier3dSimulator {
    /// `"rapier3d"` (Coulomb) or `"rapier3d_simplified"`.
    fn name(&self) -> String {
        match self.settings.friction {
            ContactFriction::Coulomb => "rapier3d".to_string(),
            ContactFriction::Simplified => "rapier3d_simplified".to_string(),
        }
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        self.run(problem).map(|r| r.trajectory)
    }
}
