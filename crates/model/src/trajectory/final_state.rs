//! The dynamic model asked only for what the caller needs: the state at
//! the end of the schedule ([`DynamicModel::final_state`]), or samples at
//! the caller's own times ([`DynamicModel::sample_at`]). `sample_at` takes
//! the same path as [`Simulator::simulate`] (the same steps, switches and
//! closed forms), so its samples are the full run's at those times;
//! `final_state` ends each settling segment by the series in `δ`
//! (`tail::ends`), cheaper than the sampled series in `E`, so it agrees
//! with the full run's last sample to within the tolerance.

use super::dynamic_model::DynamicModel;
use super::push_cache::PushCache;
use super::sampling::Sampler;
use super::segment::Recorder;
use super::{SolverStats, Trajectory};
use crate::{perp, ModelError, Problem, Simulator, Vec2};

/// The state of the object at the end of a push schedule: what a predictor
/// needs to score a plan or to start the next one from.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FinalState {
    /// End time (s): the schedule's duration.
    pub t: f64,
    /// World x of the centre of mass (m).
    pub x: f64,
    /// World y of the centre of mass (m).
    pub y: f64,
    /// Object angle, unwrapped (rad).
    pub theta: f64,
    /// Angular velocity (rad/s).
    pub omega: f64,
    /// World x velocity of the centre of mass (m/s) at the end of the last
    /// push, the pusher still in contact.
    pub vx: f64,
    /// World y velocity of the centre of mass (m/s), as `vx`.
    pub vy: f64,
    /// Integrator work.
    pub stats: SolverStats,
}

impl DynamicModel {
    /// Runs the dynamic model to the end of `problem`'s push schedule and
    /// returns only the final state: the pose, ω and the centre of mass's
    /// velocity at `problem.duration()`, at the integrator's tolerance.
    ///
    /// `problem.sample_dt` is not read: no sample is taken, stored or
    /// interpolated, no segment report is kept, and an integrated step
    /// builds no dense output. A segment that settles toward a stable root
    /// ends by the series in `δ = ω − ω*` (its end state alone, about a
    /// fifth of the set-up of the sampled series in `E`), handed over to as
    /// soon as they hold to a share of the tolerance; so the state agrees
    /// with the last sample of [`Simulator::simulate`] on the same problem
    /// to within the tolerance, not to rounding (with `skip_settled` off
    /// both take the same steps and agree to rounding). The assumption checks are made at samples, so none is
    /// made here whatever `check_assumptions` says: run `simulate` for them.
    /// With a `[release]`, the state is the slide's end: at rest, or at
    /// `max_duration` when the plate has not stopped.
    pub fn final_state(&self, problem: &Problem) -> Result<FinalState, ModelError> {
        self.final_state_in(problem, None)
    }

    /// [`DynamicModel::final_state`] with the analysis of each push kept in
    /// `cache` between calls (the root its segments tend to and the series
    /// in `δ` about it, see [`PushCache`]): the same state to the bit,
    /// at less cost when pushes repeat, as in a planner's finite-difference
    /// Jacobian or a warm-started re-plan.
    pub fn final_state_cached(
        &self,
        problem: &Problem,
        cache: &mut PushCache,
    ) -> Result<FinalState, ModelError> {
        self.final_state_in(problem, Some(cache))
    }

    fn final_state_in(
        &self,
        problem: &Problem,
        cache: Option<&mut PushCache>,
    ) -> Result<FinalState, ModelError> {
        problem.check()?;
        self.check_integrator()?;
        let mut rec = Recorder::with_sampler(problem, String::new(), false, Sampler::none());
        rec.ends_only = true;
        let end = self.run(problem, &mut rec, false, cache)?;
        if let Some(release) = &problem.release {
            // Through the free slide to rest, with no sample taken.
            let vel = (!problem.pushes.is_empty()).then_some(end.vel);
            let start = crate::slide::release_state(problem, end.c, end.theta, end.omega, vel);
            let slide = crate::slide::slide_to_rest(
                &problem.body,
                &start,
                &crate::slide::SlideOptions {
                    max_duration: release.max_duration,
                    ..Default::default()
                },
            )?;
            let mut stats = rec.out.stats;
            stats.steps += slide.steps;
            stats.rejected += slide.rejected;
            stats.rhs_evals += slide.rhs_evals;
            let e = slide.end;
            return Ok(FinalState {
                t: e.t,
                x: e.x,
                y: e.y,
                theta: e.theta,
                omega: e.omega,
                vx: e.vx,
                vy: e.vy,
                stats,
            });
        }
        let pc = problem.body.contact();
        let (s, c) = end.theta.sin_cos();
        let turn = |a: Vec2| Vec2::new(c * a.x - s * a.y, s * a.x + c * a.y);
        let p = end.c - turn(pc);
        // v_cm = R(θ) (v_c − ω D p_c): the contact point's velocity plus
        // the turn about it.
        let v = turn(end.vel - perp(&pc) * end.omega);
        Ok(FinalState {
            t: problem.duration(),
            x: p.x,
            y: p.y,
            theta: end.theta,
            omega: end.omega,
            vx: v.x,
            vy: v.y,
            stats: rec.out.stats,
        })
    }

    /// Runs the dynamic model over `problem` sampling only at `times` (s,
    /// increasing, within `[0, problem.duration()]`) instead of every
    /// `problem.sample_dt`: a sample at a switch time is the state just
    /// after the switch, as in [`Simulator::simulate`], whose trajectory
    /// this is in every other respect (segment reports, assumption checks
    /// at the samples, solver work).
    pub fn sample_at(&self, problem: &Problem, times: &[f64]) -> Result<Trajectory, ModelError> {
        problem.check()?;
        self.check_integrator()?;
        let end = problem.duration();
        let mut prev = 0.0;
        for &t in times {
            if !(t.is_finite() && t >= prev && t <= end * (1.0 + 1e-12)) {
                return Err(ModelError::Parameter {
                    name: "sample time",
                    requirement: "finite, not decreasing, within [0, the schedule's duration]",
                    value: t,
                });
            }
            prev = t;
        }
        // Within a relative 1e-12 of the run a time counts as a switch's.
        let sampler = Sampler::at(times.to_vec(), 1e-12 * end);
        let mut rec = Recorder::with_sampler(problem, self.name(), self.check_assumptions, sampler);
        self.run(problem, &mut rec, true, None)?;
        rec.out.assumptions = rec.checker.finish();
        Ok(rec.out)
    }
}
