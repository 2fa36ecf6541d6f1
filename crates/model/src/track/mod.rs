//! Online friction estimation: streaming estimators of the friction
//! parameters of a pushed object, and the resultant friction force that
//! follows from them.
//!
//! Each new pose sample `(t, x, y, θ)` (optionally ω and the pusher force)
//! updates estimates of the parameter vector
//!
//! ```text
//! p = [mu_scale, c_x, c_y, I_cm]
//! ```
//!
//! with its covariance: a factor on every support's friction (1 = as in the
//! problem), the centre of friction `c` (m, relative to the centre of mass)
//! and the inertia about the centre of mass (kg m²).
//!
//! # Parametrisation of the centre of friction
//!
//! The support friction magnitudes `F_i = μ_i N_i` of the problem are moved
//! to the least-change magnitudes (least squares in N) that keep `Σ F_i` and
//! put `Σ F_i p_i / Σ F_i` at `c`:
//!
//! ```text
//! F_i(p) = mu_scale · (F0_i + g_i · (c − c0)),   g = T Aᵀ (A Aᵀ)⁻¹ [e_2 e_3],
//! A = [1; p_x; p_y] (3 × n),  T = Σ F0_i
//! ```
//!
//! which is affine in `c`. With one μ for every support this is the same
//! load shift as `pushval fit`'s `center_of_friction`. It needs at least
//! three supports not on one line.
//!
//! # Methods
//!
//! * [`Ekf`] (the default): an extended Kalman filter whose state is the
//!   pose, ω and the four parameters; it predicts with the dynamic model
//!   (RK4 on the state and its sensitivity, impulsive switches included) and
//!   corrects with each sample. What it uses is exactly what `pushval fit`
//!   uses (the pose), so its covariance can be set against the Fisher
//!   information's Cramér–Rao bound.
//! * [`Rls`]: recursive least squares on the Newton–Euler moment balance
//!   about the contact point, linear in `[mu_scale, mu_scale·(c − c0), I_cm]`,
//!   with ω and ω̇ from a local quadratic fit to θ over a sliding window.
//!
//! Neither allocates per update: every buffer is sized when the estimator is
//! built. This module does no I/O.

mod ekf;
mod resultant;
mod rls;

pub use ekf::{Ekf, EkfSettings};
pub use resultant::{Resultant, ResultantStd};
pub use rls::{Rls, RlsSettings};

use crate::{cross, perp, rotate, Initial, ModelError, Problem, Switching, Vec2};

/// Index of `mu_scale` in the parameter vector.
pub const MU: usize = 0;
/// Index of the centre of friction's x (m, from the centre of mass).
pub const CX: usize = 1;
/// Index of the centre of friction's y (m, from the centre of mass).
pub const CY: usize = 2;
/// Index of `inertia_cm` (kg m²).
pub const INERTIA: usize = 3;

/// Which parameters an estimator frees; the others stay at the problem's
/// values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Free {
    /// Estimate `mu_scale`.
    pub mu_scale: bool,
    /// Estimate the centre of friction.
    pub center_of_friction: bool,
    /// Estimate `inertia_cm`.
    pub inertia_cm: bool,
}

impl Default for Free {
    /// All three.
    fn default() -> Self {
        Self {
            mu_scale: true,
            center_of_friction: true,
            inertia_cm: true,
        }
    }
}

impl Free {
    /// Per parameter component (`MU`, `CX`, `CY`, `INERTIA`): free or not.
    pub fn mask(&self) -> [bool; 4] {
        [
            self.mu_scale,
            self.center_of_friction,
            self.center_of_friction,
            self.inertia_cm,
        ]
    }
}

/// One sample of a tracked object.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Measurement {
    /// Time (s) from the start of the first push.
    pub t: f64,
    /// World x of the centre of mass (m).
    pub x: f64,
    /// World y of the centre of mass (m).
    pub y: f64,
    /// Object angle, unwrapped (rad).
    pub theta: f64,
    /// Angular velocity (rad/s), if measured.
    pub omega: Option<f64>,
    /// Pusher force on the object in the world frame (N), if measured.
    pub force: Option<Vec2>,
}

/// An estimate: values and covariance of `[mu_scale, c_x, c_y, I_cm]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// `[mu_scale (1), c_x (m), c_y (m), I_cm (kg m²)]`, the centre of
    /// friction relative to the centre of mass.
    pub value: [f64; 4],
    /// Their covariance (units the products of theirs); zero rows and
    /// columns for fixed parameters.
    pub covariance: [[f64; 4]; 4],
}

impl Estimate {
    /// Standard deviation of each component (0 for a fixed one).
    pub fn std(&self) -> [f64; 4] {
        std::array::from_fn(|i| self.covariance[i][i].max(0.0).sqrt())
    }
}

/// What one update saw.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UpdateReport {
    /// Normalised innovation squared of this sample, `νᵀ S⁻¹ ν` (a χ² with
    /// `dof` degrees of freedom when the model and the stated noise hold).
    pub nis: f64,
    /// Measurement components used.
    pub dof: usize,
    /// The running test over the last window of samples rejects the model
    /// at this sample (see [`LackOfFit`]).
    pub lack_of_fit: bool,
}

/// A streaming estimator of the friction parameters.
pub trait Estimator {
    /// A short name (`"ekf"`, `"rls"`).
    fn name(&self) -> &'static str;
    /// Takes one sample (times strictly increasing, within the schedule).
    fn update(&mut self, m: &Measurement) -> Result<UpdateReport, TrackError>;
    /// The current estimate.
    fn estimate(&self) -> Estimate;
    /// The current angular velocity estimate (rad/s) and its variance.
    fn omega(&self) -> (f64, f64);
    /// The model it runs.
    fn model(&self) -> &TrackModel;
    /// The time (s) the ω estimate refers to.
    fn time(&self) -> f64;
    /// Covariance of `[ω, mu_scale, c_x, c_y]` (default: ω uncorrelated
    /// with the parameters).
    fn friction_covariance(&self) -> [[f64; 4]; 4] {
        let e = self.estimate();
        let (_, wv) = self.omega();
        std::array::from_fn(|a| {
            std::array::from_fn(|b| match (a, b) {
                (0, 0) => wv,
                (0, _) | (_, 0) => 0.0,
                _ => e.covariance[a - 1][b - 1],
            })
        })
    }
    /// The resultant friction force now, with its std.
    fn resultant(&self) -> (Resultant, ResultantStd) {
        let md = self.model();
        let v = md.pusher_velocity(self.time());
        let (w, _) = self.omega();
        let e = self.estimate();
        Resultant::with_std(md, v, w, &e.value, &self.friction_covariance())
    }
}

/// Why an update was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TrackError {
    /// Time did not increase.
    #[error("t = {t} s does not follow the previous sample's {previous} s")]
    TimeOrder {
        /// The sample's time (s).
        t: f64,
        /// The previous sample's time (s).
        previous: f64,
    },
    /// The sample lies outside the push schedule.
    #[error("t = {t} s is outside the push schedule [0, {end}] s")]
    OutsideSchedule {
        /// The sample's time (s).
        t: f64,
        /// The schedule's end (s).
        end: f64,
    },
    /// A value is not finite.
    #[error("{name} = {value} is not finite")]
    NotFinite {
        /// Which value.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// The filter's state left the finite numbers.
    #[error("the estimate became non-finite at t = {t} s")]
    Diverged {
        /// Time (s).
        t: f64,
    },
}

/// One push segment as the estimators use it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Segment {
    pub t_start: f64,
    /// Pusher velocity in the object frame (m/s).
    pub v: Vec2,
}

/// The pushing problem in the form the estimators evaluate: supports, the
/// friction basis of the centre of friction, the schedule and the start.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackModel {
    mass: f64,
    contact: Vec2,
    sx: Vec<f64>,
    sy: Vec<f64>,
    f0: Vec<f64>,
    gx: Vec<f64>,
    gy: Vec<f64>,
    c0: Vec2,
    inertia0: f64,
    size: f64,
    polygon: Vec<Vec2>,
    pub(crate) segments: Vec<Segment>,
    end: f64,
    initial: Initial,
    switching: Switching,
    cof_free: bool,
}

/// Friction of every support at `p`, and the pieces the derivatives need.
#[derive(Debug, Clone, Copy, PartialEq)]
#[doc(hidden)]
pub struct Rates {
    /// ω̇ (rad/s²).
    pub omega_dot: f64,
    /// ∂ω̇/∂ω.
    pub d_omega: f64,
    /// ∂ω̇/∂p, p = [mu_scale, c_x, c_y, I_cm].
    pub d_param: [f64; 4],
}

impl TrackModel {
    /// The problem's body, schedule and start; `polygon` is the outline
    /// relative to the centre of mass (m), for the friction point.
    pub fn new(problem: &Problem, polygon: &[Vec2]) -> Result<Self, ModelError> {
        problem.check()?;
        let body = &problem.body;
        let n = body.len();
        let (sx, sy, f0) = {
            let (x, y, f) = body.arrays();
            (x.to_vec(), y.to_vec(), f.to_vec())
        };
        let total: f64 = f0.iter().sum();
        let c0 = body.center_of_friction();
        // g = T Aᵀ (A Aᵀ)⁻¹ [e_2 e_3], A = [1; p_x; p_y].
        let mut m = [[0.0; 3]; 3];
        for i in 0..n {
            let a = [1.0, sx[i], sy[i]];
            for r in 0..3 {
                for s in 0..3 {
                    m[r][s] += a[r] * a[s];
                }
            }
        }
        let (mut gx, mut gy) = (vec![0.0; n], vec![0.0; n]);
        let cof_free = match invert3(&m) {
            Some(inv) => {
                for i in 0..n {
                    let a = [1.0, sx[i], sy[i]];
                    for r in 0..3 {
                        gx[i] += total * a[r] * inv[r][1];
                        gy[i] += total * a[r] * inv[r][2];
                    }
                }
                true
            }
            None => false,
        };
        let size = (0..n)
            .map(|i| Vec2::new(sx[i], sy[i]).norm())
            .chain(std::iter::once(body.contact().norm()))
            .fold(1e-3f64, f64::max);
        let mut t = 0.0;
        let segments = problem
            .pushes
            .iter()
            .map(|p| {
                let s = Segment {
                    t_start: t,
                    v: p.velocity(),
                };
                t += p.duration;
                s
            })
            .collect();
        Ok(Self {
            mass: body.mass(),
            contact: body.contact(),
            sx,
            sy,
            f0,
            gx,
            gy,
            c0,
            inertia0: body.inertia_cm(),
            size,
            polygon: polygon.to_vec(),
            segments,
            end: t,
            initial: problem.initial,
            switching: problem.switching,
            cof_free,
        })
    }

    /// The model with no pushes yet, for pushes decided online: each is
    /// appended with [`TrackModel::extend`] as it is applied, before any
    /// sample it acts on is given to an estimator. `problem`'s schedule is
    /// ignored (its body, start and switching rule are used).
    pub fn online(problem: &Problem, polygon: &[Vec2]) -> Result<Self, ModelError> {
        let mut m = Self::new(problem, polygon)?;
        m.segments.clear();
        m.end = 0.0;
        Ok(m)
    }

    /// Appends a push applied after the last one: pusher velocity `v`
    /// (object frame, m/s) for `duration` s. A push with the velocity of the
    /// one before it continues that one (no switch).
    pub fn extend(&mut self, v: Vec2, duration: f64) {
        if !(duration > 0.0) {
            return;
        }
        if self.segments.last().is_none_or(|s| s.v != v) {
            self.segments.push(Segment {
                t_start: self.end,
                v,
            });
        }
        self.end += duration;
    }

    /// The problem's own parameter values `[1, c0_x, c0_y, I_cm]`.
    pub fn nominal(&self) -> [f64; 4] {
        [1.0, self.c0.x, self.c0.y, self.inertia0]
    }

    /// Whether the supports can carry a centre of friction other than the
    /// problem's (at least three, not on one line).
    pub fn center_of_friction_free(&self) -> bool {
        self.cof_free
    }

    /// The farthest support or contact from the centre of mass (m), at
    /// least 1 mm: the scale of the centre of friction.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// Mass (kg).
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// Contact point relative to the centre of mass (m).
    pub fn contact(&self) -> Vec2 {
        self.contact
    }

    /// End of the schedule (s).
    pub fn end(&self) -> f64 {
        self.end
    }

    /// The outline relative to the centre of mass (m).
    pub fn polygon(&self) -> &[Vec2] {
        &self.polygon
    }

    /// Support `i`'s position relative to the centre of mass (m).
    pub fn support_position(&self, i: usize) -> Vec2 {
        Vec2::new(self.sx[i], self.sy[i])
    }

    /// Number of supports.
    pub fn supports(&self) -> usize {
        self.sx.len()
    }

    /// Support `i`'s friction magnitude `F_i` (N) at parameters `p`.
    #[inline]
    pub fn support_friction(&self, i: usize, p: &[f64; 4]) -> f64 {
        p[MU] * (self.f0[i] + self.gx[i] * (p[CX] - self.c0.x) + self.gy[i] * (p[CY] - self.c0.y))
    }

    /// The segment in force at `t` (the later one at a switch time).
    pub(crate) fn segment_at(&self, t: f64) -> usize {
        let mut k = 0;
        while k + 1 < self.segments.len() && self.segments[k + 1].t_start <= t {
            k += 1;
        }
        k
    }

    /// ω̇ and its derivatives at ω under pusher velocity `v` (object frame).
    ///
    /// The model's equations ([`crate::SegmentDynamics::omega_dot`]) written
    /// again, because the filter needs ∂ω̇/∂ω and ∂ω̇/∂p with ω̇ in one pass
    /// over the supports, with the parameters free; the test
    /// `filter_rates_are_the_models_right_hand_side` (tests/track.rs) holds
    /// this and [`TrackModel::rates_q`] to the model at random states and
    /// parameters (1e-12 relative).
    #[doc(hidden)]
    pub fn rates(&self, v: Vec2, omega: f64, p: &[f64; 4]) -> Rates {
        let pc = self.contact;
        let scale = v.norm() + omega.abs() * self.size;
        let floor = 1e-12 * scale.max(1e-12);
        // M_c = −Σ F_i w_i, w_i = r_i × û_i.
        let (mut m, mut dm_w) = (0.0, 0.0);
        let (mut s_q, mut s_gx, mut s_gy) = (0.0, 0.0, 0.0);
        for i in 0..self.sx.len() {
            let r = Vec2::new(self.sx[i] - pc.x, self.sy[i] - pc.y);
            let dr = perp(&r);
            let u = v + dr * omega;
            let len = u.norm().max(floor);
            let uh = u / len;
            let w = cross(&r, &uh);
            // ∂û/∂ω = (D r − û (û·D r)) / |u|
            let duh = (dr - uh * uh.dot(&dr)) / len;
            let dw = cross(&r, &duh);
            let q =
                self.f0[i] + self.gx[i] * (p[CX] - self.c0.x) + self.gy[i] * (p[CY] - self.c0.y);
            let f = p[MU] * q;
            m -= f * w;
            dm_w -= f * dw;
            s_q += q * w;
            s_gx += self.gx[i] * w;
            s_gy += self.gy[i] * w;
        }
        let ip = p[INERTIA] + self.mass * pc.norm_squared();
        let k = self.mass * pc.dot(&v);
        let omega_dot = (m + k * omega) / ip;
        Rates {
            omega_dot,
            d_omega: (dm_w + k) / ip,
            d_param: [
                -s_q / ip,
                -p[MU] * s_gx / ip,
                -p[MU] * s_gy / ip,
                -omega_dot / ip,
            ],
        }
    }

    /// ω̇ and its derivatives in the filter's coordinates
    /// `q = [γ₀, γ₁, γ₂, ζ] = [μ ζ, μ (c − c0) ζ, 1 / I_P]`, in which
    /// `ω̇ = −Σ_i w_i(ω) (γ₀ F0_i + γ₁ gx_i + γ₂ gy_i) + m (p_c · v) ω ζ` is
    /// linear: `d_param` is `∂ω̇/∂q`.
    #[doc(hidden)]
    pub fn rates_q(&self, v: Vec2, omega: f64, q: &[f64; 4]) -> Rates {
        let pc = self.contact;
        let scale = v.norm() + omega.abs() * self.size;
        let floor = 1e-12 * scale.max(1e-12);
        let (mut s0, mut s1, mut s2, mut dw_sum) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..self.sx.len() {
            let r = Vec2::new(self.sx[i] - pc.x, self.sy[i] - pc.y);
            let dr = perp(&r);
            let u = v + dr * omega;
            let len = u.norm().max(floor);
            let uh = u / len;
            let w = cross(&r, &uh);
            let duh = (dr - uh * uh.dot(&dr)) / len;
            let dw = cross(&r, &duh);
            s0 += self.f0[i] * w;
            s1 += self.gx[i] * w;
            s2 += self.gy[i] * w;
            dw_sum += (q[0] * self.f0[i] + q[1] * self.gx[i] + q[2] * self.gy[i]) * dw;
        }
        let k = self.mass * pc.dot(&v);
        Rates {
            omega_dot: -(q[0] * s0 + q[1] * s1 + q[2] * s2) + k * omega * q[3],
            d_omega: -dw_sum + k * q[3],
            d_param: [-s0, -s1, -s2, k * omega],
        }
    }

    /// `I_P = I_cm + m |p_c|²` (kg m²).
    fn inertia_contact(&self, inertia_cm: f64) -> f64 {
        inertia_cm + self.mass * self.contact.norm_squared()
    }

    /// The filter's coordinates `q` of parameters `p`, and `∂q/∂p`.
    #[doc(hidden)]
    pub fn to_q(&self, p: &[f64; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
        let zeta = 1.0 / self.inertia_contact(p[INERTIA]);
        let dz = -zeta * zeta;
        let (dx, dy) = (p[CX] - self.c0.x, p[CY] - self.c0.y);
        let mu = p[MU];
        let q = [mu * zeta, mu * dx * zeta, mu * dy * zeta, zeta];
        let j = [
            [zeta, 0.0, 0.0, mu * dz],
            [dx * zeta, mu * zeta, 0.0, mu * dx * dz],
            [dy * zeta, 0.0, mu * zeta, mu * dy * dz],
            [0.0, 0.0, 0.0, dz],
        ];
        (q, j)
    }

    /// The parameters `p` of filter coordinates `q`, and `∂p/∂q`.
    #[doc(hidden)]
    pub fn from_q(&self, q: &[f64; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
        let [g0, g1, g2, zeta] = *q;
        let p = [
            g0 / zeta,
            self.c0.x + g1 / g0,
            self.c0.y + g2 / g0,
            1.0 / zeta - self.mass * self.contact.norm_squared(),
        ];
        let j = [
            [1.0 / zeta, 0.0, 0.0, -g0 / (zeta * zeta)],
            [-g1 / (g0 * g0), 1.0 / g0, 0.0, 0.0],
            [-g2 / (g0 * g0), 0.0, 1.0 / g0, 0.0],
            [0.0, 0.0, 0.0, -1.0 / (zeta * zeta)],
        ];
        (p, j)
    }

    /// The jump of ω at a switch from `before` (None: at rest) to segment
    /// `after`, and its derivative: with the impulsive rule the angular momentum about the contact is kept,
    /// `ω⁺ = ω⁻ + m p_c × (v⁺ − v⁻) / I_P`; the derivative is with respect
    /// to `ζ = 1 / I_P`.
    pub(crate) fn switch_jump(&self, before: Option<usize>, after: usize, zeta: f64) -> (f64, f64) {
        if self.switching == Switching::Continuous {
            return (0.0, 0.0);
        }
        let vb = before.map_or(Vec2::zeros(), |k| self.segments[k].v);
        let dv = self.segments[after].v - vb;
        let h = self.mass * cross(&self.contact, &dv);
        (h * zeta, h)
    }

    /// The start state `[x, y, θ, ω]` before the first push takes effect,
    /// and whether the object starts at rest (the first push is then a
    /// switch from rest).
    pub(crate) fn start(&self) -> ([f64; 4], bool) {
        let i = &self.initial;
        let omega = if i.from_rest { 0.0 } else { i.omega };
        ([i.position.x, i.position.y, i.theta, omega], i.from_rest)
    }

    /// World velocity of the centre of mass (m/s) at angle θ and ω under
    /// pusher velocity `v`: `R(θ) (v − ω D p_c)`.
    #[inline]
    pub(crate) fn cm_velocity(&self, v: Vec2, theta: f64, omega: f64) -> Vec2 {
        rotate(theta, &(v - perp(&self.contact) * omega))
    }

    /// Sum of the support friction forces (object frame, N) and their
    /// moment about the centre of mass (N m) at ω under `v` and `p`.
    pub fn friction(&self, v: Vec2, omega: f64, p: &[f64; 4]) -> (Vec2, f64) {
        let pc = self.contact;
        let scale = v.norm() + omega.abs() * self.size;
        let floor = 1e-12 * scale.max(1e-12);
        let mut force = Vec2::zeros();
        let mut moment = 0.0;
        for i in 0..self.sx.len() {
            let pi = Vec2::new(self.sx[i], self.sy[i]);
            let u = v + perp(&(pi - pc)) * omega;
            let len = u.norm();
            if len <= floor {
                continue;
            }
            let f = -u * (self.support_friction(i, p) / len);
            force += f;
            moment += cross(&pi, &f);
        }
        (force, moment)
    }

    /// The pusher force on the object in the world frame (N): `m a_cm − R Σ f_i`,
    /// with `a_cm = R (ω D v − ω̇ D p_c + ω² p_c)`.
    pub(crate) fn pusher_force(&self, v: Vec2, theta: f64, omega: f64, p: &[f64; 4]) -> Vec2 {
        let r = self.rates(v, omega, p);
        let pc = self.contact;
        let a = perp(&v) * omega - perp(&pc) * r.omega_dot + pc * (omega * omega);
        let (f, _) = self.friction(v, omega, p);
        rotate(theta, &(a * self.mass - f))
    }

    /// The schedule's segment velocity (object frame, m/s) at `t`.
    pub fn pusher_velocity(&self, t: f64) -> Vec2 {
        self.segments[self.segment_at(t)].v
    }
}

/// The running lack-of-fit test: the sum of the normalised innovations
/// squared over the last `window` samples against the upper `alpha` quantile
/// of χ² with their total degrees of freedom (Wilson–Hilferty). Holds a
/// fixed ring buffer (no allocation per sample).
#[derive(Debug, Clone, PartialEq)]
pub struct LackOfFit {
    nis: Vec<f64>,
    dof: Vec<usize>,
    next: usize,
    filled: usize,
    /// The standard normal quantile of `1 − alpha`.
    z: f64,
}

impl LackOfFit {
    /// A test over `window` samples (≥ 1) at standard normal quantile `z`
    /// (4.75 ≈ a false alarm rate of 1e-6 per window).
    pub fn new(window: usize, z: f64) -> Self {
        let window = window.max(1);
        Self {
            nis: vec![0.0; window],
            dof: vec![0; window],
            next: 0,
            filled: 0,
            z,
        }
    }

    /// Adds one sample's NIS; true when the window is full and rejects.
    pub fn push(&mut self, nis: f64, dof: usize) -> bool {
        self.nis[self.next] = nis;
        self.dof[self.next] = dof;
        self.next = (self.next + 1) % self.nis.len();
        self.filled = (self.filled + 1).min(self.nis.len());
        if self.filled < self.nis.len() {
            return false;
        }
        let sum: f64 = self.nis.iter().sum();
        let k: usize = self.dof.iter().sum();
        !(sum <= chi2_quantile(k as f64, self.z))
    }

    /// Empties the window (after the estimator re-opened its parameters).
    pub fn clear(&mut self) {
        self.filled = 0;
    }

    /// Mean NIS per degree of freedom over the filled part of the window.
    pub fn mean(&self) -> f64 {
        let n = self.filled;
        let idx = |j: usize| (self.next + self.nis.len() - 1 - j) % self.nis.len();
        let s: f64 = (0..n).map(|j| self.nis[idx(j)]).sum();
        let k: usize = (0..n).map(|j| self.dof[idx(j)]).sum();
        s / k.max(1) as f64
    }
}

/// Upper quantile of χ² with `k` degrees of freedom at standard normal
/// quantile `z` (Wilson & Hilferty 1931): `k (1 − 2/(9k) + z √(2/(9k)))³`.
pub fn chi2_quantile(k: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

fn invert3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c = |r: usize, s: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (s1, s2) = ((s + 1) % 3, (s + 2) % 3);
        m[r1][s1] * m[r2][s2] - m[r1][s2] * m[r2][s1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let scale = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    if !(det.abs() > 1e-12 * scale.powi(3)) {
        return None;
    }
    let mut inv = [[0.0; 3]; 3];
    for (r, row) in inv.iter_mut().enumerate() {
        for (s, v) in row.iter_mut().enumerate() {
            *v = c(s, r) / det;
        }
    }
    Some(inv)
}
