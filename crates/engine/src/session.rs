//! The caller owns the loop: an engine run as a session.
//!
//! [`Engine::start`](crate::Engine::start) builds the engine's world for a
//! problem and a time step and returns a [`Session`]: the caller reads its
//! [`state`](EngineSession::state), applies one piecewise-constant push at a
//! time with [`advance`](EngineSession::advance) and ends it with
//! [`finish`](EngineSession::finish), which returns the [`EngineRun`] a whole
//! run returns. `run(problem, dt)` is `start`, one `advance` per push of the
//! schedule, then `finish` ([`run_via_session`]).
//!
//! A session answers only what it is asked: its result depends on the pushes
//! it was advanced by, never on a schedule announced at `start` (the engine
//! is handed the start's problem without its schedule; an object that does
//! not start at rest is set moving with the first push applied,
//! [`on_first_push`](crate::on_first_push)).
//!
//! A session is owned and `Send`: it borrows nothing from its engine, so a
//! loop, a thread or a binding can hold one. An engine whose world cannot
//! leave the thread it was built on keeps it on a thread of the session's
//! own ([`on_thread`]).
//!
//! An engine that cannot keep its world between pushes gets a
//! [`ReplaySession`]: every `advance` re-runs the schedule applied so far
//! from the start. That is correct (the engines are deterministic) at N
//! times the cost for N pushes, and [`EngineSession::replays`] says so.

use std::sync::{mpsc, Arc};
use std::thread::JoinHandle;

use pushval_model::{ModelError, Problem, Push, SlideReport};

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
    /// Lets go of the plate: the pusher's constraint goes and the engine
    /// steps until the plate is at rest, or until `max_duration` (s) has
    /// passed (then the slide is reported as not stopped, never as rest).
    ///
    /// **At rest** means: the plate's speed `|v_cm| + |ω| L` (m/s, `L` the
    /// largest distance of a support from the centre of mass) is below
    /// [`REST_SPEED`] on [`REST_STEPS`] consecutive steps; the stop time is
    /// the end of the first of those steps. After a release,
    /// [`state`](EngineSession::state) is the rest state (its `t` the stop
    /// time) or the state at `max_duration`, [`slide`](EngineSession::slide)
    /// says which, and the run [`finish`](EngineSession::finish) returns goes
    /// on through the slide (its last row the rest) with
    /// [`Trajectory::slide`](pushval_model::Trajectory::slide) set. No push
    /// can follow a release.
    ///
    /// Without a push applied before it, the plate is thrown: it starts
    /// the slide with the problem's `initial.velocity` and ω.
    ///
    /// By default an engine cannot release: [`ModelError::NoRelease`], never
    /// a run that ends at the release.
    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        let _ = max_duration;
        Err(no_release("its session has no free slide"))
    }
    /// What the release found (None before a release, or for a session that
    /// does not release).
    fn slide(&self) -> Option<SlideReport> {
        None
    }
}

/// Speed (m/s) below which a plate counts as at rest: `|v_cm| + |ω| L`, `L`
/// the largest distance of a support from the centre of mass. At a
/// deceleration μg of a few m/s² it is passed a few microseconds before the
/// stop.
pub const REST_SPEED: f64 = 1e-5;

/// Consecutive steps the plate must stay below [`REST_SPEED`] to be at
/// rest (a plate passing through zero speed is not at rest).
pub const REST_STEPS: usize = 10;

/// The refusal of an engine that cannot release, for `reason`; the engine's
/// name is filled in by the session [`start`] hands out.
pub fn no_release(reason: impl Into<String>) -> ModelError {
    ModelError::NoRelease {
        engine: String::new(),
        reason: reason.into(),
    }
}

/// The plate's speed measure of the rest rule (m/s): `|v_cm| + |ω| L`.
pub fn rest_speed(problem: &Problem, v_cm: [f64; 2], omega: f64) -> f64 {
    let l = problem
        .body
        .supports()
        .map(|s| s.position.norm())
        .fold(0.0, f64::max);
    v_cm[0].hypot(v_cm[1]) + omega.abs() * l
}

/// An owned engine session, as [`Engine::start`](crate::Engine::start)
/// hands it out: no borrow of the engine, and `Send`.
pub type Session = Box<dyn EngineSession + Send>;

/// The problem with `pushes` as its schedule (the start's problem carries
/// the schedule applied so far).
pub fn with_pushes(problem: &Problem, pushes: Vec<Push>) -> Problem {
    Problem {
        pushes,
        ..problem.clone()
    }
}

/// What a [`Threaded`] session asks its thread.
enum Ask {
    Advance(Push),
    Release(f64),
    Finish,
}

/// What the thread answers: the state and steps after an advance, or the
/// run.
enum Answer {
    Advanced(Result<(EngineState, usize), ModelError>),
    Released(Result<(EngineState, usize, Option<SlideReport>), ModelError>),
    Finished(Box<Result<EngineRun, ModelError>>),
}

/// The session of an engine whose world cannot leave the thread that built
/// it (a native library's handles): `build` runs on a thread the session
/// owns, the world stays there, and `advance` and `finish` are requests to
/// that thread (the state is kept on this side after every answer). The
/// session is `Send` whatever the world is; the thread ends with the
/// session (at `finish`, or when it is dropped).
pub fn on_thread<F>(build: F) -> Result<Session, ModelError>
where
    F: FnOnce() -> Result<Box<dyn EngineSession>, ModelError> + Send + 'static,
{
    let (ask_tx, ask_rx) = mpsc::channel::<Ask>();
    let (answer_tx, answer_rx) = mpsc::channel::<Answer>();
    let thread = std::thread::Builder::new()
        .name("pushval-engine-session".into())
        .spawn(move || {
            let mut session = match build() {
                Ok(s) => {
                    let first = Ok((s.state(), s.steps_taken()));
                    if answer_tx.send(Answer::Advanced(first)).is_err() {
                        return;
                    }
                    s
                }
                Err(e) => {
                    let _ = answer_tx.send(Answer::Advanced(Err(e)));
                    return;
                }
            };
            while let Ok(ask) = ask_rx.recv() {
                match ask {
                    Ask::Advance(push) => {
                        let r = session
                            .advance(&push)
                            .map(|()| (session.state(), session.steps_taken()));
                        if answer_tx.send(Answer::Advanced(r)).is_err() {
                            return;
                        }
                    }
                    Ask::Release(max_duration) => {
                        let r = session
                            .release(max_duration)
                            .map(|()| (session.state(), session.steps_taken(), session.slide()));
                        if answer_tx.send(Answer::Released(r)).is_err() {
                            return;
                        }
                    }
                    Ask::Finish => {
                        let _ = answer_tx.send(Answer::Finished(Box::new(session.finish())));
                        return;
                    }
                }
            }
        })
        .map_err(|e| {
            ModelError::Adapter(format!("cannot start an engine session's thread: {e}"))
        })?;
    let mut s = Threaded {
        ask: ask_tx,
        answer: answer_rx,
        thread: Some(thread),
        state: EngineState::default(),
        steps: 0,
        slide: None,
    };
    let (state, steps) = s.advanced()?;
    s.state = state;
    s.steps = steps;
    Ok(Box::new(s))
}

/// A session whose world lives on its own thread ([`on_thread`]).
struct Threaded {
    ask: mpsc::Sender<Ask>,
    answer: mpsc::Receiver<Answer>,
    thread: Option<JoinHandle<()>>,
    state: EngineState,
    steps: usize,
    slide: Option<SlideReport>,
}

impl Threaded {
    /// The thread ended without an answer: its panic, or that it is gone.
    fn lost(&mut self) -> ModelError {
        let why = match self.thread.take().map(JoinHandle::join) {
            Some(Err(panic)) => panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic".into()),
            _ => "it ended".into(),
        };
        ModelError::Adapter(format!("the engine session's thread stopped: {why}"))
    }

    /// The answer to an advance (or to the start).
    fn advanced(&mut self) -> Result<(EngineState, usize), ModelError> {
        match self.answer.recv() {
            Ok(Answer::Advanced(r)) => r,
            Ok(Answer::Finished(_) | Answer::Released(_)) | Err(_) => Err(self.lost()),
        }
    }
}

impl EngineSession for Threaded {
    fn state(&self) -> EngineState {
        self.state
    }

    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        if self.ask.send(Ask::Advance(*push)).is_err() {
            return Err(self.lost());
        }
        let (state, steps) = self.advanced()?;
        self.state = state;
        self.steps = steps;
        Ok(())
    }

    fn finish(mut self: Box<Self>) -> Result<EngineRun, ModelError> {
        if self.ask.send(Ask::Finish).is_err() {
            return Err(self.lost());
        }
        let run = match self.answer.recv() {
            Ok(Answer::Finished(r)) => *r,
            Ok(Answer::Advanced(_) | Answer::Released(_)) | Err(_) => Err(self.lost()),
        };
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        run
    }

    fn steps_taken(&self) -> usize {
        self.steps
    }

    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        if self.ask.send(Ask::Release(max_duration)).is_err() {
            return Err(self.lost());
        }
        let (state, steps, slide) = match self.answer.recv() {
            Ok(Answer::Released(r)) => r?,
            Ok(Answer::Advanced(_) | Answer::Finished(_)) | Err(_) => return Err(self.lost()),
        };
        self.state = state;
        self.steps = steps;
        self.slide = slide;
        Ok(())
    }

    fn slide(&self) -> Option<SlideReport> {
        self.slide.clone()
    }
}

/// A session of an engine that cannot step: every `advance` re-runs the
/// schedule applied so far with [`Engine::run`]. It owns (a share of) its
/// engine.
pub struct ReplaySession {
    engine: Arc<dyn Engine>,
    problem: Problem,
    dt: f64,
    applied: Vec<Push>,
    last: Option<EngineRun>,
    state: EngineState,
    steps: usize,
    released: bool,
}

impl ReplaySession {
    /// A session of `engine` on `problem` (its schedule is ignored) at `dt`.
    pub fn new(engine: Arc<dyn Engine>, problem: &Problem, dt: f64) -> Self {
        Self {
            engine,
            state: EngineState::initial(problem),
            problem: with_pushes(problem, Vec::new()),
            dt,
            applied: Vec::new(),
            last: None,
            steps: 0,
            released: false,
        }
    }
}

impl EngineSession for ReplaySession {
    fn state(&self) -> EngineState {
        self.state
    }

    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        if self.released {
            return Err(after_release());
        }
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

    /// Re-runs the pushes applied with the release after them; the state
    /// is the run's last row (its velocity the rest's zero, or, when the
    /// plate has not stopped, the last two rows' difference).
    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        if self.released {
            return Err(after_release());
        }
        let mut problem = with_pushes(&self.problem, self.applied.clone());
        problem.release = Some(pushval_model::Release { max_duration });
        let run = self.engine.run(&problem, self.dt)?;
        self.steps += run.steps;
        let rows = &run.trajectory.samples;
        let s = *rows.last().ok_or(ModelError::EmptySchedule)?;
        let stopped = run
            .trajectory
            .slide
            .as_ref()
            .is_some_and(|r| r.t_stop.is_some());
        let v_cm = match rows.len() {
            n if n >= 2 && !stopped => {
                let p = rows[n - 2];
                let dt = (s.t - p.t).max(f64::MIN_POSITIVE);
                [(s.x - p.x) / dt, (s.y - p.y) / dt]
            }
            _ => [0.0, 0.0],
        };
        self.state = EngineState {
            t: s.t,
            x: s.x,
            y: s.y,
            theta: s.theta,
            omega: if stopped { 0.0 } else { s.omega },
            v_cm,
        };
        self.last = Some(run);
        self.released = true;
        Ok(())
    }

    fn slide(&self) -> Option<SlideReport> {
        self.last.as_ref().and_then(|r| r.trajectory.slide.clone())
    }

    fn steps_taken(&self) -> usize {
        self.steps
    }
}

/// Builds `engine`'s session for `problem` at `dt` (what
/// [`Engine::start`](crate::Engine::start) does): the step is checked, and
/// the engine is handed the problem without its schedule.
pub fn start<E: Engine + ?Sized>(
    engine: &E,
    problem: &Problem,
    dt: f64,
) -> Result<Session, ModelError> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(ModelError::Parameter {
            name: "dt",
            requirement: "finite and > 0",
            value: dt,
        });
    }
    let inner = engine.session(&with_pushes(problem, Vec::new()), dt)?;
    Ok(Box::new(Named {
        engine: engine.info().name.clone(),
        inner,
    }))
}

/// The refusal of a push after the release.
pub fn after_release() -> ModelError {
    ModelError::Adapter("the plate was released: no push can follow the release".into())
}

/// An engine's session as [`start`] hands it out: the engine's own, whose
/// refusal to release names the engine and whose run carries its name.
struct Named {
    engine: String,
    inner: Session,
}

impl EngineSession for Named {
    fn state(&self) -> EngineState {
        self.inner.state()
    }
    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        self.inner.advance(push)
    }
    fn finish(self: Box<Self>) -> Result<EngineRun, ModelError> {
        let mut run = self.inner.finish()?;
        if run.trajectory.model.is_empty() {
            run.trajectory.model = self.engine;
        }
        Ok(run)
    }
    fn replays(&self) -> bool {
        self.inner.replays()
    }
    fn steps_taken(&self) -> usize {
        self.inner.steps_taken()
    }
    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        if !(max_duration.is_finite() && max_duration > 0.0) {
            return Err(ModelError::Parameter {
                name: "release max_duration",
                requirement: "finite and > 0",
                value: max_duration,
            });
        }
        match self.inner.release(max_duration) {
            Err(ModelError::NoRelease { engine, reason }) if engine.is_empty() => {
                Err(ModelError::NoRelease {
                    engine: self.engine.clone(),
                    reason,
                })
            }
            r => r,
        }
    }
    fn slide(&self) -> Option<SlideReport> {
        self.inner.slide()
    }
}

/// `run` as the contract defines it: `start`, one `advance` per push of the
/// schedule, the release when the problem has one (without pushes: at once,
/// the plate thrown with `initial.velocity` and ω), `finish`. The one push
/// loop of the engines.
pub fn run_via_session<E: Engine + ?Sized>(
    engine: &E,
    problem: &Problem,
    dt: f64,
) -> Result<EngineRun, ModelError> {
    problem.check()?;
    let mut session = start(engine, problem, dt)?;
    for push in &problem.pushes {
        session.advance(push)?;
    }
    if let Some(release) = &problem.release {
        session.release(release.max_duration)?;
    }
    session.finish()
}
