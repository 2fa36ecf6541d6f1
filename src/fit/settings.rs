//! How a fit weighs and computes ([`Settings`]): the noise levels, the
//! model's tolerance, the finite-difference step and the solver's patience.

/// How a fit weighs and computes. Every field's default is the command
/// line's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Noise level of x and y (m); position residuals are divided by it.
    /// Default 1e-3.
    pub sigma_position: f64,
    /// Noise level of θ (rad); θ residuals are divided by it. Default 1e-3.
    pub sigma_theta: f64,
    /// DOP853 tolerance of the model's trajectory (m, rad). Default 1e-11:
    /// the trajectory's error must stay far below the effect of a
    /// finite-difference step.
    pub tolerance: f64,
    /// Central-difference step relative to each component's scale.
    /// Default 1e-5.
    pub fd_step: f64,
    /// Levenberg–Marquardt's patience: at most `patience × (n + 1)` residual
    /// evaluations. Default 100.
    pub patience: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            sigma_position: 1e-3,
            sigma_theta: 1e-3,
            tolerance: 1e-11,
            fd_step: 1e-5,
            patience: 100,
        }
    }
}
