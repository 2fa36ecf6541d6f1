//! The validated scene.

use std::path::{Path, PathBuf};

use pushval_engine::EngineOptions;
use pushval_model::{Body, ContactLimits, Initial, Problem, Push, Support, Switching, Vec2};

use crate::geometry::{
    boundary_distance, contains, convex_hull, grid_supports, polygon_mass_properties,
    self_intersection,
};
use crate::raw::{PerPoint, RawLimit, RawLoad, RawScenario};
use crate::ScenarioError;

/// The analytic models every build has, in output order; the engine models
/// come from the command line's registry.
pub const ANALYTIC_MODELS: [&str; 3] = ["dynamic", "kinematic", "limit_surface"];

/// The models a scenario runs when `[run] models` is absent.
pub const DEFAULT_MODELS: [&str; 4] = ["dynamic", "kinematic", "limit_surface", "rapier2d"];

/// The engines a scenario gates when `[run] gate` is absent.
pub const DEFAULT_GATE: [&str; 1] = ["rapier2d"];

/// One `[tolerance]` figure: a number, or derived from the gated engine's
/// own accuracy (`"auto"`, and the default when the key is absent).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Limit {
    /// The number in the file (its unit is the figure's).
    Value(f64),
    /// A stated multiple of the gated engine's self-convergence estimate,
    /// plus the model's own error (resolved by the harness).
    #[default]
    Auto,
}

impl Limit {
    /// The number, None for `Auto`.
    pub fn value(self) -> Option<f64> {
        match self {
            Limit::Value(v) => Some(v),
            Limit::Auto => None,
        }
    }
}

/// `[tolerance]`: what `validate` asserts between a gated engine and the
/// dynamic model.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tolerance {
    /// Relative error of the steady ω per settled segment.
    pub omega_steady_rel: Limit,
    /// Largest centre-of-mass position difference (m).
    pub position_max: Limit,
    /// Largest angle difference (rad).
    pub theta_max: Limit,
}

/// One support as the scenario defines it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SupportLoad {
    /// Position in the file's object frame (m).
    pub position: Vec2,
    /// Friction coefficient.
    pub mu: f64,
    /// Normal load (N).
    pub load: f64,
}

/// A validated scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    pub name: String,
    pub description: String,
    /// Where it was read from.
    pub path: PathBuf,
    /// Mass (kg).
    pub mass: f64,
    /// Outline in the file's object frame (m), counter-clockwise.
    pub polygon: Vec<Vec2>,
    /// Polygon area (m²).
    pub area: f64,
    /// Centre of mass in the file's object frame (m).
    pub center_of_mass: Vec2,
    /// Inertia about the centre of mass (kg m²).
    pub inertia_cm: f64,
    /// Where `inertia_cm` came from: "geometry", "inertia_cm" or "inertia_contact".
    pub inertia_source: &'static str,
    pub supports: Vec<SupportLoad>,
    /// How the loads were set: "equal", "statics", "uniform" or "explicit".
    pub load_rule: &'static str,
    /// m/s².
    pub gravity: f64,
    /// Contact point in the file's object frame (m).
    pub contact: Vec2,
    pub contact_limits: ContactLimits,
    pub pushes: Vec<Push>,
    pub initial: Initial,
    pub switching: Switching,
    /// s
    pub sample_dt: f64,
    /// `[run] models`, in order, without repeats (names are checked against
    /// the engine registry by the command line).
    pub models: Vec<String>,
    /// `[run] gate`: the engines whose agreement with the dynamic model is
    /// asserted (checked like `models`).
    pub gate: Vec<String>,
    pub tolerance: Tolerance,
    /// `[engine]`: `dt` checked here, the other keys by the engines.
    pub engine: EngineOptions,
}

fn finite_pos(file: &Path, key: &str, v: f64) -> Result<f64, ScenarioError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ScenarioError::new(
            file,
            key,
            format!("must be a finite number > 0, got {v}"),
        ))
    }
}

fn finite(file: &Path, key: &str, v: f64) -> Result<f64, ScenarioError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ScenarioError::new(
            file,
            key,
            format!("must be finite, got {v}"),
        ))
    }
}

fn point(file: &Path, key: &str, p: [f64; 2]) -> Result<Vec2, ScenarioError> {
    if p.iter().all(|c| c.is_finite()) {
        Ok(Vec2::new(p[0], p[1]))
    } else {
        Err(ScenarioError::new(
            file,
            key,
            format!("must be finite, got [{}, {}]", p[0], p[1]),
        ))
    }
}

impl Scenario {
    /// Reads and validates a scenario file.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, ScenarioError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|e| ScenarioError::new(path, "file", format!("cannot read: {e}")))?;
        Self::from_toml(&text, path)
    }

    /// Parses and validates scenario text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &Path) -> Result<Self, ScenarioError> {
        let line_of = |span: Option<std::ops::Range<usize>>| {
            span.map(|s| {
                let line = text[..s.start.min(text.len())].lines().count().max(1);
                format!(" (line {line})")
            })
            .unwrap_or_default()
        };
        // Syntax first; then the structure, with serde_path_to_error naming
        // the key (`object.mass`, `push[2].speed`) that failed.
        let de = toml::Deserializer::parse(text).map_err(|e| {
            let msg = e.message().trim().to_string();
            let key = key_of_toml_error(text, e.span());
            ScenarioError::new(file, key, format!("{msg}{}", line_of(e.span())))
        })?;
        let raw: RawScenario = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let msg = inner.message().trim().to_string();
            let mut key = if path == "." { String::new() } else { path };
            for quote in ["unknown field `", "missing field `"] {
                if let Some(rest) = msg.strip_prefix(quote) {
                    let name = rest.split('`').next().unwrap_or_default();
                    if !key.ends_with(name) {
                        key = if key.is_empty() {
                            name.to_string()
                        } else {
                            format!("{key}.{name}")
                        };
                    }
                }
            }
            if key.is_empty() {
                key = "toml".into();
            }
            ScenarioError::new(file, key, format!("{msg}{}", line_of(inner.span())))
        })?;
        Self::from_raw(raw, file)
    }

    /// Validates a parsed file.
    pub fn from_raw(raw: RawScenario, file: &Path) -> Result<Self, ScenarioError> {
        let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
        if raw.name.trim().is_empty() {
            return Err(err("name", "must not be empty".into()));
        }
        // Object.
        let mass = finite_pos(file, "object.mass", raw.object.mass)?;
        if raw.object.polygon.len() < 3 {
            return Err(err(
                "object.polygon",
                format!(
                    "needs at least 3 vertices, got {}",
                    raw.object.polygon.len()
                ),
            ));
        }
        let polygon = raw
            .object
            .polygon
            .iter()
            .enumerate()
            .map(|(i, p)| point(file, &format!("object.polygon[{i}]"), *p))
            .collect::<Result<Vec<_>, _>>()?;
        let size = polygon
            .iter()
            .flat_map(|p| polygon.iter().map(move |q| (p - q).norm()))
            .fold(0.0f64, f64::max);
        if let Some((i, j)) = self_intersection(&polygon) {
            return Err(err(
                "object.polygon",
                format!("is self-intersecting (edges {i} and {j} cross)"),
            ));
        }
        let props = polygon_mass_properties(&polygon);
        if !(props.area.abs() > 1e-12 * size * size) || size == 0.0 {
            return Err(err(
                "object.polygon",
                format!("is degenerate (area {:e} m²)", props.area),
            ));
        }
        if props.area < 0.0 {
            return Err(err(
                "object.polygon",
                "vertices are clockwise; list them counter-clockwise".into(),
            ));
        }
        let center_of_mass = match raw.object.center_of_mass {
            Some(p) => point(file, "object.center_of_mass", p)?,
            None => props.centroid,
        };
        if !contains(&polygon, center_of_mass)
            && boundary_distance(&polygon, center_of_mass).0 > 1e-9 * size
        {
            return Err(err(
                "object.center_of_mass",
                format!(
                    "[{}, {}] lies outside the polygon",
                    center_of_mass.x, center_of_mass.y
                ),
            ));
        }
        // Contact.
        let contact = point(file, "contact.point", raw.contact.point)?;
        let (dist, edge, s) = boundary_distance(&polygon, contact);
        let tol = 1e-6 * size;
        if dist > tol {
            return Err(err(
                "contact.point",
                format!(
                    "[{}, {}] is not on the polygon's boundary ({dist:.3e} m away)",
                    contact.x, contact.y
                ),
            ));
        }
        let n = polygon.len();
        let inward = |k: usize| {
            let e = polygon[(k + 1) % n] - polygon[k];
            Vec2::new(-e.y, e.x).normalize()
        };
        let elen = (polygon[(edge + 1) % n] - polygon[edge]).norm();
        let normals = if s * elen <= tol {
            (inward((edge + n - 1) % n), inward(edge))
        } else if (1.0 - s) * elen <= tol {
            (inward(edge), inward((edge + 1) % n))
        } else {
            (inward(edge), inward(edge))
        };
        let contact_mu = raw
            .contact
            .mu
            .map(|m| finite_pos(file, "contact.mu", m))
            .transpose()?;
        let max_force = raw
            .contact
            .max_force
            .map(|m| finite_pos(file, "contact.max_force", m))
            .transpose()?;
        // Inertia.
        let pc_cm = contact - center_of_mass;
        let (inertia_cm, inertia_source) = match (raw.object.inertia_cm, raw.object.inertia_contact)
        {
            (Some(_), Some(_)) => {
                return Err(err(
                    "object.inertia_contact",
                    "give inertia_cm or inertia_contact, not both".into(),
                ))
            }
            (Some(i), None) => (finite_pos(file, "object.inertia_cm", i)?, "inertia_cm"),
            (None, Some(i)) => {
                let i = finite_pos(file, "object.inertia_contact", i)?;
                let icm = i - mass * pc_cm.norm_squared();
                if icm <= 0.0 {
                    return Err(err(
                        "object.inertia_contact",
                        format!(
                            "{i} kg m² is at most m |p_c − p_cm|² = {:.6} kg m²: no body has that inertia",
                            mass * pc_cm.norm_squared()
                        ),
                    ));
                }
                (icm, "inertia_contact")
            }
            (None, None) => {
                let pp = if raw.object.center_of_mass.is_some() {
                    // Uniform density: inertia about the given centre of mass by the parallel-axis theorem.
                    props.polar_moment
                        + props.area * (props.centroid - center_of_mass).norm_squared()
                } else {
                    props.polar_moment
                };
                (mass * pp / props.area, "geometry")
            }
        };
        // Supports.
        let gravity = finite_pos(
            file,
            "supports.gravity",
            raw.supports.gravity.unwrap_or(9.81),
        )?;
        let weight = mass * gravity;
        let (positions, grid_weights): (Vec<Vec2>, Option<Vec<f64>>) =
            match (&raw.supports.points, raw.supports.uniform_grid) {
                (Some(_), Some(_)) => {
                    return Err(err(
                        "supports.uniform_grid",
                        "give points or uniform_grid, not both".into(),
                    ))
                }
                (None, None) => {
                    return Err(err("supports", "needs points or uniform_grid".into()));
                }
                (Some(pts), None) => {
                    if pts.is_empty() {
                        return Err(err("supports.points", "is empty".into()));
                    }
                    let pts = pts
                        .iter()
                        .enumerate()
                        .map(|(i, p)| point(file, &format!("supports.points[{i}]"), *p))
                        .collect::<Result<Vec<_>, _>>()?;
                    for (i, p) in pts.iter().enumerate() {
                        if !contains(&polygon, *p) && boundary_distance(&polygon, *p).0 > tol {
                            return Err(err(
                                &format!("supports.points[{i}]"),
                                format!("[{}, {}] lies outside the object's polygon", p.x, p.y),
                            ));
                        }
                    }
                    (pts, None)
                }
                (None, Some(h)) => {
                    let h = finite_pos(file, "supports.uniform_grid", h)?;
                    let cells = props.area / (h * h);
                    if cells > 2.0e6 {
                        return Err(err(
                            "supports.uniform_grid",
                            format!(
                                "spacing {h} m gives about {cells:.0} supports; the limit is 2e6"
                            ),
                        ));
                    }
                    let g = grid_supports(&polygon, h);
                    (
                        g.iter().map(|p| p.0).collect(),
                        Some(g.iter().map(|p| p.1).collect()),
                    )
                }
            };
        let ns = positions.len();
        let mu: Vec<f64> = match &raw.supports.mu {
            PerPoint::One(m) => vec![finite_pos(file, "supports.mu", *m)?; ns],
            PerPoint::Each(v) => {
                if v.len() != ns {
                    return Err(err(
                        "supports.mu",
                        format!("has {} values for {ns} supports", v.len()),
                    ));
                }
                v.iter()
                    .enumerate()
                    .map(|(i, m)| finite_pos(file, &format!("supports.mu[{i}]"), *m))
                    .collect::<Result<_, _>>()?
            }
        };
        // Tipping: the centre of mass must lie over the support polygon.
        let hull = convex_hull(&positions);
        if hull.len() >= 3 {
            let inside = (0..hull.len()).all(|k| {
                let a = hull[k];
                let b = hull[(k + 1) % hull.len()];
                pushval_model::cross(&(b - a), &(center_of_mass - a)) >= -1e-9 * size * size
            });
            if !inside {
                return Err(err(
                    "supports",
                    format!(
                        "the centre of mass [{}, {}] lies outside the support polygon: the object would tip",
                        center_of_mass.x, center_of_mass.y
                    ),
                ));
            }
        }
        let default_load = if grid_weights.is_some() {
            "uniform"
        } else {
            "equal"
        };
        let (loads, load_rule): (Vec<f64>, &'static str) =
            match raw.supports.load.clone().unwrap_or(RawLoad::Named(default_load.into())) {
                RawLoad::Named(s) => match s.as_str() {
                    "equal" => (vec![weight / ns as f64; ns], "equal"),
                    "uniform" => match &grid_weights {
                        Some(w) => {
                            let tot: f64 = w.iter().sum();
                            (w.iter().map(|a| weight * a / tot).collect(), "uniform")
                        }
                        None => {
                            return Err(err(
                                "supports.load",
                                "\"uniform\" needs supports.uniform_grid".into(),
                            ))
                        }
                    },
                    "statics" => (
                        statics_loads(&positions, center_of_mass, weight)
                            .map_err(|m| err("supports.load", m))?,
                        "statics",
                    ),
                    other => {
                        return Err(err(
                            "supports.load",
                            format!(
                                "unknown rule \"{other}\"; expected \"equal\", \"statics\", \"uniform\" or a list of loads in N"
                            ),
                        ))
                    }
                },
                RawLoad::Explicit(v) => {
                    if v.len() != ns {
                        return Err(err(
                            "supports.load",
                            format!("has {} values for {ns} supports", v.len()),
                        ));
                    }
                    for (i, l) in v.iter().enumerate() {
                        if !(l.is_finite() && *l >= 0.0) {
                            return Err(err(
                                &format!("supports.load[{i}]"),
                                format!("must be finite and >= 0, got {l}"),
                            ));
                        }
                    }
                    let sum: f64 = v.iter().sum();
                    if (sum - weight).abs() > 1e-6 * weight {
                        return Err(err(
                            "supports.load",
                            format!("loads sum to {sum} N but m g = {weight} N"),
                        ));
                    }
                    (v, "explicit")
                }
            };
        if loads.iter().zip(&mu).all(|(l, m)| l * m == 0.0) {
            return Err(err(
                "supports.load",
                "every support carries zero friction".into(),
            ));
        }
        let supports: Vec<SupportLoad> = positions
            .iter()
            .zip(&mu)
            .zip(&loads)
            .map(|((p, m), l)| SupportLoad {
                position: *p,
                mu: *m,
                load: *l,
            })
            .collect();
        // Schedule.
        if raw.push.is_empty() {
            return Err(err(
                "push",
                "the schedule is empty: add at least one [[push]]".into(),
            ));
        }
        let pushes = raw
            .push
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let duration = finite_pos(file, &format!("push[{i}].duration"), p.duration)?;
                let speed = finite(file, &format!("push[{i}].speed"), p.speed)?;
                if speed < 0.0 {
                    return Err(err(
                        &format!("push[{i}].speed"),
                        format!("must be >= 0, got {speed}"),
                    ));
                }
                let phi = finite(file, &format!("push[{i}].phi"), p.phi)?;
                Ok(Push {
                    duration,
                    speed,
                    phi,
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        // Initial state.
        let ri = raw.initial.unwrap_or_default();
        let initial = Initial {
            theta: finite(file, "initial.theta", ri.theta.unwrap_or(0.0))?,
            omega: finite(file, "initial.omega", ri.omega.unwrap_or(0.0))?,
            position: point(file, "initial.position", ri.position.unwrap_or([0.0, 0.0]))?,
            from_rest: ri.from_rest.unwrap_or(false),
        };
        // Run.
        let rr = raw.run.unwrap_or_default();
        let sample_dt = finite_pos(file, "run.sample_dt", rr.sample_dt.unwrap_or(0.01))?;
        let total: f64 = pushes.iter().map(|p| p.duration).sum();
        if total / sample_dt > 1e7 {
            return Err(err(
                "run.sample_dt",
                format!("{sample_dt} s over {total} s gives more than 1e7 samples"),
            ));
        }
        let switching = match rr.switching.as_deref().unwrap_or("impulsive") {
            "impulsive" => Switching::Impulsive,
            "continuous" => Switching::Continuous,
            other => {
                return Err(err(
                    "run.switching",
                    format!("unknown value \"{other}\"; expected \"impulsive\" or \"continuous\""),
                ))
            }
        };
        let names = |key: &str, list: Option<Vec<String>>, default: &[&str]| match list {
            None => Ok(default.iter().map(|m| m.to_string()).collect::<Vec<_>>()),
            Some(list) => {
                if list.is_empty() {
                    return Err(err(key, "is empty".into()));
                }
                let mut out: Vec<String> = Vec::new();
                for m in list {
                    if !out.contains(&m) {
                        out.push(m);
                    }
                }
                Ok(out)
            }
        };
        let mut models = names("run.models", rr.models, &DEFAULT_MODELS)?;
        // Absent `gate`: the default engines the scenario runs. A gate named
        // explicitly runs whether `models` lists it or not.
        let gate = match rr.gate {
            None => DEFAULT_GATE
                .iter()
                .map(|g| g.to_string())
                .filter(|g| models.contains(g))
                .collect(),
            list => names("run.gate", list, &DEFAULT_GATE)?,
        };
        for g in &gate {
            if !models.contains(g) {
                models.push(g.clone());
            }
        }
        let rt = raw.tolerance.unwrap_or_default();
        let limit = |key: &str, v: Option<RawLimit>| match v {
            None => Ok(Limit::Auto),
            Some(RawLimit::Number(x)) => finite_pos(file, key, x).map(Limit::Value),
            Some(RawLimit::Word(w)) if w == "auto" => Ok(Limit::Auto),
            Some(RawLimit::Word(w)) => Err(err(
                key,
                format!("must be a finite number > 0 or \"auto\", got \"{w}\""),
            )),
        };
        let tolerance = Tolerance {
            omega_steady_rel: limit("tolerance.omega_steady_rel", rt.omega_steady_rel)?,
            position_max: limit("tolerance.position_max", rt.position_max)?,
            theta_max: limit("tolerance.theta_max", rt.theta_max)?,
        };
        let mut engine = EngineOptions::default();
        for (key, value) in raw.engine.unwrap_or_default() {
            if key == "dt" {
                let dt = value
                    .as_float()
                    .or_else(|| value.as_integer().map(|i| i as f64))
                    .ok_or_else(|| err("engine.dt", format!("must be a number, got {value}")))?;
                engine.dt = Some(finite_pos(file, "engine.dt", dt)?);
            } else {
                let json = serde_json::to_value(&value)
                    .map_err(|e| err(&format!("engine.{key}"), format!("unreadable value: {e}")))?;
                engine.values.insert(key, json);
            }
        }
        Ok(Self {
            name: raw.name,
            description: raw.description.unwrap_or_default(),
            path: file.to_path_buf(),
            mass,
            polygon,
            area: props.area,
            center_of_mass,
            inertia_cm,
            inertia_source,
            supports,
            load_rule,
            gravity,
            contact,
            contact_limits: ContactLimits {
                normals,
                mu: contact_mu,
                max_force,
            },
            pushes,
            initial,
            switching,
            sample_dt,
            models,
            gate,
            tolerance,
            engine,
        })
    }

    /// The body in the model frame (origin at the centre of mass).
    pub fn body(&self) -> Body {
        let supports: Vec<Support> = self
            .supports
            .iter()
            .map(|s| Support {
                position: s.position - self.center_of_mass,
                friction: s.mu * s.load,
            })
            .collect();
        Body::new(
            self.mass,
            self.inertia_cm,
            self.contact - self.center_of_mass,
            &supports,
        )
        .expect("validated scenario gives a valid body")
    }

    /// The problem the models run.
    pub fn problem(&self) -> Problem {
        Problem {
            body: self.body(),
            limits: self.contact_limits,
            pushes: self.pushes.clone(),
            initial: self.initial,
            switching: self.switching,
            sample_dt: self.sample_dt,
        }
    }

    /// Effective friction coefficient `Σ μ_i N_i / (m g)`.
    pub fn effective_mu(&self) -> f64 {
        self.supports.iter().map(|s| s.mu * s.load).sum::<f64>() / (self.mass * self.gravity)
    }

    /// The Froude number's length `L = |p_c − p_cm|` (m): the lever arm of
    /// the inertial term `m v_c ω (p_c · n_φ)`.
    pub fn froude_length(&self) -> f64 {
        (self.contact - self.center_of_mass).norm()
    }

    /// `Fr = v_c² / (μ g L)` for a pusher speed (m/s).
    pub fn froude(&self, speed: f64) -> f64 {
        speed * speed / (self.effective_mu() * self.gravity * self.froude_length())
    }
}

/// Normal loads from statics: `Σ N_i = W`, `Σ N_i p_i = W p_cm`. Exact for up
/// to three supports; for more, the least-norm solution `N = Aᵀ (A Aᵀ)⁻¹ b`
/// (the loads closest to equal that balance), refused when any load would be
/// negative.
fn statics_loads(p: &[Vec2], cm: Vec2, weight: f64) -> Result<Vec<f64>, String> {
    let n = p.len();
    let tip = || {
        format!(
            "statics gives a negative load: the centre of mass [{}, {}] is outside the supports (the object would tip)",
            cm.x, cm.y
        )
    };
    let loads: Vec<f64> = match n {
        1 => {
            if (p[0] - cm).norm() > 1e-9 {
                return Err(tip());
            }
            vec![weight]
        }
        2 => {
            let d = p[1] - p[0];
            let s = (cm - p[0]).dot(&d) / d.norm_squared();
            if (p[0] + d * s - cm).norm() > 1e-9 * d.norm() {
                return Err(
                    "with 2 supports the centre of mass must lie on the line between them".into(),
                );
            }
            vec![weight * (1.0 - s), weight * s]
        }
        _ => {
            let a = nalgebra::DMatrix::from_fn(3, n, |r, c| match r {
                0 => 1.0,
                1 => p[c].x - cm.x,
                _ => p[c].y - cm.y,
            });
            let b = nalgebra::DVector::from_vec(vec![weight, 0.0, 0.0]);
            let aat = &a * a.transpose();
            let y = aat
                .lu()
                .solve(&b)
                .ok_or("statics is singular: the supports are collinear")?;
            let x = a.transpose() * y;
            if (&a * &x - &b).norm() > 1e-9 * weight {
                return Err("statics is singular: the supports are collinear".into());
            }
            x.iter().copied().collect()
        }
    };
    if loads.iter().any(|l| *l < -1e-12 * weight) {
        return Err(if n > 3 {
            "the least-norm statics solution has a negative load; give the loads explicitly".into()
        } else {
            tip()
        });
    }
    Ok(loads.into_iter().map(|l| l.max(0.0)).collect())
}

/// Best-effort dotted key for a TOML syntax error: the key on the line the
/// error points at, prefixed by its table header.
fn key_of_toml_error(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    let Some(span) = span else {
        return "toml".into();
    };
    let start = span.start.min(text.len());
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next().unwrap_or("");
    let header = line.trim_start();
    if header.starts_with('[') && start > line_start + (line.len() - header.len()) {
        // Inside a table header (a duplicate table): that table is the key.
        return header
            .trim_start_matches('[')
            .split(']')
            .next()
            .unwrap_or("")
            .trim()
            .to_string();
    }
    let table = header_before(text, line_start);
    match line.split_once('=') {
        Some((k, _)) if !line.trim_start().starts_with('[') => {
            let k = k.trim();
            match table {
                Some(t) => format!("{t}.{k}"),
                None => k.to_string(),
            }
        }
        _ => table.unwrap_or_else(|| "toml".into()),
    }
}

fn header_before(text: &str, pos: usize) -> Option<String> {
    text[..pos.min(text.len())]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string())
}
