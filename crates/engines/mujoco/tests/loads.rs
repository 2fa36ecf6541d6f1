//! The feet's loads: what MuJoCo measures (the run diagnostics' `"loads"`)
//! against statics and the elliptic model's law (`FrictionLaw::loads`, the
//! tilting balance of `pushval_mujoco::theory`). Expected values come from
//! statics solved here by hand and from the law's closed form.
#![cfg(feature = "mujoco")]

mod common;

use common::*;
use pushval_engine::{tail_loads, tail_mean_omega, Engine, EngineOptions, EngineRun};
use pushval_model::{Body, Problem, Support, Vec2};
use pushval_mujoco::models;

fn model(name: &str, options: serde_json::Value) -> Box<dyn Engine> {
    let opts = EngineOptions {
        values: serde_json::from_value(options).unwrap(),
        ..Default::default()
    };
    let entry = models().into_iter().find(|m| m.name == name).unwrap();
    (entry.build)(&opts).unwrap()
}

fn elliptic(h_cm: f64, h_push: f64) -> Box<dyn Engine> {
    model(
        "mujoco_elliptic",
        serde_json::json!({"cm_height": h_cm, "push_height": h_push}),
    )
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

fn triangle() -> Body {
    let rest = statics3(G, [0.0, 0.0]);
    let supports: Vec<Support> = TRIANGLE
        .iter()
        .zip(rest)
        .map(|(p, n)| Support {
            position: Vec2::new(p[0], p[1]),
            friction: MU * n,
        })
        .collect();
    Body::new(1.0, 0.008, Vec2::new(-0.12, -0.1), &supports).unwrap()
}

/// `(Σ N, Σ N x, Σ N y)` (N, N m) of loads on `body`'s supports.
fn resultant(body: &Body, loads: &[f64]) -> [f64; 3] {
    body.supports().zip(loads).fold([0.0; 3], |a, (s, n)| {
        [a[0] + n, a[1] + n * s.position.x, a[2] + n * s.position.y]
    })
}

fn run(m: &dyn Engine, p: &Problem) -> (EngineRun, Vec<f64>, Vec<f64>) {
    let r = m.run(p, 1e-3).unwrap();
    let measured = tail_loads(&r).unwrap();
    let law = m.law().unwrap().loads(p, 0, 1e-3).unwrap();
    (r, measured, law)
}

/// At both heights 0 the law's loads are the rest loads: statics for three
/// feet, a quarter of the weight on each foot of the square plate.
#[test]
fn law_loads_at_the_floor_are_the_rest_loads() {
    let m = elliptic(0.0, 0.0);
    let law = m.law().unwrap();
    let t = problem(&triangle(), 0.5, paper_phi(), 4.0);
    let loads = law.loads(&t, 0, 1e-3).unwrap();
    for (n, e) in loads.iter().zip(statics3(G, [0.0, 0.0])) {
        assert!((n - e).abs() < 1e-9, "{loads:?}");
    }
    // μ_i N_i = F_i: the problem's friction at rest.
    for (n, s) in loads.iter().zip(t.body.supports()) {
        assert!((MU * n - s.friction).abs() < 1e-9);
    }
    let p = problem(&plate(), 0.5, paper_phi(), 4.0);
    for n in law.loads(&p, 0, 1e-3).unwrap() {
        assert!((n - G / 4.0).abs() < 1e-9);
    }
    // And ω is the Coulomb model's.
    let w = law.steady(&p, 0, 1e-3).unwrap().omega;
    assert!((w - pushval_engine::coulomb_steady(&p, 0).unwrap()).abs() < 1e-12);
}

/// Raised centre of mass or pusher, three feet (statics fixes every load):
/// MuJoCo's loads over the run's last fifth match the law's foot by foot
/// within 0.06 N (measured: at most 0.044 N, at h_cm = 0.05 m and v = 1
/// m/s; the loads move by up to 2.6 N), and sum to m g within 1 % (measured
/// ≤ 0.5 %). The law's loads satisfy the vertical balance exactly.
#[test]
fn three_feet_carry_the_loads_of_the_tilting_balance() {
    let body = triangle();
    for (h_cm, h_push) in [(0.0, 0.0), (0.05, 0.0), (0.05, 0.05), (0.05, 0.1)] {
        for speed in [0.5, 1.0] {
            let m = elliptic(h_cm, h_push);
            let p = problem(&body, speed, paper_phi(), 4.0);
            let (_, measured, law) = run(m.as_ref(), &p);
            let sum: f64 = measured.iter().sum();
            assert!((sum - G).abs() < 0.01 * G, "Σ N = {sum}");
            assert!((law.iter().sum::<f64>() - G).abs() < 1e-9 * G);
            for (a, b) in measured.iter().zip(&law) {
                assert!(
                    (a - b).abs() < 0.06,
                    "h_cm {h_cm} h_push {h_push} v {speed}: MuJoCo {measured:?}, law {law:?}"
                );
            }
        }
    }
    // The transfer is large enough to be seen: foot 0 loses 2.6 N.
    let p = problem(&body, 0.5, paper_phi(), 4.0);
    let law = elliptic(0.05, 0.1)
        .law()
        .unwrap()
        .loads(&p, 0, 1e-3)
        .unwrap();
    assert!(statics3(G, [0.0, 0.0])[0] - law[0] > 2.5, "{law:?}");
}

/// Four feet on the square plate are statically indeterminate: MuJoCo's
/// solver picks its own split. What statics fixes — the total and the first
/// moment `Σ N p` — matches the law within 0.008 N m (measured ≤ 0.0058 N m,
/// the moment reaches 0.38 N m); the total is m g within 2.5 % (measured
/// ≤ 2.3 %: the plate's contacts chatter more). The remaining mode,
/// `(N₀ − N₁ + N₂ − N₃)/4`, is MuJoCo's choice (0.05 to 0.55 N here; the
/// law's least-norm split has 0): only its existence is asserted.
#[test]
fn four_feet_match_the_law_in_what_statics_fixes() {
    let body = plate();
    let mut largest_twist = 0.0f64;
    for (h_cm, h_push) in [(0.0, 0.0), (0.05, 0.0), (0.05, 0.05), (0.05, 0.1)] {
        for speed in [0.5, 1.0] {
            let m = elliptic(h_cm, h_push);
            let p = problem(&body, speed, paper_phi(), 4.0);
            let (_, measured, law) = run(m.as_ref(), &p);
            let (a, b) = (resultant(&body, &measured), resultant(&body, &law));
            assert!((a[0] - G).abs() < 0.025 * G, "Σ N = {}", a[0]);
            assert!((b[0] - G).abs() < 1e-9 * G);
            for k in 1..3 {
                assert!(
                    (a[k] - b[k]).abs() < 0.008,
                    "h_cm {h_cm} h_push {h_push} v {speed}: Σ N p MuJoCo {a:?}, law {b:?}"
                );
            }
            let twist = (measured[0] - measured[1] + measured[2] - measured[3]) / 4.0;
            largest_twist = largest_twist.max(twist.abs());
        }
    }
    assert!(
        largest_twist > 0.1,
        "MuJoCo split the plate's weight evenly"
    );
}

/// `cm_height` and `push_height` reach the settings and the law; a bad value
/// is an error naming its key.
#[test]
fn height_options() {
    let m = elliptic(0.03, 0.07);
    assert!(m.option_keys().contains(&"cm_height"));
    assert!(m.option_keys().contains(&"push_height"));
    let s = m.settings(1e-3);
    assert_eq!(s["cm_height"], 0.03);
    assert_eq!(s["push_height"], 0.07);
    for key in ["cm_height", "push_height"] {
        for bad in [serde_json::json!(-0.01), serde_json::json!("high")] {
            let opts = EngineOptions {
                values: [(key.to_string(), bad)].into_iter().collect(),
                ..Default::default()
            };
            let entry = models()
                .into_iter()
                .find(|m| m.name == "mujoco_elliptic")
                .unwrap();
            let err = (entry.build)(&opts).err().unwrap();
            assert_eq!(err.key, key);
        }
    }
    // The pyramidal cone declares no law, raised or not.
    assert!(
        model("mujoco_pyramidal", serde_json::json!({"cm_height": 0.05}))
            .law()
            .is_none()
    );
}

/// The law's steady ω with load transfer is the closed form of the old
/// MuJoCo study (results/friction_models/mujoco/load_transfer.csv before
/// d481d53, column `omega_load_transfer`), and MuJoCo's ω follows it within
/// 3 % (measured 2.1 % at h_cm = 0.05 m, h_push = 0, 2.5 % at 0.05/0.05).
#[test]
fn raised_law_omega_is_the_old_closed_form() {
    let body = plate();
    for (h_cm, h_push, speed, old) in [
        (0.05, 0.05, 0.5, -0.442642),
        (0.05, 0.0, 1.0, -0.612334),
        (0.05, 0.1, 0.5, -0.432165),
    ] {
        let m = elliptic(h_cm, h_push);
        let p = problem(&body, speed, paper_phi(), 4.0);
        let law = m.law().unwrap().steady(&p, 0, 1e-3).unwrap().omega;
        assert!((law - old).abs() < 2e-6, "{law} vs {old}");
    }
    for (h_cm, h_push) in [(0.05, 0.0), (0.05, 0.05)] {
        let m = elliptic(h_cm, h_push);
        let p = problem(&body, 1.0, paper_phi(), 4.0);
        let r = m.run(&p, 1e-3).unwrap();
        let w = tail_mean_omega(&p, &r.trajectory, 0.2)[0].unwrap();
        let law = m.law().unwrap().steady(&p, 0, 1e-3).unwrap().omega;
        assert!((w - law).abs() < 0.03 * law.abs(), "MuJoCo {w}, law {law}");
    }
}
