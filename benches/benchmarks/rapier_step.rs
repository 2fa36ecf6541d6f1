//! The rapier2d pusher scene: a 1 s, one-segment run at dt = 1e-3 (1000 steps),
//! by precision and friction-velocity mode; and, beside the default scene
//! (no colliders: friction is applied as forces, rapier's broad and narrow
//! phases have nothing to do), the same run with massless, non-interacting
//! colliders on the object and the pusher (`EngineSettings::colliders`), to
//! measure what skipping the collision stages saves. Adapter-specific on
//! purpose (precision, friction-velocity modes, colliders and the split of
//! the time between rapier's step and the adapter are not in the `Engine`
//! trait); `engine_step` times every engine through the trait.

use criterion::{criterion_group, BenchmarkId, Criterion, Throughput};
use pushval_model::{Initial, Problem, Push, Switching};
use pushval_rapier2d::{
    DetailedEngine, EngineSettings, FrictionVelocity, Precision, RapierSimulator,
};
use std::hint::black_box;

fn rapier_step(c: &mut Criterion) {
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
    let mut g = c.benchmark_group("rapier_step");
    g.throughput(Throughput::Elements(1000));
    for precision in [Precision::F64, Precision::F32] {
        for mode in FrictionVelocity::ALL {
            let settings = EngineSettings {
                precision,
                friction_velocity: mode,
                ..Default::default()
            };
            let sim = RapierSimulator { settings };
            g.bench_with_input(
                BenchmarkId::new(precision.as_str(), mode.as_str()),
                &sim,
                |b, sim| b.iter(|| black_box(sim.run(&problem).unwrap())),
            );
        }
    }
    // Default settings (f64, leapfrog) without and with colliders, side by
    // side: the ratio of the two medians is the cost of the collision stages.
    for colliders in [false, true] {
        let sim = RapierSimulator::new(EngineSettings {
            colliders,
            ..Default::default()
        });
        let name = if colliders { "with" } else { "without" };
        g.bench_with_input(BenchmarkId::new("colliders", name), &sim, |b, sim| {
            b.iter(|| black_box(sim.run(&problem).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, rapier_step);
