//! `model_short_horizon`: one dynamic-model run of the model-predictive
//! controller's horizon (6 segments from rest, assumption checks off;
//! `short_horizon/mod.rs`), the fixed cost every control period pays per
//! prediction: sampled at its start and end (`model_short_horizon`), asked
//! for the final state alone (`model_short_horizon/final_state`), and that
//! at the predictor's tolerance (`model_short_horizon/final_state_predictor_tol`);
//! then the predictor's call with the pushes' analysis kept between calls
//! (`PushCache`): all six pushes seen before (`…/cached_repeat`), and per
//! call over a finite-difference Jacobian's calls as the planner makes
//! them (the plan, then each direction moved in turn, then every duration
//! scaled; `…/jacobian_calls` from a fresh cache, against the same calls
//! without one, `…/jacobian_calls_uncached`).
//!
//! `cargo bench --bench model_short_horizon`

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use pushval_model::{Problem, PushCache, Simulator};

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
    let mut cache = PushCache::new();
    let end = predictor.final_state(&problem).unwrap();
    assert_eq!(
        predictor.final_state_cached(&problem, &mut cache).unwrap(),
        end
    );
    c.bench_function(
        "model_short_horizon/final_state_predictor_tol/cached_repeat",
        |b| {
            b.iter(|| {
                black_box(
                    predictor
                        .final_state_cached(black_box(&problem), &mut cache)
                        .unwrap(),
                )
            })
        },
    );
    let calls = jacobian_calls(&problem);
    // Each iteration is one call: a Jacobian's time over its calls.
    let n = calls.len() as u32;
    c.bench_function(
        "model_short_horizon/final_state_predictor_tol/jacobian_calls",
        |b| {
            b.iter_custom(|iters| {
                let t0 = std::time::Instant::now();
                for _ in 0..iters {
                    let mut cache = PushCache::new();
                    for p in &calls {
                        black_box(
                            predictor
                                .final_state_cached(black_box(p), &mut cache)
                                .unwrap(),
                        );
                    }
                }
                t0.elapsed() / n
            })
        },
    );
    c.bench_function(
        "model_short_horizon/final_state_predictor_tol/jacobian_calls_uncached",
        |b| {
            b.iter_custom(|iters| {
                let t0 = std::time::Instant::now();
                for _ in 0..iters {
                    for p in &calls {
                        black_box(predictor.final_state(black_box(p)).unwrap());
                    }
                }
                t0.elapsed() / n
            })
        },
    );
}

/// The calls of a finite-difference Jacobian as the planner makes them
/// (`crates/control/src/plan.rs`): the plan itself, each push's direction
/// moved by 1e-6 in turn, then every duration scaled by 1 + 1e-6.
fn jacobian_calls(problem: &Problem) -> Vec<Problem> {
    let mut calls = vec![problem.clone()];
    for k in 0..problem.pushes.len() {
        let mut p = problem.clone();
        p.pushes[k].phi += 1e-6;
        calls.push(p);
    }
    let mut p = problem.clone();
    p.pushes.iter_mut().for_each(|q| q.duration *= 1.0 + 1e-6);
    p.sample_dt = p.duration();
    calls.push(p);
    calls
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = model_short_horizon
}
criterion_main!(benches);
