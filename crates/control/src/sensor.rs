//! What the controller reads of the plant: its state with seeded Gaussian
//! noise and a delay ([`SensorSpec`]), and the generator behind the noise
//! ([`Rng`]).
//!
//! The loop records the plant's true state at the times a reading will ask
//! for and [`Sensor::read`] gives the one recorded `latency` seconds
//! earlier, with independent noise on each component. The noise comes from
//! one seeded stream, six draws per reading whatever the sigmas, so a seed
//! gives the same readings on every machine and with any sigma set to 0.

use std::collections::VecDeque;

use pushval_engine::EngineState;

use crate::ControlError;

/// A SplitMix64 generator (Steele, Lea & Flood 2014) with Box–Muller
/// normals. Written here rather than taken from `rand`: a seed must give the
/// same numbers on every platform and in every version of pushval (the
/// outputs of a seeded loop are compared across runs), which `rand`'s
/// distributions do not promise across its releases.
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

/// The sensor the controller reads the plant through. Every field defaults
/// to 0 (an exact, immediate reading).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct SensorSpec {
    /// Noise (standard deviation) of x and of y (m).
    pub sigma_position: f64,
    /// Noise of θ (rad).
    pub sigma_theta: f64,
    /// Noise of ω (rad/s).
    pub sigma_omega: f64,
    /// Noise of each component of the centre of mass's velocity (m/s).
    pub sigma_velocity: f64,
    /// Delay of a reading (s): rounded to whole plant steps by the loop.
    pub latency: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl SensorSpec {
    /// The keys of [`SensorSpec::parse`], in order.
    pub const KEYS: [&'static str; 6] = [
        "sigma_position",
        "sigma_theta",
        "sigma_omega",
        "sigma_velocity",
        "latency",
        "seed",
    ];

    /// Whether readings are the plant's state, exactly and at once.
    pub fn is_exact(&self) -> bool {
        self.sigma_position == 0.0
            && self.sigma_theta == 0.0
            && self.sigma_omega == 0.0
            && self.sigma_velocity == 0.0
            && self.latency == 0.0
    }

    /// Whether the readings carry noise.
    pub fn is_noisy(&self) -> bool {
        self.sigma_position > 0.0
            || self.sigma_theta > 0.0
            || self.sigma_omega > 0.0
            || self.sigma_velocity > 0.0
    }

    /// `key=value,…` with the keys of [`SensorSpec::KEYS`] (each optional).
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut s = Self::default();
        for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let (key, value) = part
                .split_once('=')
                .ok_or_else(|| format!("`{part}` is not key=value"))?;
            let key = key.trim();
            let value = value.trim();
            if key == "seed" {
                s.seed = value
                    .parse()
                    .map_err(|_| format!("seed: `{value}` is not a whole number >= 0"))?;
                continue;
            }
            let v: f64 = value
                .parse()
                .map_err(|_| format!("{key}: `{value}` is not a number"))?;
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{key}: must be finite and >= 0, got {value}"));
            }
            match key {
                "sigma_position" => s.sigma_position = v,
                "sigma_theta" => s.sigma_theta = v,
                "sigma_omega" => s.sigma_omega = v,
                "sigma_velocity" => s.sigma_velocity = v,
                "latency" => s.latency = v,
                other => {
                    return Err(format!(
                        "`{other}` is not a sensor key (keys: {})",
                        Self::KEYS.join(", ")
                    ))
                }
            }
        }
        Ok(s)
    }

    /// Checks the values (finite, ≥ 0).
    pub fn check(&self) -> Result<(), ControlError> {
        for (name, v) in [
            ("sensor sigma_position (m)", self.sigma_position),
            ("sensor sigma_theta (rad)", self.sigma_theta),
            ("sensor sigma_omega (rad/s)", self.sigma_omega),
            ("sensor sigma_velocity (m/s)", self.sigma_velocity),
            ("sensor latency (s)", self.latency),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ControlError::Setting {
                    name,
                    requirement: "finite and >= 0".into(),
                    value: v,
                });
            }
        }
        Ok(())
    }
}

/// The plant's states as the loop recorded them, read back late and noisy.
#[derive(Debug, Clone)]
pub struct Sensor {
    spec: SensorSpec,
    /// The delay applied (s): whole plant steps.
    latency: f64,
    rng: Rng,
    records: VecDeque<EngineState>,
}

impl Sensor {
    /// A sensor of `spec` whose delay is `latency` (s, the spec's rounded to
    /// the plant's steps).
    pub fn new(spec: SensorSpec, latency: f64) -> Self {
        Self {
            spec,
            latency,
            rng: Rng::new(spec.seed),
            records: VecDeque::new(),
        }
    }

    /// The delay applied (s).
    pub fn latency(&self) -> f64 {
        self.latency
    }

    /// Records the plant's true state (times increasing).
    pub fn record(&mut self, state: EngineState) {
        self.records.push_back(state);
    }

    /// What the controller reads at time `now` (s): the last state recorded
    /// at or before `now − latency` (the first one when none is that old),
    /// with noise. Records older than it are dropped.
    pub fn read(&mut self, now: f64) -> EngineState {
        let due = now - self.latency + 1e-9 * now.abs().max(1e-3);
        while self.records.len() > 1 && self.records[1].t <= due {
            self.records.pop_front();
        }
        let mut st = *self.records.front().expect("a record before a reading");
        let s = &self.spec;
        let z: [f64; 6] = std::array::from_fn(|_| self.rng.normal());
        st.x += s.sigma_position * z[0];
        st.y += s.sigma_position * z[1];
        st.theta += s.sigma_theta * z[2];
        st.omega += s.sigma_omega * z[3];
        st.v_cm[0] += s.sigma_velocity * z[4];
        st.v_cm[1] += s.sigma_velocity * z[5];
        st
    }
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

    fn state(t: f64) -> EngineState {
        EngineState {
            t,
            x: t,
            y: 0.0,
            theta: 0.0,
            omega: 0.0,
            v_cm: [0.0, 0.0],
        }
    }

    #[test]
    fn a_reading_is_the_state_recorded_latency_earlier() {
        let mut s = Sensor::new(SensorSpec::default(), 0.03);
        for k in 0..=10 {
            s.record(state(k as f64 * 0.01));
        }
        // At 0.1 s a 30 ms delay reads the state of 0.07 s; before any state
        // is that old, the first one.
        let r = s.read(0.1);
        assert!((r.t - 0.07).abs() < 1e-12, "{}", r.t);
        let mut early = Sensor::new(SensorSpec::default(), 0.03);
        early.record(state(0.0));
        early.record(state(0.01));
        assert_eq!(early.read(0.01).t, 0.0);
    }

    #[test]
    fn the_same_seed_gives_the_same_readings_and_noise_has_its_sigma() {
        let spec = SensorSpec {
            sigma_position: 2e-3,
            seed: 11,
            ..SensorSpec::default()
        };
        let read = |spec: SensorSpec| {
            let mut s = Sensor::new(spec, 0.0);
            (0..4000)
                .map(|k| {
                    s.record(state(k as f64));
                    let r = s.read(k as f64);
                    r.x - k as f64
                })
                .collect::<Vec<_>>()
        };
        let a = read(spec);
        assert_eq!(a, read(spec));
        assert_ne!(a, read(SensorSpec { seed: 12, ..spec }));
        let sd = (a.iter().map(|e| e * e).sum::<f64>() / a.len() as f64).sqrt();
        // 4000 draws: the sample sd is within 3·σ/√(2n) ≈ 3.4 % of σ.
        assert!((sd / 2e-3 - 1.0).abs() < 0.04, "{sd}");
    }

    #[test]
    fn keys_parse_and_bad_ones_are_named() {
        let s = SensorSpec::parse("sigma_position=0.0005,sigma_theta=0.0035,latency=0.01,seed=3")
            .unwrap();
        assert_eq!(s.sigma_position, 5e-4);
        assert_eq!(s.latency, 0.01);
        assert_eq!(s.seed, 3);
        assert!(SensorSpec::parse("sigma_pos=1")
            .unwrap_err()
            .contains("sigma_pos"));
        assert!(SensorSpec::parse("latency=-1")
            .unwrap_err()
            .contains("latency"));
        assert!(SensorSpec::parse("seed=1.5").unwrap_err().contains("seed"));
    }
}
