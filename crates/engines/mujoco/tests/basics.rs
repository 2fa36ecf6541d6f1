//! The scene behaves like the rigid body it stands for: it rests, its weight
//! is carried by the feet, it is mirror symmetric, and the pusher never
//! overwrites its momentum.
#![cfg(feature = "mujoco")]

mod common;

use common::*;
use pushval_model::{kinematic, Push, Simulator};
use pushval_mujoco::theory::coulomb_steady;
use pushval_mujoco::{Cone, DetailedEngine, MujocoSettings, MujocoSimulator};

fn sim(cone: Cone) -> MujocoSimulator {
    MujocoSimulator::new(MujocoSettings {
        cone,
        ..Default::default()
    })
}

/// At high Froude number (v_c = 1 m/s, Fr ≈ 1.15) the inertial term moves
/// the steady ω far from the kinematic model's; MuJoCo (elliptic cone) must
/// follow the dynamic model, which it can only do if the driver leaves the
/// object's momentum alone.
#[test]
fn mass_term_survives_at_high_froude() {
    let body = plate();
    let push = Push {
        duration: 4.0,
        speed: 1.0,
        phi: paper_phi(),
    };
    let w_dyn = coulomb_steady(&body, &push, 0.0).unwrap();
    let w_kin = kinematic::omega(&body, &push).unwrap();
    // The physics: ω* = −0.6495, ω_kin = −1.1183 rad/s.
    assert!((w_dyn + 0.6495).abs() < 1e-3 && (w_kin + 1.1183).abs() < 1e-3);
    let run = sim(Cone::Elliptic)
        .run(&problem(&body, 1.0, paper_phi(), 4.0))
        .unwrap();
    let w = run.segment_tail_omega[0];
    assert!(
        (w - w_dyn).abs() < 0.03 * w_dyn.abs(),
        "MuJoCo ω = {w}, dynamic model ω* = {w_dyn}"
    );
    assert!(
        (w - w_kin).abs() > 0.4 * w_kin.abs(),
        "MuJoCo ω = {w} collapsed onto the kinematic ω = {w_kin}"
    );
}

/// With the pusher held still the object stays put, the feet carry its
/// weight (Σ N_i = m g), and the calibrated μ_i reproduce F_i = μ N_i.
#[test]
fn at_rest_stays_put_and_feet_carry_the_weight() {
    let body = plate();
    for cone in Cone::ALL {
        let run = sim(cone).run(&problem(&body, 0.0, 0.0, 1.0)).unwrap();
        let sum: f64 = run.rest_loads.iter().sum();
        assert!((sum - body.mass() * G).abs() < 1e-6 * G, "Σ N = {sum}");
        let tail: f64 = run.tail_loads[0].iter().sum();
        assert!((tail - body.mass() * G).abs() < 1e-6 * G, "Σ N = {tail}");
        for (k, (&n, &mu)) in run.rest_loads.iter().zip(&run.mu).enumerate() {
            // Equal loads on the symmetric square: μ_i = μ.
            assert!((n - G / 4.0).abs() < 1e-4 * G, "N_{k} = {n}");
            assert!((mu - MU).abs() < 1e-4, "μ_{k} = {mu}");
        }
        let last = run.trajectory.samples.last().unwrap();
        let first = run.trajectory.samples[0];
        assert!(
            (last.x - first.x).abs() < 1e-6 && (last.y - first.y).abs() < 1e-6,
            "moved by ({}, {})",
            last.x - first.x,
            last.y - first.y
        );
        assert!((last.theta - first.theta).abs() < 1e-6);
        assert!(run.max_tilt < 1e-3);
    }
}

/// Mirroring the scene about the x axis (y → −y, φ → −φ) mirrors the motion:
/// ω → −ω, y → −y. Holds for both cones (the pyramid's world axes map onto
/// themselves under the mirror).
#[test]
fn mirror_symmetry() {
    let body = plate();
    let mirror = mirrored(&body);
    for cone in Cone::ALL {
        let a = sim(cone)
            .simulate(&problem(&body, 0.5, paper_phi(), 1.0))
            .unwrap();
        let b = sim(cone)
            .simulate(&problem(&mirror, 0.5, -paper_phi(), 1.0))
            .unwrap();
        let mut worst = 0.0f64;
        for (p, q) in a.samples.iter().zip(&b.samples) {
            worst = worst
                .max((p.x - q.x).abs())
                .max((p.y + q.y).abs())
                .max((p.theta + q.theta).abs())
                .max(0.1 * (p.omega + q.omega).abs());
        }
        assert!(worst < 1e-6, "{cone:?}: mirror mismatch {worst}");
        assert!(a.samples.last().unwrap().theta.abs() > 0.05);
    }
}

/// Without the feature the simulator reports itself unavailable; with it,
/// the names follow the cone.
#[test]
#[allow(clippy::assertions_on_constants)]
fn names() {
    assert!(pushval_mujoco::AVAILABLE);
    assert_eq!(sim(Cone::Pyramidal).name(), "mujoco_pyramidal");
    assert_eq!(sim(Cone::Elliptic).name(), "mujoco_elliptic");
}
