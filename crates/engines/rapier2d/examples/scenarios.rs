//! Every scenario of `scenarios/` (or the files given), every friction-velocity
//! mode: max position and θ error against the analytic dynamic model, the
//! largest steady-ω relative error over the settled segments (tail mean over
//! the last 20 % against the root ω*), and the observed order of the steady-ω
//! error from runs at 4h, 2h and h.
//!
//! `cargo run --release -p pushval-rapier --example scenarios [DT] [FILES...]`

use std::path::PathBuf;

use pushval_model::{DynamicModel, RootKind, SegmentDynamics, Simulator, Trajectory};
use pushval_rapier2d::{
    tail_mean_omega, DetailedEngine, EngineSettings, FrictionVelocity, RapierSimulator,
};

fn errors(a: &Trajectory, b: &Trajectory) -> (f64, f64) {
    let (mut p, mut t) = (0.0f64, 0.0f64);
    for (a, b) in a.samples.iter().zip(&b.samples) {
        p = p.max(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt());
        t = t.max((a.theta - b.theta).abs());
    }
    (p, t)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let dt: f64 = args.next().map(|s| s.parse().unwrap()).unwrap_or(1e-3);
    let mut files: Vec<PathBuf> = args.map(PathBuf::from).collect();
    if files.is_empty() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../scenarios");
        files = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        files.sort();
    }
    println!("scenario mode pos_max theta_max omega_rel order drift us/step");
    for f in files {
        let sc = pushval_scenario::Scenario::from_path(&f).unwrap();
        let problem = sc.problem();
        let reference = DynamicModel::default().simulate(&problem).unwrap();
        let ref_tail = tail_mean_omega(&problem, &reference, 0.2);
        // Settled segments: a stable smooth root that the model's tail reaches.
        let roots: Vec<Option<f64>> = problem
            .pushes
            .iter()
            .enumerate()
            .map(|(j, push)| {
                if push.speed <= 0.0 {
                    return None;
                }
                let seg = SegmentDynamics::new(&problem.body, push);
                let roots = seg.steady_states();
                let r = seg.attractor(&roots, reference.segments[j].omega_start)?;
                let tail = ref_tail[j]?;
                let floor = 1e-3 * push.speed / sc.froude_length();
                (matches!(r.kind, RootKind::Stable)
                    && r.tau.is_some()
                    && (tail - r.omega).abs() / r.omega.abs().max(floor) < 1e-6)
                    .then_some(r.omega)
            })
            .collect();
        for mode in FrictionVelocity::ALL {
            let run_at = |h: f64| {
                RapierSimulator::new(EngineSettings {
                    dt: h,
                    friction_velocity: mode,
                    ..Default::default()
                })
                .run(&problem)
                .unwrap()
            };
            let runs = [run_at(4.0 * dt), run_at(2.0 * dt), run_at(dt)];
            let (p, t) = errors(&runs[2].trajectory, &reference);
            let mut rel_max = 0.0f64;
            let mut orders = Vec::new();
            for (j, r) in roots.iter().enumerate() {
                let Some(ws) = r else { continue };
                let floor = 1e-3 * problem.pushes[j].speed / sc.froude_length();
                let w: Vec<f64> = runs
                    .iter()
                    .map(|r| tail_mean_omega(&problem, &r.trajectory, 0.2)[j].unwrap())
                    .collect();
                rel_max = rel_max.max((w[2] - ws).abs() / ws.abs().max(floor));
                orders.push(((w[0] - w[1]).abs() / (w[1] - w[2]).abs()).log2());
            }
            orders.sort_by(f64::total_cmp);
            let order = orders.get(orders.len() / 2).copied().unwrap_or(f64::NAN);
            println!(
                "{:28} {:10} {:.3e} {:.3e} {:.3e} {:5.2} {:.1e} {:.2}",
                sc.name,
                mode.as_str(),
                p,
                t,
                rel_max,
                order,
                runs[2].max_joint_drift,
                runs[2].wall_time.as_secs_f64() * 1e6 / runs[2].steps as f64
            );
        }
    }
}
