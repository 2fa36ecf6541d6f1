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
//! It also holds the one resampler every adapter shares ([`resample`]):
//! engine steps in, samples at the problem's sample times out.
//!
//! What it is not: an engine (it depends on none), or the analytic model
//! (that is `pushval-model`).
#![warn(missing_docs)]

use std::time::Duration;

use pushval_model::{ModelError, Problem, Trajectory};

mod options;
mod resample;

pub use options::{EngineOptions, OptionError, SceneFrame};
/// The friction laws in closed form live in `pushval-laws`; re-exported so
/// that `pushval_engine::FrictionLaw` and its companions keep their paths.
pub use pushval_laws::{coulomb_steady, Coulomb, FrictionLaw, LawClass, LawSteady, COULOMB};
pub use resample::{
    resample, sample, segment_reports, step_tail_omega, tail_mean_omega, trajectory_from_steps,
    StepRecord,
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

/// One engine model: an engine, a scene and a friction law, runnable at any
/// time step. Implemented by each engine crate; used through `dyn Engine`.
pub trait Engine: Send + Sync {
    /// The model name used in scenarios and outputs (`"rapier2d"`, …).
    /// Compiled-in adapters return a `&'static str`; an outside engine
    /// (declared in `pushval.toml`) returns the name it was declared under.
    fn name(&self) -> &str;
    /// One line saying what the model is (scene and friction law).
    fn description(&self) -> &str;
    /// The adapter crate (`pushval-rapier2d`, …), or where an outside
    /// engine was declared (`outside: pushval.toml`).
    fn adapter(&self) -> &str;
    /// The engine crate this adapter depends on, with its version.
    fn engine_crate(&self) -> EngineCrate;
    /// The engine's version as shown to users; defaults to the engine crate's
    /// (an adapter over a native library names the library's version too).
    fn version(&self) -> String {
        let c = self.engine_crate();
        format!("{} {}", c.name, c.version)
    }
    /// The order of accuracy in the time step the model's steady ω and
    /// trajectory show (measured: see the adapter's README).
    fn order(&self) -> f64;
    /// Whether `[run] gate` may name it: it runs the scene the dynamic model
    /// describes closely enough that agreement is a meaningful test (an
    /// engine whose friction law differs can still be gated, and fails).
    fn gateable(&self) -> bool {
        true
    }
    /// `Ok` when this build can run it; otherwise why not, naming the cargo
    /// feature that brings it in (e.g. "build with --features mujoco").
    fn availability(&self) -> Result<(), String> {
        Ok(())
    }
    /// The time step used when neither the scenario nor the ladder sets one (s).
    fn default_dt(&self) -> f64;
    /// The `[engine]` keys this model reads, besides `dt`.
    fn option_keys(&self) -> &'static [&'static str] {
        &[]
    }
    /// Whether the model reads the `[engine]` key `key`: by default, whether
    /// [`Engine::option_keys`] lists it. An outside engine receives the whole
    /// table verbatim and accepts every key.
    fn accepts_option(&self, key: &str) -> bool {
        self.option_keys().contains(&key)
    }
    /// The settings that produce a run at `dt`, as JSON for the outputs
    /// (includes `"engine"`: the version, and `"dt"`).
    fn settings(&self, dt: f64) -> serde_json::Value;
    /// Runs the problem at time step `dt` (s).
    fn run(&self, problem: &Problem, dt: f64) -> Result<EngineRun, ModelError>;
    /// The engine's own friction law in closed form, if it declares one
    /// ([`FrictionLaw`]; [`COULOMB`] for an engine that applies Coulomb
    /// friction at every support). None by default.
    fn law(&self) -> Option<&dyn FrictionLaw> {
        None
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
