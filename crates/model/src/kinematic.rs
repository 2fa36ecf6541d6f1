//! Kurisu & Yoshikawa's quasi-static model: `ω = v_c ψ(φ)`, where ψ makes the
//! friction moment about the contact point vanish for a unit pusher speed.

use crate::{dynamic::SegmentDynamics, Body, Push};

/// ψ(φ) (rad/m): the root of the friction moment alone at unit pusher speed.
/// The friction moment is non-increasing in ψ, so the root is unique where it
/// exists; None when it never changes sign (all supports on the push line).
pub fn psi(body: &Body, phi: f64) -> Option<f64> {
    let seg = SegmentDynamics::new(
        body,
        &Push {
            duration: 1.0,
            speed: 1.0,
            phi,
        },
    );
    psi_of(&seg)
}

/// ψ for a prepared segment (its speed is ignored: ψ uses unit speed).
pub fn psi_of(seg: &SegmentDynamics) -> Option<f64> {
    let g = |w: f64| seg.friction_moment_at(1.0, w);
    let mut w = 1.0;
    let mut found = false;
    for _ in 0..1100 {
        if g(w) < 0.0 && g(-w) > 0.0 {
            found = true;
            break;
        }
        if g(w) == 0.0 {
            return Some(w);
        }
        if g(-w) == 0.0 {
            return Some(-w);
        }
        w *= 2.0;
        if !w.is_finite() {
            break;
        }
    }
    if !found {
        return None;
    }
    let (mut lo, mut hi) = (-w, w);
    // Bisection to the last bit: g is monotone, possibly with a jump at a pivot.
    for _ in 0..2200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let gm = g(mid);
        if gm == 0.0 {
            return Some(mid);
        }
        if gm > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Kinematic angular velocity `v_c ψ(φ)` (rad/s).
pub fn omega(body: &Body, push: &Push) -> Option<f64> {
    if push.speed == 0.0 {
        return Some(0.0);
    }
    psi(body, push.phi).map(|p| p * push.speed)
}
