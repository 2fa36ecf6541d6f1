//! The closed forms of `pushval_physx::predict`, checked against the model
//! and against themselves (no PhysX needed).

mod common;

use common::*;
use pushval_model::SegmentDynamics;
use pushval_physx::predict::{
    alternating_mask, holds_at_rest, lock_moments, locks, moment, patch_anchors, rest_moments,
    steady_from_rest, steady_omega, Law,
};

#[test]
fn coulomb_law_is_the_model() {
    let b = plate();
    for v in [0.2, 0.5, 1.0] {
        let p = push(v, PHI, 1.0);
        let seg = SegmentDynamics::new(&b, &p);
        for w in [-0.9, -0.3, 0.0, 0.4] {
            let m = moment(&b, &p, w, Law::Coulomb);
            assert!(
                (m - seg.moment(w)).abs() < 1e-12,
                "{m} vs {}",
                seg.moment(w)
            );
        }
        let s = steady_omega(&b, &p, Law::Coulomb, 0.0);
        let roots = seg.steady_states();
        let star = seg.attractor(&roots, 0.0).unwrap().omega;
        assert!((s.omega - star).abs() < 1e-9, "{} vs {star}", s.omega);
        assert!(!s.sticks);
    }
}

#[test]
fn lock_is_where_g_jumps_across_zero() {
    // The closed form M₀ ∓ H is G just either side of 0.
    for (half, phi, v) in [(HALF, PHI, 0.5), (0.05, 0.15, 0.3), (0.08, 0.6, 1.0)] {
        let b = plate_with(half, [1.4, 1.05, 1.4, 1.05]);
        let p = push(v, phi, 1.0);
        for law in [Law::Box, Law::Alternating(0b0101), Law::Anchors(0, 2)] {
            let (m0, h) = lock_moments(&b, &p, law);
            let (gp, gm) = (moment(&b, &p, 1e-9, law), moment(&b, &p, -1e-9, law));
            assert!((gp - (m0 - h)).abs() < 1e-6, "{law:?}: {gp} vs {}", m0 - h);
            assert!((gm - (m0 + h)).abs() < 1e-6, "{law:?}: {gm} vs {}", m0 + h);
            assert_eq!(locks(&b, &p, law), gp <= 0.0 && gm >= 0.0, "{law:?}");
        }
    }
}

#[test]
fn box_and_anchors_lock_the_paper_plate_line_turns() {
    // PhysX's PGS loads on the paper plate (2.80 / 2.10 N on the diagonals).
    let b = with_friction(&plate(), &[1.401, 1.051, 1.401, 1.051]);
    for v in [0.2, 0.5, 1.0] {
        let p = push(v, PHI, 1.0);
        for law in [Law::Box, Law::Anchors(0, 2), Law::Anchors(1, 3)] {
            assert!(locks(&b, &p, law), "{law:?} at {v}");
            let s = steady_omega(&b, &p, law, 0.0);
            assert_eq!(s.omega, 0.0);
            assert!(s.sticks);
        }
        assert!(!locks(&b, &p, Law::Line));
        let line = steady_omega(&b, &p, Law::Line, 0.0);
        assert!(line.omega < 0.0 && !line.sticks);
        // Welded one-directional with t0 on feet 0 and 2 (what PhysX does):
        // G(0±) < 0, the continuous law drifts away from 0.
        let (m0, h) = lock_moments(&b, &p, Law::Alternating(0b0101));
        assert!(m0 < 0.0 && m0 + h < 0.0 && h > 0.0, "{m0} {h}");
        let alt = steady_omega(&b, &p, Law::Alternating(0b0101), 0.0);
        assert!(alt.omega < -0.1 && !alt.sticks, "{alt:?}");
    }
}

#[test]
fn small_feet_do_not_lock() {
    let b = plate_with(0.05, [1.85, 0.6, 1.85, 0.6]);
    let p = push(0.3, 0.15, 1.0);
    for law in [
        Law::Box,
        Law::Anchors(0, 2),
        Law::Alternating(0b0101),
        Law::Line,
    ] {
        assert!(!locks(&b, &p, law), "{law:?}");
        let s = steady_omega(&b, &p, law, 0.0);
        assert!(s.omega > 0.3 && !s.sticks, "{law:?}: {s:?}");
        assert!(moment(&b, &p, s.omega, law).abs() < 1e-9);
    }
}

#[test]
fn patch_anchors_are_a_diagonal_of_a_rectangle() {
    let c = corners(HALF);
    for (order, want) in [
        ([0, 1, 2, 3], (0, 2)),
        ([2, 1, 0, 3], (2, 0)),
        ([0, 2, 1, 3], (0, 2)),
        ([1, 0, 2, 3], (2, 0)),
        ([3, 2, 1, 0], (3, 1)),
    ] {
        assert_eq!(patch_anchors(&c, &order), want, "{order:?}");
    }
}

#[test]
fn alternating_mask_takes_every_other_point() {
    assert_eq!(alternating_mask(&[0, 1, 2, 3]), 0b0101);
    assert_eq!(alternating_mask(&[2, 1, 0, 3]), 0b0101);
    assert_eq!(alternating_mask(&[1, 0, 2, 3]), 0b0110);
    assert_eq!(alternating_mask(&[0, 1, 2]), 0b101);
}

#[test]
fn static_balance_contains_the_lock() {
    // |M₀| ≤ H implies |M₀| ≤ S (S ≥ H term by term), and with every `t1`
    // point ahead of the centre of mass (p·n ≥ 0) the two are one condition.
    for (half, phi, v) in [
        (HALF, PHI, 0.5),
        (0.05, 0.15, 0.3),
        (0.08, 0.6, 1.0),
        (HALF, 0.2, 0.4),
        (HALF, 1.3, 0.4),
    ] {
        let b = plate_with(half, [1.4, 1.05, 1.4, 1.05]);
        let p = push(v, phi, 1.0);
        for law in [Law::Box, Law::Alternating(0b0101), Law::Anchors(0, 2)] {
            let (m0, h) = lock_moments(&b, &p, law);
            let (m0s, s) = rest_moments(&b, &p, law);
            assert_eq!(m0, m0s);
            assert!(s >= h.abs() - 1e-15, "{law:?}: {s} < {h}");
            if locks(&b, &p, law) {
                assert!(holds_at_rest(&b, &p, law), "{law:?}");
            }
        }
        assert!(!holds_at_rest(&b, &p, Law::Line), "no t1 rows, S = 0");
        assert!(!holds_at_rest(&b, &p, Law::Coulomb));
    }
}

#[test]
fn static_balance_holds_welded_one_directional_on_the_paper_plate() {
    // The paper plate with PhysX's PGS loads: foot 1 (t1 row) lies behind the
    // centre of mass along n_φ, so G(0±) < 0 (no Filippov lock) while the
    // sticking t1 rows of feet 1 and 3 can hold |M₀| (the static balance).
    let b = with_friction(&plate(), &[1.401, 1.051, 1.401, 1.051]);
    let law = Law::Alternating(0b0101);
    for v in [0.2, 0.5, 1.0] {
        let p = push(v, PHI, 1.0);
        let n = p.direction();
        assert!(b.support(1).position.dot(&n) < 0.0);
        assert!(!locks(&b, &p, law));
        assert!(holds_at_rest(&b, &p, law));
        // By hand: M₀ = −c₂ (p₂ − p_c) × n, S = c₁ |(p₁ − p_c)·n| + c₃ |(p₃ − p_c)·n|.
        let pc = b.contact();
        let d = |i: usize| b.support(i).position - pc;
        let m0 = -1.401 * (d(2).x * n.y - d(2).y * n.x);
        let s = 1.051 * d(1).dot(&n).abs() + 1.051 * d(3).dot(&n).abs();
        let (m0c, sc) = rest_moments(&b, &p, law);
        assert!((m0 - m0c).abs() < 1e-12 && (s - sc).abs() < 1e-12);
        let r = steady_from_rest(&b, &p, law);
        assert_eq!(r.omega, 0.0);
        assert!(r.sticks);
        // Where the static balance fails, the prediction is the law's root.
        assert_eq!(
            steady_from_rest(&b, &p, Law::Line),
            steady_omega(&b, &p, Law::Line, 0.0)
        );
    }
}
