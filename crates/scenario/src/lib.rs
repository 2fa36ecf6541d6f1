//! Scenario files for pushval: TOML in, a validated scene out.
//!
//! Loading happens in two layers: [`raw`] mirrors the file with
//! `deny_unknown_fields` (so a misspelt key is an error, not a silent default),
//! and [`Scenario::from_raw`] turns it into a validated scene — polygon mass
//! properties, support points and their normal loads, the contact geometry —
//! or into a [`ScenarioError`] that names the file, the key and the value.
//!
//! The file format is documented in the repository README ("Scenario format").
#![warn(missing_docs)]

mod error;
mod geometry;
pub mod raw;
mod scene;

pub use error::ScenarioError;
pub use geometry::{polygon_mass_properties, PolygonProperties};
pub use scene::{
    check_sample_count, EngineTable, Limit, Loosened, Scenario, SupportLoad, Tolerance,
    ANALYTIC_MODELS, DEFAULT_AUTO_CEILING, DEFAULT_GATE, DEFAULT_MODELS, MAX_ENGINE_STEPS,
    MAX_SAMPLES,
};
