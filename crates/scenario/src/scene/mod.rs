//! The validated scene.
//!
//! [`Scenario::from_raw`] checks the parsed file one table at a time, in the
//! order a reader meets the dependencies: the object, the contact on its
//! outline, the inertia (which may be given about the contact), the
//! supports, the schedule and the initial state, the run settings (which
//! count the schedule's samples), the tolerances and the engine options.
//! The first failure is the error.

mod check;
mod contact;
mod engine;
mod object;
mod run;
mod schedule;
mod supports;
mod syntax;
mod tolerance;

use std::path::{Path, PathBuf};

use pushval_model::{
    Body, ContactLimits, Initial, Problem, Push, Release, Support, Switching, Vec2,
};

pub use engine::{EngineTable, MAX_ENGINE_STEPS};
pub use run::{check_sample_count, ANALYTIC_MODELS, DEFAULT_GATE, DEFAULT_MODELS, MAX_SAMPLES};
pub use supports::SupportLoad;
pub use tolerance::{Limit, Loosened, Tolerance, DEFAULT_AUTO_CEILING};

use crate::raw::RawScenario;
use crate::ScenarioError;

/// A validated scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// The scenario's name (not empty).
    pub name: String,
    /// Free text; empty when absent.
    pub description: String,
    /// Where it was read from.
    pub path: PathBuf,
    /// Mass (kg).
    pub mass: f64,
    /// Outline in the file's object frame (m), counter-clockwise.
    pub polygon: Vec<Vec2>,
    /// Polygon area (m²).
    pub area: f64,
    /// Centre of mass in the file's object frame (m).
    pub center_of_mass: Vec2,
    /// Inertia about the centre of mass (kg m²).
    pub inertia_cm: f64,
    /// Where `inertia_cm` came from: "geometry", "inertia_cm" or "inertia_contact".
    pub inertia_source: &'static str,
    /// The supports with their friction coefficients and normal loads.
    pub supports: Vec<SupportLoad>,
    /// How the loads were set: "equal", "statics", "uniform" or "explicit".
    pub load_rule: &'static str,
    /// m/s².
    pub gravity: f64,
    /// Contact point in the file's object frame (m).
    pub contact: Vec2,
    /// What the contact can transmit: its normal cone, the pusher friction
    /// and the largest force (for the assumption checks).
    pub contact_limits: ContactLimits,
    /// The input schedule, in order.
    pub pushes: Vec<Push>,
    /// The state when the first push starts (without pushes: when the slide
    /// starts).
    pub initial: Initial,
    /// `[release]`: the slide to rest after the last push; None: the run
    /// ends with the last push.
    pub release: Option<Release>,
    /// What ω does at a switch.
    pub switching: Switching,
    /// Sample interval (s).
    pub sample_dt: f64,
    /// `[run] models`, in order, without repeats (names are checked against
    /// the engine registry by the command line).
    pub models: Vec<String>,
    /// `[run] gate`: the engines whose agreement with the dynamic model is
    /// asserted (checked like `models`).
    pub gate: Vec<String>,
    /// `[tolerance]`: what is asserted for the gated engines.
    pub tolerance: Tolerance,
    /// `[engine]`: `dt` checked here, the other keys by the engines.
    pub engine: EngineTable,
}

impl Scenario {
    /// Reads and validates a scenario file.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, ScenarioError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|e| ScenarioError::new(path, "file", format!("cannot read: {e}")))?;
        Self::from_toml(&text, path)
    }

    /// Parses and validates scenario text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &Path) -> Result<Self, ScenarioError> {
        let line_of = |span: Option<std::ops::Range<usize>>| {
            span.map(|s| {
                let line = text[..s.start.min(text.len())].lines().count().max(1);
                format!(" (line {line})")
            })
            .unwrap_or_default()
        };
        // Syntax first; then the structure, with serde_path_to_error naming
        // the key (`object.mass`, `push[2].speed`) that failed.
        let de = toml::Deserializer::parse(text).map_err(|e| {
            let msg = e.message().trim().to_string();
            let key = syntax::key_of_toml_error(text, e.span());
            ScenarioError::new(file, key, format!("{msg}{}", line_of(e.span())))
        })?;
        let raw: RawScenario = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let msg = inner.message().trim().to_string();
            let mut key = if path == "." { String::new() } else { path };
            for quote in ["unknown field `", "missing field `"] {
                if let Some(rest) = msg.strip_prefix(quote) {
                    let name = rest.split('`').next().unwrap_or_default();
                    if !key.ends_with(name) {
                        key = if key.is_empty() {
                            name.to_string()
                        } else {
                            format!("{key}.{name}")
                        };
                    }
                }
            }
            if key.is_empty() {
                key = "toml".into();
            }
            ScenarioError::new(file, key, format!("{msg}{}", line_of(inner.span())))
        })?;
        Self::from_raw(raw, file)
    }

    /// Validates a parsed file, one table at a time (see the module docs).
    pub fn from_raw(raw: RawScenario, file: &Path) -> Result<Self, ScenarioError> {
        if raw.name.trim().is_empty() {
            return Err(ScenarioError::new(file, "name", "must not be empty"));
        }
        let object = object::from_raw(&raw.object, file)?;
        let (contact, contact_limits) = contact::from_raw(&raw.contact, &object, file)?;
        let (inertia_cm, inertia_source) = object::inertia(&raw.object, &object, contact, file)?;
        let supports = supports::from_raw(&raw.supports, &object, file)?;
        let release = schedule::release(raw.release, file)?;
        let pushes = schedule::pushes(&raw.push, release.as_ref(), file)?;
        let initial = schedule::initial(raw.initial, &pushes, file)?;
        let slide = release.map_or(0.0, |r| r.max_duration);
        let run = run::from_raw(raw.run, &pushes, slide, file)?;
        let tolerance = tolerance::from_raw(raw.tolerance, file)?;
        let engine = engine::from_raw(raw.engine, file, &pushes)?;
        let sc = Self {
            name: raw.name,
            description: raw.description.unwrap_or_default(),
            path: file.to_path_buf(),
            mass: object.mass,
            polygon: object.polygon,
            area: object.props.area,
            center_of_mass: object.center_of_mass,
            inertia_cm,
            inertia_source,
            supports: supports.list,
            load_rule: supports.load_rule,
            gravity: supports.gravity,
            contact,
            contact_limits,
            pushes,
            initial,
            release,
            switching: run.switching,
            sample_dt: run.sample_dt,
            models: run.models,
            gate: run.gate,
            tolerance,
            engine,
        };
        // The model's own checks, last: whatever the tables above let
        // through that the model refuses is still bad input, named here.
        if let Err(e) = sc.try_body() {
            return Err(ScenarioError::new(
                file,
                "object",
                format!("the scene is not a valid body for the model: {e}"),
            ));
        }
        Ok(sc)
    }

    /// The body in the model frame (origin at the centre of mass).
    pub fn body(&self) -> Body {
        self.try_body()
            .expect("Scenario::from_raw checked that the body is valid")
    }

    /// [`Scenario::body`], or the model's reason to refuse it (for scenarios
    /// changed after loading, e.g. by `pushval fit` or `power`).
    pub fn try_body(&self) -> Result<Body, pushval_model::ModelError> {
        let supports: Vec<Support> = self
            .supports
            .iter()
            .map(|s| Support {
                position: s.position - self.center_of_mass,
                friction: s.mu * s.load,
            })
            .collect();
        Body::new(
            self.mass,
            self.inertia_cm,
            self.contact - self.center_of_mass,
            &supports,
        )
    }

    /// The problem the models run.
    pub fn problem(&self) -> Problem {
        Problem {
            body: self.body(),
            limits: self.contact_limits,
            pushes: self.pushes.clone(),
            initial: self.initial,
            switching: self.switching,
            sample_dt: self.sample_dt,
            release: self.release,
        }
    }

    /// Effective friction coefficient `Σ μ_i N_i / (m g)`.
    pub fn effective_mu(&self) -> f64 {
        self.supports.iter().map(|s| s.mu * s.load).sum::<f64>() / (self.mass * self.gravity)
    }

    /// The Froude number's length `L = |p_c − p_cm|` (m): the lever arm of
    /// the inertial term `m v_c ω (p_c · n_φ)`.
    pub fn froude_length(&self) -> f64 {
        (self.contact - self.center_of_mass).norm()
    }

    /// `Fr = v_c² / (μ g L)` for a pusher speed (m/s).
    pub fn froude(&self, speed: f64) -> f64 {
        speed * speed / (self.effective_mu() * self.gravity * self.froude_length())
    }
}
