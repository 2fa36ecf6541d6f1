//! What the protocol tests share.

use pushval_engine::{EngineOptions, SceneFrame};
use pushval_scenario::Scenario;

/// A scenario's engine options as the command line's registry makes them
/// (`pushval::registry::engine_options`): its `[engine]` table with the scene
/// the file describes.
pub fn options(sc: &Scenario) -> EngineOptions {
    let scene = SceneFrame {
        center_of_mass: [sc.center_of_mass.x, sc.center_of_mass.y],
        polygon: sc.polygon.iter().map(|p| [p.x, p.y]).collect(),
        gravity: sc.gravity,
        normal_forces: sc.supports.iter().map(|s| s.load).collect(),
    };
    EngineOptions::from_table(sc.engine.dt, sc.engine.values.clone(), Some(scene))
}
