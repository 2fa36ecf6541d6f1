//! `model_short_horizon`: one dynamic-model run of the model-predictive
//! controller's horizon (6 segments from rest, assumption checks off;
//! `short_horizon/mod.rs`), the fixed cost every control period pays per
//! prediction: sampled at its start and end (`model_short_horizon`), asked
//! for the final state alone (`model_short_horizon/final_state`), and that
//! at the predictor's tolerance (`model_short_horizon/final_state_predictor_tol`).
//!
//! `cargo bench --bench model_short_horizon`

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use pushval_model::Simulator;

mod short_horizon;

fn model_short_horizon(c: &mut Criterion) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let problem = short_horizon::problem(root);
    let model = short_horizon::model();
    let tr = model.simulate(&problem).unwrap();
    assert_eq!(tr.samples.len(), 2);
    assert_eq!(tr.segments.len(), short_horizon::SEGMENTS);
    c.bench_function("model_short_horizon", |b| {
        b.iter(|| black_box(model.simulate(black_box(&problem)).unwrap()))
    });
    c.bench_function("model_short_horizon/final_state", |b| {
        b.iter(|| black_box(model.final_state(black_box(&problem)).unwrap()))
    });
    let predictor = short_horizon::predictor();
    c.bench_function("model_short_horizon/final_state_predictor_tol", |b| {
        b.iter(|| black_box(predictor.final_state(black_box(&problem)).unwrap()))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = model_short_horizon
}
criterion_main!(benches);
