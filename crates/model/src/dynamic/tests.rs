//! Unit tests of [`SegmentDynamics`]: the friction sum, its reuse, the
//! roots, the transient and the Taylor series.

use super::*;
use crate::Support;

/// `−Σ F_i (r_i × u_i) / |u_i|` one support at a time, straight from the
/// definition (no pairing, no clamp; a support at rest contributes 0).
fn moment_by_definition(body: &Body, push: &Push, omega: f64) -> f64 {
    let pc = body.contact();
    body.supports()
        .map(|s| {
            let r = s.position - pc;
            let u = push.velocity() + perp(&r) * omega;
            if u.norm() == 0.0 {
                0.0
            } else {
                -s.friction * cross(&r, &u) / u.norm()
            }
        })
        .sum()
}

fn body(points: &[(f64, f64)]) -> Body {
    let sup: Vec<Support> = points
        .iter()
        .enumerate()
        .map(|(i, &(x, y))| Support {
            position: Vec2::new(x, y),
            friction: 0.3 + 0.1 * i as f64,
        })
        .collect();
    Body::new(1.3, 0.02, Vec2::new(-0.1, -0.05), &sup).unwrap()
}

/// The paired sum (blocks of four plus a remainder) equals the
/// per-support definition for every support count that exercises a
/// different block/remainder split.
#[test]
fn paired_friction_sum_matches_the_definition() {
    let pts: Vec<(f64, f64)> = (0..11)
        .map(|i| {
            let t = 2.4 * i as f64;
            (0.1 * t.cos() + 0.01 * i as f64, 0.08 * t.sin())
        })
        .collect();
    let push = Push {
        duration: 1.0,
        speed: 0.7,
        phi: 0.4,
    };
    for n in 1..=pts.len() {
        let b = body(&pts[..n]);
        let seg = SegmentDynamics::new(&b, &push);
        for omega in [-30.0, -2.0, -0.3, 0.0, 0.05, 1.7, 25.0] {
            let want = moment_by_definition(&b, &push, omega);
            let got = seg.friction_moment_at(push.speed, omega);
            let scale = seg.max_moment();
            assert!(
                (got - want).abs() <= 1e-14 * scale,
                "n {n}, ω {omega}: {got} against {want}"
            );
        }
    }
}

/// A segment re-made in place from another segment's arrays (another
/// body, more supports, a zero-friction support, the flipped inertial
/// term before) is the segment made afresh: the same ω̇, roots and
/// pusher force.
#[test]
fn a_reset_segment_is_a_fresh_one() {
    let mut b = body(&[(0.1, 0.08), (0.12, -0.07), (-0.05, 0.02), (0.0, -0.1)]);
    let small = body(&[(0.1, 0.1), (-0.1, 0.1)]);
    let push = Push {
        duration: 1.0,
        speed: 0.7,
        phi: 0.4,
    };
    let other = Push {
        duration: 1.0,
        speed: 0.2,
        phi: -1.1,
    };
    let mut sup: Vec<Support> = b.supports().collect();
    sup[1].friction = 0.0;
    b = Body::new(1.3, 0.02, b.contact(), &sup).unwrap();
    for (before, term) in [(&small, InertialTerm::Flipped), (&b, InertialTerm::Derived)] {
        let mut seg = SegmentDynamics::with_inertial_term(before, &other, term);
        seg.reset(&b, &push, InertialTerm::Derived);
        let fresh = SegmentDynamics::new(&b, &push);
        for w in [-3.0, -0.2, 0.0, 0.5, 4.0] {
            assert_eq!(seg.omega_dot(w), fresh.omega_dot(w), "ω {w}");
            assert_eq!(seg.pusher_force(w), fresh.pusher_force(w), "ω {w}");
        }
        assert_eq!(seg.steady_states(), fresh.steady_states());
        assert_eq!(seg.max_moment(), fresh.max_moment());
    }
}

/// A segment given another push on the same body (only the push's part
/// redone, as a run does from one segment to the next) is the segment made
/// afresh for that push, under either reading of the inertial term.
#[test]
fn a_repushed_segment_is_a_fresh_one() {
    let b = body(&[(0.1, 0.08), (0.12, -0.07), (-0.05, 0.02), (0.0, -0.1)]);
    let first = Push {
        duration: 1.0,
        speed: 0.2,
        phi: -1.1,
    };
    let push = Push {
        duration: 0.5,
        speed: 0.7,
        phi: 0.4,
    };
    for term in [InertialTerm::Derived, InertialTerm::Flipped] {
        let mut seg = SegmentDynamics::with_inertial_term(&b, &first, term);
        seg.repush(&push, push.direction(), term);
        let fresh = SegmentDynamics::with_inertial_term(&b, &push, term);
        assert_eq!(seg.inertial_slope(), fresh.inertial_slope());
        assert_eq!(seg.speed(), fresh.speed());
        for w in [-3.0, -0.2, 0.0, 0.5, 4.0] {
            assert_eq!(seg.omega_dot(w), fresh.omega_dot(w), "ω {w}");
            assert_eq!(seg.moment_slope(w), fresh.moment_slope(w), "ω {w}");
            assert_eq!(seg.pusher_force(w), fresh.pusher_force(w), "ω {w}");
        }
        assert_eq!(seg.steady_states(), fresh.steady_states());
    }
}

/// A push through the centre of a support set that is mirror-symmetric
/// about the push line has its steady state at ω = 0 (the mirror image
/// of a turning motion turns the other way), from either side and
/// whether the search is the full scan or the directed one. There `G`
/// is rounding noise, so the search stops on `|G|` at its rounding floor
/// (waiting for the bracket to shrink relative to |ω| spent the whole
/// iteration budget); this checks that stop lands at zero.
#[test]
fn a_symmetric_push_settles_at_zero_rate() {
    let sup: Vec<Support> = [(0.1, 0.1), (0.1, -0.1), (-0.1, 0.1), (-0.1, -0.1)]
        .iter()
        .map(|&(x, y)| Support {
            position: Vec2::new(x, y),
            friction: 0.5,
        })
        .collect();
    // Contact on the x axis, pushed along +x: the mirror is y → −y.
    let b = Body::new(1.0, 0.01, Vec2::new(-0.1, 0.0), &sup).unwrap();
    let push = Push {
        duration: 1.0,
        speed: 0.3,
        phi: 0.0,
    };
    let seg = SegmentDynamics::new(&b, &push);
    let scale = push.speed / 0.1;
    let roots = seg.steady_states();
    assert_eq!(roots.len(), 1, "{roots:?}");
    assert!(roots[0].omega.abs() <= 1e-14 * scale, "{roots:?}");
    for w in [-2.0, -0.3, 0.3, 2.0] {
        let r = seg.attractor_from(w).expect("a stable root");
        assert!(r.omega.abs() <= 1e-14 * scale, "from {w}: {r:?}");
        assert_eq!(r.kind, RootKind::Stable);
    }
}

/// Near a stable smooth root the flow is linear: a small offset decays
/// as e^(−t/τ) with the root's own relaxation time τ = −I_P/G'(ω*).
#[test]
fn advance_decays_with_the_roots_relaxation_time() {
    let b = body(&[(0.1, 0.08), (0.12, -0.07), (-0.05, 0.02)]);
    let push = Push {
        duration: 1.0,
        speed: 0.7,
        phi: 0.4,
    };
    let seg = SegmentDynamics::new(&b, &push);
    let root = seg.attractor_from(0.0).expect("a steady state");
    let tau = root.tau.expect("a smooth stable root");
    let eps = 1e-6 * (1.0 + root.omega.abs());
    for sign in [1.0, -1.0] {
        for k in [0.5, 1.0, 3.0] {
            let w = seg.advance(root.omega + sign * eps, k * tau).unwrap();
            let ratio = (w - root.omega) / (sign * eps);
            assert!(
                (ratio - (-k).exp()).abs() < 1e-4,
                "t = {k} τ: ratio {ratio}, e^-t/τ {}",
                (-k).exp()
            );
        }
    }
}

/// The transient composes (a then b is a + b), moves monotonically
/// towards the attractor without passing it, and reaches it.
#[test]
fn advance_composes_and_settles_monotonically() {
    let b = body(&[(0.1, 0.08), (0.12, -0.07), (-0.05, 0.02), (0.0, -0.1)]);
    let push = Push {
        duration: 1.0,
        speed: 0.3,
        phi: -0.7,
    };
    let seg = SegmentDynamics::new(&b, &push);
    let root = seg.attractor_from(0.0).expect("a steady state");
    let tau = root.tau.expect("a smooth stable root");
    let scale = 1.0 + root.omega.abs();
    let (a, c) = (0.37 * tau, 1.9 * tau);
    let two = seg.advance(seg.advance(0.0, a).unwrap(), c).unwrap();
    let one = seg.advance(0.0, a + c).unwrap();
    assert!((two - one).abs() < 1e-8 * scale, "{two} vs {one}");
    let mut prev = 0.0;
    for j in 1..=40 {
        let w = seg.advance(0.0, 0.25 * tau * j as f64).unwrap();
        assert!(
            (w - prev) * root.omega.signum() >= 0.0,
            "step {j}: {prev} → {w}"
        );
        assert!(
            (w - 0.0) * (w - root.omega) <= 0.0,
            "passed ω* = {}: {w}",
            root.omega
        );
        prev = w;
    }
    let late = seg.advance(0.0, 60.0 * tau).unwrap();
    assert!(
        (late - root.omega).abs() < 1e-9 * scale,
        "{late} vs {}",
        root.omega
    );
}

/// A pivot is reached in finite time (G does not vanish there) and held:
/// ω equals the pivot's rate exactly, without chattering about it.
#[test]
fn advance_reaches_a_pivot_and_stays() {
    // A heavily loaded support straight beside the contact point across
    // the push: the plate turns about it at ω = v / 0.1.
    let sup = [
        Support {
            position: Vec2::new(-0.1, 0.1),
            friction: 5.0,
        },
        Support {
            position: Vec2::new(0.1, -0.1),
            friction: 0.05,
        },
    ];
    let b = Body::new(1.0, 0.01, Vec2::new(-0.1, 0.0), &sup).unwrap();
    let push = Push {
        duration: 1.0,
        speed: 0.2,
        phi: 0.0,
    };
    let seg = SegmentDynamics::new(&b, &push);
    let root = seg.attractor_from(0.0).expect("a steady state");
    assert!(
        matches!(root.kind, RootKind::Pivot { stable: true, .. }),
        "{root:?}"
    );
    let pivot = root.omega;
    assert!((pivot.abs() - 0.2 / 0.1).abs() < 1e-9, "{pivot}");
    let early = seg.advance(0.0, 1e-4).unwrap();
    assert!(early.abs() > 0.0 && early.abs() < pivot.abs(), "{early}");
    assert_eq!(seg.advance(0.0, 10.0), Some(pivot));
}

/// With its one support under the contact point friction has no moment
/// about it: ω̇ = k ω / I_P, which runs away as e^(k t / I_P) when the
/// contact lies ahead of the centre of mass along the push (a pull,
/// k > 0).
#[test]
fn advance_follows_a_runaway_exactly() {
    let sup = [Support {
        position: Vec2::new(-0.1, 0.0),
        friction: 0.5,
    }];
    let b = Body::new(1.0, 0.01, Vec2::new(-0.1, 0.0), &sup).unwrap();
    let push = Push {
        duration: 1.0,
        speed: 0.4,
        phi: std::f64::consts::PI - 0.3,
    };
    let seg = SegmentDynamics::new(&b, &push);
    let rate = seg.inertial_slope() / seg.inertia_contact();
    assert!(rate > 0.0, "{rate}");
    assert!(seg.attractor_from(0.2).is_none());
    for t in [0.01, 0.3, 2.0] {
        let want = 0.2 * (rate * t).exp();
        let got = seg.advance(0.2, t).unwrap();
        assert!((got - want).abs() < 1e-8 * want, "t {t}: {got} vs {want}");
    }
}

/// A support whose sliding velocity is exactly zero contributes nothing,
/// whichever pair slot it sits in, and the sum stays finite.
#[test]
fn a_support_at_rest_contributes_nothing() {
    // Contact at (−0.1, −0.05); push along +x at 1 m/s (φ = 0). A support
    // at r = (0, 0.5) relative to the contact has u = (1 − 0.5 ω, 0),
    // which vanishes at ω = 2 rad/s.
    let rest = (-0.1, 0.45);
    let others = [
        (0.1, 0.1),
        (0.05, -0.1),
        (-0.05, 0.2),
        (0.2, 0.0),
        (0.0, 0.0),
    ];
    let push = Push {
        duration: 1.0,
        speed: 1.0,
        phi: 0.0,
    };
    for slot in 0..5 {
        let mut pts = others.to_vec();
        pts.insert(slot, rest);
        let b = body(&pts);
        let seg = SegmentDynamics::new(&b, &push);
        let got = seg.friction_moment_at(1.0, 2.0);
        let want = moment_by_definition(&b, &push, 2.0);
        assert!(got.is_finite(), "slot {slot}: {got}");
        assert!(
            (got - want).abs() <= 1e-14 * seg.max_moment(),
            "slot {slot}: {got} against {want}"
        );
    }
}

/// The Taylor coefficients of ω̇ against ω̇ itself: the constant term,
/// the slope against the analytic `G'` of [`SegmentDynamics::moment_slope`],
/// the curvature against a central difference, and the whole polynomial
/// against ω̇ at offsets up to a fifth of the distance to the nearest
/// complex singularity (`v |n·r| / r²`, where a support's sliding speed
/// would vanish), where the dropped terms are below 1e-14. One support
/// sits under the contact (no lever arm).
#[test]
fn taylor_coefficients_reproduce_omega_dot() {
    let b = body(&[
        (0.12, 0.03),
        (-0.1, -0.05),
        (0.02, 0.11),
        (-0.09, 0.08),
        (0.05, -0.1),
    ]);
    let push = Push {
        duration: 1.0,
        speed: 0.7,
        phi: 0.4,
    };
    let seg = SegmentDynamics::new(&b, &push);
    let n = push.direction();
    let radius = b
        .supports()
        .map(|s| s.position - b.contact())
        .filter(|r| r.norm() > 0.0)
        .map(|r| push.speed * n.dot(&r).abs() / r.norm_squared())
        .fold(f64::INFINITY, f64::min);
    let scale = seg.max_moment() / seg.inertia_contact();
    let mut c = [0.0; 21];
    for omega in [-3.0, -0.4, 0.0, 0.9, 4.0] {
        seg.omega_dot_taylor(omega, &mut c);
        assert!(
            (c[0] - seg.omega_dot(omega)).abs() <= 1e-14 * scale,
            "ω {omega}: g"
        );
        let slope = seg.moment_slope(omega) / seg.inertia_contact();
        assert!(
            (c[1] - slope).abs() <= 1e-12 * slope.abs().max(scale),
            "ω {omega}: g'"
        );
        let h = 1e-3 * radius;
        let g = |w: f64| seg.omega_dot(w);
        let g2 = (g(omega + h) - 2.0 * g(omega) + g(omega - h)) / (h * h);
        assert!(
            (g2 - 2.0 * c[2]).abs() <= 1e-5 * g2.abs().max(scale / radius),
            "ω {omega}: g''"
        );
        for d in [-0.2, -0.05, 0.05, 0.2].map(|f| f * radius) {
            let series: f64 = c.iter().rev().fold(0.0, |acc, cj| acc * d + cj);
            assert!(
                (series - g(omega + d)).abs() <= 1e-12 * scale,
                "ω {omega}, d {d}: {series} against {}",
                g(omega + d)
            );
        }
    }
}

/// With `k < 0` (`G` strictly decreasing: one root, the attractor of every
/// start) the root found does not depend on where ω starts, to the bit:
/// what lets a run keep it per push (`PushCache`). It is a root: `G`
/// changes sign within a few ulps of it.
#[test]
fn monotone_root_is_the_same_from_every_start() {
    let b = body(&[(0.1, 0.08), (0.12, -0.07), (-0.05, 0.02), (0.0, 0.1)]);
    for phi in [0.2, 0.4, 0.9] {
        let push = Push {
            duration: 1.0,
            speed: 0.7,
            phi,
        };
        let seg = SegmentDynamics::new(&b, &push);
        assert!(
            seg.inertial_slope() < 0.0,
            "phi {phi}: k = {}",
            seg.inertial_slope()
        );
        let root = seg.attractor_from(0.0).expect("a steady state");
        for w in [-30.0, -2.0, -0.3, 1e-9, 0.3, 2.0, 30.0] {
            let r = seg.attractor_from(w).expect("a steady state");
            assert_eq!(
                r.omega.to_bits(),
                root.omega.to_bits(),
                "phi {phi} from {w}"
            );
            assert_eq!(r.kind, root.kind);
        }
        let ulps = 8.0 * f64::EPSILON * (1.0 + root.omega.abs());
        assert!(seg.moment(root.omega - ulps) >= 0.0 && seg.moment(root.omega + ulps) <= 0.0);
    }
}
