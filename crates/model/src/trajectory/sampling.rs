//! Sample bookkeeping shared by the models: which sample times fall in a
//! segment, and the sample of a pose.

use crate::tail::{Tail, TailCursor, TailPose};
use crate::{Problem, Rotor, Sample, Vec2};

/// The run's sample times and the next one to hand out.
pub(super) struct Sampler {
    pub(super) times: Vec<f64>,
    pub(super) next: usize,
    eps: f64,
}

impl Sampler {
    pub(super) fn new(problem: &Problem) -> Self {
        Self::at(problem.sample_times(), 1e-9 * problem.sample_dt)
    }

    /// No sample at all (allocates nothing).
    pub(super) fn none() -> Self {
        Self::at(Vec::new(), 0.0)
    }

    /// The sample times `times` (s, increasing); times within `eps` (s) of
    /// a switch belong to the segment that starts there.
    pub(super) fn at(times: Vec<f64>, eps: f64) -> Self {
        Self {
            times,
            next: 0,
            eps,
        }
    }

    /// The next sample time if it lies at or before `t` and inside the segment
    /// ending at `t_end` (the last segment owns its end time).
    pub(super) fn due(&self, t: f64, t_end: f64, last: bool) -> Option<f64> {
        let ts = *self.times.get(self.next)?;
        let inside = last || ts < t_end - self.eps;
        (inside && ts <= t + self.eps).then_some(ts)
    }
}

/// The sample at time `t` from the contact point `c` and the angle; `rotor`
/// serves `R(θ)` (samples come in order, so θ moves little between them).
pub(super) fn pose_sample(
    rotor: &mut Rotor,
    t: f64,
    c: Vec2,
    theta: f64,
    omega: f64,
    pc: &Vec2,
) -> Sample {
    let (s, co) = rotor.sin_cos(theta);
    let p = c - Vec2::new(co * pc.x - s * pc.y, s * pc.x + co * pc.y);
    Sample {
        t,
        x: p.x,
        y: p.y,
        theta,
        omega,
    }
}

/// Samples a closed-form tail at the sample times due up to `t1` (the end of
/// its segment; `last` for the last segment, which owns its end time) and
/// returns its pose at `t1`, evaluated afresh there: the same whatever
/// samples came before.
pub(super) fn sample_tail(
    tail: Tail,
    sampler: &mut Sampler,
    t1: f64,
    last: bool,
    pc: Vec2,
    out: &mut Vec<Sample>,
) -> TailPose {
    let mut cursor = TailCursor::new(tail);
    let first = sampler.next;
    // Every sample `due` would hand out up to t1 (times increase).
    let (eps, times) = (sampler.eps, &sampler.times[first..]);
    sampler.next += times.partition_point(|&ts| (last || ts < t1 - eps) && ts <= t1 + eps);
    if sampler.next > first {
        cursor.fill(&sampler.times[first..sampler.next], pc, out);
    }
    cursor.end(t1)
}
