//! A 100 × 100 (Fr, φ) steady-state map of the paper plate: every root of ω̇
//! with its stability and τ per cell, on 1 and 2 threads.

use criterion::{criterion_group, BenchmarkId, Criterion, Throughput};
use pushval_model::{Push, SegmentDynamics, SteadyState};
use rayon::prelude::*;
use std::hint::black_box;

/// The map: Fr from 1e-3 to 10 (log), φ across the corner's inward cone.
pub fn steady_map(body: &pushval_model::Body, n: usize) -> Vec<Vec<SteadyState>> {
    let l = body.contact().norm();
    let mu_g = body.total_friction() / body.mass();
    (0..n * n)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k / n, k % n);
            let fr = 10f64.powf(-3.0 + 4.0 * i as f64 / (n - 1) as f64);
            let phi = 0.05 + (std::f64::consts::FRAC_PI_2 - 0.1) * j as f64 / (n - 1) as f64;
            let speed = (fr * mu_g * l).sqrt();
            SegmentDynamics::new(
                body,
                &Push {
                    duration: 1.0,
                    speed,
                    phi,
                },
            )
            .steady_states()
        })
        .collect()
}

fn sweep(c: &mut Criterion) {
    let body = super::plate(4);
    let mut g = c.benchmark_group("sweep_steady_map");
    g.sample_size(10);
    g.throughput(Throughput::Elements(10_000));
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        g.bench_with_input(BenchmarkId::new("threads", threads), &threads, |b, _| {
            b.iter(|| pool.install(|| black_box(steady_map(&body, 100))))
        });
    }
    g.finish();
}

criterion_group!(benches, sweep);
