//! The steady ω of every PhysX model on the paper plate (0.25 m square, 1 kg,
//! four corner feet, μ 0.5, pushed at the corner (−0.125, −0.125) at
//! φ = π/4 + 0.3 for 4 s) beside the Coulomb ω* and each closed form.
//!
//! `cargo run --release -p pushval-physx --features physx --example paper_table [dt]`

use pushval_model::{Body, Initial, Problem, Push, Support, Switching, Vec2};
use pushval_physx::predict::{steady_omega, Law};
use pushval_physx::{DetailedEngine, FootContacts, FrictionType, PhysxSettings, PhysxSimulator};

fn main() {
    let h = 0.125;
    let corners = [[-h, -h], [h, -h], [h, h], [-h, h]];
    let supports: Vec<Support> = corners
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: 0.5 * 9.81 / 4.0,
        })
        .collect();
    let body = Body::new(
        1.0,
        0.25f64.powi(2) * 2.0 / 12.0,
        Vec2::new(-h, -h),
        &supports,
    )
    .expect("the paper plate is valid");
    let dt: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().expect("dt in seconds"))
        .unwrap_or(1e-3);
    println!("contacts,friction,v_c,omega_engine,omega_law,omega_coulomb,law");
    for contacts in FootContacts::ALL {
        for v in [0.2, 0.5, 1.0] {
            let push = Push {
                duration: 4.0,
                speed: v,
                phi: std::f64::consts::FRAC_PI_4 + 0.3,
            };
            let problem = Problem {
                body: body.clone(),
                limits: Default::default(),
                pushes: vec![push],
                initial: Initial::default(),
                switching: Switching::Impulsive,
                sample_dt: 0.01,
                release: None,
            };
            let coulomb = steady_omega(&body, &push, Law::Coulomb, 0.0).omega;
            for f in FrictionType::ALL {
                let settings = PhysxSettings {
                    friction: f,
                    contacts,
                    dt,
                    ..Default::default()
                };
                let run = PhysxSimulator::new(settings)
                    .run(&problem)
                    .expect("PhysX runs the paper plate");
                let feet: Vec<Support> = body
                    .supports()
                    .zip(&run.engine_friction)
                    .map(|(s, &friction)| Support { friction, ..s })
                    .collect();
                let engine_body =
                    Body::new(1.0, body.inertia_cm(), body.contact(), &feet).expect("same plate");
                // PhysX's welded order puts feet 0 and 2 first in the patch.
                let law = f.law(contacts, &[0, 1, 2, 3], &corners);
                let pred = steady_omega(&engine_body, &push, law, 0.0).omega;
                println!(
                    "{},{},{v},{:.6},{:.6},{:.6},{law:?}",
                    contacts.as_str(),
                    f.as_str(),
                    run.segment_tail_omega[0],
                    pred,
                    coulomb
                );
            }
        }
    }
}
