//! The Taylor series of ω̇ about a given ω, from Legendre's recurrence.

use super::SegmentDynamics;

/// `((2j + 1)/(j + 1), j/(j + 1))`, the factors of Legendre's three-term
/// recurrence, for the Taylor coefficients of ω̇.
const TAYLOR_FAC: [(f64, f64); 32] = {
    let mut t = [(0.0, 0.0); 32];
    let mut j = 0;
    while j < 32 {
        let jf = j as f64;
        t[j] = ((2.0 * jf + 1.0) / (jf + 1.0), jf / (jf + 1.0));
        j += 1;
    }
    t
};

impl SegmentDynamics {
    /// Taylor coefficients of ω̇ about `omega`: `out[j] = g⁽ʲ⁾(ω)/j!` for
    /// `j = 0 .. out.len()`, with `g = ω̇` (units rad/s² per (rad/s)ʲ).
    ///
    /// Per support, `|u|²` is a quadratic in the offset `d`:
    /// `x₀ + x₁ d + x₂ d² = x₀ (1 − 2 t z + z²)` with `z = d √(x₂/x₀)` and
    /// `t = −x₁ / (2 √(x₀ x₂))`, `|t| ≤ 1`, and Legendre's generating
    /// function `(1 − 2 t z + z²)^(−1/2) = Σ Pₙ(t) zⁿ` gives the series of
    /// `1/|u|` by the three-term recurrence of `Pₙ`; the numerator
    /// `F (r × u)` is linear in `d`. So each support costs O(`out.len()`).
    ///
    /// A support at rest at `omega` (`|u| = 0`) has no series: the result is
    /// then NaN.
    pub fn omega_dot_taylor(&self, omega: f64, out: &mut [f64]) {
        let n = out.len();
        out.fill(0.0);
        if n == 0 {
            return;
        }
        let (vx, vy) = (self.speed * self.dir.x, self.speed * self.dir.y);
        // The recurrence's factors (2j + 1)/(j + 1) and j/(j + 1), from a
        // table, so no division sits on its serial chain.
        let fac = |j: usize| {
            TAYLOR_FAC.get(j).copied().unwrap_or_else(|| {
                let jf = j as f64;
                ((2.0 * jf + 1.0) / (jf + 1.0), jf / (jf + 1.0))
            })
        };
        // Per support: (m₀, m₁, t sc, sc², Pⱼ(t) scʲ/√x₀ for j = 0). Supports
        // go through the recurrence four at a time, side by side, so their
        // serial chains overlap; padding lanes carry zeros.
        const W: usize = 4;
        let ns = self.f.len();
        let mut i0 = 0;
        while i0 < ns {
            let mut m0 = [0.0; W];
            let mut m1 = [0.0; W];
            let mut ts = [0.0; W];
            let mut s2 = [0.0; W];
            let mut pj = [0.0; W];
            for l in 0..W.min(ns - i0) {
                let i = i0 + l;
                let (rx, ry) = (self.rx[i], self.ry[i]);
                let x2 = rx * rx + ry * ry;
                if x2 == 0.0 {
                    // The support under the contact: no lever arm, no moment.
                    continue;
                }
                let ux = vx - omega * ry;
                let uy = vy + omega * rx;
                let x0 = ux * ux + uy * uy;
                if x0 == 0.0 {
                    out.fill(f64::NAN);
                    return;
                }
                let x1 = 2.0 * (rx * uy - ry * ux);
                let sc = (x2 / x0).sqrt();
                let t = (-x1 / (2.0 * (x0 * x2).sqrt())).clamp(-1.0, 1.0);
                (ts[l], s2[l]) = (t * sc, sc * sc);
                // Moment −F (r × u)/|u| = (m₀ + m₁ d) / |u|.
                m0[l] = -self.f[i] * (rx * uy - ry * ux);
                m1[l] = -self.f[i] * x2;
                pj[l] = 1.0 / x0.sqrt();
            }
            // pj = Pⱼ(t) scʲ / √x₀, the series of 1/|u|.
            let mut prev = [0.0; W];
            out[0] += (0..W).map(|l| m0[l] * pj[l]).sum::<f64>();
            for (j, o) in out.iter_mut().enumerate().skip(1) {
                let (a, b) = fac(j - 1);
                let mut acc = 0.0;
                for l in 0..W {
                    let next = a * ts[l] * pj[l] - b * s2[l] * prev[l];
                    acc += m0[l] * next + m1[l] * pj[l];
                    prev[l] = pj[l];
                    pj[l] = next;
                }
                *o += acc;
            }
            i0 += W;
        }
        out[0] += self.k * omega;
        if n > 1 {
            out[1] += self.k;
        }
        for o in out.iter_mut() {
            *o *= self.inv_inertia_contact;
        }
    }
}
