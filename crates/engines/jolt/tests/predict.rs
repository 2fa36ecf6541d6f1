//! Jolt's law in closed form (`pushval_jolt::predict`), checked against the
//! Coulomb model and against geometry (no Jolt needed).

mod common;

use common::*;
use pushval_jolt::predict::{
    at_rest, averaging_bias, friction_slip_angle, linear_moment, rest_moments, steady_omega,
    tail_omega, AtRest, Direction, Law, Manifold,
};
use pushval_model::{cross, SegmentDynamics, Vec2};

/// One-point discs along the slip, with the problem's loads, are Coulomb's
/// law support by support: the same moment and the same steady ω.
#[test]
fn feet_along_the_slip_are_coulomb() {
    let b = plate();
    let law = Law::jolt_feet(&b, None, Direction::Slip);
    for v in [0.2, 0.5, 1.0] {
        let p = push(v, PHI, 1.0);
        let seg = SegmentDynamics::new(&b, &p);
        for w in [-0.9, -0.3, 0.0, 0.4] {
            let g = linear_moment(&law, &b, &p, w, 0.3);
            assert!(
                (g - seg.moment(w)).abs() < 1e-12,
                "{g} vs {}",
                seg.moment(w)
            );
        }
        let star = seg.attractor(&seg.steady_states(), 0.0).unwrap().omega;
        assert!((steady_omega(&law, &b, &p) - star).abs() < 1e-9);
        let tail = tail_omega(&law, &b, &p, 4.0, (0.0, 0.0), 1e-4);
        assert!((tail - star).abs() < 1e-3 * star.abs(), "{tail} vs {star}");
    }
}

/// The effective-mass direction: at a point r from the centre of mass the
/// world-x row has `1/m_x = 1/m + r_y²/I`, the world-y row `1/m_y = 1/m +
/// r_x²/I`; for a slip along (1, 1) the force points along −(m_x, m_y),
/// `atan(m_y/m_x) − π/4` from the slip's opposite.
#[test]
fn effective_mass_turns_the_force_off_the_slip() {
    let b = plate();
    let law = Law {
        manifolds: vec![Manifold {
            point: Vec2::new(0.0, 0.2),
            cap: 1.0,
            twist_cap: 0.0,
        }],
        direction: Direction::EffectiveMass,
        mass: b.mass(),
        inertia: b.inertia_cm(),
    };
    let i = b.inertia_cm();
    let (mx, my): (f64, f64) = (1.0 / (1.0 + 0.04 / i), 1.0);
    let u = Vec2::new(1.0, 1.0);
    let f = law.force(0, u, 0.0);
    let expected = my.atan2(mx) - std::f64::consts::FRAC_PI_4;
    assert!((friction_slip_angle(f, u) - expected).abs() < 1e-12);
    assert!((f.norm() - 1.0).abs() < 1e-12, "the disc's radius");
    // Turned by 45°, the point lies on a world diagonal: equal rows, the
    // force is opposite the slip; turned by 90° the rows swap and so do
    // the slip's world components: the same angle again.
    let g = law.force(0, u, std::f64::consts::FRAC_PI_4);
    assert!(friction_slip_angle(g, u).abs() < 1e-12);
    let g = law.force(0, u, std::f64::consts::FRAC_PI_2);
    assert!((friction_slip_angle(g, u) - expected).abs() < 1e-12);
    // At the centre of mass the two rows have the mass: along the slip.
    let at_cm = Law::jolt_box(&b, None, Direction::EffectiveMass);
    let h = at_cm.force(0, Vec2::new(0.3, -0.7), 1.1);
    assert!(friction_slip_angle(h, Vec2::new(0.3, -0.7)).abs() < 1e-12);
    assert!(!at_cm.depends_on_yaw());
    assert!(Law::jolt_feet(&b, None, Direction::EffectiveMass).depends_on_yaw());
}

/// The box: one disc of radius μW at the centroid and a twist row of
/// μW·h√2 (four corners at h√2 from it, equal loads). With a corner push
/// the linear friction's moment about the pusher at ω = 0 is
/// `μW (p_c × n_φ)`, at most `μW |p_c| = T`: the box never turns.
#[test]
fn box_locks_for_every_corner_push() {
    let b = plate();
    let law = Law::jolt_box(&b, None, Direction::EffectiveMass);
    let w = MU * G;
    assert!((law.manifolds[0].cap - w).abs() < 1e-12);
    assert!((law.twist_cap() - w * HALF * 2f64.sqrt()).abs() < 1e-12);
    for k in 0..=20 {
        let phi = 0.01 + k as f64 * (std::f64::consts::FRAC_PI_2 - 0.02) / 20.0;
        let p = push(0.5, phi, 1.0);
        let (m0, t) = rest_moments(&law, &b, &p, 0.0);
        assert!((m0 - w * cross(&b.contact(), &p.direction())).abs() < 1e-12);
        assert!(m0.abs() <= t);
        assert_eq!(at_rest(&law, &b, &p, 0.0), AtRest::Locked);
        assert_eq!(steady_omega(&law, &b, &p), 0.0);
        assert_eq!(tail_omega(&law, &b, &p, 1.0, (0.0, 0.0), 1e-4), 0.0);
    }
    // Half the twist clamp and the plate turns where M₀ exceeds it: a push
    // across p_c has |M₀| = μW|p_c| = T.
    let weak = Law {
        manifolds: vec![Manifold {
            twist_cap: 0.5 * law.twist_cap(),
            ..law.manifolds[0]
        }],
        ..law.clone()
    };
    let across = push(0.5, 3.0 * std::f64::consts::FRAC_PI_4, 1.0);
    assert_eq!(at_rest(&weak, &b, &across, 0.0), AtRest::Turns);
    assert!(steady_omega(&weak, &b, &across) != 0.0);
}

/// The unweighted mean against the load-weighted centre: loads (2, 1, 1, 1)
/// on the square's corners put the weighted centre at p₀/5, the mean at 0.
#[test]
fn averaging_bias_is_mean_minus_weighted_centre() {
    let h = HALF;
    let pts = [
        Vec2::new(-h, -h),
        Vec2::new(h, -h),
        Vec2::new(h, h),
        Vec2::new(-h, h),
    ];
    let bias = averaging_bias(&pts, &[2.0, 1.0, 1.0, 1.0]);
    assert!((bias - (-pts[0] / 5.0)).norm() < 1e-15);
    assert!(averaging_bias(&pts, &[1.0; 4]).norm() < 1e-15);
    // The manifold puts its disc at the plain mean whatever the loads.
    let m = Manifold::of(&pts, &[2.0, 1.0, 1.0, 1.0]);
    assert!(m.point.norm() < 1e-15);
    assert!((m.cap - 5.0).abs() < 1e-15);
    assert!((m.twist_cap - 5.0 * h * 2f64.sqrt()).abs() < 1e-12);
}
