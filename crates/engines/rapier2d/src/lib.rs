//! The pushing problem of `pushval-model`, run in the rapier2d physics engine.
//!
//! This is the only crate of the workspace that imports rapier. It builds, for a
//! [`Problem`], a rapier world seen from above (gravity zero) with two bodies:
//!
//! * the **object**, a dynamic body whose mass and inertia about its centre of
//!   mass are set directly (it has no collider by default: nothing collides,
//!   so rapier's broad and narrow phases have nothing to do; see
//!   [`EngineSettings::colliders`] for the scene with colliders);
//! * the **pusher**, a kinematic velocity-based body pinned to the object at the
//!   contact point by a revolute impulse joint. Every step its velocity is set to
//!   the commanded contact velocity `v_c R(θ) n_φ` (taken at a mode-dependent
//!   angle and, in the default [`FrictionVelocity::Leapfrog`] mode, corrected
//!   for rapier's step-start lever arm), so the engine's joint solver
//!   prescribes the contact velocity and produces, by itself, the contact
//!   force and the impulses at switches.
//!
//! Every step, each support point `i` receives the Coulomb force
//! `−F_i u_i / |u_i|` through `add_force_at_point`, where `u_i` is the support's
//! sliding velocity, obtained in one of the ways of [`FrictionVelocity`].
//!
//! The engine runs in f64 (`rapier2d-f64`, the default) or f32 (`rapier2d`),
//! chosen at run time by [`EngineSettings::precision`]; one source file
//! (`world.rs`) is compiled once for each precision.
//!
//! After a release the pin joint goes and the plate slides to rest under
//! its support friction: Coulomb's as implicit impulses, the impulse idioms'
//! joints solved together by sequential impulses (they stop the plate in a
//! step once their caps can), the regularised laws as forces (a geometric
//! creep below their slip speed): see [`slide`] and the README.
//!
//! Units are SI throughout (m, s, rad, kg, N).
#![warn(missing_docs)]

use std::time::{Duration, Instant};

use pushval_engine::stepping::PlateSession;
use pushval_engine::{on_first_push, DetailedRun, EngineRun, FirstPush};
use pushval_model::{ModelError, Problem, Simulator, Trajectory};

pub mod engine;
/// The f32 build of the engine adapter (`rapier2d`).
mod f32_engine;
/// The f64 build of the engine adapter (`rapier2d-f64`).
mod f64_engine;
/// The 2-D friction idioms and their closed forms (they live in
/// `pushval-laws`).
pub use pushval_laws::idioms;
/// The friction idioms over a step of the free slide.
pub mod slide;

pub use engine::{laws, models, Rapier2dModel, ENGINE_CRATE};
pub use idioms::FrictionModel;
pub use pushval_engine::{drive, tail_mean_omega, DetailedEngine, DetailedSession, StepRecord};

/// What the per-precision engine code hands back.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct RawRun {
    pub history: Vec<StepRecord>,
    pub steps: usize,
    /// Time spent inside rapier's `step()`.
    pub step_time: std::time::Duration,
    /// Time of the whole stepping loop (rapier's steps and the adapter's work
    /// around them).
    pub loop_time: std::time::Duration,
    pub max_drift: f64,
    pub min_support_speed: f64,
}

/// Floating-point precision of the rapier build that runs the problem.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Precision {
    /// `rapier2d-f64` (default).
    #[default]
    F64,
    /// `rapier2d` (single precision).
    F32,
}

impl Precision {
    /// `"f64"` or `"f32"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }
}

/// How the sliding velocity `u_i` of each support is obtained when its friction
/// force is computed for a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum FrictionVelocity {
    /// The engine's own `velocity_at_point` of the object at the start of the
    /// step, with the pusher heading taken at the start of the step.
    Body,
    /// The commanded pusher velocity plus `ω × (p_i − p_c)` (world frame), with
    /// `ω` the object's angular velocity at the start of the step. The pusher
    /// heading is taken at the start of the step.
    Constraint,
    /// Like [`FrictionVelocity::Constraint`], but evaluated where a
    /// second-order (leapfrog) reading of the engine's symplectic Euler step
    /// wants it: `ω` is extrapolated from the last two step velocities of the
    /// segment to the start of the step (the engine's step velocities live at
    /// mid-steps), and the pusher heading is taken at the mid-step angle
    /// `θ + ω h / 2`. First order: the joint's lever arm is taken at the
    /// step start while the pusher velocity is a mid-step one, which leaves
    /// an `O(h)` bias of order `m h ω³ |p_c|²` in the moment balance, and the
    /// step velocities start and end each segment half a step out of phase.
    Midpoint,
    /// Second order (the default). Reads rapier's symplectic Euler step as a
    /// leapfrog (kick–drift) scheme, with the step velocities at mid-steps,
    /// and makes every part of the step consistent with that reading:
    ///
    /// * friction as in [`FrictionVelocity::Midpoint`]: the constraint form
    ///   at the step-start pose, with `ω` extrapolated to the step start;
    /// * the pusher velocity is
    ///   `v_c R(θ_m) n_φ + ω_m D (R(θ) − R(θ_m)) p_c`, with `ω_m` the
    ///   extrapolated mid-step ω and `θ_m = θ + atan(h ω_m)/2` the mid-step
    ///   angle (rapier turns a body by `atan(h ω)` per step). Since the joint
    ///   holds the contact with the step-start lever arm `R(θ) p_c`, this
    ///   gives the centre of mass the chord velocity
    ///   `R(θ_m)(v_c n_φ − ω D p_c)` of the arc it should follow, and the
    ///   joint impulse the moment of a centred difference of momenta;
    /// * the pusher is re-pinned onto the object's contact point before each
    ///   step, so the joint's position bias has nothing to correct and the
    ///   body moves with exactly the velocity the joint solved for (the bias
    ///   would otherwise push it off the chord by `h ω² p_c / 2`);
    /// * each segment opens with a half kick (the first full step after the
    ///   switch step applies half the friction impulse) and closes with one
    ///   (an extra step of the switch-step length, taken off the last step,
    ///   with the pusher velocity at the segment's end and the friction
    ///   impulse of half a step), so a switch impulse acts on the velocity
    ///   at the switch, not on a mid-step one, and the state a segment
    ///   leaves holds the velocity at its end time. Every segment closes,
    ///   whether or not a push follows: a segment's steps depend on its
    ///   push alone.
    ///
    /// Requires `switch_step_fraction > 0` for the closing half kick. The
    /// joint still produces every switch and start impulse: ω is never set.
    #[default]
    Leapfrog,
}

impl FrictionVelocity {
    /// `"body"`, `"constraint"`, `"midpoint"` or `"leapfrog"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            FrictionVelocity::Body => "body",
            FrictionVelocity::Constraint => "constraint",
            FrictionVelocity::Midpoint => "midpoint",
            FrictionVelocity::Leapfrog => "leapfrog",
        }
    }

    /// Every mode, in the order body, constraint, midpoint, leapfrog.
    pub const ALL: [FrictionVelocity; 4] = [
        FrictionVelocity::Body,
        FrictionVelocity::Constraint,
        FrictionVelocity::Midpoint,
        FrictionVelocity::Leapfrog,
    ];
}

/// How the engine runs a problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EngineSettings {
    /// Largest time step (s); default `1e-3`. Each push segment is cut into
    /// `n = ceil(duration / dt)` equal steps of `duration / n`, so steps land
    /// exactly on the switch times.
    pub dt: f64,
    /// rapier's `num_solver_iterations` (its number of solver substeps per
    /// step), ≥ 1; default `1`. rapier's own default is 4, but here more
    /// substeps *raise* the error (in `midpoint` mode the steady-ω error at
    /// dt = 1e-3 grows from 1.6e-5 with 1 substep to 1.4e-3 with 4): the
    /// friction forces are evaluated once per step, not per substep.
    pub solver_iterations: usize,
    /// rapier's `num_internal_pgs_iterations` (Gauss–Seidel sweeps per
    /// substep), ≥ 1; default `1` (rapier's). The lone pin joint is solved
    /// exactly in one sweep, so more change nothing measurable.
    pub pgs_iterations: usize,
    /// Precision of the rapier build; default [`Precision::F64`].
    pub precision: Precision,
    /// How the support sliding velocities (and the pusher velocity) are
    /// obtained; default [`FrictionVelocity::Leapfrog`].
    pub friction_velocity: FrictionVelocity,
    /// At the start and at every switch, first take a step of
    /// `switch_step_fraction · h` (h the segment's step) so that the joint
    /// delivers the switch impulse before the friction forces of the first
    /// full step are evaluated; that step's length is taken off the next one,
    /// so steps still land on the switch times. `0` turns this off (the
    /// friction of the first step then sees the angular velocity from before
    /// the switch). In [`FrictionVelocity::Leapfrog`] mode every segment
    /// also ends with a closing step of the same length (taken off the step
    /// before it). Dimensionless, in `[0, 0.5)`;
    /// default `1e-3`.
    pub switch_step_fraction: f64,
    /// The support-friction law; default [`FrictionModel::Coulomb`] (the
    /// analytic model's). The others are game-engine idioms (see
    /// [`idioms`]); their impulse cap uses the segment's nominal step.
    pub friction_model: FrictionModel,
    /// Attach colliders (default `false`): a convex polygon on the object
    /// (the outline given to [`RapierSimulator::start_with_outline`], else the
    /// convex hull of the supports and the contact point) and a 5 mm ball on
    /// the pusher. They are massless (density 0: the body's mass and inertia
    /// stay the ones set directly), in collision groups that exclude each
    /// other and in no solver group, so the motion is the same to rounding;
    /// only rapier's broad and narrow phases get work. Exists to measure what
    /// the collider-free scene saves (bench `rapier_step`).
    pub colliders: bool,
}

impl Default for EngineSettings {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            solver_iterations: 1,
            pgs_iterations: 1,
            precision: Precision::F64,
            friction_velocity: FrictionVelocity::Leapfrog,
            switch_step_fraction: 1e-3,
            friction_model: FrictionModel::Coulomb,
            colliders: false,
        }
    }
}

impl EngineSettings {
    /// A short label naming the variant, e.g. `rapier2d[f64,leapfrog,dt=0.001]`
    /// (with the friction model appended when it is not Coulomb).
    pub fn label(&self) -> String {
        let model = match self.friction_model {
            FrictionModel::Coulomb => String::new(),
            m => format!(",{}", m.as_str()),
        };
        format!(
            "rapier2d[{},{},dt={}{}]",
            self.precision.as_str(),
            self.friction_velocity.as_str(),
            self.dt,
            model
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
        if self.solver_iterations == 0 {
            return Err(ModelError::Parameter {
                name: "engine solver_iterations",
                requirement: ">= 1",
                value: 0.0,
            });
        }
        if self.pgs_iterations == 0 {
            return Err(ModelError::Parameter {
                name: "engine pgs_iterations",
                requirement: ">= 1",
                value: 0.0,
            });
        }
        self.friction_model.check()?;
        if !(self.switch_step_fraction >= 0.0 && self.switch_step_fraction < 0.5) {
            return Err(ModelError::Parameter {
                name: "engine switch_step_fraction",
                requirement: "in [0, 0.5)",
                value: self.switch_step_fraction,
            });
        }
        Ok(())
    }
}

/// A rapier run: the sampled trajectory and what the engine did.
#[derive(Debug, Clone, PartialEq)]
pub struct RapierRun {
    /// The trajectory sampled at [`Problem::sample_times`] (model `"rapier2d"`).
    pub trajectory: Trajectory,
    /// Largest distance (m) between the pusher's anchor and the object's
    /// contact point after any step: how far the joint let the contact drift.
    pub max_joint_drift: f64,
    /// Number of engine steps taken (the zero-length set-up step excluded,
    /// switch steps included).
    pub steps: usize,
    /// The settings used.
    pub settings: EngineSettings,
    /// Wall-clock time of the run (set-up, stepping and sampling).
    pub wall_time: Duration,
    /// The part of `wall_time` spent inside rapier's `step()`.
    pub rapier_step_time: Duration,
    /// The part of `wall_time` spent in the stepping loop: rapier's steps plus
    /// the adapter's per-step work (friction forces, pusher velocity, reading
    /// and recording the state). `stepping_time − rapier_step_time` is the
    /// adapter's overhead.
    pub stepping_time: Duration,
    /// Per segment, the mean angular velocity (rad/s) over the segment's last
    /// 20 % of engine steps (time-weighted): a cheap steady-ω estimate.
    pub segment_tail_omega: Vec<f64>,
    /// Every engine step: time, pose at the step's end, and the angular
    /// velocity the engine held over the step.
    pub history: Vec<StepRecord>,
}

/// The rapier2d engine as a [`Simulator`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RapierSimulator {
    /// How it runs.
    pub settings: EngineSettings,
}

impl RapierSimulator {
    /// A simulator with the given settings.
    pub fn new(settings: EngineSettings) -> Self {
        Self { settings }
    }

    /// [`DetailedEngine::start`] with the object's outline (m, object
    /// frame with the origin at the centre of mass) for the object's
    /// collider when [`EngineSettings::colliders`] is set: the collider is
    /// the outline's convex hull. An empty outline means the convex hull of
    /// the supports and the contact point. Without colliders the outline is
    /// not used.
    pub fn start_with_outline(
        &self,
        problem: &Problem,
        outline: &[[f64; 2]],
    ) -> Result<RapierSession, ModelError> {
        self.settings.check()?;
        let sim = *self;
        let outline = outline.to_vec();
        on_first_push(problem, move |problem| {
            let start = Instant::now();
            Ok(match sim.settings.precision {
                Precision::F64 => session::Worlds::F64(Box::new(PlateSession::new(
                    f64_engine::world::start(problem, &sim.settings, &outline)?,
                    Box::new(move |world, stepped, problem| {
                        Ok(sim.rapier_run(
                            problem,
                            f64_engine::world::raw_run(world, &stepped),
                            start,
                        ))
                    }),
                ))),
                Precision::F32 => session::Worlds::F32(Box::new(PlateSession::new(
                    f32_engine::world::start(problem, &sim.settings, &outline)?,
                    Box::new(move |world, stepped, problem| {
                        Ok(sim.rapier_run(
                            problem,
                            f32_engine::world::raw_run(world, &stepped),
                            start,
                        ))
                    }),
                ))),
            })
        })
    }

    /// The run of `raw` on `problem` (the pushes applied), started at `start`.
    pub(crate) fn rapier_run(&self, problem: &Problem, raw: RawRun, start: Instant) -> RapierRun {
        let segment_tail_omega = pushval_engine::step_tail_omega(problem, &raw.history, 0.2);
        let mut trajectory =
            pushval_engine::trajectory_from_steps(&self.name(), problem, &raw.history);
        trajectory.stats.steps = raw.steps;
        trajectory.stats.rhs_evals = raw.steps;
        trajectory.assumptions.min_support_speed = raw.min_support_speed;
        RapierRun {
            trajectory,
            max_joint_drift: raw.max_drift,
            steps: raw.steps,
            settings: self.settings,
            wall_time: start.elapsed(),
            rapier_step_time: raw.step_time,
            stepping_time: raw.loop_time,
            segment_tail_omega,
            history: raw.history,
        }
    }
}

/// The crate's one face: a session of the rapier world, pushed one push at
/// a time, finished into a [`RapierRun`].
impl DetailedEngine for RapierSimulator {
    type Session = RapierSession;

    /// The world of `problem` in the settings' precision, without colliders'
    /// outline ([`RapierSimulator::start_with_outline`]).
    fn start(&self, problem: &Problem) -> Result<RapierSession, ModelError> {
        self.start_with_outline(problem, &[])
    }
}

impl Simulator for RapierSimulator {
    fn name(&self) -> String {
        "rapier2d".to_string()
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        self.run(problem).map(|r| r.trajectory)
    }
}

impl DetailedRun for RapierRun {
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

/// A rapier2d session: the world in the settings' precision, owned and
/// `Send`; built at the first push for an object that starts moving.
pub type RapierSession = FirstPush<session::Worlds>;

mod session {
    use pushval_engine::stepping::PlateSession;
    use pushval_engine::{DetailedSession, EngineState};
    use pushval_model::{ModelError, Push, SlideReport};

    use crate::{f32_engine, f64_engine, RapierRun};

    /// The session's world in either precision.
    pub enum Worlds {
        F64(Box<PlateSession<f64_engine::world::World2d, RapierRun>>),
        F32(Box<PlateSession<f32_engine::world::World2d, RapierRun>>),
    }

    /// Both precisions' sessions answer alike.
    macro_rules! each {
        ($self:expr, $s:ident => $e:expr) => {
            match $self {
                Worlds::F64($s) => $e,
                Worlds::F32($s) => $e,
            }
        };
    }

    impl DetailedSession for Worlds {
        type Run = RapierRun;
        fn state(&self) -> EngineState {
            each!(self, s => s.state())
        }
        fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
            each!(self, s => s.advance(push))
        }
        fn steps_taken(&self) -> usize {
            each!(self, s => s.steps_taken())
        }
        fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
            each!(self, s => s.release(max_duration))
        }
        fn slide(&self) -> Option<SlideReport> {
            each!(self, s => s.slide())
        }
        fn finish(self) -> Result<RapierRun, ModelError> {
            each!(self, s => (*s).finish())
        }
    }
}
