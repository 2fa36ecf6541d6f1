//! The dynamic model's cost per call, for a profiler (`valgrind --tool=callgrind`):
//! `paper` runs the 10 s paper trajectory (five segments, 1,001 samples) at
//! the tolerance the work–precision bench picks for 1e-9 m; `short` runs a
//! model-predictive controller's unit of work, a 6-segment horizon from rest
//! at 1 m/s with two samples (its start and end), the problem of
//! `benches/short_horizon` on the same plate. Assumption checks are off in
//! both.
//!
//! `cargo run --release -p pushval-model --example per_call -- paper|short [runs [sample_dt]]`;
//! `NO_SKIP=1` integrates every segment (no series tail), `TOL=…` sets the
//! tolerance, `SEGMENTS=1` prints the solver work and each segment's report,
//! `FINAL=1` asks for the final state alone ([`DynamicModel::final_state`]),
//! `CACHE=1` the same with the pushes' analysis kept between calls
//! ([`DynamicModel::final_state_cached`]; every call after the first finds
//! all its pushes).
use pushval_model::*;

fn plate() -> Body {
    let a = 0.125;
    let sup: Vec<Support> = [(-a, -a), (a, -a), (a, a), (-a, a)]
        .iter()
        .map(|&(x, y)| Support {
            position: Vec2::new(x, y),
            friction: 0.5 * 9.81 / 4.0,
        })
        .collect();
    Body::new(1.0, 0.25f64.powi(2) / 6.0, Vec2::new(-a, -a), &sup).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map_or("paper", String::as_str);
    let runs: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let dt_override: Option<f64> = args.get(3).and_then(|s| s.parse().ok());
    let q = std::f64::consts::FRAC_PI_4;
    let (pushes, sample_dt, tol): (Vec<Push>, f64, f64) = match which {
        "paper" => (
            [q + 0.3, q, q - 0.3, q + 0.5, q + 0.15]
                .iter()
                .map(|&phi| Push {
                    duration: 2.0,
                    speed: 1.0,
                    phi,
                })
                .collect(),
            0.01,
            3.162e-8,
        ),
        _ => (
            [q + 0.3, q, q - 0.3, q + 0.5, q + 0.15, q - 0.1]
                .iter()
                .map(|&phi| Push {
                    duration: 0.1,
                    speed: 1.0,
                    phi,
                })
                .collect(),
            0.6,
            1e-10,
        ),
    };
    let pb = Problem {
        body: plate(),
        limits: ContactLimits::default(),
        pushes,
        // The paper's start moves with the pusher; a horizon starts at rest.
        initial: Initial {
            from_rest: which != "paper",
            ..Default::default()
        },
        switching: Switching::Impulsive,
        sample_dt: dt_override.unwrap_or(sample_dt),
        release: None,
    };
    // `TOL=…` overrides the tolerance.
    let tol = std::env::var("TOL")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(tol);
    let m = DynamicModel {
        integrator: Integrator::Dop853 { tol },
        check_assumptions: false,
        skip_settled: std::env::var_os("NO_SKIP").is_none(),
        ..Default::default()
    };
    let mut evals = 0;
    let mut last = 0.0;
    let t0 = std::time::Instant::now();
    let final_only = std::env::var_os("FINAL").is_some();
    let mut cache = std::env::var_os("CACHE").map(|_| PushCache::new());
    for _ in 0..runs {
        if let Some(cache) = cache.as_mut() {
            let end = m
                .final_state_cached(std::hint::black_box(&pb), cache)
                .unwrap();
            (evals, last) = (end.stats.rhs_evals, end.x);
        } else if final_only {
            let end = m.final_state(std::hint::black_box(&pb)).unwrap();
            (evals, last) = (end.stats.rhs_evals, end.x);
        } else {
            let tr = m.simulate(std::hint::black_box(&pb)).unwrap();
            evals = tr.stats.rhs_evals;
            last = tr.samples.last().map_or(0.0, |s| s.x);
        }
    }
    let per = t0.elapsed().as_secs_f64() / runs as f64;
    if std::env::var_os("SEGMENTS").is_some() {
        let tr = m.simulate(&pb).unwrap();
        println!("{:?}", tr.stats);
        for r in &tr.segments {
            println!("{r:?}");
        }
    }
    println!(
        "{which}: {runs} runs, {evals} rhs evaluations per run, {:.2} us per run (wall), last x {last}",
        per * 1e6
    );
}
