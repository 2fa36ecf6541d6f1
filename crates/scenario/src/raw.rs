//! The scenario file as written: one struct per TOML table, unknown keys refused.

use serde::{Deserialize, Deserializer};

/// A point `[x, y]`. serde's `[f64; 2]` reads the first two elements of a
/// longer array and drops the rest silently; this refuses any other length.
struct Xy([f64; 2]);

impl<'de> Deserialize<'de> for Xy {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        match v[..] {
            [x, y] => Ok(Xy([x, y])),
            _ => Err(serde::de::Error::invalid_length(
                v.len(),
                &"2 coordinates [x, y]",
            )),
        }
    }
}

fn xy<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    Xy::deserialize(d).map(|p| p.0)
}

fn opt_xy<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
    Option::<Xy>::deserialize(d).map(|p| p.map(|p| p.0))
}

fn xys<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
    Vec::<Xy>::deserialize(d).map(|v| v.into_iter().map(|p| p.0).collect())
}

fn opt_xys<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<[f64; 2]>>, D::Error> {
    Option::<Vec<Xy>>::deserialize(d).map(|v| v.map(|v| v.into_iter().map(|p| p.0).collect()))
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScenario {
    pub name: String,
    pub description: Option<String>,
    pub object: RawObject,
    pub supports: RawSupports,
    pub contact: RawContact,
    pub initial: Option<RawInitial>,
    #[serde(default)]
    pub push: Vec<RawPush>,
    pub run: Option<RawRun>,
    pub tolerance: Option<RawTolerance>,
    pub engine: Option<RawEngine>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawObject {
    /// kg
    pub mass: f64,
    /// m, object frame, counter-clockwise
    #[serde(deserialize_with = "xys")]
    pub polygon: Vec<[f64; 2]>,
    /// m; default: the polygon's centroid
    #[serde(default, deserialize_with = "opt_xy")]
    pub center_of_mass: Option<[f64; 2]>,
    /// kg m² about the centre of mass; default: uniform density over the polygon
    pub inertia_cm: Option<f64>,
    /// kg m² about the contact point (the seed paper's Table I reading); an
    /// alternative to `inertia_cm`
    pub inertia_contact: Option<f64>,
}

/// One value for every support, or one per support.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum PerPoint {
    One(f64),
    Each(Vec<f64>),
}

/// `"equal"`, `"statics"`, `"uniform"` or explicit loads in newtons.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum RawLoad {
    Named(String),
    Explicit(Vec<f64>),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSupports {
    #[serde(default, deserialize_with = "opt_xys")]
    pub points: Option<Vec<[f64; 2]>>,
    /// m spacing of a uniform-pressure grid, instead of `points`
    pub uniform_grid: Option<f64>,
    pub mu: PerPoint,
    pub load: Option<RawLoad>,
    /// m/s², default 9.81
    pub gravity: Option<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawContact {
    #[serde(deserialize_with = "xy")]
    pub point: [f64; 2],
    pub mu: Option<f64>,
    pub max_force: Option<f64>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawInitial {
    pub theta: Option<f64>,
    pub omega: Option<f64>,
    #[serde(default, deserialize_with = "opt_xy")]
    pub position: Option<[f64; 2]>,
    pub from_rest: Option<bool>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPush {
    pub duration: f64,
    pub speed: f64,
    pub phi: f64,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRun {
    pub models: Option<Vec<String>>,
    pub gate: Option<Vec<String>>,
    pub sample_dt: Option<f64>,
    pub switching: Option<String>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTolerance {
    pub omega_steady_rel: Option<RawLimit>,
    pub position_max: Option<RawLimit>,
    pub theta_max: Option<RawLimit>,
}

/// A tolerance figure as written: a number, or a word (`"auto"`).
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum RawLimit {
    Number(f64),
    Word(String),
}

/// `[engine]`: `dt` for every engine, the other keys for the engines that
/// read them (checked by the engines, through the command line's registry).
pub type RawEngine = toml::Table;
