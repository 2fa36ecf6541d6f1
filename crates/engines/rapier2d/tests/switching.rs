//! The engine's behaviour at switches and at an impulsive start: a rigid body
//! keeps its angular momentum about the contact point, so ω jumps.

mod common;

use pushval_model::{Problem, Switching};
use pushval_rapier2d::{DetailedEngine, EngineSettings, FrictionVelocity, RapierSimulator};

#[test]
fn omega_jump_at_switch_conserves_contact_momentum() {
    for mode in FrictionVelocity::ALL {
        let problem = common::plate(1.0, false);
        let run = RapierSimulator::new(EngineSettings {
            friction_velocity: mode,
            ..Default::default()
        })
        .run(&problem)
        .unwrap();
        let seg = &run.trajectory.segments;
        let (w0, w1) = (seg[0].omega_end, seg[1].omega_start);
        let expect = problem.omega_after_switch(Some(&problem.pushes[0]), &problem.pushes[1], w0);
        let mut cont = problem.clone();
        cont.switching = Switching::Continuous;
        let continuous = cont.omega_after_switch(Some(&problem.pushes[0]), &problem.pushes[1], w0);
        println!(
            "{}: before {w0:.6} after {w1:.6} H-conserving {expect:.6}",
            mode.as_str()
        );
        // The leapfrog mode closes the segment on the velocity at the
        // switch, so the jump starts from ω(t_s−), not a mid-step ω.
        let tol = if mode == FrictionVelocity::Leapfrog {
            2e-5
        } else {
            2e-3
        };
        assert!(
            (w1 - expect).abs() < tol * expect.abs(),
            "{}: {w1} vs {expect}",
            mode.as_str()
        );
        assert!((w1 - continuous).abs() > 0.5, "the jump is not continuous");
        // H itself, before and after.
        let h0 = Problem::contact_momentum(&problem.body, Some(&problem.pushes[0]), w0);
        let h1 = Problem::contact_momentum(&problem.body, Some(&problem.pushes[1]), w1);
        assert!((h0 - h1).abs() < 1e-4, "H {h0} -> {h1}");
    }
}

#[test]
fn impulsive_start_from_rest_jumps_to_zero_momentum() {
    // An off-centre push so that H = 0 gives a non-zero ω.
    let mut problem = common::plate(1.0, true);
    problem.pushes[0].phi += 0.3;
    let run = RapierSimulator::default().run(&problem).unwrap();
    let w = run.trajectory.segments[0].omega_start;
    let expect = problem.omega_after_switch(None, &problem.pushes[0], 0.0);
    println!("start: {w:.6} vs {expect:.6}");
    assert!(expect.abs() > 0.1);
    assert!((w - expect).abs() < 2e-3 * expect.abs(), "{w} vs {expect}");
    assert_eq!(
        run.trajectory.samples[0].omega, w,
        "the t = 0 sample is just after the start"
    );
}
