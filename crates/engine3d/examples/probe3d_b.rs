//! Probe: per-foot friction against μN.
use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};
use pushval_rapier3d::{ContactFriction, FeetColliders, Rapier3dSettings, Rapier3dSimulator};

fn main() {
    let h = 0.125;
    let sup: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: 0.5 * 9.81 / 4.0,
        })
        .collect();
    let body = Body::new(1.0, 0.0625 * 2.0 / 12.0, Vec2::new(-h, -h), &sup).unwrap();
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let v = *args.first().unwrap_or(&0.2);
    let it = *args.get(1).unwrap_or(&4.0) as usize;
    let push = Push {
        duration: 5.0,
        speed: v,
        phi: std::f64::consts::FRAC_PI_4 + 0.3,
    };
    let p = Problem {
        body: body.clone(),
        limits: Default::default(),
        pushes: vec![push],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
    };
    let s = Rapier3dSettings {
        friction: ContactFriction::Coulomb,
        feet: FeetColliders::Separate,
        solver_iterations: it,
        ..Default::default()
    };
    let run = Rapier3dSimulator::new(s).run(&p).unwrap();
    println!("omega {:?}", run.segment_tail_omega);
    println!("mu {:?}", run.mu);
    println!("N {:?}", run.segment_tail_loads[0]);
    println!("F {:?}", run.segment_tail_friction[0]);
    println!(
        "muN {:?}",
        run.segment_tail_loads[0]
            .iter()
            .zip(&run.mu)
            .map(|(n, m)| n * m)
            .collect::<Vec<_>>()
    );
    println!("slip {:?}", run.segment_tail_min_slip[0]);
    for r in run.history.iter().step_by(250) {
        println!(
            "{:.3} {:.4} {:.4} {:.4} {:.5}",
            r.t1, r.x, r.y, r.theta, r.omega
        );
    }
}
