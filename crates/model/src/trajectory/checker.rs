//! The checks of the dynamic model's assumptions, accumulated over a run.

use super::{Assumptions, Violation};
use crate::dynamic::{SegmentDynamics, SteadyState};
use crate::{perp, Problem, Push, RootKind, Vec2};

/// Accumulates the assumption checks over a run.
pub(super) struct Checker<'a> {
    problem: &'a Problem,
    out: Assumptions,
    /// False: every check is skipped (`DynamicModel::check_assumptions`).
    pub(super) enabled: bool,
}

impl<'a> Checker<'a> {
    pub(super) fn new(problem: &'a Problem, enabled: bool) -> Self {
        Self {
            problem,
            out: Assumptions {
                min_support_speed: f64::INFINITY,
                ..Default::default()
            },
            enabled,
        }
    }

    /// The checks at one sample: ω at time `t` (s) in segment `segment`.
    #[inline(always)]
    pub(super) fn sample(&mut self, seg: &SegmentDynamics, omega: f64, t: f64, segment: usize) {
        if self.enabled {
            self.check(seg, omega, t, segment);
        }
    }

    fn check(&mut self, seg: &SegmentDynamics, omega: f64, t: f64, segment: usize) {
        let lim = &self.problem.limits;
        let f = seg.pusher_force(omega);
        let fm = f.norm();
        let angle = lim.cone_angle(&f);
        let o = &mut self.out;
        o.max_force = o.max_force.max(fm);
        o.max_cone_angle = o.max_cone_angle.max(angle);
        let gt = |a: f64, b: f64| a > b;
        if angle > std::f64::consts::FRAC_PI_2 + 1e-9 {
            Violation::record(&mut o.pulling, t, angle, segment, None, gt);
        }
        if let Some(mu) = lim.mu {
            if angle > mu.atan() + 1e-9 {
                Violation::record(&mut o.contact_slip, t, angle, segment, None, gt);
            }
        }
        if let Some(fmax) = lim.max_force {
            if fm > fmax {
                Violation::record(&mut o.force_limit, t, fm, segment, None, gt);
            }
        }
        if seg.speed() > 0.0 {
            let (u, i) = seg.min_support_speed(omega);
            o.min_support_speed = o.min_support_speed.min(u);
            if u < 1e-6 * seg.speed() {
                Violation::record(&mut o.sticking, t, u, segment, Some(i), |a, b| a < b);
            }
        }
    }

    /// Where ω tends from the start `t` (s) of a moving segment with ω =
    /// `omega`: nowhere (`target` None: it runs away), or to a pivot (that
    /// support will stick).
    pub(super) fn target(
        &mut self,
        target: Option<SteadyState>,
        t: f64,
        omega: f64,
        segment: usize,
    ) {
        if !self.enabled {
            return;
        }
        match target {
            None => {
                Violation::record(
                    &mut self.out.runaway,
                    t,
                    omega.abs(),
                    segment,
                    None,
                    |a, b| a > b,
                );
            }
            Some(SteadyState {
                kind: RootKind::Pivot { support, .. },
                ..
            }) => {
                Violation::record(
                    &mut self.out.sticking,
                    t,
                    0.0,
                    segment,
                    Some(support),
                    |a, b| a < b,
                );
            }
            _ => {}
        }
    }

    /// The impulse of a switch at `t` (s) from `before` at ω = `w0` to
    /// `after` at ω = `w1` (rad/s): it must not pull.
    pub(super) fn switch(
        &mut self,
        before: Option<&Push>,
        w0: f64,
        after: &Push,
        w1: f64,
        t: f64,
        segment: usize,
    ) {
        if !self.enabled {
            return;
        }
        let pc = self.problem.body.contact();
        let vcm = |p: Option<&Push>, w: f64| {
            p.map(|p| p.velocity()).unwrap_or_else(Vec2::zeros) - perp(&pc) * w
        };
        let j = (vcm(Some(after), w1) - vcm(before, w0)) * self.problem.body.mass();
        let scale = self.problem.body.mass() * (after.speed + before.map_or(0.0, |p| p.speed));
        if j.norm() > 1e-9 * scale.max(1e-300) {
            let angle = self.problem.limits.cone_angle(&j);
            if angle > std::f64::consts::FRAC_PI_2 + 1e-9 {
                Violation::record(
                    &mut self.out.pulling_impulse,
                    t,
                    angle,
                    segment,
                    None,
                    |a, b| a > b,
                );
            }
        }
    }

    pub(super) fn finish(mut self) -> Assumptions {
        if !self.out.min_support_speed.is_finite() {
            self.out.min_support_speed = 0.0;
        }
        self.out
    }
}
