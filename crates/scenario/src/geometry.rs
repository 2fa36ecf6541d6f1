//! Polygon geometry for scenario validation.

use pushval_model::{cross, Vec2};

/// Area, centroid and polar moment of a uniform-density polygon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolygonProperties {
    /// Signed area (m²): positive for counter-clockwise vertices.
    pub area: f64,
    /// Centroid (m).
    pub centroid: Vec2,
    /// Polar second moment of area about the centroid, `∫ |p − c|² dA` (m⁴);
    /// times mass / area it is the inertia about the centre of mass.
    pub polar_moment: f64,
}

/// Mass properties of any simple polygon by the shoelace formulas (Green's
/// theorem over the edges). parry2d offers these for convex polygons only
/// (`MassProperties::from_convex_polygon`); scenario objects may be concave,
/// and the tests check the two against each other on convex shapes.
pub fn polygon_mass_properties(poly: &[Vec2]) -> PolygonProperties {
    // Shift to the first vertex to keep the sums well conditioned.
    let o = poly[0];
    let (mut a2, mut cx, mut cy, mut j) = (0.0, 0.0, 0.0, 0.0);
    for k in 0..poly.len() {
        let p = poly[k] - o;
        let q = poly[(k + 1) % poly.len()] - o;
        let w = cross(&p, &q);
        a2 += w;
        cx += (p.x + q.x) * w;
        cy += (p.y + q.y) * w;
        j += (p.x * p.x + p.x * q.x + q.x * q.x + p.y * p.y + p.y * q.y + q.y * q.y) * w;
    }
    let area = a2 / 2.0;
    let c = Vec2::new(cx, cy) / (3.0 * a2);
    let j_origin = j / 12.0;
    PolygonProperties {
        area,
        centroid: c + o,
        polar_moment: j_origin - area * c.norm_squared(),
    }
}

/// Whether two closed segments `ab` and `cd` share a point.
fn segments_touch(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let o = |p: Vec2, q: Vec2, r: Vec2| cross(&(q - p), &(r - p));
    let on = |p: Vec2, q: Vec2, r: Vec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

/// The first pair of non-adjacent edges that touch, if any (edge `k` runs
/// from vertex `k` to `k + 1`).
pub(crate) fn self_intersection(poly: &[Vec2]) -> Option<(usize, usize)> {
    let n = poly.len();
    for i in 0..n {
        for j in i + 1..n {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            if adjacent {
                continue;
            }
            if segments_touch(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n]) {
                return Some((i, j));
            }
        }
    }
    None
}

/// Distance from `p` to segment `ab` and the parameter of the closest point.
fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> (f64, f64) {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let s = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((a + ab * s - p).norm(), s)
}

/// Distance from `p` to the polygon's boundary, and the nearest edge.
pub(crate) fn boundary_distance(poly: &[Vec2], p: Vec2) -> (f64, usize, f64) {
    let n = poly.len();
    let mut best = (f64::INFINITY, 0, 0.0);
    for k in 0..n {
        let (d, s) = segment_distance(p, poly[k], poly[(k + 1) % n]);
        if d < best.0 {
            best = (d, k, s);
        }
    }
    best
}

/// Whether `p` lies inside the polygon (even–odd rule; parry2d's test).
pub(crate) fn contains(poly: &[Vec2], p: Vec2) -> bool {
    let pts: Vec<_> = poly
        .iter()
        .map(|v| parry2d_f64::math::Vector::new(v.x, v.y))
        .collect();
    parry2d_f64::utils::point_in_poly2d(parry2d_f64::math::Vector::new(p.x, p.y), &pts)
}

/// Convex hull of a point set (counter-clockwise, parry2d).
pub(crate) fn convex_hull(points: &[Vec2]) -> Vec<Vec2> {
    // parry needs two points at least; one point is its own hull.
    if points.len() < 2 {
        return points.to_vec();
    }
    let pts: Vec<_> = points
        .iter()
        .map(|v| parry2d_f64::math::Vector::new(v.x, v.y))
        .collect();
    parry2d_f64::transformation::convex_hull(&pts)
        .into_iter()
        .map(|v| Vec2::new(v.x, v.y))
        .collect()
}

/// Clips a simple polygon to the axis-aligned box `[lo, hi]` (Sutherland–
/// Hodgman). Written here because the clip window is convex and the subject
/// arbitrary, and grid cells share edges with rectangular objects: parry's
/// general polygon intersection is not built for collinear overlaps.
pub(crate) fn clip_to_box(poly: &[Vec2], lo: Vec2, hi: Vec2) -> Vec<Vec2> {
    let mut out: Vec<Vec2> = poly.to_vec();
    // (axis, bound, keep >= bound?)
    for (axis, bound, keep_ge) in [
        (0, lo.x, true),
        (0, hi.x, false),
        (1, lo.y, true),
        (1, hi.y, false),
    ] {
        if out.is_empty() {
            break;
        }
        let input = std::mem::take(&mut out);
        let inside = |p: &Vec2| {
            if keep_ge {
                p[axis] >= bound
            } else {
                p[axis] <= bound
            }
        };
        for k in 0..input.len() {
            let cur = input[k];
            let prev = input[(k + input.len() - 1) % input.len()];
            let (ci, pi) = (inside(&cur), inside(&prev));
            if ci != pi {
                let s = (bound - prev[axis]) / (cur[axis] - prev[axis]);
                out.push(prev + (cur - prev) * s);
            }
            if ci {
                out.push(cur);
            }
        }
    }
    out
}

/// Uniform-pressure supports: the polygon cut into grid cells of side `h`
/// (m); one support per non-empty piece, at the piece's centroid, weighted by
/// its area. The weights sum to the polygon's area and their first moment to
/// its centroid exactly, so the support set's centre of pressure is the centroid.
pub(crate) fn grid_supports(poly: &[Vec2], h: f64) -> Vec<(Vec2, f64)> {
    let (mut lo, mut hi) = (poly[0], poly[0]);
    for p in poly {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let nx = ((hi.x - lo.x) / h - 1e-9).ceil().max(1.0) as usize;
    let ny = ((hi.y - lo.y) / h - 1e-9).ceil().max(1.0) as usize;
    // Centre the grid on the bounding box so symmetric shapes get symmetric grids.
    let off = Vec2::new(
        lo.x - (nx as f64 * h - (hi.x - lo.x)) / 2.0,
        lo.y - (ny as f64 * h - (hi.y - lo.y)) / 2.0,
    );
    let total = polygon_mass_properties(poly).area.abs();
    let mut out = Vec::new();
    for iy in 0..ny {
        for ix in 0..nx {
            let a = off + Vec2::new(ix as f64 * h, iy as f64 * h);
            let piece = clip_to_box(poly, a, a + Vec2::new(h, h));
            if piece.len() < 3 {
                continue;
            }
            let pp = polygon_mass_properties(&piece);
            if pp.area.abs() > 1e-12 * total {
                out.push((pp.centroid, pp.area.abs()));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn v(x: f64, y: f64) -> Vec2 {
        Vec2::new(x, y)
    }

    #[test]
    fn shoelace_agrees_with_parry_on_convex_polygons() {
        // A square offset from the origin and an irregular convex pentagon.
        for poly in [
            vec![v(1.0, 1.0), v(1.5, 1.0), v(1.5, 1.5), v(1.0, 1.5)],
            vec![
                v(0.0, 0.0),
                v(0.4, -0.1),
                v(0.6, 0.3),
                v(0.3, 0.6),
                v(-0.1, 0.35),
            ],
        ] {
            let ours = polygon_mass_properties(&poly);
            let pts: Vec<_> = poly
                .iter()
                .map(|p| parry2d_f64::math::Vector::new(p.x, p.y))
                .collect();
            let mp = parry2d_f64::mass_properties::MassProperties::from_convex_polygon(1.0, &pts);
            assert_relative_eq!(ours.area, mp.mass(), max_relative = 1e-12);
            assert_relative_eq!(ours.centroid.x, mp.local_com.x, max_relative = 1e-12);
            assert_relative_eq!(ours.centroid.y, mp.local_com.y, max_relative = 1e-12);
            assert_relative_eq!(
                ours.polar_moment,
                mp.principal_inertia(),
                max_relative = 1e-10
            );
        }
    }

    #[test]
    fn square_polar_moment_is_closed_form() {
        // ∫|p|² dA over a square of side a about its centre = a⁴/6.
        let a = 0.25;
        let h = a / 2.0;
        let p = polygon_mass_properties(&[v(-h, -h), v(h, -h), v(h, h), v(-h, h)]);
        assert_relative_eq!(p.polar_moment, a.powi(4) / 6.0, max_relative = 1e-12);
    }

    #[test]
    fn grid_weights_sum_to_area_and_centroid_of_a_concave_polygon() {
        let l = vec![
            v(0.0, 0.0),
            v(0.3, 0.0),
            v(0.3, 0.1),
            v(0.1, 0.1),
            v(0.1, 0.4),
            v(0.0, 0.4),
        ];
        let props = polygon_mass_properties(&l);
        let g = grid_supports(&l, 0.037);
        let a: f64 = g.iter().map(|(_, w)| w).sum();
        let c = g.iter().fold(Vec2::zeros(), |acc, (p, w)| acc + p * *w) / a;
        assert_relative_eq!(a, props.area, max_relative = 1e-12);
        assert_relative_eq!(c.x, props.centroid.x, max_relative = 1e-10);
        assert_relative_eq!(c.y, props.centroid.y, max_relative = 1e-10);
    }

    #[test]
    fn bow_tie_is_self_intersecting_and_square_is_not() {
        assert!(self_intersection(&[v(0.0, 0.0), v(1.0, 1.0), v(1.0, 0.0), v(0.0, 1.0)]).is_some());
        assert!(self_intersection(&[v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)]).is_none());
    }
}
