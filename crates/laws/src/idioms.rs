//! Friction idioms of top-down 2-D game engines, as support-friction laws the
//! adapter can run instead of Coulomb's, and the closed forms that predict
//! what the engine then does.
//!
//! Every idiom replaces, at each support `i` (sliding velocity `u`, lever arm
//! `r` from the centre of mass, both in the world frame), the Coulomb force
//! `−F u/|u|` (`F = μ_i N_i`) by a force `f(u, r)` that the adapter applies
//! every step, like the Coulomb force, through `add_force_at_point`:
//!
//! * [`FrictionModel::ImpulseDisk`]: the friction *joint* of Box2D
//!   (`b2FrictionJoint`) and Chipmunk (`cpPivotJoint` with `maxForce`) put at
//!   a support. The joint's 2×2 effective-mass matrix
//!   `K = I₂/m + (D r)(D r)ᵀ/I` gives the impulse that would stop the support
//!   of the free body, `−K⁻¹ u`; its length is capped at `F Δt`:
//!   `f = −clamp_len(K⁻¹ u/Δt, F)`. (Iterating it, as those solvers do, has
//!   the same fixed point: the accumulated impulse `λ` solves
//!   `λ = clamp(λ − K⁻¹(u + K λ))`, i.e. `λ = clamp(−K⁻¹ u)`.)
//! * [`FrictionModel::ImpulseBox`]: the same with each *world axis* capped on
//!   its own (two 1-D constraints, each with its scalar effective mass
//!   `1/(1/m + (r × e)²/I)`, each impulse in `[−F Δt, F Δt]`): rapier's own
//!   idiom (a joint to the ground with linear motors of `max_force = μ N`
//!   on its two axes) and the pyramid friction of many solvers.
//! * [`FrictionModel::ImpulseRowsDisk`]: the box's two per-axis rows (each
//!   with its own scalar effective mass), but the *pair* capped in length at
//!   `F Δt`: Bullet's multibody contact friction (PyBullet), whose solver
//!   solves the two lateral friction rows of a contact one by one and then
//!   scales the pair back onto the disk of radius `μ λ_n`. Sliding, its
//!   force has Coulomb's magnitude `F` but points along
//!   `−(m_x u_x, m_y u_y)`, `m_x = 1/(1/m + r_y²/I)`, `m_y = 1/(1/m + r_x²/I)`:
//!   the direction of `u` bent towards the axis with the larger effective
//!   mass. The rows are Bullet's fixed friction axes (`btPlaneSpace1` of the
//!   contact normal: world x and y on a level floor), so the law depends on
//!   θ with period π/2 for the square plate and is exactly Coulomb's where
//!   every support has `r_x² = r_y²` (θ = 0 mod π/2 for corner supports).
//! * [`FrictionModel::RegularisedLinear`] / [`FrictionModel::RegularisedTanh`]:
//!   Coulomb below a slip speed `v_s` replaced by `−F u/v_s`, or
//!   `−F tanh(|u|/v_s) u/|u|` everywhere (smooth simulators).
//!
//! The rapier2d adapter evaluates these laws explicitly, once per step, with
//! the support velocity of its `FrictionVelocity` mode and `Δt` the segment's
//! nominal step; so the engine integrates (to second order in the default
//! leapfrog mode) the analytic model with the law substituted, and
//! [`predicted_steady_omega`] — the root of that modified moment balance —
//! predicts its steady ω. The isotropic laws (all but the per-axis ones) depend on the
//! object frame only, so ω̇ depends on ω alone; the box law depends on the
//! object's angle θ as well ([`idiom_moment`] takes θ), and
//! [`predicted_mean_omega`] gives the quasi-steady period mean
//! `1/⟨1/ω*(θ)⟩_θ` of a body that keeps turning.

//!
//! As laws ([`crate::FrictionLaw`]): [`FrictionModel`] itself (the idiom with
//! its parameters), and one value per idiom for the catalogue:
//! [`ImpulseDisk`], [`ImpulseBox`], [`RowsDisk`] (Bullet's rows on the disc),
//! [`RegularisedLinear`], [`RegularisedTanh`].

use pushval_model::{cross, rotate, Body, ModelError, Problem, Push, Vec2};

use crate::{FrictionLaw, LawClass, LawSteady, COULOMB};

/// The regularised idioms' default slip speed (m/s; see
/// results/friction_models/).
pub const DEFAULT_SLIP_SPEED: f64 = 0.01;

/// Sliding speeds (m/s) at or below this give no friction force.
const MIN_SLIDING_SPEED: f64 = 1e-12;

/// The support-friction law the engine adapter applies.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum FrictionModel {
    /// `−F u/|u|` (the analytic model's law; the default).
    #[default]
    Coulomb,
    /// Box2D / Chipmunk friction joint at each support: the free-body
    /// stopping impulse `−K⁻¹ u` with its length capped at `F Δt`.
    ImpulseDisk,
    /// The stopping impulse per world axis, each component capped at `F Δt`.
    ImpulseBox,
    /// The stopping impulse per world axis (diagonal effective masses), the
    /// pair capped in length at `F Δt` (Bullet's multibody cone friction).
    ImpulseRowsDisk,
    /// `−F u/v_s` below the slip speed `slip_speed` (m/s), Coulomb above.
    RegularisedLinear {
        /// The slip speed `v_s` (m/s).
        slip_speed: f64,
    },
    /// `−F tanh(|u|/v_s) u/|u|`, `v_s = slip_speed` (m/s).
    RegularisedTanh {
        /// The slip speed `v_s` (m/s).
        slip_speed: f64,
    },
}

impl FrictionModel {
    /// `"coulomb"`, `"impulse_disk"`, `"impulse_box"`, `"impulse_rows_disk"`,
    /// `"regularised_linear"` or `"regularised_tanh"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            FrictionModel::Coulomb => "coulomb",
            FrictionModel::ImpulseDisk => "impulse_disk",
            FrictionModel::ImpulseBox => "impulse_box",
            FrictionModel::ImpulseRowsDisk => "impulse_rows_disk",
            FrictionModel::RegularisedLinear { .. } => "regularised_linear",
            FrictionModel::RegularisedTanh { .. } => "regularised_tanh",
        }
    }

    /// Whether the law is the same in every frame (all but the per-axis
    /// laws): then the engine's steady ω does not depend on the object's
    /// angle.
    pub fn is_isotropic(&self) -> bool {
        !matches!(
            self,
            FrictionModel::ImpulseBox | FrictionModel::ImpulseRowsDisk
        )
    }

    /// Checks the slip speed; errors name the field.
    pub fn check(&self) -> Result<(), ModelError> {
        match *self {
            FrictionModel::RegularisedLinear { slip_speed }
            | FrictionModel::RegularisedTanh { slip_speed } => {
                if slip_speed.is_finite() && slip_speed > 0.0 {
                    Ok(())
                } else {
                    Err(ModelError::Parameter {
                        name: "friction slip_speed",
                        requirement: "finite and > 0",
                        value: slip_speed,
                    })
                }
            }
            _ => Ok(()),
        }
    }
}

/// The mass properties and step a law needs besides `u`, `r` and `F`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawContext {
    /// Object mass (kg).
    pub mass: f64,
    /// Inertia about the centre of mass (kg m²).
    pub inertia_cm: f64,
    /// The step Δt of the impulse cap (s).
    pub dt: f64,
}

/// The friction force (N) of one support under `model`: `u` its sliding
/// velocity, `r` its position relative to the centre of mass, both in the
/// world frame (the box law's axes are the frame's axes), `friction = μ N`.
pub fn support_force(
    model: FrictionModel,
    u: [f64; 2],
    r: [f64; 2],
    friction: f64,
    ctx: &LawContext,
) -> [f64; 2] {
    let speed = (u[0] * u[0] + u[1] * u[1]).sqrt();
    if speed <= MIN_SLIDING_SPEED || friction <= 0.0 {
        return [0.0, 0.0];
    }
    let inv_m = 1.0 / ctx.mass;
    let inv_i = 1.0 / ctx.inertia_cm;
    match model {
        FrictionModel::Coulomb => {
            let k = -friction / speed;
            [k * u[0], k * u[1]]
        }
        FrictionModel::ImpulseDisk => {
            // K = I/m + (D r)(D r)^T / I, D r = (−r_y, r_x).
            let a = inv_m + r[1] * r[1] * inv_i;
            let b = -r[0] * r[1] * inv_i;
            let c = inv_m + r[0] * r[0] * inv_i;
            let det = a * c - b * b;
            let fx = -(c * u[0] - b * u[1]) / (det * ctx.dt);
            let fy = -(a * u[1] - b * u[0]) / (det * ctx.dt);
            let len = (fx * fx + fy * fy).sqrt();
            if len > friction {
                let s = friction / len;
                [fx * s, fy * s]
            } else {
                [fx, fy]
            }
        }
        FrictionModel::ImpulseBox => {
            let mx = 1.0 / (inv_m + r[1] * r[1] * inv_i);
            let my = 1.0 / (inv_m + r[0] * r[0] * inv_i);
            [
                (-mx * u[0] / ctx.dt).clamp(-friction, friction),
                (-my * u[1] / ctx.dt).clamp(-friction, friction),
            ]
        }
        FrictionModel::ImpulseRowsDisk => {
            let mx = 1.0 / (inv_m + r[1] * r[1] * inv_i);
            let my = 1.0 / (inv_m + r[0] * r[0] * inv_i);
            let fx = -mx * u[0] / ctx.dt;
            let fy = -my * u[1] / ctx.dt;
            let len = (fx * fx + fy * fy).sqrt();
            if len > friction {
                let s = friction / len;
                [fx * s, fy * s]
            } else {
                [fx, fy]
            }
        }
        FrictionModel::RegularisedLinear { slip_speed } => {
            let k = -friction * (speed / slip_speed).min(1.0) / speed;
            [k * u[0], k * u[1]]
        }
        FrictionModel::RegularisedTanh { slip_speed } => {
            let k = -friction * (speed / slip_speed).tanh() / speed;
            [k * u[0], k * u[1]]
        }
    }
}

/// The magnitude of the isotropic laws' force as a function of the sliding
/// speed along a direction whose free-body effective mass is `m_eff`:
/// Coulomb `F`; impulse (along an eigen-direction of `K`)
/// `min(F, m_eff |u|/Δt)`; linear `F min(|u|/v_s, 1)`; tanh `F tanh(|u|/v_s)`.
/// For the box, the per-axis law `min(F, m_eff |u_axis|/Δt)`.
pub fn force_magnitude(
    model: FrictionModel,
    speed: f64,
    friction: f64,
    m_eff: f64,
    dt: f64,
) -> f64 {
    let s = speed.abs();
    match model {
        FrictionModel::Coulomb => friction,
        FrictionModel::ImpulseDisk | FrictionModel::ImpulseBox | FrictionModel::ImpulseRowsDisk => {
            friction.min(m_eff * s / dt)
        }
        FrictionModel::RegularisedLinear { slip_speed } => friction * (s / slip_speed).min(1.0),
        FrictionModel::RegularisedTanh { slip_speed } => friction * (s / slip_speed).tanh(),
    }
}

/// `I_P ω̇` (N m) of the analytic model with the support law of `model`
/// substituted: `Σ (p_i − p_c) × f_i + m v_c ω (p_c · n_φ)`, at object angle
/// `theta` (only the per-axis laws depend on it) and cap step `dt`.
pub fn idiom_moment(
    model: FrictionModel,
    body: &Body,
    push: &Push,
    dt: f64,
    theta: f64,
    omega: f64,
) -> f64 {
    let pc = body.contact();
    let vc = push.velocity();
    let ctx = LawContext {
        mass: body.mass(),
        inertia_cm: body.inertia_cm(),
        dt,
    };
    let mut m = body.mass() * push.speed * pc.dot(&push.direction()) * omega;
    for s in body.supports() {
        let d = s.position - pc;
        let u = Vec2::new(vc.x - omega * d.y, vc.y + omega * d.x);
        let uw = rotate(theta, &u);
        let rw = rotate(theta, &s.position);
        let fw = support_force(model, [uw.x, uw.y], [rw.x, rw.y], s.friction, &ctx);
        let f = rotate(-theta, &Vec2::new(fw[0], fw[1]));
        m += cross(&d, &f);
    }
    m
}

/// The steady ω (rad/s) that the law of `model` predicts for `push`, frozen at
/// the angle `theta`: the root of [`idiom_moment`] that the scalar flow
/// `I_P ω̇ = G(ω)` reaches from `omega0` (the first sign change of `G` in the
/// direction `G(omega0)` points). None when there is none within the bound
/// `|k ω| ≤ √2 Σ F_i |p_i − p_c|`.
pub fn predicted_steady_omega(
    model: FrictionModel,
    body: &Body,
    push: &Push,
    dt: f64,
    theta: f64,
    omega0: f64,
) -> Option<f64> {
    let g = |w: f64| idiom_moment(model, body, push, dt, theta, w);
    let g0 = g(omega0);
    if g0 == 0.0 {
        return Some(omega0);
    }
    let pc = body.contact();
    let mmax: f64 = body
        .supports()
        .map(|s| s.friction * (s.position - pc).norm())
        .sum::<f64>()
        * std::f64::consts::SQRT_2;
    let k = (body.mass() * push.speed * pc.dot(&push.direction())).abs();
    let reach = if k > 0.0 {
        mmax / k + omega0.abs() + 1.0
    } else {
        1e3 * (push.speed + 1.0)
    };
    let dir = g0.signum();
    let n = 40_000;
    let step = reach / n as f64;
    let mut lo = omega0;
    for i in 1..=n {
        let hi = omega0 + dir * step * i as f64;
        if g(hi) * dir <= 0.0 {
            let (mut a, mut b) = (lo, hi);
            for _ in 0..200 {
                let mid = 0.5 * (a + b);
                if mid == a || mid == b {
                    break;
                }
                if g(mid) * dir > 0.0 {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            return Some(0.5 * (a + b));
        }
        lo = hi;
    }
    None
}

/// The quasi-steady period mean of ω for a law that depends on the angle
/// (the box): with ω*(θ) the frozen root, a body that keeps turning takes
/// `∫ dθ/ω*(θ)` per turn, so its mean ω is `1/⟨1/ω*(θ)⟩` over θ (sampled at
/// `n` angles of one turn). Exact when the relaxation time is short against
/// the time of a turn. For an isotropic law, ω*. None when ω*(θ) is missing
/// or changes sign (the body locks at an angle).
pub fn predicted_mean_omega(
    model: FrictionModel,
    body: &Body,
    push: &Push,
    dt: f64,
    n: usize,
) -> Option<f64> {
    if model.is_isotropic() {
        return predicted_steady_omega(model, body, push, dt, 0.0, 0.0);
    }
    let mut inv = 0.0;
    let mut sign = 0.0;
    for j in 0..n {
        let th = std::f64::consts::TAU * j as f64 / n as f64;
        let w = predicted_steady_omega(model, body, push, dt, th, 0.0)?;
        if w == 0.0 || (sign != 0.0 && w.signum() != sign) {
            return None;
        }
        sign = w.signum();
        inv += 1.0 / w;
    }
    Some(n as f64 / inv)
}

/// The reduced model with the law of `model` integrated in time (classical
/// RK4 on `θ̇ = ω`, `I_P ω̇ = G(θ, ω)` with `n` steps per second):
/// `(t, θ, ω)` every `sample_dt` from `t = 0` to `t_end`. The prediction of
/// an engine run's angle and ω over the transient, not only at steady state.
pub fn predicted_angle_history(
    model: FrictionModel,
    body: &Body,
    push: &Push,
    dt: f64,
    start: (f64, f64),
    t_end: f64,
    sample_dt: f64,
) -> Vec<(f64, f64, f64)> {
    let ip = body.inertia_contact();
    let f = |th: f64, w: f64| (w, idiom_moment(model, body, push, dt, th, w) / ip);
    let per_sample = 20usize;
    let h = sample_dt / per_sample as f64;
    let (mut th, mut w) = start;
    let samples = (t_end / sample_dt).round() as usize;
    let mut out = Vec::with_capacity(samples + 1);
    out.push((0.0, th, w));
    for k in 1..=samples {
        for _ in 0..per_sample {
            let (a1, b1) = f(th, w);
            let (a2, b2) = f(th + 0.5 * h * a1, w + 0.5 * h * b1);
            let (a3, b3) = f(th + 0.5 * h * a2, w + 0.5 * h * b2);
            let (a4, b4) = f(th + h * a3, w + h * b3);
            th += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
            w += h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
        }
        out.push((k as f64 * sample_dt, th, w));
    }
    out
}

/// The angles (rad, in `[0, 2π)`) at which the law of `model` holds the body
/// at ω = 0 while it is pushed, and whether each is stable: the zeros of
/// `θ ↦ G(θ, 0)` ([`idiom_moment`] at ω = 0), stable where `G` falls through
/// zero as θ grows (the frozen flow `θ̇ = ω*(θ)` has the sign of `G(θ, 0)`).
/// Empty for the isotropic laws unless the push already passes through the
/// centre of friction; for the box, the angles where it locks the
/// orientation. Found on a grid of `n` angles, refined by bisection.
pub fn lock_angles(
    model: FrictionModel,
    body: &Body,
    push: &Push,
    dt: f64,
    n: usize,
) -> Vec<(f64, bool)> {
    let g = |th: f64| idiom_moment(model, body, push, dt, th, 0.0);
    let tau = std::f64::consts::TAU;
    let mut out = Vec::new();
    let mut a = 0.0;
    let mut ga = g(a);
    for j in 1..=n {
        let b = tau * j as f64 / n as f64;
        let gb = g(b);
        if ga == 0.0 || ga * gb < 0.0 {
            let (mut lo, mut hi, glo) = (a, b, ga);
            if ga != 0.0 {
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if g(mid) * glo > 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
            } else {
                hi = a;
            }
            let prev = g(hi - 1e-6);
            let next = g(hi + 1e-6);
            out.push((hi.rem_euclid(tau), prev > 0.0 && next < 0.0));
        }
        a = b;
        ga = gb;
    }
    out
}

/// The per-step gain with which an impulse idiom stops a body pinned at the
/// contact when every support is inside its sticking zone (pusher at rest):
/// the explicit step maps `ω ↦ (1 − γ) ω` with
/// `γ = Σ_i ((p_i − p_c) × K_i⁻¹ D (p_i − p_c)) / I_P` (disk) or the same
/// with `K_i` replaced by its diagonal (box, evaluated at angle `theta`),
/// independent of Δt. `γ > 2` means the stop chatters (bounded by the cap).
/// For the linear regularised law the same map holds with
/// `γ = Δt Σ_i F_i |p_i − p_c|² / (v_s I_P)`, so it chatters when
/// `Δt > 2 v_s I_P / Σ F_i |p_i − p_c|²`.
pub fn stop_gain(model: FrictionModel, body: &Body, dt: f64, theta: f64) -> Option<f64> {
    let pc = body.contact();
    let (m, i) = (body.mass(), body.inertia_cm());
    let ip = body.inertia_contact();
    let mut gamma = 0.0;
    for s in body.supports() {
        let d = s.position - pc;
        let dw = rotate(theta, &d);
        let r = rotate(theta, &s.position);
        // Velocity of the support per unit ω, world frame: D (p_i − p_c).
        let e = [-dw.y, dw.x];
        let a = 1.0 / m + r.y * r.y / i;
        let b = -r.x * r.y / i;
        let c = 1.0 / m + r.x * r.x / i;
        let j = match model {
            FrictionModel::ImpulseDisk => {
                let det = a * c - b * b;
                [(c * e[0] - b * e[1]) / det, (a * e[1] - b * e[0]) / det]
            }
            FrictionModel::ImpulseBox | FrictionModel::ImpulseRowsDisk => [e[0] / a, e[1] / c],
            FrictionModel::RegularisedLinear { slip_speed } => {
                let k = s.friction * dt / slip_speed;
                [k * e[0], k * e[1]]
            }
            _ => return None,
        };
        gamma += cross(&dw, &Vec2::new(j[0], j[1])) / ip;
    }
    Some(gamma)
}

/// Angles per turn of the per-axis laws' period mean.
const BOX_ANGLES: usize = 360;

/// The idioms' closed forms: the moment balance with the idiom's support law
/// substituted; for the per-axis laws, the period mean over the object's
/// angle, and a lock where the frozen root changes sign.
/// [`FrictionModel::Coulomb`] is [`COULOMB`].
impl FrictionLaw for FrictionModel {
    fn law_name(&self) -> &'static str {
        match self {
            FrictionModel::ImpulseBox => {
                "stopping impulse capped per world axis; mean ω over a turn, locked where ω*(θ) changes sign (pushval_rapier2d::idioms)"
            }
            FrictionModel::ImpulseDisk => {
                "stopping impulse −K⁻¹u capped in length at μNΔt (pushval_rapier2d::idioms)"
            }
            FrictionModel::ImpulseRowsDisk => {
                "stopping impulse solved per world axis, the pair scaled onto the disk μNΔt; mean ω over a turn (pushval_rapier2d::idioms)"
            }
            FrictionModel::Coulomb => COULOMB.law_name(),
            _ => "Coulomb regularised below the slip speed (pushval_rapier2d::idioms)",
        }
    }
    fn catalog_name(&self) -> Option<&'static str> {
        match self {
            FrictionModel::RegularisedLinear { .. } => Some("regularised_linear"),
            FrictionModel::RegularisedTanh { .. } => Some("regularised_tanh"),
            _ => None,
        }
    }
    /// The per-axis laws repeat when the object turns by π (the world axes'
    /// rows see `r_x², r_y²` again), by π/2 where the supports are symmetric
    /// under a quarter turn about the centre of mass (the square plate).
    fn angle_period(&self, problem: &Problem) -> Option<f64> {
        if self.is_isotropic() {
            return None;
        }
        let body = &problem.body;
        let quarter = body.supports().all(|s| {
            let q = Vec2::new(-s.position.y, s.position.x);
            body.supports().any(|t| {
                (t.position - q).norm() <= 1e-12 * (1.0 + q.norm())
                    && (t.friction - s.friction).abs() <= 1e-12 * s.friction.abs().max(1e-300)
            })
        });
        Some(if quarter {
            std::f64::consts::FRAC_PI_2
        } else {
            std::f64::consts::PI
        })
    }
    fn steady(&self, problem: &Problem, segment: usize, dt: f64) -> Option<LawSteady> {
        let model = *self;
        if model == FrictionModel::Coulomb {
            return COULOMB.steady(problem, segment, dt);
        }
        let push = problem.pushes.get(segment)?;
        let body = &problem.body;
        if model.is_isotropic() {
            let omega = predicted_steady_omega(model, body, push, dt, 0.0, 0.0)?;
            return Some(LawSteady {
                omega,
                class: LawClass::Turns,
            });
        }
        match predicted_mean_omega(model, body, push, dt, BOX_ANGLES) {
            Some(omega) => Some(LawSteady {
                omega,
                class: LawClass::Turns,
            }),
            None => lock_angles(model, body, push, dt, BOX_ANGLES)
                .iter()
                .any(|&(_, stable)| stable)
                .then_some(LawSteady {
                    omega: 0.0,
                    class: LawClass::Locked,
                }),
        }
    }
}

/// One law value per idiom, each the [`FrictionModel`] it names.
macro_rules! idiom_law {
    ($(#[$doc:meta])* $name:ident, $model:expr) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub struct $name;

        impl $name {
            /// The idiom as a [`FrictionModel`].
            pub fn model(&self) -> FrictionModel {
                $model
            }
        }

        idiom_law!(@law $name);
    };
    ($(#[$doc:meta])* $name:ident { slip_speed }, $model:path) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct $name {
            /// The slip speed `v_s` (m/s, > 0; default [`DEFAULT_SLIP_SPEED`]).
            pub slip_speed: f64,
        }

        impl $name {
            /// The idiom as a [`FrictionModel`].
            pub fn model(&self) -> FrictionModel {
                $model {
                    slip_speed: self.slip_speed,
                }
            }
        }

        impl Default for $name {
            fn default() -> Self {
                Self {
                    slip_speed: DEFAULT_SLIP_SPEED,
                }
            }
        }

        idiom_law!(@law $name);
    };
    (@law $name:ident) => {
        impl FrictionLaw for $name {
            fn law_name(&self) -> &'static str {
                self.model().law_name()
            }
            fn catalog_name(&self) -> Option<&'static str> {
                self.model().catalog_name()
            }
            fn steady(&self, problem: &Problem, segment: usize, dt: f64) -> Option<LawSteady> {
                self.model().steady(problem, segment, dt)
            }
            fn angle_period(&self, problem: &Problem) -> Option<f64> {
                self.model().angle_period(problem)
            }
        }
    };
}

idiom_law!(
    /// The friction joint of Box2D and Chipmunk at every support:
    /// [`FrictionModel::ImpulseDisk`].
    ImpulseDisk,
    FrictionModel::ImpulseDisk
);
idiom_law!(
    /// The stopping impulse capped per world axis (rapier's joint motors,
    /// pyramid friction): [`FrictionModel::ImpulseBox`].
    ImpulseBox,
    FrictionModel::ImpulseBox
);
idiom_law!(
    /// Bullet's two friction rows per contact scaled back onto the disc
    /// `μ N Δt` (PyBullet): [`FrictionModel::ImpulseRowsDisk`].
    RowsDisk,
    FrictionModel::ImpulseRowsDisk
);
idiom_law!(
    /// Coulomb made linear below the slip speed:
    /// [`FrictionModel::RegularisedLinear`].
    RegularisedLinear { slip_speed },
    FrictionModel::RegularisedLinear
);
idiom_law!(
    /// Coulomb smoothed by `tanh(|u|/v_s)`: [`FrictionModel::RegularisedTanh`].
    RegularisedTanh { slip_speed },
    FrictionModel::RegularisedTanh
);
