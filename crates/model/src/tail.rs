//! Closed-form motion once a segment has settled, to second order in the
//! remaining deviation from the steady state.
//!
//! Over one push segment ω obeys the scalar autonomous ODE `ω̇ = g(ω)`. Near a
//! stable root ω* write `ω = ω* + δ`; then
//! `δ̇ = −δ/τ + q δ² + r δ³ + …` with `q = g''(ω*)/2`, `r = g'''(ω*)/6`. The
//! tail keeps the first two terms and solves that logistic (Bernoulli)
//! equation exactly:
//!
//! ```text
//! E = e^{−s/τ},  a = q τ δ₀,  x = a (1 − E)
//! δ(s) = δ₀ E / (1 − x)
//! ε(s) = ∫₀ˢ δ = −ln(1 − x) / q = τ δ₀ (1 − E) (1 + x/2 + x²/3 + …)
//! ```
//!
//! so `θ = θ_s + ω* s + ε(s)`. The contact point moves with `R(θ) v`; with
//! complex numbers, `e^{iθ} = e^{i(θ_s + ω* s)} (1 + iε − ε²/2 + O(ε³))`, and
//! to second order `iε − ε²/2 = iτδ₀(1 − E) + (τδ₀)²/2 (iq − 1)(1 − E)²`. The
//! integrals of `e^{iω* u}`, `e^{iω* u}(1 − E)` and `e^{iω* u}(1 − E)²` are
//! closed forms (sums of `(e^{z s} − 1)/z`, `z = iω* − k/τ`). What is left out
//! is third order in `τδ₀` (see [`SettleRule`]).
//!
//! Samples are usually evenly spaced, so [`TailCursor`] advances `e^{iω* s}`
//! and `e^{−s/τ}` by multiplication instead of calling `exp`/`sin_cos` per
//! sample (that per-sample cost dominated the run time of a trajectory whose
//! segments settle early).

use nalgebra::Complex;

use crate::rotor::{small_cos_sin, Rotor};
use crate::{dynamic::SegmentDynamics, Vec2};

type C = Complex<f64>;

/// Share of the tolerance the settled tail may leave out.
pub(crate) const SETTLE_FRACTION: f64 = 0.03;

/// When a transient may be handed over to the closed-form [`Tail`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct SettleRule {
    pub omega: f64,
    pub tau: f64,
    /// `g''(ω*)/2` (1/rad).
    pub q: f64,
    /// `g'''(ω*)/6` (s/rad²).
    pub r: f64,
    pub speed: f64,
    pub tol: f64,
}

impl SettleRule {
    /// The rule for a stable root `omega` with time constant `tau`. The
    /// derivatives of `g = ω̇` come from central differences (five
    /// evaluations of the friction moment); a kink inside the stencil only
    /// makes them larger, i.e. the hand-over later.
    pub fn new(seg: &SegmentDynamics, omega: f64, tau: f64, tol: f64) -> Self {
        let h = 1e-2 * (omega.abs() + 1.0 / tau);
        let g = |k: f64| seg.omega_dot(omega + k * h);
        let (gm2, gm1, g0, gp1, gp2) = (g(-2.0), g(-1.0), g(0.0), g(1.0), g(2.0));
        let g2 = (gp1 - 2.0 * g0 + gm1) / (h * h);
        let g3 = (gp2 - 2.0 * gp1 + 2.0 * gm1 - gm2) / (2.0 * h * h * h);
        Self {
            omega,
            tau,
            q: g2 / 2.0,
            r: g3 / 6.0,
            speed: seg.speed(),
            tol,
        }
    }

    /// True when the tail started at deviation `w − ω*` leaves out less than
    /// [`SETTLE_FRACTION`] of the tolerance over the `remaining` time (s):
    ///
    /// * angle: the cubic term of `δ̇` shifts ε by at most `|r| |δ₀|³ τ²/3`;
    /// * position: the dropped third-order terms of `e^{iε}` (`iε₃ − ε₁ε₂ −
    ///   iε₁³/6`) are at most `(τ|δ₀|)³ (1/6 + |q|/2 + q²/3)` plus the angle
    ///   shift, times the distance `v_c T` they act over.
    pub fn holds(&self, w: f64, remaining: f64) -> bool {
        let d = (w - self.omega).abs();
        let td = d * self.tau;
        let q = self.q.abs();
        let e_theta = self.r.abs() * d * td * td / 3.0;
        let e_pos =
            self.speed * remaining * (td * td * td * (1.0 / 6.0 + q / 2.0 + q * q / 3.0) + e_theta);
        // |x| < 1/4 keeps the logistic's series (and its bound) valid.
        !d.is_nan() && q * td <= 0.25 && e_theta.max(e_pos) <= SETTLE_FRACTION * self.tol
    }

    pub fn tail(&self, t: f64, c: Vec2, theta: f64, w: f64, vel: Vec2) -> Tail {
        Tail {
            t,
            c,
            theta,
            omega: self.omega,
            delta: w - self.omega,
            tau: self.tau,
            q: self.q,
            vel,
        }
    }
}

/// Motion from time `t` on: relaxation from `omega + delta` onto `omega`
/// with time constant `tau` and curvature `q` (see the module docs). With
/// `delta = 0` it is the steady circular arc (also used after a pivot).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tail {
    pub t: f64,
    /// World position of the contact point at `t` (m).
    pub c: Vec2,
    pub theta: f64,
    pub omega: f64,
    pub delta: f64,
    pub tau: f64,
    pub q: f64,
    /// Contact-point velocity in the object frame (m/s).
    pub vel: Vec2,
}

/// A tail pose: contact point, angle, ω, and `(cos θ, sin θ)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TailPose {
    pub c: Vec2,
    pub theta: f64,
    pub omega: f64,
    pub cos: f64,
    pub sin: f64,
}

/// `(cos ε, sin ε)` for the small angles of a settled tail: below 1e-3 rad
/// the short Taylor polynomials (first dropped terms ε⁶/720 and ε⁷/5040,
/// below 2e-21), within [`Rotor::REACH`] the long ones, libm beyond. Short
/// polynomials matter: a sample's cost is the latency of this chain.
#[inline(always)]
fn small_sin_cos(e: f64) -> (f64, f64) {
    if e.abs() < 1e-3 {
        let e2 = e * e;
        return (
            1.0 - e2 * (0.5 - e2 * (1.0 / 24.0)),
            e * (1.0 - e2 * (1.0 / 6.0 - e2 * (1.0 / 120.0))),
        );
    }
    if e.abs() > Rotor::REACH {
        let (s, c) = e.sin_cos();
        return (c, s);
    }
    small_cos_sin(e)
}

/// `−ln(1 − x)/x`, continuous at 0 (series below |x| = 1e-3: the first
/// dropped term, x⁵/6, is below 2e-16).
#[inline(always)]
fn log_ratio(x: f64) -> f64 {
    if x.abs() < 1e-3 {
        1.0 + x * (1.0 / 2.0 + x * (1.0 / 3.0 + x * (1.0 / 4.0 + x * (1.0 / 5.0))))
    } else {
        -(-x).ln_1p() / x
    }
}

/// Evaluates a [`Tail`] at increasing times, advancing the phasors
/// `P = e^{iω* s}` and `E = e^{−s/τ}` by multiplication when the time step
/// repeats.
///
/// The contact point's displacement is linear in the three integrals
/// `A₀ = ∫e^{iω* u}`, `A₁ = ∫e^{iω* u}E`, `A₂ = ∫e^{iω* u}E²` (module docs):
/// `Δc = β₀ A₀ + β₁ (PE − 1) + β₂ (PE² − 1)` with complex constants `β`
/// that fold in `e^{iθ_s}`, the contact velocity, τδ₀ and q, so a sample
/// costs four complex products.
pub(crate) struct TailCursor {
    tail: Tail,
    /// Time since the tail's start of the last evaluation, as accumulated (s).
    s: f64,
    p: C,
    e: f64,
    /// The last step taken and its phasors.
    step: f64,
    p_step: C,
    e_step: f64,
    /// `1/(iω*)`.
    inv_iw: C,
    beta: [C; 3],
    /// `τ δ₀` (rad).
    td: f64,
    /// `ε(∞) = −ln(1 − a)/q` (rad), the angle the relaxation adds in all.
    eps_inf: f64,
    /// `g = τδ₀/(1 − a)` (rad) and `q g`: `ε(s) = ε(∞) − ln(1 + q g E)/q`.
    g: f64,
    qg: f64,
    /// `e^{i(θ_s + ε(∞))}`.
    rot_inf: C,
}

impl TailCursor {
    pub fn new(tail: Tail) -> Self {
        let (s0, c0) = tail.theta.sin_cos();
        let rot0 = C::new(c0, s0);
        let rv = rot0 * C::new(tail.vel.x, tail.vel.y);
        let td = tail.tau * tail.delta;
        // ε(s) split into its limit and a remainder that decays with E, so
        // the remainder's log and rotation take their short series for most
        // samples: 1 − x = (1 − a)(1 + q g E) with a = q τδ₀.
        let a = tail.q * td;
        let eps_inf = td * log_ratio(a);
        let g = td / (1.0 - a);
        let (si, ci) = eps_inf.sin_cos();
        // With J₁ = A₀ − A₁ and J₂ = A₀ − 2A₁ + A₂ the local displacement is
        // A₀ + iτδ₀ J₁ + κ J₂, κ = (iq − 1)(τδ₀)²/2; A₁ = (PE − 1)/z₁ and
        // A₂ = (PE² − 1)/z₂ with z_k = iω* − k/τ.
        let kappa = C::new(-1.0, tail.q) * (0.5 * td * td);
        let itd = C::new(0.0, td);
        let inv_z1 = C::new(-1.0 / tail.tau, tail.omega).inv();
        let inv_z2 = C::new(-2.0 / tail.tau, tail.omega).inv();
        let beta = [
            rv * (C::new(1.0, 0.0) + itd + kappa),
            rv * (-itd - kappa * 2.0) * inv_z1,
            rv * kappa * inv_z2,
        ];
        Self {
            tail,
            s: 0.0,
            p: C::new(1.0, 0.0),
            e: 1.0,
            step: f64::NAN,
            p_step: C::new(1.0, 0.0),
            e_step: 1.0,
            rot_inf: rot0 * C::new(ci, si),
            eps_inf,
            g,
            qg: tail.q * g,
            inv_iw: C::new(0.0, -1.0 / tail.omega),
            beta,
            td,
        }
    }

    /// The pose at time `t` (s), `t` not before the last evaluation.
    #[inline(always)]
    pub fn eval(&mut self, t: f64) -> TailPose {
        self.advance(t);
        self.pose(self.s, self.p, self.e)
    }

    /// Samples the tail at `times` (increasing, not before the last
    /// evaluation), appending the centre-of-mass samples for the contact
    /// point `pc` (object frame) to `out`.
    ///
    /// Two passes per block: the phasor recurrences (a short serial chain),
    /// then the poses, which are independent of each other so the processor
    /// overlaps them (one pass per sample was bound by the latency of each
    /// pose's arithmetic).
    pub fn fill(&mut self, times: &[f64], pc: Vec2, out: &mut Vec<crate::Sample>) {
        const BLOCK: usize = 32;
        let mut phase = [(0.0, C::new(1.0, 0.0), 1.0); BLOCK];
        out.reserve(times.len());
        for block in times.chunks(BLOCK) {
            for (ph, &t) in phase.iter_mut().zip(block) {
                self.advance(t);
                *ph = (self.s, self.p, self.e);
            }
            for (&(s, p, e), &t) in phase.iter().zip(block) {
                let q = self.pose(s, p, e);
                out.push(crate::Sample {
                    t,
                    x: q.c.x - (q.cos * pc.x - q.sin * pc.y),
                    y: q.c.y - (q.sin * pc.x + q.cos * pc.y),
                    theta: q.theta,
                    omega: q.omega,
                });
            }
        }
    }

    /// Moves the phasors to time `t` (s).
    #[inline(always)]
    fn advance(&mut self, t: f64) {
        let tl = &self.tail;
        let ds = (t - tl.t) - self.s;
        if ds != 0.0 {
            // Reuse the last step's phasors when the step repeats (to 1e-9
            // relative: the accumulated time then differs from `t` by
            // rounding only).
            if !((ds - self.step).abs() <= 1e-9 * self.step.abs()) {
                let (sn, cs) = (tl.omega * ds).sin_cos();
                self.step = ds;
                self.p_step = C::new(cs, sn);
                self.e_step = if tl.delta == 0.0 {
                    0.0
                } else {
                    (-ds / tl.tau).exp()
                };
            }
            self.s += self.step;
            self.p *= self.p_step;
            self.e *= self.e_step;
        }
    }

    /// The pose at time `s` (s) after the tail's start, with `p = e^{iω* s}`
    /// and `e = e^{−s/τ}`.
    #[inline(always)]
    fn pose(&self, s: f64, p: C, e: f64) -> TailPose {
        let tl = &self.tail;
        let w = tl.omega;
        // A₀ = (P − 1)/(iω*) loses a factor |ω* s| to cancellation, so
        // angles below 1e-3 rad take the series
        // s (1 − x²/6 + x⁴/120, x/2 − x³/24 + x⁵/720), x = ω* s.
        let x = w * s;
        let a0 = if x.abs() < 1e-3 {
            let x2 = x * x;
            C::new(
                1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0)),
                x * 0.5 * (1.0 - x2 * (1.0 / 12.0) * (1.0 - x2 * (1.0 / 30.0))),
            ) * s
        } else {
            (p - 1.0) * self.inv_iw
        };
        let [b0, b1, b2] = self.beta;
        let mut dc = b0 * a0;
        // ε − ε(∞) (rad).
        let mut eps_rest = 0.0;
        let mut omega = w;
        if tl.delta != 0.0 {
            let pe = p * e;
            dc += pe * (b1 + b2 * e) - (b1 + b2);
            let x = tl.q * self.td * (1.0 - e);
            omega = w + tl.delta * e / (1.0 - x);
            // ε − ε(∞) = −ln(1 + q g E)/q = −g E ln(1 + y)/y, y = q g E.
            eps_rest = -self.g * e * log_ratio(-self.qg * e);
        }
        let (ce, se) = small_sin_cos(eps_rest);
        let rot = self.rot_inf * p * C::new(ce, se);
        TailPose {
            c: tl.c + Vec2::new(dc.re, dc.im),
            theta: tl.theta + x + (self.eps_inf + eps_rest),
            omega,
            cos: rot.re,
            sin: rot.im,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The logistic tail against a fine RK4 integration of
    /// `δ̇ = −δ/τ + q δ²` with the position ODE `ċ = R(θ) v`: they must agree
    /// to third order in τδ₀ (halving δ₀ divides the position error by ≥ 6).
    #[test]
    fn tail_is_second_order_accurate() {
        let run = |delta: f64| {
            let tail = Tail {
                t: 0.3,
                c: Vec2::new(0.1, -0.2),
                theta: 0.4,
                omega: -0.65,
                delta,
                tau: 0.1,
                q: 0.8,
                vel: Vec2::new(0.7, 0.7),
            };
            let f = |y: [f64; 4]| {
                let d = y[1] - tail.omega;
                let (s, c) = y[0].sin_cos();
                [
                    y[1],
                    -d / tail.tau + tail.q * d * d,
                    c * tail.vel.x - s * tail.vel.y,
                    s * tail.vel.x + c * tail.vel.y,
                ]
            };
            let mut y = [tail.theta, tail.omega + delta, tail.c.x, tail.c.y];
            let h = 1e-4;
            let mut cur = TailCursor::new(tail);
            let mut err: f64 = 0.0;
            let mut err_w: f64 = 0.0;
            let mut err_th: f64 = 0.0;
            for k in 1..=20_000 {
                let add =
                    |a: [f64; 4], b: [f64; 4], s: f64| std::array::from_fn(|i| a[i] + s * b[i]);
                let k1 = f(y);
                let k2 = f(add(y, k1, h / 2.0));
                let k3 = f(add(y, k2, h / 2.0));
                let k4 = f(add(y, k3, h));
                y = std::array::from_fn(|i| {
                    y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                });
                if k % 100 == 0 {
                    let p = cur.eval(tail.t + k as f64 * h);
                    err = err.max(((p.c.x - y[2]).powi(2) + (p.c.y - y[3]).powi(2)).sqrt());
                    err_w = err_w.max((p.omega - y[1]).abs());
                    err_th = err_th.max((p.theta - y[0]).abs());
                    assert!(
                        (p.cos - y[0].cos()).abs() < 1e-12 && (p.sin - y[0].sin()).abs() < 1e-12
                    );
                }
            }
            (err, err_w, err_th)
        };
        let (e1, w1, t1) = run(0.2);
        let (e2, _, _) = run(0.1);
        // ω and θ follow the logistic exactly (RK4 error only).
        assert!(w1 < 1e-11 && t1 < 1e-11, "omega {w1:e}, theta {t1:e}");
        assert!(e1 > 0.0 && e1 / e2 > 6.0, "position errors {e1:e} {e2:e}");
        assert!(e1 < (0.2f64 * 0.1).powi(3) * 2.0, "position error {e1:e}");
    }

    /// The batched [`TailCursor::fill`] gives the same samples as one
    /// [`TailCursor::eval`] per sample (same arithmetic, other order of
    /// phasor steps and poses), across block boundaries, for a relaxing
    /// tail and for a steady arc with ω* = 0 (the series branch).
    #[test]
    fn fill_matches_eval() {
        for (omega, delta) in [(-0.65, 0.2), (0.0, 0.0), (0.3, -0.05)] {
            let tail = Tail {
                t: 0.25,
                c: Vec2::new(0.1, -0.2),
                theta: 0.4,
                omega,
                delta,
                tau: 0.1,
                q: 0.8,
                vel: Vec2::new(0.7, 0.7),
            };
            let pc = Vec2::new(-0.125, -0.125);
            let times: Vec<f64> = (0..100).map(|k| 0.25 + 0.01 * k as f64).collect();
            let mut batch = Vec::new();
            TailCursor::new(tail).fill(&times, pc, &mut batch);
            let mut one = TailCursor::new(tail);
            assert_eq!(batch.len(), times.len());
            for (smp, &t) in batch.iter().zip(&times) {
                let p = one.eval(t);
                let x = p.c.x - (p.cos * pc.x - p.sin * pc.y);
                let y = p.c.y - (p.sin * pc.x + p.cos * pc.y);
                assert_eq!(smp.t, t);
                assert!((smp.x - x).abs() < 1e-15 && (smp.y - y).abs() < 1e-15);
                assert!((smp.theta - p.theta).abs() < 1e-15 && (smp.omega - p.omega).abs() < 1e-15);
            }
            // And the arc itself: with δ = 0 the angle grows at exactly ω*.
            if delta == 0.0 {
                let last = batch.last().unwrap();
                assert!((last.theta - (0.4 + omega * 0.99)).abs() < 1e-14);
            }
        }
    }

    /// The tail's angle, ω and rotation against the logistic solution written
    /// out directly (module docs): `θ = θ_s + ω* s − ln(1 − x)/q`,
    /// `ω = ω* + δ₀E/(1 − x)`, `x = qτδ₀(1 − E)`, for `qτδ₀` from the
    /// largest the settle rule admits (0.25, the log's libm branch) down to
    /// 1e-6 (its series), both signs, and `q = 0`.
    #[test]
    fn angle_and_rate_follow_the_logistic_solution() {
        for (q, delta) in [
            (2.5, 1.0),
            (-2.5, 1.0),
            (0.8, 0.05),
            (0.8, -0.05),
            (0.8, 1e-5),
            (0.0, 0.3),
        ] {
            let tail = Tail {
                t: 0.25,
                c: Vec2::new(0.1, -0.2),
                theta: 0.4,
                omega: -0.65,
                delta,
                tau: 0.1,
                q,
                vel: Vec2::new(0.7, 0.7),
            };
            let td = tail.tau * delta;
            let mut cur = TailCursor::new(tail);
            for k in 0..200 {
                let s = 0.005 * k as f64;
                let p = cur.eval(tail.t + s);
                let e = (-s / tail.tau).exp();
                let x = q * td * (1.0 - e);
                let eps = if q == 0.0 {
                    td * (1.0 - e)
                } else {
                    -(-x).ln_1p() / q
                };
                let theta = tail.theta + tail.omega * s + eps;
                let omega = tail.omega + delta * e / (1.0 - x);
                assert!(
                    (p.theta - theta).abs() <= 1e-14,
                    "q {q}, δ₀ {delta}, s {s}: θ {} against {theta}",
                    p.theta
                );
                assert!((p.omega - omega).abs() <= 1e-14, "q {q}, δ₀ {delta}, s {s}");
                assert!(
                    (p.cos - theta.cos()).abs() <= 1e-14 && (p.sin - theta.sin()).abs() <= 1e-14,
                    "q {q}, δ₀ {delta}, s {s}: rotation"
                );
            }
        }
    }
}
