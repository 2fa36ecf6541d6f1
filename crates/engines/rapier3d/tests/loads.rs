//! rapier3d's feet loads through the plug-in: what rapier measures (the run
//! diagnostics' `"loads"`) against statics and the law's loads
//! (`FrictionLaw::loads`, the tilting balance of `predict::predict_steady`).

use std::f64::consts::FRAC_PI_4;

use pushval_engine::{tail_loads, Engine, EngineOptions};
use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};
use pushval_rapier3d::models;

const G: f64 = 9.81;
const H: f64 = 0.125;
const PHI: f64 = FRAC_PI_4 + 0.3;

fn model(name: &str, cm_height: f64, push_height: f64) -> Box<dyn Engine> {
    let opts = EngineOptions {
        values: [
            ("cm_height".to_string(), serde_json::json!(cm_height)),
            ("push_height".to_string(), serde_json::json!(push_height)),
        ]
        .into_iter()
        .collect(),
        ..Default::default()
    };
    let entry = models().into_iter().find(|m| m.name == name).unwrap();
    (entry.build)(&opts).unwrap()
}

/// Three feet around the centre of mass: statics fixes their loads.
const TRIANGLE: [[f64; 2]; 3] = [[-0.1, -0.08], [0.12, -0.06], [-0.01, 0.11]];

/// The loads (N) of three feet at `TRIANGLE` carrying `weight` (N) with no
/// first moment: `Σ N = W`, `Σ N p = 0`, by Cramer's rule.
fn statics3(weight: f64) -> [f64; 3] {
    let m = [
        [1.0, 1.0, 1.0],
        [TRIANGLE[0][0], TRIANGLE[1][0], TRIANGLE[2][0]],
        [TRIANGLE[0][1], TRIANGLE[1][1], TRIANGLE[2][1]],
    ];
    let b = [weight, 0.0, 0.0];
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        let mut mk = m;
        for r in 0..3 {
            mk[r][k] = b[r];
        }
        *o = det(&mk) / d;
    }
    out
}

fn problem(body: Body, speed: f64, duration: f64) -> Problem {
    Problem {
        body,
        limits: Default::default(),
        pushes: vec![Push {
            duration,
            speed,
            phi: PHI,
        }],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

fn plate() -> Body {
    let supports: Vec<Support> = [[-H, -H], [H, -H], [H, H], [-H, H]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: 0.5 * G / 4.0,
        })
        .collect();
    Body::new(1.0, 0.0625 * 2.0 / 12.0, Vec2::new(-H, -H), &supports).unwrap()
}

fn triangle() -> Body {
    let supports: Vec<Support> = TRIANGLE
        .iter()
        .zip(statics3(G))
        .map(|(q, n)| Support {
            position: Vec2::new(q[0], q[1]),
            friction: 0.5 * n,
        })
        .collect();
    Body::new(1.0, 0.008, Vec2::new(-0.12, -0.1), &supports).unwrap()
}

fn run(m: &dyn Engine, p: &Problem) -> (Vec<f64>, Vec<f64>) {
    let r = m.run(p, 1e-3).unwrap();
    (
        tail_loads(&r).unwrap(),
        m.law().unwrap().loads(p, 0, 1e-3).unwrap(),
    )
}

/// With the centre of mass and the pusher on the floor (a law-only limit:
/// the engine's ball feet need the centre of mass above it) the law's loads
/// are the rest loads: statics for three feet (μ_i N_i = F_i), m g / 4 on
/// each foot of the square plate.
#[test]
fn law_loads_on_the_floor_are_the_rest_loads() {
    use pushval_rapier3d::{ContactFriction, Rapier3dModel, Rapier3dSettings};
    for friction in [ContactFriction::Coulomb, ContactFriction::Simplified] {
        let m = Rapier3dModel::new(Rapier3dSettings {
            friction,
            cm_height: 0.0,
            push_height: 0.0,
            ..Default::default()
        });
        let m = m.law().unwrap();
        let t = problem(triangle(), 0.5, 2.5);
        let loads = m.loads(&t, 0, 1e-3).unwrap();
        for ((n, e), s) in loads.iter().zip(statics3(G)).zip(t.body.supports()) {
            assert!((n - e).abs() < 1e-9, "{loads:?}");
            assert!((0.5 * n - s.friction).abs() < 1e-9);
        }
        for n in m.loads(&problem(plate(), 0.5, 2.5), 0, 1e-3).unwrap() {
            assert!((n - G / 4.0).abs() < 1e-9);
        }
    }
}

/// rapier's loads over the run's last fifth sum to m g (within 1e-4 N;
/// measured ≤ 2.3e-5 N) and match the law's foot by foot: within 8e-3 N for
/// `rapier3d` (measured ≤ 5.9e-3 N) and 1.5e-2 N for `rapier3d_simplified`
/// (measured ≤ 1.1e-2 N), the loads moving by up to 3.3 N, for the plate
/// (four feet: springs ∝ effective mass) and three feet (statics).
#[test]
fn measured_loads_are_the_laws() {
    for (name, tol) in [("rapier3d", 8e-3), ("rapier3d_simplified", 1.5e-2)] {
        for body in [plate(), triangle()] {
            for (h_cm, h_push) in [(0.005, 0.0), (0.05, 0.0), (0.05, 0.05), (0.1, 0.1)] {
                let p = problem(body.clone(), 1.0, 2.5);
                let (measured, law) = run(model(name, h_cm, h_push).as_ref(), &p);
                let sum: f64 = measured.iter().sum();
                assert!((sum - G).abs() < 1e-4, "{name}: Σ N = {sum}");
                for (a, b) in measured.iter().zip(&law) {
                    assert!(
                        (a - b).abs() < tol,
                        "{name} h_cm {h_cm} h_push {h_push}: rapier {measured:?}, law {law:?}"
                    );
                }
            }
        }
    }
}

/// The law's loads are the closed form of the old rapier3d study
/// (results/friction_models/rapier3d/load_transfer.csv before d481d53,
/// columns `N*_pred`, printed to 1e-4 N).
#[test]
fn law_loads_are_the_old_closed_form() {
    for (h_cm, h_push, speed, old) in [
        (0.05, 0.05, 0.5, [1.7699, 2.3700, 3.1351, 2.5350]),
        (0.1, 0.1, 1.0, [1.1107, 2.1740, 3.7943, 2.7310]),
    ] {
        let law = model("rapier3d", h_cm, h_push)
            .law()
            .unwrap()
            .loads(&problem(plate(), speed, 4.0), 0, 1e-3)
            .unwrap();
        for (a, b) in law.iter().zip(old) {
            assert!((a - b).abs() < 1e-4, "{law:?} vs {old:?}");
        }
    }
}

/// `cm_height` must be above the floor (the feet hang below it).
#[test]
fn cm_height_on_the_floor_is_refused() {
    let opts = EngineOptions {
        values: [("cm_height".to_string(), serde_json::json!(0.0))]
            .into_iter()
            .collect(),
        ..Default::default()
    };
    let entry = models().into_iter().find(|m| m.name == "rapier3d").unwrap();
    assert_eq!((entry.build)(&opts).err().unwrap().key, "cm_height");
}
