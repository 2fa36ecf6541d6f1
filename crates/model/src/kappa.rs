//! The scaling factor `κ = ω* / (v_c ψ)` between the dynamic steady angular
//! velocity ω* and the kinematic (quasi-static) one `v_c ψ`, exactly and as a
//! series in the Froude number.
//!
//! # Froude number
//!
//! `Fr = v_c² / (μ̄ g L)` with `μ̄ = Σ μ_i N_i / (m g)` and `L = |p_c − p_cm|`,
//! the definitions of the scenario crate (`Scenario::froude`). A [`Body`]
//! stores `F_i = μ_i N_i` and has its origin at the centre of mass, so here
//! `μ̄ m g = Σ F_i`, `L = |p_c|` and `Fr = m v_c² / (L Σ F_i)`: no gravity is
//! needed ([`froude_number`], [`speed_for_froude`]).
//!
//! # Derivation
//!
//! Each support's friction `−F_i u_i / |u_i|`, `u_i = v_c n_φ + ω D r_i`,
//! `r_i = p_i − p_c`, is homogeneous of degree 0 in `(v_c, ω)`, so the friction
//! moment about the contact depends on `s = ω / v_c` (rad/m) alone. Write it
//! `M(s) = (Σ F_i) h(s)`, `h` in metres:
//!
//! ```text
//! h(s) = −(1/ΣF) Σ F_i (r_i × u_i) / |u_i|,   u_i = n_φ + s D r_i.
//! ```
//!
//! The kinematic root ψ is `h(ψ) = 0`. The dynamic steady state is
//! `M(s) + m v_c² s (p_c · n_φ) = 0`; dividing by `ΣF`,
//!
//! ```text
//! h(s) + Fr · c · s = 0,      c = L a,  a = p_c · n_φ   (c in m²).
//! ```
//!
//! Hence κ depends on geometry, φ and Fr only (not on m, I, g or v_c
//! separately). Expanding `s = ψ (1 + κ₁ Fr + κ₂ Fr² + …)` and collecting
//! powers of Fr:
//!
//! ```text
//! Fr¹:  h'(ψ) s₁ + c ψ = 0                       ⇒ κ₁ = s₁/ψ = −c / h'(ψ)
//! Fr²:  h'(ψ) s₂ + ½ h''(ψ) s₁² + c s₁ = 0        ⇒ κ₂ = s₂/ψ = κ₁² (1 − ψ h''(ψ) / (2 h'(ψ)))
//! ```
//!
//! The derivatives are closed-form. Per support, with `q = |u|²`,
//! `N = r × u = (r × n) + s |r|²` and `c_i = r · n_φ` (using
//! `|r|² q − N² = c_i²`):
//!
//! ```text
//! m(s)   = −F N / q^{1/2}
//! m'(s)  = −F c_i² / q^{3/2}
//! m''(s) = 3 F c_i² N / q^{5/2}
//! ```
//!
//! `h' ≤ 0` everywhere (each `m' ≤ 0`), so κ₁ has the sign of `−a`: pushing
//! towards the centre of mass (`p_c · n_φ < 0`, the usual case) gives κ < 1;
//! `p_c · n_φ > 0` gives κ > 1 and, at a finite Fr, a fold where the branch
//! connected to ψ merges with an unstable root and disappears.
//!
//! `h'(ψ) = 0` needs every friction-carrying support on the line through the
//! contact perpendicular to the push (all `c_i = 0`); `h` is then piecewise
//! constant, the root is an interval or a jump and no series exists.

use crate::{
    cross,
    dynamic::{SegmentDynamics, STICK_REL},
    kinematic, perp, Body, Push, Vec2,
};

/// The second-order Froude series of κ = ω* / (v_c ψ) for one body and push
/// direction: `κ ≈ 1 + κ₁ Fr + κ₂ Fr²`, with `Fr = v_c² / (μ̄ g L)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KappaSeries {
    /// The kinematic root ψ (rad/m): `ω = v_c ψ` in the quasi-static model.
    pub psi: f64,
    /// First-order coefficient κ₁ = −L (p_c · n_φ) / h'(ψ) (dimensionless).
    pub kappa1: f64,
    /// Second-order coefficient κ₂ = κ₁² (1 − ψ h''(ψ) / (2 h'(ψ))) (dimensionless).
    pub kappa2: f64,
    /// The length L = |p_c − p_cm| (m) in the Froude number the coefficients
    /// refer to.
    pub froude_length: f64,
}

impl KappaSeries {
    /// `1 + κ₁ Fr` (dimensionless) at Froude number `froude`.
    pub fn first_order(&self, froude: f64) -> f64 {
        1.0 + self.kappa1 * froude
    }

    /// `1 + κ₁ Fr + κ₂ Fr²` (dimensionless) at Froude number `froude`.
    pub fn second_order(&self, froude: f64) -> f64 {
        1.0 + froude * (self.kappa1 + self.kappa2 * froude)
    }
}

/// The Froude number's length `L = |p_c − p_cm|` (m); the body's origin is
/// its centre of mass, so this is `|p_c|`.
pub fn froude_length(body: &Body) -> f64 {
    body.contact().norm()
}

/// `Fr = v_c² / (μ̄ g L) = m v_c² / (L Σ μ_i N_i)` (dimensionless) for a pusher
/// speed `speed` (m/s). Infinite when the contact is at the centre of mass.
pub fn froude_number(body: &Body, speed: f64) -> f64 {
    body.mass() * speed * speed / (froude_length(body) * body.total_friction())
}

/// The pusher speed (m/s) at which the Froude number is `froude`, the
/// inverse of [`froude_number`]: `v_c = √(Fr L Σ μ_i N_i / m)`.
pub fn speed_for_froude(body: &Body, froude: f64) -> f64 {
    (froude * froude_length(body) * body.total_friction() / body.mass()).sqrt()
}

/// The reduced friction moment about the contact and its first two
/// derivatives at `s = ω / v_c` (rad/m), push direction `phi` (rad):
/// `[h(s), h'(s), h''(s)]` in m, m², m³, where `(Σ μ_i N_i) h(s)` is the
/// friction moment. Closed form per support (see the module docs); no
/// differencing.
///
/// A support at rest at `s` (`u_i = 0`) contributes 0 to `h` (its friction
/// is set-valued there) and NaN to `h'` and `h''` (`h` jumps there).
pub fn reduced_moment(body: &Body, phi: f64, s: f64) -> [f64; 3] {
    let (n, pc) = (direction(phi), body.contact());
    let mut acc = [0.0; 3];
    for sup in body.supports().filter(|sup| sup.friction > 0.0) {
        let r = sup.position - pc;
        let u = n + perp(&r) * s;
        let q = u.norm_squared();
        let big_n = cross(&r, &u);
        let f = sup.friction;
        if q == 0.0 {
            acc[1] = f64::NAN;
            acc[2] = f64::NAN;
            continue;
        }
        let ci = r.dot(&n);
        let root_q = q.sqrt();
        let q32 = q * root_q;
        acc[0] -= f * big_n / root_q;
        acc[1] -= f * ci * ci / q32;
        acc[2] += 3.0 * f * ci * ci * big_n / (q32 * q);
    }
    let total = body.total_friction();
    acc.map(|x| x / total)
}

/// The series of κ in the Froude number for push direction `phi` (rad). The
/// push speed does not enter: κ's coefficients depend on geometry, friction
/// distribution and φ only.
///
/// None when the series does not exist:
/// * the kinematic root ψ does not exist (every support on the push line) or
///   is zero within rounding (`|ψ| max|r_i| ≤ 1e-12`): then ω* = 0 too and κ
///   is 0/0;
/// * the contact is at the centre of mass (L = 0, Fr undefined; the inertial
///   term vanishes and ω* = v_c ψ exactly);
/// * ψ is a pivot, a support at rest (`|u_i| ≤ STICK_REL (1 + |ψ| |r_i|)`):
///   `h` jumps through zero there and is not differentiable, so ω* sticks to
///   the pivot rate over a finite range of Fr (κ = 1) and then leaves it,
///   which no power series describes;
/// * `h'(ψ) = 0` within rounding (`|h'| ≤ 1e-12 Σ F_i |r_i|² / Σ F_i`), which
///   needs every support on the line through the contact perpendicular to the
///   push: the root is not isolated and κ₁ would be infinite.
pub fn kappa_series(body: &Body, phi: f64) -> Option<KappaSeries> {
    let l = froude_length(body);
    if l == 0.0 {
        return None;
    }
    let psi = kinematic_root(body, phi)?;
    let (n, pc) = (direction(phi), body.contact());
    for sup in body.supports().filter(|sup| sup.friction > 0.0) {
        let r = sup.position - pc;
        let u = n + perp(&r) * psi;
        if u.norm() <= STICK_REL * (1.0 + psi.abs() * r.norm()) {
            return None;
        }
    }
    let [_, h1, h2] = reduced_moment(body, phi, psi);
    let second_moment = body
        .supports()
        .map(|sup| sup.friction * (sup.position - pc).norm_squared())
        .sum::<f64>()
        / body.total_friction();
    if !(h1 < -1e-12 * second_moment) {
        return None;
    }
    let c = l * pc.dot(&n);
    let kappa1 = -c / h1;
    let kappa2 = kappa1 * kappa1 * (1.0 - 0.5 * psi * h2 / h1);
    Some(KappaSeries {
        psi,
        kappa1,
        kappa2,
        froude_length: l,
    })
}

/// κ = ω* / (v_c ψ) (dimensionless) from the exact steady root of the dynamic
/// model at Froude number `froude`, push direction `phi` (rad).
///
/// The root is [`SegmentDynamics::attractor_from`] the kinematic rate `v_c ψ`:
/// the first root met going from `v_c ψ` the way ω̇ drives it. As Fr → 0
/// that root tends to `v_c ψ`, and it follows the branch continuously
/// connected to ψ as Fr grows, up to the branch's first fold (possible only
/// for `p_c · n_φ > 0`); past a fold it is whatever the transient from
/// `v_c ψ` settles on, or None if ω runs away.
///
/// `Some(1.0)` at `froude = 0` (the limit). None for a negative or non-finite
/// Fr, when ψ does not exist or is zero, when L = 0 (see [`kappa_series`]),
/// and when the root reached is not stable.
pub fn kappa_exact(body: &Body, phi: f64, froude: f64) -> Option<f64> {
    if !(froude >= 0.0 && froude.is_finite()) || froude_length(body) == 0.0 {
        return None;
    }
    let psi = kinematic_root(body, phi)?;
    if froude == 0.0 {
        return Some(1.0);
    }
    let speed = speed_for_froude(body, froude);
    let seg = SegmentDynamics::new(
        body,
        &Push {
            duration: 1.0,
            speed,
            phi,
        },
    );
    let w0 = speed * psi;
    let root = seg.attractor_from(w0)?;
    root.is_stable().then(|| root.omega / w0)
}

/// Where the scans of [`first_order_froude_limit`] and
/// [`second_order_froude_limit`] start and stop, and their density.
const SCAN_FROUDE_MIN: f64 = 1e-6;
const SCAN_DECADES: usize = 12;
const SCAN_PER_DECADE: usize = 8;

/// The largest Froude number below which the first-order formula
/// `1 + κ₁ Fr` stays within a relative error `tolerance` of [`kappa_exact`]:
/// `|κ_first − κ_exact| / κ_exact ≤ tolerance` for every Fr up to it.
///
/// Method: Fr is scanned upwards on a logarithmic grid from 1e-6 to 1e6,
/// eight points a decade; at the first grid point that fails (error above
/// `tolerance`, or no stable exact root) the crossing is bisected between it
/// and the last passing point (or 0) to a relative width of 1e-10. An
/// excursion above `tolerance` narrower than the grid spacing could be
/// missed. `f64::INFINITY` when no grid point up to 1e6 fails (e.g.
/// `p_c · n_φ = 0`, where κ ≡ 1).
///
/// None when [`kappa_series`] is None or `tolerance` is not finite and > 0.
/// The exact κ carries a rounding error of about 1e-15 relative, so a
/// `tolerance` below ~1e-12 measures rounding.
pub fn first_order_froude_limit(body: &Body, phi: f64, tolerance: f64) -> Option<f64> {
    let series = kappa_series(body, phi)?;
    froude_limit(body, phi, tolerance, |fr| series.first_order(fr))
}

/// As [`first_order_froude_limit`] for the second-order formula
/// `1 + κ₁ Fr + κ₂ Fr²`.
pub fn second_order_froude_limit(body: &Body, phi: f64, tolerance: f64) -> Option<f64> {
    let series = kappa_series(body, phi)?;
    froude_limit(body, phi, tolerance, |fr| series.second_order(fr))
}

fn froude_limit(body: &Body, phi: f64, tolerance: f64, approx: impl Fn(f64) -> f64) -> Option<f64> {
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return None;
    }
    let within = |fr: f64| match kappa_exact(body, phi, fr) {
        Some(k) if k > 0.0 => ((approx(fr) - k) / k).abs() <= tolerance,
        _ => false,
    };
    let mut lo = 0.0;
    for j in 0..=SCAN_DECADES * SCAN_PER_DECADE {
        let fr = SCAN_FROUDE_MIN * 10f64.powf(j as f64 / SCAN_PER_DECADE as f64);
        if within(fr) {
            lo = fr;
            continue;
        }
        let mut hi = fr;
        for _ in 0..200 {
            if hi - lo <= 1e-10 * hi {
                break;
            }
            let mid = 0.5 * (lo + hi);
            if within(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        return Some(lo);
    }
    Some(f64::INFINITY)
}

/// `n_φ = (cos φ, sin φ)`.
fn direction(phi: f64) -> Vec2 {
    let (s, c) = phi.sin_cos();
    Vec2::new(c, s)
}

/// ψ (rad/m), None when it does not exist or is zero within rounding.
fn kinematic_root(body: &Body, phi: f64) -> Option<f64> {
    let psi = kinematic::psi(body, phi)?;
    let pc = body.contact();
    let r_max = body
        .supports()
        .map(|s| (s.position - pc).norm())
        .fold(0.0f64, f64::max);
    (psi.is_finite() && psi.abs() * r_max > 1e-12).then_some(psi)
}
