//! The public API, with or without the `mujoco` feature.

use pushval_model::Simulator;
use pushval_mujoco::{Cone, MujocoSettings, MujocoSimulator};

#[test]
fn names_labels_defaults() {
    assert_eq!(Cone::Pyramidal.as_str(), "pyramidal");
    assert_eq!(Cone::Elliptic.as_str(), "elliptic");
    let s = MujocoSettings::default();
    assert_eq!(s.timestep, 1e-3);
    assert_eq!(s.label(), "mujoco[pyramidal,dt=0.001,impratio=1,noslip=0]");
    let e = MujocoSimulator {
        settings: MujocoSettings {
            cone: Cone::Elliptic,
            ..s
        },
    };
    assert_eq!(e.name(), "mujoco_elliptic");
    assert!(MujocoSettings { timestep: 0.0, ..s }.check().is_err());
}

/// The scene text holds what the crate docs promise.
#[test]
fn scene_text() {
    let body = pushval_model::Body::new(
        2.0,
        0.05,
        pushval_model::Vec2::new(-0.1, 0.0),
        &[pushval_model::Support {
            position: pushval_model::Vec2::new(0.1, 0.0),
            friction: 1.0,
        }],
    )
    .unwrap();
    let p = pushval_model::Problem {
        body,
        limits: Default::default(),
        pushes: vec![pushval_model::Push {
            duration: 1.0,
            speed: 0.1,
            phi: 0.0,
        }],
        initial: Default::default(),
        switching: Default::default(),
        sample_dt: 0.01,
        release: None,
    };
    let x = pushval_mujoco::scene::mjcf(&p, &MujocoSettings::default(), &[0.7]);
    assert!(x.contains(r#"diaginertia="0.025 0.025 0.05""#), "{x}");
    assert!(x.contains(r#"friction="0.7 0 0" condim="3" priority="1""#));
    assert!(x.contains(r#"<geom name="floor" type="plane" size="0 0 1" friction="0 0 0""#));
    assert!(x.contains("<connect site1=\"contact\" site2=\"tip\""));
}
