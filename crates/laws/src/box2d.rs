//! The steady state of Box2D's top-down friction idiom (model
//! `box2d_motor_joint`) in closed form.
//!
//! A motor joint from a static ground body to the object's centre of mass
//! with zero target velocities solves, every sub-step, for the impulse that
//! would stop the object, and caps it: the linear impulse at `h F_max` in
//! length (a disk), the angular one at `h T_max`, each on its own. While the
//! object slides and turns, both caps are active, so the joint is a "box"
//! friction law, force and torque capped separately:
//!
//! ```text
//! f = −F_max v_cm / |v_cm|        (N, at the centre of mass)
//! τ = −T_max sgn ω                (N m; any value in [−T_max, T_max] at ω = 0)
//! ```
//!
//! With `F_max = Σ F_i` and `T_max = Σ F_i |p_i|` ([`motor_joint_limits`]).
//! The pusher holds the contact point `p_c` at `v_c n_φ` (object frame), so
//! `v_cm = v_c n_φ − ω D p_c`. The moment balance about the contact point
//! (docs/architecture.md, "The model", with the friction moment `(0 − p_c) × f + τ`) is
//!
//! ```text
//! I_P ω̇ = g(ω) = F_max (v_c c − ω L²) / |v_cm|  −  T_max sgn ω  +  m v_c a ω
//! |v_cm|² = v_c² − 2 v_c c ω + ω² L²
//! c = p_c × n_φ,   a = p_c · n_φ,   L = |p_c|
//! ```
//!
//! The first term is non-increasing in ω (its derivative is
//! `F_max v_c² (c² − L²)/|v_cm|³ ≤ 0`), and `−T_max sgn ω` steps down at 0.
//! Hence:
//!
//! * **Lock.** At ω = 0 the first term is `F_max c`; the torque cap holds
//!   the object from turning (`ω* = 0`, whatever `v_c` and `m`) exactly when
//!   `F_max |c| ≤ T_max` ([`motor_joint_locks`]). With equal loads this is
//!   `|c| ≤ r̄`, the mean support distance: a contact point no farther from
//!   the centre of mass than the supports on average (every corner push of
//!   a square plate, for example) never turns the object.
//! * **Otherwise** the steady ω is the root of `g` on the side of 0 where
//!   `F_max c` points. For `a ≤ 0` (the pusher pushes towards the centre of
//!   mass) `g` is decreasing and the root is unique and stable; for `a > 0`
//!   the inertial term can destabilise it, as in the dynamic model. In the
//!   quasi-static limit (`m v_c a → 0`) the root is explicit: with
//!   `x = ω L / v_c`, `γ = c/L` and `ρ = T_max/(F_max L) < 1`,
//!   `x = γ − sgn(γ) ρ √((1 − γ²)/(1 − ρ²))` ([`motor_joint_quasi_static`]).
//!
//! [`motor_joint_steady`] returns the steady ω a transient from a given ω
//! reaches, to round-off (a bracket from the closed-form moment, then
//! bisection). Compare the Coulomb steady state of the same push:
//! `pushval_model::SegmentDynamics::steady_states`.
//!
//! Units: SI (m, kg, N, N m, rad/s); positions in the object frame relative
//! to the centre of mass.

use pushval_model::{cross, Body, Problem, Push};

use crate::{FrictionLaw, LawClass, LawSteady};

/// The motor joint's caps for a body: `F_max = Σ F_i` (N), the total sliding
/// friction (`μ m g` for one μ), and `T_max = Σ F_i |p_i|` (N m), the
/// friction torque of a pure spin about the centre of mass (`μ m g` times the
/// mean support distance for equal loads). The values a Box2D user would pick
/// for top-down friction.
pub fn motor_joint_limits(body: &Body) -> (f64, f64) {
    body.supports().fold((0.0, 0.0), |(f, t), s| {
        (f + s.friction, t + s.friction * s.position.norm())
    })
}

/// The constants of the moment balance for one push.
#[derive(Debug, Clone, Copy)]
struct Balance {
    f_max: f64,
    t_max: f64,
    speed: f64,
    /// `p_c × n_φ` (m).
    c: f64,
    /// `|p_c|²` (m²).
    l2: f64,
    /// `m v_c (p_c · n_φ)` (kg m²/s).
    k: f64,
}

impl Balance {
    fn new(body: &Body, push: &Push) -> Self {
        let (f_max, t_max) = motor_joint_limits(body);
        let pc = body.contact();
        let n = push.direction();
        Self {
            f_max,
            t_max,
            speed: push.speed,
            c: cross(&pc, &n),
            l2: pc.norm_squared(),
            k: body.mass() * push.speed * pc.dot(&n),
        }
    }

    /// The friction force's moment about the contact point (N m), without
    /// the torque cap; 0 where the centre of mass does not move.
    fn force_moment(&self, omega: f64) -> f64 {
        let q = self.speed * self.c - omega * self.l2;
        let v2 =
            self.speed * self.speed - 2.0 * self.speed * self.c * omega + omega * omega * self.l2;
        if v2 > 0.0 {
            self.f_max * q / v2.sqrt()
        } else {
            0.0
        }
    }

    /// `g(ω)` for ω ≠ 0 (N m).
    fn moment(&self, omega: f64) -> f64 {
        self.force_moment(omega) - self.t_max * omega.signum() + self.k * omega
    }
}

/// `I_P ω̇ = g(ω)` (N m) of the motor-joint friction at ω (rad/s) for `push`;
/// at ω = 0 the torque the joint needs to hold the object (its cap
/// permitting) is taken, so `g(0) = 0` when the joint locks.
pub fn motor_joint_moment(body: &Body, push: &Push, omega: f64) -> f64 {
    let b = Balance::new(body, push);
    if omega == 0.0 {
        let m0 = b.force_moment(0.0);
        return m0 - m0.clamp(-b.t_max, b.t_max);
    }
    b.moment(omega)
}

/// Whether the motor joint's torque cap holds the object at ω = 0 for
/// `push`: `F_max |p_c × n_φ| ≤ T_max`.
pub fn motor_joint_locks(body: &Body, push: &Push) -> bool {
    let b = Balance::new(body, push);
    b.f_max * b.c.abs() <= b.t_max
}

/// The quasi-static steady ω (rad/s, `m v_c (p_c · n_φ)` neglected) of the
/// motor-joint friction: 0 when the joint locks, else
/// `(v_c / L) (γ − sgn(γ) ρ √((1 − γ²)/(1 − ρ²)))` with `γ = (p_c × n_φ)/L`,
/// `ρ = T_max/(F_max L)`, `L = |p_c|`.
pub fn motor_joint_quasi_static(body: &Body, push: &Push) -> f64 {
    let b = Balance::new(body, push);
    if push.speed == 0.0 || b.f_max * b.c.abs() <= b.t_max {
        return 0.0;
    }
    let l = b.l2.sqrt();
    let gamma = b.c / l;
    let rho = b.t_max / (b.f_max * l);
    let x = gamma - gamma.signum() * rho * ((1.0 - gamma * gamma) / (1.0 - rho * rho)).sqrt();
    push.speed / l * x
}

/// The sign of `x`: −1, 0 or 1.
fn sgn(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// A steady state of the motor-joint friction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorJointSteady {
    /// ω* (rad/s).
    pub omega: f64,
    /// The torque cap holds the object at ω* = 0.
    pub locked: bool,
}

/// The steady ω (rad/s) a transient of the motor-joint friction starting at
/// `omega0` (rad/s) reaches for `push`: the first root of `g` in the
/// direction `g` drives ω, or the lock at 0. None when ω runs away (only
/// possible for `p_c · n_φ > 0`).
pub fn motor_joint_steady(body: &Body, push: &Push, omega0: f64) -> Option<MotorJointSteady> {
    let b = Balance::new(body, push);
    let locked = Some(MotorJointSteady {
        omega: 0.0,
        locked: true,
    });
    if push.speed == 0.0 {
        // Nothing moves the centre of mass; the torque cap stops any turn.
        return locked;
    }
    // g at ω → 0 from the side of sign `side`.
    let at_zero = |side: f64| b.force_moment(0.0) - b.t_max * side;
    // g at ω on the side `side` of 0 (ω = 0 stands for the one-sided limit).
    let g = |w: f64, side: f64| if w == 0.0 { at_zero(side) } else { b.moment(w) };
    let (mut lo, mut side, dir) = if omega0 == 0.0 {
        let m0 = b.force_moment(0.0);
        if m0.abs() <= b.t_max {
            return locked;
        }
        (0.0, m0.signum(), m0.signum())
    } else {
        let g0 = b.moment(omega0);
        if g0 == 0.0 {
            return Some(MotorJointSteady {
                omega: omega0,
                locked: false,
            });
        }
        (omega0, omega0.signum(), g0.signum())
    };
    // Bisection of a bracket [a, z] on one side of 0, g(a) of sign `dir`.
    let bisect = |mut a: f64, mut z: f64, side: f64| {
        for _ in 0..200 {
            let mid = 0.5 * (a + z);
            if mid == a || mid == z {
                break;
            }
            if sgn(g(mid, side)) == dir {
                a = mid;
            } else {
                z = mid;
            }
        }
        0.5 * (a + z)
    };
    // March from ω0 in the direction g drives it, in steps growing by
    // doubling, until g changes sign; passing through 0, the lock decides.
    let scale = push.speed / b.l2.sqrt().max(1e-300);
    let mut h = 1e-3 * scale.max(omega0.abs());
    for _ in 0..400 {
        let hi = lo + dir * h;
        if side != dir && (hi == 0.0 || hi.signum() != side) {
            // The step reaches 0 from the side `side`.
            if sgn(at_zero(side)) != dir {
                return Some(MotorJointSteady {
                    omega: bisect(lo, 0.0, side),
                    locked: false,
                });
            }
            if sgn(at_zero(-side)) != dir {
                return locked;
            }
            side = -side;
            lo = 0.0;
            continue;
        }
        let ghi = b.moment(hi);
        if sgn(ghi) != dir {
            return Some(MotorJointSteady {
                omega: if ghi == 0.0 { hi } else { bisect(lo, hi, side) },
                locked: false,
            });
        }
        lo = hi;
        h *= 2.0;
    }
    None
}

/// Box2D's motor joint to the ground as a law: force capped at `Σ F_i`,
/// torque at `Σ F_i |p_i|`, each on its own ([`motor_joint_steady`] from
/// ω = 0). The caps come from the problem's support friction; no parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Box2dMotorJoint;

impl FrictionLaw for Box2dMotorJoint {
    fn law_name(&self) -> &'static str {
        "motor joint to the ground: force and torque capped apart (pushval_box2d::predict)"
    }
    fn steady(&self, problem: &Problem, segment: usize, _dt: f64) -> Option<LawSteady> {
        let push = problem.pushes.get(segment)?;
        let s = motor_joint_steady(&problem.body, push, 0.0)?;
        Some(LawSteady {
            omega: s.omega,
            class: if s.locked {
                LawClass::Locked
            } else {
                LawClass::Turns
            },
        })
    }
}
