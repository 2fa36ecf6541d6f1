//! `[object]`: the outline, the mass and where it sits, and the inertia.

use std::path::Path;

use pushval_model::Vec2;

use super::check::{finite_pos, point};
use crate::geometry::{boundary_distance, contains, polygon_mass_properties, self_intersection};
use crate::raw::RawObject;
use crate::{PolygonProperties, ScenarioError};

/// The object's outline and mass, checked.
pub(super) struct Object {
    /// kg.
    pub(super) mass: f64,
    /// m, object frame, counter-clockwise.
    pub(super) polygon: Vec<Vec2>,
    pub(super) props: PolygonProperties,
    /// The largest distance between two vertices (m): the scale of the
    /// geometric tolerances.
    pub(super) size: f64,
    /// m, object frame.
    pub(super) center_of_mass: Vec2,
}

impl Object {
    /// How far from the polygon a point may lie and still count as on its
    /// boundary or inside it (m).
    pub(super) fn boundary_tol(&self) -> f64 {
        1e-6 * self.size
    }
}

/// The mass, a simple counter-clockwise polygon of nonzero area, and a
/// centre of mass inside it.
pub(super) fn from_raw(raw: &RawObject, file: &Path) -> Result<Object, ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    let mass = finite_pos(file, "object.mass", raw.mass)?;
    if raw.polygon.len() < 3 {
        return Err(err(
            "object.polygon",
            format!("needs at least 3 vertices, got {}", raw.polygon.len()),
        ));
    }
    let polygon = raw
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
    let center_of_mass = match raw.center_of_mass {
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
    Ok(Object {
        mass,
        polygon,
        props,
        size,
        center_of_mass,
    })
}

/// The inertia about the centre of mass (kg m²) and where it came from:
/// `inertia_cm`, `inertia_contact` about the `contact` point (m, object
/// frame), or uniform density over the polygon ("geometry").
pub(super) fn inertia(
    raw: &RawObject,
    object: &Object,
    contact: Vec2,
    file: &Path,
) -> Result<(f64, &'static str), ScenarioError> {
    let err = |key: &str, msg: String| ScenarioError::new(file, key, msg);
    let mass = object.mass;
    let pc_cm = contact - object.center_of_mass;
    Ok(match (raw.inertia_cm, raw.inertia_contact) {
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
            let props = &object.props;
            let pp = if raw.center_of_mass.is_some() {
                // Uniform density: inertia about the given centre of mass by the parallel-axis theorem.
                props.polar_moment
                    + props.area * (props.centroid - object.center_of_mass).norm_squared()
            } else {
                props.polar_moment
            };
            (mass * pp / props.area, "geometry")
        }
    })
}
