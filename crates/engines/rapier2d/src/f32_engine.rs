//! `world.rs` compiled against `rapier2d` (f32).
pub(crate) use rapier2d as rapier;
// One source, compiled once per precision on purpose.
#[allow(clippy::duplicate_mod)]
#[path = "world.rs"]
pub(crate) mod world;
