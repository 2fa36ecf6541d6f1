//! `avian3d`: Avian's own contact friction on the plate's feet is Coulomb
//! along −u per contact point with the contacts' loads, as `predict` derives
//! from the solver; the loads are the rigid plate's on soft contacts. Needs
//! the `avian` feature.
#![cfg(feature = "avian")]

mod common;

use pushval_avian::predict::PlateScene;
use pushval_avian::{Avian3dSettings, Avian3dSimulator, DetailedEngine};
use pushval_engine::step_tail_omega;

use common::*;

/// At rest the four feet of the symmetric plate carry m g / 4 each, read as
/// the step's mean normal impulse (which checks the adapter's reading of
/// Avian's accumulated impulses), and the calibration gives μ = 0.5.
#[test]
fn rest_loads_are_statics_and_mu_is_calibrated() {
    let p = paper(0.5, 0.1);
    let r = Avian3dSimulator::new(Avian3dSettings::default())
        .run(&p)
        .unwrap();
    let total: f64 = r.rest_loads.iter().sum();
    assert!((total - 9.81).abs() < 1e-6, "Σ N = {total}");
    for (n, mu) in r.rest_loads.iter().zip(&r.mu) {
        assert!((n - 9.81 / 4.0).abs() < 1e-6, "{n}");
        assert!((mu - 0.5).abs() < 1e-6, "{mu}");
    }
    assert!(r.max_tilt < 1e-5, "tilt {}", r.max_tilt);
}

/// With the centre of mass on the floor's plane (the default) the loads do
/// not move and Avian's friction, Coulomb along −u per contact, settles on
/// the Coulomb root ω* (within 1e-3; measured 2.4e-4 to 3.2e-4). A −K⁻¹u
/// law (rapier3d's `FrictionModel::Coulomb`) would turn 40–50 % faster.
#[test]
fn flat_plate_settles_on_the_coulomb_root() {
    for speed in [0.2, 0.5, 1.0] {
        let p = paper(speed, 4.0);
        let star = coulomb_root(&p, 0);
        let r = Avian3dSimulator::new(Avian3dSettings::default())
            .run(&p)
            .unwrap();
        let w = step_tail_omega(&p, &r.history, 0.2)[0];
        assert!((w / star - 1.0).abs() < 1e-3, "{speed} m/s: {w} vs {star}");
        for n in &r.segment_tail_loads[0] {
            assert!((n - 9.81 / 4.0).abs() < 1e-3 * 9.81, "{n}");
        }
    }
}

/// With the centre of mass (and the pinned point) 2 cm above the floor, the
/// pusher and the friction form a couple that moves load between the feet:
/// the steady ω leaves ω* by more than 1 %, and the closed form (loads of the
/// rigid plate on soft contacts with `Σ N_i r_i = −h Σ f_i`, ω the root of
/// the moment balance with `F_i = μ N_i`) predicts both the loads and ω.
#[test]
fn load_transfer_of_a_raised_plate_is_predicted() {
    let p = paper(0.5, 4.0);
    let s = Avian3dSettings {
        cm_height: 0.02,
        ..Default::default()
    };
    let star = coulomb_root(&p, 0);
    let (pred, loads) = PlateScene::new(&p, &s)
        .unwrap()
        .steady(&p.pushes[0], 0.0)
        .unwrap();
    let r = Avian3dSimulator::new(s).run(&p).unwrap();
    let w = step_tail_omega(&p, &r.history, 0.2)[0];
    assert!(
        (pred / star - 1.0).abs() > 1e-2,
        "the couple matters: {pred} vs {star}"
    );
    assert!(
        (w / pred - 1.0).abs() < 2e-3,
        "engine {w} vs predicted {pred}"
    );
    for (n, m) in r.segment_tail_loads[0].iter().zip(&loads) {
        assert!((n - m).abs() < 1e-3 * 9.81, "load {n} vs predicted {m}");
    }
}
