//! `sin θ, cos θ` for an angle that moves little between calls.
//!
//! An integrator evaluates the pushing ODE's right-hand side at angles that
//! differ by a fraction of a radian from step to step, and every evaluation
//! needs `R(θ)`. A libm `sin_cos` (range reduction and two polynomials, about
//! a hundred instructions) was a quarter of a trajectory's run time. The
//! [`Rotor`] keeps `(cos θ_r, sin θ_r)` for a reference angle `θ_r` and
//! returns `R(θ_r) R(d)` with `d = θ − θ_r` and `(cos d, sin d)` from their
//! Taylor polynomials; it re-anchors (one libm call) once `|d|` exceeds
//! [`Rotor::REACH`].
//!
//! Accuracy: with `|d| ≤ 0.2` the first dropped terms, `d¹²/12!` and
//! `d¹³/13!`, are below 1e-17; the product adds two roundings, so the result
//! is within a few ulp of libm's. No crate offers this (it is a memo of a
//! rotation, not a faster `sin`), hence written here.

/// Cached `(sin θ, cos θ)` about a reference angle (see the module docs).
#[derive(Debug, Clone, Copy)]
pub struct Rotor {
    theta: f64,
    sin: f64,
    cos: f64,
}

impl Default for Rotor {
    fn default() -> Self {
        Self::new()
    }
}

impl Rotor {
    /// Largest `|θ − θ_r|` (rad) served by the polynomials.
    pub const REACH: f64 = 0.2;

    /// A rotor with no reference yet (the first call anchors it).
    pub fn new() -> Self {
        Self {
            theta: f64::NAN,
            sin: 0.0,
            cos: 1.0,
        }
    }

    /// `(sin θ, cos θ)`, like [`f64::sin_cos`].
    #[inline]
    pub fn sin_cos(&mut self, theta: f64) -> (f64, f64) {
        let d = theta - self.theta;
        // Also true for the NaN reference of a new rotor.
        if !(d.abs() <= Self::REACH) {
            let (s, c) = theta.sin_cos();
            *self = Self {
                theta,
                sin: s,
                cos: c,
            };
            return (s, c);
        }
        let (cd, sd) = small_cos_sin(d);
        (self.sin * cd + self.cos * sd, self.cos * cd - self.sin * sd)
    }
}

/// `(cos d, sin d)` by Taylor polynomials, for `|d| ≤` [`Rotor::REACH`].
#[inline]
pub(crate) fn small_cos_sin(d: f64) -> (f64, f64) {
    let d2 = d * d;
    // Horner form; the reciprocal factorials are folded at compile time.
    let c = 1.0
        - d2 * (1.0 / 2.0
            - d2 * (1.0 / 24.0
                - d2 * (1.0 / 720.0 - d2 * (1.0 / 40320.0 - d2 * (1.0 / 3628800.0)))));
    let s = d
        * (1.0
            - d2 * (1.0 / 6.0
                - d2 * (1.0 / 120.0
                    - d2 * (1.0 / 5040.0 - d2 * (1.0 / 362880.0 - d2 * (1.0 / 39916800.0))))));
    (c, s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against libm over a slow sweep (re-anchoring as it goes), a jump back
    /// and forth, and large angles: within 4e-16 everywhere.
    #[test]
    fn rotor_matches_libm() {
        let mut r = Rotor::new();
        let mut worst: f64 = 0.0;
        let mut check = |r: &mut Rotor, th: f64| {
            let (s, c) = r.sin_cos(th);
            let (s0, c0) = th.sin_cos();
            worst = worst.max((s - s0).abs()).max((c - c0).abs());
        };
        for k in 0..20_000 {
            check(&mut r, -3.0 + k as f64 * 3.1e-4);
        }
        for th in [0.0, 1e3, 1e3 + 0.19, 1e3 - 0.19, -1e3, 0.2, -0.2, 5.0] {
            check(&mut r, th);
        }
        assert!(worst < 4e-16, "worst difference {worst:e}");
        // The polynomials alone at the edge of their reach.
        for d in [-Rotor::REACH, -0.1, 1e-9, 0.1, Rotor::REACH] {
            let (c, s) = small_cos_sin(d);
            assert!((c - d.cos()).abs() < 2e-16 && (s - d.sin()).abs() < 2e-16);
        }
    }
}
