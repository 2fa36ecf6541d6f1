//! What an engine's scene does for the loop ([`PlateWorld`]).

use pushval_model::{ModelError, Push};

use super::{Plate, StepLayout, StepPlan, SupportForces};

/// What an engine's scene does for the loop: drive the pusher, step, read
/// the object and, where it can, the supports' forces and slip.
pub trait PlateWorld {
    /// The engine's reading of the object (pose, velocities, …).
    type State;

    /// The loop's view of a state.
    fn plate(&self, state: &Self::State) -> Plate;

    /// The heading (rad) at which the pusher velocity is set for a step of
    /// length `h` from `state`: by default the yaw at mid-step, `θ + ω h/2`.
    fn heading(&self, state: &Self::State, h: f64) -> f64 {
        let p = self.plate(state);
        p.theta + 0.5 * h * p.omega
    }

    /// The steps of a segment of `push`, where the world lays them out
    /// itself; `n` steps of `h = duration / n` otherwise (None, the
    /// default). The layout depends on the push alone: nothing tells the
    /// world what follows it.
    fn segment_steps(&mut self, _push: &Push, _n: usize, _h: f64) -> Option<StepLayout> {
        None
    }

    /// Drives the pusher for the step `plan` from `state`: by default the
    /// commanded contact velocity `v_c R(ψ) n_φ` at the heading ψ of
    /// [`PlateWorld::heading`], through [`PlateWorld::drive`]. Returns the
    /// pusher's drift (m) as `drive` does.
    fn drive_step(&mut self, state: &Self::State, plan: &StepPlan) -> f64 {
        let vc = plan.push.velocity();
        let (sn, cs) = self.heading(state, plan.h).sin_cos();
        let vel = [cs * vc.x - sn * vc.y, sn * vc.x + cs * vc.y];
        self.drive(state, vel, plan.h)
    }

    /// Re-pins the pusher on the object's contact point and gives it the
    /// world velocity `velocity` (m/s) for a step of length `h`; returns how
    /// far (m, horizontal) it was from the contact point before.
    fn drive(&mut self, state: &Self::State, velocity: [f64; 2], h: f64) -> f64;

    /// One engine step of length `h` (s) ending at time `t1`.
    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError>;

    /// The object after a step; `prev` is the reading before it (to unwrap
    /// the yaw).
    fn state(&mut self, prev: &Self::State) -> Self::State;

    /// Each support's forces over the last step of length `h`, or None where
    /// the engine reads none.
    fn support_forces(
        &mut self,
        state: &Self::State,
        h: f64,
    ) -> Result<Option<SupportForces>, ModelError>;

    /// Whether a state is usable: by default its position and ω are finite.
    fn finite(&self, state: &Self::State) -> bool {
        let p = self.plate(state);
        p.x.is_finite() && p.y.is_finite() && p.z.is_finite() && p.omega.is_finite()
    }

    /// Called after every step once the state is checked, for what the
    /// engine records itself. Nothing by default.
    fn after_step(&mut self, _state: &Self::State) {}

    /// Horizontal slip speed (m/s) of support `i` after the step, where the
    /// engine gives it (read in the segment tails only). None by default.
    fn slip(&self, _state: &Self::State, _i: usize) -> Option<f64> {
        None
    }

    /// Called on every tail step of a segment (after the loop's own tail
    /// sums), for what the engine gathers itself. Nothing by default.
    fn tail_step(&mut self, _state: &Self::State, _h: f64) -> Result<(), ModelError> {
        Ok(())
    }

    /// Called at the end of every segment (time `t`, s) with the total
    /// weight of its tail (its length in s, or its number of steps with
    /// [`TailWeight::Steps`](super::TailWeight::Steps)). Nothing by default.
    fn end_segment(&mut self, _tail_weight: f64, _t: f64) -> Result<(), ModelError> {
        Ok(())
    }

    /// The world velocity (m/s) of the centre of mass in `state`, where the
    /// engine gives it; None (the default) leaves the session to report the
    /// one a rigid contact moving with the last push gives.
    fn cm_velocity(&self, _state: &Self::State) -> Option<[f64; 2]> {
        None
    }

    /// Lets go of the plate ([`Stepping::release`](super::Stepping::release)): the pusher's
    /// constraint goes (the pusher withdraws without an impulse). `throw`,
    /// given when no push was applied, is the velocity to start the slide
    /// with: the centre of mass's (m/s, world) and ω (rad/s). By default the
    /// world cannot release ([`crate::no_release`]).
    fn release(
        &mut self,
        _state: &Self::State,
        _throw: Option<([f64; 2], f64)>,
    ) -> Result<(), ModelError> {
        Err(crate::no_release(
            "its world cannot remove the pusher's constraint",
        ))
    }

    /// Before every step of the slide (the pusher gone) from `state`, of
    /// length `h` (s): what the world applies itself (its supports'
    /// friction where the engine's own contacts do not). Nothing by
    /// default.
    fn slide_step(&mut self, _state: &Self::State, _h: f64) {}
}

/// A world borrowed by the loop is a world.
impl<W: PlateWorld + ?Sized> PlateWorld for &mut W {
    type State = W::State;
    fn plate(&self, state: &Self::State) -> Plate {
        (**self).plate(state)
    }
    fn heading(&self, state: &Self::State, h: f64) -> f64 {
        (**self).heading(state, h)
    }
    fn segment_steps(&mut self, push: &Push, n: usize, h: f64) -> Option<StepLayout> {
        (**self).segment_steps(push, n, h)
    }
    fn drive_step(&mut self, state: &Self::State, plan: &StepPlan) -> f64 {
        (**self).drive_step(state, plan)
    }
    fn drive(&mut self, state: &Self::State, velocity: [f64; 2], h: f64) -> f64 {
        (**self).drive(state, velocity, h)
    }
    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError> {
        (**self).step(h, t1)
    }
    fn state(&mut self, prev: &Self::State) -> Self::State {
        (**self).state(prev)
    }
    fn support_forces(
        &mut self,
        state: &Self::State,
        h: f64,
    ) -> Result<Option<SupportForces>, ModelError> {
        (**self).support_forces(state, h)
    }
    fn finite(&self, state: &Self::State) -> bool {
        (**self).finite(state)
    }
    fn after_step(&mut self, state: &Self::State) {
        (**self).after_step(state)
    }
    fn slip(&self, state: &Self::State, i: usize) -> Option<f64> {
        (**self).slip(state, i)
    }
    fn tail_step(&mut self, state: &Self::State, h: f64) -> Result<(), ModelError> {
        (**self).tail_step(state, h)
    }
    fn end_segment(&mut self, tail_weight: f64, t: f64) -> Result<(), ModelError> {
        (**self).end_segment(tail_weight, t)
    }
    fn cm_velocity(&self, state: &Self::State) -> Option<[f64; 2]> {
        (**self).cm_velocity(state)
    }
    fn release(
        &mut self,
        state: &Self::State,
        throw: Option<([f64; 2], f64)>,
    ) -> Result<(), ModelError> {
        (**self).release(state, throw)
    }
    fn slide_step(&mut self, state: &Self::State, h: f64) {
        (**self).slide_step(state, h)
    }
}
