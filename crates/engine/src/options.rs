//! The scenario's `[engine]` table, as the engines read it.

use std::collections::BTreeMap;

/// The `[engine]` table of a scenario as the engines read it: the time step
/// every engine reads, the other keys by name, for the engines that read
/// them, and the scene the table belongs to. The scenario loader checks `dt`
/// and keeps the table as read (`pushval_scenario::EngineTable`, which knows
/// no engine); [`EngineOptions::from_table`] makes the options of it; each
/// engine checks the keys it reads ([`crate::Engine::option_keys`]) and the
/// command line refuses keys no engine reads.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EngineOptions {
    /// `[engine] dt` (s), kept exactly when set.
    pub dt: Option<f64>,
    /// The other keys with their values.
    pub values: BTreeMap<String, serde_json::Value>,
    /// What the scenario file says about the scene beyond the
    /// [`pushval_model::Problem`] (its frame, outline, gravity and loads), for
    /// adapters that hand the scene to another program; None when the
    /// options were not read from a scenario.
    pub scene: Option<SceneFrame>,
}

/// The scenario's own description of the scene, which the
/// [`pushval_model::Problem`] (centre-of-mass frame, friction magnitudes
/// `μ_i N_i` only) does not keep.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneFrame {
    /// Centre of mass in the file's object frame (m).
    pub center_of_mass: [f64; 2],
    /// The outline in the file's object frame (m), counter-clockwise.
    pub polygon: Vec<[f64; 2]>,
    /// Gravity (m/s²).
    pub gravity: f64,
    /// Normal load of each support as the scenario resolved it (N), in the
    /// order of the problem's supports.
    pub normal_forces: Vec<f64>,
}

/// A bad `[engine]` value: the key (without the `engine.` prefix) and what
/// is wrong with it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OptionError {
    /// The key, e.g. `precision`.
    pub key: String,
    /// What is wrong, e.g. `unknown value "f16"; expected "f64" or "f32"`.
    pub problem: String,
}

impl std::fmt::Display for OptionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "engine.{}: {}", self.key, self.problem)
    }
}

impl std::error::Error for OptionError {}

impl EngineOptions {
    /// The options of a scenario's `[engine]` table: `dt` as the scenario
    /// loader checked it, the other keys verbatim, and the scene they belong
    /// to (None: not read from a scenario).
    pub fn from_table(
        dt: Option<f64>,
        values: BTreeMap<String, serde_json::Value>,
        scene: Option<SceneFrame>,
    ) -> Self {
        Self { dt, values, scene }
    }

    fn bad(key: &str, problem: String) -> OptionError {
        OptionError {
            key: key.into(),
            problem,
        }
    }

    /// A string key that must be one of `allowed`; None when absent.
    pub fn choice(
        &self,
        key: &str,
        allowed: &[&'static str],
    ) -> Result<Option<&'static str>, OptionError> {
        let Some(v) = self.values.get(key) else {
            return Ok(None);
        };
        let expected = allowed
            .iter()
            .map(|a| format!("\"{a}\""))
            .collect::<Vec<_>>()
            .join(", ");
        match v.as_str() {
            Some(s) => allowed
                .iter()
                .find(|a| **a == s)
                .copied()
                .map(Some)
                .ok_or_else(|| {
                    Self::bad(
                        key,
                        format!("unknown value \"{s}\"; expected one of {expected}"),
                    )
                }),
            None => Err(Self::bad(
                key,
                format!("must be a string, one of {expected}; got {v}"),
            )),
        }
    }

    /// An integer key that must be ≥ `min`; None when absent.
    pub fn integer(&self, key: &str, min: u64) -> Result<Option<usize>, OptionError> {
        let Some(v) = self.values.get(key) else {
            return Ok(None);
        };
        match v.as_u64() {
            Some(n) if n >= min => Ok(Some(n as usize)),
            _ => Err(Self::bad(
                key,
                format!("must be an integer >= {min}, got {v}"),
            )),
        }
    }

    /// A finite number key that must be ≥ 0; None when absent.
    pub fn non_negative(&self, key: &str) -> Result<Option<f64>, OptionError> {
        let Some(v) = self.values.get(key) else {
            return Ok(None);
        };
        match v.as_f64() {
            Some(x) if x.is_finite() && x >= 0.0 => Ok(Some(x)),
            _ => Err(Self::bad(
                key,
                format!("must be a finite number >= 0, got {v}"),
            )),
        }
    }

    /// A finite number key that must be > 0; None when absent.
    pub fn positive(&self, key: &str) -> Result<Option<f64>, OptionError> {
        let Some(v) = self.values.get(key) else {
            return Ok(None);
        };
        match v.as_f64() {
            Some(x) if x.is_finite() && x > 0.0 => Ok(Some(x)),
            _ => Err(Self::bad(
                key,
                format!("must be a finite number > 0, got {v}"),
            )),
        }
    }
}
