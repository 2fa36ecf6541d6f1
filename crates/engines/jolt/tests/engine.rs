//! Jolt itself against the closed forms of `pushval_jolt::predict`.
#![cfg(feature = "jolt")]

mod common;

use common::*;
use pushval_jolt::predict::{at_rest, AtRest, Direction, Law};
use pushval_jolt::{DetailedEngine, JoltRun, JoltSettings, JoltSimulator, Scene};

fn run(scene: Scene, v: f64, phi: f64, t: f64) -> JoltRun {
    JoltSimulator::new(JoltSettings {
        scene,
        ..Default::default()
    })
    .run(&problem(&plate(), push(v, phi, t)))
    .unwrap()
}

/// The box is one manifold of four points; the feet, with manifold
/// reduction off, four manifolds of one.
#[test]
fn manifold_sizes() {
    assert_eq!(run(Scene::Box, 0.5, PHI, 0.2).manifold_sizes, vec![4]);
    assert_eq!(run(Scene::Feet, 0.5, PHI, 0.2).manifold_sizes, vec![1; 4]);
}

/// At rest the loads carry the weight, and a symmetric plate's statics tie
/// opposite corners only: N₀ + N₁ = N₂ + N₃ and N₁ + N₂ = N₀ + N₃.
#[test]
fn rest_loads_carry_the_weight() {
    for scene in Scene::ALL {
        let r = run(scene, 0.5, PHI, 0.2);
        let n = &r.rest_loads;
        let w: f64 = n.iter().sum();
        assert!((w - G).abs() < 1e-3 * G, "{scene:?}: {n:?}");
        assert!((n[0] + n[1] - n[2] - n[3]).abs() < 1e-3 * G, "{n:?}");
        assert!((n[1] + n[2] - n[0] - n[3]).abs() < 1e-3 * G, "{n:?}");
    }
}

/// The sliding box's friction is the disc's radius μ Σ N: μ reaches the
/// contact unchanged (geometric mean of μ and μ), along the slip (its
/// friction point is the centre of mass, where both rows have the mass).
/// Its twist row holds the plate within its clamp μ Σ dᵢNᵢ, and the plate
/// does not turn, as the law's lock says.
#[test]
fn box_slides_without_turning() {
    let b = plate();
    for v in [0.2, 1.0] {
        let r = run(Scene::Box, v, PHI, 2.0);
        let c = &r.segment_tail_contacts[0];
        let n: f64 = c.iter().map(|x| x.normal).sum();
        let f = c[0].friction[0].hypot(c[0].friction[1]);
        assert!((f / n - MU).abs() < 1e-3 * MU, "μ = {}", f / n);
        assert!(r.segment_tail_max_angle[0] < 1e-3);
        let caps: Vec<f64> = r.rest_loads.iter().map(|n| r.mu * n).collect();
        let law = Law::jolt_box(&b, Some(&caps), Direction::EffectiveMass);
        assert_eq!(at_rest(&law, &b, &push(v, PHI, 1.0), 0.0), AtRest::Locked);
        assert!(c[0].twist.abs() <= law.twist_cap());
        assert!(
            r.segment_tail_omega[0].abs() < 1e-4,
            "{}",
            r.segment_tail_omega[0]
        );
    }
}

/// Each foot's friction is off its slip by up to tens of degrees, and by
/// the angle the effective-mass law gives to within 1e-2 rad.
#[test]
fn feet_friction_follows_the_effective_mass_direction() {
    let r = run(Scene::Feet, 0.5, PHI, 2.0);
    assert!(
        r.segment_tail_max_angle[0] > 0.1,
        "{}",
        r.segment_tail_max_angle[0]
    );
    assert!(
        r.segment_tail_max_angle_vs_law[0] < 1e-2,
        "{}",
        r.segment_tail_max_angle_vs_law[0]
    );
    assert!(r.segment_tail_contacts[0].iter().all(|c| c.twist == 0.0));
}
