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
//! `F` needs no series of `e^{iΦ}` of its own: `δΦ' = (ω* + δ) r + μ`, so
//! `δG' = i(ω* + δ) F + iμ G` for `G = e^{iΦ}`, which ties `G_n` to `F_n`
//! and `F_{n−1}`, and put into `F_n = Σ G_j r_{n−j}` it leaves one
//! convolution a term (`EndSeries::new`). The sum's weights are kept as
//! `H_n = F_n/(n − iμ)`, so the end is `e^{iy} P(x_T) − P(1)` with
//! `P = Σ_{n≥1} H̃_n x^n` and `y = −μ ln x_T`, a Horner sum.
//!
//! Every series is `δ₀^n` times one of the root's own (`r_n`, `H_n` for
//! `δ₀ = 1`; `Φ(1) = ω* R(1) + Λ(1)` is a sum of `r_n`), so [`EndSeries`]
//! holds those per push and root and an end costs `O(N)` (Horner sums in
//! `δ₀ x`) plus the Newton steps. The series hold where `|δ₀|` is
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
/// `δ₀ = 1` (module docs): `r_n`, and `F_n` as `H_n = F_n/(n − iμ)`, the
/// weight of `x^{n − iμ} − 1` in the contact point's sum (`Φ(1)` is
/// `ω* R(1) + Λ(1)`, sums of `r_n` too).
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
    /// `H_n = F_n/(n − iμ)` for `n ≥ 1` (s per (rad/s)^n; `H_0` unused:
    /// `F_0 = −τ`).
    h: [C; N],
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
        // The Taylor coefficients of g, `gp[j] = g_j`, each made when the
        // recurrence first needs it (term n reads up to g_{n+1}) where the
        // segment has one block of supports; else all at once.
        const P: usize = 4;
        const L: usize = N + 2 * P;
        let mut gp = [0.0; L];
        let mut stream = seg.omega_dot_series(omega);
        let made = match &mut stream {
            Some(s) => {
                gp[0] = s.next_coefficient();
                gp[1] = s.next_coefficient();
                2
            }
            None => {
                seg.omega_dot_taylor(omega, &mut gp[..N + 1]);
                N + 1
            }
        };
        if !(gp[1] < 0.0) || gp[..made].iter().any(|v| !v.is_finite()) {
            return None;
        }
        let tau = -1.0 / gp[1];
        // Two recurrences, one term of each per n, so the processor
        // overlaps their serial chains; each sum in four partial sums over
        // arrays padded with zeros (a chunk of four may run past the last
        // term), the terms of r also kept in reverse (`rr[N − k] = r_k`) so
        // both factors run forwards in memory:
        //   r Σ g_{j+1} δ^j = 1:  r_0 = −τ, r_n = τ Σ_{j=1..n} g_{j+1} r_{n−j};
        //   F = G r, G = e^{iΦ}:  with n Φ_n = ω* r_n + r_{n−1}, δΦ' =
        //                         (ω* + δ) r + μ, so δG' = i(ω* + δ) F + iμ G:
        //                         (n − iμ) G_n = i (ω* F_n + F_{n−1}). Put in
        //                         F_n = Σ_{j=0..n} G_j r_{n−j} (G_0 = 1, r_0 = −τ):
        //                         F_n = ((n − iμ) A_n − iτ F_{n−1})/n with
        //                         A_n = r_n + Σ_{j=1..n−1} G_j r_{n−j}.
        // So `F` costs one convolution of complex by real a term, where the
        // exponential's own recurrence (`m G_m = i Σ k Φ_k G_{m−k}`) and
        // the product `G r` took two; `F_{n−1}`'s weight `τ/n` shrinks, so
        // rounding does not grow along n.
        let mut r = [0.0; L];
        let (mut gre, mut gim) = ([0.0; L], [0.0; L]);
        r[P] = -tau;
        const R: usize = N + 2 * P;
        let mut rr = [0.0; R];
        rr[N] = -tau;
        let mu = omega * tau;
        let mut h = [C::new(0.0, 0.0); N];
        let mut prev = C::new(-tau, 0.0);
        let budget = budget(reach, omega, tau, speed, span, tol);
        let mut len = N;
        // reach^n, for the stopping test.
        let mut reach_n = 1.0;
        for n in 1..N {
            if let Some(s) = &mut stream {
                let next = s.next_coefficient();
                if !next.is_finite() {
                    return None;
                }
                gp[n + 1] = next;
            }
            let chunks = n.div_ceil(4);
            // r_n: j = 1 + 4c + l against r_{n−j} at P + n − j.
            let mut acc = [0.0; 4];
            for c in 0..chunks {
                for (l, a) in acc.iter_mut().enumerate() {
                    let j = 1 + 4 * c + l;
                    *a += gp[j + 1] * rr[N - n + j];
                }
            }
            let rn = tau * ((acc[0] + acc[1]) + (acc[2] + acc[3]));
            // A_n − r_n: j = 1 + 4c + l against r_{n−j} (G_j is still zero
            // for j ≥ n, as the padding is).
            let (mut are, mut aim) = ([0.0; 4], [0.0; 4]);
            for c in 0..chunks {
                for l in 0..4 {
                    let j = 1 + 4 * c + l;
                    let rv = rr[N - n + j];
                    are[l] += gre[P + j] * rv;
                    aim[l] += gim[P + j] * rv;
                }
            }
            let a_re = rn + ((are[0] + are[1]) + (are[2] + are[3]));
            let a_im = (aim[0] + aim[1]) + (aim[2] + aim[3]);
            (r[P + n], rr[N - n]) = (rn, rn);
            let nf = n as f64;
            let fnew = C::new(
                (nf * a_re + mu * a_im + tau * prev.im) * INV[n],
                (nf * a_im - mu * a_re - tau * prev.re) * INV[n],
            );
            // G_n = i (ω* F_n + F_{n−1}) (n + iμ)/(n² + μ²), and
            // H_n = F_n (n + iμ)/(n² + μ²).
            let q = 1.0 / (nf * nf + mu * mu);
            let b = fnew * omega + prev;
            gre[P + n] = -(b.re * mu + b.im * nf) * q;
            gim[P + n] = (b.re * nf - b.im * mu) * q;
            h[n] = fnew * C::new(nf * q, mu * q);
            let reach_prev = reach_n;
            reach_n *= reach;
            let last = [r[P + n - 1], r[P + n]];
            if stops(n, last, [prev, fnew], [reach_prev, reach_n], budget) {
                len = n + 1;
                break;
            }
            prev = fnew;
        }
        let r: [f64; N] = std::array::from_fn(|n| r[P + n]);
        Some(Self {
            omega,
            tau,
            len,
            r,
            h,
        })
    }

    /// `F_n` (s per (rad/s)^n), from `H_n`.
    fn f(&self, n: usize) -> C {
        if n == 0 {
            C::new(-self.tau, 0.0)
        } else {
            self.h[n] * C::new(n as f64, -self.omega * self.tau)
        }
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
        // Every sum is a polynomial in `X = δ₀ x` of the unscaled terms
        // (`r̃_n x^n = r_n X^n`), by Horner: first at `x = 1`.
        let len = self.len;
        let (r, h) = (&self.r, &self.h);
        let mu = ws * tau;
        // r̃(1); R(1) = Σ r̃_n/n; Λ(1) = δ₀ Σ r̃_{n−1}/n (to n = len); the
        // contact point's P(1) = Σ_{n≥1} H̃_n.
        let (mut r1, mut big_r1, mut lam1) = (0.0, 0.0, r[len - 1] * INV[len] * d0);
        let mut p_one = C::new(0.0, 0.0);
        for n in (1..len).rev() {
            r1 = (r1 + r[n]) * d0;
            big_r1 = (big_r1 + r[n] * INV[n]) * d0;
            lam1 = (lam1 + r[n - 1] * INV[n]) * d0;
            p_one = (p_one + h[n]) * d0;
        }
        r1 += r[0];
        // What the series leave out, and r̃(1) against δ₀/g(ω₀) (s): the
        // first shows a series still converging, the second one taken
        // beyond its radius.
        let dl = d0.powi(len as i32 - 2);
        let cut = ((r[len - 2].abs() + r[len - 1].abs() * d0.abs()) * dl.abs())
            .max((l1(self.f(len - 2)) + l1(self.f(len - 1)) * d0.abs()) * dl.abs());
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
        let mut u = -span / tau;
        let mut x = u.exp();
        for it in 0.. {
            let xd = x * d0;
            let (mut p1, mut p2) = (0.0, 0.0);
            for n in (1..len).rev() {
                p1 = (p1 + r[n] * INV[n]) * xd;
                p2 = (p2 + r[n]) * xd;
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
        // ε = Λ(x) − Λ(1), and the contact point's sum
        // F̃_0 (x^{−iμ} − 1)/(−iμ) + Σ_{n≥1} H̃_n (x^{n − iμ} − 1)
        //   = F̃_0 u (e^{iy} − 1)/(iy) + e^{iy} P(x) − P(1).
        let y = -mu * u;
        let (sy, cy) = y.sin_cos();
        let ey = C::new(cy, sy);
        let e1 = if y.abs() < 1e-3 {
            C::new(1.0 - y * y / 6.0, y / 2.0 - y * y * y / 24.0)
        } else {
            C::new(sy / y, (1.0 - cy) / y)
        };
        let xd = x * d0;
        let mut lam = r[len - 1] * INV[len] * xd;
        let mut p_x = C::new(0.0, 0.0);
        for n in (1..len).rev() {
            lam = (lam + r[n - 1] * INV[n]) * xd;
            p_x = (p_x + h[n]) * xd;
        }
        let sum = C::new(-tau, 0.0) * u * e1 + ey * p_x - p_one;
        let eps = lam - lam1;
        // Φ(1) = ω* R(1) + Λ(1).
        let phi1 = ws * big_r1 + lam1;
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
            let f = [self.f(n - 1), self.f(n)];
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Initial, Problem, Push};

    /// `F = e^{iΦ} r` term by term the classical way, from the `r_n` the
    /// series hold: `n Φ_n = ω* r_n + r_{n−1}`, the exponential's own
    /// recurrence `m G_m = i Σ_k k Φ_k G_{m−k}`, the product `Σ G_j
    /// r_{n−j}`. `EndSeries::new` gets `F` by the one-term recurrence
    /// `F_n = ((n − iμ) A_n − iτ F_{n−1})/n` instead; both must agree to
    /// rounding, on pushes whose roots spread from ω* < 0 through 0 to ω* > 0.
    #[test]
    fn contact_series_match_the_exponential_of_the_angle_series() {
        // The seed plate, pushed at the middle of its side: φ = 0 turns it
        // not at all (ω* = 0, μ = 0), ±φ turn it either way.
        let body = Problem::seed_plate(9.81, vec![], Initial::default())
            .unwrap()
            .body;
        let mut roots = Vec::new();
        for k in 0..9 {
            let push = Push {
                duration: 1.0,
                speed: 1.0,
                phi: -0.6 + 0.15 * k as f64,
            };
            let seg = SegmentDynamics::new(&body, &push);
            let ws = seg.monotone_root().expect("a root").omega;
            roots.push(ws);
            // A reach no series converges at: every term is computed.
            let e = EndSeries::new(&seg, ws, 1e3, 1.0, 1.0, 1e-9).expect("a series");
            assert_eq!(e.len, N);
            let (tau, mu) = (e.tau, ws * e.tau);
            let r = e.r;
            let phi: Vec<f64> = (0..N)
                .map(|n| {
                    if n == 0 {
                        0.0
                    } else {
                        (ws * r[n] + r[n - 1]) / n as f64
                    }
                })
                .collect();
            let mut g = vec![C::new(0.0, 0.0); N];
            g[0] = C::new(1.0, 0.0);
            for m in 1..N {
                let s: C = (1..=m).map(|k| g[m - k] * (k as f64 * phi[k])).sum();
                g[m] = C::new(0.0, 1.0) * s / m as f64;
            }
            assert!((r[0] + tau).abs() <= 1e-15 * tau);
            for n in 1..N {
                let f: C = (0..=n).map(|j| g[j] * r[n - j]).sum();
                let h = f / C::new(n as f64, -mu);
                // Terms fall like ρ^{−n}: compare each with its own size
                // and with the first terms' (rounding of the sums).
                let scale = h.norm() + 1e-13 * e.h[1].norm().max(tau);
                assert!(
                    (e.h[n] - h).norm() <= 1e-11 * scale,
                    "push {k}, n = {n}: {} against {h}",
                    e.h[n]
                );
                assert!((e.f(n) - f).norm() <= 1e-11 * (f.norm() + 1e-13 * tau));
            }
        }
        assert!(roots.iter().any(|w| *w < 0.0) && roots.iter().any(|w| *w > 0.0));
        assert!(roots.iter().any(|w| w.abs() < 1e-12));
    }
}
