//! The MuJoCo findings of `pushval study mujoco` (results/friction_models/mujoco/), asserted: if an
//! explanation stops holding, these fail. Expected values come from the
//! model (`pushval-model`) and closed forms, not from MuJoCo's output.
#![cfg(feature = "mujoco")]

mod common;

use std::f64::consts::FRAC_PI_4;

use common::*;
use pushval_model::Push;
use pushval_mujoco::theory::{coulomb_steady, steady_omega_load_transfer};
use pushval_mujoco::{Cone, DetailedEngine, MujocoSettings, MujocoSimulator};

fn run(settings: MujocoSettings, speed: f64) -> pushval_mujoco::MujocoRun {
    MujocoSimulator::new(settings)
        .run(&problem(&plate(), speed, paper_phi(), 4.0))
        .unwrap()
}

fn omega_star(speed: f64) -> f64 {
    let push = Push {
        duration: 4.0,
        speed,
        phi: paper_phi(),
    };
    coulomb_steady(&plate(), &push, 0.0).unwrap()
}

/// Pyramidal cone: the plate stops turning and locks where the push runs
/// along the diagonal of the pyramid's world-fixed tangent axes,
/// θ_lock = π/4 − φ (mod π/2), at every speed and whatever impratio.
#[test]
fn pyramid_locks_orientation_on_its_diagonal() {
    for (speed, impratio) in [(0.2, 1.0), (1.0, 1.0), (0.5, 100.0)] {
        let r = run(
            MujocoSettings {
                cone: Cone::Pyramidal,
                impratio,
                ..Default::default()
            },
            speed,
        );
        let w = r.segment_tail_omega[0];
        let ws = omega_star(speed);
        assert!(w.abs() < 0.1 * ws.abs(), "v={speed}: ω = {w}, ω* = {ws}");
        let theta = r.history.last().unwrap().theta;
        let lock = FRAC_PI_4 - paper_phi();
        let d = (theta - lock + FRAC_PI_4).rem_euclid(std::f64::consts::FRAC_PI_2) - FRAC_PI_4;
        assert!(
            d.abs() < 0.05,
            "v={speed}: θ_end = {theta}, predicted lock {lock}"
        );
    }
}

/// Elliptic cone: the steady ω follows the Coulomb model's ω* within 3 %
/// at v_c = 0.5 and 1 m/s, with the default solver, with impratio 100 and
/// with noslip iterations; ω chatters by less than 10 % of ω*.
#[test]
fn elliptic_follows_the_coulomb_model() {
    for s in [
        MujocoSettings::default(),
        MujocoSettings {
            impratio: 100.0,
            ..Default::default()
        },
        MujocoSettings {
            noslip_iterations: 10,
            ..Default::default()
        },
    ] {
        for speed in [0.5, 1.0] {
            let r = run(
                MujocoSettings {
                    cone: Cone::Elliptic,
                    ..s
                },
                speed,
            );
            let (w, ws) = (r.segment_tail_omega[0], omega_star(speed));
            assert!(
                (w - ws).abs() < 0.03 * ws.abs(),
                "{}: ω = {w}, ω* = {ws}",
                s.label()
            );
            assert!(r.segment_tail_omega_std[0] < 0.1 * ws.abs());
            // Vertical balance while sliding: the feet carry the weight.
            let sum: f64 = r.tail_loads[0].iter().sum();
            assert!((sum - G).abs() < 0.01 * G, "Σ N = {sum}");
        }
    }
}

/// Load transfer: with the centre of mass 5 cm up and the push at the
/// floor, MuJoCo's ω moves away from ω* towards the quasi-static
/// load-transfer prediction (tilt balance, least-norm load split).
#[test]
fn load_transfer_moves_omega_as_tilt_balance_predicts() {
    let speed = 1.0;
    let r = run(
        MujocoSettings {
            cone: Cone::Elliptic,
            cm_height: 0.05,
            push_height: 0.0,
            ..Default::default()
        },
        speed,
    );
    let push = Push {
        duration: 4.0,
        speed,
        phi: paper_phi(),
    };
    let (wt, loads) =
        steady_omega_load_transfer(&plate(), &push, &r.mu, &r.rest_loads, 0.05, 0.0).unwrap();
    let ws = omega_star(speed);
    let w = r.segment_tail_omega[0];
    assert!(
        (wt - ws).abs() > 0.03 * ws.abs(),
        "transfer too small to test"
    );
    assert!(
        (w - wt).abs() < 0.25 * (wt - ws).abs(),
        "MuJoCo ω = {w}, load-transfer ω = {wt}, ω* = {ws}"
    );
    // The transfer only moves load between the feet.
    let total: f64 = loads.iter().sum();
    let rest: f64 = r.rest_loads.iter().sum();
    assert!((total - rest).abs() < 1e-9 * G);
}
