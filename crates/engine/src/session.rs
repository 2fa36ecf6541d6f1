//! The caller owns the loop: an engine run as a session.
//!
//! [`Engine::start`](crate::Engine::start) builds the engine's world for a
//! problem and a time step and returns an [`EngineSession`]: the caller reads
//! its [`state`](EngineSession::state), applies one piecewise-constant push
//! at a time with [`advance`](EngineSession::advance) and ends it with
//! [`finish`](EngineSession::finish), which returns the [`EngineRun`] a whole
//! run returns. `run(problem, dt)` is `start`, one `advance` per push of the
//! schedule, then `finish`, bit for bit ([`run_via_session`]).
//!
//! An engine that cannot keep its world between pushes gets a
//! [`ReplaySession`]: every `advance` re-runs the schedule applied so far
//! from the start. That is correct (the engines are deterministic) at N
//! times the cost for N pushes, and [`EngineSession::replays`] says so.

use pushval_model::{ModelError, Problem, Push};

use crate::{Engine, EngineRun};

/// The object's state at the end of the pushes applied so far.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EngineState {
    /// Time since the start (s).
    pub t: f64,
    /// World x of the centre of mass (m).
    pub x: f64,
    /// World y of the centre of mass (m).
    pub y: f64,
    /// Object angle, unwrapped (rad).
    pub theta: f64,
    /// Angular velocity (rad/s).
    pub omega: f64,
    /// World velocity of the centre of mass (m/s).
    pub v_cm: [f64; 2],
}

impl EngineState {
    /// The state of an object at rest at the problem's start.
    pub fn initial(problem: &Problem) -> Self {
        let i = &problem.initial;
        Self {
            t: 0.0,
            x: i.position.x,
            y: i.position.y,
            theta: i.theta,
            omega: if i.from_rest { 0.0 } else { i.omega },
            v_cm: [0.0, 0.0],
        }
    }

    /// The angular momentum about the world point under the object's
    /// contact (kg m²/s): `I_cm ω + m (r_cm − r_P) × v_cm`. It is what an
    /// impulsive switch of the pusher's velocity keeps, so it carries the
    /// state over a switch into the next push.
    pub fn contact_momentum(&self, problem: &Problem) -> f64 {
        let body = &problem.body;
        let d = -pushval_model::rotate(self.theta, &body.contact());
        body.inertia_cm() * self.omega + body.mass() * (d.x * self.v_cm[1] - d.y * self.v_cm[0])
    }
}

/// The world velocity of the centre of mass of a body whose contact point
/// moves with `push` while it turns at `omega` at angle `theta` (m/s):
/// `v_P + ω × (r_cm − r_P)`, what a rigid contact (a joint) imposes.
pub fn rigid_cm_velocity(
    problem: &Problem,
    push: Option<&Push>,
    theta: f64,
    omega: f64,
) -> [f64; 2] {
    let Some(push) = push else {
        return [0.0, 0.0];
    };
    let vp = pushval_model::rotate(theta, &push.velocity());
    let d = -pushval_model::rotate(theta, &problem.body.contact());
    [vp.x - omega * d.y, vp.y + omega * d.x]
}

/// One engine world being pushed, segment by segment.
pub trait EngineSession {
    /// The state at the end of the pushes applied so far (at the start: the
    /// problem's initial state).
    fn state(&self) -> EngineState;
    /// Applies one piecewise-constant push (speed, φ in the object frame,
    /// duration); the switch into it follows the problem's switching rule.
    fn advance(&mut self, push: &Push) -> Result<(), ModelError>;
    /// Ends the session: the run of the pushes applied, resampled at the
    /// problem's sample times and with its loads, as [`Engine::run`] gives it.
    fn finish(self: Box<Self>) -> Result<EngineRun, ModelError>;
    /// Whether the session re-runs the schedule applied so far at every
    /// `advance` (an engine that cannot keep its world between pushes).
    fn replays(&self) -> bool {
        false
    }
    /// Engine steps taken so far, replays included (the cost of the session).
    fn steps_taken(&self) -> usize;
}

/// The problem with `pushes` as its schedule (the start's problem carries
/// the schedule applied so far).
pub fn with_pushes(problem: &Problem, pushes: Vec<Push>) -> Problem {
    Problem {
        pushes,
        ..problem.clone()
    }
}

/// A session of an engine that cannot step: every `advance` re-runs the
/// schedule applied so far with [`Engine::run`].
pub struct ReplaySession<'a> {
    engine: &'a dyn Engine,
    problem: Problem,
    dt: f64,
    applied: Vec<Push>,
    last: Option<EngineRun>,
    state: EngineState,
    steps: usize,
}

impl<'a> ReplaySession<'a> {
    /// A session of `engine` on `problem` (its schedule is ignored) at `dt`.
    pub fn new(engine: &'a dyn Engine, problem: &Problem, dt: f64) -> Self {
        Self {
            engine,
            state: EngineState::initial(problem),
            problem: problem.clone(),
            dt,
            applied: Vec::new(),
            last: None,
            steps: 0,
        }
    }
}

impl EngineSession for ReplaySession<'_> {
    fn state(&self) -> EngineState {
        self.state
    }

    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        self.applied.push(*push);
        let problem = with_pushes(&self.problem, self.applied.clone());
        let run = self.engine.run(&problem, self.dt)?;
        self.steps += run.steps;
        let s = run
            .trajectory
            .samples
            .last()
            .copied()
            .ok_or(ModelError::EmptySchedule)?;
        self.state = EngineState {
            t: s.t,
            x: s.x,
            y: s.y,
            theta: s.theta,
            omega: s.omega,
            v_cm: rigid_cm_velocity(&self.problem, Some(push), s.theta, s.omega),
        };
        self.last = Some(run);
        Ok(())
    }

    fn finish(self: Box<Self>) -> Result<EngineRun, ModelError> {
        self.last.ok_or(ModelError::EmptySchedule)
    }

    fn replays(&self) -> bool {
        true
    }

    fn steps_taken(&self) -> usize {
        self.steps
    }
}

/// `run` as the contract defines it: `start`, one `advance` per push of the
/// schedule, `finish`.
pub fn run_via_session(
    engine: &dyn Engine,
    problem: &Problem,
    dt: f64,
) -> Result<EngineRun, ModelError> {
    problem.check()?;
    let mut session = engine.start(problem, dt)?;
    for push in &problem.pushes {
        session.advance(push)?;
    }
    session.finish()
}
