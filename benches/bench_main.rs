//! pushval's criterion benches: one file per subject in `benchmarks/`.
//!
//! `cargo bench --bench bench_main` runs them all; `-- model_rhs` one subject.

mod benchmarks;

criterion::criterion_main!(
    benchmarks::engine_step::benches,
    benchmarks::model_rhs::benches,
    benchmarks::model_steady::benches,
    benchmarks::model_trajectory::benches,
    benchmarks::rapier_step::benches,
    benchmarks::sweep::benches,
    benchmarks::validate::benches,
);
