//! `box2d_motor_joint` (Box2D's top-down friction idiom) against its closed
//! form (`predict`), and how far it is from Coulomb support friction.

mod common;

use std::f64::consts::FRAC_PI_4;

use pushval_box2d::predict::{
    motor_joint_limits, motor_joint_locks, motor_joint_moment, motor_joint_quasi_static,
    motor_joint_steady,
};
use pushval_box2d::{tail_mean_omega, Box2dSettings, Box2dSimulator, DetailedEngine, Friction};
use pushval_engine::rel_err;
use pushval_model::{cross, Body, Problem, SegmentDynamics, Support};

/// Steady ω (rad/s) of the engine: the mean of ω over the last 20 % of the
/// (single) push.
fn engine_steady(problem: &Problem) -> f64 {
    let r = Box2dSimulator::new(Box2dSettings {
        friction: Friction::MotorJoint,
        ..Default::default()
    })
    .run(problem)
    .unwrap();
    tail_mean_omega(problem, &r.trajectory, 0.2)[0].unwrap()
}

/// The Coulomb steady ω (rad/s) reached from ω = 0.
fn coulomb_steady(problem: &Problem) -> f64 {
    let seg = SegmentDynamics::new(&problem.body, &problem.pushes[0]);
    seg.attractor(&seg.steady_states(), 0.0).unwrap().omega
}

/// The paper plate with its supports moved to (±s, ±s): s < 0.125 m puts
/// them closer to the centre than the pushed corner.
fn with_supports_at(problem: &Problem, s: f64) -> Problem {
    let b = &problem.body;
    let supports: Vec<Support> = b
        .supports()
        .map(|p| Support {
            position: p.position * (s / 0.125),
            friction: p.friction,
        })
        .collect();
    let mut p = problem.clone();
    p.body = Body::new(b.mass(), b.inertia_cm(), b.contact(), &supports).unwrap();
    p
}

/// The paper plate at φ = π/4 + 0.3: the corner is as far from the centre
/// as every support, so `F_max |p_c × n_φ| ≤ T_max` and the joint's torque
/// cap holds the plate from turning at every speed (closed form: ω* = 0),
/// where Coulomb friction turns it at 0.22–0.65 rad/s.
#[test]
fn paper_plate_locks_as_the_closed_form_says() {
    let length = 0.125 * 2f64.sqrt();
    for speed in [0.2, 0.5, 1.0] {
        let problem = common::one_push(speed, FRAC_PI_4 + 0.3, 6.0);
        let push = problem.pushes[0];
        let predicted = motor_joint_steady(&problem.body, &push, 0.0).unwrap();
        let w = engine_steady(&problem);
        let coulomb = coulomb_steady(&problem);
        let rel = rel_err(w, predicted.omega, speed, length);
        println!(
            "v_c {speed}: engine {w:.3e}, closed form {:.3e} (locked {}), Coulomb {coulomb:.4}",
            predicted.omega, predicted.locked
        );
        assert!(predicted.locked && motor_joint_locks(&problem.body, &push));
        assert!(
            rel <= 1e-2,
            "v_c {speed}: engine {w} vs {}: {rel:.2e}",
            predicted.omega
        );
        assert!(coulomb.abs() > 0.2, "Coulomb turns the plate: {coulomb}");
    }
}

/// Supports at (±0.05, ±0.05) m and φ = π/4 + 0.8: the corner's moment arm
/// exceeds the supports' mean distance, the joint slides and turns, and ω*
/// is the root of the closed-form moment balance.
#[test]
fn inner_supports_turn_at_the_closed_form_omega() {
    for speed in [0.2, 0.5, 1.0] {
        let problem = with_supports_at(&common::one_push(speed, FRAC_PI_4 + 0.8, 6.0), 0.05);
        let push = problem.pushes[0];
        let predicted = motor_joint_steady(&problem.body, &push, 0.0).unwrap();
        let w = engine_steady(&problem);
        let coulomb = coulomb_steady(&problem);
        let rel = ((w - predicted.omega) / predicted.omega).abs();
        println!(
            "v_c {speed}: engine {w:.6}, closed form {:.6}, Coulomb {coulomb:.6}",
            predicted.omega
        );
        assert!(!predicted.locked);
        assert!(
            rel <= 1e-2,
            "v_c {speed}: engine {w} vs {}: {rel:.2e}",
            predicted.omega
        );
        // Not Coulomb: 40–50 % slower here.
        assert!((w - coulomb).abs() > 0.15 * coulomb.abs());
    }
}

/// The closed form itself: the root zeroes the moment balance, the caps are
/// μ m g and μ m g r̄, and with a vanishing mass (no inertial term) the
/// root is the explicit quasi-static one.
#[test]
fn closed_form_is_consistent() {
    let problem = with_supports_at(&common::one_push(0.5, FRAC_PI_4 + 0.8, 6.0), 0.05);
    let body = &problem.body;
    let push = problem.pushes[0];
    let (f, t) = motor_joint_limits(body);
    assert!((f - 0.5 * 9.81).abs() < 1e-12);
    assert!((t - 0.5 * 9.81 * 0.05 * 2f64.sqrt()).abs() < 1e-12);
    let s = motor_joint_steady(body, &push, 0.0).unwrap();
    let g = motor_joint_moment(body, &push, s.omega);
    assert!(g.abs() < 1e-12, "g(omega*) = {g}");
    // The same from either side: one stable root.
    for w0 in [-5.0, -0.3, 0.7, 4.0] {
        let o = motor_joint_steady(body, &push, w0).unwrap().omega;
        assert!(
            (o - s.omega).abs() < 1e-12 * s.omega.abs(),
            "from {w0}: {o}"
        );
    }
    let supports: Vec<Support> = body.supports().collect();
    let light = Body::new(1e-9, 1e-9 * body.inertia_cm(), body.contact(), &supports).unwrap();
    let dynamic = motor_joint_steady(&light, &push, 0.0).unwrap().omega;
    let quasi = motor_joint_quasi_static(&light, &push);
    assert!(
        (dynamic - quasi).abs() < 1e-6 * quasi.abs(),
        "{dynamic} vs {quasi}"
    );
    // The heavy body turns more slowly than the quasi-static one here
    // (p_c · n_φ < 0: the inertial term opposes ω).
    assert!(s.omega.abs() < quasi.abs());
    // Lock boundary: F_max |p_c × n_φ| = T_max.
    let c = cross(&body.contact(), &push.direction());
    assert_eq!(motor_joint_locks(body, &push), f * c.abs() <= t);
}
