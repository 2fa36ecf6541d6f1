//! The three gated figures ([`Figures`]) and what the dt ladder aims for on
//! each: a share of the scenario's `[tolerance]` number, or [`AUTO_TARGET`]
//! for an auto figure.

use pushval_scenario::{Limit, Scenario};

/// The three gated figures: largest centre-of-mass distance (m), largest
/// angle difference (rad), largest relative steady-ω error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Figures {
    /// m
    pub position_max: f64,
    /// rad
    pub theta_max: f64,
    /// relative
    pub omega_steady_rel: f64,
}

/// What the dt ladder aims for on an `"auto"` figure: the engine's
/// self-convergence estimate at the chosen step is at most this. Small enough
/// that model errors of a fraction of a per cent move the trajectory past the
/// resulting tolerance (results/gate_power.csv), large enough that a
/// second-order engine reaches it at 1/2000 s or so on the shipped scenes.
pub const AUTO_TARGET: Figures = Figures {
    position_max: 2e-6,
    theta_max: 2e-6,
    omega_steady_rel: 2e-6,
};

/// The scenario's `[tolerance]` limits in [`Figures`] order.
pub(super) fn limits(sc: &Scenario) -> [Limit; 3] {
    let t = &sc.tolerance;
    [t.position_max, t.theta_max, t.omega_steady_rel]
}

/// What the dt ladder aims for per figure: a share of the scenario's number,
/// or [`AUTO_TARGET`] for an auto figure.
pub fn ladder_targets(sc: &Scenario, fraction: f64) -> Figures {
    let l = limits(sc);
    let pick = |l: Limit, auto: f64| l.value().map_or(auto, |v| fraction * v);
    Figures {
        position_max: pick(l[0], AUTO_TARGET.position_max),
        theta_max: pick(l[1], AUTO_TARGET.theta_max),
        omega_steady_rel: pick(l[2], AUTO_TARGET.omega_steady_rel),
    }
}
