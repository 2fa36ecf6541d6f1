//! Without the `physx` feature the crate builds and says so.
#![cfg(not(feature = "physx"))]

mod common;

use common::*;
use pushval_model::Simulator;
use pushval_physx::{models, PhysxSettings, PhysxSimulator, AVAILABLE, UNAVAILABLE};

#[test]
#[allow(clippy::assertions_on_constants)]
fn reports_unavailable() {
    assert!(!AVAILABLE);
    for m in models() {
        let why = m.default_engine().availability().unwrap_err();
        assert_eq!(
            why,
            "build with --features physx (needs clang++: apt-get install clang)"
        );
    }
    let err = PhysxSimulator::new(PhysxSettings::default())
        .simulate(&problem(&plate(), push(0.5, PHI, 1.0)))
        .unwrap_err();
    assert!(err.to_string().contains(UNAVAILABLE), "{err}");
}
