//! Closed-loop control of a pushed plate: push plans made on a model
//! ([`plan`]), model-predictive control with any engine session as the plant
//! ([`mpc`]), and the predictors both are built on ([`predict`]).
//!
//! A plan is `N` pushes of equal duration at one speed: the unknowns are the
//! `N` directions φ (object frame) and the total duration. The planner
//! drives the predicted final pose onto the goal by damped Gauss–Newton
//! (Levenberg–Marquardt) on those `N + 1` numbers: three residuals (x, y and
//! the angle times a length), so each step is the minimum-norm one. See
//! docs/closed-loop.md.
//!
//! The library knows nothing of a command line: its errors are typed
//! ([`ControlError`]) and name quantities, not flags; the loop reports each
//! control period to an observer ([`mpc::Observer`]). The plant is any
//! [`pushval_engine::EngineSession`] the caller owns.

pub mod error;
pub mod estimate;
pub mod mpc;
pub mod plan;
pub mod predict;
pub mod sensor;
pub mod stats;

use std::f64::consts::PI;

pub use error::ControlError;
pub use predict::{ModelKind, ModelPredictor, Predictor};
use pushval_model::{Problem, Vec2};

/// When a plan or a loop is judged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum At {
    /// When the plate has stopped after the pusher let go (the slide to rest
    /// in the prediction and in the plant).
    #[default]
    Rest,
    /// When the last push ends, the plate still moving.
    Release,
}

impl At {
    /// Both rules, the release's first (the order a study reports them in).
    pub const ALL: [At; 2] = [At::Release, At::Rest];

    /// `rest` or `release`.
    pub fn as_str(&self) -> &'static str {
        match self {
            At::Rest => "rest",
            At::Release => "release",
        }
    }

    /// The rule named `name` ([`At::as_str`]).
    pub fn from_name(name: &str) -> Option<Self> {
        [At::Rest, At::Release]
            .into_iter()
            .find(|a| a.as_str() == name)
    }
}

/// The goal of a push: the centre of mass's world position and the angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Goal {
    /// World x of the centre of mass (m).
    pub x: f64,
    /// World y of the centre of mass (m).
    pub y: f64,
    /// Object angle (rad).
    pub theta: f64,
}

impl std::fmt::Display for Goal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "x {:.4} m, y {:.4} m, θ {:.4} rad",
            self.x, self.y, self.theta
        )
    }
}

/// What counts as reaching a goal: the final position within `position`
/// (m) and the angle within `angle` (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reach {
    /// Largest distance of the centre of mass from the goal (m).
    pub position: f64,
    /// Largest angle error (rad).
    pub angle: f64,
}

impl Default for Reach {
    /// 20 mm and 5°.
    fn default() -> Self {
        Self {
            position: 0.02,
            angle: 5.0_f64.to_radians(),
        }
    }
}

impl Reach {
    /// Whether a pose with these errors reaches the goal.
    pub fn holds(&self, position_error: f64, angle_error: f64) -> bool {
        position_error <= self.position && angle_error <= self.angle
    }
}

/// The predicted final pose's errors from the goal: (distance (m), |angle
/// difference| (rad)).
pub fn pose_errors(x: f64, y: f64, theta: f64, goal: &Goal) -> (f64, f64) {
    ((x - goal.x).hypot(y - goal.y), (theta - goal.theta).abs())
}

/// The directions φ (rad, object frame) in which the pusher pushes the
/// object: the cone between the contact's inward normals, widened by the
/// contact's friction angle at an edge (one normal) where the pusher may
/// slant. Returns (lowest, highest) with lowest < highest.
pub fn push_cone(problem: &Problem) -> (f64, f64) {
    let (a, b) = problem.limits.normals;
    let ang = |n: &Vec2| n.y.atan2(n.x);
    if a.norm_squared() == 0.0 || b.norm_squared() == 0.0 {
        return (-PI / 2.0, PI / 2.0);
    }
    let (lo, mut hi) = (ang(&a), ang(&b));
    // The shorter way round from a to b.
    while hi - lo > PI {
        hi -= 2.0 * PI;
    }
    while hi - lo < -PI {
        hi += 2.0 * PI;
    }
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let widen = problem
        .limits
        .mu
        .map_or(PI / 8.0, |mu| mu.atan())
        .min(PI / 4.0);
    if hi - lo < 1e-9 {
        (lo - 0.9 * widen, hi + 0.9 * widen)
    } else {
        // A corner: the cone between its two normals, widened by half the
        // contact's friction angle either side (the pusher may slant
        // a little while its force stays in the friction cone; the
        // model's checks say where it does not).
        (lo - 0.5 * widen, hi + 0.5 * widen)
    }
}

/// The length that weighs an angle error against a position error: the
/// radius of gyration about the centre of mass (m).
pub fn gyration_length(problem: &Problem) -> f64 {
    (problem.body.inertia_cm() / problem.body.mass()).sqrt()
}
