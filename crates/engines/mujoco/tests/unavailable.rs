//! Without the `mujoco` feature the crate builds and says so.
#![cfg(not(feature = "mujoco"))]

use pushval_model::{Body, Initial, Problem, Push, Simulator, Support, Switching, Vec2};
use pushval_mujoco::{MujocoSettings, MujocoSimulator, AVAILABLE, UNAVAILABLE};

#[test]
#[allow(clippy::assertions_on_constants)]
fn reports_unavailable() {
    assert!(!AVAILABLE);
    let body = Body::new(
        1.0,
        0.01,
        Vec2::new(-0.1, 0.0),
        &[Support {
            position: Vec2::new(0.1, 0.0),
            friction: 1.0,
        }],
    )
    .unwrap();
    let p = Problem {
        body,
        limits: Default::default(),
        pushes: vec![Push {
            duration: 1.0,
            speed: 0.1,
            phi: 0.0,
        }],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    };
    let err = MujocoSimulator::new(MujocoSettings::default())
        .simulate(&p)
        .unwrap_err();
    assert!(err.to_string().contains(UNAVAILABLE), "{err}");
}
