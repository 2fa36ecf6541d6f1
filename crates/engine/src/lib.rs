//! The engine plug-in interface of pushval.
//!
//! Every physics engine pushval runs (rapier2d, rapier3d, MuJoCo, …) lives in
//! its own crate and implements [`Engine`] for each of its models (an engine
//! and a friction mode, e.g. `rapier3d_simplified`). The crate exports one
//! function returning its [`ModelEntry`] rows (name and constructor); the
//! command line's registry lists those functions, one line per engine crate.
//! The harness, the time-step ladder, the convergence check, `compare`,
//! `report`, `stress`, the studies and the benches use engines only through
//! this trait, so none of them names an engine.
//!
//! An engine crate has one face: its simulator's typed session
//! ([`DetailedEngine`], [`DetailedSession`]), which finishes into the
//! crate's own record of the run ([`DetailedRun`]); its [`Engine`] session
//! is that same session behind [`Detailed`], and the [`EngineRun`] is the
//! record converted once.
//!
//! It also holds the one resampler every adapter shares ([`resample`]):
//! engine steps in, samples at the problem's sample times out; and the one
//! stepping loop of the plate engines ([`stepping`]).
//!
//! What it is not: an engine (it depends on none), or the analytic model
//! (that is `pushval-model`).
#![warn(missing_docs)]

use std::time::Duration;

use pushval_model::{ModelError, Problem, Trajectory};

mod contact;
mod detailed;
mod options;
mod resample;
mod session;
pub mod slide;
pub mod stepping;

pub use contact::{ContactRecord, LoadRecorder, LOST_SHARE_OF_WEIGHT};
pub use detailed::{
    drive, on_first_push, Detailed, DetailedEngine, DetailedRun, DetailedSession, FirstPush, RunOf,
    Unavailable,
};
pub use options::{EngineOptions, OptionError, SceneFrame};
/// The friction laws in closed form live in `pushval-laws`; re-exported so
/// that `pushval_engine::FrictionLaw` and its companions keep their paths.
pub use pushval_laws::{
    coulomb_steady, Coulomb, FrictionLaw, LawClass, LawSteady, COULOMB, GRAVITY,
};
pub use resample::{
    extend_through_slide, resample, sample, segment_reports, step_tail_omega, tail_mean_omega,
    trajectory_from_steps, StepRecord,
};
pub use session::{
    after_release, no_release, on_thread, rest_speed, rigid_cm_velocity, run_via_session,
    with_pushes, EngineSession, EngineState, ReplaySession, Session, REST_SPEED, REST_STEPS,
};

/// What one engine run produced.
#[derive(Debug, Clone, PartialEq)]
pub struct EngineRun {
    /// The trajectory sampled at [`Problem::sample_times`].
    pub trajectory: Trajectory,
    /// The time step the run used (s).
    pub dt: f64,
    /// Engine steps taken.
    pub steps: usize,
    /// Wall-clock time of the run (set-up, stepping and sampling).
    pub wall_time: Duration,
    /// Engine-specific diagnostics for the outputs (joint drift, tilt, loads,
    /// …); an object, possibly empty. One key is shared: an engine whose
    /// supports carry measured normal loads writes `"loads"`, an array with
    /// each support's load (N, in the problem's support order) averaged over
    /// the last fifth of the run ([`tail_loads`] reads it).
    pub diagnostics: serde_json::Value,
    /// The supports' loads at every sample, the largest rise and the share
    /// of steps with a support out of contact, where the engine measures
    /// loads (None for the 2-D engines and outside engines whose rows carry
    /// no `load_i` columns).
    pub contact: Option<ContactRecord>,
}

/// The measured support loads of a run (N): its diagnostics' `"loads"`
/// array, or None where the engine reports none.
pub fn tail_loads(run: &EngineRun) -> Option<Vec<f64>> {
    run.diagnostics
        .get("loads")?
        .as_array()?
        .iter()
        .map(|v| v.as_f64())
        .collect()
}

/// The crate that provides an engine, as locked in `Cargo.lock`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EngineCrate {
    /// The crates.io name of the engine's Rust crate (e.g. `rapier2d-f64`).
    pub name: &'static str,
    /// Its version as the adapter's `Cargo.toml` requires and `Cargo.lock`
    /// locks it (a test checks the two agree).
    pub version: &'static str,
}

/// Which `[engine]` keys a model reads, besides `dt`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OptionKeys {
    /// Exactly these keys; the command line refuses any other.
    Listed(&'static [&'static str]),
    /// Every key (an outside engine receives the table verbatim).
    Any,
}

/// What a model is, in one value: everything the harness, the listings and
/// the outputs need to know about an engine model besides running it.
///
/// Built once by the model's constructor ([`EngineInfo::new`] and the
/// `with_*` setters) and returned by [`Engine::info`].
#[derive(Debug, Clone, PartialEq)]
pub struct EngineInfo {
    /// The model name used in scenarios and outputs (`"rapier2d"`, …); an
    /// outside engine's is the name it was declared under.
    pub name: String,
    /// One line saying what the model is (scene and friction law).
    pub description: String,
    /// The adapter crate (`pushval-rapier2d`, …), or where an outside engine
    /// was declared (`outside: pushval.toml`).
    pub adapter: String,
    /// The engine crate the adapter depends on, with its version.
    pub engine_crate: EngineCrate,
    /// The engine's version as shown to users: by default the engine crate's
    /// (`rapier2d-f64 0.36.1`); an adapter over a native library names the
    /// library's too.
    pub version: String,
    /// The order of accuracy in the time step the model's steady ω and
    /// trajectory show (measured: see the adapter's README).
    pub order: f64,
    /// The order in the time step its free slide shows when the problem
    /// has a release (measured: see the adapter's README); None: the same as
    /// [`EngineInfo::order`]. A slide's friction is integrated once per step
    /// and its stop read at a step's end, so it may converge more slowly
    /// than the pushes do.
    pub release_order: Option<f64>,
    /// The time step used when neither the scenario nor the ladder sets one (s).
    pub default_dt: f64,
    /// The `[engine]` keys the model reads, besides `dt`.
    pub options: OptionKeys,
    /// Whether `[run] gate` may name it: it runs the scene the dynamic model
    /// describes closely enough that agreement is a meaningful test (an
    /// engine whose friction law differs can still be gated, and fails).
    pub gateable: bool,
    /// `Ok` when this build can run it; otherwise why not, naming the cargo
    /// feature that brings it in (e.g. "build with --features mujoco").
    pub available: Result<(), String>,
}

impl EngineInfo {
    /// A gateable, available model reading no `[engine]` key besides `dt`,
    /// whose version is its engine crate's.
    pub fn new(
        name: impl Into<String>,
        description: impl Into<String>,
        adapter: impl Into<String>,
        engine_crate: EngineCrate,
        order: f64,
        default_dt: f64,
    ) -> Self {
        Self {
            name: name.into(),
            description: description.into(),
            adapter: adapter.into(),
            version: format!("{} {}", engine_crate.name, engine_crate.version),
            engine_crate,
            order,
            release_order: None,
            default_dt,
            options: OptionKeys::Listed(&[]),
            gateable: true,
            available: Ok(()),
        }
    }

    /// The `[engine]` keys the model reads.
    #[must_use]
    pub fn with_options(mut self, options: OptionKeys) -> Self {
        self.options = options;
        self
    }

    /// The version as shown to users.
    #[must_use]
    pub fn with_version(mut self, version: impl Into<String>) -> Self {
        self.version = version.into();
        self
    }

    /// The order its free slide shows ([`EngineInfo::release_order`]).
    #[must_use]
    pub fn with_release_order(mut self, order: f64) -> Self {
        self.release_order = Some(order);
        self
    }

    /// Whether this build can run the model.
    #[must_use]
    pub fn with_availability(mut self, available: Result<(), String>) -> Self {
        self.available = available;
        self
    }

    /// Whether `[run] gate` may name the model.
    #[must_use]
    pub fn with_gateable(mut self, gateable: bool) -> Self {
        self.gateable = gateable;
        self
    }

    /// Whether the model reads the `[engine]` key `key`.
    pub fn accepts_option(&self, key: &str) -> bool {
        match self.options {
            OptionKeys::Listed(keys) => keys.contains(&key),
            OptionKeys::Any => true,
        }
    }
}

/// One engine model: an engine, a scene and a friction law, runnable at any
/// time step. Implemented by each engine crate; used through `dyn Engine`.
///
/// What the model is ([`EngineInfo`]), the settings of a run, its session
/// (the world, pushed one push at a time by the caller), the friction law it
/// declares, and the run, which is its session driven through the schedule
/// ([`run_via_session`], the default) unless the engine cannot keep a world
/// between pushes. The accessors on `dyn Engine` (`name()`, `order()`, …)
/// read [`Engine::info`].
pub trait Engine: Send + Sync {
    /// What the model is (name, version, order, default step, options, …).
    fn info(&self) -> &EngineInfo;
    /// The settings that produce a run at `dt`, as JSON for the outputs
    /// (includes `"engine"`: the version, and `"dt"`).
    fn settings(&self, dt: f64) -> serde_json::Value;
    /// Runs the problem at time step `dt` (s): by default
    /// [`run_via_session`], `start`, one `advance` per push, `finish`. Only
    /// an engine whose session replays (it cannot keep its world between
    /// pushes) runs a schedule otherwise.
    fn run(&self, problem: &Problem, dt: f64) -> Result<EngineRun, ModelError> {
        run_via_session(self, problem, dt)
    }
    /// The engine's session for `problem` at `dt`: an owned, `Send` world
    /// that borrows nothing from the engine. Called through
    /// [`start`](dyn Engine::start), which checks `dt` and hands over the
    /// problem without its schedule: the session's result depends only on
    /// the pushes it is advanced by (an object that starts moving takes the
    /// first push applied, [`on_first_push`]). An engine that cannot keep
    /// its world between pushes returns a [`ReplaySession`].
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError>;
    /// The engine's own friction law in closed form, if it declares one
    /// ([`FrictionLaw`]; [`COULOMB`] for an engine that applies Coulomb
    /// friction at every support). None by default.
    fn law(&self) -> Option<&dyn FrictionLaw> {
        None
    }
}

/// Shorthands for the fields of [`Engine::info`], and the session.
impl dyn Engine + '_ {
    /// Builds the engine's world for `problem` (its schedule is neither
    /// applied nor read) at time step `dt` (s), the only place the step is
    /// given, and hands the loop to the caller: an owned [`Session`], the
    /// engine's own or a [`ReplaySession`] that re-runs the schedule applied
    /// so far at every `advance`.
    pub fn start(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        session::start(self, problem, dt)
    }
    /// [`EngineInfo::name`].
    pub fn name(&self) -> &str {
        &self.info().name
    }
    /// [`EngineInfo::description`].
    pub fn description(&self) -> &str {
        &self.info().description
    }
    /// [`EngineInfo::adapter`].
    pub fn adapter(&self) -> &str {
        &self.info().adapter
    }
    /// [`EngineInfo::engine_crate`].
    pub fn engine_crate(&self) -> EngineCrate {
        self.info().engine_crate
    }
    /// [`EngineInfo::version`].
    pub fn version(&self) -> String {
        self.info().version.clone()
    }
    /// [`EngineInfo::order`].
    pub fn order(&self) -> f64 {
        self.info().order
    }
    /// The order the ladder assumes for `problem`: [`EngineInfo::release_order`]
    /// when the problem has a release and the engine declares one, else
    /// [`EngineInfo::order`].
    pub fn order_for(&self, problem: &Problem) -> f64 {
        let info = self.info();
        match (problem.release, info.release_order) {
            (Some(_), Some(p)) => p,
            _ => info.order,
        }
    }
    /// [`EngineInfo::gateable`].
    pub fn gateable(&self) -> bool {
        self.info().gateable
    }
    /// [`EngineInfo::available`].
    pub fn availability(&self) -> Result<(), String> {
        self.info().available.clone()
    }
    /// [`EngineInfo::default_dt`].
    pub fn default_dt(&self) -> f64 {
        self.info().default_dt
    }
    /// The keys of [`EngineInfo::options`] (none listed for an engine that
    /// accepts every key).
    pub fn option_keys(&self) -> &'static [&'static str] {
        match self.info().options {
            OptionKeys::Listed(keys) => keys,
            OptionKeys::Any => &[],
        }
    }
    /// [`EngineInfo::accepts_option`].
    pub fn accepts_option(&self, key: &str) -> bool {
        self.info().accepts_option(key)
    }
}

/// A constructor of an engine model from the scenario's `[engine]` table.
pub type Build = fn(&EngineOptions) -> Result<Box<dyn Engine>, OptionError>;

/// One row of an engine crate's model table: a name and its constructor.
#[derive(Debug, Clone, Copy)]
pub struct ModelEntry {
    /// The model name (as [`Engine::name`] returns it).
    pub name: &'static str,
    /// Builds the model from the `[engine]` options.
    pub build: Build,
}

impl ModelEntry {
    /// The model with default options (for listings).
    pub fn default_engine(&self) -> Box<dyn Engine> {
        (self.build)(&EngineOptions::default()).expect("default options are valid for every engine")
    }
}

/// Relative steady-ω error with a floor for segments whose ω* is (near) zero:
/// the denominator is at least `1e-3 v_c / L` (v_c in m/s, L in m).
pub fn rel_err(w: f64, reference: f64, speed: f64, length: f64) -> f64 {
    (w - reference).abs() / reference.abs().max(1e-3 * speed / length)
}
