//! Prints what Jolt does on the paper plate (development probe).
use pushval_jolt::predict::{self, Direction, Law};
use pushval_jolt::{JoltSettings, JoltSimulator, Scene};
use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};

fn plate() -> Body {
    let h = 0.125;
    let s: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support { position: Vec2::new(c[0], c[1]), friction: 0.5 * 9.81 / 4.0 })
        .collect();
    Body::new(1.0, 0.25 * 0.25 / 6.0, Vec2::new(-h, -h), &s).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let phi: f64 = args.get(1).map_or(std::f64::consts::FRAC_PI_4 + 0.3, |s| s.parse().unwrap());
    let dt: f64 = args.get(2).map_or(1e-3, |s| s.parse().unwrap());
    let vs: u32 = args.get(3).map_or(10, |s| s.parse().unwrap());
    for scene in [Scene::Feet] {
        for v in [0.5] {
            let p = Problem {
                body: plate(),
                limits: Default::default(),
                pushes: vec![Push { duration: 4.0, speed: v, phi }],
                initial: Initial::default(),
                switching: Switching::Impulsive,
                sample_dt: 0.01,
            };
            let r = JoltSimulator::new(JoltSettings { scene, dt, velocity_steps: vs, ..Default::default() }).run(&p).unwrap();
            let push = p.pushes[0];
            let caps: Vec<f64> = r.rest_loads.iter().map(|n| r.mu * n).collect();
            let law = |d| match scene {
                Scene::Box => Law::jolt_box(&p.body, Some(&caps), d),
                Scene::Feet => Law::jolt_feet(&p.body, Some(&caps), d),
            };
            let wl = predict::tail_omega(&law(Direction::EffectiveMass), &p.body, &push, 4.0, (0.0, 0.0), 1e-4);
            let wi = predict::tail_omega(&law(Direction::Slip), &p.body, &push, 4.0, (0.0, 0.0), 1e-4);
            println!("{:?} v={v} omega={:.5} std={:.5} law_em={:.5} law_slip={:.5} loads={:?} sizes={:?} angle={:.4} vs_law={:.2e} tilt={:.2e} lift={:.2e} drift={:.2e}",
                scene, r.segment_tail_omega[0], r.segment_tail_omega_std[0], wl, wi,
                r.rest_loads.iter().map(|x| (x*1e4).round()/1e4).collect::<Vec<_>>(), r.manifold_sizes,
                r.segment_tail_max_angle[0], r.segment_tail_max_angle_vs_law[0], r.max_tilt, r.max_lift, r.max_joint_drift);
            if std::env::var_os("SERIES").is_some() {
                let l = law(Direction::EffectiveMass);
                for k in 1..=16 {
                    let t = 0.25 * k as f64;
                    let w = predict::tail_omega(&l, &p.body, &push, t / 0.8 * 0.0 + t, (0.0, 0.0), 1e-4);
                    let _ = w;
                    let i = (t / dt).round() as usize;
                    let hrec = &r.history[i];
                    println!("  t={t} engine w={:.4} th={:.4}", hrec.omega, hrec.theta);
                }
                let (th, w) = predict::integrate(&l, &p.body, &push, 4.0, (0.0, 0.0), 1e-4, 0.25);
                println!("  law: {:?}", th.iter().zip(&w).map(|(a,b)| format!("{:.4}/{:.4}", b, a)).collect::<Vec<_>>());
            }
            let c = &r.segment_tail_contacts[0];
            for (i, x) in c.iter().enumerate() {
                println!("   sup {i}: N={:.4} F=({:.4},{:.4}) |F|/N={:.4} twist={:.4} slip=({:.4},{:.4})", x.normal, x.friction[0], x.friction[1], (x.friction[0].hypot(x.friction[1]))/x.normal, x.twist, x.slip[0], x.slip[1]);
            }
        }
    }
}
