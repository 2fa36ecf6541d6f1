//! Closed-form motion at constant ω: once a segment has settled (or for the
//! kinematic models, always), the contact point follows a circular arc.

use crate::{rotate, Vec2};

/// `(sin x / x, (1 − cos x) / x)`, accurate near `x = 0`.
#[inline]
pub fn sinc_versc(x: f64) -> (f64, f64) {
    if x.abs() < 1e-4 {
        let x2 = x * x;
        (1.0 - x2 / 6.0 + x2 * x2 / 120.0, x / 2.0 - x * x2 / 24.0)
    } else {
        let h = (0.5 * x).sin();
        (x.sin() / x, 2.0 * h * h / x)
    }
}

/// Advances the contact point's world position `c` and the angle `theta` by `t`
/// seconds of motion at constant angular velocity `omega` (rad/s), the contact
/// point moving with `velocity` (m/s) in the object frame. Returns `(c, θ)`.
///
/// The contact point's world velocity is `R(θ) v`; with θ = θ₀ + ω s, its
/// integral is `R(θ₀) [[S, −V], [V, S]] v t` with `S = sin(ωt)/(ωt)` and
/// `V = (1 − cos ωt)/(ωt)`.
#[inline]
pub fn arc_advance(c: Vec2, theta: f64, omega: f64, velocity: &Vec2, t: f64) -> (Vec2, f64) {
    let (s, v) = sinc_versc(omega * t);
    let local = Vec2::new(
        s * velocity.x - v * velocity.y,
        v * velocity.x + s * velocity.y,
    ) * t;
    (c + rotate(theta, &local), theta + omega * t)
}
