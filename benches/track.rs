//! `pushval track`'s cost per sample: one extended Kalman filter update
//! (prediction over the sample interval, three scalar corrections, the
//! lack-of-fit window) on the seed paper's 1 m/s push
//! (`scenarios/paper-square-v1.0.toml`) with 1 mm / 1 mrad noise, at sample
//! rates of 30 Hz, 100 Hz and 1 kHz, and the same plus the resultant
//! friction force. Target: ≤ 5 µs per update at 1 kHz. The filter and the
//! data are built outside the timing; each iteration takes the next sample
//! (the filter restarts when the push ends).
//!
//! `cargo bench --bench track` (results/track_cost.csv has the same
//! measurement as thread CPU time, median and 99th percentile).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use pushval::fit::noise;
use pushval_model::track::{Ekf, EkfSettings, Estimator, Free, Measurement};
use pushval_model::{DynamicModel, Simulator};

fn track_update(c: &mut Criterion) {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/paper-square-v1.0.toml");
    let sc = pushval::registry::load(path).unwrap();
    let mut group = c.benchmark_group("track_update");
    for rate in [30.0, 100.0, 1000.0] {
        let mut s = sc.clone();
        s.sample_dt = 1.0 / rate;
        let exact = DynamicModel::default()
            .simulate(&s.problem())
            .unwrap()
            .samples;
        let data: Vec<Measurement> = noise::add_noise(&exact, 1e-3, 1e-3, 1)
            .iter()
            .map(|p| Measurement {
                t: p.t,
                x: p.x,
                y: p.y,
                theta: p.theta,
                omega: None,
                force: None,
            })
            .collect();
        let model = pushval::track::track_model(&s).unwrap();
        let fresh = || Ekf::new(model.clone(), Free::default(), EkfSettings::default(), None);
        for with_resultant in [false, true] {
            let name = if with_resultant {
                "ekf_and_resultant"
            } else {
                "ekf"
            };
            let mut ekf = fresh();
            let mut k = 0;
            group.bench_function(BenchmarkId::new(name, format!("{rate} Hz")), |b| {
                b.iter(|| {
                    if k == data.len() {
                        ekf = fresh();
                        k = 0;
                    }
                    ekf.update(&data[k]).unwrap();
                    k += 1;
                    if with_resultant {
                        std::hint::black_box(ekf.resultant());
                    }
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, track_update);
criterion_main!(benches);
