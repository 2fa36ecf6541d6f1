//! The extended Kalman filter on the dynamic model.

use nalgebra::{SMatrix, SVector};

use super::{
    Estimate, Estimator, Free, LackOfFit, Measurement, TrackError, TrackModel, UpdateReport,
    INERTIA, MU,
};
use crate::{perp, rotate, Vec2};

type Mat8 = SMatrix<f64, 8, 8>;
type Vec8 = SVector<f64, 8>;
/// The state's sensitivity `∂[x, y, θ, ω] / ∂(state at the interval start)`.
type Sens = [[f64; 8]; 4];

/// How the filter weighs and starts. Every field's default is the command
/// line's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EkfSettings {
    /// Noise of x and y (m). Default 1e-3.
    pub sigma_position: f64,
    /// Noise of θ (rad). Default 1e-3.
    pub sigma_theta: f64,
    /// Noise of a measured ω (rad/s); None: ω samples are not used. Default None.
    pub sigma_omega: Option<f64>,
    /// Noise of each component of a measured pusher force (N); None: force
    /// samples are not used. Default 0.05.
    pub sigma_force: Option<f64>,
    /// Prior std relative to each parameter's scale: `mu_scale` (scale 1),
    /// centre of friction (scale: [`TrackModel::size`]), `inertia_cm`
    /// (scale: the problem's). Default `[0.2, 0.05, 0.2]`.
    pub prior: [f64; 3],
    /// Std of the start state: position (m), θ (rad), ω (rad/s). Default
    /// `[1e-3, 1e-3, 1e-2]`.
    pub initial_std: [f64; 3],
    /// Process noise of ω (rad/s per √s): a random walk that lets the filter
    /// forgive small model errors. Default 0.
    pub omega_noise: f64,
    /// Longest RK4 step of the prediction (s). Default 2.5e-3.
    pub max_step: f64,
    /// Samples in the lack-of-fit window. Default 25.
    pub window: usize,
    /// Standard normal quantile of the lack-of-fit test (4.75: a false alarm
    /// rate of about 1e-6 per window). Default 4.75.
    pub z: f64,
    /// On lack of fit, re-open the free parameters to `reopen_scale` times
    /// their prior std and the pose and ω to their start std (the estimate
    /// can then follow a change such as a new surface). Default true.
    pub reopen: bool,
    /// See `reopen`. Default 1.
    pub reopen_scale: f64,
}

impl Default for EkfSettings {
    fn default() -> Self {
        Self {
            sigma_position: 1e-3,
            sigma_theta: 1e-3,
            sigma_omega: None,
            sigma_force: Some(0.05),
            prior: [0.2, 0.05, 0.2],
            initial_std: [1e-3, 1e-3, 1e-2],
            omega_noise: 0.0,
            max_step: 2.5e-3,
            window: 25,
            z: 4.75,
            reopen: true,
            reopen_scale: 1.0,
        }
    }
}

/// The extended Kalman filter. State `[x, y, θ, ω, γ₀, γ₁, γ₂, ζ]` with
/// `ζ = 1 / I_P` (the inertia about the contact), `γ₀ = mu_scale ζ`,
/// `[γ₁, γ₂] = mu_scale (c − c0) ζ`: in these coordinates ω̇ is linear in the
/// parameters, so the set of parameters a single push cannot tell apart is
/// a straight line the filter's linearisation follows (in
/// `[mu_scale, c, I_cm]` it is curved, and a filter there collapses its
/// covariance across it and locks onto a wrong point). Parameters that are
/// not free are linear constraints on `q` (`ζ` fixed; `γ₁ = γ₂ = 0`;
/// `γ₀ = mu_scale ζ`), kept exactly by a prior covariance without those
/// directions. The parameters have no process noise (they are constants), the
/// pose and ω none either (the model is taken as exact: any mismatch shows
/// up in the lack-of-fit test instead of being absorbed).
///
/// Per sample: RK4 over the interval (steps of at most
/// [`EkfSettings::max_step`], split at switches where ω jumps) on the state
/// and its sensitivity `Φ`, `P ← Φ P Φᵀ`, then one scalar Kalman update per
/// measured component (x, y, θ, and ω or the pusher force when given;
/// independent noise, so sequential scalar updates equal the joint one).
#[derive(Debug, Clone)]
pub struct Ekf {
    model: TrackModel,
    settings: EkfSettings,
    free: [bool; 4],
    prior_var: [f64; 4],
    /// The start values of the parameters (the fixed ones keep them).
    start: [f64; 4],
    s: Vec8,
    p: Mat8,
    time: f64,
    seg: usize,
    started: bool,
    from_rest: bool,
    last_t: Option<f64>,
    test: LackOfFit,
    reopened: usize,
}

impl Ekf {
    /// A filter starting from the problem's values (`start`: other
    /// parameter values, e.g. a previous estimate).
    pub fn new(
        model: TrackModel,
        free: Free,
        settings: EkfSettings,
        start: Option<[f64; 4]>,
    ) -> Self {
        let mut free = free.mask();
        if !model.center_of_friction_free() {
            free[1] = false;
            free[2] = false;
        }
        let nominal = model.nominal();
        let p0 = start.unwrap_or(nominal);
        let scale = [1.0, model.size(), model.size(), nominal[INERTIA]];
        let rel = [
            settings.prior[0],
            settings.prior[1],
            settings.prior[1],
            settings.prior[2],
        ];
        let prior_var: [f64; 4] = std::array::from_fn(|j| (rel[j] * scale[j]).powi(2));
        let (y, from_rest) = model.start();
        let (q0, jq) = model.to_q(&p0);
        let mut s = Vec8::zeros();
        for j in 0..4 {
            s[j] = y[j];
            s[4 + j] = q0[j];
        }
        let mut p = Mat8::zeros();
        let [sp, st, sw] = settings.initial_std;
        p[(0, 0)] = sp * sp;
        p[(1, 1)] = sp * sp;
        p[(2, 2)] = st * st;
        p[(3, 3)] = sw * sw;
        let prior_q = prior_in_q(&jq, &free, &prior_var);
        for a in 0..4 {
            for b in 0..4 {
                p[(4 + a, 4 + b)] = prior_q[a][b];
            }
        }
        let test = LackOfFit::new(settings.window, settings.z);
        Self {
            model,
            settings,
            free,
            prior_var,
            start: p0,
            s,
            p,
            time: 0.0,
            seg: 0,
            started: false,
            from_rest,
            last_t: None,
            test,
            reopened: 0,
        }
    }

    /// The full state `[x, y, θ, ω, mu_scale, c_x, c_y, I_cm]` and its covariance.
    pub fn state(&self) -> (Vec8, Mat8) {
        (self.s, self.p)
    }

    /// Appends a push applied online (see [`TrackModel::extend`]): samples
    /// up to the new end of the schedule may follow.
    pub fn extend(&mut self, v: Vec2, duration: f64) {
        self.model.extend(v, duration);
    }

    /// Times the parameters were re-opened after a lack of fit.
    pub fn reopened(&self) -> usize {
        self.reopened
    }

    /// The segment whose input acts now.
    pub fn segment(&self) -> usize {
        self.seg
    }

    fn q(&self) -> [f64; 4] {
        [self.s[4], self.s[5], self.s[6], self.s[7]]
    }

    /// `f(y)` and `J(y) = ∂f/∂[y, p]` for `y = [x, y, θ, ω]`.
    fn rhs(&self, v: Vec2, y: &[f64; 4], p: &[f64; 4]) -> ([f64; 4], [[f64; 8]; 4]) {
        let r = self.model.rates_q(v, y[3], p);
        let vel = self.model.cm_velocity(v, y[2], y[3]);
        let dvel_dtheta = perp(&vel);
        let dvel_domega = -rotate(y[2], &perp(&self.model.contact()));
        let mut j = [[0.0; 8]; 4];
        j[0][2] = dvel_dtheta.x;
        j[1][2] = dvel_dtheta.y;
        j[0][3] = dvel_domega.x;
        j[1][3] = dvel_domega.y;
        j[2][3] = 1.0;
        j[3][3] = r.d_omega;
        j[3][4..8].copy_from_slice(&r.d_param);
        ([vel.x, vel.y, y[3], r.omega_dot], j)
    }

    /// `Ṡ = J_y S + [0 | J_p]`.
    fn sens_rate(j: &[[f64; 8]; 4], sens: &Sens) -> Sens {
        let mut d = [[0.0; 8]; 4];
        for r in 0..4 {
            for c in 0..8 {
                let mut acc = if c >= 4 { j[r][c] } else { 0.0 };
                for k in 0..4 {
                    acc += j[r][k] * sens[k][c];
                }
                d[r][c] = acc;
            }
        }
        d
    }

    /// RK4 from `t0` to `t1` on the state and its sensitivity.
    fn integrate(&self, v: Vec2, y: &mut [f64; 4], sens: &mut Sens, t0: f64, t1: f64) {
        let span = t1 - t0;
        if !(span > 0.0) {
            return;
        }
        let n = (span / self.settings.max_step).ceil().max(1.0) as usize;
        let h = span / n as f64;
        let p = self.q();
        for _ in 0..n {
            let (k1, j1) = self.rhs(v, y, &p);
            let s1 = Self::sens_rate(&j1, sens);
            let y2: [f64; 4] = std::array::from_fn(|i| y[i] + 0.5 * h * k1[i]);
            let sn2: Sens =
                std::array::from_fn(|r| std::array::from_fn(|c| sens[r][c] + 0.5 * h * s1[r][c]));
            let (k2, j2) = self.rhs(v, &y2, &p);
            let s2 = Self::sens_rate(&j2, &sn2);
            let y3: [f64; 4] = std::array::from_fn(|i| y[i] + 0.5 * h * k2[i]);
            let sn3: Sens =
                std::array::from_fn(|r| std::array::from_fn(|c| sens[r][c] + 0.5 * h * s2[r][c]));
            let (k3, j3) = self.rhs(v, &y3, &p);
            let s3 = Self::sens_rate(&j3, &sn3);
            let y4: [f64; 4] = std::array::from_fn(|i| y[i] + h * k3[i]);
            let sn4: Sens =
                std::array::from_fn(|r| std::array::from_fn(|c| sens[r][c] + h * s3[r][c]));
            let (k4, j4) = self.rhs(v, &y4, &p);
            let s4 = Self::sens_rate(&j4, &sn4);
            for i in 0..4 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            for r in 0..4 {
                for c in 0..8 {
                    sens[r][c] += h / 6.0 * (s1[r][c] + 2.0 * s2[r][c] + 2.0 * s3[r][c] + s4[r][c]);
                }
            }
        }
    }

    fn jump(&self, before: Option<usize>, after: usize, y: &mut [f64; 4], sens: &mut Sens) {
        let (j, dj) = self.model.switch_jump(before, after, self.s[7]);
        y[3] += j;
        sens[3][4 + INERTIA] += dj;
    }

    /// Moves the state and covariance to `t`.
    fn predict(&mut self, t: f64) {
        let mut y = [self.s[0], self.s[1], self.s[2], self.s[3]];
        let mut sens: Sens = [[0.0; 8]; 4];
        for (r, row) in sens.iter_mut().enumerate() {
            row[r] = 1.0;
        }
        if !self.started {
            self.started = true;
            if self.from_rest {
                self.jump(None, 0, &mut y, &mut sens);
            }
        }
        let segs = &self.model.segments;
        let eps = 1e-9 * self.model.end().max(1.0);
        while self.seg + 1 < segs.len() && segs[self.seg + 1].t_start <= t + eps {
            let b = segs[self.seg + 1].t_start;
            self.integrate(segs[self.seg].v, &mut y, &mut sens, self.time, b);
            self.time = b;
            self.jump(Some(self.seg), self.seg + 1, &mut y, &mut sens);
            self.seg += 1;
        }
        self.integrate(segs[self.seg].v, &mut y, &mut sens, self.time, t);
        let dt = (t - self.time).max(0.0);
        self.time = self.time.max(t);
        let mut phi = Mat8::identity();
        for r in 0..4 {
            for c in 0..8 {
                phi[(r, c)] = sens[r][c];
            }
            self.s[r] = y[r];
        }
        self.p = phi * self.p * phi.transpose();
        self.p[(3, 3)] += self.settings.omega_noise.powi(2) * dt;
    }

    /// One scalar update with measurement row `h` (a linearisation), innovation
    /// `nu` and noise variance `r`; returns `ν² / S`.
    fn scalar_update(&mut self, h: &Vec8, nu: f64, r: f64) -> f64 {
        let ph = self.p * h;
        let s = h.dot(&ph) + r;
        if !(s > 0.0) {
            return 0.0;
        }
        let k = ph / s;
        self.s += k * nu;
        // Joseph form: P ← (I − k hᵀ) P (I − k hᵀ)ᵀ + r k kᵀ.
        let a = Mat8::identity() - k * h.transpose();
        self.p = a * self.p * a.transpose() + k * k.transpose() * r;
        nu * nu / s
    }

    fn reopen(&mut self) {
        let (p, _) = self.model.from_q(&self.q());
        let (_, jq) = self.model.to_q(&p);
        let scaled = self
            .prior_var
            .map(|v| v * self.settings.reopen_scale.powi(2));
        let prior_q = prior_in_q(&jq, &self.free, &scaled);
        self.p = Mat8::zeros();
        let [sp, st, sw] = self.settings.initial_std;
        for (i, v) in [sp * sp, sp * sp, st * st, sw * sw].into_iter().enumerate() {
            self.p[(i, i)] = v;
        }
        for (a, row) in prior_q.iter().enumerate() {
            for (b, v) in row.iter().enumerate() {
                self.p[(4 + a, 4 + b)] = *v;
            }
        }
        self.reopened += 1;
        self.test.clear();
    }

    /// Keeps the parameters in their domain and the fixed ones fixed, in
    /// `p` (so that clamping one coordinate of `q` cannot move a fixed
    /// parameter): `mu_scale` and `I_cm` within [1 %, 100 ×] of the
    /// problem's values, the centre of friction within ten sizes of the
    /// centre of mass; fixed parameters back to their start values.
    fn keep_in_domain(&mut self) {
        let (mut p, _) = self.model.from_q(&self.q());
        let nominal = self.model.nominal();
        let reach = 10.0 * self.model.size();
        for j in 0..4 {
            p[j] = if !self.free[j] {
                self.start[j]
            } else if j == MU || j == INERTIA {
                let v = if p[j].is_finite() { p[j] } else { nominal[j] };
                v.clamp(1e-2 * nominal[j], 1e2 * nominal[j])
            } else {
                let v = if p[j].is_finite() { p[j] } else { nominal[j] };
                v.clamp(nominal[j] - reach, nominal[j] + reach)
            };
        }
        let (q, _) = self.model.to_q(&p);
        for (j, v) in q.iter().enumerate() {
            self.s[4 + j] = *v;
        }
    }
}

/// The prior covariance in `q` of independent priors `prior_var` on the
/// free parameters (`∂q/∂p` = `jq`); fixed parameters contribute nothing.
fn prior_in_q(jq: &[[f64; 4]; 4], free: &[bool; 4], prior_var: &[f64; 4]) -> [[f64; 4]; 4] {
    std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            (0..4)
                .filter(|&k| free[k])
                .map(|k| jq[a][k] * prior_var[k] * jq[b][k])
                .sum()
        })
    })
}

fn finite(name: &'static str, value: f64) -> Result<(), TrackError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(TrackError::NotFinite { name, value })
    }
}

impl Estimator for Ekf {
    fn name(&self) -> &'static str {
        "ekf"
    }

    fn update(&mut self, m: &Measurement) -> Result<UpdateReport, TrackError> {
        finite("t", m.t)?;
        finite("x", m.x)?;
        finite("y", m.y)?;
        finite("theta", m.theta)?;
        if let Some(w) = m.omega {
            finite("omega", w)?;
        }
        if let Some(f) = m.force {
            finite("fx", f.x)?;
            finite("fy", f.y)?;
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
        self.predict(m.t.max(0.0));

        let sp2 = self.settings.sigma_position.powi(2);
        let st2 = self.settings.sigma_theta.powi(2);
        let mut nis = 0.0;
        let mut dof = 0;
        let unit = |i: usize| {
            let mut h = Vec8::zeros();
            h[i] = 1.0;
            h
        };
        nis += self.scalar_update(&unit(0), m.x - self.s[0], sp2);
        nis += self.scalar_update(&unit(1), m.y - self.s[1], sp2);
        nis += self.scalar_update(&unit(2), m.theta - self.s[2], st2);
        dof += 3;
        if let (Some(w), Some(sw)) = (m.omega, self.settings.sigma_omega) {
            nis += self.scalar_update(&unit(3), w - self.s[3], sw * sw);
            dof += 1;
        }
        if let (Some(f), Some(sf)) = (m.force, self.settings.sigma_force) {
            let v = self.model.segments[self.seg].v;
            for axis in 0..2 {
                let h_of = |s: &Vec8| {
                    let (p, _) = self.model.from_q(&[s[4], s[5], s[6], s[7]]);
                    self.model.pusher_force(v, s[2], s[3], &p)[axis]
                };
                let mut h = Vec8::zeros();
                for i in 2..8 {
                    let step = 1e-6 * (1.0 + self.s[i].abs());
                    let (mut a, mut b) = (self.s, self.s);
                    a[i] += step;
                    b[i] -= step;
                    h[i] = (h_of(&a) - h_of(&b)) / (2.0 * step);
                }
                let nu = f[axis] - h_of(&self.s);
                nis += self.scalar_update(&h, nu, sf * sf);
                dof += 1;
            }
        }
        self.keep_in_domain();
        self.p = (self.p + self.p.transpose()) * 0.5;
        if !self.s.iter().all(|v| v.is_finite()) || !self.p.iter().all(|v| v.is_finite()) {
            return Err(TrackError::Diverged { t: m.t });
        }
        let lack = self.test.push(nis, dof);
        if lack && self.settings.reopen {
            self.reopen();
        }
        Ok(UpdateReport {
            nis,
            dof,
            lack_of_fit: lack,
        })
    }

    fn estimate(&self) -> Estimate {
        let (value, j) = self.model.from_q(&self.q());
        let mut cov = [[0.0; 4]; 4];
        for a in 0..4 {
            for b in 0..4 {
                if !(self.free[a] && self.free[b]) {
                    continue;
                }
                let mut acc = 0.0;
                for k in 0..4 {
                    for l in 0..4 {
                        acc += j[a][k] * self.p[(4 + k, 4 + l)] * j[b][l];
                    }
                }
                cov[a][b] = acc;
            }
        }
        Estimate {
            value,
            covariance: cov,
        }
    }

    fn omega(&self) -> (f64, f64) {
        (self.s[3], self.p[(3, 3)])
    }

    fn model(&self) -> &TrackModel {
        &self.model
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn friction_covariance(&self) -> [[f64; 4]; 4] {
        // [ω, μ, c_x, c_y] = g(ω, q): ω itself and the first three rows of ∂p/∂q.
        let (_, j) = self.model.from_q(&self.q());
        let row = |a: usize, k: usize| -> f64 {
            match a {
                0 => (k == 3) as u8 as f64,
                _ if k >= 4 => j[a - 1][k - 4],
                _ => 0.0,
            }
        };
        std::array::from_fn(|a| {
            std::array::from_fn(|b| {
                let mut acc = 0.0;
                for k in 3..8 {
                    for l in 3..8 {
                        acc += row(a, k) * self.p[(k, l)] * row(b, l);
                    }
                }
                acc
            })
        })
    }
}
