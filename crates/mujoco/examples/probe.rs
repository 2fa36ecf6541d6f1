//! Scratch probe: the paper plate at one speed (`cargo run --release -p pushval-mujoco --features mujoco --example probe -- V CONE`).
use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};
use pushval_mujoco::{Cone, MujocoSettings, MujocoSimulator};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let v: f64 = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(1.0);
    let cone = if args.get(2).map(|s| s.as_str()) == Some("e") {
        Cone::Elliptic
    } else {
        Cone::Pyramidal
    };
    let h = 0.125;
    let supports: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: 0.5 * 9.81 / 4.0,
        })
        .collect();
    let body = Body::new(1.0, 0.0625 * 2.0 / 12.0, Vec2::new(-h, -h), &supports).unwrap();
    let push = Push {
        duration: 4.0,
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
    let mut s = MujocoSettings {
        cone,
        ..Default::default()
    };
    for kv in args.iter().skip(3) {
        let (k, val) = kv.split_once('=').unwrap();
        let x: f64 = val.parse().unwrap();
        match k {
            "dt" => s.timestep = x,
            "imp" => s.impratio = x,
            "ns" => s.noslip_iterations = x as usize,
            "hcm" => s.cm_height = x,
            "hp" => s.push_height = x,
            "tc" => s.contact_solref[0] = x,
            _ => panic!(),
        }
    }
    let r = MujocoSimulator::new(s).run(&p).unwrap();
    let ws = pushval_mujoco::theory::coulomb_steady(&body, &push, 0.0).unwrap();
    println!("{} v={v} tail={:.5} std={:.2e} model={ws:.5} rel={:.4} rest={:?} mu={:?} tail_loads={:?} gap={:.2e} pen={:.2e} tilt={:.2e} wall={:?}",
        s.label(), r.segment_tail_omega[0], r.segment_tail_omega_std[0], (r.segment_tail_omega[0]-ws)/ws.abs(), r.rest_loads, r.mu, r.tail_loads[0], r.max_pusher_gap, r.max_penetration, r.max_tilt, r.wall_time);
    for k in (0..r.history.len()).step_by(250) {
        let h = &r.history[k];
        println!(
            "  t={:.3} th={:.4} w={:.4} tilt={:.2e} minu={:.4}",
            h.t, h.theta, h.omega, h.tilt, h.min_foot_speed
        );
    }
}
