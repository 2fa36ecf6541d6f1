//! Closed loop: push plans made on a model (`pushval plan`), model-predictive
//! control with any engine as the plant (`pushval loop`), and the study of
//! both across every engine (`pushval control-study`).
//!
//! A plan is `N` pushes of equal duration at one speed: the unknowns are the
//! `N` directions φ (object frame) and the total duration. The planner
//! drives the predicted final pose onto the goal by damped Gauss–Newton
//! (Levenberg–Marquardt) on those `N + 1` numbers: three residuals (x, y and
//! the angle times a length), so each step is the minimum-norm one. See
//! docs/closed-loop.md.

pub mod cli;
pub mod mpc;
pub mod plan;
pub mod study;

use std::f64::consts::PI;

use anyhow::{bail, Context};
use pushval_model::{Problem, Vec2};

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

impl Goal {
    /// Parses `X,Y,THETA` (m, m, rad).
    pub fn parse(text: &str) -> anyhow::Result<Self> {
        let v = parse_numbers(text, 3, "--goal X,Y,THETA (m, m, rad)")?;
        Ok(Self {
            x: v[0],
            y: v[1],
            theta: v[2],
        })
    }
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
    /// Parses `POS,ANGLE` (m, rad).
    pub fn parse(text: &str) -> anyhow::Result<Self> {
        let v = parse_numbers(text, 2, "--tolerance POS,ANGLE (m, rad)")?;
        if v.iter().any(|&x| x <= 0.0) {
            bail!("--tolerance POS,ANGLE: both must be > 0, got {text}");
        }
        Ok(Self {
            position: v[0],
            angle: v[1],
        })
    }

    /// Whether a pose with these errors reaches the goal.
    pub fn holds(&self, position_error: f64, angle_error: f64) -> bool {
        position_error <= self.position && angle_error <= self.angle
    }
}

fn parse_numbers(text: &str, n: usize, what: &str) -> anyhow::Result<Vec<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .with_context(|| format!("{what}: `{}` is not a number", s.trim()))
        })
        .collect::<anyhow::Result<_>>()?;
    if v.len() != n {
        bail!(
            "{what}: expected {n} numbers separated by commas, got {}",
            v.len()
        );
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        bail!("{what}: {x} is not finite");
    }
    Ok(v)
}

/// The predicted final pose's errors from the goal: (distance (m), |angle
/// difference| (rad)).
pub fn pose_errors(x: f64, y: f64, theta: f64, goal: &Goal) -> (f64, f64) {
    ((x - goal.x).hypot(y - goal.y), (theta - goal.theta).abs())
}

/// Which model predicts the plan's outcome.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Predictor {
    /// The dynamic model (inertia, impulsive switches).
    #[default]
    Dynamic,
    /// The quasi-static kinematic model (ω constant per push).
    Kinematic,
    /// The ellipsoidal limit-surface model (ω constant per push).
    LimitSurface,
}

impl Predictor {
    /// Every predictor, in order.
    pub const ALL: [Predictor; 3] = [
        Predictor::Dynamic,
        Predictor::Kinematic,
        Predictor::LimitSurface,
    ];

    /// The name used on the command line and in outputs.
    pub fn as_str(&self) -> &'static str {
        match self {
            Predictor::Dynamic => "dynamic",
            Predictor::Kinematic => "kinematic",
            Predictor::LimitSurface => "limit_surface",
        }
    }

    /// Parses a name of [`Predictor::as_str`].
    pub fn parse(text: &str) -> anyhow::Result<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.as_str() == text)
            .with_context(|| {
                format!("--predictor: `{text}` is not one of dynamic, kinematic, limit_surface")
            })
    }
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
