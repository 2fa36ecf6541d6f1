//! Analytic models of an object pushed at a single point while it slides on
//! support points with Coulomb friction.
//!
//! Three models answer the same question (how does the object move for a
//! piecewise-constant pusher velocity?):
//!
//! * [`dynamic`]: the full rigid-body model. The pusher prescribes the contact
//!   velocity; the angular acceleration follows from the moment balance about
//!   the contact point, including the inertial term `m v_c ω (p_c · n_φ)`.
//!   For a constant input, ω̇ depends on ω alone, so the steady angular
//!   velocity is the root of a scalar function ([`SegmentDynamics::steady_states`]).
//! * [`kinematic`]: Kurisu & Yoshikawa's quasi-static model, `ω = v_c ψ(φ)`,
//!   with ψ the root of the friction moment alone.
//! * [`kappa`]: the scaling factor `κ = ω* / (v_c ψ)` between the two, exactly
//!   and as a series in the Froude number.
//! * [`track`]: online estimators of μ, the centre of friction and I_cm from
//!   a stream of pose samples, and the resultant friction force.
//! * [`limit_surface`]: the ellipsoidal limit-surface approximation used in
//!   quasi-static planning (Goyal, Ruina & Papadopoulos; Lynch, Maekawa & Tanie).
//! * [`slide`]: the free slide after the pusher lets go, to rest (Coulomb
//!   friction at every support, pivots about a sticking support included).
//! * [`format`]: the one trajectory format (`t,x,y,theta[,omega][,model]`),
//!   its streaming reader and its writer.
//!
//! Conventions: SI units, f64, object frame with its origin at the centre of
//! mass, `D = [[0,−1],[1,0]]`, `a × b = a_x b_y − a_y b_x`.
//!
//! This crate opens no file and runs no process ([`format`] reads and writes
//! through the caller's `BufRead` / `Write`), and depends on no physics engine.
#![warn(missing_docs)]

mod arc;
mod body;
#[allow(clippy::excessive_precision, dead_code)]
mod dop853_tables;
pub mod dynamic;
mod error;
pub mod format;
pub mod integrate;
pub mod kappa;
pub mod kinematic;
pub mod limit_surface;
mod problem;
mod rotor;
pub mod slide;
mod tail;
pub mod track;
mod trajectory;

pub use arc::{arc_advance, sinc_versc};
pub use body::{Body, Push, Support};
pub use dynamic::{InertialTerm, RootKind, SegmentDynamics, SteadyState};
pub use error::ModelError;
pub use kappa::{kappa_exact, kappa_series, KappaSeries};
pub use problem::{ContactLimits, Initial, Problem, Release, Simulator, Switching};
pub use rotor::Rotor;
pub use slide::{
    slide_to_rest, PivotEnd, PivotPhase, Slide, SlideOptions, SlideReport, SlideState,
};
pub use trajectory::{
    Assumptions, DynamicModel, FinalState, Integrator, KinematicModel, LimitSurfaceModel,
    PushCache, Sample, SegmentReport, SolverStats, Trajectory, Violation,
};

/// A 2-D vector in metres (or m/s, N, as the context says).
pub type Vec2 = nalgebra::Vector2<f64>;

/// `a × b = a_x b_y − a_y b_x` for 2-D vectors.
#[inline]
pub fn cross(a: &Vec2, b: &Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// `D a`: `a` turned by +90°.
#[inline]
pub fn perp(a: &Vec2) -> Vec2 {
    Vec2::new(-a.y, a.x)
}

/// `R(θ) a`: `a` rotated by θ (rad).
#[inline]
pub fn rotate(theta: f64, a: &Vec2) -> Vec2 {
    let (s, c) = theta.sin_cos();
    Vec2::new(c * a.x - s * a.y, s * a.x + c * a.y)
}
