//! The pushing problem as a MuJoCo scene (skeleton; see the crate description).

/// True when this build links MuJoCo (feature `mujoco`).
pub const AVAILABLE: bool = cfg!(feature = "mujoco");
