//! An engine crate's one face: its typed session.
//!
//! An engine crate's simulator starts a typed session
//! ([`DetailedEngine::start`]); the caller advances it one push at a time
//! and [`finish`](DetailedSession::finish)es it into the crate's own record
//! of the run (the trajectory with what the engine measured besides it:
//! joint drift, step times, tails, loads, …). The [`Engine`](crate::Engine)
//! plug-in's session is that same typed session behind [`Detailed`], and the
//! generic [`EngineRun`] is the crate's record converted once
//! ([`DetailedRun::engine_run`]): there is no second path through an engine.
//!
//! [`DetailedEngine::run`] is the one whole-run convenience: `start`, one
//! `advance` per push of the problem's schedule, its release if it has one,
//! `finish`.

use pushval_model::{ModelError, Problem, Push, SlideReport, Trajectory};

use crate::session::{no_release, with_pushes};
use crate::{EngineRun, EngineSession, EngineState};

/// An engine's own record of a run: the trajectory and what the engine
/// measured besides it.
pub trait DetailedRun {
    /// The trajectory sampled at the problem's sample times (a session that
    /// released the plate continues it through the slide).
    fn trajectory_mut(&mut self) -> &mut Trajectory;
    /// The run as every engine gives it: the one conversion of the record
    /// into an [`EngineRun`] (its diagnostics, loads and contact record).
    fn engine_run(self) -> EngineRun;
}

/// One engine world being pushed, segment by segment, that finishes into
/// the engine's own record of the run ([`DetailedRun`]). The same calls as
/// [`EngineSession`], typed.
pub trait DetailedSession {
    /// The engine's record of a run.
    type Run: DetailedRun;
    /// The state at the end of the pushes applied so far
    /// ([`EngineSession::state`]).
    fn state(&self) -> EngineState;
    /// Applies one piecewise-constant push ([`EngineSession::advance`]).
    fn advance(&mut self, push: &Push) -> Result<(), ModelError>;
    /// Engine steps taken so far ([`EngineSession::steps_taken`]).
    fn steps_taken(&self) -> usize;
    /// Lets go of the plate and slides it to rest
    /// ([`EngineSession::release`]); by default the engine cannot.
    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        let _ = max_duration;
        Err(no_release("its session has no free slide"))
    }
    /// What the release found ([`EngineSession::slide`]).
    fn slide(&self) -> Option<SlideReport> {
        None
    }
    /// Ends the session: the engine's record of the pushes applied (and of
    /// the slide after a release).
    fn finish(self) -> Result<Self::Run, ModelError>;
}

/// The record a [`DetailedEngine`]'s session finishes with.
pub type RunOf<E> = <<E as DetailedEngine>::Session as DetailedSession>::Run;

/// An engine crate's simulator: it starts typed sessions.
pub trait DetailedEngine {
    /// Its typed session.
    type Session: DetailedSession;
    /// Builds the engine's world for `problem` (its schedule is not read:
    /// an object that does not start at rest is set moving with the first
    /// push applied, [`on_first_push`]) with the simulator's settings, time
    /// step included.
    fn start(&self, problem: &Problem) -> Result<Self::Session, ModelError>;
    /// The whole run of `problem`: [`start`](DetailedEngine::start), one
    /// `advance` per push of its schedule, the release when it has one,
    /// `finish` ([`drive`]).
    fn run(&self, problem: &Problem) -> Result<RunOf<Self>, ModelError> {
        problem.check()?;
        drive(self.start(problem)?, problem)
    }
}

/// Advances `session` by every push of `problem`'s schedule, releases the
/// plate when `problem` has a release, and finishes it.
pub fn drive<S: DetailedSession>(mut session: S, problem: &Problem) -> Result<S::Run, ModelError> {
    for push in &problem.pushes {
        session.advance(push)?;
    }
    if let Some(release) = &problem.release {
        session.release(release.max_duration)?;
    }
    session.finish()
}

/// A typed session as an [`EngineSession`]: its record converted once
/// ([`DetailedRun::engine_run`]), its trajectory named after the model
/// when [`Detailed::named`] says so.
pub struct Detailed<S> {
    session: S,
    model: Option<String>,
}

impl<S: DetailedSession> Detailed<S> {
    /// `session` as an [`EngineSession`].
    pub fn new(session: S) -> Self {
        Self {
            session,
            model: None,
        }
    }

    /// The run's trajectory is named `model` (an engine crate whose models
    /// share one simulator names each run after its model).
    #[must_use]
    pub fn named(mut self, model: impl Into<String>) -> Self {
        self.model = Some(model.into());
        self
    }
}

impl<S: DetailedSession> EngineSession for Detailed<S> {
    fn state(&self) -> EngineState {
        self.session.state()
    }
    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        self.session.advance(push)
    }
    fn finish(self: Box<Self>) -> Result<EngineRun, ModelError> {
        let Self { session, model } = *self;
        let mut run = session.finish()?.engine_run();
        if let Some(model) = model {
            run.trajectory.model = model;
        }
        Ok(run)
    }
    fn steps_taken(&self) -> usize {
        self.session.steps_taken()
    }
    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        self.session.release(max_duration)
    }
    fn slide(&self) -> Option<SlideReport> {
        self.session.slide()
    }
}

/// What builds a [`FirstPush`] session's world, from the start's problem
/// with the first push as its schedule.
type Build<S> = Box<dyn FnOnce(&Problem) -> Result<S, ModelError> + Send>;

/// A typed session whose world is built at once for an object at rest and
/// at the first push for one that starts moving ([`on_first_push`]).
pub struct FirstPush<S> {
    problem: Problem,
    build: Option<Build<S>>,
    session: Option<S>,
}

/// Builds an engine's session for `problem` (its schedule is dropped) with
/// `build`, where the start can be built without a push: at once for an
/// object at rest; for an object that starts moving (with the contact
/// velocity of its first push), at the first `advance`, with that push as
/// the schedule of the problem `build` receives. Until then the session's
/// state is [`EngineState::initial`].
pub fn on_first_push<S, F>(problem: &Problem, build: F) -> Result<FirstPush<S>, ModelError>
where
    F: FnOnce(&Problem) -> Result<S, ModelError> + Send + 'static,
{
    let problem = with_pushes(problem, Vec::new());
    if problem.initial.from_rest {
        let session = build(&problem)?;
        return Ok(FirstPush {
            problem,
            build: None,
            session: Some(session),
        });
    }
    Ok(FirstPush {
        problem,
        build: Some(Box::new(build)),
        session: None,
    })
}

impl<S: DetailedSession> DetailedSession for FirstPush<S> {
    type Run = S::Run;

    fn state(&self) -> EngineState {
        match &self.session {
            Some(s) => s.state(),
            None => EngineState::initial(&self.problem),
        }
    }

    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        if self.session.is_none() {
            let build = self.build.take().ok_or_else(|| {
                ModelError::Adapter("the session failed to start at its first push".into())
            })?;
            self.session = Some(build(&with_pushes(&self.problem, vec![*push]))?);
        }
        self.session.as_mut().expect("built above").advance(push)
    }

    fn steps_taken(&self) -> usize {
        self.session.as_ref().map_or(0, |s| s.steps_taken())
    }

    /// A release before any push throws the plate: the world is built at
    /// rest (no push gives it a velocity) and the release sets it moving
    /// with `initial.velocity` and ω.
    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        if self.session.is_none() {
            let build = self.build.take().ok_or_else(|| {
                ModelError::Adapter("the session failed to start at its release".into())
            })?;
            let mut problem = self.problem.clone();
            problem.initial.from_rest = true;
            self.session = Some(build(&problem)?);
        }
        self.session
            .as_mut()
            .expect("built above")
            .release(max_duration)
    }

    fn slide(&self) -> Option<SlideReport> {
        self.session.as_ref().and_then(|s| s.slide())
    }

    fn finish(self) -> Result<S::Run, ModelError> {
        self.session.ok_or(ModelError::EmptySchedule)?.finish()
    }
}

/// The session of an engine this build cannot run (a cargo feature left
/// out): it cannot be made, so its simulator's `start` only returns the
/// error that says why; its record type is the engine's.
pub enum Unavailable<R> {
    #[doc(hidden)]
    Never(std::convert::Infallible, std::marker::PhantomData<R>),
}

impl<R: DetailedRun> DetailedSession for Unavailable<R> {
    type Run = R;
    fn state(&self) -> EngineState {
        match *self {
            Self::Never(never, _) => match never {},
        }
    }
    fn advance(&mut self, _: &Push) -> Result<(), ModelError> {
        match *self {
            Self::Never(never, _) => match never {},
        }
    }
    fn steps_taken(&self) -> usize {
        match *self {
            Self::Never(never, _) => match never {},
        }
    }
    fn finish(self) -> Result<R, ModelError> {
        match self {
            Self::Never(never, _) => match never {},
        }
    }
}
