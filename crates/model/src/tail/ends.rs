//! A settling segment's end state in closed form, as series in the
//! distance from the root: what a caller that wants only the state at the
//! segment's end (the predictor, [`crate::DynamicModel::final_state`])
//! needs, at a fraction of the cost of the series in `E` ([`super::Tail`]).
//!
//! With `δ = ω − ω*` and `g(ω* + δ) = Σ_{j≥1} g_j δ^j` (`g_1 = −1/τ`), the
//! flow is `dt = dδ/g = r(δ) dδ/δ` with `r(δ) = δ/g(ω* + δ) = Σ r_n δ^n`,
//! `r_0 = −τ`, the reciprocal of `Σ g_{j+1} δ^j` (`O(N²)`, where the series
//! in `E` needs the linearising map's `O(N³)`). From `δ₀` at the start, with
//! `x = δ/δ₀` (it falls from 1; `r̃_n = r_n δ₀^n` keeps `|x| ≤ 1`):
//!
//! ```text
//! t(x) = −τ ln x + Σ_{n≥1} r̃_n (x^n − 1)/n             (the end: t(x_T) = T, by Newton)
//! ε(x) = ∫ δ dt = δ₀ Σ_{n≥0} r̃_n (x^{n+1} − 1)/(n + 1)  (θ = θ_s + ω* t + ε)
//! ```
//!
//! The contact point moves with `ċ = e^{iθ} V`. With `μ = ω* τ`,
//! `Φ(x) = ω* R(x) + Λ(x)` (`R = Σ_{n≥1} r̃_n x^n/n`, `Λ = δ₀ Σ r̃_n
//! x^{n+1}/(n + 1)`) and `F = e^{iΦ} r̃ = Σ F̃_n x^n`:
//!
//! ```text
//! e^{iθ} = e^{i(θ_s − Φ(1))} x^{−iμ} e^{iΦ(x)}
//! c(T) = c_s + V e^{i(θ_s − Φ(1))} Σ_n F̃_n (x_T^{n − iμ} − 1)/(n − iμ)
//! ```
//!
//! Every series is `δ₀^n` times one of the root's own (`r_n`, `Φ_n`, `F_n`
//! for `δ₀ = 1`), so [`EndSeries`] holds those per push and root and an end
//! costs `O(N)` plus the Newton steps. The series hold where `|δ₀|` is
//! inside their radius (the nearest complex singularity of `1/g`: another
//! root, or a support whose sliding velocity would vanish); [`EndSeries::end`]
//! checks the last terms and `r̃(1)` against `δ₀/g(ω₀)` itself before it
//! answers, as [`super::SettleRule::tail`] does for the series in `E`.

use nalgebra::Complex;

use super::{TailPose, INV, SETTLE_FRACTION};
use crate::{dynamic::SegmentDynamics, Vec2};

type C = Complex<f64>;

/// Terms kept of each series in `δ` (powers `0 … N − 1`).
pub(crate) const N: usize = 24;

/// The series of one segment's dynamics about one stable root, for
/// `δ₀ = 1` (module docs): `r_n`, `Φ_n` and `F_n`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct EndSeries {
    /// ω* (rad/s).
    pub omega: f64,
    /// τ = −1/g'(ω*) (s).
    pub tau: f64,
    /// Terms computed of each series (`n < len`; zero beyond).
    len: usize,
    /// `r_n` (s per (rad/s)^n).
    r: [f64; N],
    /// `Φ_n` (rad per (rad/s)^n; `Φ_0 = 0`).
    phi: [f64; N],
    /// `F_n` (s per (rad/s)^n).
    f: [C; N],
}

impl EndSeries {
    /// The series of `seg` about its root `omega`, with as many terms as
    /// [`EndSeries::end`] needs from a distance `reach` (rad/s) to the root
    /// at contact speed `speed` (m/s) over `span` (s) at tolerance `tol`
    /// (up to [`N`]; `end` checks again); `None` where `g` has no series
    /// there (a support at rest) or the root does not attract. The terms do
    /// not depend on how many are computed, only the stopping point does.
    pub fn new(
        seg: &SegmentDynamics,
        omega: f64,
        reach: f64,
        speed: f64,
        span: f64,
        tol: f64,
    ) -> Option<Self> {
        let mut g = [0.0; N + 1];
        seg.omega_dot_taylor(omega, &mut g);
        if !(g[1] < 0.0) || g.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let tau = -1.0 / g[1];
        // Three recurrences, one term of each per n, so the processor
        // overlaps their serial chains; each sum in four partial sums over
        // arrays padded with zeros (a chunk of four may run past the first
        // term), the terms read backwards also kept in reverse (`rr[N − k]
        // = r_k`, the same for G) so both factors run forwards in memory:
        //   r Σ g_{j+1} δ^j = 1:  r_0 = −τ, r_n = τ Σ_{j=1..n} g_{j+1} r_{n−j};
        //   G = e^{iΦ}:           G_0 = 1,  m G_m = i Σ_{k=1..m} k Φ_k G_{m−k},
        //                         with n Φ_n = ω* r_n + r_{n−1};
        //   F = G r:              F_n = Σ_{j=0..n} G_j r_{n−j}.
        const P: usize = 4;
        const L: usize = N + 2 * P;
        let mut gp = [0.0; L];
        gp[..N + 1].copy_from_slice(&g);
        let mut r = [0.0; L];
        let mut kphi = [0.0; L];
        let (mut gre, mut gim) = ([0.0; L], [0.0; L]);
        r[P] = -tau;
        gre[P] = 1.0;
        const R: usize = N + 2 * P;
        let (mut rr, mut grr, mut gir) = ([0.0; R], [0.0; R], [0.0; R]);
        rr[N] = -tau;
        grr[N] = 1.0;
        let mut phi = [0.0; N];
        let mut f = [C::new(0.0, 0.0); N];
        f[0] = C::new(-tau, 0.0);
        let budget = budget(reach, omega, tau, speed, span, tol);
        let mut len = N;
        // reach^n, for the stopping test.
        let mut reach_n = 1.0;
        for n in 1..N {
            let chunks = n.div_ceil(4);
            // r_n: j = 1 + 4c + l against r_{n−j} at P + n − j.
            let mut acc = [0.0; 4];
            for c in 0..chunks {
                for (l, a) in acc.iter_mut().enumerate() {
                    let j = 1 + 4 * c + l;
                    *a += gp[j + 1] * rr[N - n + j];
                }
            }
            r[P + n] = tau * ((acc[0] + acc[1]) + (acc[2] + acc[3]));
            rr[N - n] = r[P + n];
            kphi[P + n] = omega * r[P + n] + r[P + n - 1];
            phi[n] = kphi[P + n] * INV[n];
            // G_n: k = 1 + 4c + l against G_{n−k} (k Φ_k is still zero for
            // k > n, as the padding is).
            let (mut are, mut aim) = ([0.0; 4], [0.0; 4]);
            for c in 0..chunks {
                for l in 0..4 {
                    let k = 1 + 4 * c + l;
                    are[l] += kphi[P + k] * grr[N - n + k];
                    aim[l] += kphi[P + k] * gir[N - n + k];
                }
            }
            let sre = (are[0] + are[1]) + (are[2] + are[3]);
            let sim = (aim[0] + aim[1]) + (aim[2] + aim[3]);
            gre[P + n] = -sim * INV[n];
            gim[P + n] = sre * INV[n];
            (grr[N - n], gir[N - n]) = (gre[P + n], gim[P + n]);
            // F_n: j = 4c + l against r_{n−j}.
            let (mut fre, mut fim) = ([0.0; 4], [0.0; 4]);
            for c in 0..(n + 1).div_ceil(4) {
                for l in 0..4 {
                    let j = 4 * c + l;
                    let rv = rr[N - n + j];
                    fre[l] += gre[P + j] * rv;
                    fim[l] += gim[P + j] * rv;
                }
            }
            f[n] = C::new(
                (fre[0] + fre[1]) + (fre[2] + fre[3]),
                (fim[0] + fim[1]) + (fim[2] + fim[3]),
            );
            let reach_prev = reach_n;
            reach_n *= reach;
            let last = [r[P + n - 1], r[P + n]];
            if stops(n, last, [f[n - 1], f[n]], [reach_prev, reach_n], budget) {
                len = n + 1;
                break;
            }
        }
        let r: [f64; N] = std::array::from_fn(|n| r[P + n]);
        Some(Self {
            omega,
            tau,
            len,
            r,
            phi,
            f,
        })
    }

    /// The state `span` (s) after contact point `c`, angle `theta` and ω =
    /// `w` (`g_w = g(w)`, rad/s²) with contact velocity `vel` (object frame,
    /// m/s), if the series hold there to within [`SETTLE_FRACTION`] of
    /// `tol` (m, rad; relative in ω): else `None`.
    #[allow(clippy::too_many_arguments)]
    pub fn end(
        &self,
        span: f64,
        c: Vec2,
        theta: f64,
        w: f64,
        g_w: f64,
        vel: Vec2,
        tol: f64,
    ) -> Option<TailPose> {
        let (ws, tau) = (self.omega, self.tau);
        let d0 = w - ws;
        if !d0.is_finite() || span < 0.0 {
            return None;
        }
        // The scaled series r̃_n = r_n δ₀^n, F̃_n, Φ̃_n.
        let len = self.len;
        let mut r = [0.0; N];
        let mut f = [C::new(0.0, 0.0); N];
        let mut dn = 1.0;
        let (mut r1, mut phi1) = (0.0, 0.0);
        for n in 0..len {
            r[n] = self.r[n] * dn;
            f[n] = self.f[n] * dn;
            r1 += r[n];
            phi1 += self.phi[n] * dn;
            dn *= d0;
        }
        // What the series leave out, and r̃(1) against δ₀/g(ω₀) (s): the
        // first shows a series still converging, the second one taken
        // beyond its radius.
        let cut = (r[len - 2].abs() + r[len - 1].abs()).max(l1(f[len - 2]) + l1(f[len - 1]));
        let residual = if d0 == 0.0 {
            0.0
        } else {
            (r1 - d0 / g_w).abs()
        };
        if !(cut.max(residual) <= budget(d0.abs(), ws, tau, vel.norm(), span, tol)) {
            return None;
        }
        // u = ln x at the end: t(x) = span by Newton from the linear flow's
        // u = −span/τ (dt/du = r̃(x) < 0 where the series hold).
        let rk: [f64; N] = std::array::from_fn(|n| r[n] * INV[n.max(1)]);
        let big_r1: f64 = rk[1..].iter().sum();
        let mut u = -span / tau;
        let mut x = u.exp();
        for it in 0.. {
            let (mut p1, mut p2) = (0.0, 0.0);
            for n in (1..len).rev() {
                p1 = (p1 + rk[n]) * x;
                p2 = (p2 + r[n]) * x;
            }
            let dt_du = p2 + r[0];
            if !(dt_du < 0.0) || it == 40 {
                return None;
            }
            let du = (-tau * u + p1 - big_r1 - span) / dt_du;
            u -= du;
            x = u.exp();
            // Quadratic convergence: a step this small leaves an error of
            // the order of its square (two to three steps from the linear
            // flow's u on the short horizon).
            if du.abs() <= 1e-9 * (1.0 + u.abs()) {
                break;
            }
        }
        // ε = δ₀ Σ r̃_n (x^{n+1} − 1)/(n + 1), and the contact point's sum.
        let mu = ws * tau;
        let y = -mu * u;
        let (sy, cy) = y.sin_cos();
        let ey = C::new(cy, sy);
        // n = 0: F̃_0 (x^{−iμ} − 1)/(−iμ) = F̃_0 u (e^{iy} − 1)/(iy).
        let e1 = if y.abs() < 1e-3 {
            C::new(1.0 - y * y / 6.0, y / 2.0 - y * y * y / 24.0)
        } else {
            C::new(sy / y, (1.0 - cy) / y)
        };
        let mut sum = f[0] * u * e1;
        let mut eps = 0.0;
        let mut xn = x;
        for n in 1..len {
            eps += r[n - 1] * (xn - 1.0) * INV[n];
            let nf = n as f64;
            let z = C::new(nf, mu) / (nf * nf + mu * mu);
            sum += f[n] * ((ey * xn - 1.0) * z);
            xn *= x;
        }
        eps += r[len - 1] * (xn - 1.0) * INV[len];
        eps *= d0;
        let (s0, c0) = (theta - phi1).sin_cos();
        let dc = C::new(vel.x, vel.y) * C::new(c0, s0) * sum;
        Some(TailPose {
            c: c + Vec2::new(dc.re, dc.im),
            theta: theta + ws * span + eps,
            omega: ws + d0 * x,
        })
    }

    /// The series cut where [`EndSeries::new`] would have stopped for
    /// `reach`, `speed`, `span` and `tol` (the same test on the same terms),
    /// or `None` if that is beyond the terms computed.
    pub fn cut(&self, reach: f64, speed: f64, span: f64, tol: f64) -> Option<Self> {
        let budget = budget(reach, self.omega, self.tau, speed, span, tol);
        let mut reach_n = 1.0;
        for n in 1..self.len {
            let reach_prev = reach_n;
            reach_n *= reach;
            let last = [self.r[n - 1], self.r[n]];
            let f = [self.f[n - 1], self.f[n]];
            if stops(n, last, f, [reach_prev, reach_n], budget) {
                return Some(Self {
                    len: n + 1,
                    ..*self
                });
            }
        }
        (self.len == N).then_some(*self)
    }
}

/// Whether a series may stop after term `n`: its last two terms of `r` and
/// of `F` at `reach^(n−1)` and `reach^n` are below `budget` (s).
#[inline]
fn stops(n: usize, r: [f64; 2], f: [C; 2], reach: [f64; 2], budget: f64) -> bool {
    n >= 4
        && (r[0].abs() * reach[0] + r[1].abs() * reach[1])
            .max(l1(f[0]) * reach[0] + l1(f[1]) * reach[1])
            < budget
}

/// The error (s) the series in `δ` may leave in `r̃` from a distance `d`
/// (rad/s) to the root `omega` (τ = `tau`, s) at contact speed `speed`
/// (m/s) over `span` (s): [`SETTLE_FRACTION`] of `tol`. An error `e` in
/// `r̃` moves the end by `e` in time, so the angle by `e (|δ| + |ω*|)` and ω
/// by `e |δ|/τ`; the contact point by `v e` and by the angle's error over the
/// span.
fn budget(d: f64, omega: f64, tau: f64, speed: f64, span: f64, tol: f64) -> f64 {
    let allowed = SETTLE_FRACTION * tol;
    let turn = d + omega.abs();
    (allowed / (turn * (speed * span).max(1.0)))
        .min(allowed / speed)
        .min(allowed * (1.0 + omega.abs()) * tau / d)
}

/// `|re| + |im|`, a bound on `|z|` within √2 of it and without `hypot`.
#[inline]
fn l1(z: C) -> f64 {
    z.re.abs() + z.im.abs()
}
