//! Closed forms that explain where MuJoCo departs from the Coulomb model
//! (no MuJoCo needed; they use only `pushval-model`), and the law of its
//! elliptic cone with load transfer ([`MujocoElliptic`]).
//!
//! [`FrictionLaw`] here is a *support-force* law (the force on one support
//! for its slip); the steady-state interface all engines' laws answer is
//! [`crate::FrictionLaw`].

use pushval_model::{cross, Body, Problem, Push, SegmentDynamics, Vec2};

use crate::{LawClass, LawSteady, COULOMB};

/// A support-friction law: the force (N, object frame) on support `i`
/// sliding with velocity `u` (m/s, object frame), given its Coulomb
/// magnitude `f = μ_i N_i` (N).
pub trait FrictionLaw {
    /// The force (N, object frame) on support `i` sliding at `u` (m/s),
    /// Coulomb magnitude `f` (N).
    fn force(&self, i: usize, u: Vec2, f: f64) -> Vec2;
}

/// Coulomb friction, `−f u/|u|`.
pub struct Coulomb;

impl FrictionLaw for Coulomb {
    fn force(&self, _i: usize, u: Vec2, f: f64) -> Vec2 {
        let n = u.norm();
        if n > 0.0 {
            -u * (f / n)
        } else {
            Vec2::zeros()
        }
    }
}

/// Coulomb friction made viscous below the slip speed `v_s` (m/s):
/// `−f u / max(|u|, v_s)`. The force of a soft (regularised) contact.
pub struct Regularised {
    /// The slip speed `v_s` (m/s).
    pub slip_speed: f64,
}

impl FrictionLaw for Regularised {
    fn force(&self, _i: usize, u: Vec2, f: f64) -> Vec2 {
        -u * (f / u.norm().max(self.slip_speed))
    }
}

/// `G(ω) = I_P ω̇` (N m) for `law`: the friction moment about the contact
/// point plus the inertial term `m v_c ω (p_c · n_φ)`, with the support
/// friction magnitudes `forces` (N; default the body's).
pub fn moment(body: &Body, push: &Push, omega: f64, law: &dyn FrictionLaw, forces: &[f64]) -> f64 {
    let pc = body.contact();
    let v = push.velocity();
    let mut m = body.mass() * push.speed * omega * pc.dot(&push.direction());
    for (i, s) in body.supports().enumerate() {
        let r = s.position - pc;
        let u = v + Vec2::new(-r.y, r.x) * omega;
        m += cross(&r, &law.force(i, u, forces[i]));
    }
    m
}

/// Steady ω (rad/s) under `law` with support friction magnitudes `forces`:
/// the root of [`moment`] nearest `guess`, found by bracketing and bisection.
pub fn steady_omega(
    body: &Body,
    push: &Push,
    law: &dyn FrictionLaw,
    forces: &[f64],
    guess: f64,
) -> Option<f64> {
    let g = |w: f64| moment(body, push, w, law, forces);
    let mut d = 1e-3 * guess.abs().max(1e-3);
    let (mut lo, mut hi) = (guess - d, guess + d);
    for _ in 0..80 {
        if g(lo) * g(hi) <= 0.0 {
            break;
        }
        d *= 1.6;
        lo = guess - d;
        hi = guess + d;
    }
    if g(lo) * g(hi) > 0.0 {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(lo) * g(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// The Coulomb model's stable steady ω nearest `omega0` (rad/s).
pub fn coulomb_steady(body: &Body, push: &Push, omega0: f64) -> Option<f64> {
    let seg = SegmentDynamics::new(body, push);
    let roots = seg.steady_states();
    seg.attractor(&roots, omega0).map(|r| r.omega)
}

/// Normal loads (N) of the supports when the horizontal forces act at
/// heights that are not the centre of mass's: quasi-static tilt balance with
/// the supports' friction forces `friction` (N, object frame, at the floor),
/// the pusher force `f_c` at height `h_push` and the centre of mass at
/// `h_cm` (m); `rest` are the loads at rest (N). The extra load moment is
/// spread over the supports by the least-norm (elastic-foundation) rule,
/// `ΔN_i = c_0 + c · p_i`.
///
/// Moment balance about the centre of mass for horizontal axes gives
/// `Σ p_i N_i = Σ p_i N_i^rest + (h_push − h_cm) m a − h_push Σ f_i`, with
/// `m a = f_c + Σ f_i`.
pub fn transferred_loads(
    body: &Body,
    rest: &[f64],
    friction: &[Vec2],
    f_c: Vec2,
    h_cm: f64,
    h_push: f64,
) -> Vec<f64> {
    let sum_f: Vec2 = friction.iter().fold(Vec2::zeros(), |a, b| a + b);
    // Required change of the load moment Σ p_i ΔN_i (object frame).
    let dm = f_c * (h_push - h_cm) - sum_f * h_cm;
    let pts: Vec<Vec2> = body.supports().map(|s| s.position).collect();
    least_norm_loads(&pts, dm)
        .iter()
        .zip(rest)
        .map(|(d, r)| r + d)
        .collect()
}

/// The loads (N) of the supports at rest by the least-norm rule: the
/// `N_i = a + b · p_i` with `Σ N_i = weight` (N) and `Σ p_i N_i = 0` (the
/// supports' positions are relative to the centre of mass). Statics for up
/// to three supports; for more, the elastic-foundation split (equal loads on
/// a symmetric square). None when the supports lie on one line.
pub fn rest_loads(body: &Body, weight: f64) -> Option<Vec<f64>> {
    let pts: Vec<Vec2> = body.supports().map(|s| s.position).collect();
    let n = pts.len() as f64;
    let sx: f64 = pts.iter().map(|p| p.x).sum();
    let sy: f64 = pts.iter().map(|p| p.y).sum();
    let sxx: f64 = pts.iter().map(|p| p.x * p.x).sum();
    let syy: f64 = pts.iter().map(|p| p.y * p.y).sum();
    let sxy: f64 = pts.iter().map(|p| p.x * p.y).sum();
    let m = [[n, sx, sy], [sx, sxx, sxy], [sy, sxy, syy]];
    let a = solve3(m, [weight, 0.0, 0.0]);
    if a == [0.0; 3] {
        return None;
    }
    Some(pts.iter().map(|p| a[0] + a[1] * p.x + a[2] * p.y).collect())
}

/// The steady state under Coulomb friction with load transfer for a scene
/// whose feet were calibrated at rest (`μ_i = F_i / N_i^rest`, the MuJoCo
/// adapter's calibration, with the [`rest_loads`] of weight `weight`): the
/// steady ω (rad/s) and the feet's loads (N), from
/// [`steady_omega_load_transfer`]. With both heights 0 the loads are the
/// rest loads and ω is the Coulomb model's. None where a support with
/// friction carries no load at rest or the iteration finds no root.
pub fn calibrated_load_transfer(
    body: &Body,
    push: &Push,
    weight: f64,
    h_cm: f64,
    h_push: f64,
) -> Option<(f64, Vec<f64>)> {
    let rest = rest_loads(body, weight)?;
    let mut mu = Vec::with_capacity(rest.len());
    for (s, &n) in body.supports().zip(&rest) {
        if s.friction == 0.0 {
            mu.push(0.0);
        } else if n > 0.0 {
            mu.push(s.friction / n);
        } else {
            return None;
        }
    }
    steady_omega_load_transfer(body, push, &mu, &rest, h_cm, h_push)
}

/// The least-norm ΔN with `Σ ΔN_i = 0` and `Σ p_i ΔN_i = dm`.
fn least_norm_loads(pts: &[Vec2], dm: Vec2) -> Vec<f64> {
    // ΔN_i = a + b·p_i; solve the 3×3 normal equations.
    let n = pts.len() as f64;
    let sx: f64 = pts.iter().map(|p| p.x).sum();
    let sy: f64 = pts.iter().map(|p| p.y).sum();
    let sxx: f64 = pts.iter().map(|p| p.x * p.x).sum();
    let syy: f64 = pts.iter().map(|p| p.y * p.y).sum();
    let sxy: f64 = pts.iter().map(|p| p.x * p.y).sum();
    let a = solve3(
        [[n, sx, sy], [sx, sxx, sxy], [sy, sxy, syy]],
        [0.0, dm.x, dm.y],
    );
    pts.iter().map(|p| a[0] + a[1] * p.x + a[2] * p.y).collect()
}

/// The 3×3 system `m x = b` (singular: zeros).
fn solve3(m: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let m = nalgebra::Matrix3::from_fn(|r, c| m[r][c]);
    m.lu()
        .solve(&nalgebra::Vector3::from(b))
        .map_or([0.0; 3], |x| x.into())
}

/// Steady ω with load transfer: iterate `ω → forces(ω) → loads → ω` from
/// the Coulomb steady state. `mu` are the support friction coefficients and
/// `rest` the loads at rest (N).
pub fn steady_omega_load_transfer(
    body: &Body,
    push: &Push,
    mu: &[f64],
    rest: &[f64],
    h_cm: f64,
    h_push: f64,
) -> Option<(f64, Vec<f64>)> {
    let mut w = coulomb_steady(body, push, 0.0)?;
    let mut forces: Vec<f64> = body.supports().map(|s| s.friction).collect();
    let pc = body.contact();
    let dir = push.direction();
    let mut loads = rest.to_vec();
    for _ in 0..50 {
        // Friction forces at the steady state (object frame).
        let fr: Vec<Vec2> = body
            .supports()
            .enumerate()
            .map(|(i, s)| {
                let r = s.position - pc;
                let u = push.velocity() + Vec2::new(-r.y, r.x) * w;
                Coulomb.force(i, u, forces[i])
            })
            .collect();
        let sum: Vec2 = fr.iter().fold(Vec2::zeros(), |a, b| a + b);
        // Steady: ω̇ = 0, a_cm = v_c ω D n_φ + ω² p_c.
        let a = Vec2::new(-dir.y, dir.x) * (push.speed * w) + pc * (w * w);
        let f_c = a * body.mass() - sum;
        loads = transferred_loads(body, rest, &fr, f_c, h_cm, h_push);
        forces = loads
            .iter()
            .zip(mu)
            .map(|(n, m)| (n * m).max(0.0))
            .collect();
        let w_new = steady_omega(body, push, &Coulomb, &forces, w)?;
        if (w_new - w).abs() < 1e-12 * w.abs().max(1.0) {
            w = w_new;
            break;
        }
        w = w_new;
    }
    Some((w, loads))
}

/// MuJoCo's elliptic cone: Coulomb at every foot with the feet calibrated at
/// rest (`μ_i = F_i / N_i`) and the loads of the quasi-static tilting
/// balance when the centre of mass or the pusher is above the floor, spread
/// by the least-norm rule ([`calibrated_load_transfer`]). At both heights 0
/// the loads are the rest loads and the steady state is [`COULOMB`]'s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MujocoElliptic {
    /// Height of the centre of mass above the floor (m, ≥ 0); default 0.
    pub cm_height: f64,
    /// Height of the pusher above the floor (m, ≥ 0); default 0.
    pub push_height: f64,
    /// Gravity (m/s²); default 9.81.
    pub gravity: f64,
}

impl Default for MujocoElliptic {
    fn default() -> Self {
        Self {
            cm_height: 0.0,
            push_height: 0.0,
            gravity: 9.81,
        }
    }
}

impl MujocoElliptic {
    /// Whether the centre of mass or the pusher is above the floor (the
    /// push then moves load between the feet).
    pub fn raised(&self) -> bool {
        self.cm_height != 0.0 || self.push_height != 0.0
    }

    fn transfer(&self, problem: &Problem, segment: usize) -> Option<(f64, Vec<f64>)> {
        let push = problem.pushes.get(segment)?;
        calibrated_load_transfer(
            &problem.body,
            push,
            problem.body.mass() * self.gravity,
            self.cm_height,
            self.push_height,
        )
    }
}

impl crate::FrictionLaw for MujocoElliptic {
    fn law_name(&self) -> &'static str {
        "Coulomb at every foot (elliptic cone) with the loads of the tilting balance (pushval_mujoco::theory::calibrated_load_transfer)"
    }
    fn steady(&self, problem: &Problem, segment: usize, dt: f64) -> Option<LawSteady> {
        if !self.raised() {
            return COULOMB.steady(problem, segment, dt);
        }
        let (omega, _) = self.transfer(problem, segment)?;
        Some(LawSteady {
            omega,
            class: if omega == 0.0 {
                LawClass::Locked
            } else {
                LawClass::Turns
            },
        })
    }
    /// The feet's loads (N) in the steady state, least-norm split of the
    /// weight `m g` at rest plus the transfer; a negative load means the
    /// foot would lift (the scene's assumptions fail there).
    fn loads(&self, problem: &Problem, segment: usize, _dt: f64) -> Option<Vec<f64>> {
        self.transfer(problem, segment).map(|(_, loads)| loads)
    }
    /// Coulomb at every foot with the given loads (the transfer is what the
    /// run's loads already hold).
    fn coulomb_on_run_loads(&self) -> bool {
        true
    }
}
