//! Time of the `box2d` models per simulated second at dt = 1e-3 s: the
//! median over 21 runs of a scenario (default
//! scenarios/paper-square-v1.0.toml, 10 s) of the wall time and, on Linux,
//! of the thread's CPU time (from /proc/thread-self/schedstat, so waiting
//! for a core on a busy machine does not count), and the share of the wall
//! time inside `b2World_Step`.
//!
//! `cargo run --release -p pushval-box2d --example box2d_timing [FILE] [DT]`

use pushval_box2d::{Box2dSettings, Box2dSimulator, DetailedEngine, Friction};
use pushval_scenario::Scenario;

/// CPU time of this thread (s), if the kernel reports it.
fn thread_cpu() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let file = std::env::args().nth(1).unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../scenarios/paper-square-v1.0.toml"
        )
        .into()
    });
    let dt: f64 = std::env::args().nth(2).map_or(1e-3, |s| s.parse().unwrap());
    let problem = Scenario::from_path(&file).unwrap().problem();
    let seconds = problem.duration();
    let steps = (seconds / dt).round();
    for friction in [Friction::Coulomb, Friction::MotorJoint] {
        let sim = Box2dSimulator::new(Box2dSettings {
            dt,
            friction,
            ..Default::default()
        });
        let (mut wall, mut cpu, mut step) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..21 {
            let c0 = thread_cpu();
            let r = sim.run(&problem).unwrap();
            if let (Some(a), Some(b)) = (c0, thread_cpu()) {
                cpu.push(b - a);
            }
            wall.push(r.wall_time.as_secs_f64());
            step.push(r.step_time.as_secs_f64());
        }
        let cpu = if cpu.is_empty() {
            "-".to_string()
        } else {
            format!("{:.3}", 1e3 * median(cpu) / seconds)
        };
        println!(
            "{}: per simulated second {:.3} ms wall, {cpu} ms CPU; per step {:.2} us wall, of which b2World_Step {:.2} us",
            friction.as_str(),
            1e3 * median(wall.clone()) / seconds,
            1e6 * median(wall) / steps,
            1e6 * median(step) / steps
        );
    }
}
