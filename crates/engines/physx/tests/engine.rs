//! The PhysX models as engine plug-ins: names, versions, settings, and a run
//! through the `Engine` trait.

mod common;

use pushval_engine::EngineOptions;
use pushval_physx::{models, PhysxSettings, ENGINE_CRATE, PHYSX_SDK_VERSION};

#[test]
fn three_models_one_per_friction_type() {
    let names: Vec<&str> = models().iter().map(|m| m.name).collect();
    assert_eq!(
        names,
        [
            "physx_patch",
            "physx_two_directional",
            "physx_one_directional"
        ]
    );
    for m in models() {
        let e = m.default_engine();
        assert_eq!(e.name(), m.name);
        assert_eq!(e.adapter(), "pushval-physx");
        assert_eq!(e.engine_crate(), ENGINE_CRATE);
        assert!(e.version().contains("0.19.0") && e.version().contains(PHYSX_SDK_VERSION));
        assert_eq!(e.default_dt(), 1e-3);
        let s = e.settings(2e-3);
        assert_eq!(s["dt"], 2e-3);
        assert!(s["engine"].as_str().unwrap().contains("PhysX 5.1.3"));
        assert_eq!(s["contacts"], "welded");
        assert!(s["label"].as_str().unwrap().contains("dt=0.002"));
    }
}

#[test]
fn the_scenario_dt_is_kept() {
    let opts = EngineOptions {
        dt: Some(5e-4),
        ..Default::default()
    };
    for m in models() {
        let e = (m.build)(&opts).unwrap();
        assert_eq!(e.default_dt(), 5e-4);
    }
}

#[test]
fn settings_are_checked() {
    for (s, field) in [
        (
            PhysxSettings {
                dt: 0.0,
                ..Default::default()
            },
            "physx dt",
        ),
        (
            PhysxSettings {
                position_iterations: 0,
                ..Default::default()
            },
            "physx position_iterations",
        ),
        (
            PhysxSettings {
                cm_height: -1.0,
                ..Default::default()
            },
            "physx cm_height",
        ),
    ] {
        let e = s.check().unwrap_err().to_string();
        assert!(e.contains(field), "{e}");
    }
}

#[cfg(feature = "physx")]
#[test]
fn a_run_through_the_trait_samples_the_problem() {
    use common::*;
    let p = problem(&plate(), push(0.5, PHI, 0.5));
    for m in models() {
        let e = m.default_engine();
        assert!(e.availability().is_ok());
        let r = e.run(&p, 1e-3).unwrap();
        assert_eq!(r.steps, 500);
        assert_eq!(r.trajectory.samples.len(), p.sample_times().len());
        assert_eq!(r.trajectory.model, m.name);
        let last = r.trajectory.samples.last().unwrap();
        // Moved with the pusher, 0.25 m in 0.5 s.
        assert!((last.x.hypot(last.y) - 0.25).abs() < 0.02, "{last:?}");
        assert!(r.diagnostics["max_joint_drift"].as_f64().unwrap() < 1e-4);
    }
}
