//! MuJoCo's creep law: the steady slip of a body held by a tangential load
//! below the friction limit, in closed form from MuJoCo's regularised
//! constraint formulation (no MuJoCo needed for it; the engine side is the
//! feature-gated `sim`).
//!
//! # Derivation
//!
//! MuJoCo finds the constraint forces f of a step from the convex problem
//! whose dual reads `min ½ fᵀ(A + R)f + fᵀ(a₀ − a_ref)` over the friction
//! cone, with `A = J M⁻¹ Jᵀ`, a₀ the unconstrained constraint-space
//! acceleration, R the diagonal regulariser and the reference acceleration
//! `a_ref = −B v − K d (pos − margin)` row by row. Inside the cone (MuJoCo's
//! "bottom zone", every row quadratic) the optimum is the linear solve
//! `(A + R) f = a_ref − a₀`, so the constraint acceleration `a = A f + a₀`
//! obeys
//!
//! ```text
//! a = a_ref − R f .
//! ```
//!
//! In a steady creep every contact row has `a = 0` (constant velocity, constant
//! penetration): **`R f = a_ref`, whatever A is** — the mass matrix drops
//! out, and so does the time step of the semi-implicit Euler update
//! `v ← v + h a` (a fixed point of it has `a = 0`). What is left is MuJoCo's
//! own bookkeeping (`mj_makeImpedance`, `engine_core_constraint.c`):
//!
//! * impedance `d = d(δ)` of the contact from `solimp` at the penetration δ
//!   ([`impedance`]);
//! * `B = 2/(d_max t_c)`, `K = 1/(d_max² t_c² ζ²)` from `solref = (t_c, ζ)`,
//!   with `t_c` raised to `2h` (the `refsafe` clamp) and `d_max = solimp[1]`;
//! * `R = (1 − d)/d · Â`, Â MuJoCo's approximate diagonal of A: for a contact
//!   of one free body on the world, the body's translational `invweight0`,
//!   `1/m` (the whole body's, not a share per contact);
//! * elliptic cone: `R_t = R_n / impratio` on the two friction rows, and
//!   friction rows have `K = 0`, so `a_ref,t = −B u` (u the slip velocity);
//! * pyramidal cone: the 4 edge rows `n ± μ t_j` carry Â(1 + μ²) and all get
//!   `R_py = 2 μ² R_edge / impratio = 2 μ²(1 + μ²) (1 − d)/d · Â / impratio`.
//!
//! **Elliptic.** `R_t f_t = −B u` with `f_t` balancing the tangential load F
//! of the contact: `u = F R_t / B`, i.e.
//!
//! ```text
//! u* = F · (1 − d)/d · Â · d_max t_c / (2 impratio)        (|F| < μN)
//! ```
//!
//! The penetration δ (hence d) comes from the normal row, `R_n N = K d δ`
//! (independent of F).
//!
//! **Pyramidal.** Edge forces `f_{j±} ≥ 0` along `n ± μ t_j`; the edge rows'
//! `a_ref = −B(±μ u_j) + K d δ`. With all four edges active,
//! `R_py f_{j±} = K d δ ∓ B μ u_j`, so each pair carries `N/2` and
//! `F_j = μ(f_{j−} − f_{j+}) = 2 B μ² u_j / R_py`:
//!
//! ```text
//! u_j = F_j R_py / (2 μ² B) = F_j (1 + μ²) (1 − d)/d · Â / (B impratio)
//! ```
//!
//! — the elliptic law times `(1 + μ²)`, valid while `|F_j| ≤ μN/2` on both
//! tangent axes (the opposing edge keeps a non-negative force). Beyond, the
//! edge `n + μ t_1` (for `F_1 > 0`) lifts off (`f = 0`); with the other three
//! active, `f_{1−} = F_1/μ`, the cross pair shares `N − F_1/μ`, and
//!
//! ```text
//! u_1 = R_py (3 F_1/μ − N) / (2 B μ),   u_2 = F_2 R_py / (2 μ² B),
//! K d δ = R_py (N − F_1/μ) / 2 ,
//! ```
//!
//! continuous at `F_1 = μN/2` and three times steeper: along a tangent axis
//! the creep is `ε (1 + μ²) g(λ)` with `g = λ` up to `λ = 1/2` and
//! `g = 3λ − 1` above. It holds while `|F_1| + |F_2| < μN` (the pyramid's L1
//! diamond); beyond, there is no steady state: the body slides. (The
//! penetration changes with the load here, so d does too.)
//!
//! In the regularised-friction picture `f = μN u / max(|u|, ε)`, the elliptic
//! law is a slip scale **`ε = μ N R_t / B`** ([`slip_scale`]): `u* = λ ε` for
//! a load `λ μ N`. With `Â = 1/m` and `N = m g / n` for n equal contacts,
//! `ε = μ g (1 − d) d_max t_c / (2 n d impratio)`: creep falls as 1/impratio,
//! grows with the time constant, and falls with the number of contacts that
//! share the body's weight.
//!
//! Units: SI (m, s, N, kg).
//!
//! The closed form (`creep`, `slip_scale`, …) is in `law`, the scene and
//! what a run measures in `scene`, the MuJoCo run itself in the
//! feature-gated `sim`; the report written from a ladder's CSV is the
//! root package's (`pushval::study::creep_law`).

mod law;
mod scene;
#[cfg(feature = "mujoco")]
mod sim;

pub use law::{
    clamped_solimp, creep, impedance, reference, slip_scale, CreepInput, CreepPrediction,
    CreepRegime, Reference, MJ_MAXIMP, MJ_MINIMP,
};
pub use scene::{
    hold_time, CreepCase, CreepMeasurement, CreepScene, CHATTER_HEIGHT_STD, SLIDING_SPEED,
};

/// Runs the creep scene in MuJoCo: settles the plate, switches on the load
/// `load_fraction · μ W` along world angle `direction` (rad) at the centre of
/// mass (for [`CreepCase::Sliding`] the plate also gets that speed along the
/// load), holds it for `hold_time` s and measures the slip over the last
/// 40 %. Without the `mujoco` feature:
/// [`ModelError::Integration`](pushval_model::ModelError::Integration) with
/// [`crate::UNAVAILABLE`].
pub fn measure(
    scene: &CreepScene,
    case: CreepCase,
    load_fraction: f64,
    direction: f64,
    hold_time: f64,
) -> Result<CreepMeasurement, pushval_model::ModelError> {
    #[cfg(feature = "mujoco")]
    {
        sim::measure(scene, case, load_fraction, direction, hold_time)
    }
    #[cfg(not(feature = "mujoco"))]
    {
        let _ = (scene, case, load_fraction, direction, hold_time);
        Err(pushval_model::ModelError::Integration {
            t: 0.0,
            reason: crate::UNAVAILABLE.into(),
        })
    }
}
