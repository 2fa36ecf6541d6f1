//! The order of accuracy `order()` reports is the one measured: first order
//! in dt, against the dynamic model and in self-convergence over dt = h,
//! h/2, h/4 (h = 4 ms), on the paper plate at 1 m/s. And where it stops:
//! Box2D's f32 rotation sets a round-off floor that grows as 1/dt.

mod common;

use pushval_box2d::{tail_mean_omega, Box2dSettings, Box2dSimulator, DetailedEngine};
use pushval_model::{DynamicModel, Problem, Simulator, Trajectory};
use pushval_scenario::Scenario;

fn run(problem: &Problem, dt: f64) -> Trajectory {
    Box2dSimulator::new(Box2dSettings {
        dt,
        ..Default::default()
    })
    .run(problem)
    .unwrap()
    .trajectory
}

const H: f64 = 4e-3;

#[test]
fn first_order_against_the_model_and_in_self_convergence() {
    let problem = common::plate(1.0, false);
    let reference = DynamicModel::default().simulate(&problem).unwrap();
    let w_ref = tail_mean_omega(&problem, &reference, 0.2)[1].unwrap();
    let runs: Vec<Trajectory> = [H, H / 2.0, H / 4.0]
        .iter()
        .map(|&dt| run(&problem, dt))
        .collect();
    let err: Vec<(f64, f64, f64)> = runs
        .iter()
        .map(|r| {
            let (p, t) = common::max_errors(r, &reference);
            let w = tail_mean_omega(&problem, r, 0.2)[1].unwrap();
            (p, t, ((w - w_ref) / w_ref).abs())
        })
        .collect();
    let order = |a: f64, b: f64| (a / b).log2();
    for k in 0..2 {
        let (a, b) = (err[k], err[k + 1]);
        let q = [order(a.0, b.0), order(a.1, b.1), order(a.2, b.2)];
        println!("against the model, step {k}: orders {q:?}");
        for q in q {
            assert!((0.9..1.1).contains(&q), "order {q}");
        }
    }
    // Self-convergence: |X(h) − X(h/2)| against |X(h/2) − X(h/4)|.
    let (d1, _) = common::max_errors(&runs[0], &runs[1]);
    let (d2, _) = common::max_errors(&runs[1], &runs[2]);
    let q = order(d1, d2);
    println!("self-convergence order {q:.3}");
    assert!((0.9..1.1).contains(&q), "self-convergence order {q}");
    assert_eq!(pushval_box2d::models()[0].default_engine().order(), 1.0);
}

/// Box2D's rotation is an f32 (cos, sin) pair, integrated and normalised
/// every step: each step's angle increment carries a round-off of order
/// 1e-9 rad, which the pusher heading turns into a spurious ω of order
/// 1e-9/dt. It shows where ω* = 0 (a push through the centre after a turn):
/// the steady ω grows as dt shrinks, from 4e-7 rad/s at 1/960 s to about
/// 2e-5 rad/s at 1/7680 s (the dt ladder's floor).
#[test]
fn f32_rotation_floor_grows_as_dt_shrinks() {
    let text = r#"
name = "centre-after-turn"
description = "paper plate pushed through the centre while turning at -0.65 rad/s"
[object]
mass = 1.0
polygon = [[-0.125, -0.125], [0.125, -0.125], [0.125, 0.125], [-0.125, 0.125]]
[supports]
points = [[-0.125, -0.125], [0.125, -0.125], [0.125, 0.125], [-0.125, 0.125]]
mu = 0.5
load = "equal"
[contact]
point = [-0.125, -0.125]
[initial]
omega = -0.65
[[push]]
duration = 2.0
speed = 0.6
phi = 0.7853981633974483
"#;
    let problem = Scenario::from_toml(text, std::path::Path::new("centre.toml"))
        .unwrap()
        .problem();
    let tail = |dt: f64| tail_mean_omega(&problem, &run(&problem, dt), 0.2)[0].unwrap();
    let (coarse, fine) = (tail(1.0 / 960.0), tail(1.0 / 7680.0));
    println!("steady omega {coarse:.2e} rad/s at 1/960 s, {fine:.2e} at 1/7680 s");
    assert!(coarse.abs() < 2e-6, "{coarse:.2e}");
    assert!(
        fine.abs() > 5.0 * coarse.abs() && fine.abs() < 1e-4,
        "{fine:.2e}"
    );
}
