//! The transient of ω alone over a segment, by adaptive steps clamped to
//! the stretch before the steady state.

use super::SegmentDynamics;

impl SegmentDynamics {
    /// ω (rad/s) after `duration` (s) of the segment's flow ω̇ = G(ω)/I_P
    /// from `omega`: the dynamic model's transient with the push held. ω
    /// may run away (no steady state ahead): it is still followed for
    /// `duration`. None where it leaves the finite numbers.
    ///
    /// The flow is one-dimensional and autonomous, so ω moves monotonically
    /// towards [`Self::attractor_from`] and never passes it. Adaptive
    /// Dormand–Prince 5(4) steps ([`crate::integrate`]) evaluate G only on
    /// the stretch between the start and that steady state: at a pivot G
    /// jumps, and an integrator that stepped past it would chatter; clamped,
    /// ω reaches the pivot in finite time and stays.
    pub fn advance(&self, omega: f64, duration: f64) -> Option<f64> {
        use crate::integrate::{dp5_attempt, initial_step, next_step, State};
        if duration <= 0.0 {
            return Some(omega);
        }
        // Without a steady state ahead, ω runs away: nothing to stop at.
        let target = self.attractor_from(omega).map(|r| r.omega);
        if target == Some(omega) {
            return target;
        }
        let (lo, hi) = match target {
            Some(t) => (omega.min(t), omega.max(t)),
            None => (f64::NEG_INFINITY, f64::INFINITY),
        };
        let mut f = |y: &State| [0.0, self.omega_dot(y[1].clamp(lo, hi)), 0.0, 0.0];
        let rtol = [0.0, 1e-10, 0.0, 0.0];
        let atol = 1e-12 * (1.0 + omega.abs().max(target.unwrap_or(0.0).abs()));
        let mut y = [0.0, omega, 0.0, 0.0];
        let mut k1 = f(&y);
        let mut h = initial_step(&mut f, &y, &k1, atol, &rtol, 5, duration);
        let mut t = 0.0;
        // A bound on the work, never reached by a flow that settles: each
        // accepted step is at least as long as the flow's fastest time scale.
        for _ in 0..1_000_000 {
            if t >= duration {
                return Some(y[1]);
            }
            let step = h.min(duration - t);
            let a = dp5_attempt(&mut f, &y, &k1, step, atol, &rtol);
            if a.err <= 1.0 {
                t = if step == duration - t {
                    duration
                } else {
                    t + step
                };
                y[1] = a.y1[1].clamp(lo, hi);
                if Some(y[1]) == target || !y[1].is_finite() {
                    return y[1].is_finite().then_some(y[1]);
                }
                k1 = f(&y);
            }
            h = next_step(step, a.err);
        }
        y[1].is_finite().then_some(y[1])
    }
}
