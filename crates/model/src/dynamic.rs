//! The dynamic model for one constant input: ω̇(ω), its roots and their
//! stability, the relaxation time, the pusher force.
//!
//! With `r_i = p_i − p_c`, `s_i = r_i × n_φ`, `b_i = |r_i|²` and
//! `u_i = v_c n_φ + ω D r_i` (so `|u_i|² = v_c² + 2 v_c ω s_i + ω² b_i`), the
//! moment balance about the contact point is
//!
//! ```text
//! I_P ω̇ = G(ω) = −Σ F_i (v_c s_i + ω b_i) / |u_i|  +  k ω,   k = m v_c (p_c · n_φ)
//! G'(ω) = −Σ F_i v_c² (b_i − s_i²) / |u_i|³  +  k
//! ```
//!
//! The friction part is non-increasing in ω (each term's derivative is
//! `−F_i v_c² (b_i − s_i²)/|u_i|³ ≤ 0` by Cauchy–Schwarz), so for `k ≤ 0` there
//! is exactly one root and it is stable. For `k > 0` the inertial term
//! destabilises and roots come in odd numbers inside `|ω| ≤ M / k` with
//! `M = Σ F_i |r_i|` the largest friction moment; all are found and reported.
//!
//! Whole (about 740 lines of code, then its unit tests): one type,
//! [`SegmentDynamics`], whose methods (ω̇ and its Taylor series, the roots
//! and their stability, the pusher force) all read the same per-support
//! sums precomputed by its constructor; split, they would share private
//! fields across files.

use crate::{cross, perp, Body, Push, Vec2};

/// How a root of ω̇ behaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RootKind {
    /// ω̇ crosses zero downwards: nearby ω relax onto it with time constant τ.
    Stable,
    /// ω̇ crosses zero upwards: nearby ω move away from it.
    Unstable,
    /// ω̇ jumps through zero where a support stops sliding: the object pivots
    /// on that support (friction there is set-valued). Stable if the jump is downward.
    Pivot {
        /// Index of the support that stops sliding.
        support: usize,
        /// Whether ω̇ jumps downward through zero there (nearby ω tend to it).
        stable: bool,
    },
}

/// A steady angular velocity of one segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyState {
    /// ω* (rad/s).
    pub omega: f64,
    /// Stable, unstable, or a pivot on a support.
    pub kind: RootKind,
    /// Relaxation time `τ = −I_P / G'(ω*)` (s) for a stable smooth root, else None.
    pub tau: Option<f64>,
}

impl SteadyState {
    /// Whether trajectories starting near it converge to it.
    pub fn is_stable(&self) -> bool {
        matches!(
            self.kind,
            RootKind::Stable | RootKind::Pivot { stable: true, .. }
        )
    }
}

/// The inertial term `m v_c ω (p_c · n_φ)` of the moment balance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InertialTerm {
    /// As derived (docs/architecture.md, "The model"): the moment about the contact point of the
    /// centre of mass's acceleration.
    #[default]
    Derived,
    /// Deliberately wrong: the term with its sign flipped. Exists so that the
    /// tests can show the engine gate catches a sign error in a model.
    Flipped,
}

/// Per-segment precomputation of the dynamic model (structure of arrays, so
/// the friction loop vectorises).
#[derive(Debug, Clone)]
pub struct SegmentDynamics {
    /// `F_i`, `s_i`, `b_i` for the supports with non-zero friction.
    f: Vec<f64>,
    s: Vec<f64>,
    b: Vec<f64>,
    /// Index into the body's supports of each entry above.
    index: Vec<usize>,
    /// Object-frame support positions relative to the contact point (for forces).
    rx: Vec<f64>,
    ry: Vec<f64>,
    speed: f64,
    dir: Vec2,
    k: f64,
    inertia_contact: f64,
    /// `1 / I_P` (1/(kg m²)): ω̇ multiplies by it (a division would sit on
    /// the integrator's critical path, see [`SegmentDynamics::omega_dot`]).
    inv_inertia_contact: f64,
    mass: f64,
    contact: Vec2,
    max_moment: f64,
}

/// Lower clamp on `|u_i|²` (m²/s²) in the friction sum: a product of two
/// clamped values stays a normal f64. Sliding speeds below 1e-75 m/s count as
/// rest there (the set-valued friction of a stopped support is handled by the
/// pivot analysis, not by this sum). Speeds above 1e77 m/s would overflow.
pub const U2_FLOOR: f64 = 1e-150;

/// Relative speed below which a support counts as not sliding.
pub const STICK_REL: f64 = 1e-9;

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

/// Intervals of the uniform grid that [`SegmentDynamics::steady_states`]
/// scans for sign changes of `G` over ±(the bound on |ω*|).
const ROOT_GRID: usize = 512;

impl SegmentDynamics {
    /// Precomputes the segment for `push` (only its speed and direction matter).
    pub fn new(body: &Body, push: &Push) -> Self {
        Self::with_inertial_term(body, push, InertialTerm::Derived)
    }

    /// As [`SegmentDynamics::new`], with a chosen reading of the inertial term.
    pub fn with_inertial_term(body: &Body, push: &Push, term: InertialTerm) -> Self {
        let n = body.len();
        let mut me = Self {
            f: Vec::with_capacity(n),
            s: Vec::with_capacity(n),
            b: Vec::with_capacity(n),
            index: Vec::with_capacity(n),
            rx: Vec::with_capacity(n),
            ry: Vec::with_capacity(n),
            speed: 0.0,
            dir: Vec2::zeros(),
            k: 0.0,
            inertia_contact: 1.0,
            inv_inertia_contact: 1.0,
            mass: 1.0,
            contact: Vec2::zeros(),
            max_moment: 0.0,
        };
        me.reset(body, push, term);
        me
    }

    /// Makes `self` the segment for `body` and `push`, reusing its arrays:
    /// a run of many segments allocates them once (what
    /// [`SegmentDynamics::with_inertial_term`] returns, bit for bit).
    pub(crate) fn reset(&mut self, body: &Body, push: &Push, term: InertialTerm) {
        self.reset_along(body, push, push.direction(), term);
    }

    /// [`SegmentDynamics::reset`] with the push direction `dir = n_φ` the
    /// caller already has.
    pub(crate) fn reset_along(&mut self, body: &Body, push: &Push, dir: Vec2, term: InertialTerm) {
        let sign = match term {
            InertialTerm::Derived => 1.0,
            InertialTerm::Flipped => -1.0,
        };
        let (sx, sy, fr) = body.arrays();
        let pc = body.contact();
        self.speed = push.speed;
        self.dir = dir;
        self.k = sign * body.mass() * push.speed * pc.dot(&dir);
        self.inertia_contact = body.inertia_contact();
        self.inv_inertia_contact = 1.0 / body.inertia_contact();
        self.mass = body.mass();
        self.contact = pc;
        self.max_moment = 0.0;
        for v in [
            &mut self.f,
            &mut self.s,
            &mut self.b,
            &mut self.rx,
            &mut self.ry,
        ] {
            v.clear();
        }
        self.index.clear();
        for i in 0..body.len() {
            if fr[i] == 0.0 {
                continue;
            }
            let r = Vec2::new(sx[i] - pc.x, sy[i] - pc.y);
            self.f.push(fr[i]);
            self.s.push(cross(&r, &dir));
            self.b.push(r.norm_squared());
            self.index.push(i);
            self.rx.push(r.x);
            self.ry.push(r.y);
            self.max_moment += fr[i] * r.norm();
        }
    }

    /// Pusher speed (m/s).
    pub fn speed(&self) -> f64 {
        self.speed
    }
    /// `k = m v_c (p_c · n_φ)` (kg m²/s): the inertial term's slope.
    pub fn inertial_slope(&self) -> f64 {
        self.k
    }
    /// Largest possible friction moment about the contact, `Σ F_i |r_i|` (N m).
    pub fn max_moment(&self) -> f64 {
        self.max_moment
    }
    /// Inertia about the contact point (kg m²).
    pub fn inertia_contact(&self) -> f64 {
        self.inertia_contact
    }

    /// Friction moment about the contact point at `omega` for pusher speed `v`
    /// (N m). A support with `|u_i| = 0` contributes zero (its friction is
    /// set-valued there; see [`RootKind::Pivot`]).
    ///
    /// `u_i` is formed component by component rather than from
    /// `|u_i|² = v² + 2 v ω s_i + ω² b_i`, which cancels catastrophically where
    /// a support nearly stops and would misplace a pivot by ~1e-8 relative.
    ///
    /// The loop is bound by the divider (square roots and divisions share
    /// it), so supports are taken in pairs over one division:
    /// `a/√x + c/√y = (a y √x + c x √y) / (x y)` with `x, y = |u|²` — two
    /// square roots and one division per pair instead of two of each
    /// (`model_rhs` bench: about 2× per support at 1024 supports). The
    /// reciprocal `1/(x y)` is taken apart from the numerator so the division
    /// runs beside the square roots rather than after them: for a handful of
    /// supports the sum's latency, not its throughput, is what an integrator
    /// waits for. `|u|²` is clamped below at [`U2_FLOOR`] so `x y` stays a
    /// normal number; a support at rest then has `a = r_i × u_i = 0` and
    /// contributes nothing.
    #[inline]
    pub fn friction_moment_at(&self, v: f64, omega: f64) -> f64 {
        let (vx, vy) = (v * self.dir.x, v * self.dir.y);

        // a/√x + b/√y over one reciprocal; `a y` and `b x` are ready before
        // the square roots finish, so one product follows each of them.
        let pair = |(a, x): (f64, f64), (b, y): (f64, f64)| {
            (a * y * x.sqrt() + b * x * y.sqrt()) * (1.0 / (x * y))
        };
        let n = self.f.len();
        let (f, rx, ry) = (&self.f[..n], &self.rx[..n], &self.ry[..n]);
        // (F_i r_i × u_i, |u_i|²) of support i, branch-free so the loop vectorises.
        let term = |i: usize| {
            let ux = vx - omega * ry[i];
            let uy = vy + omega * rx[i];
            let u2 = (ux * ux + uy * uy).max(U2_FLOOR);
            (f[i] * (rx[i] * uy - ry[i] * ux), u2)
        };
        // Blocks of four: supports k, k+1 are paired with k+2, k+3, into two
        // independent accumulators (a single sum would be a serial chain).
        // The first block initialises them, sparing two additions on the
        // path an integrator waits on.
        let blocks = n / 4;
        let mut acc = [-0.0f64; 2];
        if blocks > 0 {
            acc = [pair(term(0), term(2)), pair(term(1), term(3))];
        }
        for c in 1..blocks {
            let k = 4 * c;
            for (l, a) in acc.iter_mut().enumerate() {
                *a += pair(term(k + l), term(k + 2 + l));
            }
        }
        // The remainder (0–3 supports): one more pair, then a single one.
        // −0.0 is the additive identity the compiler may drop (x + −0.0 = x
        // for every x, −0.0 included).
        let mut tail = -0.0;
        let mut i = 4 * blocks;
        if n - i >= 2 {
            tail = pair(term(i), term(i + 1));
            i += 2;
        }
        if i < n {
            let (a, x) = term(i);
            tail += a / x.sqrt();
        }
        -((acc[0] + acc[1]) + tail)
    }

    /// `G(ω) = I_P ω̇` (N m).
    #[inline]
    pub fn moment(&self, omega: f64) -> f64 {
        self.friction_moment_at(self.speed, omega) + self.k * omega
    }

    /// ω̇ (rad/s²).
    ///
    /// An integrator's stages are serial in ω, so this function's latency
    /// (not its throughput) sets the integration speed for few supports:
    /// it multiplies by a stored `1/I_P` instead of dividing.
    #[inline]
    pub fn omega_dot(&self, omega: f64) -> f64 {
        self.moment(omega) * self.inv_inertia_contact
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

    /// `G'(ω)` (N m s), using `b_i − s_i² = (r_i · n_φ)²`. Supports that are
    /// not sliding are skipped.
    pub fn moment_slope(&self, omega: f64) -> f64 {
        let v = self.speed;
        let (vx, vy) = (v * self.dir.x, v * self.dir.y);
        let mut acc = self.k;
        for i in 0..self.f.len() {
            let ux = vx - omega * self.ry[i];
            let uy = vy + omega * self.rx[i];
            let u2 = ux * ux + uy * uy;
            if u2 > 0.0 {
                let c = v * (self.rx[i] * self.dir.x + self.ry[i] * self.dir.y);
                acc -= self.f[i] * c * c / (u2 * u2.sqrt());
            }
        }
        acc
    }

    /// Smallest support sliding speed at `omega` (m/s) and the body's index of
    /// that support.
    pub fn min_support_speed(&self, omega: f64) -> (f64, usize) {
        let (vx, vy) = (self.speed * self.dir.x, self.speed * self.dir.y);
        let mut best = (f64::INFINITY, 0);
        for i in 0..self.f.len() {
            let ux = vx - omega * self.ry[i];
            let uy = vy + omega * self.rx[i];
            let u2 = ux * ux + uy * uy;
            if u2 < best.0 {
                best = (u2, self.index[i]);
            }
        }
        (best.0.sqrt(), best.1)
    }

    /// Speed scale for "has this support stopped?" tests (m/s).
    fn speed_scale(&self, omega: f64) -> f64 {
        let rmax = self.b.iter().fold(0.0f64, |a, &b| a.max(b)).sqrt();
        self.speed + omega.abs() * rmax
    }

    /// Every steady state, sorted by ω, with its stability. Empty when ω̇ never
    /// vanishes (possible only when all supports lie on the push line).
    pub fn steady_states(&self) -> Vec<SteadyState> {
        let g = |w: f64| self.moment(w);
        let mut roots = Vec::new();
        if self.speed == 0.0 {
            // The contact point is held still: the object can only pivot about it,
            // and friction stops it. ω* = 0, reached in finite time.
            return vec![SteadyState {
                omega: 0.0,
                kind: RootKind::Stable,
                tau: None,
            }];
        }
        let bound = self.root_bound();
        if self.k <= 0.0 {
            // Monotone: one sign change in [−bound, bound] at most.
            let (lo, hi) = (-bound, bound);
            if g(lo) > 0.0 && g(hi) < 0.0 {
                roots.push(self.refine(lo, hi));
            } else if g(lo) == 0.0 || g(hi) == 0.0 {
                roots.push(if g(lo) == 0.0 { lo } else { hi });
            }
        } else {
            // Several roots possible: scan a grid clustered where each support's
            // term is steepest (ω = −v s_i / b_i, where |u_i| is smallest).
            let mut grid: Vec<f64> = (0..=ROOT_GRID)
                .map(|j| -bound + 2.0 * bound * j as f64 / ROOT_GRID as f64)
                .collect();
            self.cluster_points(bound, &mut grid);
            grid.sort_by(f64::total_cmp);
            grid.dedup();
            let vals: Vec<f64> = grid.iter().map(|&w| g(w)).collect();
            for j in 0..grid.len() - 1 {
                let (a, b) = (vals[j], vals[j + 1]);
                if a == 0.0 {
                    roots.push(grid[j]);
                } else if a * b < 0.0 {
                    roots.push(self.refine(grid[j], grid[j + 1]));
                }
            }
            if vals[grid.len() - 1] == 0.0 {
                roots.push(grid[grid.len() - 1]);
            }
        }
        roots.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * (1.0 + b.abs()));
        roots.into_iter().map(|w| self.classify(w)).collect()
    }

    /// The distance from the contact point to the nearest support not under
    /// it, `min √b_i` over `b_i = |r_i|² > 0` (m; infinite when there is
    /// none).
    fn r_min(&self) -> f64 {
        self.b
            .iter()
            .fold(f64::INFINITY, |a, &b| if b > 0.0 { a.min(b) } else { a })
            .sqrt()
    }

    /// A bound on |ω| of every steady state (rad/s). With `k > 0` the friction
    /// moment is at most M, so |k ω*| ≤ M; with k ≤ 0 the root sits where the
    /// friction moment changes sign, within a few v/r.
    fn root_bound(&self) -> f64 {
        let g = |w: f64| self.moment(w);
        if self.k > 0.0 {
            return self.max_moment / self.k * (1.0 + 1e-9) + 1e-300;
        }
        // Expand until the sign changes (G decreasing: G(+∞) < 0 < G(−∞)).
        let mut w = self.speed / self.r_min().max(1e-300);
        for _ in 0..200 {
            if g(w) < 0.0 && g(-w) > 0.0 {
                break;
            }
            w *= 2.0;
        }
        w
    }

    /// Appends to `grid` the scan points clustered about each support's
    /// steepest place (ω = −v s_i / b_i) that lie inside ±`bound`.
    fn cluster_points(&self, bound: f64, grid: &mut Vec<f64>) {
        for i in 0..self.f.len() {
            if self.b[i] > 0.0 {
                let w0 = -self.speed * self.s[i] / self.b[i];
                let width = self.speed / self.b[i].sqrt();
                for d in [
                    -1.0, -0.3, -0.1, -0.03, -0.01, 0.0, 0.01, 0.03, 0.1, 0.3, 1.0,
                ] {
                    let w = w0 + d * width;
                    if w.abs() < bound {
                        grid.push(w);
                    }
                }
            }
            if grid.len() > 20_000 {
                break;
            }
        }
    }

    /// The steady state a transient starting at `omega` converges to, as
    /// [`Self::attractor`] of [`Self::steady_states`] but scanning only the
    /// stretch of the grid from `omega` in the direction ω̇ drives it, up to
    /// its first sign change (a trajectory needs no other root). None when ω
    /// runs away.
    pub fn attractor_from(&self, omega: f64) -> Option<SteadyState> {
        if self.speed == 0.0 {
            return self.attractor(&self.steady_states(), omega);
        }
        let g0 = self.moment(omega);
        if g0 == 0.0 {
            return Some(self.classify(omega));
        }
        // A root within rounding of ω is the state itself (as in `attractor`).
        let h = 1e-12 * (1.0 + omega.abs());
        let (gl, gh) = (self.moment(omega - h), self.moment(omega + h));
        if (gl > 0.0) != (gh > 0.0) && gl != 0.0 && gh != 0.0 {
            return Some(self.classify(self.refine(omega - h, omega + h)));
        }
        let up = g0 > 0.0;
        if self.k <= 0.0 {
            // G is monotone: its one root lies ahead. Steps from ω growing
            // by doubling from a tenth of v/r_min bracket it; past 2⁶⁰ times
            // that scale there is none (the full scan's bound stops sooner).
            let mut h = 0.1 * self.speed / self.r_min().max(1e-300);
            let dir = if up { 1.0 } else { -1.0 };
            let mut prev = omega;
            for _ in 0..64 {
                let w = omega + dir * h;
                let gw = self.moment(w);
                if gw == 0.0 {
                    return Some(self.classify(w));
                }
                if (gw > 0.0) != up {
                    let (lo, hi) = if up { (prev, w) } else { (w, prev) };
                    return Some(self.classify(self.refine(lo, hi)));
                }
                prev = w;
                h *= 2.0;
            }
            return None;
        }
        let bound = self.root_bound();
        // The clustered points ahead, nearest first.
        let mut extra = Vec::new();
        self.cluster_points(bound, &mut extra);
        extra.retain(|&w| if up { w > omega } else { w < omega });
        extra.sort_by(|a, b| if up { a.total_cmp(b) } else { b.total_cmp(a) });
        // The uniform points ahead, nearest first.
        let step = 2.0 * bound / ROOT_GRID as f64;
        let first = ((omega + bound) / step).floor();
        let mut j = if up {
            (first + 1.0).max(0.0)
        } else {
            first.min(ROOT_GRID as f64)
        };
        let uniform_done = |j: f64| !(0.0..=ROOT_GRID as f64).contains(&j);
        let mut e = 0;
        let (mut prev, mut gprev) = (omega, g0);
        loop {
            let wu = (!uniform_done(j)).then(|| -bound + step * j);
            let we = extra.get(e).copied();
            let w = match (wu, we) {
                (Some(a), Some(b)) if (a < b) == up => a,
                (Some(_), Some(b)) | (None, Some(b)) => b,
                (Some(a), None) => a,
                (None, None) => return None,
            };
            if wu == Some(w) {
                j += if up { 1.0 } else { -1.0 };
            } else {
                e += 1;
            }
            if (w > prev) != up || w == prev {
                continue;
            }
            let gw = self.moment(w);
            if gw == 0.0 {
                return Some(self.classify(w));
            }
            if (gw > 0.0) != (gprev > 0.0) {
                let (lo, hi) = if up { (prev, w) } else { (w, prev) };
                return Some(self.classify(self.refine(lo, hi)));
            }
            (prev, gprev) = (w, gw);
        }
    }

    fn classify(&self, w: f64) -> SteadyState {
        let (umin, idx) = self.min_support_speed(w);
        let scale = self.speed_scale(w);
        let h = 1e-7 * scale.max(1e-300)
            / self
                .b
                .iter()
                .fold(0.0f64, |a, &b| a.max(b))
                .sqrt()
                .max(1e-300);
        if umin <= 1e-6 * scale {
            // A jump in G: decide stability from the sign on each side.
            let stable = self.moment(w - h) > 0.0 && self.moment(w + h) < 0.0;
            return SteadyState {
                omega: w,
                kind: RootKind::Pivot {
                    support: idx,
                    stable,
                },
                tau: None,
            };
        }
        let slope = self.moment_slope(w);
        if slope < 0.0 {
            SteadyState {
                omega: w,
                kind: RootKind::Stable,
                tau: Some(-self.inertia_contact / slope),
            }
        } else {
            SteadyState {
                omega: w,
                kind: RootKind::Unstable,
                tau: None,
            }
        }
    }

    /// Bracketed root refinement to machine precision: regula falsi with the
    /// Anderson–Björck scaling of the retained end (superlinear), and a
    /// bisection whenever three steps in a row have not halved the bracket.
    /// Stops when the bracket is a few ulps wide or `|G|` is down to its
    /// rounding floor (a few ε times the moments summed): near ω* = 0 the
    /// bracket's relative width never gets there. `g(lo)` and `g(hi)` have
    /// opposite signs.
    fn refine(&self, mut lo: f64, mut hi: f64) -> f64 {
        let g = |w: f64| self.moment(w);
        let (mut glo, mut ghi) = (g(lo), g(hi));
        let mut side = 0i8;
        let mut width = (hi - lo).abs();
        let mut slow = 0;
        for _ in 0..200 {
            let mut w = if slow >= 3 {
                slow = 0;
                0.5 * (lo + hi)
            } else {
                (lo * ghi - hi * glo) / (ghi - glo)
            };
            if !(w > lo.min(hi) && w < lo.max(hi)) {
                w = 0.5 * (lo + hi);
            }
            let gw = g(w);
            // |G| at its rounding floor: no point in the bracket is closer.
            if gw.abs() <= 4.0 * f64::EPSILON * (self.max_moment + (self.k * w).abs()) {
                return w;
            }
            if gw.signum() == glo.signum() {
                // The hi end is kept: scale its value (Anderson–Björck).
                if side == -1 {
                    let m = 1.0 - gw / glo;
                    ghi *= if m > 0.0 { m } else { 0.5 };
                }
                lo = w;
                glo = gw;
                side = -1;
            } else {
                if side == 1 {
                    let m = 1.0 - gw / ghi;
                    glo *= if m > 0.0 { m } else { 0.5 };
                }
                hi = w;
                ghi = gw;
                side = 1;
            }
            let new_width = (hi - lo).abs();
            if new_width <= 4.0 * f64::EPSILON * lo.abs().max(hi.abs()) + 1e-300 {
                break;
            }
            if new_width > 0.5 * width {
                slow += 1;
            } else {
                slow = 0;
            }
            width = new_width;
        }
        if glo.abs() < ghi.abs() {
            lo
        } else {
            hi
        }
    }

    /// The steady state a transient starting at `omega` converges to: the
    /// nearest root in the direction ω̇ drives it. None when ω runs away.
    pub fn attractor(&self, roots: &[SteadyState], omega: f64) -> Option<SteadyState> {
        let gw = self.moment(omega);
        if let Some(r) = roots
            .iter()
            .find(|r| (r.omega - omega).abs() <= 1e-12 * (1.0 + omega.abs()))
        {
            return Some(*r);
        }
        if gw > 0.0 {
            roots.iter().find(|r| r.omega > omega).copied()
        } else if gw < 0.0 {
            roots.iter().rev().find(|r| r.omega < omega).copied()
        } else {
            roots
                .iter()
                .min_by(|a, b| (a.omega - omega).abs().total_cmp(&(b.omega - omega).abs()))
                .copied()
        }
    }

    /// ω (rad/s) after `duration` (s) of the segment's flow ω̇ = G(ω)/I_P
    /// from `omega`: the dynamic model's transient with the push held. ω
    /// may run away (no steady state ahead): it is still followed for
    /// `duration`. None where it leaves the finite numbers.
    ///
    /// The flow is one-dimensional and autonomous, so ω moves monotonically
    /// towards [`Self::attractor_from`] and never passes it. Adaptive
    /// Dormand–Prince 5(4) steps ([`crate::integrate`]) evaluate G only on
    /// the stretch between the start and that steady state: at a pivot G
    /// jumps, and an integrator that stepped past it would chatter; clamped,
    /// ω reaches the pivot in finite time and stays.
    pub fn advance(&self, omega: f64, duration: f64) -> Option<f64> {
        use crate::integrate::{dp5_attempt, initial_step, next_step, State};
        if duration <= 0.0 {
            return Some(omega);
        }
        // Without a steady state ahead, ω runs away: nothing to stop at.
        let target = self.attractor_from(omega).map(|r| r.omega);
        if target == Some(omega) {
            return target;
        }
        let (lo, hi) = match target {
            Some(t) => (omega.min(t), omega.max(t)),
            None => (f64::NEG_INFINITY, f64::INFINITY),
        };
        let mut f = |y: &State| [0.0, self.omega_dot(y[1].clamp(lo, hi)), 0.0, 0.0];
        let rtol = [0.0, 1e-10, 0.0, 0.0];
        let atol = 1e-12 * (1.0 + omega.abs().max(target.unwrap_or(0.0).abs()));
        let mut y = [0.0, omega, 0.0, 0.0];
        let mut k1 = f(&y);
        let mut h = initial_step(&mut f, &y, &k1, atol, &rtol, 5, duration);
        let mut t = 0.0;
        // A bound on the work, never reached by a flow that settles: each
        // accepted step is at least as long as the flow's fastest time scale.
        for _ in 0..1_000_000 {
            if t >= duration {
                return Some(y[1]);
            }
            let step = h.min(duration - t);
            let a = dp5_attempt(&mut f, &y, &k1, step, atol, &rtol);
            if a.err <= 1.0 {
                t = if step == duration - t {
                    duration
                } else {
                    t + step
                };
                y[1] = a.y1[1].clamp(lo, hi);
                if Some(y[1]) == target || !y[1].is_finite() {
                    return y[1].is_finite().then_some(y[1]);
                }
                k1 = f(&y);
            }
            h = next_step(step, a.err);
        }
        y[1].is_finite().then_some(y[1])
    }

    /// Sum of the support friction forces in the object frame (N).
    pub fn friction_force(&self, omega: f64) -> Vec2 {
        let v = self.speed;
        let mut acc = Vec2::zeros();
        for i in 0..self.f.len() {
            let u = Vec2::new(
                v * self.dir.x - omega * self.ry[i],
                v * self.dir.y + omega * self.rx[i],
            );
            let n = u.norm();
            if n > 0.0 {
                acc -= u * (self.f[i] / n);
            }
        }
        acc
    }

    /// Pusher force in the object frame (N), `f_c = m a_cm − Σ f_i`, with
    /// `a_cm = v_c ω D n_φ − ω̇ D p_c + ω² p_c` (object frame).
    pub fn pusher_force(&self, omega: f64) -> Vec2 {
        let wd = self.omega_dot(omega);
        let a = perp(&self.dir) * (self.speed * omega) - perp(&self.contact) * wd
            + self.contact * (omega * omega);
        a * self.mass - self.friction_force(omega)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Support;

    /// `−Σ F_i (r_i × u_i) / |u_i|` one support at a time, straight from the
    /// definition (no pairing, no clamp; a support at rest contributes 0).
    fn moment_by_definition(body: &Body, push: &Push, omega: f64) -> f64 {
        let pc = body.contact();
        body.supports()
            .map(|s| {
                let r = s.position - pc;
                let u = push.velocity() + perp(&r) * omega;
                if u.norm() == 0.0 {
                    0.0
                } else {
                    -s.friction * cross(&r, &u) / u.norm()
                }
            })
            .sum()
    }

    fn body(points: &[(f64, f64)]) -> Body {
        let sup: Vec<Support> = points
            .iter()
            .enumerate()
            .map(|(i, &(x, y))| Support {
                position: Vec2::new(x, y),
                friction: 0.3 + 0.1 * i as f64,
            })
            .collect();
        Body::new(1.3, 0.02, Vec2::new(-0.1, -0.05), &sup).unwrap()
    }

    /// The paired sum (blocks of four plus a remainder) equals the
    /// per-support definition for every support count that exercises a
    /// different block/remainder split.
    #[test]
    fn paired_friction_sum_matches_the_definition() {
        let pts: Vec<(f64, f64)> = (0..11)
            .map(|i| {
                let t = 2.4 * i as f64;
                (0.1 * t.cos() + 0.01 * i as f64, 0.08 * t.sin())
            })
            .collect();
        let push = Push {
            duration: 1.0,
            speed: 0.7,
            phi: 0.4,
        };
        for n in 1..=pts.len() {
            let b = body(&pts[..n]);
            let seg = SegmentDynamics::new(&b, &push);
            for omega in [-30.0, -2.0, -0.3, 0.0, 0.05, 1.7, 25.0] {
                let want = moment_by_definition(&b, &push, omega);
                let got = seg.friction_moment_at(push.speed, omega);
                let scale = seg.max_moment();
                assert!(
                    (got - want).abs() <= 1e-14 * scale,
                    "n {n}, ω {omega}: {got} against {want}"
                );
            }
        }
    }

    /// A segment re-made in place from another segment's arrays (another
    /// body, more supports, a zero-friction support, the flipped inertial
    /// term before) is the segment made afresh: the same ω̇, roots and
    /// pusher force.
    #[test]
    fn a_reset_segment_is_a_fresh_one() {
        let mut b = body(&[(0.1, 0.08), (0.12, -0.07), (-0.05, 0.02), (0.0, -0.1)]);
        let small = body(&[(0.1, 0.1), (-0.1, 0.1)]);
        let push = Push {
            duration: 1.0,
            speed: 0.7,
            phi: 0.4,
        };
        let other = Push {
            duration: 1.0,
            speed: 0.2,
            phi: -1.1,
        };
        let mut sup: Vec<Support> = b.supports().collect();
        sup[1].friction = 0.0;
        b = Body::new(1.3, 0.02, b.contact(), &sup).unwrap();
        for (before, term) in [(&small, InertialTerm::Flipped), (&b, InertialTerm::Derived)] {
            let mut seg = SegmentDynamics::with_inertial_term(before, &other, term);
            seg.reset(&b, &push, InertialTerm::Derived);
            let fresh = SegmentDynamics::new(&b, &push);
            for w in [-3.0, -0.2, 0.0, 0.5, 4.0] {
                assert_eq!(seg.omega_dot(w), fresh.omega_dot(w), "ω {w}");
                assert_eq!(seg.pusher_force(w), fresh.pusher_force(w), "ω {w}");
            }
            assert_eq!(seg.steady_states(), fresh.steady_states());
            assert_eq!(seg.max_moment(), fresh.max_moment());
        }
    }

    /// A push through the centre of a support set that is mirror-symmetric
    /// about the push line has its steady state at ω = 0 (the mirror image
    /// of a turning motion turns the other way), from either side and
    /// whether the search is the full scan or the directed one. There `G`
    /// is rounding noise, so the search stops on `|G|` at its rounding floor
    /// (waiting for the bracket to shrink relative to |ω| spent the whole
    /// iteration budget); this checks that stop lands at zero.
    #[test]
    fn a_symmetric_push_settles_at_zero_rate() {
        let sup: Vec<Support> = [(0.1, 0.1), (0.1, -0.1), (-0.1, 0.1), (-0.1, -0.1)]
            .iter()
            .map(|&(x, y)| Support {
                position: Vec2::new(x, y),
                friction: 0.5,
            })
            .collect();
        // Contact on the x axis, pushed along +x: the mirror is y → −y.
        let b = Body::new(1.0, 0.01, Vec2::new(-0.1, 0.0), &sup).unwrap();
        let push = Push {
            duration: 1.0,
            speed: 0.3,
            phi: 0.0,
        };
        let seg = SegmentDynamics::new(&b, &push);
        let scale = push.speed / 0.1;
        let roots = seg.steady_states();
        assert_eq!(roots.len(), 1, "{roots:?}");
        assert!(roots[0].omega.abs() <= 1e-14 * scale, "{roots:?}");
        for w in [-2.0, -0.3, 0.3, 2.0] {
            let r = seg.attractor_from(w).expect("a stable root");
            assert!(r.omega.abs() <= 1e-14 * scale, "from {w}: {r:?}");
            assert_eq!(r.kind, RootKind::Stable);
        }
    }

    /// Near a stable smooth root the flow is linear: a small offset decays
    /// as e^(−t/τ) with the root's own relaxation time τ = −I_P/G'(ω*).
    #[test]
    fn advance_decays_with_the_roots_relaxation_time() {
        let b = body(&[(0.1, 0.08), (0.12, -0.07), (-0.05, 0.02)]);
        let push = Push {
            duration: 1.0,
            speed: 0.7,
            phi: 0.4,
        };
        let seg = SegmentDynamics::new(&b, &push);
        let root = seg.attractor_from(0.0).expect("a steady state");
        let tau = root.tau.expect("a smooth stable root");
        let eps = 1e-6 * (1.0 + root.omega.abs());
        for sign in [1.0, -1.0] {
            for k in [0.5, 1.0, 3.0] {
                let w = seg.advance(root.omega + sign * eps, k * tau).unwrap();
                let ratio = (w - root.omega) / (sign * eps);
                assert!(
                    (ratio - (-k).exp()).abs() < 1e-4,
                    "t = {k} τ: ratio {ratio}, e^-t/τ {}",
                    (-k).exp()
                );
            }
        }
    }

    /// The transient composes (a then b is a + b), moves monotonically
    /// towards the attractor without passing it, and reaches it.
    #[test]
    fn advance_composes_and_settles_monotonically() {
        let b = body(&[(0.1, 0.08), (0.12, -0.07), (-0.05, 0.02), (0.0, -0.1)]);
        let push = Push {
            duration: 1.0,
            speed: 0.3,
            phi: -0.7,
        };
        let seg = SegmentDynamics::new(&b, &push);
        let root = seg.attractor_from(0.0).expect("a steady state");
        let tau = root.tau.expect("a smooth stable root");
        let scale = 1.0 + root.omega.abs();
        let (a, c) = (0.37 * tau, 1.9 * tau);
        let two = seg.advance(seg.advance(0.0, a).unwrap(), c).unwrap();
        let one = seg.advance(0.0, a + c).unwrap();
        assert!((two - one).abs() < 1e-8 * scale, "{two} vs {one}");
        let mut prev = 0.0;
        for j in 1..=40 {
            let w = seg.advance(0.0, 0.25 * tau * j as f64).unwrap();
            assert!(
                (w - prev) * root.omega.signum() >= 0.0,
                "step {j}: {prev} → {w}"
            );
            assert!(
                (w - 0.0) * (w - root.omega) <= 0.0,
                "passed ω* = {}: {w}",
                root.omega
            );
            prev = w;
        }
        let late = seg.advance(0.0, 60.0 * tau).unwrap();
        assert!(
            (late - root.omega).abs() < 1e-9 * scale,
            "{late} vs {}",
            root.omega
        );
    }

    /// A pivot is reached in finite time (G does not vanish there) and held:
    /// ω equals the pivot's rate exactly, without chattering about it.
    #[test]
    fn advance_reaches_a_pivot_and_stays() {
        // A heavily loaded support straight beside the contact point across
        // the push: the plate turns about it at ω = v / 0.1.
        let sup = [
            Support {
                position: Vec2::new(-0.1, 0.1),
                friction: 5.0,
            },
            Support {
                position: Vec2::new(0.1, -0.1),
                friction: 0.05,
            },
        ];
        let b = Body::new(1.0, 0.01, Vec2::new(-0.1, 0.0), &sup).unwrap();
        let push = Push {
            duration: 1.0,
            speed: 0.2,
            phi: 0.0,
        };
        let seg = SegmentDynamics::new(&b, &push);
        let root = seg.attractor_from(0.0).expect("a steady state");
        assert!(
            matches!(root.kind, RootKind::Pivot { stable: true, .. }),
            "{root:?}"
        );
        let pivot = root.omega;
        assert!((pivot.abs() - 0.2 / 0.1).abs() < 1e-9, "{pivot}");
        let early = seg.advance(0.0, 1e-4).unwrap();
        assert!(early.abs() > 0.0 && early.abs() < pivot.abs(), "{early}");
        assert_eq!(seg.advance(0.0, 10.0), Some(pivot));
    }

    /// With its one support under the contact point friction has no moment
    /// about it: ω̇ = k ω / I_P, which runs away as e^(k t / I_P) when the
    /// contact lies ahead of the centre of mass along the push (a pull,
    /// k > 0).
    #[test]
    fn advance_follows_a_runaway_exactly() {
        let sup = [Support {
            position: Vec2::new(-0.1, 0.0),
            friction: 0.5,
        }];
        let b = Body::new(1.0, 0.01, Vec2::new(-0.1, 0.0), &sup).unwrap();
        let push = Push {
            duration: 1.0,
            speed: 0.4,
            phi: std::f64::consts::PI - 0.3,
        };
        let seg = SegmentDynamics::new(&b, &push);
        let rate = seg.inertial_slope() / seg.inertia_contact();
        assert!(rate > 0.0, "{rate}");
        assert!(seg.attractor_from(0.2).is_none());
        for t in [0.01, 0.3, 2.0] {
            let want = 0.2 * (rate * t).exp();
            let got = seg.advance(0.2, t).unwrap();
            assert!((got - want).abs() < 1e-8 * want, "t {t}: {got} vs {want}");
        }
    }

    /// A support whose sliding velocity is exactly zero contributes nothing,
    /// whichever pair slot it sits in, and the sum stays finite.
    #[test]
    fn a_support_at_rest_contributes_nothing() {
        // Contact at (−0.1, −0.05); push along +x at 1 m/s (φ = 0). A support
        // at r = (0, 0.5) relative to the contact has u = (1 − 0.5 ω, 0),
        // which vanishes at ω = 2 rad/s.
        let rest = (-0.1, 0.45);
        let others = [
            (0.1, 0.1),
            (0.05, -0.1),
            (-0.05, 0.2),
            (0.2, 0.0),
            (0.0, 0.0),
        ];
        let push = Push {
            duration: 1.0,
            speed: 1.0,
            phi: 0.0,
        };
        for slot in 0..5 {
            let mut pts = others.to_vec();
            pts.insert(slot, rest);
            let b = body(&pts);
            let seg = SegmentDynamics::new(&b, &push);
            let got = seg.friction_moment_at(1.0, 2.0);
            let want = moment_by_definition(&b, &push, 2.0);
            assert!(got.is_finite(), "slot {slot}: {got}");
            assert!(
                (got - want).abs() <= 1e-14 * seg.max_moment(),
                "slot {slot}: {got} against {want}"
            );
        }
    }

    /// The Taylor coefficients of ω̇ against ω̇ itself: the constant term,
    /// the slope against the analytic `G'` of [`SegmentDynamics::moment_slope`],
    /// the curvature against a central difference, and the whole polynomial
    /// against ω̇ at offsets up to a fifth of the distance to the nearest
    /// complex singularity (`v |n·r| / r²`, where a support's sliding speed
    /// would vanish), where the dropped terms are below 1e-14. One support
    /// sits under the contact (no lever arm).
    #[test]
    fn taylor_coefficients_reproduce_omega_dot() {
        let b = body(&[
            (0.12, 0.03),
            (-0.1, -0.05),
            (0.02, 0.11),
            (-0.09, 0.08),
            (0.05, -0.1),
        ]);
        let push = Push {
            duration: 1.0,
            speed: 0.7,
            phi: 0.4,
        };
        let seg = SegmentDynamics::new(&b, &push);
        let n = push.direction();
        let radius = b
            .supports()
            .map(|s| s.position - b.contact())
            .filter(|r| r.norm() > 0.0)
            .map(|r| push.speed * n.dot(&r).abs() / r.norm_squared())
            .fold(f64::INFINITY, f64::min);
        let scale = seg.max_moment() / seg.inertia_contact();
        let mut c = [0.0; 21];
        for omega in [-3.0, -0.4, 0.0, 0.9, 4.0] {
            seg.omega_dot_taylor(omega, &mut c);
            assert!(
                (c[0] - seg.omega_dot(omega)).abs() <= 1e-14 * scale,
                "ω {omega}: g"
            );
            let slope = seg.moment_slope(omega) / seg.inertia_contact();
            assert!(
                (c[1] - slope).abs() <= 1e-12 * slope.abs().max(scale),
                "ω {omega}: g'"
            );
            let h = 1e-3 * radius;
            let g = |w: f64| seg.omega_dot(w);
            let g2 = (g(omega + h) - 2.0 * g(omega) + g(omega - h)) / (h * h);
            assert!(
                (g2 - 2.0 * c[2]).abs() <= 1e-5 * g2.abs().max(scale / radius),
                "ω {omega}: g''"
            );
            for d in [-0.2, -0.05, 0.05, 0.2].map(|f| f * radius) {
                let series: f64 = c.iter().rev().fold(0.0, |acc, cj| acc * d + cj);
                assert!(
                    (series - g(omega + d)).abs() <= 1e-12 * scale,
                    "ω {omega}, d {d}: {series} against {}",
                    g(omega + d)
                );
            }
        }
    }
}
