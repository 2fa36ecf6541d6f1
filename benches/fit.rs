//! `pushval fit`'s cost: Levenberg–Marquardt on `mu_scale` and `inertia_cm`
//! against the seed paper's 10 s trajectory (`scenarios/paper-square-v1.0.toml`,
//! five segments, 1001 samples), started from the file's values. Target:
//! under 50 ms per fit.
//!
//! Two data sets: the exact trajectory of the plate with μ × 0.84 and
//! I_cm × 1.2 (the solver walks 16 % and 20 % to the truth), and the file's
//! own trajectory with 1 mm / 1 mrad Gaussian noise (seed 1), started at
//! μ × 0.9 and I_cm × 1.15. Set-up (loading, the data) is outside the timing.
//!
//! `cargo bench --bench fit`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use pushval::fit::{self, noise, Param, Parametrised, Settings};
use pushval_model::{DynamicModel, Simulator};

fn paper() -> pushval_scenario::Scenario {
    let p =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/paper-square-v1.0.toml");
    pushval::registry::load(p).unwrap()
}

fn fit_paper(c: &mut Criterion) {
    let sc = paper();
    let model = Parametrised::new(&sc, &[Param::MuScale, Param::InertiaCm]).unwrap();
    let file = model.file_values();
    let settings = Settings::default();

    let mut moved = sc.clone();
    for s in &mut moved.supports {
        s.mu *= 0.84;
    }
    moved.inertia_cm *= 1.2;
    let exact = DynamicModel::default()
        .simulate(&moved.problem())
        .unwrap()
        .samples;
    let own = DynamicModel::default()
        .simulate(&sc.problem())
        .unwrap()
        .samples;
    let noisy = noise::add_noise(&own, 1e-3, 1e-3, 1);
    // Components in Param::ALL order: inertia_cm, mu_scale.
    let off = vec![file[0] * 1.15, file[1] * 0.9];

    let mut g = c.benchmark_group("fit");
    g.sample_size(50);
    for (name, data, start) in [
        ("exact_mu0.84_I1.2", &exact, &file),
        ("noisy_1mm_1mrad", &noisy, &off),
    ] {
        // One fit outside the timing: it must converge where it should.
        let f = fit::fit(&model, data, start, &settings).unwrap();
        assert!(
            f.converged && f.unidentifiable.is_empty(),
            "{}",
            f.termination
        );
        g.bench_with_input(
            BenchmarkId::new("mu_scale+inertia_cm/paper_10s", name),
            &(data, start),
            |b, (data, start)| b.iter(|| fit::fit(&model, data, start, &settings).unwrap()),
        );
    }
    g.finish();
}

criterion_group!(benches, fit_paper);
criterion_main!(benches);
