//! The PhysX findings (crates/engines/physx/README.md), asserted: expected values
//! come from the Coulomb model and the closed forms of
//! `pushval_physx::predict`, evaluated with the friction magnitudes PhysX
//! gives the feet at rest (`μ̄ N_i`), never from engine output alone.
#![cfg(feature = "physx")]

mod common;

use common::*;
use pushval_model::Body;
use pushval_physx::predict::{
    at_rest, holds_at_rest, lock_moments, locks, steady_omega, AtRest, Law,
};
use pushval_physx::{
    DetailedEngine, FootContacts, FrictionType, PhysxRun, PhysxSettings, PhysxSimulator,
};

fn run(body: &Body, p: pushval_model::Push, s: PhysxSettings) -> PhysxRun {
    PhysxSimulator::new(s).run(&problem(body, p)).unwrap()
}

fn settings(friction: FrictionType, contacts: FootContacts, dt: f64) -> PhysxSettings {
    PhysxSettings {
        friction,
        contacts,
        dt,
        ..Default::default()
    }
}

/// The body the closed forms see: PhysX's friction magnitudes at rest.
fn engine_body(body: &Body, r: &PhysxRun) -> Body {
    with_friction(body, &r.engine_friction)
}

fn coulomb(body: &Body, p: &pushval_model::Push) -> f64 {
    steady_omega(body, p, Law::Coulomb, 0.0).omega
}

/// The registered models (welded feet, PhysX's default) hold the paper plate
/// at ω = 0 while the Coulomb model turns it at ω* = −0.217, −0.474,
/// −0.649 rad/s. Patch and two-directional: the closed-form lock (the `t1`
/// rows' jump in G straddles 0). One-directional: G(0±) < 0, so ω = 0 is no
/// Filippov lock, but the sticking `t1` rows of feet 1 and 3 balance M₀
/// (`holds_at_rest`): ω = 0 is semi-stable, and PhysX holds it.
#[test]
fn registered_models_hold_the_paper_plate_still() {
    let b = plate();
    for (v, star_paper) in [(0.2, -0.2174), (0.5, -0.4738), (1.0, -0.6495)] {
        let p = push(v, PHI, 4.0);
        let star = coulomb(&b, &p);
        assert!((star - star_paper).abs() < 1e-4, "ω* {star}");
        for f in FrictionType::ALL {
            let r = run(&b, p, settings(f, FootContacts::Welded, 1e-3));
            let w = r.segment_tail_omega[0];
            assert!(w.abs() < 1e-3 * star.abs(), "{f:?} v {v}: ω {w}");
            let eb = engine_body(&b, &r);
            match f {
                FrictionType::Patch => {
                    assert!(locks(&eb, &p, Law::Anchors(0, 2)));
                    assert!(locks(&eb, &p, Law::Anchors(1, 3)));
                }
                FrictionType::TwoDirectional => assert!(locks(&eb, &p, Law::Box)),
                FrictionType::OneDirectional => {
                    let law = Law::Alternating(0b0101);
                    let (m0, h) = lock_moments(&eb, &p, law);
                    assert!(m0 + h < 0.0 && m0 - h < 0.0, "{m0} {h}");
                    assert!(steady_omega(&eb, &p, law, 0.0).omega < -0.1);
                    assert!(holds_at_rest(&eb, &p, law));
                    assert_eq!(at_rest(&eb, &p, law), AtRest::SemiStable);
                }
            }
        }
    }
}

/// Unwelded feet, one-directional: one `t0` row per foot along the
/// centre-of-mass velocity and nothing across it (`Law::Line`). The engine
/// approaches the closed form at first order in dt; Richardson's
/// extrapolation from dt = 1e-3 and 5e-4 lands on it.
#[test]
fn separate_one_directional_is_the_line_law() {
    let b = plate();
    for v in [0.2, 0.5, 1.0] {
        let p = push(v, PHI, 4.0);
        let s = |dt| settings(FrictionType::OneDirectional, FootContacts::Separate, dt);
        let (r1, r2) = (run(&b, p, s(1e-3)), run(&b, p, s(5e-4)));
        let pred = steady_omega(&engine_body(&b, &r1), &p, Law::Line, 0.0);
        assert!(!pred.sticks);
        let (w1, w2) = (r1.segment_tail_omega[0], r2.segment_tail_omega[0]);
        // Measured 5.4e-4, 1.5e-3, 3.4e-3 at v 0.2, 0.5, 1 (first order in
        // dt: the extrapolation below closes it).
        assert!(rel(w1, pred.omega) < 4e-3, "v {v}: {w1} vs {}", pred.omega);
        assert!(
            rel(w2, pred.omega) < rel(w1, pred.omega),
            "v {v}: no approach"
        );
        let extrapolated = 2.0 * w2 - w1;
        assert!(
            rel(extrapolated, pred.omega) < 1e-4,
            "v {v}: {extrapolated} vs {}",
            pred.omega
        );
        // 25–50 % faster than Coulomb.
        let e = rel(pred.omega, coulomb(&b, &p));
        assert!(e > 0.2 && e < 0.5, "v {v}: {e}");
    }
}

/// Unwelded feet, patch and two-directional: both rows at every foot
/// (`Law::Box`), which locks the paper plate.
#[test]
fn separate_patch_and_two_directional_lock() {
    let b = plate();
    for v in [0.2, 1.0] {
        let p = push(v, PHI, 4.0);
        let star = coulomb(&b, &p);
        for f in [FrictionType::Patch, FrictionType::TwoDirectional] {
            let r = run(&b, p, settings(f, FootContacts::Separate, 1e-3));
            assert!(locks(&engine_body(&b, &r), &p, Law::Box));
            let w = r.segment_tail_omega[0];
            assert!(w.abs() < 1e-3 * star.abs(), "{f:?} v {v}: ω {w}");
        }
    }
}

/// Feet at ±0.05 m, pushed at the plate's corner nearly along x: no law
/// locks, and every one of the five has the steady ω of its closed form.
#[test]
fn small_feet_turn_as_each_law_predicts() {
    let b = plate_with(0.05, [MU * G / 4.0; 4]);
    let p = push(0.3, 0.15, 4.0);
    for (f, contacts, law) in [
        (
            FrictionType::Patch,
            FootContacts::Welded,
            Law::Anchors(0, 2),
        ),
        (FrictionType::Patch, FootContacts::Separate, Law::Box),
        (FrictionType::TwoDirectional, FootContacts::Welded, Law::Box),
        (
            FrictionType::TwoDirectional,
            FootContacts::Separate,
            Law::Box,
        ),
        (
            FrictionType::OneDirectional,
            FootContacts::Welded,
            Law::Alternating(0b0101),
        ),
        (
            FrictionType::OneDirectional,
            FootContacts::Separate,
            Law::Line,
        ),
    ] {
        let r = run(&b, p, settings(f, contacts, 1e-3));
        let eb = engine_body(&b, &r);
        assert!(!locks(&eb, &p, law), "{f:?} {contacts:?}");
        let pred = steady_omega(&eb, &p, law, 0.0);
        let w = r.segment_tail_omega[0];
        // Measured 5.9e-4 to 7.2e-4, 4.5e-3 for two-directional.
        assert!(
            rel(w, pred.omega) < 6e-3,
            "{f:?} {contacts:?}: {w} vs {}",
            pred.omega
        );
    }
}

/// Welding, seen in the pusher force of the locked plate (steady translation
/// along n_φ): patch and two-directional resist with μ̄ m g, welded
/// one-directional with only the feet that got a `t0` row, μ̄ (N₀ + N₂).
#[test]
fn welded_one_directional_pulls_with_every_other_foot() {
    let b = plate();
    let p = push(0.5, PHI, 2.0);
    let n = p.direction();
    let along = |r: &PhysxRun| {
        let f = r.segment_tail_pusher_force[0];
        f[0] * n.x + f[1] * n.y
    };
    let weight = b.mass() * 9.81;
    for f in [FrictionType::Patch, FrictionType::TwoDirectional] {
        let r = run(&b, p, settings(f, FootContacts::Welded, 1e-3));
        // Measured 1.4e-5 (patch), 2.4e-4 (two-directional).
        assert!(rel(along(&r), r.mu * weight) < 5e-4, "{f:?}: {}", along(&r));
    }
    let r = run(
        &b,
        p,
        settings(FrictionType::OneDirectional, FootContacts::Welded, 1e-3),
    );
    let two = r.mu * (r.rest_loads[0] + r.rest_loads[2]);
    // Measured 8.1e-4.
    assert!(rel(along(&r), two) < 2e-3, "{} vs {two}", along(&r));
}

/// PhysX's PGS shares the weight of four rigid feet unequally (the support is
/// statically indeterminate; the split depends on the order it visits them):
/// equal on each diagonal, 2.80 / 2.10 N on the paper plate, not 2.45 N.
#[test]
fn pgs_shares_the_weight_on_the_diagonals() {
    let b = plate();
    for contacts in FootContacts::ALL {
        let r = run(
            &b,
            push(0.5, PHI, 0.1),
            settings(FrictionType::Patch, contacts, 1e-3),
        );
        let n = &r.rest_loads;
        let total: f64 = n.iter().sum();
        assert!(rel(total, 9.81) < 1e-3, "{n:?}");
        assert!(rel(n[0], n[2]) < 1e-3 && rel(n[1], n[3]) < 1e-3, "{n:?}");
        assert!((n[0] - n[1]).abs() > 0.5, "{n:?}");
        assert!(rel(r.mu, MU) < 1e-12);
    }
}

/// One thread, no randomness: a run is reproducible to the bit.
#[test]
fn runs_are_deterministic() {
    let b = plate();
    let p = push(0.5, PHI, 0.5);
    let s = settings(FrictionType::OneDirectional, FootContacts::Separate, 1e-3);
    let (a, c) = (run(&b, p, s), run(&b, p, s));
    assert_eq!(a.history, c.history);
}
