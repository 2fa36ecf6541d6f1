//! The steady ω of `avian2d` and `avian3d` on the paper plate (0.25 m
//! square, 1 kg, μ = 0.5, corner push) at φ = π/4 + 0.3, beside the Coulomb
//! root ω* of the analytic model and, for `avian3d`, the closed-form
//! prediction (`predict::PlateScene::steady`).
//!
//! `cargo run --release -p pushval-avian --features avian --example steady [DT] [SUBSTEPS]`

use std::f64::consts::FRAC_PI_4;

use pushval_avian::predict::PlateScene;
use pushval_avian::{
    Avian2dSettings, Avian2dSimulator, Avian3dSettings, Avian3dSimulator, DetailedEngine,
};
use pushval_model::{Body, Initial, Problem, Push, SegmentDynamics, Support, Switching, Vec2};

fn plate(speed: f64, duration: f64) -> Problem {
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
        pushes: vec![Push {
            duration,
            speed,
            phi: FRAC_PI_4 + 0.3,
        }],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dt: f64 = args.get(1).map_or(1e-3, |a| a.parse().expect("DT"));
    let substeps: u32 = args.get(2).map_or(16, |a| a.parse().expect("SUBSTEPS"));
    println!("dt = {dt} s, {substeps} substeps; steady ω = mean over the last 20 % of 6 s");
    println!("v_c (m/s)  omega* Coulomb   avian2d (rel)              avian3d (rel)              avian3d predicted");
    for speed in [0.2, 0.5, 1.0] {
        let p = plate(speed, 6.0);
        let star = SegmentDynamics::new(&p.body, &p.pushes[0])
            .attractor_from(0.0)
            .unwrap()
            .omega;
        let r2 = Avian2dSimulator::new(Avian2dSettings { dt, substeps })
            .run(&p)
            .unwrap();
        let w2 = pushval_engine::step_tail_omega(&p, &r2.history, 0.2)[0];
        let s3 = Avian3dSettings {
            dt,
            substeps,
            ..Default::default()
        };
        let r3 = Avian3dSimulator::new(s3).run(&p).unwrap();
        let w3 = pushval_engine::step_tail_omega(&p, &r3.history, 0.2)[0];
        let (pred, _) = PlateScene::new(&p, &s3)
            .unwrap()
            .steady(&p.pushes[0], 0.0)
            .unwrap();
        println!(
            "{speed:<10} {star:<16.8} {w2:<11.8} ({:+.2e})   {w3:<11.8} ({:+.2e})   {pred:.8}",
            w2 / star - 1.0,
            w3 / star - 1.0
        );
    }
}
