//! PhysX's feet loads: the PGS split of the weight at rest in closed form
//! (`predict::pgs_rest_loads`, the law's `FrictionLaw::loads`) against what
//! PhysX measures (the run diagnostics' `"loads"` and its rest loads).
#![cfg(feature = "physx")]

mod common;

use common::*;
use pushval_engine::{tail_loads, tail_mean_omega, Engine, EngineOptions};
use pushval_model::{Body, Support, Vec2};
use pushval_physx::models;

fn model(name: &str, contacts: &str) -> Box<dyn Engine> {
    let opts = EngineOptions {
        values: [("contacts".to_string(), serde_json::json!(contacts))]
            .into_iter()
            .collect(),
        ..Default::default()
    };
    let entry = models().into_iter().find(|m| m.name == name).unwrap();
    (entry.build)(&opts).unwrap()
}

/// Three feet around the centre of mass: statics fixes their loads.
const TRIANGLE: [[f64; 2]; 3] = [[-0.1, -0.08], [0.12, -0.06], [-0.01, 0.11]];

fn triangle() -> Body {
    let supports: Vec<Support> = TRIANGLE
        .iter()
        .map(|q| Support {
            position: Vec2::new(q[0], q[1]),
            friction: MU * G / 3.0,
        })
        .collect();
    Body::new(1.0, 0.008, Vec2::new(-0.12, -0.1), &supports).unwrap()
}

/// PhysX's PGS shares the weight of rigid feet as the closed form says
/// (Gauss–Seidel from zero impulses in the supports' order): its loads at
/// rest and over the run's last fifth are the law's within 1e-3 N (measured
/// ≤ 5.8e-4 N) for four feet at the plate's corners (2.803 / 2.102 N, not
/// 2.4525), four feet at ±0.05 m (3.704 / 1.201 N) and three feet (statics),
/// welded or separate; the loads sum to m g within 1e-4 N.
#[test]
fn pgs_split_of_the_weight_is_the_laws() {
    let small = plate_with(0.05, [MU * G / 4.0; 4]);
    for (body, v, phi, uneven) in [
        (plate(), 0.5, PHI, 0.3),
        (small, 0.3, 0.15, 1.2),
        (triangle(), 0.5, PHI, 0.0),
    ] {
        for contacts in ["welded", "separate"] {
            let m = model("physx_one_directional", contacts);
            let p = problem(&body, push(v, phi, 2.5));
            let r = m.run(&p, 1e-3).unwrap();
            let law = m.law().unwrap().loads(&p, 0, 1e-3).unwrap();
            let rest: Vec<f64> =
                serde_json::from_value(r.diagnostics["rest_loads"].clone()).unwrap();
            let measured = tail_loads(&r).unwrap();
            for loads in [&rest, &measured] {
                assert!((loads.iter().sum::<f64>() - G).abs() < 1e-4, "{loads:?}");
                for (a, b) in loads.iter().zip(&law) {
                    assert!(
                        (a - b).abs() < 1e-3,
                        "{contacts}: PhysX {loads:?}, law {law:?}"
                    );
                }
            }
            assert!((law.iter().sum::<f64>() - G).abs() < 1e-9 * G);
            let even = G / law.len() as f64;
            if uneven > 0.0 {
                assert!((law[0] - even).abs() > uneven, "{law:?}");
            }
        }
    }
    // Three feet: the split is statics (Σ N p = 0).
    let m = model("physx_patch", "welded");
    let law = m
        .law()
        .unwrap()
        .loads(&problem(&triangle(), push(0.5, PHI, 1.0)), 0, 1e-3)
        .unwrap();
    for k in 0..2 {
        let first: f64 = law.iter().zip(TRIANGLE).map(|(n, q)| n * q[k]).sum();
        assert!(first.abs() < 1e-9, "{law:?}");
    }
}

/// The closed form against the old PhysX study's measured rest loads
/// (results/friction_models/physx/map_one_directional_welded.csv before
/// d481d53, `rest_load_0..3`): within 6e-4 N.
#[test]
fn pgs_split_is_the_old_measurement() {
    let old = [
        2.8024559995780387,
        2.1025435184128582,
        2.8024562479307256,
        2.102543281701704,
    ];
    let law = model("physx_one_directional", "welded")
        .law()
        .unwrap()
        .loads(&problem(&plate(), push(0.5, PHI, 1.0)), 0, 1e-3)
        .unwrap();
    for (a, b) in law.iter().zip(old) {
        assert!((a - b).abs() < 6e-4, "{law:?} vs {old:?}");
    }
}

/// The law's caps are PhysX's (μ̄ times the PGS loads): on separate feet
/// with one-directional friction (`Law::Line`, no lock) the engine's ω is
/// the law's within 3e-3 (measured 1.5e-3 on the plate, 1.6e-3 on three
/// feet at dt = 1e-3; first order in dt).
#[test]
fn law_with_the_pgs_caps_predicts_omega() {
    for body in [plate(), triangle()] {
        let m = model("physx_one_directional", "separate");
        let p = problem(&body, push(0.5, PHI, 2.5));
        let r = m.run(&p, 1e-3).unwrap();
        let w = tail_mean_omega(&p, &r.trajectory, 0.2)[0].unwrap();
        let law = m.law().unwrap().steady(&p, 0, 1e-3).unwrap().omega;
        assert!((w - law).abs() < 3e-3 * law.abs(), "PhysX {w}, law {law}");
    }
}
