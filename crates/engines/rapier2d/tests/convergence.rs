//! Error of the rapier run against the analytic dynamic model versus dt, per
//! friction-velocity mode and precision (square plate, 1 m/s, 4 s).
//! `leapfrog` converges at second order, the other modes at first order.

mod common;

use pushval_model::{DynamicModel, Simulator};
use pushval_rapier2d::{
    tail_mean_omega, DetailedEngine, EngineSettings, FrictionVelocity, Precision, RapierSimulator,
};

const DTS: [f64; 4] = [1e-2, 5e-3, 2.5e-3, 1e-3];

/// (dt, max position error, max θ error, steady-ω relative error of segment 1).
fn sweep(precision: Precision, mode: FrictionVelocity) -> Vec<(f64, f64, f64, f64)> {
    let problem = common::plate(1.0, false);
    let reference = DynamicModel::default().simulate(&problem).unwrap();
    let w_ref = tail_mean_omega(&problem, &reference, 0.2)[1].unwrap();
    DTS.iter()
        .map(|&dt| {
            let sim = RapierSimulator::new(EngineSettings {
                dt,
                precision,
                friction_velocity: mode,
                ..Default::default()
            });
            let run = sim.run(&problem).unwrap();
            let (p, t) = common::max_errors(&run.trajectory, &reference);
            let w = run.segment_tail_omega[1];
            println!(
                "{} {:10} dt={dt:.1e} pos={p:.2e} theta={t:.2e} omega_rel={:.2e} drift={:.1e}",
                precision.as_str(),
                mode.as_str(),
                ((w - w_ref) / w_ref).abs(),
                run.max_joint_drift
            );
            (dt, p, t, ((w - w_ref) / w_ref).abs())
        })
        .collect()
}

/// Observed order of the position error between the coarsest and finest dt.
fn order(rows: &[(f64, f64, f64, f64)]) -> f64 {
    let (a, b) = (rows[0], rows[rows.len() - 1]);
    (a.1 / b.1).ln() / (a.0 / b.0).ln()
}

#[test]
fn leapfrog_f64_is_second_order_and_most_accurate() {
    let rows = sweep(Precision::F64, FrictionVelocity::Leapfrog);
    let last = rows[rows.len() - 1];
    assert!(last.1 < 5e-6, "position error {:.2e}", last.1);
    assert!(last.2 < 2e-6, "theta error {:.2e}", last.2);
    assert!(last.3 < 1e-6, "steady omega error {:.2e}", last.3);
    let q = order(&rows);
    assert!((1.9..2.1).contains(&q), "order {q}");
    for w in rows.windows(2) {
        let q = (w[0].1 / w[1].1).ln() / (w[0].0 / w[1].0).ln();
        assert!(
            (1.9..2.1).contains(&q),
            "order {q} between dt {} and {}",
            w[0].0,
            w[1].0
        );
    }
    let midpoint = sweep(Precision::F64, FrictionVelocity::Midpoint);
    for (a, b) in rows.iter().zip(&midpoint) {
        assert!(a.1 < b.1, "leapfrog must beat midpoint at dt {}", a.0);
    }
}

#[test]
fn midpoint_f64_is_first_order() {
    let rows = sweep(Precision::F64, FrictionVelocity::Midpoint);
    let last = rows[rows.len() - 1];
    assert!(last.1 < 3e-4, "position error {:.2e}", last.1);
    assert!(last.2 < 2e-4, "theta error {:.2e}", last.2);
    assert!(last.3 < 1e-4, "steady omega error {:.2e}", last.3);
    let q = order(&rows);
    assert!((0.8..1.3).contains(&q), "order {q}");
    for w in rows.windows(2) {
        assert!(w[1].1 < w[0].1, "error must fall with dt");
    }
}

#[test]
fn constraint_f64_converges() {
    let rows = sweep(Precision::F64, FrictionVelocity::Constraint);
    let last = rows[rows.len() - 1];
    assert!(last.1 < 2e-3, "position error {:.2e}", last.1);
    assert!(last.3 < 1e-4, "steady omega error {:.2e}", last.3);
    let q = order(&rows);
    assert!((0.8..1.3).contains(&q), "order {q}");
}

#[test]
fn body_f64_converges_but_is_least_accurate() {
    let body = sweep(Precision::F64, FrictionVelocity::Body);
    let constraint = sweep(Precision::F64, FrictionVelocity::Constraint);
    let (b, c) = (body[body.len() - 1], constraint[constraint.len() - 1]);
    assert!(b.1 < 1e-2, "position error {:.2e}", b.1);
    assert!(b.3 < 5e-3, "steady omega error {:.2e}", b.3);
    assert!(
        b.3 > 10.0 * c.3,
        "body mode should be much less accurate in steady ω"
    );
    let q = order(&body);
    assert!((0.8..1.3).contains(&q), "order {q}");
}

#[test]
fn f32_matches_f64_down_to_its_roundoff() {
    for mode in FrictionVelocity::ALL {
        let rows32 = sweep(Precision::F32, mode);
        let rows64 = sweep(Precision::F64, mode);
        for (a, b) in rows32.iter().zip(&rows64) {
            // f32 adds a round-off floor of about 1e-4 m over 4000 steps.
            assert!(
                a.1 < b.1 * 1.5 + 2e-4,
                "{}: f32 {:.2e} vs f64 {:.2e}",
                mode.as_str(),
                a.1,
                b.1
            );
        }
    }
}
