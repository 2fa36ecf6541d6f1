//! `validate` end to end (every model, engine convergence runs included), per scenario.

use criterion::{criterion_group, BenchmarkId, Criterion};
use pushval::{run_scenario, RunOptions};
use std::hint::black_box;

fn validate(c: &mut Criterion) {
    let mut g = c.benchmark_group("validate");
    g.sample_size(10);
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for f in files {
        let sc = pushval_scenario::Scenario::from_path(&f).unwrap();
        g.bench_with_input(BenchmarkId::from_parameter(&sc.name), &sc, |b, sc| {
            b.iter(|| black_box(run_scenario(sc, &RunOptions::default()).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, validate);
