//! Error of the rapier run against the analytic dynamic model, versus dt, for
//! every friction-velocity mode and precision, on the square plate pushed at a
//! corner (1 s at φ = π/4, then 3 s at φ = π/4 + 0.3, 1 m/s).
//!
//! `cargo run --release -p pushval-rapier --example sweep [speed]`

use std::f64::consts::FRAC_PI_4;

use pushval_model::{
    Body, DynamicModel, Initial, Problem, Push, Simulator, Support, Switching, Vec2,
};
use pushval_rapier2d::{
    tail_mean_omega, DetailedEngine, EngineSettings, FrictionVelocity, Precision, RapierSimulator,
};

fn plate(speed: f64, from_rest: bool) -> Problem {
    let (m, a, mu, g) = (1.0, 0.25, 0.5, 9.81);
    let h = a / 2.0;
    let corners = [[-h, -h], [h, -h], [h, h], [-h, h]];
    let supports: Vec<Support> = corners
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: mu * m * g / 4.0,
        })
        .collect();
    let body = Body::new(m, m * (a * a + a * a) / 12.0, Vec2::new(-h, -h), &supports).unwrap();
    Problem {
        body,
        limits: Default::default(),
        pushes: vec![
            Push {
                duration: 1.0,
                speed,
                phi: FRAC_PI_4,
            },
            Push {
                duration: 3.0,
                speed,
                phi: FRAC_PI_4 + 0.3,
            },
        ],
        initial: Initial {
            from_rest,
            ..Default::default()
        },
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

fn main() {
    let speed: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1.0);
    let from_rest = std::env::args()
        .nth(2)
        .map(|s| s == "rest")
        .unwrap_or(false);
    let frac: f64 = std::env::args()
        .nth(3)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1e-3);
    let iters: usize = std::env::args()
        .nth(4)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1);
    let problem = plate(speed, from_rest);
    let reference = DynamicModel::default().simulate(&problem).unwrap();
    let ref_tail = tail_mean_omega(&problem, &reference, 0.2);
    println!("reference tail omega {:?}", ref_tail);
    println!("precision mode dt steps pos_max theta_max omega_rel(seg0,seg1) drift us/step ms/run");
    for precision in [Precision::F64, Precision::F32] {
        for mode in FrictionVelocity::ALL {
            let mut prev: Option<f64> = None;
            for dt in [1e-2, 5e-3, 2.5e-3, 1e-3, 5e-4, 2.5e-4] {
                let sim = RapierSimulator::new(EngineSettings {
                    dt,
                    precision,
                    friction_velocity: mode,
                    switch_step_fraction: frac,
                    solver_iterations: iters,
                    pgs_iterations: std::env::var("PV_PGS")
                        .ok()
                        .and_then(|s| s.parse().ok())
                        .unwrap_or(1),
                    ..Default::default()
                });
                let run = sim.run(&problem).unwrap();
                let (mut pmax, mut tmax) = (0.0f64, 0.0f64);
                for (a, b) in run.trajectory.samples.iter().zip(&reference.samples) {
                    pmax = pmax.max(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt());
                    tmax = tmax.max((a.theta - b.theta).abs());
                }
                let rel: Vec<String> = run
                    .segment_tail_omega
                    .iter()
                    .zip(&ref_tail)
                    .map(|(w, r)| format!("{:.2e}", ((w - r.unwrap()) / r.unwrap()).abs()))
                    .collect();
                let order = prev.map(|p| (p / pmax).log2() / (dt_ratio(dt)).log2());
                prev = Some(pmax);
                println!(
                    "{} {:10} {:7.1e} {:6} {:.2e} {:.2e} [{}] {:.1e} {:.2} {:.1}  order {}",
                    precision.as_str(),
                    mode.as_str(),
                    dt,
                    run.steps,
                    pmax,
                    tmax,
                    rel.join(","),
                    run.max_joint_drift,
                    run.wall_time.as_secs_f64() * 1e6 / run.steps as f64,
                    run.wall_time.as_secs_f64() * 1e3,
                    order.map(|o| format!("{o:.2}")).unwrap_or_default()
                );
            }
        }
    }
}

fn dt_ratio(dt: f64) -> f64 {
    // ratio previous/current in the sequence 1e-2, 5e-3, 2.5e-3, 1e-3, 5e-4, 2.5e-4
    let seq = [1e-2, 5e-3, 2.5e-3, 1e-3, 5e-4, 2.5e-4];
    let i = seq.iter().position(|&d| d == dt).unwrap();
    seq[i - 1] / seq[i]
}
