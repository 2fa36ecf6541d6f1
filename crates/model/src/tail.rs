//! Closed-form motion of a segment's transient, as a series in `e^{−s/τ}`.
//!
//! Over one push segment ω obeys the scalar autonomous ODE `ω̇ = g(ω)`. Near a
//! stable root ω* (`τ = −1/g'(ω*)`) there is an analytic change of variable
//! (Poincaré's linearisation) `δ = ω − ω* = h(z)`, `h(z) = Σ_{k≥1} a_k z^k`,
//! `a_1 = 1`, in which the motion is exactly `ż = −z/τ`. Putting
//! `g(ω* + δ) = Σ_j g_j δ^j` into `−(z/τ) h'(z) = g(ω* + h(z))` and matching
//! powers of `z`:
//!
//! ```text
//! a_k = −τ/(k − 1) · Σ_{j=2..k} g_j [h^j]_k          (k ≥ 2)
//! δ(s) = Σ α_k E^k,   α_k = a_k ξ^k,   E = e^{−s/τ},   h(ξ) = δ₀
//! ε(s) = ∫₀ˢ δ = ε∞ − b(E),   b(E) = Σ β_k E^k,   β_k = α_k τ/k,   ε∞ = Σ β_k
//! ```
//!
//! so `θ = θ_s + ω* s + ε(s)`. The contact point moves with `ċ = e^{iθ} V`
//! (complex numbers, `V` the contact velocity in the object frame). With
//! `e^{−i b(E)} = Σ γ_m E^m`, `P = e^{iω* s}` and `z_m = iω* − m/τ`:
//!
//! ```text
//! c(s) = c' + W A₀(s) + P Σ_{m≥1} κ_m E^m,   W = V e^{i(θ_s + ε∞)},
//! A₀ = (P − 1)/(iω*),   κ_m = W γ_m / z_m,   c' = c_s − Σ κ_m
//! ```
//!
//! The rotation is a series too, `e^{iθ} = e^{i(θ_s + ε∞)} P Σ γ_m E^m`, so
//! a sample of the centre of mass, `c − e^{iθ} p_c`, is three Horner sums in
//! `E` and a complex product, with no sine or cosine. The `g_j` come from
//! [`SegmentDynamics::omega_dot_taylor`]; the series is cut at [`ORDER`]
//! terms, and [`SettleRule`] hands a transient over only once the dropped
//! part, checked against `g` itself, is below a share of the tolerance. How
//! early that is depends on how far `δ₀` is from the nearest complex
//! singularity of `g` (a support whose sliding velocity would vanish): on the
//! paper's segments the series usually holds from the switch on, and nothing
//! is integrated.
//!
//! Samples are usually evenly spaced, so [`TailCursor`] advances `P` and `E`
//! by multiplication instead of calling `exp`/`sin_cos` per sample, and cuts
//! the sums per block of samples at the last term that still counts.
//!
//! Whole (about 720 lines of code; its unit tests in `tail/tests.rs`): the series' three
//! stages (the linearising map, the hand-over rule, the cursor that samples
//! it) pass one another fixed-size coefficient arrays of the one truncation
//! order [`ORDER`] and crate-private types; apart, each file would need the
//! others' internals. A run that wants a segment's end alone (the
//! predictor) takes the series in `δ` instead ([`ends`]): the same motion,
//! no linearising map and no rotation series.

use nalgebra::Complex;

pub(crate) mod ends;

use crate::{dynamic::SegmentDynamics, Vec2};

type C = Complex<f64>;

/// Share of the tolerance the tail may leave out.
pub(crate) const SETTLE_FRACTION: f64 = 0.03;

/// Share of the tolerance (as an angle, rad) below which a term of the
/// series is left out of a block of samples: a thousandth of what the
/// hand-over itself may leave out ([`SETTLE_FRACTION`]), so the terms dropped
/// stay far below the tolerance.
pub(crate) const DROP_FRACTION: f64 = 1e-3 * SETTLE_FRACTION;

/// Terms below this size (rad, as an angle) are always left out of samples:
/// at rounding level for any angle the series could reach.
const DROP_FLOOR: f64 = 1e-18;

/// Terms kept of the series in `E`.
pub(crate) const ORDER: usize = 20;

/// The longest series of this module: the series in `E` ([`ORDER`] terms)
/// and those in `δ` ([`ends::N`]).
const LONGEST: usize = if ends::N > ORDER { ends::N } else { ORDER };

/// `1/m` for `m = 0 ..= LONGEST` (`INV[0]` unused): the same values as the
/// divisions, taken from a table so none sits in a recurrence.
const INV: [f64; LONGEST + 1] = {
    let mut t = [0.0; LONGEST + 1];
    let mut m = 1;
    while m <= LONGEST {
        t[m] = 1.0 / m as f64;
        m += 1;
    }
    t
};

/// The coefficients `a_1 … a_ORDER` of the linearising map `h` (index
/// `k − 1`) from the Taylor coefficients `g_0 … g_ORDER` of `g` at a root
/// (`g_1 < 0`). Writing `[h^j]_k` for the `k`-th coefficient of `h^j`, each
/// power is built from the one below, `[h^j]_k = Σ_i a_i [h^{j−1}]_{k−i}`,
/// and for `j ≥ 2` only needs `a_1 … a_{k−1}`: about `K³/6` products for
/// `K` terms.
///
/// Stops early, at `K ≥ 4` terms, once the last two terms at `|z| = reach`
/// are below `small` (the work grows as `K³`; a tight tolerance or a long way
/// to the root needs more terms). Returns the coefficients (zero beyond
/// `K`) and `K`.
pub(crate) fn linearising_map(
    g: &[f64; ORDER + 1],
    reach: f64,
    small: f64,
) -> ([f64; ORDER], usize) {
    POWERS.with_borrow_mut(|pw| linearising_map_in(pw, g, reach, small))
}

/// Columns of a row of the table of powers in [`linearising_map`]: `ORDER`
/// and a chunk of four beyond, so chunks need no remainder.
const ROW: usize = ORDER + 4;

/// The table of `[h^j]_k` of [`linearising_map`], kept per thread instead
/// of zeroing 4 KB per call. A call's step `k` writes row `k`, always at the
/// same columns, before any later step reads it; the columns no step writes
/// (all with `j > k`) keep the zeros they started as. So a call never sees
/// another's values, and the result is the one a fresh table gives.
type Powers = [[f64; ROW]; ORDER + 1];

thread_local! {
    static POWERS: std::cell::RefCell<Powers> = const {
        std::cell::RefCell::new({
            let mut pw = [[0.0; ROW]; ORDER + 1];
            pw[1][1] = 1.0;
            pw
        })
    };
}

/// [`linearising_map`] in the table `pw` (row 1 is `[h]_1 = a_1 = 1`).
fn linearising_map_in(
    pw: &mut Powers,
    g: &[f64; ORDER + 1],
    reach: f64,
    small: f64,
) -> ([f64; ORDER], usize) {
    let tau = -1.0 / g[1];
    let mut a = [0.0; ORDER + 1];
    a[1] = 1.0;
    // pw[k][j] = [h^j]_k, zero for j > k.
    let gp: [f64; ROW] = std::array::from_fn(|j| if j <= ORDER { g[j] } else { 0.0 });
    // reach^(k−1), kept as a running product for the stopping test.
    let mut reach_km1 = reach;
    for k in 2..=ORDER {
        let (lo, hi) = pw.split_at_mut(k);
        let dst = &mut hi[0];
        // [h^j]_k = Σ_i a_i [h^{j−1}]_{k−i}, four j at a time held in
        // registers over i (the terms with i ≥ k − j + 2 are zero).
        let mut o = 0;
        while o + 1 < k {
            let mut acc = [0.0; 4];
            // i = 1, 2, … against rows k − 1, k − 2, …, o + 1.
            for (ai, row) in a[1..k - o].iter().zip(lo[o + 1..].iter().rev()) {
                let s: &[f64; 4] = row[o + 1..o + 5].try_into().expect("in the row");
                for l in 0..4 {
                    acc[l] += ai * s[l];
                }
            }
            dst[o + 2..o + 6].copy_from_slice(&acc);
            o += 4;
        }
        // Σ_j g_j [h^j]_k in four partial sums, over the chunks that reach
        // j = k (the row is zero past k).
        let mut part = [0.0; 4];
        for c in 0..(k + 2) / 4 {
            for l in 0..4 {
                part[l] += gp[2 + 4 * c + l] * dst[2 + 4 * c + l];
            }
        }
        let sum = (part[0] + part[1]) + (part[2] + part[3]);
        a[k] = -tau / (k as f64 - 1.0) * sum;
        dst[1] = a[k];
        let reach_k = reach_km1 * reach;
        if k >= 4 && a[k].abs() * reach_k + a[k - 1].abs() * reach_km1 < small {
            return (std::array::from_fn(|i| a[i + 1]), k);
        }
        reach_km1 = reach_k;
    }
    (std::array::from_fn(|k| a[k + 1]), ORDER)
}

/// `α_k = a_k ξ^k` for the deviation `d = h(ξ)` (Newton's method from
/// `ξ = d`); `None` where `h` is not safely invertible there.
pub(crate) fn series_for(a: &[f64; ORDER], order: usize, d: f64) -> Option<[f64; ORDER]> {
    // (k + 1) a_k, the coefficients of h'.
    let da: [f64; ORDER] = std::array::from_fn(|k| (k + 1) as f64 * a[k]);
    let mut xi = d;
    let mut converged = false;
    for _ in 0..30 {
        // h(ξ) = ξ Σ a_k ξ^k and h'(ξ) = Σ (k + 1) a_k ξ^k, each as its even
        // and odd terms in ξ²: four Horner chains of half the length side
        // by side (an iteration waits on their latency, not their work).
        let x2 = xi * xi;
        let (mut he, mut ho, mut de, mut dd) = (0.0, 0.0, 0.0, 0.0);
        let mut k = order;
        if k % 2 == 1 {
            k -= 1;
            he = a[k];
            de = da[k];
        }
        while k >= 2 {
            k -= 2;
            ho = ho * x2 + a[k + 1];
            he = he * x2 + a[k];
            dd = dd * x2 + da[k + 1];
            de = de * x2 + da[k];
        }
        let h = xi * (he + xi * ho);
        let dh = de + xi * dd;
        if !(dh > 0.25) {
            return None;
        }
        let step = (h - d) / dh;
        xi -= step;
        // Newton converges quadratically: a step this small leaves an
        // error of the order of its square, far below rounding.
        if step.abs() <= 1e-9 * xi.abs() {
            converged = true;
            break;
        }
    }
    if !converged {
        return None;
    }
    let mut xk = 1.0;
    Some(std::array::from_fn(|k| {
        xk *= xi;
        a[k] * xk
    }))
}

/// When a transient may be handed over to the closed-form [`Tail`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct SettleRule {
    /// ω* (rad/s).
    pub omega: f64,
    /// τ = −1/g'(ω*) (s).
    pub tau: f64,
    /// `a_1 … a_K` (index `k − 1`; zero beyond `K`).
    a: [f64; ORDER],
    /// `K`, the number of terms kept.
    order: usize,
    speed: f64,
    tol: f64,
}

impl SettleRule {
    /// The rule for a stable root `omega` of a segment that starts at
    /// ω = `w_start` and lasts `duration` (s); `None` where `g` has no series
    /// there (a support at rest) or the root is not attracting. The series
    /// gets as many terms (up to [`ORDER`]) as it needs to hold from the
    /// segment's start.
    pub fn new(
        seg: &SegmentDynamics,
        omega: f64,
        tol: f64,
        w_start: f64,
        duration: f64,
    ) -> Option<Self> {
        let mut g = [0.0; ORDER + 1];
        seg.omega_dot_taylor(omega, &mut g);
        if !(g[1] < 0.0) || g.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mut rule = Self {
            omega,
            tau: -1.0 / g[1],
            a: [0.0; ORDER],
            order: ORDER,
            speed: seg.speed(),
            tol,
        };
        // As many terms as the hand-over check in `tail` asks for at the
        // segment's start (there with the actual ξ, here with the bound
        // 1.25 |δ₀| on it); that check decides, so this only sets the work.
        let reach = 1.25 * (w_start - omega).abs();
        let small = rule.allowed(duration);
        (rule.a, rule.order) = linearising_map(&g, reach, small);
        rule.a.iter().all(|v| v.is_finite()).then_some(rule)
    }

    /// The error allowed in ω at a hand-over (rad/s) with `remaining` time
    /// (s) to go: the angle error is at most `τ` times it, the position
    /// error at most `v_c × remaining` times the angle error.
    fn allowed(&self, remaining: f64) -> f64 {
        SETTLE_FRACTION * self.tol / (self.tau * (self.speed * remaining.max(0.0)).max(1.0))
    }

    /// The tail from time `t` (s) with contact point `c`, angle `theta` and
    /// ω = `w`, if it leaves out less than [`SETTLE_FRACTION`] of the
    /// tolerance over the `remaining` time (s) of the segment.
    ///
    /// The error in ω at the start is estimated twice and the larger taken:
    /// the last two terms kept (the series converges geometrically), and `τ`
    /// times the residual `δ̇ − g(ω)` of the cut series at the start, where it
    /// is largest (this one compares with `g` itself, so it also catches a
    /// series taken beyond its radius). That error decays at least as fast as
    /// `E`, so the angle is off by at most `τ` times it and the position by
    /// at most `v_c × remaining` times the angle.
    #[allow(clippy::too_many_arguments)]
    pub fn tail(
        &self,
        seg: &SegmentDynamics,
        t: f64,
        c: Vec2,
        theta: f64,
        w: f64,
        vel: Vec2,
        remaining: f64,
    ) -> Option<Tail> {
        let d = w - self.omega;
        if !d.is_finite() {
            return None;
        }
        let mut tail = Tail::arc(t, c, theta, self.omega, vel);
        tail.tau = self.tau;
        tail.drop = (DROP_FRACTION * self.tol).max(DROP_FLOOR);
        if d == 0.0 {
            return Some(tail);
        }
        let allowed = self.allowed(remaining);
        let k = self.order;
        // Cheap screen before solving for ξ (|ξ| is within 1.25 |δ₀| wherever
        // the series is of any use).
        let dd = 1.25 * d.abs();
        let dd_km1 = dd.powi(k as i32 - 1);
        if (self.a[k - 1].abs() * dd + self.a[k - 2].abs()) * dd_km1 > allowed {
            return None;
        }
        tail.alpha = series_for(&self.a, k, d)?;
        let al = &tail.alpha;
        let cut = al[k - 1].abs() + al[k - 2].abs();
        // δ̇ = −Σ k α_k / τ and ε∞ = τ Σ α_k / k at the start (1/k from
        // the table: no division per term).
        let (mut ka, mut ak) = (0.0, 0.0);
        for (j, a) in al[..k].iter().enumerate().rev() {
            ka += (j + 1) as f64 * a;
            ak += a * INV[j + 1];
        }
        let residual = -ka / self.tau - seg.omega_dot(w);
        let eps_inf = ak * self.tau;
        (cut.max(self.tau * residual.abs()) <= allowed && eps_inf.abs() <= 0.5).then_some(tail)
    }
}

/// Motion from time `t` on: relaxation onto `omega` with time constant `tau`
/// as the series `ω − ω* = Σ α_k e^{−k s/τ}` (module docs). With every `α_k`
/// zero it is the steady circular arc (also used after a pivot).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tail {
    pub t: f64,
    /// World position of the contact point at `t` (m).
    pub c: Vec2,
    pub theta: f64,
    /// ω* (rad/s).
    pub omega: f64,
    pub tau: f64,
    /// `α_1 … α_ORDER` (rad/s; index `k − 1`).
    pub alpha: [f64; ORDER],
    /// Contact-point velocity in the object frame (m/s).
    pub vel: Vec2,
    /// Size (rad, as an angle) below which a term of the series no longer
    /// counts in a sample.
    pub drop: f64,
}

impl Tail {
    /// The circular arc at constant `omega` from time `t`.
    pub fn arc(t: f64, c: Vec2, theta: f64, omega: f64, vel: Vec2) -> Self {
        Self {
            t,
            c,
            theta,
            omega,
            tau: 1.0,
            alpha: [0.0; ORDER],
            vel,
            drop: DROP_FLOOR,
        }
    }
}

/// A tail pose: contact point, angle and ω.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TailPose {
    pub c: Vec2,
    pub theta: f64,
    pub omega: f64,
}

/// Samples per block in [`TailCursor::fill`].
const BLOCK: usize = 16;

/// Samples summed together in registers in [`TailCursor::fill`].
const LANES: usize = 4;

/// `j Δt`, `P^j` and `E^j` for `j < BLOCK` and a time step `Δt` (s).
struct StepPowers {
    dt: f64,
    s: [f64; BLOCK],
    /// `P^j`, real and imaginary parts apart, so the products vectorise.
    pr: [f64; BLOCK],
    pi: [f64; BLOCK],
    e: [f64; BLOCK],
}

/// Evaluates a [`Tail`] at increasing times, advancing the phasors
/// `P = e^{iω* s}` and `E = e^{−s/τ}` by multiplication when the time step
/// repeats.
pub(crate) struct TailCursor {
    tail: Tail,
    /// Number of series terms in use (those of `α` and `γ`).
    n: usize,
    /// `β_k` (rad).
    beta: [f64; ORDER],
    /// `κ_m` (m).
    kappa: [C; ORDER],
    /// `γ_0 … γ_ORDER` of `e^{−i b(E)} = Σ γ_m E^m` (those past `n` unused).
    gamma: [C; ORDER + 1],
    /// `ε∞` (rad).
    eps_inf: f64,
    /// `e^{i(θ_s + ε∞)}`.
    rot_inf: C,
    /// `W` (m/s).
    w: C,
    /// `c'` (m).
    c_base: C,
    /// `1/(iω*)`.
    inv_iw: C,
    /// Time since the tail's start of the last evaluation, as accumulated (s).
    s: f64,
    p: C,
    e: f64,
    /// The last step taken and its phasors.
    step: f64,
    p_step: C,
    e_step: f64,
}

impl TailCursor {
    pub fn new(tail: Tail) -> Self {
        let tau = tail.tau;
        let n = tail
            .alpha
            .iter()
            .rposition(|a| *a != 0.0)
            .map_or(0, |k| k + 1);
        // β_k = α_k τ/k by the table of 1/k: no division per term.
        let beta: [f64; ORDER] = std::array::from_fn(|k| tail.alpha[k] * tau * INV[k + 1]);
        let eps_inf: f64 = beta[..n].iter().rev().sum();
        let (s0, c0) = (tail.theta + eps_inf).sin_cos();
        let rot_inf = C::new(c0, s0);
        let v = C::new(tail.vel.x, tail.vel.y);
        let w = v * rot_inf;
        // e^{−i b(E)} = Σ γ_m E^m: with f = e^u, m γ_m = Σ_k k u_k γ_{m−k},
        // u_k = −i β_k, and k β_k = τ α_k.
        let ta: [f64; ORDER] = std::array::from_fn(|k| tail.alpha[k] * tau);
        // γ does not stop where β does (e^{−iβ₁E} alone has every power), so
        // it goes on to ORDER terms and is cut where it no longer counts.
        let mut gamma = [C::new(0.0, 0.0); ORDER + 1];
        gamma[0] = C::new(1.0, 0.0);
        let n_alpha = n;
        let n = if n == 0 { 0 } else { ORDER };
        // γ_{m−1}, held apart from the array so the chain need not wait
        // for it to be stored and read back.
        let mut last = gamma[0];
        for m in 1..=n {
            // The terms k ≥ 2 (γ_{m−2} and older) in four partial sums, then
            // k = 1: the serial chain from γ_{m−1} to γ_m is one product,
            // one sum and the scaling. The terms run to k = n_alpha only
            // (τ α_k is zero beyond).
            let mut acc4 = [C::new(0.0, 0.0); 4];
            let top = m.min(n_alpha);
            let mut k = 2;
            while k + 3 <= top {
                for (l, a) in acc4.iter_mut().enumerate() {
                    *a += gamma[m - k - l] * ta[k + l - 1];
                }
                k += 4;
            }
            for (l, a) in acc4
                .iter_mut()
                .enumerate()
                .take((top + 1).saturating_sub(k))
            {
                *a += gamma[m - k - l] * ta[k + l - 1];
            }
            let acc = ((acc4[0] + acc4[1]) + (acc4[2] + acc4[3])) + last * ta[0];
            last = C::new(acc.im, -acc.re) * INV[m];
            gamma[m] = last;
        }
        let n = (n_alpha..=n)
            .rev()
            .find(|&m| m == n_alpha || gamma[m].norm_sqr() > 1e-40)
            .unwrap_or(0);
        // κ_m = W γ_m / z_m, 1/z_m = conj(z_m)/|z_m|²; the divisions are
        // independent of each other, so they go first, one per term in use.
        let inv_tau = 1.0 / tau;
        let rate: [f64; ORDER] = std::array::from_fn(|k| (k + 1) as f64 * inv_tau);
        let mut inv_z2 = [0.0; ORDER];
        for (iz, r) in inv_z2.iter_mut().zip(&rate).take(n) {
            *iz = 1.0 / (r * r + tail.omega * tail.omega);
        }
        let mut kappa = [C::new(0.0, 0.0); ORDER];
        let mut sum_kappa = C::new(0.0, 0.0);
        for m in (1..=n).rev() {
            let z = C::new(-rate[m - 1], -tail.omega);
            kappa[m - 1] = w * gamma[m] * z * inv_z2[m - 1];
            sum_kappa += kappa[m - 1];
        }
        Self {
            tail,
            n,
            beta,
            kappa,
            gamma,
            eps_inf,
            rot_inf,
            w,
            c_base: C::new(tail.c.x, tail.c.y) - sum_kappa,
            inv_iw: C::new(0.0, -1.0 / tail.omega),
            s: 0.0,
            p: C::new(1.0, 0.0),
            e: 1.0,
            step: f64::NAN,
            p_step: C::new(1.0, 0.0),
            e_step: 1.0,
        }
    }

    /// The pose at time `t` (s), `t` not before the last evaluation, by
    /// the phasors advanced as [`TailCursor::fill`] advances them (what the
    /// tests check `fill` and [`TailCursor::end`] against).
    #[cfg(test)]
    pub fn eval(&mut self, t: f64) -> TailPose {
        self.advance(t);
        let (mut wa, mut ba, mut ka) = (0.0, 0.0, C::new(0.0, 0.0));
        for k in (0..self.n).rev() {
            wa = (wa + self.tail.alpha[k]) * self.e;
            ba = (ba + self.beta[k]) * self.e;
            ka = (ka + self.kappa[k]) * self.e;
        }
        self.pose(self.s, self.p, wa, ba, ka)
    }

    /// The pose at time `t` (s) from phasors taken afresh at `t`, not
    /// advanced through the evaluations before it: a segment's end state
    /// that does not depend on which samples were taken on the way (the
    /// products that advance the phasors round differently for different
    /// sample times), so a run asked for fewer samples takes the same steps.
    pub fn end(&self, t: f64) -> TailPose {
        let tl = &self.tail;
        let s = t - tl.t;
        let (sn, cs) = (tl.omega * s).sin_cos();
        let e = if self.n == 0 {
            0.0
        } else {
            (-s / tl.tau).exp()
        };
        let (mut wa, mut ba, mut ka) = (0.0, 0.0, C::new(0.0, 0.0));
        for k in (0..self.n).rev() {
            wa = (wa + self.tail.alpha[k]) * e;
            ba = (ba + self.beta[k]) * e;
            ka = (ka + self.kappa[k]) * e;
        }
        self.pose(s, C::new(cs, sn), wa, ba, ka)
    }

    /// Samples the tail at `times` (increasing, not before the last
    /// evaluation), appending the centre-of-mass samples for the contact
    /// point `pc` (object frame) to `out`.
    ///
    /// The centre of mass is `c − e^{iθ} p_c`, and with
    /// `e^{iθ} = e^{i(θ_s+ε∞)} P Σ γ_m E^m` both parts are one series in `E`
    /// times `P`:
    ///
    /// ```text
    /// c − e^{iθ} p_c = c' + W A₀(s) + P (−r + Σ λ_m E^m),
    /// r = e^{i(θ_s+ε∞)} p_c,   λ_m = κ_m − r γ_m
    /// ```
    ///
    /// so a sample needs no sine or cosine: three Horner sums (`ω`, the
    /// angle, `λ`) and a complex product. Per block of samples: the phasor
    /// recurrences (a short serial chain); the Horner sums with the samples
    /// innermost, so they vectorise, cut at the last term that counts at the
    /// block's largest `E`; then the poses, independent of each other.
    pub fn fill(&mut self, times: &[f64], pc: Vec2, out: &mut Vec<crate::Sample>) {
        let tl = self.tail;
        let n = self.n;
        let r = self.rot_inf * C::new(pc.x, pc.y);
        let mut lam = [C::new(0.0, 0.0); ORDER];
        // Size of a term as an angle (rad): the λ terms over the lengths they
        // scale, |V| τ for the path and |p_c| for the lever. A block drops
        // the terms that stay below the tail's `drop` (rad).
        // Size of the k-th terms of ω and the angle at `E = 1`, as angles
        // (rad): `|α_k| τ` (the angle's `|β_k| = |α_k| τ/k` is no larger).
        let mut mag: [f64; ORDER] = std::array::from_fn(|k| (tl.alpha[k] * tl.tau).abs());
        let len_scale = tl.vel.norm() * tl.tau + pc.norm();
        for m in 0..n {
            lam[m] = self.kappa[m] - r * self.gamma[m + 1];
            if len_scale > 0.0 {
                mag[m] = mag[m].max(lam[m].norm_sqr().sqrt() / len_scale);
            }
        }
        // A₀ = (P − 1)/(iω*) away from s = 0 (then c' + W A₀ − P r =
        // c'' + P (W/(iω*) − r), c'' = c' − W/(iω*)); its series below
        // |ω* s| = 1e-3, where the quotient would lose a factor |ω* s| to
        // cancellation.
        let w_iw = self.w * self.inv_iw;
        let c_far = self.c_base - w_iw;
        let mu_far = w_iw - r;
        let theta0 = tl.theta + self.eps_inf;
        // Per term: α_k, β_k, λ_k.
        let coef: [[f64; 4]; ORDER] =
            std::array::from_fn(|k| [tl.alpha[k], self.beta[k], lam[k].re, lam[k].im]);
        // Every block computes all BLOCK lanes (a short last block repeats
        // its last sample), so the loops below have a fixed length.
        let mut s = [0.0; BLOCK];
        let mut pr = [1.0; BLOCK];
        let mut pi = [0.0; BLOCK];
        let mut e = [1.0; BLOCK];
        // Powers of the phasor steps for evenly spaced samples, so a block's
        // samples do not wait on each other.
        let mut pows: Option<StepPowers> = None;
        // Usually all of `times` is evenly spaced: one check for the lot
        // (eight at a time against a table of offsets, without early exit
        // or NaN rules, so it vectorises); otherwise per block.
        let spacing = |ts: &[f64]| {
            let dt = if ts.len() > 1 { ts[1] - ts[0] } else { 0.0 };
            let tol = 1e-9 * dt;
            let off: [f64; 8] = std::array::from_fn(|l| l as f64 * dt);
            let mut ok = true;
            for (c, chunk) in ts.chunks(8).enumerate() {
                let base = (8 * c) as f64 * dt + ts[0];
                for (t, o) in chunk.iter().zip(&off) {
                    ok &= ((t - base) - o).abs() <= tol;
                }
            }
            (ts.len() > 1 && ok).then_some(dt)
        };
        let all_even = spacing(times);
        let mut nb = n;
        // Written per block straight into `out` (zeroed, then overwritten):
        // a block assembled on the stack and then copied would be read back
        // before its narrow stores retire.
        out.reserve(times.len());
        for block in times.chunks(BLOCK) {
            let len = block.len();
            self.advance(block[0]);
            (s[0], pr[0], pi[0], e[0]) = (self.s, self.p.re, self.p.im, self.e);
            let even = match all_even {
                Some(dt) if len > 1 => Some(dt),
                Some(_) => None,
                None => spacing(block),
            };
            if let Some(dt) = even {
                if pows.as_ref().is_none_or(|w| w.dt != dt) {
                    let (sn, cs) = (tl.omega * dt).sin_cos();
                    let (ps, es) = (
                        C::new(cs, sn),
                        if n == 0 { 0.0 } else { (-dt / tl.tau).exp() },
                    );
                    let mut pp = [C::new(1.0, 0.0); BLOCK];
                    let mut ep = [1.0; BLOCK];
                    for j in 1..BLOCK {
                        pp[j] = pp[j - 1] * ps;
                        ep[j] = ep[j - 1] * es;
                    }
                    // The step between blocks is the same one.
                    (self.step, self.p_step, self.e_step) = (dt, ps, es);
                    pows = Some(StepPowers {
                        dt,
                        s: std::array::from_fn(|j| j as f64 * dt),
                        pr: pp.map(|z| z.re),
                        pi: pp.map(|z| z.im),
                        e: ep,
                    });
                }
                let w = pows.as_ref().expect("just set");
                // P_j = P_0 P^j written out, the same products as `C`'s
                // (lane 0 reproduces itself: P^0 = 1, E^0 = 1), over the
                // whole block so the loop vectorises.
                let (s0, p0r, p0i, e0) = (s[0], pr[0], pi[0], e[0]);
                for j in 0..BLOCK {
                    s[j] = s0 + w.s[j];
                    pr[j] = p0r * w.pr[j] - p0i * w.pi[j];
                    pi[j] = p0r * w.pi[j] + p0i * w.pr[j];
                    e[j] = e0 * w.e[j];
                }
                (self.s, self.p, self.e) =
                    (s[len - 1], C::new(pr[len - 1], pi[len - 1]), e[len - 1]);
            } else {
                for j in 1..BLOCK {
                    if j < len {
                        self.advance(block[j]);
                    }
                    (s[j], pr[j], pi[j], e[j]) = (self.s, self.p.re, self.p.im, self.e);
                }
            }
            // Terms that still count at the block's largest E (E only
            // decreases, so neither do the terms beyond the last block's).
            while nb > 0 && mag[nb - 1] * e[0].powi(nb as i32) <= tl.drop {
                nb -= 1;
            }
            // The four sums LANES samples at a time, so the accumulators
            // stay in registers (a whole block's would spill to the stack
            // and cost a load and a store per term).
            let mut sums = [[0.0; BLOCK]; 4];
            for g in (0..BLOCK).step_by(LANES) {
                let eg: [f64; LANES] = std::array::from_fn(|l| e[g + l]);
                let mut acc = [[0.0; LANES]; 4];
                for c in coef[..nb].iter().rev() {
                    for (a, ck) in acc.iter_mut().zip(c) {
                        for (al, el) in a.iter_mut().zip(&eg) {
                            *al = (*al + ck) * el;
                        }
                    }
                }
                for (sq, a) in sums.iter_mut().zip(&acc) {
                    sq[g..g + LANES].copy_from_slice(a);
                }
            }
            let [wa, ba, lr, li] = &sums;
            let mut xs = [0.0; BLOCK];
            let mut ys = [0.0; BLOCK];
            if (tl.omega * s[0]).abs() >= 1e-3 {
                // Branch-free over the block, so the poses vectorise.
                for j in 0..BLOCK {
                    let (ir, ii) = (mu_far.re + lr[j], mu_far.im + li[j]);
                    let (pr, pi) = (pr[j], pi[j]);
                    xs[j] = c_far.re + (pr * ir - pi * ii);
                    ys[j] = c_far.im + (pr * ii + pi * ir);
                }
            } else if (tl.omega * s[BLOCK - 1]).abs() < 1e-3 {
                for j in 0..BLOCK {
                    let a0 = self.w * self.a0_short(s[j]);
                    let (ir, ii) = (lr[j] - r.re, li[j] - r.im);
                    let (pr, pi) = (pr[j], pi[j]);
                    xs[j] = (self.c_base.re + a0.re) + (pr * ir - pi * ii);
                    ys[j] = (self.c_base.im + a0.im) + (pr * ii + pi * ir);
                }
            } else {
                for j in 0..BLOCK {
                    let pj = C::new(pr[j], pi[j]);
                    let a0 = if (tl.omega * s[j]).abs() < 1e-3 {
                        self.a0_short(s[j])
                    } else {
                        (pj - 1.0) * self.inv_iw
                    };
                    let q = self.c_base + self.w * a0 + pj * (C::new(lr[j], li[j]) - r);
                    (xs[j], ys[j]) = (q.re, q.im);
                }
            }
            // Zeroed in place, then overwritten: plain stores, no
            // capacity check per sample.
            let base = out.len();
            out.resize(base + len, crate::Sample::default());
            for (j, (o, &t)) in out[base..].iter_mut().zip(block).enumerate() {
                *o = crate::Sample {
                    t,
                    x: xs[j],
                    y: ys[j],
                    theta: theta0 + tl.omega * s[j] - ba[j],
                    omega: tl.omega + wa[j],
                };
            }
        }
    }

    /// `A₀ = (P − 1)/(iω*)` by its series in `x = ω* s`, for `|x| < 1e-3`:
    /// `s (1 − x²/6 + x⁴/120, x/2 − x³/24 + x⁵/720)`.
    #[inline(always)]
    fn a0_short(&self, s: f64) -> C {
        let x = self.tail.omega * s;
        let x2 = x * x;
        C::new(
            1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0)),
            x * 0.5 * (1.0 - x2 * (1.0 / 12.0) * (1.0 - x2 * (1.0 / 30.0))),
        ) * s
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
                self.e_step = if self.n == 0 {
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
    /// and the sums `wa = Σ α_k E^k`, `ba = b(E)`, `ka = Σ κ_m E^m`.
    #[inline(always)]
    fn pose(&self, s: f64, p: C, wa: f64, ba: f64, ka: C) -> TailPose {
        let tl = &self.tail;
        let w = tl.omega;
        // A₀ = (P − 1)/(iω*) loses a factor |ω* s| to cancellation, so
        // angles below 1e-3 rad take its series.
        let x = w * s;
        let a0 = if x.abs() < 1e-3 {
            self.a0_short(s)
        } else {
            (p - 1.0) * self.inv_iw
        };
        let c = self.c_base + self.w * a0 + p * ka;
        TailPose {
            c: Vec2::new(c.re, c.im),
            theta: tl.theta + x + (self.eps_inf - ba),
            omega: w + wa,
        }
    }
}
#[cfg(test)]
mod tests;
