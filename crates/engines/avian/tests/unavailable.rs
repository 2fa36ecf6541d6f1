//! Without the `avian` feature the crate builds and says so.
#![cfg(not(feature = "avian"))]

mod common;

use pushval_avian::{Avian2dSimulator, Avian3dSimulator, UNAVAILABLE};
use pushval_model::Simulator;

#[test]
fn simulators_report_the_missing_feature() {
    let p = common::paper(0.5, 1.0);
    for err in [
        Avian2dSimulator::default().simulate(&p).unwrap_err(),
        Avian3dSimulator::default().simulate(&p).unwrap_err(),
    ] {
        assert!(err.to_string().contains(UNAVAILABLE), "{err}");
    }
}
