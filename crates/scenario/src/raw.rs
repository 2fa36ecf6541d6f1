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

/// The whole file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScenario {
    /// `name`: names the scenario in every output.
    pub name: String,
    /// `description`: free text.
    pub description: Option<String>,
    /// `[object]`.
    pub object: RawObject,
    /// `[supports]`.
    pub supports: RawSupports,
    /// `[contact]`.
    pub contact: RawContact,
    /// `[initial]`; absent: all zero.
    pub initial: Option<RawInitial>,
    /// `[[push]]`, in order.
    #[serde(default)]
    pub push: Vec<RawPush>,
    /// `[release]`: the plate slides to rest after the last push; absent:
    /// the run ends with the last push.
    pub release: Option<RawRelease>,
    /// `[run]`; absent: the defaults.
    pub run: Option<RawRun>,
    /// `[tolerance]`; absent: every figure `"auto"`.
    pub tolerance: Option<RawTolerance>,
    /// `[engine]`; absent: each engine's defaults.
    pub engine: Option<RawEngine>,
}

/// `[object]`: the pushed object.
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
    /// The same value at every support.
    One(f64),
    /// One value per support, in the supports' order.
    Each(Vec<f64>),
}

/// `"equal"`, `"statics"`, `"uniform"` or explicit loads in newtons.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum RawLoad {
    /// A rule: `"equal"`, `"statics"` or `"uniform"`.
    Named(String),
    /// One normal load per support (N).
    Explicit(Vec<f64>),
}

/// `[supports]`: where the object rests on the floor.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSupports {
    /// m, object frame
    #[serde(default, deserialize_with = "opt_xys")]
    pub points: Option<Vec<[f64; 2]>>,
    /// m spacing of a uniform-pressure grid, instead of `points`
    pub uniform_grid: Option<f64>,
    /// Friction coefficient of the supports against the floor
    pub mu: PerPoint,
    /// Normal loads; default `"equal"` (`"uniform"` with `uniform_grid`)
    pub load: Option<RawLoad>,
    /// m/s², default 9.81
    pub gravity: Option<f64>,
}

/// `[contact]`: where the pusher touches the object.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawContact {
    /// m, object frame, on the polygon's boundary
    #[serde(deserialize_with = "xy")]
    pub point: [f64; 2],
    /// Pusher–object friction coefficient: flags contact slip
    pub mu: Option<f64>,
    /// N: flags where the pusher would need more
    pub max_force: Option<f64>,
}

/// `[initial]`: the state when the first push starts.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawInitial {
    /// rad, default 0
    pub theta: Option<f64>,
    /// rad/s, default 0
    pub omega: Option<f64>,
    /// m, world position of the centre of mass; default [0, 0]
    #[serde(default, deserialize_with = "opt_xy")]
    pub position: Option<[f64; 2]>,
    /// At rest when the pusher starts (an impulsive start); default false
    pub from_rest: Option<bool>,
    /// m/s, world velocity of the centre of mass; default [0, 0]; only
    /// without `[[push]]` (the slide starts from it)
    #[serde(default, deserialize_with = "opt_xy")]
    pub velocity: Option<[f64; 2]>,
}

/// `[release]`: after the last push (at t = 0 without `[[push]]`) the pusher
/// withdraws and the plate slides on its supports until it stops.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRelease {
    /// s, > 0, default 10: the longest slide; not stopped by then is reported
    pub max_duration: Option<f64>,
}

/// One `[[push]]`: a constant pusher velocity for a while.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPush {
    /// s, > 0
    pub duration: f64,
    /// m/s, >= 0
    pub speed: f64,
    /// rad, direction of the push in the object frame
    pub phi: f64,
}

/// `[run]`: what runs and how it is sampled.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRun {
    /// Model names, in output order
    pub models: Option<Vec<String>>,
    /// The engines asserted against the dynamic model
    pub gate: Option<Vec<String>>,
    /// s, default 0.01
    pub sample_dt: Option<f64>,
    /// `"impulsive"` (default) or `"continuous"`
    pub switching: Option<String>,
}

/// `[tolerance]`: what is asserted between a gated engine and the dynamic model.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTolerance {
    /// Relative error of the steady ω
    pub omega_steady_rel: Option<RawLimit>,
    /// m, largest centre-of-mass position difference
    pub position_max: Option<RawLimit>,
    /// rad, largest angle difference
    pub theta_max: Option<RawLimit>,
    /// [m, rad, relative]: the most an `"auto"` figure may be
    pub auto_ceiling: Option<Vec<f64>>,
    /// Why the file loosens the gate past the default ceiling
    pub reason: Option<String>,
}

/// A tolerance figure as written: a number, or a word (`"auto"`).
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum RawLimit {
    /// The figure itself (in its unit).
    Number(f64),
    /// A word; only `"auto"` is valid.
    Word(String),
}

/// `[engine]`: `dt` for every engine, the other keys for the engines that
/// read them (checked by the engines, through the command line's registry).
pub type RawEngine = toml::Table;
