//! The whole 10 s paper trajectory (1 m/s, five segments) by integrator and tolerance.

use criterion::{criterion_group, BenchmarkId, Criterion};
use pushval_model::{DynamicModel, Integrator, Simulator};
use std::hint::black_box;

fn model_trajectory(c: &mut Criterion) {
    let problem = super::scenario("paper-square-v1.0").problem();
    let mut g = c.benchmark_group("model_trajectory");
    for tol in [1e-6, 1e-9, 1e-12] {
        let m = DynamicModel {
            integrator: Integrator::Adaptive { tol },
            ..Default::default()
        };
        g.bench_with_input(
            BenchmarkId::new("adaptive", format!("{tol:e}")),
            &m,
            |b, m| b.iter(|| black_box(m.simulate(&problem).unwrap())),
        );
        let m = DynamicModel {
            integrator: Integrator::Adaptive { tol },
            skip_settled: false,
            ..Default::default()
        };
        g.bench_with_input(
            BenchmarkId::new("adaptive_no_skip", format!("{tol:e}")),
            &m,
            |b, m| b.iter(|| black_box(m.simulate(&problem).unwrap())),
        );
    }
    // The skips, measured: the settled-arc shortcut (above, `adaptive_no_skip`)
    // and the per-sample pusher-force and assumption work.
    for (label, check) in [("with_checks", true), ("without_checks", false)] {
        let m = DynamicModel {
            check_assumptions: check,
            ..Default::default()
        };
        g.bench_with_input(BenchmarkId::new("dop853_default", label), &m, |b, m| {
            b.iter(|| black_box(m.simulate(&problem).unwrap()))
        });
    }
    for tol in [1e-6, 1e-9, 1e-12] {
        let m = DynamicModel {
            integrator: Integrator::Dop853 { tol },
            ..Default::default()
        };
        g.bench_with_input(
            BenchmarkId::new("dop853", format!("{tol:e}")),
            &m,
            |b, m| b.iter(|| black_box(m.simulate(&problem).unwrap())),
        );
    }
    for dt in [1e-2, 1e-3] {
        let m = DynamicModel {
            integrator: Integrator::Rk4 { dt },
            skip_settled: false,
            ..Default::default()
        };
        g.bench_with_input(BenchmarkId::new("rk4", format!("{dt:e}")), &m, |b, m| {
            b.iter(|| black_box(m.simulate(&problem).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, model_trajectory);
