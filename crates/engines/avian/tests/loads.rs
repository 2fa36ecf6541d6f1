//! avian3d's feet loads through the plug-in: what Avian measures (the run
//! diagnostics' `"loads"`) against statics and the law's loads
//! (`FrictionLaw::loads`, `predict::PlateScene::steady`). Needs the `avian`
//! feature.
#![cfg(feature = "avian")]

mod common;

use pushval_avian::models;
use pushval_engine::{tail_loads, Engine, EngineOptions};
use pushval_model::{Body, Problem, Support, Vec2};

use common::*;

const G: f64 = 9.81;

fn avian3d(cm_height: f64) -> Box<dyn Engine> {
    let opts = EngineOptions {
        values: [("cm_height".to_string(), serde_json::json!(cm_height))]
            .into_iter()
            .collect(),
        ..Default::default()
    };
    let entry = models().into_iter().find(|m| m.name == "avian3d").unwrap();
    (entry.build)(&opts).unwrap()
}

/// Three feet around the centre of mass: statics fixes their loads.
const TRIANGLE: [[f64; 2]; 3] = [[-0.1, -0.08], [0.12, -0.06], [-0.01, 0.11]];

/// The loads (N) of three feet at `TRIANGLE` carrying `weight` (N) with
/// first moment `moment` (N m): `Σ N = W`, `Σ N p = M`.
fn statics3(weight: f64, moment: [f64; 2]) -> [f64; 3] {
    let m = nalgebra::Matrix3::from_fn(|r, c| if r == 0 { 1.0 } else { TRIANGLE[c][r - 1] });
    let b = nalgebra::Vector3::new(weight, moment[0], moment[1]);
    m.lu().solve(&b).expect("the feet are not collinear").into()
}

fn triangle(speed: f64, duration: f64) -> Problem {
    let mut p = paper(speed, duration);
    let supports: Vec<Support> = TRIANGLE
        .iter()
        .zip(statics3(G, [0.0, 0.0]))
        .map(|(q, n)| Support {
            position: Vec2::new(q[0], q[1]),
            friction: 0.5 * n,
        })
        .collect();
    p.body = Body::new(1.0, 0.008, Vec2::new(-0.12, -0.1), &supports).unwrap();
    p
}

fn run(m: &dyn Engine, p: &Problem) -> (Vec<f64>, Vec<f64>) {
    let r = m.run(p, 1e-3).unwrap();
    (
        tail_loads(&r).unwrap(),
        m.law().unwrap().loads(p, 0, 1e-3).unwrap(),
    )
}

/// With the centre of mass on the floor the law's loads are the rest loads:
/// statics for three feet, m g / 4 on each foot of the square plate, so
/// `μ_i N_i = F_i`.
#[test]
fn law_loads_on_the_floor_are_the_rest_loads() {
    let law = avian3d(0.0);
    let law = law.law().unwrap();
    let t = triangle(0.5, 2.5);
    let loads = law.loads(&t, 0, 1e-3).unwrap();
    for ((n, e), s) in loads
        .iter()
        .zip(statics3(G, [0.0, 0.0]))
        .zip(t.body.supports())
    {
        assert!((n - e).abs() < 1e-9, "{loads:?}");
        assert!((0.5 * n - s.friction).abs() < 1e-9);
    }
    for n in law.loads(&paper(0.5, 2.5), 0, 1e-3).unwrap() {
        assert!((n - G / 4.0).abs() < 1e-9);
    }
}

/// Avian's loads over the run's last fifth match the law's foot by foot
/// within 1e-3 N (measured ≤ 5.8e-4 N, the loads moving by up to 0.7 N) and
/// sum to m g within 1e-3 N, for the square plate (four feet: the soft
/// contacts' split) and three feet (statics), the centre of mass at 0, 2 and
/// 5 cm.
#[test]
fn measured_loads_are_the_laws() {
    for h in [0.0, 0.02, 0.05] {
        for speed in [0.2, 1.0] {
            for p in [paper(speed, 2.5), triangle(speed, 2.5)] {
                let (measured, law) = run(avian3d(h).as_ref(), &p);
                let sum: f64 = measured.iter().sum();
                assert!((sum - G).abs() < 1e-3, "h {h} v {speed}: Σ N = {sum}");
                for (a, b) in measured.iter().zip(&law) {
                    assert!(
                        (a - b).abs() < 1e-3,
                        "h {h} v {speed}: Avian {measured:?}, law {law:?}"
                    );
                }
            }
        }
    }
}

/// The law's loads are the closed form of the old avian study
/// (results/friction_models/avian/load_transfer.csv before d481d53,
/// columns `N*_predicted`, printed to 1e-6 N).
#[test]
fn law_loads_are_the_old_closed_form() {
    for (h, speed, old) in [
        (0.02, 0.5, [2.179256, 2.417033, 2.725744, 2.487967]),
        (0.05, 1.0, [1.771687, 2.331109, 3.133313, 2.573891]),
    ] {
        let law = avian3d(h)
            .law()
            .unwrap()
            .loads(&paper(speed, 4.0), 0, 1e-3)
            .unwrap();
        for (a, b) in law.iter().zip(old) {
            assert!((a - b).abs() < 1e-6, "{law:?} vs {old:?}");
        }
    }
}
