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
//! [`SegmentDynamics`] holds the per-support sums every method reads; its
//! methods are split by what they answer: here ω̇ itself and the forces,
//! `taylor` its series about a point, `roots` the steady states and their
//! stability, `transient` ω's relaxation over a segment. The submodules
//! read the struct's private fields as its children.

mod roots;
mod taylor;
mod transient;

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

    /// [`SegmentDynamics::reset_along`] for another push on the body `self`
    /// was last reset for, with the same reading of the inertial term: only
    /// what depends on the push is recomputed (the speed, the direction,
    /// `k` and the `s_i`); the per-support arrays of the body stay. The
    /// result is the one `reset_along` gives, bit for bit.
    pub(crate) fn repush(&mut self, push: &Push, dir: Vec2, term: InertialTerm) {
        let sign = match term {
            InertialTerm::Derived => 1.0,
            InertialTerm::Flipped => -1.0,
        };
        self.speed = push.speed;
        self.dir = dir;
        self.k = sign * self.mass * push.speed * self.contact.dot(&dir);
        for ((s, rx), ry) in self.s.iter_mut().zip(&self.rx).zip(&self.ry) {
            *s = cross(&Vec2::new(*rx, *ry), &dir);
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
mod tests;
