//! ω̇(ω): the dynamic model's right-hand side, by number of supports.

use criterion::{criterion_group, BenchmarkId, Criterion, Throughput};
use pushval_model::{Push, SegmentDynamics};
use std::hint::black_box;

fn model_rhs(c: &mut Criterion) {
    let mut g = c.benchmark_group("model_rhs");
    for n in [3usize, 4, 64, 1024, 16384] {
        let body = super::plate(n);
        let seg = SegmentDynamics::new(
            &body,
            &Push {
                duration: 1.0,
                speed: 1.0,
                phi: 1.0854,
            },
        );
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &seg, |b, seg| {
            let mut w = -0.6;
            b.iter(|| {
                w += 1e-9;
                black_box(seg.omega_dot(black_box(w)))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, model_rhs);
