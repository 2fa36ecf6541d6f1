//! Recursive least squares on the Newton–Euler moment balance.

use nalgebra::{SMatrix, SVector};

use super::{
    Estimate, Estimator, Free, Measurement, TrackError, TrackModel, UpdateReport, CX, CY, INERTIA,
    MU,
};
use crate::{cross, perp, Vec2};

type Mat4 = SMatrix<f64, 4, 4>;
type Vec4 = SVector<f64, 4>;

/// How the least-squares estimator smooths and starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RlsSettings {
    /// Samples in the local quadratic fit to θ that gives ω and ω̇ at its
    /// middle sample (odd, ≥ 5). Default 21.
    pub window: usize,
    /// Noise of θ (rad), for the std of ω only. Default 1e-3.
    pub sigma_theta: f64,
    /// Forgetting factor per equation, in (0, 1]. Default 1 (none).
    pub forgetting: f64,
}

impl Default for RlsSettings {
    fn default() -> Self {
        Self {
            window: 21,
            sigma_theta: 1e-3,
            forgetting: 1.0,
        }
    }
}

/// Recursive least squares on the moment balance about the contact point,
///
/// ```text
/// I_cm ω̇ + Σ_i w_i(ω) (β₀ F0_i + β₁ gx_i + β₂ gy_i) = m ω (p_c · v) − m |p_c|² ω̇,
/// w_i = (p_i − p_c) × û_i,   β = [mu_scale, mu_scale (c − c0)]
/// ```
///
/// linear in `[β, I_cm]`. ω and ω̇ come from a least-squares quadratic in
/// time fitted to θ over the last [`RlsSettings::window`] samples (so the
/// equation is for the window's middle sample, half a window late); windows
/// across a switch are skipped. The covariance is `s² P` with `s²` the
/// running mean squared residual of the equation (its noise is unknown: it
/// comes from differentiating noisy θ twice). Noise in the regressor ω̇
/// biases `I_cm` towards zero (errors in variables); the measurements show
/// how much.
#[derive(Debug, Clone)]
pub struct Rls {
    model: TrackModel,
    settings: RlsSettings,
    free: [bool; 4],
    beta: Vec4,
    p: Mat4,
    ring_t: Vec<f64>,
    ring_theta: Vec<f64>,
    next: usize,
    filled: usize,
    last_t: Option<f64>,
    sum_e2: f64,
    equations: usize,
    omega: f64,
    omega_var: f64,
    omega_time: f64,
}

impl Rls {
    /// An estimator starting from the problem's values.
    pub fn new(model: TrackModel, free: Free, settings: RlsSettings) -> Self {
        let mut free = free.mask();
        if !model.center_of_friction_free() {
            free[CX] = false;
            free[CY] = false;
        }
        let nominal = model.nominal();
        let scale = [1.0, model.size(), model.size(), nominal[INERTIA]];
        let mut p = Mat4::zeros();
        for j in 0..4 {
            if free[j] {
                // Uninformative: a thousand times each parameter's scale.
                p[(j, j)] = (1e3 * scale[j]).powi(2);
            }
        }
        let w = (settings.window.max(5)) | 1;
        Self {
            beta: Vec4::new(1.0, 0.0, 0.0, nominal[INERTIA]),
            model,
            settings: RlsSettings {
                window: w,
                ..settings
            },
            free,
            p,
            ring_t: vec![0.0; w],
            ring_theta: vec![0.0; w],
            next: 0,
            filled: 0,
            last_t: None,
            sum_e2: 0.0,
            equations: 0,
            omega: 0.0,
            omega_var: f64::INFINITY,
            omega_time: 0.0,
        }
    }

    /// Least-squares ω and ω̇ at the window's middle sample, with the
    /// middle time; None across a switch.
    fn window_fit(&self) -> Option<(f64, f64, f64, f64)> {
        let w = self.ring_t.len();
        let idx = |j: usize| (self.next + j) % w; // oldest first
        let (t_first, t_last) = (self.ring_t[idx(0)], self.ring_t[idx(w - 1)]);
        if self.model.segment_at(t_first) != self.model.segment_at(t_last) {
            return None;
        }
        let tc = self.ring_t[idx(w / 2)];
        let th0 = self.ring_theta[idx(w / 2)];
        let mut s = [0.0; 5];
        let mut b = [0.0; 3];
        for j in 0..w {
            let tau = self.ring_t[idx(j)] - tc;
            let th = self.ring_theta[idx(j)] - th0;
            let mut pw = 1.0;
            for (k, sk) in s.iter_mut().enumerate() {
                *sk += pw;
                if k < 3 {
                    b[k] += pw * th;
                }
                pw *= tau;
            }
        }
        let m = Mat3::new(s[0], s[1], s[2], s[1], s[2], s[3], s[2], s[3], s[4]);
        let inv = m.try_inverse()?;
        let c = inv * Vec3::new(b[0], b[1], b[2]);
        Some((
            tc,
            c[1],
            2.0 * c[2],
            inv[(1, 1)] * self.settings.sigma_theta.powi(2),
        ))
    }
}

type Mat3 = SMatrix<f64, 3, 3>;
type Vec3 = SVector<f64, 3>;

impl Estimator for Rls {
    fn name(&self) -> &'static str {
        "rls"
    }

    fn update(&mut self, m: &Measurement) -> Result<UpdateReport, TrackError> {
        for (name, v) in [("t", m.t), ("theta", m.theta)] {
            if !v.is_finite() {
                return Err(TrackError::NotFinite { name, value: v });
            }
        }
        if let Some(prev) = self.last_t {
            if !(m.t > prev) {
                return Err(TrackError::TimeOrder {
                    t: m.t,
                    previous: prev,
                });
            }
        }
        let end = self.model.end();
        if m.t < -1e-9 * end.max(1.0) || m.t > end * (1.0 + 1e-9) + 1e-12 {
            return Err(TrackError::OutsideSchedule { t: m.t, end });
        }
        self.last_t = Some(m.t);
        let w = self.ring_t.len();
        self.ring_t[self.next] = m.t;
        self.ring_theta[self.next] = m.theta;
        self.next = (self.next + 1) % w;
        self.filled = (self.filled + 1).min(w);
        if self.filled < w {
            return Ok(UpdateReport::default());
        }
        let Some((tc, omega, omega_dot, omega_var)) = self.window_fit() else {
            return Ok(UpdateReport::default());
        };
        self.omega = omega;
        self.omega_var = omega_var;
        self.omega_time = tc;
        let md = &self.model;
        let v = md.pusher_velocity(tc);
        let pc = md.contact();
        let (mut r0, mut r1, mut r2) = (0.0, 0.0, 0.0);
        let nominal = md.nominal();
        let c0 = Vec2::new(nominal[CX], nominal[CY]);
        let unit = [1.0, c0.x, c0.y, nominal[INERTIA]];
        for i in 0..md.supports() {
            // F0_i, gx_i, gy_i through support_friction at unit steps of
            // the parameters (it is affine in them).
            let f0 = md.support_friction(i, &unit);
            let gx = md.support_friction(i, &[1.0, c0.x + 1.0, c0.y, 0.0]) - f0;
            let gy = md.support_friction(i, &[1.0, c0.x, c0.y + 1.0, 0.0]) - f0;
            let pi = md.support_position(i);
            let r = pi - pc;
            let u = v + perp(&r) * omega;
            let len = u.norm();
            if len <= 0.0 {
                continue;
            }
            let wi = cross(&r, &u) / len;
            r0 += wi * f0;
            r1 += wi * gx;
            r2 += wi * gy;
        }
        let mass = md.mass();
        let phi = Vec4::new(r0, r1, r2, omega_dot);
        let mut y = mass * omega * pc.dot(&v) - mass * pc.norm_squared() * omega_dot;
        // Fixed components move to the right-hand side.
        let mut phi_free = phi;
        for j in 0..4 {
            if !self.free[j] {
                y -= phi[j] * self.beta[j];
                phi_free[j] = 0.0;
            }
        }
        let lam = self.settings.forgetting;
        let pphi = self.p * phi_free;
        let denom = lam + phi_free.dot(&pphi);
        let k = pphi / denom;
        let e = y - phi_free.dot(&self.beta_free());
        self.beta += k * e;
        self.p = (self.p - k * pphi.transpose()) / lam;
        self.p = (self.p + self.p.transpose()) * 0.5;
        let e_post = y - phi_free.dot(&self.beta_free());
        self.sum_e2 = lam * self.sum_e2 + e_post * e_post;
        self.equations += 1;
        if !self.beta.iter().all(|v| v.is_finite()) {
            return Err(TrackError::Diverged { t: m.t });
        }
        Ok(UpdateReport::default())
    }

    fn estimate(&self) -> Estimate {
        let b = self.beta;
        let nominal = self.model.nominal();
        let mu = b[0];
        let value = [mu, nominal[CX] + b[1] / mu, nominal[CY] + b[2] / mu, b[3]];
        let dof = self.equations.saturating_sub(4).max(1) as f64;
        let s2 = if self.equations > 4 {
            self.sum_e2 / dof
        } else {
            f64::INFINITY
        };
        let cov_b = self.p * s2;
        let mut jac = Mat4::identity();
        jac[(CX, MU)] = -b[1] / (mu * mu);
        jac[(CX, CX)] = 1.0 / mu;
        jac[(CY, MU)] = -b[2] / (mu * mu);
        jac[(CY, CY)] = 1.0 / mu;
        let cov = jac * cov_b * jac.transpose();
        Estimate {
            value,
            covariance: std::array::from_fn(|a| {
                std::array::from_fn(|c| {
                    if self.free[a] && self.free[c] {
                        cov[(a, c)]
                    } else {
                        0.0
                    }
                })
            }),
        }
    }

    fn omega(&self) -> (f64, f64) {
        (self.omega, self.omega_var)
    }

    fn model(&self) -> &TrackModel {
        &self.model
    }

    fn time(&self) -> f64 {
        self.omega_time
    }
}

impl Rls {
    fn beta_free(&self) -> Vec4 {
        let mut b = self.beta;
        for j in 0..4 {
            if !self.free[j] {
                b[j] = 0.0;
            }
        }
        b
    }
}
