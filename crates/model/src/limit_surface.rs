//! The ellipsoidal limit-surface approximation for a sticking point pusher.
//!
//! The set of friction wrenches `(f_x, f_y, m)` the support can transmit is
//! approximated by the ellipsoid `(f/f_max)² + (m/m_max)² = 1` centred on the
//! centre of friction, with `f_max = Σ F_i` and `m_max = Σ F_i |p_i − p_cof|`
//! (pure rotation about the centre of friction). The twist is normal to that
//! surface, `V ∝ (f_x, f_y, m / c²)` with `c = m_max / f_max`. Requiring the
//! contact point to move with the pusher, `v_cof + ω D p = v_c n_φ` with `p` the
//! contact relative to the centre of friction, gives in closed form
//!
//! ```text
//! ω = v_c (p × n_φ) / (c² + |p|²)
//! ```
//!
//! ## References
//! Goyal, Ruina & Papadopoulos (1991), "Planar sliding with dry friction";
//! Lynch, Maekawa & Tanie (1992), "Manipulation and active sensing by pushing
//! using tactile feedback".

use crate::{cross, Body, Push};

/// `c = m_max / f_max` (m), the ellipsoid's moment-to-force ratio.
pub fn characteristic_length(body: &Body) -> f64 {
    let cof = body.center_of_friction();
    let f_max = body.total_friction();
    let m_max: f64 = body
        .supports()
        .map(|s| s.friction * (s.position - cof).norm())
        .sum();
    m_max / f_max
}

/// Angular velocity (rad/s) for the push, under the ellipsoidal approximation.
pub fn omega(body: &Body, push: &Push) -> f64 {
    let p = body.contact() - body.center_of_friction();
    let c = characteristic_length(body);
    push.speed * cross(&p, &push.direction()) / (c * c + p.norm_squared())
}
