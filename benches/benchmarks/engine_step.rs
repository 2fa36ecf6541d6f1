//! Every engine model in this build, through the registry and the `Engine`
//! trait: a 1 s, one-segment run of the paper plate at dt = 1e-3 (1000
//! steps), so criterion's per-element time is the cost of one engine step
//! with pushval's per-step work (friction forces, pusher, recording).

use criterion::{criterion_group, BenchmarkId, Criterion, Throughput};
use pushval_model::{Initial, Problem, Push, Switching};
use std::hint::black_box;

fn engine_step(c: &mut Criterion) {
    let problem = Problem {
        body: super::plate(4),
        limits: Default::default(),
        pushes: vec![Push {
            duration: 1.0,
            speed: 1.0,
            phi: 1.0854,
        }],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    };
    let mut g = c.benchmark_group("engine_step");
    g.throughput(Throughput::Elements(1000));
    for entry in pushval::registry::entries() {
        let engine = entry.default_engine();
        if engine.availability().is_err() {
            continue;
        }
        g.bench_with_input(BenchmarkId::from_parameter(entry.name), &engine, |b, e| {
            b.iter(|| black_box(e.run(&problem, 1e-3).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, engine_step);
