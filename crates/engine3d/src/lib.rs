//! The pushing problem as a 3-D rapier scene (skeleton; see the crate description).
