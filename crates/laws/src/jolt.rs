//! Jolt 5.6's contact friction in closed form (no Jolt needed: only
//! `pushval-model`).
//!
//! From `Jolt/Physics/Constraints/ContactConstraintManager.cpp` of Jolt
//! 5.6.0 (oxijolt-sys vendors it; `CalculateFrictionConstraintProperties`
//! and `sSolveVelocityConstraint`):
//!
//! * **One friction point per manifold.** The friction rows of a contact
//!   manifold act at the *unweighted* average `c` of its contact points,
//!   whatever their loads.
//! * **Two linear rows, clamped together.** Along the tangents `t1 =
//!   n.GetNormalizedPerpendicular()`, `t2 = n × t1` — for a vertical normal
//!   the world's y and x axes, whatever the body's yaw — each row computes
//!   its total impulse `λ_k + m_k (u·t_k)` from the same velocity (its own
//!   effective mass `m_k`, the rows are not coupled), and the pair is scaled
//!   back into the disc of radius `μ Σλ_n` (the points' normal impulses of
//!   the previous iteration). Sliding, the fixed point of that iteration is
//!   the direction of `−D u`, `D = diag(m_x, m_y)` in world axes with
//!   `1/m_x = 1/m + r_y²/I_z`, `1/m_y = 1/m + r_x²/I_z` (`r = c − x_cm`,
//!   horizontal when the centre of mass is at the contact height): the
//!   friction force is **not** opposite the slip unless `m_x = m_y`
//!   ([`Direction::EffectiveMass`]).
//! * **One twist row.** About the normal, clamped on its own to `±μ Σ d_i
//!   λ_i` (`d_i` the distance of point i from `c`), only when the manifold
//!   has more than one point. Its effective mass is the plate's `I_z`, so
//!   while the plate turns it saturates: a torque `−sgn(ω) μ Σ d_i λ_i`
//!   *in addition to* the full linear friction. The allowed set is a
//!   cylinder (disc × interval), where Coulomb's is a coupled limit surface.
//!
//! Two scenes ([`Law::jolt_box`], [`Law::jolt_feet`]):
//!
//! * `jolt_box`: one box collider, one manifold of its four bottom corners:
//!   one disc at their centroid and one twist row. At ω = 0 the twist row
//!   jumps by `2T`, `T = μ Σ d_i λ_i`; it holds ω = 0 whenever the moment of
//!   the linear friction about the pusher, `M₀`, satisfies `|M₀| ≤ T`
//!   ([`at_rest`]). With a corner push the linear friction's moment arm is
//!   at most `|c − p_c|`, which is the corners' `d`, so with equal loads
//!   `|M₀| ≤ T` always: **the box never turns**. A single row can hold at
//!   rest exactly what it holds in Filippov's sense, so this law has no
//!   semi-stable class.
//! * `jolt_feet`: one sphere per support, one one-point manifold each (with
//!   manifold reduction off): no twist row, a disc of radius `μ λ_i` at the
//!   foot along `−D_i u_i`. With `m_x = m_y` at every foot that is Coulomb's
//!   law foot by foot; otherwise it depends on the yaw θ, through the world
//!   axes of `D_i`, and ω does not settle to a constant ([`tail_omega`]).
//!
//! The unweighted average biases a manifold with unequal loads: Coulomb's
//! translational friction acts at the load-weighted centre `Σ λ_i p_i /
//! Σ λ_i`, Jolt's at the plain mean `c` ([`averaging_bias`]).

use pushval_model::{cross, perp, rotate, Body, Problem, Push, Vec2};

use crate::{FrictionLaw, LawClass, LawSteady};

/// One contact manifold as Jolt's solver has it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Manifold {
    /// The friction point `c`: the unweighted mean of the manifold's contact
    /// points (m, object frame, relative to the centre of mass).
    pub point: Vec2,
    /// Radius of the linear friction disc, `μ Σ λ_i` as a force (N).
    pub cap: f64,
    /// Clamp of the twist row, `μ Σ d_i λ_i` (N m); 0 for a one-point
    /// manifold (Jolt makes no twist row then).
    pub twist_cap: f64,
}

impl Manifold {
    /// The manifold of contact `points` (m, object frame) with friction
    /// magnitudes `caps` (`μ λ_i` as forces, N).
    pub fn of(points: &[Vec2], caps: &[f64]) -> Self {
        let n = points.len() as f64;
        let c = points.iter().fold(Vec2::zeros(), |a, p| a + p) / n;
        let twist_cap = if points.len() > 1 {
            points
                .iter()
                .zip(caps)
                .map(|(p, f)| (p - c).norm() * f)
                .sum()
        } else {
            0.0
        };
        Self {
            point: c,
            cap: caps.iter().sum(),
            twist_cap,
        }
    }
}

/// Which way the linear friction of a sliding manifold points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Opposite the slip of the friction point, `−u/|u|`.
    Slip,
    /// What Jolt's iteration converges to: `−D u / |D u|`, `D` the diagonal
    /// of the two world-axis rows' effective masses at the friction point
    /// (see the module docs).
    EffectiveMass,
}

/// A friction law: manifolds and the direction rule.
#[derive(Debug, Clone, PartialEq)]
pub struct Law {
    /// The manifolds.
    pub manifolds: Vec<Manifold>,
    /// The direction rule of the linear rows.
    pub direction: Direction,
    /// Mass (kg) and yaw inertia about the centre of mass (kg m²) for the
    /// rows' effective masses.
    pub mass: f64,
    /// Yaw inertia about the centre of mass (kg m²).
    pub inertia: f64,
}

/// The corners of the supports' bounding rectangle (object frame), in the
/// order (−,−), (+,−), (+,+), (−,+): the bottom face of `jolt_box`'s box.
pub fn box_corners(body: &Body) -> [Vec2; 4] {
    let (mut lo, mut hi) = (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY));
    for s in body.supports() {
        lo = lo.inf(&s.position);
        hi = hi.sup(&s.position);
    }
    [
        Vec2::new(lo.x, lo.y),
        Vec2::new(hi.x, lo.y),
        Vec2::new(hi.x, hi.y),
        Vec2::new(lo.x, hi.y),
    ]
}

impl Law {
    /// `jolt_box`: one manifold of the box's four bottom corners
    /// ([`box_corners`]) with friction magnitudes `caps` (N, one per corner;
    /// `None`: the body's total friction split equally).
    pub fn jolt_box(body: &Body, caps: Option<&[f64]>, direction: Direction) -> Self {
        let corners = box_corners(body);
        let equal = [body.total_friction() / 4.0; 4];
        Self {
            manifolds: vec![Manifold::of(&corners, caps.unwrap_or(&equal))],
            direction,
            mass: body.mass(),
            inertia: body.inertia_cm(),
        }
    }

    /// `jolt_feet`: one one-point manifold per support with friction
    /// magnitudes `caps` (N; `None`: the problem's `F_i`).
    pub fn jolt_feet(body: &Body, caps: Option<&[f64]>, direction: Direction) -> Self {
        let manifolds = body
            .supports()
            .enumerate()
            .map(|(i, s)| Manifold {
                point: s.position,
                cap: caps.map_or(s.friction, |c| c[i]),
                twist_cap: 0.0,
            })
            .collect();
        Self {
            manifolds,
            direction,
            mass: body.mass(),
            inertia: body.inertia_cm(),
        }
    }

    /// The two world-axis effective masses `(m_x, m_y)` (kg) at a point
    /// `r` (m, world axes, relative to the centre of mass).
    pub fn effective_masses(&self, r: Vec2) -> (f64, f64) {
        let inv = 1.0 / self.mass;
        (
            1.0 / (inv + r.y * r.y / self.inertia),
            1.0 / (inv + r.x * r.x / self.inertia),
        )
    }

    /// The friction force (N, object frame) of manifold `k` when its point
    /// slips at `u` (m/s, object frame) and the body's yaw is `theta` (rad);
    /// zero when `u` is.
    pub fn force(&self, k: usize, u: Vec2, theta: f64) -> Vec2 {
        let m = &self.manifolds[k];
        let dir = match self.direction {
            Direction::Slip => u,
            Direction::EffectiveMass => {
                let (mx, my) = self.effective_masses(rotate(theta, &m.point));
                let uw = rotate(theta, &u);
                rotate(-theta, &Vec2::new(mx * uw.x, my * uw.y))
            }
        };
        let n = dir.norm();
        if n > 0.0 {
            -dir * (m.cap / n)
        } else {
            Vec2::zeros()
        }
    }

    /// The twist rows' total clamp `T = Σ μ Σ d_i λ_i` (N m).
    pub fn twist_cap(&self) -> f64 {
        self.manifolds.iter().map(|m| m.twist_cap).sum()
    }

    /// Whether the law depends on the yaw: [`Direction::EffectiveMass`] with
    /// some manifold whose two effective masses differ at θ = 0 or π/4
    /// (relative 1e-12).
    pub fn depends_on_yaw(&self) -> bool {
        self.direction == Direction::EffectiveMass
            && self.manifolds.iter().any(|m| {
                [0.0, std::f64::consts::FRAC_PI_4].iter().any(|&t| {
                    let (a, b) = self.effective_masses(rotate(t, &m.point));
                    (a - b).abs() > 1e-12 * a.max(b)
                })
            })
    }
}

/// Velocity (m/s, object frame) of the object point `p` when the pusher
/// drives the contact point at `v_c n_φ` and the body turns at ω.
fn point_velocity(body: &Body, push: &Push, omega: f64, p: Vec2) -> Vec2 {
    push.velocity() + perp(&(p - body.contact())) * omega
}

/// The continuous part of `I_P ω̇` (N m): the linear rows' moment about the
/// contact point plus the inertial term `m v_c ω (p_c·n_φ)`, at yaw θ. The
/// twist rows are left out ([`moment`] adds them).
pub fn linear_moment(law: &Law, body: &Body, push: &Push, omega: f64, theta: f64) -> f64 {
    let pc = body.contact();
    let mut g = body.mass() * push.speed * omega * pc.dot(&push.direction());
    for (k, m) in law.manifolds.iter().enumerate() {
        let u = point_velocity(body, push, omega, m.point);
        g += cross(&(m.point - pc), &law.force(k, u, theta));
    }
    g
}

/// `G(ω, θ) = I_P ω̇` (N m) for ω ≠ 0: [`linear_moment`] plus the saturated
/// twist rows `−sgn(ω) T`; at ω = 0 the twist rows are left out (they are
/// set-valued there, see [`at_rest`]).
pub fn moment(law: &Law, body: &Body, push: &Push, omega: f64, theta: f64) -> f64 {
    let t = if omega > 0.0 {
        -law.twist_cap()
    } else if omega < 0.0 {
        law.twist_cap()
    } else {
        0.0
    };
    linear_moment(law, body, push, omega, theta) + t
}

/// What ω = 0 is under the law at yaw θ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AtRest {
    /// `|M₀| ≤ T`: the twist rows hold ω = 0 (from both sides: one row per
    /// manifold, so Filippov's condition and the static balance coincide).
    Locked,
    /// `|M₀| > T`: ω leaves 0.
    Turns,
}

impl AtRest {
    /// `"locked"` or `"turns"` (the study's `class` column).
    pub fn as_str(&self) -> &'static str {
        match self {
            AtRest::Locked => "locked",
            AtRest::Turns => "turns",
        }
    }
}

/// `(M₀, T)` (N m): the linear rows' moment about the contact point at
/// ω = 0 and yaw θ, and the twist rows' clamp.
pub fn rest_moments(law: &Law, body: &Body, push: &Push, theta: f64) -> (f64, f64) {
    (linear_moment(law, body, push, 0.0, theta), law.twist_cap())
}

/// The class of ω = 0 at yaw θ ([`AtRest`]).
pub fn at_rest(law: &Law, body: &Body, push: &Push, theta: f64) -> AtRest {
    let (m0, t) = rest_moments(law, body, push, theta);
    if m0.abs() <= t {
        AtRest::Locked
    } else {
        AtRest::Turns
    }
}

/// The reduced dynamics `I_P ω̇ = G(ω, θ)`, `θ̇ = ω` of the law from
/// `(theta0, omega0)` for `duration` s, in steps of at most `h` s, with the
/// twist rows as Jolt applies them (a velocity-level clamp: the torque that
/// stops ω within the step, clamped to `±T`); returns the mean ω (rad/s)
/// over the last fifth of the time, the way the engine's ω is averaged. For
/// a yaw-independent law this is the steady ω it reaches.
pub fn tail_omega(
    law: &Law,
    body: &Body,
    push: &Push,
    duration: f64,
    (theta0, omega0): (f64, f64),
    h: f64,
) -> f64 {
    let n = (duration / h).ceil().max(1.0) as usize;
    let h = duration / n as f64;
    let ip = body.inertia_contact();
    let t_cap = law.twist_cap();
    let (mut theta, mut omega) = (theta0, omega0);
    let tail_from = (0.8 * n as f64).floor() as usize;
    let (mut acc, mut cnt) = (0.0, 0usize);
    for k in 0..n {
        // Midpoint in θ for the yaw-dependent directions.
        let g = linear_moment(law, body, push, omega, theta + 0.5 * h * omega);
        let free = omega + h * g / ip;
        let twist = (-free * ip / h).clamp(-t_cap, t_cap);
        let next = free + h * twist / ip;
        theta += 0.5 * h * (omega + next);
        omega = next;
        if k >= tail_from {
            acc += omega;
            cnt += 1;
        }
    }
    acc / cnt as f64
}

/// The reduced dynamics of [`tail_omega`], sampled every `every` s:
/// `(θ, ω)` at each sample (rad, rad/s).
pub fn integrate(
    law: &Law,
    body: &Body,
    push: &Push,
    duration: f64,
    (theta0, omega0): (f64, f64),
    h: f64,
    every: f64,
) -> (Vec<f64>, Vec<f64>) {
    let n = (duration / h).ceil().max(1.0) as usize;
    let h = duration / n as f64;
    let stride = ((every / h).round() as usize).max(1);
    let ip = body.inertia_contact();
    let t_cap = law.twist_cap();
    let (mut theta, mut omega) = (theta0, omega0);
    let (mut ths, mut ws) = (Vec::new(), Vec::new());
    for k in 0..n {
        let g = linear_moment(law, body, push, omega, theta + 0.5 * h * omega);
        let free = omega + h * g / ip;
        let twist = (-free * ip / h).clamp(-t_cap, t_cap);
        let next = free + h * twist / ip;
        theta += 0.5 * h * (omega + next);
        omega = next;
        if (k + 1) % stride == 0 {
            ths.push(theta);
            ws.push(omega);
        }
    }
    (ths, ws)
}

/// The steady ω (rad/s) a yaw-independent law reaches from ω = 0 at yaw 0:
/// 0 when [`at_rest`] says locked, otherwise the first root of
/// `G(ω, 0)` marching from 0 in the direction of `G(0±)` and bisecting
/// (as the PhysX crate's `steady_omega`). For a yaw-dependent law use
/// [`tail_omega`].
pub fn steady_omega(law: &Law, body: &Body, push: &Push) -> f64 {
    if at_rest(law, body, push, 0.0) == AtRest::Locked && law.twist_cap() > 0.0 {
        return 0.0;
    }
    let g = |w: f64| moment(law, body, push, w, 0.0);
    let eps = 1e-12;
    let (gp, gm) = (g(eps), g(-eps));
    if gp <= 0.0 && gm >= 0.0 {
        return 0.0;
    }
    let dir = if gp > 0.0 && gm > 0.0 {
        1.0
    } else if gp < 0.0 && gm < 0.0 {
        -1.0
    } else {
        (gp + gm).signum()
    };
    let mut lo = dir * eps;
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
        if mid == lo || mid == hi {
            break;
        }
        if g(mid) * dir > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The bias of the unweighted average on a manifold of `points` (m, object
/// frame) with loads `loads` (any unit): the plain mean `c` minus the
/// load-weighted centre `Σ λ_i p_i / Σ λ_i` (m). Jolt applies the linear
/// friction `F` at `c`, Coulomb's translating body has it at the weighted
/// centre: the moment about any point differs by `bias × F`.
pub fn averaging_bias(points: &[Vec2], loads: &[f64]) -> Vec2 {
    let n = points.len() as f64;
    let mean = points.iter().fold(Vec2::zeros(), |a, p| a + p) / n;
    let w: f64 = loads.iter().sum();
    let weighted = points
        .iter()
        .zip(loads)
        .fold(Vec2::zeros(), |a, (p, l)| a + p * *l)
        / w;
    mean - weighted
}

/// The angle (rad, in (−π, π]) from the slip's opposite `−u` to the force
/// `f`, positive counter-clockwise: 0 for Coulomb.
pub fn friction_slip_angle(f: Vec2, u: Vec2) -> f64 {
    let a = -u;
    cross(&a, &f).atan2(a.dot(&f))
}

/// `jolt_box`'s law ([`Law::jolt_box`] with the problem's loads, rows along
/// the effective-mass direction): yaw-independent, its root or its lock.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct JoltBox;

/// `jolt_feet`'s law ([`Law::jolt_feet`] with the problem's loads, rows
/// along the effective-mass direction): yaw-dependent, the mean ω over the
/// last fifth of the segment of the law's reduced dynamics ([`tail_omega`])
/// at the run's step (at most 1 ms).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct JoltFeet;

/// From ω = 0 at yaw 0, with the problem's loads (`F_i = μ_i N_i`; the
/// engine's own split of four feet's loads is undetermined and may differ:
/// crates/engines/jolt/README.md).
fn jolt_steady(feet: bool, problem: &Problem, segment: usize, dt: f64) -> Option<LawSteady> {
    let push = problem.pushes.get(segment)?;
    let body = &problem.body;
    let law = if feet {
        Law::jolt_feet(body, None, Direction::EffectiveMass)
    } else {
        Law::jolt_box(body, None, Direction::EffectiveMass)
    };
    let class = match at_rest(&law, body, push, 0.0) {
        AtRest::Locked => LawClass::Locked,
        AtRest::Turns => LawClass::Turns,
    };
    let omega = if law.depends_on_yaw() {
        tail_omega(&law, body, push, push.duration, (0.0, 0.0), dt.min(1e-3))
    } else {
        steady_omega(&law, body, push)
    };
    Some(LawSteady { omega, class })
}

impl FrictionLaw for JoltBox {
    fn law_name(&self) -> &'static str {
        "one manifold: a friction disc of radius μΣN at the corners' unweighted mean, rows along the world axes (effective-mass direction), and a twist row clamped to μΣ dᵢNᵢ (pushval_jolt::predict)"
    }
    fn steady(&self, problem: &Problem, segment: usize, dt: f64) -> Option<LawSteady> {
        jolt_steady(false, problem, segment, dt)
    }
}

impl FrictionLaw for JoltFeet {
    fn law_name(&self) -> &'static str {
        "a friction disc of radius μN per foot, rows along the world axes (effective-mass direction, yaw-dependent), no twist row (pushval_jolt::predict)"
    }
    fn steady(&self, problem: &Problem, segment: usize, dt: f64) -> Option<LawSteady> {
        jolt_steady(true, problem, segment, dt)
    }
}
