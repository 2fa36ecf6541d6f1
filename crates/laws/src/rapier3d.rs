//! Closed forms and model-with-loads predictions of what the 3-D scene does.
//!
//! * **Normal loads.** In 3-D the supports' normal loads are not inputs: they
//!   follow from the vertical force balance and the two tilting moments,
//!   `Σ N_i = m g`, `Σ N_i p_i = M`, with (steady state, no tilting
//!   acceleration, object frame, horizontal vectors)
//!
//!   ```text
//!   M = h_push f_c − h_cm m a_cm          (N m)
//!   ```
//!
//!   (moments about the centre of mass of the pusher force `f_c` at height
//!   `h_push`, of the support forces at the ground and of gravity; `a_cm` the
//!   centre of mass's acceleration, `f_c + Σ f_i = m a_cm`). Three equations
//!   fix three loads; four or more are statically indeterminate. rapier's soft
//!   contacts act like springs whose stiffness is proportional to each
//!   contact's normal effective mass `m_eff,i = 1/(1/m + y_i²/I_xx + x_i²/I_yy)`
//!   (its softness is set per unit effective mass), on a rigid body, so the
//!   loads are `N_i = k_i (a + b·p_i)` with `k_i ∝ m_eff,i` ([`distribute`]);
//!   with equal `k_i` this is the least-norm solution of the statics.
//! * **Steady ω with those loads** ([`predict_steady`]): a fixed point — loads
//!   give friction magnitudes `μ_i N_i`, these give the analytic model's
//!   steady ω and the forces `f_c`, `a_cm`, which give the loads again.
//! * **rapier's `Simplified` friction** on one contact manifold (all feet in
//!   one collider): one friction constraint at the manifold's *friction
//!   centre* `c` (the unweighted mean of the contact points) with a disk limit
//!   `μ Σ N_k`, plus a *twist* constraint about the normal with limit
//!   `μ Σ N_k |p_k − c|` ([`simplified_moment`]). The twist constraint holds
//!   ω = 0 while the moment it must cancel is below its limit
//!   ([`simplified_locks`]).
//!
//! Units: SI (m, kg, N, N m, rad/s); positions in the object frame relative to
//! the centre of mass.

use pushval_model::{cross, Body, ModelError, Problem, Push, SegmentDynamics, Support, Vec2};

use crate::{FrictionLaw, LawClass, LawSteady};

/// The plain parameters of the 3-D scene the predictions need (the rapier3d
/// adapter's settings convert into them). Defaults are the adapter's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneParams {
    /// Height of the centre of mass above the ground (m); default `0.01`.
    pub cm_height: f64,
    /// Height of the pusher joint above the ground (m); default `0.01`.
    pub push_height: f64,
    /// Plate thickness (m) for the tilt inertias; default `0.005`.
    pub plate_thickness: f64,
    /// Gravity (m/s²); default `9.81`.
    pub gravity: f64,
    /// All feet in one collider, one contact manifold (rapier's compound
    /// feet); default `true`. It then holds at most 4 points and one
    /// friction coefficient.
    pub compound_feet: bool,
}

impl Default for SceneParams {
    fn default() -> Self {
        Self {
            cm_height: 0.01,
            push_height: 0.01,
            plate_thickness: 0.005,
            gravity: 9.81,
            compound_feet: true,
        }
    }
}

/// Tilt-axis inertia (kg m²) of a thin plate of thickness `thickness` (m)
/// whose vertical-axis inertia is `inertia_z` (kg m²): the perpendicular-axis
/// theorem splits `inertia_z` evenly (exact for a body symmetric under a
/// quarter turn, a reasonable guess otherwise), plus `m t²/12`.
pub fn tilt_inertia(inertia_z: f64, mass: f64, thickness: f64) -> f64 {
    0.5 * inertia_z + mass * thickness * thickness / 12.0
}

/// Normal effective mass (kg) of a ground contact at `p` (object frame) of a
/// body with mass `mass` and tilt inertias `ixx`, `iyy`: `1/(1/m + y²/I_xx + x²/I_yy)`.
pub fn normal_effective_mass(p: [f64; 2], mass: f64, ixx: f64, iyy: f64) -> f64 {
    1.0 / (1.0 / mass + p[1] * p[1] / ixx + p[0] * p[0] / iyy)
}

/// Loads `N_i = k_i (a + b_x x_i + b_y y_i)` (N) with `Σ N_i = weight` and
/// `Σ N_i p_i = moment`: springs of stiffness `k_i` under a rigid body.
/// Solved as a 3×3 system (a tiny ridge keeps two or collinear supports
/// solvable: the least-norm solution in the missing direction).
pub fn distribute(points: &[[f64; 2]], k: &[f64], weight: f64, moment: [f64; 2]) -> Vec<f64> {
    // A (a, bx, by) = (W, Mx, My), A_rs = Σ k_i φ_r φ_s, φ = (1, x, y).
    let mut a = [[0.0f64; 3]; 3];
    for (p, &ki) in points.iter().zip(k) {
        let phi = [1.0, p[0], p[1]];
        for r in 0..3 {
            for s in 0..3 {
                a[r][s] += ki * phi[r] * phi[s];
            }
        }
    }
    let scale = a[0][0].abs().max(a[1][1].abs()).max(a[2][2].abs());
    for (r, row) in a.iter_mut().enumerate() {
        row[r] += 1e-12 * scale;
    }
    let c = solve3(a, [weight, moment[0], moment[1]]);
    points
        .iter()
        .zip(k)
        .map(|(p, &ki)| ki * (c[0] + c[1] * p[0] + c[2] * p[1]))
        .collect()
}

/// Gaussian elimination with partial pivoting.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> [f64; 3] {
    for col in 0..3 {
        let piv = (col..3)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, piv);
        b.swap(col, piv);
        let d = a[col][col];
        if d == 0.0 {
            continue;
        }
        for r in col + 1..3 {
            let f = a[r][col] / d;
            let pivot_row = a[col];
            for (x, p) in a[r].iter_mut().zip(pivot_row).skip(col) {
                *x -= f * p;
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for r in (0..3).rev() {
        let mut s = b[r];
        for c in r + 1..3 {
            s -= a[r][c] * x[c];
        }
        x[r] = if a[r][r] != 0.0 { s / a[r][r] } else { 0.0 };
    }
    x
}

/// The geometry and mass data the load predictions need.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Support positions (m, object frame, relative to the centre of mass).
    pub points: Vec<[f64; 2]>,
    /// Friction coefficient of each support (dimensionless).
    pub mu: Vec<f64>,
    /// Mass (kg).
    pub mass: f64,
    /// Vertical-axis inertia about the centre of mass (kg m²).
    pub inertia_z: f64,
    /// Tilt inertia about the x axis through the centre of mass (kg m²).
    pub ixx: f64,
    /// Tilt inertia about the y axis through the centre of mass (kg m²).
    pub iyy: f64,
    /// Gravity (m/s²).
    pub gravity: f64,
    /// Contact point (m, object frame).
    pub contact: [f64; 2],
    /// Height of the centre of mass above the ground (m).
    pub cm_height: f64,
    /// Height of the pusher joint above the ground (m).
    pub push_height: f64,
}

impl Scene {
    /// The prediction scene of `problem` under the scene parameters `s`
    /// (μ_i from the rest loads). Errors when a support with friction
    /// carries no load at rest, or compound feet have more than 4 points or
    /// unequal coefficients.
    pub fn of(problem: &Problem, s: &SceneParams) -> Result<Scene, ModelError> {
        let body = &problem.body;
        let tilt = tilt_inertia(body.inertia_cm(), body.mass(), s.plate_thickness);
        let mut scene = Scene {
            points: body
                .supports()
                .map(|p| [p.position.x, p.position.y])
                .collect(),
            mu: vec![0.0; body.len()],
            mass: body.mass(),
            inertia_z: body.inertia_cm(),
            ixx: tilt,
            iyy: tilt,
            gravity: s.gravity,
            contact: [body.contact().x, body.contact().y],
            cm_height: s.cm_height,
            push_height: s.push_height,
        };
        let rest = scene.rest_loads();
        for (i, sup) in body.supports().enumerate() {
            if sup.friction == 0.0 {
                continue;
            }
            if !(rest[i] > 0.0) {
                return Err(ModelError::Parameter {
                    name: "rapier3d rest load of a support with friction (supports must surround the centre of mass)",
                    requirement: "> 0",
                    value: rest[i],
                });
            }
            scene.mu[i] = sup.friction / rest[i];
        }
        if s.compound_feet {
            if body.len() > 4 {
                return Err(ModelError::Parameter {
                    name: "rapier3d compound feet: number of supports (rapier keeps at most 4 points of a contact cluster; use FeetColliders::Separate)",
                    requirement: "<= 4",
                    value: body.len() as f64,
                });
            }
            let mu0 = scene.mu[0];
            for &mu in &scene.mu {
                if (mu - mu0).abs() > 1e-9 * mu0.abs().max(1e-300) {
                    return Err(ModelError::Parameter {
                        name: "rapier3d compound feet: friction coefficient of a support (one collider has one coefficient; use FeetColliders::Separate)",
                        requirement: "equal to the first support's",
                        value: mu,
                    });
                }
            }
        }
        Ok(scene)
    }

    /// The spring stiffnesses of [`distribute`] (∝ normal effective mass).
    pub fn stiffness(&self) -> Vec<f64> {
        self.points
            .iter()
            .map(|&p| normal_effective_mass(p, self.mass, self.ixx, self.iyy))
            .collect()
    }

    /// Loads (N) under the moment `moment` (N m, `Σ N_i p_i`). A support
    /// whose load would be negative lifts off: it is dropped and the rest
    /// re-solved (its load is 0).
    pub fn loads(&self, moment: [f64; 2]) -> Vec<f64> {
        let mut k = self.stiffness();
        let w = self.mass * self.gravity;
        for _ in 0..self.points.len() {
            let n = distribute(&self.points, &k, w, moment);
            match (0..n.len())
                .filter(|&i| n[i] < 0.0)
                .min_by(|&a, &b| n[a].total_cmp(&n[b]))
            {
                Some(i) => k[i] = 0.0,
                None => return n,
            }
        }
        distribute(&self.points, &k, w, moment)
    }

    /// Loads at rest (N).
    pub fn rest_loads(&self) -> Vec<f64> {
        self.loads([0.0, 0.0])
    }

    /// The analytic model's body with friction magnitudes `μ_i N_i`.
    pub fn body(&self, loads: &[f64]) -> Result<Body, ModelError> {
        let supports: Vec<Support> = self
            .points
            .iter()
            .zip(&self.mu)
            .zip(loads)
            .map(|((p, &mu), &n)| Support {
                position: Vec2::new(p[0], p[1]),
                friction: mu * n.max(0.0),
            })
            .collect();
        Body::new(
            self.mass,
            self.inertia_z,
            Vec2::new(self.contact[0], self.contact[1]),
            &supports,
        )
    }

    /// `Σ N_i p_i = h_push f_c − h_cm m a_cm` (N m, object frame) for the
    /// steady state of `push` at `omega` with the friction resultant `friction`
    /// (N, object frame): `a_cm = v_c ω D n_φ + ω² p_c`, `f_c = m a_cm − friction`.
    pub fn tilting_moment(&self, push: &Push, omega: f64, friction: Vec2) -> [f64; 2] {
        let pc = Vec2::new(self.contact[0], self.contact[1]);
        let d = push.direction();
        let a = Vec2::new(-d.y, d.x) * (push.speed * omega) + pc * (omega * omega);
        let fc = a * self.mass - friction;
        let m = fc * self.push_height - a * (self.mass * self.cm_height);
        [m.x, m.y]
    }
}

/// Which friction law the prediction uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Law {
    /// Coulomb at every support (the analytic model; rapier's `Coulomb`
    /// friction model, and its `Simplified` one with one foot per manifold).
    Coulomb,
    /// rapier's `Simplified` friction with every foot in one manifold.
    SimplifiedOneManifold,
    /// What rapier's per-contact friction converges to while a contact
    /// slides: its 2×2 tangent solve `Δλ = −K⁻¹ Δv` followed by a cap of the
    /// impulse's length at `μ λ_n` has, at a sliding fixed point, the impulse
    /// along `−K⁻¹ u` (not `−u`), `K` the contact's tangent inverse effective
    /// mass ([`tangent_k`]): `f_i = −μ_i N_i K_i⁻¹u_i / |K_i⁻¹u_i|`.
    EffectiveMassDisk,
}

/// A steady state with the loads that go with it.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadPrediction {
    /// Steady ω (rad/s).
    pub omega: f64,
    /// Normal loads (N).
    pub loads: Vec<f64>,
    /// `Σ N_i p_i` (N m).
    pub moment: [f64; 2],
    /// Fixed-point iterations used.
    pub iterations: usize,
}

/// The stable steady ω (rad/s) of the analytic model for `body` and `push`
/// reached from `omega0`.
pub fn coulomb_steady(body: &Body, push: &Push, omega0: f64) -> Option<f64> {
    let seg = SegmentDynamics::new(body, push);
    let roots = seg.steady_states();
    seg.attractor(&roots, omega0).map(|s| s.omega)
}

/// The steady ω and loads of `law` for `push`, with the loads coupled to the
/// forces by the tilting moment (fixed-point iteration from the rest loads).
/// With `coupled = false`, the rest loads are kept (no load transfer).
pub fn predict_steady(
    scene: &Scene,
    push: &Push,
    law: Law,
    coupled: bool,
) -> Result<LoadPrediction, ModelError> {
    let mut loads = scene.rest_loads();
    let mut omega = 0.0;
    let mut moment = [0.0, 0.0];
    let mut iterations = 0;
    for it in 0..200 {
        iterations = it + 1;
        let (w, friction) = omega_at_loads(scene, push, law, &loads)?;
        omega = w;
        if !coupled {
            break;
        }
        moment = scene.tilting_moment(push, w, friction);
        let next = scene.loads(moment);
        let change: f64 = next
            .iter()
            .zip(&loads)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        loads = next;
        if change < 1e-12 * scene.mass * scene.gravity {
            break;
        }
    }
    Ok(LoadPrediction {
        omega,
        loads,
        moment,
        iterations,
    })
}

/// The law's steady ω (rad/s) with the feet carrying `loads` (N), and the
/// resultant friction force it holds there (N).
pub fn omega_at_loads(
    scene: &Scene,
    push: &Push,
    law: Law,
    loads: &[f64],
) -> Result<(f64, Vec2), ModelError> {
    let body = scene.body(loads)?;
    Ok(match law {
        Law::Coulomb => {
            let w = coulomb_steady(&body, push, 0.0).ok_or(ModelError::Integration {
                t: 0.0,
                reason: "no steady state".into(),
            })?;
            (w, SegmentDynamics::new(&body, push).friction_force(w))
        }
        Law::SimplifiedOneManifold => {
            let mu = scene.mu[0];
            let w = simplified_steady(&scene.points, loads, mu, &body, push);
            (
                w,
                simplified_friction(&scene.points, loads, mu, push, &body, w),
            )
        }
        Law::EffectiveMassDisk => {
            let w = effective_mass_steady(scene, loads, push);
            (w, effective_mass_forces(scene, loads, push, w).1)
        }
    })
}

/// Friction centre of a manifold: the unweighted mean of its points (m).
pub fn friction_centre(points: &[[f64; 2]]) -> Vec2 {
    let n = points.len() as f64;
    Vec2::new(
        points.iter().map(|p| p[0]).sum::<f64>() / n,
        points.iter().map(|p| p[1]).sum::<f64>() / n,
    )
}

/// Twist limit `μ Σ N_k |p_k − c|` (N m) of a manifold.
pub fn twist_limit(points: &[[f64; 2]], loads: &[f64], mu: f64) -> f64 {
    let c = friction_centre(points);
    mu * points
        .iter()
        .zip(loads)
        .map(|(p, n)| n * (Vec2::new(p[0], p[1]) - c).norm())
        .sum::<f64>()
}

/// `I_P ω̇` (N m) under rapier's `Simplified` friction on one manifold, for
/// ω ≠ 0: the friction force `−μ ΣN û_c` at the friction centre `c`, the
/// twist moment `−sgn(ω) μ Σ N_k |p_k − c|`, and the inertial term
/// `m v_c ω (p_c · n_φ)`, all about the contact point.
pub fn simplified_moment(
    points: &[[f64; 2]],
    loads: &[f64],
    mu: f64,
    body: &Body,
    push: &Push,
    omega: f64,
) -> f64 {
    let pc = body.contact();
    let c = friction_centre(points);
    let f = simplified_linear_force(points, loads, mu, push, &pc, omega);
    let tw = -omega.signum() * twist_limit(points, loads, mu);
    cross(&(c - pc), &f) + tw + body.mass() * push.speed * pc.dot(&push.direction()) * omega
}

fn simplified_linear_force(
    points: &[[f64; 2]],
    loads: &[f64],
    mu: f64,
    push: &Push,
    pc: &Vec2,
    omega: f64,
) -> Vec2 {
    let c = friction_centre(points);
    let r = c - pc;
    let u = push.velocity() + Vec2::new(-r.y, r.x) * omega;
    let n = u.norm();
    let total: f64 = loads.iter().sum();
    if n > 0.0 {
        -u * (mu * total / n)
    } else {
        Vec2::zeros()
    }
}

fn simplified_friction(
    points: &[[f64; 2]],
    loads: &[f64],
    mu: f64,
    push: &Push,
    body: &Body,
    omega: f64,
) -> Vec2 {
    simplified_linear_force(points, loads, mu, push, &body.contact(), omega)
}

/// Whether the twist constraint holds ω = 0: the moment about the contact
/// point of the friction force at ω = 0, `|(c − p_c) × F|`, is within the
/// twist limit.
pub fn simplified_locks(
    points: &[[f64; 2]],
    loads: &[f64],
    mu: f64,
    body: &Body,
    push: &Push,
) -> bool {
    let pc = body.contact();
    let c = friction_centre(points);
    let f = simplified_linear_force(points, loads, mu, push, &pc, 0.0);
    cross(&(c - pc), &f).abs() <= twist_limit(points, loads, mu)
}

/// The steady ω (rad/s) under rapier's `Simplified` friction on one manifold,
/// reached from ω = 0: 0 when the twist constraint locks, otherwise the root
/// of [`simplified_moment`] on the side the moment drives ω to.
pub fn simplified_steady(
    points: &[[f64; 2]],
    loads: &[f64],
    mu: f64,
    body: &Body,
    push: &Push,
) -> f64 {
    if simplified_locks(points, loads, mu, body, push) {
        return 0.0;
    }
    let pc = body.contact();
    let c = friction_centre(points);
    let f0 = simplified_linear_force(points, loads, mu, push, &pc, 0.0);
    let dir = cross(&(c - pc), &f0).signum();
    let g = |w: f64| simplified_moment(points, loads, mu, body, push, w);
    // March out from 0+ in the driven direction, then bisect.
    let mut lo = dir * 1e-12;
    let mut step = 1e-3 * (push.speed + 1e-3);
    let mut hi = lo + dir * step;
    let mut n = 0;
    while g(hi) * dir > 0.0 && n < 200 {
        lo = hi;
        step *= 1.5;
        hi += dir * step;
        n += 1;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) * dir > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The tangent block `K = J M⁻¹ Jᵀ` (1/kg, object frame `[k_xx, k_yy, k_xy]`)
/// of a ground contact at `p` (the contact point is `(x, y, −h_cm)` from the
/// centre of mass) of a body with mass `m` and principal inertias
/// `(I_xx, I_yy, I_z)`: `k_xx = 1/m + h²/I_yy + y²/I_z`,
/// `k_yy = 1/m + h²/I_xx + x²/I_z`, `k_xy = −x y / I_z`.
pub fn tangent_k(scene: &Scene, p: [f64; 2]) -> [f64; 3] {
    let h = scene.cm_height;
    let im = 1.0 / scene.mass;
    [
        im + h * h / scene.iyy + p[1] * p[1] / scene.inertia_z,
        im + h * h / scene.ixx + p[0] * p[0] / scene.inertia_z,
        -p[0] * p[1] / scene.inertia_z,
    ]
}

/// `(I_P ω̇, Σ f_i)` (N m, N; object frame) under [`Law::EffectiveMassDisk`].
pub fn effective_mass_forces(scene: &Scene, loads: &[f64], push: &Push, omega: f64) -> (f64, Vec2) {
    let pc = Vec2::new(scene.contact[0], scene.contact[1]);
    let vc = push.velocity();
    let mut moment = scene.mass * push.speed * pc.dot(&push.direction()) * omega;
    let mut total = Vec2::zeros();
    for ((p, &mu), &n) in scene.points.iter().zip(&scene.mu).zip(loads) {
        let d = Vec2::new(p[0], p[1]) - pc;
        let u = Vec2::new(vc.x - omega * d.y, vc.y + omega * d.x);
        let k = tangent_k(scene, *p);
        let det = k[0] * k[1] - k[2] * k[2];
        let w = Vec2::new(k[1] * u.x - k[2] * u.y, k[0] * u.y - k[2] * u.x) / det;
        let wn = w.norm();
        if wn > 0.0 && n > 0.0 {
            let f = -w * (mu * n / wn);
            moment += cross(&d, &f);
            total += f;
        }
    }
    (moment, total)
}

/// The steady ω (rad/s) of [`Law::EffectiveMassDisk`] reached from ω = 0.
pub fn effective_mass_steady(scene: &Scene, loads: &[f64], push: &Push) -> f64 {
    let g = |w: f64| effective_mass_forces(scene, loads, push, w).0;
    let g0 = g(0.0);
    if g0 == 0.0 {
        return 0.0;
    }
    let dir = g0.signum();
    let mut lo = 0.0;
    let mut step = 1e-3 * (push.speed + 1e-3);
    let mut hi = dir * step;
    let mut n = 0;
    while g(hi) * dir > 0.0 && n < 200 {
        lo = hi;
        step *= 1.5;
        hi += dir * step;
        n += 1;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) * dir > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// rapier3d's contact friction in closed form, with the normal loads
/// coupled to the forces by the tilting balance: [`Law::EffectiveMassDisk`]
/// (rapier's per-contact solve, the `rapier3d` model) or
/// [`Law::SimplifiedOneManifold`] (`rapier3d_simplified` on compound feet).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rapier3dTilt {
    /// The contact law ([`Law::Coulomb`] is the analytic model's with the
    /// tilting balance's loads).
    pub law: Law,
    /// The scene.
    pub scene: SceneParams,
}

impl Rapier3dTilt {
    /// Every contact along `−K⁻¹u`, capped at `μN`.
    pub fn contact_disk(scene: SceneParams) -> Self {
        Self {
            law: Law::EffectiveMassDisk,
            scene,
        }
    }

    /// `Simplified` friction on one manifold: a disc at the friction centre
    /// and a twist limit (the feet are compound).
    pub fn simplified_twist(scene: SceneParams) -> Self {
        Self {
            law: Law::SimplifiedOneManifold,
            scene: SceneParams {
                compound_feet: true,
                ..scene
            },
        }
    }
}

impl FrictionLaw for Rapier3dTilt {
    fn law_name(&self) -> &'static str {
        match self.law {
            Law::SimplifiedOneManifold => {
                "Simplified on one manifold: disk at the friction centre plus a twist limit, loads from the tilting balance (pushval_rapier3d::predict)"
            }
            _ => {
                "per-contact impulse along −K⁻¹u capped at μN, loads from the tilting balance (pushval_rapier3d::predict)"
            }
        }
    }
    fn steady(&self, problem: &Problem, segment: usize, _dt: f64) -> Option<LawSteady> {
        let push = problem.pushes.get(segment)?;
        let scene = Scene::of(problem, &self.scene).ok()?;
        let law = self.law;
        let pred = predict_steady(&scene, push, law, true).ok()?;
        let locked = law == Law::SimplifiedOneManifold && {
            let body = scene.body(&pred.loads).ok()?;
            simplified_locks(&scene.points, &pred.loads, scene.mu[0], &body, push)
        };
        Some(LawSteady {
            omega: pred.omega,
            class: if locked {
                LawClass::Locked
            } else {
                LawClass::Turns
            },
        })
    }
    /// The feet's loads (N) at the steady state: `m g` shared as springs ∝
    /// normal effective mass (statics for three feet), moved by the tilting
    /// moment `h_push f_c − h_cm m a_cm`; a foot whose load would be negative
    /// lifts off and carries 0 ([`predict_steady`]).
    fn loads(&self, problem: &Problem, segment: usize, _dt: f64) -> Option<Vec<f64>> {
        let push = problem.pushes.get(segment)?;
        let scene = Scene::of(problem, &self.scene).ok()?;
        predict_steady(&scene, push, self.law, true)
            .ok()
            .map(|p| p.loads)
    }
    /// The law's friction rule with the feet carrying the given loads (no
    /// tilting balance: the loads are the run's).
    fn steady_on_loads(
        &self,
        problem: &Problem,
        segment: usize,
        _dt: f64,
        loads: &[f64],
    ) -> Option<LawSteady> {
        let push = problem.pushes.get(segment)?;
        let scene = Scene::of(problem, &self.scene).ok()?;
        if !crate::law::usable_loads(loads, scene.points.len()) {
            return None;
        }
        let (omega, _) = omega_at_loads(&scene, push, self.law, loads).ok()?;
        let locked = self.law == Law::SimplifiedOneManifold && {
            let body = scene.body(loads).ok()?;
            simplified_locks(&scene.points, loads, scene.mu[0], &body, push)
        };
        Some(LawSteady {
            omega,
            class: if locked {
                LawClass::Locked
            } else {
                LawClass::Turns
            },
        })
    }
}
