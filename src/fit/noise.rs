//! Reproducible Gaussian measurement noise for the fit's checks: SplitMix64
//! (Steele, Lea & Flood 2014) for uniform numbers and the Box–Muller
//! transform for normal ones. Small and fixed, so a seed gives the same
//! numbers on every platform and every version.

use pushval_model::Sample;

/// A SplitMix64 generator.
#[derive(Debug, Clone)]
pub struct Rng {
    state: u64,
    spare: Option<f64>,
}

impl Rng {
    /// The generator started from `seed` (any value).
    pub fn new(seed: u64) -> Self {
        Self {
            state: seed,
            spare: None,
        }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1): 53 random bits, never 0.
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller, both values used).
    pub fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let r = (-2.0 * self.uniform().ln()).sqrt();
        let (s, c) = (2.0 * std::f64::consts::PI * self.uniform()).sin_cos();
        self.spare = Some(r * s);
        r * c
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_has_unit_variance_and_zero_mean() {
        let mut rng = Rng::new(7);
        let n = 200_000;
        let v: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        let mean = v.iter().sum::<f64>() / n as f64;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        // Standard errors: 1/√n = 0.0022 for the mean, √(2/n) = 0.0032 for the variance.
        assert!(mean.abs() < 0.01, "{mean}");
        assert!((var - 1.0).abs() < 0.015, "{var}");
    }
}
