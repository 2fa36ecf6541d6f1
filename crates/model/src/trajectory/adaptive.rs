//! One segment of the dynamic model by an adaptive embedded pair:
//! Dormand–Prince 5(4) or DOP853, with dense output at the samples.

use super::segment::{pose_of, Closed, Recorder, SegmentRun};
use crate::integrate::{self, State};
use crate::ModelError;

/// One attempted step of either method. It lives for one step on the
/// stack; boxing the larger variant would allocate on every step.
#[allow(clippy::large_enum_variant)]
enum Attempt {
    Five(integrate::Attempt),
    Eight(integrate::dop853::Attempt),
}

impl Attempt {
    /// The error norm (acceptable when ≤ 1), the state at the step's end and
    /// the derivative there.
    fn outcome(&self) -> (f64, State, State) {
        match self {
            Attempt::Five(a) => (a.err, a.y1, a.k7),
            Attempt::Eight(a) => (a.err, a.y1, a.k13),
        }
    }
}

/// Dense output of either method over one accepted step.
enum AnyDense {
    Five(integrate::Dense),
    Eight(integrate::dop853::Dense),
    /// No sample in the step: nothing built.
    None,
}

impl AnyDense {
    fn eval(&self, t: f64) -> State {
        match self {
            AnyDense::Five(d) => d.eval(t),
            AnyDense::Eight(d) => d.eval(t),
            AnyDense::None => unreachable!("dense output is built for every step holding a sample"),
        }
    }
}

/// Integrates `seg` from the state `y` (derivative `k1`) with DOP853
/// (`eighth`) or Dormand–Prince 5(4) at tolerance `tol`, sampling on the
/// way: the state where it stopped, and the closed form the segment
/// continues in if that was before the segment's end. `h_carry` (step in s,
/// distance from the steady ω in rad/s) is read for the first step and
/// written at the end, for the next integrated segment.
#[allow(clippy::too_many_arguments)]
pub(super) fn integrate<F: FnMut(&State) -> State>(
    seg: &SegmentRun,
    rec: &mut Recorder,
    rhs: &mut F,
    mut y: State,
    mut k1: State,
    tol: f64,
    eighth: bool,
    h_carry: &mut Option<(f64, f64)>,
) -> Result<(State, Option<Closed>), ModelError> {
    let (t0, t1) = (seg.t0, seg.t1);
    // Relative tolerance on ω only: the angle and the position depend on the
    // choice of frame, and their error must not (invariance under rigid
    // motion).
    let rtol = [0.0, tol, 0.0, 0.0];
    let order = if eighth { 7 } else { 4 };
    let next_step = |h: f64, err: f64| {
        if eighth {
            integrate::next_step8(h, err)
        } else {
            integrate::next_step(h, err)
        }
    };
    // A switch changes ω̇ by orders of magnitude: the step carried over from
    // a settled segment would be rejected (12 evaluations), a fresh estimate
    // costs one. On a relaxation the local error is proportional to the
    // distance from the steady state, so the step carried over shrinks by
    // (distance then / distance now)^(1/8); otherwise the usual starting-step
    // estimate.
    let dev_new = seg.root().map(|r| (y[1] - r).abs());
    let mut h = match (*h_carry, dev_new) {
        (Some((hc, dev_old)), Some(dn)) if dev_old > 0.0 && dn > 0.0 => {
            hc * (dev_old / dn).powf(1.0 / (order as f64 + 2.0)).min(1.0)
        }
        _ => {
            rec.out.stats.rhs_evals += 1;
            let h0 = integrate::initial_step(rhs, &y, &k1, tol, &rtol, order, t1 - t0);
            h_carry.map_or(h0, |(hc, _)| hc.min(h0))
        }
    };
    let mut t = t0;
    let tail = 'steps: {
        while t < t1 {
            let mut landing = t + h >= t1 - 1e-12 * t1.abs().max(1.0);
            let mut hh = if landing { t1 - t } else { h };
            if let Some(wp) = seg.pivot {
                // Aim at the pivot by the local ω̇ (smooth on this side).
                let t_hit = (wp - y[1]) / k1[1];
                if t_hit > 0.0 && t_hit < hh {
                    hh = t_hit;
                    landing = false;
                }
            }
            let attempt = if eighth {
                rec.out.stats.rhs_evals += 12;
                Attempt::Eight(integrate::dop853::attempt(rhs, &y, &k1, hh, tol, &rtol))
            } else {
                rec.out.stats.rhs_evals += 6;
                Attempt::Five(integrate::dp5_attempt(rhs, &y, &k1, hh, tol, &rtol))
            };
            let (err, y1, k_next) = attempt.outcome();
            if err <= 1.0 {
                let t_new = if landing { t1 } else { t + hh };
                // DOP853's interpolant costs three evaluations: build it only for
                // steps that hold a sample.
                // Neither interpolant is built for a step that holds no sample.
                let dense = match &attempt {
                    _ if !rec.sample_due(seg, t_new) => AnyDense::None,
                    Attempt::Five(a) => AnyDense::Five(a.dense(t, &y, hh)),
                    Attempt::Eight(a) => {
                        rec.out.stats.rhs_evals += 3;
                        AnyDense::Eight(a.dense(rhs, t, &y, hh))
                    }
                };
                rec.samples_until(seg, t_new, |ts| pose_of(&dense.eval(ts)));
                let w_before = y[1];
                y = y1;
                k1 = k_next;
                t = t_new;
                rec.out.stats.steps += 1;
                let stalled = seg.pivot.is_some() && hh < 1e-12 * t.abs().max(1.0);
                if seg.landed(t, &y, w_before, stalled, rec.out.stats.steps)? {
                    break 'steps Some(Closed::Tail(seg.pivot_tail_from(t, &y)));
                }
                let hn = next_step(hh, err);
                if !landing || hn < h {
                    h = hn;
                }
                if let Some(tail) = seg.tail_after_step(t, &y) {
                    break 'steps Some(tail);
                }
            } else {
                rec.out.stats.rejected += 1;
                h = next_step(hh, err);
                if !(h > 1e-14 * t.abs().max(1.0)) {
                    return Err(ModelError::Integration {
                        t,
                        reason: format!("step size underflow (h = {h:e} s)"),
                    });
                }
            }
        }
        None
    };
    let dev = seg.root().map_or(f64::NAN, |r| (y[1] - r).abs());
    *h_carry = Some((h, dev));
    Ok((y, tail))
}
