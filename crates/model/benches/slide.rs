//! The free slide to rest (`slide_to_rest`): the seed plate (0.25 m, 1 kg,
//! four corners, μ 0.5) thrown as a push at 1 m/s leaves it (1 m/s, turning
//! 2.3–3.5 rad/s), an uneven five-support plate, and a plate that ends
//! pivoting about its heavy foot; final state only (the controller's
//! question) and sampled every 0.01 s.
//!
//! `cargo bench -p pushval-model --bench slide`; times are the thread's
//! CPU time (the machine is shared).

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use pushval_model::{slide_to_rest, Body, SlideOptions, SlideState, Support, Vec2};
use std::hint::black_box;

/// The calling thread's CPU time (ns) as criterion's measurement, shown in
/// criterion's time units: a shared machine's load does not enter it.
struct ThreadCpu(WallTime);

fn cpu_ns() -> f64 {
    let ts = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    ts.tv_sec as f64 * 1e9 + ts.tv_nsec as f64
}

impl Measurement for ThreadCpu {
    type Intermediate = f64;
    type Value = f64;
    fn start(&self) -> f64 {
        cpu_ns()
    }
    fn end(&self, start: f64) -> f64 {
        cpu_ns() - start
    }
    fn add(&self, a: &f64, b: &f64) -> f64 {
        a + b
    }
    fn zero(&self) -> f64 {
        0.0
    }
    fn to_f64(&self, v: &f64) -> f64 {
        *v
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        self.0.formatter()
    }
}

fn body(m: f64, inertia: f64, sup: &[(f64, f64, f64)]) -> Body {
    let s: Vec<Support> = sup
        .iter()
        .map(|&(x, y, f)| Support {
            position: Vec2::new(x, y),
            friction: f,
        })
        .collect();
    Body::new(m, inertia, Vec2::new(-0.125, -0.125), &s).unwrap()
}

fn throw(vx: f64, vy: f64, omega: f64) -> SlideState {
    SlideState {
        t: 0.0,
        x: 0.0,
        y: 0.0,
        theta: 0.4,
        vx,
        vy,
        omega,
    }
}

fn slide(c: &mut Criterion<ThreadCpu>) {
    let a = 0.125;
    let f = 0.5 * 9.81 / 4.0;
    let seed = body(
        1.0,
        (2.0 * a) * (2.0 * a) / 6.0,
        &[(a, a, f), (-a, a, f), (-a, -a, f), (a, -a, f)],
    );
    let uneven = body(
        1.3,
        0.011,
        &[
            (0.12, 0.08, 2.0),
            (-0.1, 0.09, 0.9),
            (-0.11, -0.07, 1.6),
            (0.09, -0.1, 0.4),
            (0.02, 0.01, 1.1),
        ],
    );
    let heavy_foot = body(
        1.0,
        (2.0 * a) * (2.0 * a) / 6.0,
        &[(a, a, 3.0), (-a, a, 0.5), (-a, -a, 0.5), (a, -a, 0.5)],
    );
    let cases = [
        ("seed_1ms_2.3rads", &seed, throw(0.8, 0.6, 2.3)),
        ("seed_1ms_3.5rads", &seed, throw(0.6, -0.8, -3.5)),
        ("seed_0.5ms_1rads", &seed, throw(0.5, 0.0, 1.0)),
        ("uneven_1ms_3rads", &uneven, throw(1.0, 0.2, 3.0)),
        ("heavy_foot_1ms_3rads", &heavy_foot, throw(0.8, 0.6, 3.0)),
    ];
    let mut g = c.benchmark_group("slide");
    for (name, b, start) in &cases {
        let sl = slide_to_rest(b, start, &SlideOptions::default()).unwrap();
        eprintln!(
            "{name}: stop {:.6} s, {} steps, {} rejected, {} rhs, {} pivots",
            sl.stop.unwrap(),
            sl.steps,
            sl.rejected,
            sl.rhs_evals,
            sl.pivots.len()
        );
        g.bench_with_input(BenchmarkId::new("to_rest", name), start, |bch, st| {
            bch.iter(|| black_box(slide_to_rest(b, st, &SlideOptions::default()).unwrap()))
        });
        let stop = sl.stop.unwrap();
        let times: Vec<f64> = (0..)
            .map(|k| k as f64 * 0.01)
            .take_while(|&t| t <= stop)
            .collect();
        let opts = SlideOptions {
            sample_times: &times,
            ..Default::default()
        };
        g.bench_with_input(BenchmarkId::new("sampled_10ms", name), start, |bch, st| {
            bch.iter(|| black_box(slide_to_rest(b, st, &opts).unwrap()))
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpu(WallTime));
    targets = slide
}
criterion_main!(benches);
