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

/// Supports taken through the recurrence side by side.
const W: usize = 4;

/// The recurrence's factors `(2j + 1)/(j + 1)` and `j/(j + 1)`, from a
/// table, so no division sits on its serial chain.
#[inline]
fn fac(j: usize) -> (f64, f64) {
    TAYLOR_FAC.get(j).copied().unwrap_or_else(|| {
        let jf = j as f64;
        ((2.0 * jf + 1.0) / (jf + 1.0), jf / (jf + 1.0))
    })
}

/// Up to [`W`] supports in Legendre's recurrence, side by side so their
/// serial chains overlap (padding lanes carry zeros): per support the
/// moment's `(m₀, m₁)`, `t sc`, `sc²` and `Pⱼ(t) scʲ/√x₀` at the current
/// and the previous `j`.
struct Lanes {
    m0: [f64; W],
    m1: [f64; W],
    ts: [f64; W],
    s2: [f64; W],
    pj: [f64; W],
    prev: [f64; W],
}

impl Lanes {
    /// Supports `i0 ..` (at most [`W`]) of `seg` about `omega` with contact
    /// velocity `(vx, vy)` (m/s); None when one is at rest there.
    #[inline]
    fn new(seg: &SegmentDynamics, (vx, vy): (f64, f64), omega: f64, i0: usize) -> Option<Self> {
        let mut me = Self {
            m0: [0.0; W],
            m1: [0.0; W],
            ts: [0.0; W],
            s2: [0.0; W],
            pj: [0.0; W],
            prev: [0.0; W],
        };
        for l in 0..W.min(seg.f.len() - i0) {
            let i = i0 + l;
            let (rx, ry) = (seg.rx[i], seg.ry[i]);
            let x2 = rx * rx + ry * ry;
            if x2 == 0.0 {
                // The support under the contact: no lever arm, no moment.
                continue;
            }
            let ux = vx - omega * ry;
            let uy = vy + omega * rx;
            let x0 = ux * ux + uy * uy;
            if x0 == 0.0 {
                return None;
            }
            let x1 = 2.0 * (rx * uy - ry * ux);
            let sc = (x2 / x0).sqrt();
            let t = (-x1 / (2.0 * (x0 * x2).sqrt())).clamp(-1.0, 1.0);
            (me.ts[l], me.s2[l]) = (t * sc, sc * sc);
            // Moment −F (r × u)/|u| = (m₀ + m₁ d) / |u|.
            me.m0[l] = -seg.f[i] * (rx * uy - ry * ux);
            me.m1[l] = -seg.f[i] * x2;
            me.pj[l] = 1.0 / x0.sqrt();
        }
        Some(me)
    }

    /// The lanes' term of the coefficient `j = 0`.
    #[inline]
    fn first(&self) -> f64 {
        (0..W).map(|l| self.m0[l] * self.pj[l]).sum::<f64>()
    }

    /// The lanes' term of the coefficient `j ≥ 1`, the recurrence moved on
    /// to it (`j` one more than at the last call).
    #[inline]
    fn next(&mut self, j: usize) -> f64 {
        let (a, b) = fac(j - 1);
        let mut acc = 0.0;
        for l in 0..W {
            let next = a * self.ts[l] * self.pj[l] - b * self.s2[l] * self.prev[l];
            acc += self.m0[l] * next + self.m1[l] * self.pj[l];
            self.prev[l] = self.pj[l];
            self.pj[l] = next;
        }
        acc
    }
}

/// The Taylor coefficients of ω̇ one at a time, the same values as
/// [`SegmentDynamics::omega_dot_taylor`] to the bit, for a caller that stops
/// when its own series has enough terms ([`SegmentDynamics::omega_dot_series`]).
pub(crate) struct OmegaDotSeries {
    lanes: Lanes,
    j: usize,
    k_omega: f64,
    k: f64,
    inv_inertia_contact: f64,
}

impl OmegaDotSeries {
    /// The next coefficient, `g⁽ʲ⁾(ω)/j!` for `j = 0, 1, …`.
    #[inline]
    pub(crate) fn next_coefficient(&mut self) -> f64 {
        let j = self.j;
        self.j += 1;
        // The same operations, in the same order, as `omega_dot_taylor`.
        let mut o = 0.0;
        if j == 0 {
            o += self.lanes.first();
            o += self.k_omega;
        } else {
            o += self.lanes.next(j);
            if j == 1 {
                o += self.k;
            }
        }
        o * self.inv_inertia_contact
    }
}

impl SegmentDynamics {
    /// [`SegmentDynamics::omega_dot_taylor`] one coefficient at a time, for
    /// a segment of at most four supports (one block of the recurrence)
    /// none of which is at rest at `omega`; None otherwise (that function
    /// then serves).
    pub(crate) fn omega_dot_series(&self, omega: f64) -> Option<OmegaDotSeries> {
        if self.f.len() > W {
            return None;
        }
        let v = (self.speed * self.dir.x, self.speed * self.dir.y);
        Some(OmegaDotSeries {
            lanes: Lanes::new(self, v, omega, 0)?,
            j: 0,
            k_omega: self.k * omega,
            k: self.k,
            inv_inertia_contact: self.inv_inertia_contact,
        })
    }

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
        let v = (self.speed * self.dir.x, self.speed * self.dir.y);
        let ns = self.f.len();
        let mut i0 = 0;
        while i0 < ns {
            let Some(mut lanes) = Lanes::new(self, v, omega, i0) else {
                out.fill(f64::NAN);
                return;
            };
            out[0] += lanes.first();
            for (j, o) in out.iter_mut().enumerate().skip(1) {
                *o += lanes.next(j);
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
