//! Reproducible Gaussian measurement noise for the fit's checks, from the
//! control library's seeded generator ([`Rng`]: SplitMix64 and Box–Muller),
//! so a seed gives the same numbers on every platform and every version.

use pushval_model::Sample;

pub use pushval_control::sensor::Rng;

/// `samples` with independent Gaussian noise of standard deviation
/// `sigma_position` (m) on x and y and `sigma_theta` (rad) on θ; t and ω
/// unchanged.
pub fn add_noise(
    samples: &[Sample],
    sigma_position: f64,
    sigma_theta: f64,
    seed: u64,
) -> Vec<Sample> {
    let mut rng = Rng::new(seed);
    samples
        .iter()
        .map(|s| Sample {
            x: s.x + sigma_position * rng.normal(),
            y: s.y + sigma_position * rng.normal(),
            theta: s.theta + sigma_theta * rng.normal(),
            ..*s
        })
        .collect()
}
