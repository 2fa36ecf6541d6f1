//! The findings reported in results/friction_models/rapier3d/README.md, as
//! assertions: expected values come from the Coulomb model and from the
//! closed forms of `pushval_rapier3d::predict`, never from engine output.

use std::f64::consts::FRAC_PI_4;

use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};
use pushval_rapier3d::predict::{
    coulomb_steady, predict_steady, simplified_locks, simplified_steady, Law,
};
use pushval_rapier3d::{
    ContactFriction, DetailedEngine, FeetColliders, Rapier3dSettings, Rapier3dSimulator,
};

const MU: f64 = 0.5;
const G: f64 = 9.81;
const H: f64 = 0.125;

fn body(half: f64, contact: [f64; 2]) -> Body {
    let supports: Vec<Support> = [[-half, -half], [half, -half], [half, half], [-half, half]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: MU * G / 4.0,
        })
        .collect();
    Body::new(
        1.0,
        0.0625 * 2.0 / 12.0,
        Vec2::new(contact[0], contact[1]),
        &supports,
    )
    .unwrap()
}

fn problem(body: Body, speed: f64, phi: f64, duration: f64) -> Problem {
    Problem {
        body,
        limits: Default::default(),
        pushes: vec![Push {
            duration,
            speed,
            phi,
        }],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

const PHI: f64 = FRAC_PI_4 + 0.3;

#[test]
fn coulomb_omega_is_the_effective_mass_law_not_coulomb() {
    for (v, star_paper) in [(0.2, -0.2174), (0.5, -0.4738), (1.0, -0.6495)] {
        let p = problem(body(H, [-H, -H]), v, PHI, 4.0);
        let star = coulomb_steady(&p.body, &p.pushes[0], 0.0).unwrap();
        assert!((star - star_paper).abs() < 1e-4, "ω* {star}");
        for dt in [1e-3, 1.0 / 60.0] {
            let s = Rapier3dSettings {
                dt,
                ..Default::default()
            };
            let run = Rapier3dSimulator::new(s).run(&p).unwrap();
            let w = run.segment_tail_omega[0];
            let pred = predict_steady(
                &s.scene(&p).unwrap(),
                &p.pushes[0],
                Law::EffectiveMassDisk,
                true,
            )
            .unwrap()
            .omega;
            // 40–56 % off the Coulomb model, on the effective-mass law.
            let e = rel(w, star);
            assert!(e > 0.4 && e < 0.56, "v {v} dt {dt}: {w} vs ω* {star}");
            let tol = if dt < 2e-3 { 2e-3 } else { 1.5e-2 };
            assert!(rel(w, pred) < tol, "v {v} dt {dt}: {w} vs predicted {pred}");
        }
    }
}

#[test]
fn every_foot_slides_at_full_coulomb_magnitude() {
    let p = problem(body(H, [-H, -H]), 0.5, PHI, 3.0);
    let run = Rapier3dSimulator::new(Rapier3dSettings::default())
        .run(&p)
        .unwrap();
    for i in 0..4 {
        let n = run.segment_tail_loads[0][i];
        let f = run.segment_tail_friction[0][i];
        assert!(
            rel(f, run.mu[i] * n) < 1e-6,
            "foot {i}: {f} vs μN {}",
            run.mu[i] * n
        );
        assert!(run.segment_tail_min_slip[0][i] > 0.05, "foot {i} sticks");
    }
}

#[test]
fn simplified_on_one_manifold_locks_the_orientation() {
    for (v, phi) in [(0.2, PHI), (1.0, PHI), (0.5, 0.2), (0.5, 1.4)] {
        let p = problem(body(H, [-H, -H]), v, phi, 3.0);
        let s = Rapier3dSettings {
            friction: ContactFriction::Simplified,
            ..Default::default()
        };
        let scene = s.scene(&p).unwrap();
        let loads = scene.rest_loads();
        assert!(simplified_locks(
            &scene.points,
            &loads,
            MU,
            &p.body,
            &p.pushes[0]
        ));
        let run = Rapier3dSimulator::new(s).run(&p).unwrap();
        let last = run.trajectory.samples.last().unwrap();
        assert!(
            run.segment_tail_omega[0].abs() < 1e-6,
            "{v} {phi}: {:?}",
            run.segment_tail_omega
        );
        assert!(last.theta.abs() < 1e-4, "θ {}", last.theta);
        // It still slides with the pusher.
        assert!(
            (last.x.hypot(last.y) - v * 3.0).abs() < 1e-2 * v * 3.0,
            "{last:?}"
        );
    }
}

#[test]
fn simplified_with_a_collider_per_foot_is_coulomb() {
    let p = problem(body(H, [-H, -H]), 0.5, PHI, 3.0);
    let run = |f| {
        Rapier3dSimulator::new(Rapier3dSettings {
            friction: f,
            feet: FeetColliders::Separate,
            ..Default::default()
        })
        .run(&p)
        .unwrap()
        .segment_tail_omega[0]
    };
    let (c, s) = (
        run(ContactFriction::Coulomb),
        run(ContactFriction::Simplified),
    );
    assert!(rel(s, c) < 1e-4, "{s} vs {c}");
}

#[test]
fn simplified_turns_when_the_twist_limit_is_exceeded() {
    // Feet close to the centre (±0.05 m), contact at the corner of the plate,
    // push nearly along x: |(c − p_c) × n_φ| = 0.105 m > mean foot distance 0.0707 m.
    let p = problem(body(0.05, [-H, -H]), 0.3, 0.15, 4.0);
    let s = Rapier3dSettings {
        friction: ContactFriction::Simplified,
        ..Default::default()
    };
    let scene = s.scene(&p).unwrap();
    let loads = scene.rest_loads();
    assert!(!simplified_locks(
        &scene.points,
        &loads,
        MU,
        &p.body,
        &p.pushes[0]
    ));
    let pred = predict_steady(&scene, &p.pushes[0], Law::SimplifiedOneManifold, true)
        .unwrap()
        .omega;
    let quasi = simplified_steady(&scene.points, &loads, MU, &p.body, &p.pushes[0]);
    assert!(pred.abs() > 0.1 && rel(pred, quasi) < 0.05);
    let w = Rapier3dSimulator::new(s)
        .run(&p)
        .unwrap()
        .segment_tail_omega[0];
    assert!(rel(w, pred) < 1e-2, "engine {w} vs predicted {pred}");
}

#[test]
fn loads_follow_the_tilting_balance() {
    // h_cm = 0.05, h_push = 0.1: Σ N_i p_i = h_push f_c − h_cm m a_cm.
    let p = problem(body(H, [-H, -H]), 0.5, PHI, 4.0);
    let s = Rapier3dSettings {
        cm_height: 0.05,
        push_height: 0.1,
        feet: FeetColliders::Separate,
        ..Default::default()
    };
    let run = Rapier3dSimulator::new(s).run(&p).unwrap();
    let pred = predict_steady(
        &s.scene(&p).unwrap(),
        &p.pushes[0],
        Law::EffectiveMassDisk,
        true,
    )
    .unwrap();
    let total: f64 = run.segment_tail_loads[0].iter().sum();
    assert!(rel(total, G) < 1e-3);
    for (m, q) in run.segment_tail_loads[0].iter().zip(&pred.loads) {
        assert!(
            (m - q).abs() < 0.01,
            "{:?} vs {:?}",
            run.segment_tail_loads[0],
            pred.loads
        );
    }
    // The transfer is large (the pushed corner is unloaded by ~1.4 N) …
    assert!(pred.loads[0] < 0.5 * G / 4.0 + 0.1);
    // … and the prediction with it gives the engine's ω.
    assert!(rel(run.segment_tail_omega[0], pred.omega) < 2e-3);
}

#[test]
fn a_high_push_lifts_the_pushed_corner() {
    let p = problem(body(H, [-H, -H]), 0.5, PHI, 4.0);
    let s = Rapier3dSettings {
        cm_height: 0.1,
        push_height: 0.2,
        feet: FeetColliders::Separate,
        ..Default::default()
    };
    let run = Rapier3dSimulator::new(s).run(&p).unwrap();
    let pred = predict_steady(
        &s.scene(&p).unwrap(),
        &p.pushes[0],
        Law::EffectiveMassDisk,
        true,
    )
    .unwrap();
    assert_eq!(pred.loads[0], 0.0);
    assert!(run.lost_contact()[0] && !run.lost_contact()[2]);
    assert!(
        rel(run.segment_tail_omega[0], pred.omega) < 1e-2,
        "{} vs {}",
        run.segment_tail_omega[0],
        pred.omega
    );
}
