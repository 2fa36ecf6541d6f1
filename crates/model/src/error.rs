use thiserror::Error;

/// Why a model input was refused or a run could not be completed.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ModelError {
    /// A physical parameter is outside its domain (named, with its value).
    #[error("{name} must be {requirement}, got {value}")]
    Parameter {
        /// The parameter.
        name: &'static str,
        /// What it must be, e.g. "finite and > 0".
        requirement: &'static str,
        /// The value given.
        value: f64,
    },
    /// The object has no support points.
    #[error("the object needs at least one support point")]
    NoSupports,
    /// The push schedule is empty.
    #[error("the push schedule is empty")]
    EmptySchedule,
    /// The integrator could not keep its error below the tolerance.
    #[error("integration failed at t = {t} s: {reason}")]
    Integration {
        /// Time of the failure (s).
        t: f64,
        /// Why, e.g. a step size underflow.
        reason: String,
    },
    /// The state left the finite numbers (a blow-up).
    #[error("the state became non-finite at t = {t} s (step {step})")]
    NonFinite {
        /// Time (s).
        t: f64,
        /// Accepted steps so far.
        step: usize,
    },
    /// |ω| passed a thousand times the largest value a trajectory of the
    /// segment can reach (its start and its steady states): ω runs away.
    #[error("omega ran away at t = {t} s (step {step}): |{omega:.3e}| rad/s > {limit:.3e} rad/s")]
    Runaway {
        /// Time (s).
        t: f64,
        /// Accepted steps so far.
        step: usize,
        /// ω there (rad/s).
        omega: f64,
        /// The limit |ω| passed (rad/s).
        limit: f64,
    },
    /// The model cannot follow the free slide after the release: a
    /// quasi-static model has no velocity of its own once the pusher lets
    /// go. The run is refused rather than ended at the release.
    #[error("the {model} model is quasi-static and does not slide: it cannot run a problem with a release (the dynamic model slides to rest)")]
    NoSlide {
        /// The model's name.
        model: String,
    },
    /// The engine cannot let go of the plate: its session has no free slide
    /// (or not for this problem). A problem with a release is refused rather
    /// than ended at the release.
    #[error("{engine} cannot release: {reason} (the problem has a [release]; it is refused rather than ended at the release)")]
    NoRelease {
        /// The engine's name (empty until the session's engine fills it in).
        engine: String,
        /// Why it cannot.
        reason: String,
    },
    /// The engine could not be run at all (an outside engine's process
    /// failed to start, exited with an error, timed out or wrote rows that
    /// do not parse): an input error, not a result. The harness stops with
    /// it (exit 2) instead of reading it as a failed run.
    #[error("{0}")]
    Adapter(String),
}

impl ModelError {
    /// `Ok` when `value` is finite and > 0, else a [`ModelError::Parameter`]
    /// naming `name`.
    pub fn require_positive(name: &'static str, value: f64) -> Result<(), ModelError> {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(ModelError::Parameter {
                name,
                requirement: "finite and > 0",
                value,
            })
        }
    }
    /// `Ok` when `value` is finite and ≥ 0, else a [`ModelError::Parameter`]
    /// naming `name`.
    pub fn require_non_negative(name: &'static str, value: f64) -> Result<(), ModelError> {
        if value.is_finite() && value >= 0.0 {
            Ok(())
        } else {
            Err(ModelError::Parameter {
                name,
                requirement: "finite and >= 0",
                value,
            })
        }
    }
}
