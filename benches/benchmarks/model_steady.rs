//! The steady states (every root of ω̇ with its stability and τ).

use criterion::{criterion_group, BenchmarkId, Criterion};
use pushval_model::{Push, SegmentDynamics};
use std::hint::black_box;

fn model_steady(c: &mut Criterion) {
    let mut g = c.benchmark_group("model_steady");
    for (label, phi) in [("stable_pi4+0.3", 1.0854), ("three_roots_phi-2.6_v4", -2.6)] {
        let body = super::plate(4);
        let speed = if phi < 0.0 { 4.0 } else { 1.0 };
        let seg = SegmentDynamics::new(
            &body,
            &Push {
                duration: 1.0,
                speed,
                phi,
            },
        );
        g.bench_with_input(BenchmarkId::new("plate4", label), &seg, |b, seg| {
            b.iter(|| black_box(seg.steady_states()))
        });
    }
    let body = super::plate(1024);
    let seg = SegmentDynamics::new(
        &body,
        &Push {
            duration: 1.0,
            speed: 1.0,
            phi: 1.0854,
        },
    );
    g.bench_with_input(
        BenchmarkId::new("plate1024", "stable_pi4+0.3"),
        &seg,
        |b, seg| b.iter(|| black_box(seg.steady_states())),
    );
    g.finish();
}

criterion_group!(benches, model_steady);
