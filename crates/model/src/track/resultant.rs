//! The resultant friction force of an estimate: magnitude, moment about the
//! centre of mass, and where its line of action meets the object.

use super::TrackModel;
use crate::{cross, Vec2};

/// The resultant of the support friction forces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resultant {
    /// Sum of the support friction forces in the object frame (N).
    pub force: Vec2,
    /// Its magnitude (N).
    pub magnitude: f64,
    /// Moment of the friction forces about the centre of mass (N m).
    pub moment: f64,
    /// Where the line of action (the points `q` with `q × F = M`) enters the
    /// outline when followed in the direction of the force (m, relative to
    /// the centre of mass); None when the line misses the outline or the
    /// force vanishes (pure turning about a support).
    pub point: Option<Vec2>,
}

/// Standard deviations of a [`Resultant`]'s numbers, by linear propagation
/// of the covariance of `[ω, mu_scale, c_x, c_y]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResultantStd {
    /// Of the magnitude (N).
    pub magnitude: f64,
    /// Of the moment (N m).
    pub moment: f64,
    /// Of the point's x and y (m); NaN where the point does not exist nearby.
    pub point: Vec2,
}

impl Resultant {
    /// The resultant at angular velocity `omega` (rad/s) under pusher
    /// velocity `v` (object frame, m/s) and parameters `p`.
    pub fn at(model: &TrackModel, v: Vec2, omega: f64, p: &[f64; 4]) -> Self {
        let (force, moment) = model.friction(v, omega, p);
        let magnitude = force.norm();
        let point = if magnitude > 1e-12 * (p[0].abs() + 1.0) {
            entry_point(model.polygon(), force, moment)
        } else {
            None
        };
        Self {
            force,
            magnitude,
            moment,
            point,
        }
    }

    /// The resultant and its std from the covariance `cov` of
    /// `[ω, mu_scale, c_x, c_y]` (central differences, steps 1e-6 of each
    /// quantity's scale).
    pub fn with_std(
        model: &TrackModel,
        v: Vec2,
        omega: f64,
        p: &[f64; 4],
        cov: &[[f64; 4]; 4],
    ) -> (Self, ResultantStd) {
        let centre = Self::at(model, v, omega, p);
        let scales = [
            v.norm() / model.size() + omega.abs() + 1e-3,
            1.0,
            model.size(),
            model.size(),
        ];
        let mut jac = [[0.0; 4]; 4];
        for k in 0..4 {
            let h = 1e-6 * scales[k];
            let eval = |d: f64| {
                let mut w = omega;
                let mut q = *p;
                if k == 0 {
                    w += d;
                } else {
                    q[k - 1] += d;
                }
                let r = Self::at(model, v, w, &q);
                let pt = r.point.unwrap_or(Vec2::new(f64::NAN, f64::NAN));
                [r.magnitude, r.moment, pt.x, pt.y]
            };
            let (a, b) = (eval(h), eval(-h));
            for o in 0..4 {
                jac[o][k] = (a[o] - b[o]) / (2.0 * h);
            }
        }
        let var = |o: usize| {
            let mut s = 0.0;
            for a in 0..4 {
                for b in 0..4 {
                    s += jac[o][a] * cov[a][b] * jac[o][b];
                }
            }
            s.max(0.0).sqrt()
        };
        (
            centre,
            ResultantStd {
                magnitude: var(0),
                moment: var(1),
                point: Vec2::new(var(2), var(3)),
            },
        )
    }
}

/// The first crossing of the line `{q : q × F = M}`, followed along `F`,
/// with the outline `polygon` (any simple polygon).
fn entry_point(polygon: &[Vec2], force: Vec2, moment: f64) -> Option<Vec2> {
    let f2 = force.norm_squared();
    // The point of the line nearest the centre of mass: q0 × F = M.
    let q0 = Vec2::new(force.y, -force.x) * (moment / f2);
    let d = force / f2.sqrt();
    let n = polygon.len();
    let mut best: Option<f64> = None;
    for i in 0..n {
        let a = polygon[i];
        let e = polygon[(i + 1) % n] - a;
        let den = cross(&d, &e);
        if den.abs() < 1e-15 * e.norm() {
            continue;
        }
        // q0 + s d = a + τ e  ⇒  s = (a − q0) × e / (d × e), τ = (a − q0) × d / (d × e).
        let w = a - q0;
        let s = cross(&w, &e) / den;
        let tau = cross(&w, &d) / den;
        if (-1e-12..=1.0 + 1e-12).contains(&tau) && best.is_none_or(|b| s < b) {
            best = Some(s);
        }
    }
    best.map(|s| q0 + d * s)
}
