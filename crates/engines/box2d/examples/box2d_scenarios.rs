//! Error of the `box2d` model against the analytic dynamic model on
//! scenario files, at the dt ladder's rungs and for several joint
//! stiffnesses: position (m), angle (rad), the worst relative steady-ω error
//! over the segments (tail means over the last 20 %, with the harness's
//! floor `1e-3 v_c / L` on the denominator) and the joint drift (m).
//!
//! `cargo run --release -p pushval-box2d --example box2d_scenarios [FILES...]`
//! (default: every file in scenarios/).

use pushval_box2d::{tail_mean_omega, Box2dSettings, Box2dSimulator, DetailedEngine};
use pushval_model::{DynamicModel, Simulator};
use pushval_scenario::Scenario;

fn main() {
    let mut files: Vec<String> = std::env::args().skip(1).collect();
    if files.is_empty() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../scenarios");
        let mut all: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .map(|p| p.display().to_string())
            .collect();
        all.sort();
        files = all;
    }
    let hertz: Vec<f64> = std::env::var("HERTZ")
        .map(|s| s.split(',').map(|x| x.parse().unwrap()).collect())
        .unwrap_or_else(|_| vec![pushval_box2d::JOINT_HERTZ]);
    println!("file hertz dt pos_max theta_max omega_rel_max drift");
    for f in &files {
        let sc = Scenario::from_path(f).unwrap();
        let problem = sc.problem();
        let reference = DynamicModel::default().simulate(&problem).unwrap();
        let w_ref = tail_mean_omega(&problem, &reference, 0.2);
        let length = problem.body.contact().norm();
        let name = std::path::Path::new(f)
            .file_stem()
            .unwrap()
            .to_string_lossy();
        for &joint_hertz in &hertz {
            for dt in [1.0 / 960.0, 1.0 / 1920.0, 1.0 / 3840.0, 1.0 / 7680.0] {
                let run = Box2dSimulator::new(Box2dSettings {
                    dt,
                    joint_hertz,
                    ..Default::default()
                })
                .run(&problem)
                .unwrap();
                let (mut p, mut t) = (0.0f64, 0.0f64);
                for (s, r) in run.trajectory.samples.iter().zip(&reference.samples) {
                    p = p.max(((s.x - r.x).powi(2) + (s.y - r.y).powi(2)).sqrt());
                    t = t.max((s.theta - r.theta).abs());
                }
                let w = tail_mean_omega(&problem, &run.trajectory, 0.2);
                let mut e = 0.0f64;
                for ((a, b), push) in w.iter().zip(&w_ref).zip(&problem.pushes) {
                    if let (Some(a), Some(b)) = (a, b) {
                        e = e.max(pushval_engine::rel_err(*a, *b, push.speed, length));
                        if std::env::var("SEGMENTS").is_ok() {
                            println!("  segment: engine {a:.6e} model {b:.6e} diff {:.2e}", a - b);
                        }
                    }
                }
                println!(
                    "{name} {joint_hertz:.0e} {dt:.3e} {p:.3e} {t:.3e} {e:.3e} {:.1e}",
                    run.max_joint_drift
                );
            }
        }
    }
}
