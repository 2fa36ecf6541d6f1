//! Error over time of one rapier run against the dynamic model, for one
//! scenario file (diagnostics).
//! `cargo run --release -p pushval-rapier --example trace FILE DT MODE [EVERY]`
use pushval_model::{DynamicModel, Simulator};
use pushval_rapier2d::{DetailedEngine, EngineSettings, FrictionVelocity, RapierSimulator};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let problem = pushval_scenario::Scenario::from_path(&a[1])
        .unwrap()
        .problem();
    let dt: f64 = a[2].parse().unwrap();
    let mode = FrictionVelocity::ALL
        .into_iter()
        .find(|m| m.as_str() == a[3])
        .unwrap();
    let every: usize = a.get(4).map(|s| s.parse().unwrap()).unwrap_or(10);
    let r = DynamicModel::default().simulate(&problem).unwrap();
    let e = RapierSimulator::new(EngineSettings {
        dt,
        friction_velocity: mode,
        ..Default::default()
    })
    .run(&problem)
    .unwrap();
    for (i, (a, b)) in e.trajectory.samples.iter().zip(&r.samples).enumerate() {
        if i % every == 0 {
            println!(
                "t={:6.3} dx={:+.3e} dy={:+.3e} th_err={:+.3e} w={:+.6} w_err={:+.3e}",
                a.t,
                a.x - b.x,
                a.y - b.y,
                a.theta - b.theta,
                a.omega,
                a.omega - b.omega
            );
        }
    }
}
