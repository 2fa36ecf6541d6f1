//! One segment of the dynamic model by classical RK4 at a fixed step,
//! sampled by cubic Hermite interpolation (kept for benchmarks).

use super::segment::{pose_of, Closed, Recorder, SegmentRun};
use crate::integrate::{self, State};
use crate::ModelError;

/// Integrates `seg` from the state `y` (derivative `k1`) in equal steps of
/// at most `dt` (s), sampling on the way: the state where it stopped, and
/// the closed form the segment continues in if that was before the
/// segment's end.
pub(super) fn integrate<F: FnMut(&State) -> State>(
    seg: &SegmentRun,
    rec: &mut Recorder,
    rhs: &mut F,
    mut y: State,
    mut k1: State,
    dt: f64,
) -> Result<(State, Option<Closed>), ModelError> {
    let (t0, t1) = (seg.t0, seg.t1);
    let n = ((t1 - t0) / dt - 1e-9).ceil().max(1.0) as usize;
    let h = (t1 - t0) / n as f64;
    let mut t = t0;
    for step in 0..n {
        let y1 = integrate::rk4_step(rhs, &y, &k1, h);
        let k2 = rhs(&y1);
        rec.out.stats.rhs_evals += 4;
        let t_new = if step + 1 == n {
            t1
        } else {
            t0 + (step + 1) as f64 * h
        };
        rec.samples_until(seg, t_new, |ts| {
            pose_of(&integrate::hermite(t, t_new - t, &y, &k1, &y1, &k2, ts))
        });
        let w_before = y[1];
        y = y1;
        k1 = k2;
        t = t_new;
        rec.out.stats.steps += 1;
        if seg.landed(t, &y, w_before, false, rec.out.stats.steps)? {
            // First order in h here: RK4 is kept for benchmarks.
            return Ok((y, Some(Closed::Tail(seg.pivot_tail_from(t, &y)))));
        }
        if let Some(tail) = seg.tail_after_step(t, &y) {
            return Ok((y, Some(tail)));
        }
    }
    Ok((y, None))
}
