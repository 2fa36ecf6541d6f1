//! `[contact]`: the pushed point on the outline, and what the contact can
//! transmit.

use std::path::Path;

use pushval_model::{ContactLimits, Vec2};

use super::check::{finite_pos, point};
use super::object::Object;
use crate::geometry::boundary_distance;
use crate::raw::RawContact;
use crate::ScenarioError;

/// The contact point (m, object frame), on the object's boundary, and its
/// limits: the inward normals of the edges it lies on (both edges' at a
/// vertex), the pusher friction and the largest force.
pub(super) fn from_raw(
    raw: &RawContact,
    object: &Object,
    file: &Path,
) -> Result<(Vec2, ContactLimits), ScenarioError> {
    let polygon = &object.polygon;
    let contact = point(file, "contact.point", raw.point)?;
    let (dist, edge, s) = boundary_distance(polygon, contact);
    let tol = object.boundary_tol();
    if dist > tol {
        return Err(ScenarioError::new(
            file,
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
    let mu = raw
        .mu
        .map(|m| finite_pos(file, "contact.mu", m))
        .transpose()?;
    let max_force = raw
        .max_force
        .map(|m| finite_pos(file, "contact.max_force", m))
        .transpose()?;
    Ok((
        contact,
        ContactLimits {
            normals,
            mu,
            max_force,
        },
    ))
}
