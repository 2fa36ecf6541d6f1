pub mod engine_step;
pub mod model_rhs;
pub mod model_steady;
pub mod model_trajectory;
pub mod rapier_step;
pub mod sweep;
pub mod validate;

use pushval_model::{Body, Support, Vec2};

/// A 0.25 m square plate of 1 kg on `n` supports with equal loads (μ 0.5):
/// the four corners for n = 4, otherwise a deterministic spread over the plate.
pub fn plate(n: usize) -> Body {
    let a = 0.125;
    let pts: Vec<Vec2> = if n == 4 {
        vec![
            Vec2::new(-a, -a),
            Vec2::new(a, -a),
            Vec2::new(a, a),
            Vec2::new(-a, a),
        ]
    } else {
        // A golden-angle spiral: evenly spread, no two points alike.
        (0..n)
            .map(|i| {
                let r = a * ((i as f64 + 0.5) / n as f64).sqrt();
                let t = i as f64 * 2.399_963_229_728_653;
                Vec2::new(r * t.cos(), r * t.sin())
            })
            .collect()
    };
    let f = 0.5 * 9.81 / n as f64;
    let sup: Vec<Support> = pts
        .into_iter()
        .map(|p| Support {
            position: p,
            friction: f,
        })
        .collect();
    Body::new(1.0, 0.25f64.powi(2) / 6.0, Vec2::new(-a, -a), &sup).unwrap()
}

/// The scenario file `scenarios/NAME.toml`.
pub fn scenario(name: &str) -> pushval_scenario::Scenario {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(format!("{name}.toml"));
    pushval_scenario::Scenario::from_path(p).unwrap()
}
