//! Friction laws in closed form, one library for every engine.
//!
//! A law answers [`FrictionLaw`]: the steady ω it predicts for a push
//! segment of a [`pushval_model::Problem`], whether ω = 0 turns, locks or
//! holds from one side ([`LawClass`]), and, for laws that move load between
//! the supports, the loads in that steady state. [`Coulomb`] is the analytic
//! model's own law.
//!
//! One module per family, each the closed form of what one engine's solver
//! does to friction (derived from its source; no engine is needed to
//! evaluate it): [`idioms`] (2-D game-engine idioms), [`rapier3d`],
//! [`mujoco`], [`physx`], [`box2d`], [`avian`], [`jolt`], [`drake`]. Every law is a
//! value with its parameters; an engine model holds the one it follows.
//!
//! [`catalog`] lists them all by a stable name, with parameters and the
//! compiled-in models that declare each; an outside engine may declare any
//! of them (`law = "NAME"` and `law_params = { .. }` in `pushval.toml`).
//!
//! What it is not: an engine (it depends on none) or the analytic model
//! (`pushval-model`, whose moment balance the laws substitute into).
#![warn(missing_docs)]

mod catalog;
mod law;

pub mod avian;
pub mod box2d;
pub mod drake;
pub mod idioms;
pub mod jolt;
pub mod mujoco;
pub mod physx;
pub mod rapier3d;

pub use catalog::{catalog, law_entry, LawEntry, Loads, ParamError, ParamKind, ParamSpec};
pub use law::{
    coulomb_steady, on_loads, Coulomb, FrictionLaw, LawClass, LawSteady, COULOMB, GRAVITY,
};
