//! ω over time of one box2d run: `--example box2d_trace FILE DT [EVERY]`.
use pushval_box2d::{Box2dSettings, Box2dSimulator, DetailedEngine};
use pushval_scenario::Scenario;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let problem = Scenario::from_path(&a[1]).unwrap().problem();
    let dt: f64 = a[2].parse().unwrap();
    let every: usize = a.get(3).map_or(500, |s| s.parse().unwrap());
    let run = Box2dSimulator::new(Box2dSettings {
        dt,
        ..Default::default()
    })
    .run(&problem)
    .unwrap();
    for r in run.history.iter().step_by(every) {
        println!("{:.5} {:.9e} {:.9e}", r.t1, r.theta, r.omega);
    }
}
