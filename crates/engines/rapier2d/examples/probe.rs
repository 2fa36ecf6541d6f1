//! Error of one rapier run against the dynamic model over time (diagnostics).
//! `cargo run --release -p pushval-rapier --example probe DT ITERS MODE [rest]`
use std::f64::consts::FRAC_PI_4;

use pushval_model::{
    Body, DynamicModel, Initial, Problem, Push, Simulator, Support, Switching, Vec2,
};
use pushval_rapier2d::{DetailedEngine, EngineSettings, FrictionVelocity, RapierSimulator};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let dt: f64 = a[1].parse().unwrap();
    let iters: usize = a[2].parse().unwrap();
    let mode = FrictionVelocity::ALL
        .into_iter()
        .find(|m| m.as_str() == a[3])
        .unwrap();
    let from_rest = a.get(4).map(|s| s == "rest").unwrap_or(false);
    let (m, s, mu, g) = (1.0, 0.25, 0.5, 9.81);
    let h = s / 2.0;
    let supports: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: mu * m * g / 4.0,
        })
        .collect();
    let body = Body::new(m, m * (s * s + s * s) / 12.0, Vec2::new(-h, -h), &supports).unwrap();
    let problem = Problem {
        body,
        limits: Default::default(),
        pushes: vec![
            Push {
                duration: 1.0,
                speed: 1.0,
                phi: FRAC_PI_4,
            },
            Push {
                duration: 3.0,
                speed: 1.0,
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
    };
    let r = DynamicModel::default().simulate(&problem).unwrap();
    let pgs = std::env::var("PV_PGS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let settings = EngineSettings {
        dt,
        solver_iterations: iters,
        pgs_iterations: pgs,
        friction_velocity: mode,
        ..Default::default()
    };
    let e = RapierSimulator::new(settings).run(&problem).unwrap();
    for (a, b) in e.trajectory.samples.iter().zip(&r.samples) {
        let k = (a.t * 100.0).round() as i64;
        if k % 10 == 0 || (95..=110).contains(&k) {
            println!(
                "t={:5.2} pos_err={:+.3e} th_err={:+.3e} w={:+.6} w_ref={:+.6} w_err={:+.3e}",
                a.t,
                ((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt(),
                a.theta - b.theta,
                a.omega,
                b.omega,
                a.omega - b.omega
            );
        }
    }
}
