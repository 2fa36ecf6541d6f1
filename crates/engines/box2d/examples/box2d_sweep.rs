//! Error of the `box2d` model against the analytic dynamic model for every
//! dt and sub-step count, on the square plate of the seed paper (0.25 m,
//! 1 kg, μ = 0.5, corner push, 1 s at φ = π/4 then 3 s at φ = π/4 + 0.3, at
//! 1 m/s), and the wall time per simulated second.
//!
//! `cargo run --release -p pushval-box2d --example box2d_sweep [FROM_REST]`

use std::f64::consts::FRAC_PI_4;

use pushval_box2d::{tail_mean_omega, Box2dSettings, Box2dSimulator, DetailedEngine};
use pushval_model::{Body, DynamicModel, Initial, Problem, Push, Simulator, Support, Vec2};

fn plate(from_rest: bool) -> Problem {
    let (m, a, mu, g) = (1.0, 0.25, 0.5, 9.81);
    let h = a / 2.0;
    let supports: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
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
        switching: Default::default(),
        sample_dt: 0.01,
        release: None,
    }
}

fn main() {
    let from_rest = std::env::args().nth(1).is_some_and(|a| a == "from_rest");
    let problem = plate(from_rest);
    let reference = DynamicModel::default().simulate(&problem).unwrap();
    let w_ref = tail_mean_omega(&problem, &reference, 0.2)[1].unwrap();
    println!("substeps dt pos_max theta_max omega_rel drift wall_per_sim_s");
    for substeps in [1, 2, 4, 8] {
        for dt in [1e-2, 5e-3, 2.5e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4] {
            let run = Box2dSimulator::new(Box2dSettings {
                dt,
                substeps,
                ..Default::default()
            })
            .run(&problem)
            .unwrap();
            let (mut p, mut t) = (0.0f64, 0.0f64);
            for (s, r) in run.trajectory.samples.iter().zip(&reference.samples) {
                p = p.max(((s.x - r.x).powi(2) + (s.y - r.y).powi(2)).sqrt());
                t = t.max((s.theta - r.theta).abs());
            }
            let w = run.segment_tail_omega[1];
            println!(
                "{substeps} {dt:.3e} {p:.3e} {t:.3e} {:.3e} {:.1e} {:.3e}",
                ((w - w_ref) / w_ref).abs(),
                run.max_joint_drift,
                run.wall_time.as_secs_f64() / problem.duration()
            );
        }
    }
}
