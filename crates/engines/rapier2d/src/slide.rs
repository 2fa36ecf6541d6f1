//! The friction idioms over one step of the free slide (the pusher gone),
//! in f64 for both precisions' worlds.
//!
//! * The **impulse idioms** (disk, box, rows on the disk) are friction
//!   *joints* at the supports, and the engines that use them (Box2D's and
//!   Chipmunk's friction joints, rapier's joint motors, Bullet's rows) solve
//!   all the supports' joints together by sequential impulses: each joint's
//!   accumulated impulse `λᵢ` is set, in turn, to its law on the slip the
//!   other joints leave it, `λᵢ ← clamp(λᵢ − Kᵢ⁻¹uᵢ)`, sweep after sweep.
//!   [`idiom_impulses`] does exactly that with
//!   [`support_force`](crate::idioms::support_force) (the law with `Δt` the
//!   slide step): its fixed point is the idiom's own law at every support on
//!   the step's end velocity. While a support slides its impulse is the cap
//!   `F Δt` along `−Kᵢ⁻¹u` (disk) or per axis (box); once the caps hold the
//!   plate, the joints stop it within the step, as the joints' stopping
//!   impulse says, and the plate is at rest the step after.
//!
//!   Applying each support's law on its own to the step's start velocity
//!   (Jacobi, as the pushing steps do) does not stop: on the seed's square
//!   the four stopping impulses together remove 2.5 times the plate's
//!   translation and 3 times its spin per step (disk; 1.6 and 4.8 for the
//!   box: [`pushval_laws::idioms::stop_gain`]'s γ > 2), so once the caps
//!   stop binding the slip reverses and grows back to the cap every step:
//!   a chatter at about `F Δt/m` (1e-3 m/s), never below the rest rule.
//!
//! * The **regularised laws** are forces (`−F u/v_s` below the slip speed
//!   `v_s`, `−F tanh(|u|/v_s) u/|u|`) and are applied as the pushing steps
//!   apply them: each support's force on the step's start velocity. Below
//!   `v_s` the slip decays by the factor `1 − Δt μg/v_s` per step for a
//!   translation (`1 − γ` for a spin): geometrically, not in a step (0.51
//!   per step at the defaults, 1 ms and 0.01 m/s); a slip speed so small
//!   that `Δt μg/v_s > 2` would make the decay chatter, and the slide says
//!   so by not stopping.

use crate::idioms::{support_force, FrictionModel, LawContext};

/// Largest number of sweeps over the supports per step.
pub const SWEEPS: usize = 500;

/// The sweeps stop once no support's impulse changed by more than this
/// share of the largest cap `μᵢNᵢh`.
pub const SWEEP_TOL: f64 = 1e-13;

/// The impulses (N s, world frame) the impulse idiom `model` applies at the
/// supports over a slide step of `ctx.dt` (s), the plate (mass and inertia
/// of `ctx`) moving at `v` (m/s, centre of mass) and `omega` (rad/s) at
/// the step's start. `supports` gives each support's offset from the
/// centre of mass (m, world frame) and its friction `μᵢNᵢ` (N). The
/// accumulated impulses of sequential-impulse sweeps (module docs); the
/// regularised laws and Coulomb are not impulse idioms (None).
pub fn idiom_impulses(
    model: FrictionModel,
    ctx: &LawContext,
    v: [f64; 2],
    omega: f64,
    supports: &[([f64; 2], f64)],
) -> Option<Vec<[f64; 2]>> {
    let per_axis = match model {
        FrictionModel::ImpulseDisk => false,
        FrictionModel::ImpulseBox | FrictionModel::ImpulseRowsDisk => true,
        _ => return None,
    };
    let (inv_m, inv_i, h) = (1.0 / ctx.mass, 1.0 / ctx.inertia_cm, ctx.dt);
    let cap_max = supports.iter().map(|s| s.1 * h).fold(0.0, f64::max);
    let mut acc = vec![[0.0; 2]; supports.len()];
    let (mut vel, mut w) = (v, omega);
    for _ in 0..SWEEPS {
        let mut change: f64 = 0.0;
        for (&(r, friction), a) in supports.iter().zip(acc.iter_mut()) {
            let u = [vel[0] - w * r[1], vel[1] + w * r[0]];
            // The slip the others leave: this joint's own impulse taken
            // out, through its full 2×2 inverse mass K (disk) or through
            // the rows' scalar ones (box, rows: each row is its own
            // constraint).
            let (kxx, kxy, kyy) = (
                inv_m + inv_i * r[1] * r[1],
                -inv_i * r[0] * r[1],
                inv_m + inv_i * r[0] * r[0],
            );
            let own = if per_axis {
                [kxx * a[0], kyy * a[1]]
            } else {
                [kxx * a[0] + kxy * a[1], kxy * a[0] + kyy * a[1]]
            };
            let rest = [u[0] - own[0], u[1] - own[1]];
            let f = support_force(model, rest, r, friction, ctx);
            let p = [f[0] * h, f[1] * h];
            let d = [p[0] - a[0], p[1] - a[1]];
            vel = [vel[0] + inv_m * d[0], vel[1] + inv_m * d[1]];
            w += inv_i * (r[0] * d[1] - r[1] * d[0]);
            *a = p;
            change = change.max(d[0].hypot(d[1]));
        }
        if change <= SWEEP_TOL * cap_max {
            break;
        }
    }
    Some(acc)
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: f64 = 0.125;
    const MU_G: f64 = 0.5 * 9.81;

    /// The seed plate (1 kg, 0.25 m square) at angle 0, its corners with
    /// equal friction μmg/4.
    fn seed(dt: f64) -> (LawContext, Vec<([f64; 2], f64)>) {
        let ctx = LawContext {
            mass: 1.0,
            inertia_cm: (2.0 * A) * (2.0 * A) / 6.0,
            dt,
        };
        let sup = [(-A, -A), (A, -A), (A, A), (-A, A)]
            .iter()
            .map(|&(x, y)| ([x, y], MU_G / 4.0))
            .collect();
        (ctx, sup)
    }

    fn after(
        ctx: &LawContext,
        sup: &[([f64; 2], f64)],
        p: &[[f64; 2]],
        v: [f64; 2],
        w: f64,
    ) -> ([f64; 2], f64) {
        let mut vel = v;
        let mut om = w;
        for ((r, _), q) in sup.iter().zip(p) {
            vel[0] += q[0] / ctx.mass;
            vel[1] += q[1] / ctx.mass;
            om += (r[0] * q[1] - r[1] * q[0]) / ctx.inertia_cm;
        }
        (vel, om)
    }

    /// A slow plate (the caps not reached) is stopped within the step by
    /// the joints together, whatever its motion; a fast one keeps moving,
    /// each support's impulse at its cap.
    #[test]
    fn the_joints_stop_a_slow_plate_in_one_step_and_cap_a_fast_one() {
        for model in [
            FrictionModel::ImpulseDisk,
            FrictionModel::ImpulseBox,
            FrictionModel::ImpulseRowsDisk,
        ] {
            let (ctx, sup) = seed(1e-3);
            let (v, w) = ([2e-4, -1e-4], 3e-3);
            let p = idiom_impulses(model, &ctx, v, w, &sup).unwrap();
            let (v1, w1) = after(&ctx, &sup, &p, v, w);
            let speed = v1[0].hypot(v1[1]) + w1.abs() * A * 2f64.sqrt();
            assert!(speed < 1e-12, "{model:?}: {speed} m/s left");
            let (v, w) = ([1.0, 0.3], 5.0);
            let p = idiom_impulses(model, &ctx, v, w, &sup).unwrap();
            for (q, (_, f)) in p.iter().zip(&sup) {
                let cap = f * ctx.dt;
                let n = if model == FrictionModel::ImpulseBox {
                    q[0].abs().max(q[1].abs())
                } else {
                    q[0].hypot(q[1])
                };
                assert!(
                    (n - cap).abs() <= 1e-12 * cap,
                    "{model:?}: {n} against {cap}"
                );
            }
        }
    }

    /// Pure translation along x on the square: no moment (the supports
    /// are symmetric), and the impulses are the laws' sliding ones: the
    /// box's rows each at the cap against the motion (Coulomb's μmg h),
    /// the disk's each `F h` along `−Kᵢ⁻¹u` whose share along the motion
    /// is `cos∠(Kᵢ⁻¹x̂, x̂)` = (1 + ¼)/√(2 (1 + 1/16)) at the corners (the
    /// eigen-masses m along the diagonal, m/4 across it).
    #[test]
    fn a_sliding_translation_gets_the_laws_sliding_impulses() {
        let (ctx, sup) = seed(1e-3);
        let cos = 1.25 / (2.0f64 * (1.0 + 1.0 / 16.0)).sqrt();
        for (model, share) in [
            (FrictionModel::ImpulseBox, 1.0),
            (FrictionModel::ImpulseDisk, cos),
        ] {
            let p = idiom_impulses(model, &ctx, [1.0, 0.0], 0.0, &sup).unwrap();
            let (v1, w1) = after(&ctx, &sup, &p, [1.0, 0.0], 0.0);
            let dv = MU_G * ctx.dt * share;
            assert!(
                (1.0 - v1[0] - dv).abs() < 1e-12,
                "{model:?}: {}",
                1.0 - v1[0]
            );
            assert!(
                v1[1].abs() < 1e-15 && w1.abs() < 1e-12,
                "{model:?}: {v1:?} {w1}"
            );
        }
    }

    #[test]
    fn the_regularised_laws_and_coulomb_are_not_impulse_idioms() {
        let (ctx, sup) = seed(1e-3);
        for model in [
            FrictionModel::Coulomb,
            FrictionModel::RegularisedLinear { slip_speed: 0.01 },
            FrictionModel::RegularisedTanh { slip_speed: 0.01 },
        ] {
            assert!(idiom_impulses(model, &ctx, [1.0, 0.0], 0.0, &sup).is_none());
        }
    }
}
