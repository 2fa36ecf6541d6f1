//! Basic physics of the 3-D scene: rest, a push through the centre of
//! friction, mirror symmetry, the manifold structure, input checks.

use std::f64::consts::FRAC_PI_4;

use pushval_model::{Body, Initial, Problem, Push, Simulator, Support, Switching, Vec2};
use pushval_rapier3d::{
    ContactFriction, DetailedEngine, FeetColliders, Rapier3dSettings, Rapier3dSimulator,
};

const MU: f64 = 0.5;
const G: f64 = 9.81;
const H: f64 = 0.125;

fn plate(contact: [f64; 2]) -> Body {
    let supports: Vec<Support> = [[-H, -H], [H, -H], [H, H], [-H, H]]
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

fn problem(body: Body, pushes: Vec<Push>) -> Problem {
    Problem {
        body,
        limits: Default::default(),
        pushes,
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

fn push(speed: f64, phi: f64, duration: f64) -> Push {
    Push {
        duration,
        speed,
        phi,
    }
}

fn settings(friction: ContactFriction, feet: FeetColliders) -> Rapier3dSettings {
    Rapier3dSettings {
        friction,
        feet,
        ..Default::default()
    }
}

#[test]
fn at_rest_the_object_stays_put_and_the_loads_carry_its_weight() {
    for f in ContactFriction::ALL {
        for feet in [FeetColliders::Compound, FeetColliders::Separate] {
            let p = problem(plate([-H, -H]), vec![push(0.0, 0.3, 1.0)]);
            let run = Rapier3dSimulator::new(settings(f, feet)).run(&p).unwrap();
            let last = run.trajectory.samples.last().unwrap();
            // Creep of the soft contacts after the settle phase: micrometres.
            assert!(
                last.x.hypot(last.y) < 1e-5,
                "{f:?} {feet:?} drifted {last:?}"
            );
            assert!(
                last.theta.abs() < 1e-4 && last.omega.abs() < 1e-6,
                "{last:?}"
            );
            let w = 1.0 * G;
            let rest: f64 = run.rest_loads.iter().sum();
            let tail: f64 = run.segment_tail_loads[0].iter().sum();
            assert!(
                (rest - w).abs() < 1e-3 * w,
                "rest loads {:?}",
                run.rest_loads
            );
            assert!(
                (tail - w).abs() < 1e-3 * w,
                "loads {:?}",
                run.segment_tail_loads
            );
            assert!(run.max_tilt < 1e-3 && run.max_lift < 1e-4);
        }
    }
}

#[test]
fn a_push_through_the_centre_of_friction_translates() {
    // Contact at the middle of the left edge, pushed along +x: the line of
    // push passes through the centre of mass and of friction.
    for f in ContactFriction::ALL {
        let (v, t) = (0.3, 3.0);
        let p = problem(plate([-H, 0.0]), vec![push(v, 0.0, t)]);
        let run = Rapier3dSimulator::new(settings(f, FeetColliders::Compound))
            .run(&p)
            .unwrap();
        let last = run.trajectory.samples.last().unwrap();
        assert!(
            run.segment_tail_omega[0].abs() < 1e-6,
            "{f:?}: {:?}",
            run.segment_tail_omega
        );
        // The settled rest loads are slightly unequal (indeterminate statics), so
        // the start has a small turning transient before the loads even out.
        assert!(last.theta.abs() < 1e-2, "{f:?}: θ = {}", last.theta);
        assert!(
            (last.x - v * t).abs() < 1e-3 && last.y.abs() < 1e-2,
            "{last:?}"
        );
    }
}

#[test]
fn mirroring_the_scene_flips_omega() {
    let phi = FRAC_PI_4 + 0.3;
    let a = problem(plate([-H, -H]), vec![push(0.5, phi, 3.0)]);
    // Mirror y → −y: contact (−H, H), direction −φ.
    let b = problem(plate([-H, H]), vec![push(0.5, -phi, 3.0)]);
    for feet in [FeetColliders::Compound, FeetColliders::Separate] {
        let s = Rapier3dSimulator::new(settings(ContactFriction::Coulomb, feet));
        let wa = s.run(&a).unwrap().segment_tail_omega[0];
        let wb = s.run(&b).unwrap().segment_tail_omega[0];
        assert!(wa < -0.1, "{wa}");
        assert!((wa + wb).abs() < 1e-3 * wa.abs(), "{feet:?}: {wa} vs {wb}");
    }
}

#[test]
fn compound_feet_share_one_manifold_separate_feet_do_not() {
    let p = problem(plate([-H, -H]), vec![push(0.2, 1.0, 0.1)]);
    for f in ContactFriction::ALL {
        let c = Rapier3dSimulator::new(settings(f, FeetColliders::Compound))
            .run(&p)
            .unwrap();
        assert_eq!((c.manifolds, c.manifold_points), (1, 4), "{f:?} compound");
        let s = Rapier3dSimulator::new(settings(f, FeetColliders::Separate))
            .run(&p)
            .unwrap();
        assert_eq!((s.manifolds, s.manifold_points), (4, 4), "{f:?} separate");
    }
}

#[test]
fn a_switch_is_followed_and_names_are_stable() {
    let p = problem(
        plate([-H, -H]),
        vec![push(0.3, 0.8, 1.0), push(0.3, 1.2, 1.0)],
    );
    let s = Rapier3dSimulator::new(settings(ContactFriction::Coulomb, FeetColliders::Compound));
    assert_eq!(s.name(), "rapier3d");
    let t = s.simulate(&p).unwrap();
    assert_eq!(t.model, "rapier3d");
    assert_eq!(t.samples.len(), p.sample_times().len());
    assert_eq!(t.segments.len(), 2);
    let simp = Rapier3dSimulator::new(settings(
        ContactFriction::Simplified,
        FeetColliders::Compound,
    ));
    assert_eq!(simp.name(), "rapier3d_simplified");
    assert_eq!(ContactFriction::Coulomb.as_str(), "coulomb");
    assert_eq!(ContactFriction::Simplified.as_str(), "simplified");
    assert!(Rapier3dSettings::default().label().contains("coulomb"));
}

#[test]
fn unsupported_inputs_are_refused() {
    // Five supports in one compound collider.
    let five: Vec<Support> = [[-H, -H], [H, -H], [H, H], [-H, H], [0.0, 0.0]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: 1.0,
        })
        .collect();
    let body = Body::new(1.0, 0.01, Vec2::new(-H, -H), &five).unwrap();
    let p = problem(body, vec![push(0.2, 1.0, 0.1)]);
    let compound =
        Rapier3dSimulator::new(settings(ContactFriction::Coulomb, FeetColliders::Compound));
    assert!(compound.run(&p).is_err());
    assert!(
        Rapier3dSimulator::new(settings(ContactFriction::Coulomb, FeetColliders::Separate))
            .run(&p)
            .is_ok()
    );
    // Unequal μ in one compound collider.
    let mixed: Vec<Support> = [[-H, -H], [H, -H], [H, H], [-H, H]]
        .iter()
        .enumerate()
        .map(|(i, c)| Support {
            position: Vec2::new(c[0], c[1]),
            friction: if i == 0 { 2.0 } else { 1.0 },
        })
        .collect();
    let p = problem(
        Body::new(1.0, 0.01, Vec2::new(-H, -H), &mixed).unwrap(),
        vec![push(0.2, 1.0, 0.1)],
    );
    assert!(compound.run(&p).is_err());
    let bad = Rapier3dSettings {
        dt: 0.0,
        ..Default::default()
    };
    assert!(Rapier3dSimulator::new(bad).run(&p).is_err());
}
