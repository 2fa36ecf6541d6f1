//! What can go wrong in planning and in the loop, typed.

use pushval_model::ModelError;

/// An error of the control library. Each names the quantity at fault, not a
/// command-line flag: a caller words it for its own users.
#[derive(Debug, thiserror::Error)]
pub enum ControlError {
    /// A setting outside its domain (named, with what it must be).
    #[error("{name} must be {requirement}, got {value}")]
    Setting {
        /// The setting, e.g. "speed (m/s)".
        name: &'static str,
        /// What it must be.
        requirement: String,
        /// The value given.
        value: f64,
    },
    /// A goal outside what a plan can be asked for (too far, too long, too
    /// much turn): refused before any work.
    #[error("the goal is out of range: {0}")]
    GoalOutOfRange(String),
    /// The predictor failed (a model error) on every starting guess.
    #[error("the predictor failed on every starting guess: {0}")]
    PredictorFailed(String),
    /// The predictor's model failed.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The online estimator refused a reading or diverged.
    #[error("the friction estimator: {0}")]
    Estimator(#[from] pushval_model::track::TrackError),
    /// The plant (the engine session) failed while the loop drove it.
    #[error("the plant failed at t = {t:.4} s: {source}")]
    Plant {
        /// Loop time when it failed (s).
        t: f64,
        /// The engine's error.
        source: ModelError,
    },
}

impl ControlError {
    /// Whether the error is the caller's input (a setting or a goal out of
    /// range) rather than a failure of a model or an engine.
    pub fn is_input(&self) -> bool {
        matches!(
            self,
            ControlError::Setting { .. } | ControlError::GoalOutOfRange(_)
        )
    }
}
