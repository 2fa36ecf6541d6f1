//! Jolt's support loads through the plug-in (the run diagnostics'
//! `"loads"`): they carry the weight, three feet carry statics' loads, and
//! `jolt_box` reports its corners' loads only where the corners are the
//! supports. Jolt's law uses the problem's loads (`FrictionLaw::loads` is
//! None).
#![cfg(feature = "jolt")]

mod common;

use common::*;
use pushval_engine::{tail_loads, Engine, EngineOptions};
use pushval_jolt::models;
use pushval_model::{Body, Support, Vec2};

fn model(name: &str) -> Box<dyn Engine> {
    let entry = models().into_iter().find(|m| m.name == name).unwrap();
    (entry.build)(&EngineOptions::default()).unwrap()
}

/// Three feet around the centre of mass and their statics loads (N) under
/// m g = G (Cramer's rule on `Σ N = W`, `Σ N p = 0`).
const TRIANGLE: [[f64; 2]; 3] = [[-0.1, -0.08], [0.12, -0.06], [-0.01, 0.11]];

fn statics3() -> [f64; 3] {
    let [a, b, c] = TRIANGLE;
    // Areas of the sub-triangles opposite each foot, about the origin.
    let cross = |p: [f64; 2], q: [f64; 2]| p[0] * q[1] - p[1] * q[0];
    let (wa, wb, wc) = (cross(b, c), cross(c, a), cross(a, b));
    let s = wa + wb + wc;
    [G * wa / s, G * wb / s, G * wc / s]
}

fn triangle() -> Body {
    let supports: Vec<Support> = TRIANGLE
        .iter()
        .zip(statics3())
        .map(|(q, n)| Support {
            position: Vec2::new(q[0], q[1]),
            friction: 0.5 * n,
        })
        .collect();
    Body::new(1.0, 0.008, Vec2::new(-0.12, -0.1), &supports).unwrap()
}

/// Both scenes' loads over the run's last fifth sum to m g (within 1e-3 N);
/// three feet carry statics' loads within 2e-2 N (measured 1.2e-2 N);
/// `jolt_box` reports loads on the plate (its corners are the supports) and
/// none on three feet (its corners are not); the law declares none.
#[test]
fn loads_carry_the_weight_and_box_reports_corners_only_on_them() {
    for name in ["jolt_box", "jolt_feet"] {
        let m = model(name);
        for (body, is_triangle) in [(plate(), false), (triangle(), true)] {
            let p = problem(&body, push(0.5, PHI, 2.5));
            let r = m.run(&p, 1e-3).unwrap();
            assert!(m.law().unwrap().loads(&p, 0, 1e-3).is_none());
            let Some(loads) = tail_loads(&r) else {
                assert!(name == "jolt_box" && is_triangle, "{name}: no loads");
                continue;
            };
            assert!(!(name == "jolt_box" && is_triangle), "box on three feet");
            assert_eq!(loads.len(), body.len());
            let sum: f64 = loads.iter().sum();
            assert!((sum - G).abs() < 1e-3, "{name}: Σ N = {sum}");
            if is_triangle {
                for (a, b) in loads.iter().zip(statics3()) {
                    assert!((a - b).abs() < 2e-2, "{name}: {loads:?} vs statics");
                }
            }
        }
    }
}
