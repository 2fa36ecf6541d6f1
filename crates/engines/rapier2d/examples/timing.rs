//! Where an engine run's time goes: rapier's `step()` versus the adapter's
//! own per-step work (friction forces, pusher velocity, reading and recording
//! the state), and the whole run (set-up and sampling included).
//!
//! `cargo run --release -p pushval-rapier --example timing [FILE] [REPEATS]`

use pushval_rapier2d::{
    DetailedEngine, EngineSettings, FrictionVelocity, Precision, RapierSimulator,
};

fn main() {
    let mut args = std::env::args().skip(1);
    let file = args.next().unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../scenarios/paper-square-v1.0.toml"
        )
        .to_string()
    });
    let repeats: usize = args.next().map(|s| s.parse().unwrap()).unwrap_or(20);
    let problem = pushval_scenario::Scenario::from_path(&file)
        .unwrap()
        .problem();
    println!("precision mode steps rapier_us/step adapter_us/step adapter/rapier run/rapier");
    for precision in [Precision::F64, Precision::F32] {
        for mode in FrictionVelocity::ALL {
            let sim = RapierSimulator::new(EngineSettings {
                precision,
                friction_velocity: mode,
                ..Default::default()
            });
            // Warm up, then keep the least disturbed value of each part over
            // the repeats (the machine may be busy).
            let _ = sim.run(&problem).unwrap();
            let runs: Vec<_> = (0..repeats).map(|_| sim.run(&problem).unwrap()).collect();
            let n = runs[0].steps as f64;
            let min = |f: &dyn Fn(&pushval_rapier2d::RapierRun) -> f64| {
                runs.iter().map(f).fold(f64::INFINITY, f64::min)
            };
            let rapier = min(&|r| r.rapier_step_time.as_secs_f64());
            let adapter = min(&|r| (r.stepping_time - r.rapier_step_time).as_secs_f64());
            let other = min(&|r| (r.wall_time - r.rapier_step_time).as_secs_f64());
            println!(
                "{} {:10} {} {:.3} {:.3} {:.1}% {:.1}%",
                precision.as_str(),
                mode.as_str(),
                runs[0].steps,
                rapier * 1e6 / n,
                adapter * 1e6 / n,
                100.0 * adapter / rapier,
                100.0 * other / rapier,
            );
        }
    }
}
