//! `world.rs` compiled against `rapier2d-f64`.
pub(crate) use rapier2d_f64 as rapier;
// One source, compiled once per precision on purpose.
#[allow(clippy::duplicate_mod)]
#[path = "world.rs"]
pub(crate) mod world;
