//! Without the `jolt` feature the crate builds and says so.
#![cfg(not(feature = "jolt"))]

mod common;

use common::*;
use pushval_jolt::{models, JoltSettings, JoltSimulator, AVAILABLE, UNAVAILABLE};
use pushval_model::Simulator;

#[test]
#[allow(clippy::assertions_on_constants)]
fn reports_unavailable() {
    assert!(!AVAILABLE);
    for m in models() {
        let why = m.default_engine().availability().unwrap_err();
        assert!(why.contains("--features jolt"), "{why}");
    }
    let err = JoltSimulator::new(JoltSettings::default())
        .simulate(&problem(&plate(), push(0.5, PHI, 1.0)))
        .unwrap_err();
    assert!(err.to_string().contains(UNAVAILABLE), "{err}");
}
