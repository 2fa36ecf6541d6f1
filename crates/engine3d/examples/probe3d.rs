//! Quick probe: the paper plate in each friction model (`cargo run --release -p pushval-rapier3d --example probe3d`).
use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};
use pushval_rapier3d::predict::{coulomb_steady, predict_steady, Law};
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
    let hcm = *args.first().unwrap_or(&0.01);
    let hp = *args.get(1).unwrap_or(&hcm);
    let dt = *args.get(2).unwrap_or(&1e-3);
    for &v in &[0.2, 0.5, 1.0] {
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
        let star = coulomb_steady(&body, &push, 0.0).unwrap();
        for fr in ContactFriction::ALL {
            for feet in [FeetColliders::Compound, FeetColliders::Separate] {
                for rec in [false, true] {
                    let s = Rapier3dSettings {
                        friction: fr,
                        feet,
                        cm_height: hcm,
                        push_height: hp,
                        dt,
                        contact_recycling: rec,
                        ..Default::default()
                    };
                    let run = Rapier3dSimulator::new(s).run(&p).unwrap();
                    let scene = s.scene(&p).unwrap();
                    let law =
                        if fr == ContactFriction::Simplified && feet == FeetColliders::Compound {
                            Law::SimplifiedOneManifold
                        } else {
                            Law::Coulomb
                        };
                    let pred = predict_steady(&scene, &push, law, true).unwrap();
                    println!("v={v} {} star={star:.4} eng={:.4} pred={:.4} rel={:.2e} man={}/{} rest={:?} tail={:?} predN={:?} tilt={:.2e} lift={:.2e} drift={:.1e} wall={:?}",
                    s.label(), run.segment_tail_omega[0], pred.omega, (run.segment_tail_omega[0]-star)/star, run.manifolds, run.manifold_points,
                    run.rest_loads.iter().map(|x| (x*1e4).round()/1e4).collect::<Vec<_>>(),
                    run.segment_tail_loads[0].iter().map(|x| (x*1e4).round()/1e4).collect::<Vec<_>>(),
                    pred.loads.iter().map(|x| (x*1e4).round()/1e4).collect::<Vec<_>>(),
                    run.max_tilt, run.max_lift, run.max_joint_drift, run.wall_time);
                }
            }
        }
    }
}
