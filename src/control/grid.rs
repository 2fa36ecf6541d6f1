//! The control study's grid: its scene, speeds, goal counts, plan length,
//! control period and rules (shared by `study`, its README writer
//! `write_up` and the adaptive study).

use pushval_control::At;

/// The study's scene: a shipped scenario.
pub const SCENE: &str = "paper-square-v1.0.toml";
/// The speeds every goal of the full grid is reachable at on the dynamic
/// model (m/s): the goal list is the one the study has always had (and the
/// adaptive study shares), though the grid runs [`GRID_SPEEDS`] only.
pub const SPEEDS: [f64; 3] = [0.1, 0.5, 1.0];
/// The speeds of the full grid (m/s). 0.1 m/s is left out: its slide is
/// at most v²/(2μg) ≈ 1 mm, so both rules judge alike there (module doc).
pub const GRID_SPEEDS: [f64; 2] = [0.5, 1.0];
/// The speed of the quick grid (m/s).
pub const QUICK_SPEEDS: [f64; 1] = [1.0];
/// Goals of the full grid.
pub const GOALS: usize = 20;
/// Goals of the quick grid.
pub const QUICK_GOALS: usize = 3;
/// Pushes per plan.
pub const SEGMENTS: usize = 6;
/// The MPC's control period (s).
pub const PERIOD: f64 = 0.02;
/// The rule the goals are chosen by, and the default of `plan` and `loop`:
/// at rest, after the slide.
pub const AT: pushval_control::At = pushval_control::At::Rest;
/// The rules of the grid: judged at the release (the plan aimed at the
/// release pose, as `--at release`) and at rest (aimed at rest).
pub const RULES: [At; 2] = At::ALL;
