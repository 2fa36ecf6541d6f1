//! The supports' Coulomb friction over one step of the free slide, without
//! chattering at the stop: the engines that apply friction themselves
//! (rapier2d, Box2D) take each step's support impulses from here.
//!
//! A Coulomb force applied as a fixed force `μᵢNᵢ` per step overshoots once
//! a support's slip is smaller than what one step's friction removes: the
//! slip reverses every step and the plate never rests. Here the impulses
//! `Pᵢ` of a step of length `h` are implicit Coulomb friction: each within
//! its disc `|Pᵢ| ≤ μᵢNᵢh`, they leave a support's slip zero at the step's
//! end where the disc allows it and otherwise oppose its end-of-step slip
//! with the full `μᵢNᵢh` (the most dissipative impulses within the discs).
//! A support whose slip one step would reverse is stopped, not reversed,
//! and a plate that one step can stop comes to rest exactly. Far from the
//! stop this is Coulomb's law with the slip direction taken at the step's
//! end: first order in the step, like the engines' own integration.
//!
//! The impulses are solved jointly by projected Gauss–Seidel over the
//! supports, each update a gradient step of length `1/kᵢ`, `kᵢ = 1/m +
//! |rᵢ|²/I` (the largest slip change per unit impulse at the support),
//! projected on the disc. Its fixed points are exactly the Coulomb ones; a
//! step with the support's full 2×2 inverse mass would not give them (the
//! disc is round in impulse, not in that metric: on a square plate it
//! leaves a sliding plate 14 % too little friction).

/// Largest number of sweeps over the supports per step.
pub const SWEEPS: usize = 500;

/// The sweeps stop once no support's impulse changed by more than this
/// share of the largest cap `μᵢNᵢh`.
pub const SWEEP_TOL: f64 = 1e-13;

/// The supports' friction impulses (N s, world frame) over a slide step of
/// a plate of mass `mass` (kg) and inertia `inertia_cm` (kg m²) moving at
/// `v` (m/s, its centre of mass) and `omega` (rad/s) at the step's start.
/// `supports` gives each support's offset from the centre of mass (m,
/// world frame) and its cap `μᵢNᵢh` (N s).
pub fn coulomb_impulses(
    mass: f64,
    inertia_cm: f64,
    v: [f64; 2],
    omega: f64,
    supports: &[([f64; 2], f64)],
) -> Vec<[f64; 2]> {
    let (inv_m, inv_i) = (1.0 / mass, 1.0 / inertia_cm);
    let cap_max = supports.iter().map(|s| s.1).fold(0.0, f64::max);
    let mut acc = vec![[0.0; 2]; supports.len()];
    let (mut vel, mut w) = (v, omega);
    for _ in 0..SWEEPS {
        let mut change: f64 = 0.0;
        for (&(r, cap), a) in supports.iter().zip(acc.iter_mut()) {
            if cap <= 0.0 {
                continue;
            }
            let u = [vel[0] - w * r[1], vel[1] + w * r[0]];
            let k = inv_m + inv_i * (r[0] * r[0] + r[1] * r[1]);
            let mut p = [a[0] - u[0] / k, a[1] - u[1] / k];
            let n = p[0].hypot(p[1]);
            if n > cap {
                p = [p[0] * cap / n, p[1] * cap / n];
            }
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
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square plate's corners (m) and equal caps for μ m g h.
    fn square(a: f64, mu_g_h: f64) -> Vec<([f64; 2], f64)> {
        [(-a, -a), (a, -a), (a, a), (-a, a)]
            .iter()
            .map(|&(x, y)| ([x, y], mu_g_h / 4.0))
            .collect()
    }

    /// Sliding fast: the full friction μmgh against the motion, no moment
    /// (the supports are symmetric about the centre of mass).
    #[test]
    fn a_sliding_plate_gets_the_full_friction() {
        let (m, a, h) = (1.3, 0.1, 1e-3);
        let cap = 0.5 * 9.81 * m * h;
        let sup = square(a, cap);
        let p = coulomb_impulses(m, m * 4.0 * a * a / 6.0, [0.6, -0.8], 0.0, &sup);
        let total = p.iter().fold([0.0, 0.0], |s, q| [s[0] + q[0], s[1] + q[1]]);
        assert!((total[0] + 0.6 * cap).abs() < 1e-12 * cap, "{total:?}");
        assert!((total[1] - 0.8 * cap).abs() < 1e-12 * cap, "{total:?}");
        let moment: f64 = p
            .iter()
            .zip(&sup)
            .map(|(q, s)| s.0[0] * q[1] - s.0[1] * q[0])
            .sum();
        assert!(moment.abs() < 1e-12 * cap * a);
    }

    /// Slower than one step's friction removes: the plate stops exactly
    /// (no reversal), sliding and spinning alike.
    #[test]
    fn a_plate_one_step_can_stop_comes_to_rest() {
        let (m, a, h) = (1.0, 0.125, 1e-3);
        let i = m * 4.0 * a * a / 6.0;
        let sup = square(a, 0.5 * 9.81 * m * h);
        for (v, w) in [
            ([1e-3, 0.0], 0.0),
            ([1e-3, -2e-3], 0.02),
            ([0.0, 0.0], 0.03),
        ] {
            let p = coulomb_impulses(m, i, v, w, &sup);
            let total = p.iter().fold([0.0, 0.0], |s, q| [s[0] + q[0], s[1] + q[1]]);
            let moment: f64 = p
                .iter()
                .zip(&sup)
                .map(|(q, s)| s.0[0] * q[1] - s.0[1] * q[0])
                .sum();
            let (v1, w1) = ([v[0] + total[0] / m, v[1] + total[1] / m], w + moment / i);
            assert!(
                v1[0].hypot(v1[1]) < 1e-12 && w1.abs() < 1e-10,
                "{v1:?} {w1}"
            );
        }
    }
}
