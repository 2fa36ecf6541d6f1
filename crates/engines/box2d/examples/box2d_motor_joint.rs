//! The motor-joint idiom against its closed form and against Coulomb: the
//! paper plate pushed at a corner with φ = π/4 + 0.3 for 6 s, and a plate
//! whose supports sit close to the centre (so the joint does not lock).
//!
//! `cargo run --release -p pushval-box2d --example box2d_motor_joint [DT]`

use std::f64::consts::FRAC_PI_4;

use pushval_box2d::predict::{motor_joint_locks, motor_joint_quasi_static, motor_joint_steady};
use pushval_box2d::{Box2dSettings, Box2dSimulator, DetailedEngine, Friction};
use pushval_model::{Body, Initial, Problem, Push, SegmentDynamics, Support, Vec2};

fn plate(half: f64, support_half: f64, speed: f64, phi: f64) -> Problem {
    let (m, mu, g) = (1.0, 0.5, 9.81);
    let a = 2.0 * half;
    let supports: Vec<Support> = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0] * support_half, c[1] * support_half),
            friction: mu * m * g / 4.0,
        })
        .collect();
    let body = Body::new(
        m,
        m * (a * a + a * a) / 12.0,
        Vec2::new(-half, -half),
        &supports,
    )
    .unwrap();
    Problem {
        body,
        limits: Default::default(),
        pushes: vec![Push {
            duration: 6.0,
            speed,
            phi,
        }],
        initial: Initial::default(),
        switching: Default::default(),
        sample_dt: 0.01,
        release: None,
    }
}

fn main() {
    let dt: f64 = std::env::args().nth(1).map_or(1e-3, |s| s.parse().unwrap());
    println!("case v_c engine predicted quasi_static locked coulomb");
    for (case, support_half, phi) in [
        ("paper", 0.125, FRAC_PI_4 + 0.3),
        ("inner", 0.05, FRAC_PI_4 + 0.8),
    ] {
        for speed in [0.2, 0.5, 1.0] {
            let problem = plate(0.125, support_half, speed, phi);
            let push = problem.pushes[0];
            let run = Box2dSimulator::new(Box2dSettings {
                dt,
                friction: Friction::MotorJoint,
                ..Default::default()
            })
            .run(&problem)
            .unwrap();
            let w = run.segment_tail_omega[0];
            let p = motor_joint_steady(&problem.body, &push, 0.0).unwrap();
            let seg = SegmentDynamics::new(&problem.body, &push);
            let coulomb = seg.attractor(&seg.steady_states(), 0.0).unwrap().omega;
            println!(
                "{case} {speed} {w:.6e} {:.6e} {:.6e} {} {coulomb:.6e}",
                p.omega,
                motor_joint_quasi_static(&problem.body, &push),
                motor_joint_locks(&problem.body, &push)
            );
        }
    }
}
