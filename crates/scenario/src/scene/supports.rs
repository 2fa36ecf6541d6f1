//! `[supports]`: where the object rests, the friction there and the normal
//! loads.

use std::path::Path;

use pushval_model::Vec2;

use super::check::{finite_pos, point};
use super::object::Object;
use crate::geometry::{boundary_distance, contains, convex_hull, grid_supports};
use crate::raw::{PerPoint, RawLoad, RawSupports};
use crate::ScenarioError;

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

/// `[supports]` checked.
pub(super) struct Supports {
    /// m/s².
    pub(super) gravity: f64,
    pub(super) list: Vec<SupportLoad>,
    /// How the loads were set: "equal", "statics", "uniform" or "explicit".
    pub(super) load_rule: &'static str,
}

/// The supports of `object`: inside its polygon, with friction, not tipping
/// it over, and loads that carry its weight.
pub(super) fn from_raw(
    raw: &RawSupports,
    object: &Object,
    file: &Path,
) -> Result<Supports, ScenarioError> {
    let gravity = finite_pos(file, "supports.gravity", raw.gravity.unwrap_or(9.81))?;
    let weight = object.mass * gravity;
    if !weight.is_finite() {
        // Each factor is finite; their product is not: the model's forces
        // (μ N, m a) would be infinite and every comparison NaN.
        return Err(ScenarioError::new(
            file,
            "supports.gravity",
            format!(
                "object.mass × supports.gravity = {:e} kg × {gravity:e} m/s² overflows (the weight must be a finite number of newtons)",
                object.mass
            ),
        ));
    }
    let (positions, grid_weights) = positions(raw, object, file)?;
    let mu = friction(&raw.mu, positions.len(), file)?;
    check_tipping(&positions, object, file)?;
    let (loads, load_rule) = loads(
        raw,
        &positions,
        grid_weights,
        object.center_of_mass,
        weight,
        file,
    )?;
    if let Some(i) = loads
        .iter()
        .zip(&mu)
        .position(|(l, m)| !(l * m).is_finite())
    {
        return Err(ScenarioError::new(
            file,
            "supports.mu",
            format!(
                "support {i}: μ × N = {:e} × {:e} N overflows (the friction force must be finite)",
                mu[i], loads[i]
            ),
        ));
    }
    if loads.iter().zip(&mu).all(|(l, m)| l * m == 0.0) {
        return Err(ScenarioError::new(
            file,
            "supports.load",
            "every support carries zero friction",
        ));
    }
    let list = positions
        .iter()
        .zip(&mu)
        .zip(&loads)
        .map(|((p, m), l)| SupportLoad {
            position: *p,
            mu: *m,
            load: *l,
        })
        .collect();
    Ok(Supports {
        gravity,
        list,
        load_rule,
    })
}

/// The support positions (m, object frame): the listed points, each inside
/// the polygon, or a uniform grid over it with each piece's area (m²).
#[allow(clippy::type_complexity)]
fn positions(
    raw: &RawSupports,
    object: &Object,
    file: &Path,
) -> Result<(Vec<Vec2>, Option<Vec<f64>>), ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    let polygon = &object.polygon;
    match (&raw.points, raw.uniform_grid) {
        (Some(_), Some(_)) => Err(err(
            "supports.uniform_grid",
            "give points or uniform_grid, not both".into(),
        )),
        (None, None) => Err(err("supports", "needs points or uniform_grid".into())),
        (Some(pts), None) => {
            if pts.is_empty() {
                return Err(err("supports.points", "is empty".into()));
            }
            let pts = pts
                .iter()
                .enumerate()
                .map(|(i, p)| point(file, &format!("supports.points[{i}]"), *p))
                .collect::<Result<Vec<_>, _>>()?;
            let tol = object.boundary_tol();
            for (i, p) in pts.iter().enumerate() {
                if !contains(polygon, *p) && boundary_distance(polygon, *p).0 > tol {
                    return Err(err(
                        &format!("supports.points[{i}]"),
                        format!("[{}, {}] lies outside the object's polygon", p.x, p.y),
                    ));
                }
            }
            Ok((pts, None))
        }
        (None, Some(h)) => {
            let h = finite_pos(file, "supports.uniform_grid", h)?;
            let cells = object.props.area / (h * h);
            if cells > 2.0e6 {
                return Err(err(
                    "supports.uniform_grid",
                    format!("spacing {h} m gives about {cells:.0} supports; the limit is 2e6"),
                ));
            }
            let g = grid_supports(polygon, h);
            Ok((
                g.iter().map(|p| p.0).collect(),
                Some(g.iter().map(|p| p.1).collect()),
            ))
        }
    }
}

/// One friction coefficient per support: the one given for all, or one
/// each for `ns` supports.
fn friction(raw: &PerPoint, ns: usize, file: &Path) -> Result<Vec<f64>, ScenarioError> {
    match raw {
        PerPoint::One(m) => Ok(vec![finite_pos(file, "supports.mu", *m)?; ns]),
        PerPoint::Each(v) => {
            if v.len() != ns {
                return Err(ScenarioError::new(
                    file,
                    "supports.mu",
                    format!("has {} values for {ns} supports", v.len()),
                ));
            }
            v.iter()
                .enumerate()
                .map(|(i, m)| finite_pos(file, &format!("supports.mu[{i}]"), *m))
                .collect()
        }
    }
}

/// Tipping: the centre of mass must lie over the support polygon.
fn check_tipping(positions: &[Vec2], object: &Object, file: &Path) -> Result<(), ScenarioError> {
    let hull = convex_hull(positions);
    let (cm, size) = (object.center_of_mass, object.size);
    if hull.len() >= 3 {
        let inside = (0..hull.len()).all(|k| {
            let a = hull[k];
            let b = hull[(k + 1) % hull.len()];
            pushval_model::cross(&(b - a), &(cm - a)) >= -1e-9 * size * size
        });
        if !inside {
            return Err(ScenarioError::new(
                file,
                "supports",
                format!(
                    "the centre of mass [{}, {}] lies outside the support polygon: the object would tip",
                    cm.x, cm.y
                ),
            ));
        }
    } else if let [p] = hull.as_slice() {
        // One support point (or all at one place): the object balances only
        // with its centre of mass above it. (Supports on a line are checked
        // with the loads: statics names the problem there.)
        let d = (cm - p).norm();
        if !(d <= 1e-9 * size) {
            return Err(ScenarioError::new(
                file,
                "supports",
                format!(
                    "a single support point cannot carry the object: the centre of mass [{}, {}] is {d:.3e} m off it, the object would tip",
                    cm.x, cm.y
                ),
            ));
        }
    }
    Ok(())
}

/// The normal loads (N) carrying `weight` (N) with the centre of mass at
/// `cm`, and the rule that set them. Default: "uniform" over a grid
/// (`grid_weights`, each support's area), "equal" otherwise.
fn loads(
    raw: &RawSupports,
    positions: &[Vec2],
    grid_weights: Option<Vec<f64>>,
    cm: Vec2,
    weight: f64,
    file: &Path,
) -> Result<(Vec<f64>, &'static str), ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    let ns = positions.len();
    let default_load = if grid_weights.is_some() {
        "uniform"
    } else {
        "equal"
    };
    Ok(
        match raw.load.clone().unwrap_or(RawLoad::Named(default_load.into())) {
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
                    statics_loads(positions, cm, weight).map_err(|m| err("supports.load", m))?,
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
        },
    )
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
