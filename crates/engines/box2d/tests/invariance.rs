//! Invariances the model has and Box2D must keep: mirror symmetry and mass
//! independence. Round-to-nearest is symmetric under negation, so the
//! mirror image comes out bit for bit (the bound leaves room for nothing
//! but a platform's odd rounding); scaling the mass changes the f32
//! round-off Box2D makes in velocities, masses and forces, so mass
//! independence holds to about 1e-6 m (bound 1e-5).

mod common;

use pushval_box2d::{Box2dSettings, Box2dSimulator, DetailedEngine, Friction};
use pushval_model::{Body, Problem, Support, Trajectory, Vec2};

fn run(problem: &Problem, friction: Friction) -> Trajectory {
    Box2dSimulator::new(Box2dSettings {
        friction,
        ..Default::default()
    })
    .run(problem)
    .unwrap()
    .trajectory
}

/// The plate mirrored about the object's x axis: supports, contact and push
/// directions reflected (y → −y, φ → −φ).
fn mirrored(problem: &Problem) -> Problem {
    let b = &problem.body;
    let supports: Vec<Support> = b
        .supports()
        .map(|s| Support {
            position: Vec2::new(s.position.x, -s.position.y),
            friction: s.friction,
        })
        .collect();
    let c = b.contact();
    let mut p = problem.clone();
    p.body = Body::new(b.mass(), b.inertia_cm(), Vec2::new(c.x, -c.y), &supports).unwrap();
    for push in &mut p.pushes {
        push.phi = -push.phi;
    }
    p
}

/// Mirror symmetry: the mirrored scene runs the mirror image, x kept, y, θ
/// and ω negated, for both friction laws.
#[test]
fn mirrored_scene_runs_the_mirror_image() {
    for from_rest in [false, true] {
        let problem = common::plate(1.0, from_rest);
        for friction in [Friction::Coulomb, Friction::MotorJoint] {
            let a = run(&problem, friction);
            let b = run(&mirrored(&problem), friction);
            let mut worst = 0.0f64;
            for (s, m) in a.samples.iter().zip(&b.samples) {
                worst = worst
                    .max((s.x - m.x).abs())
                    .max((s.y + m.y).abs())
                    .max((s.theta + m.theta).abs())
                    .max(0.1 * (s.omega + m.omega).abs());
            }
            println!("{friction:?} from_rest={from_rest}: worst {worst:.2e}");
            assert!(worst < 1e-9, "{friction:?}: mirror differs by {worst:.2e}");
        }
    }
}

/// Mass independence: with loads N_i = w_i m g, scaling m, I_cm and every
/// F_i by the same factor leaves the motion unchanged.
#[test]
fn scaling_the_mass_leaves_the_motion_unchanged() {
    let problem = common::plate(1.0, false);
    for k in [0.1, 3.7, 40.0] {
        let b = &problem.body;
        let supports: Vec<Support> = b
            .supports()
            .map(|s| Support {
                position: s.position,
                friction: k * s.friction,
            })
            .collect();
        let mut heavy = problem.clone();
        heavy.body = Body::new(k * b.mass(), k * b.inertia_cm(), b.contact(), &supports).unwrap();
        for friction in [Friction::Coulomb, Friction::MotorJoint] {
            let (p, t) = common::max_errors(&run(&problem, friction), &run(&heavy, friction));
            println!("{friction:?} k={k}: {p:.2e} m {t:.2e} rad");
            assert!(
                p < 1e-5 && t < 1e-5,
                "{friction:?} k={k}: {p:.2e} m, {t:.2e} rad"
            );
        }
    }
}
