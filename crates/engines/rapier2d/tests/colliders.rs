//! `EngineSettings::colliders`: the scene with massless colliders that
//! interact with nothing moves exactly like the collider-free default scene
//! (only rapier's broad and narrow phases get work; the bench `rapier_step`
//! measures what that costs). The check is on the trajectory, bit for bit,
//! at switches, from rest and in both precisions; it cannot see the
//! collision stages themselves, so a second test shows that the colliders
//! are built (a degenerate outline is refused only when they are).

mod common;

use pushval_model::Trajectory;
use pushval_rapier2d::{drive, DetailedEngine, EngineSettings, Precision, RapierSimulator};

fn run(from_rest: bool, precision: Precision, colliders: bool) -> Trajectory {
    RapierSimulator::new(EngineSettings {
        precision,
        colliders,
        ..Default::default()
    })
    .run(&common::plate(1.0, from_rest))
    .unwrap()
    .trajectory
}

#[test]
fn colliders_leave_the_motion_unchanged() {
    for precision in [Precision::F64, Precision::F32] {
        for from_rest in [false, true] {
            let a = run(from_rest, precision, false);
            let b = run(from_rest, precision, true);
            assert_eq!(a.samples.len(), b.samples.len());
            // Bit for bit: the colliders add zero mass and no force, and the
            // bodies' integration does not depend on the collision stages.
            for (p, q) in a.samples.iter().zip(&b.samples) {
                assert_eq!(
                    (p.t, p.x, p.y, p.theta, p.omega),
                    (q.t, q.x, q.y, q.theta, q.omega),
                    "{precision:?} from_rest={from_rest}"
                );
            }
        }
    }
}

#[test]
fn colliders_are_built_from_the_outline() {
    let problem = common::plate(1.0, false);
    let on_a_line = [[0.0, 0.0], [0.1, 0.0], [0.2, 0.0]];
    let with = RapierSimulator::new(EngineSettings {
        colliders: true,
        ..Default::default()
    });
    assert!(with
        .start_with_outline(&problem, &on_a_line)
        .and_then(|s| drive(s, &problem))
        .is_err());
    // Without colliders the outline is not used.
    assert!(RapierSimulator::default()
        .start_with_outline(&problem, &on_a_line)
        .and_then(|s| drive(s, &problem))
        .is_ok());
    // The plate's own outline (its corners, about the centre of mass).
    let square = [
        [-0.125, -0.125],
        [0.125, -0.125],
        [0.125, 0.125],
        [-0.125, 0.125],
    ];
    let a = RapierSimulator::default().run(&problem).unwrap();
    let b = drive(
        with.start_with_outline(&problem, &square).unwrap(),
        &problem,
    )
    .unwrap();
    assert_eq!(a.steps, b.steps);
    for (p, q) in a.trajectory.samples.iter().zip(&b.trajectory.samples) {
        assert_eq!((p.x, p.y, p.theta), (q.x, q.y, q.theta));
    }
}
