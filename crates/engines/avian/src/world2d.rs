//! The `avian2d` scene: a headless app, the bodies, the support friction in
//! Avian's substep loop, and the scene as the shared stepping loop sees it
//! (see `Avian2dSettings`).

use std::f64::consts::{PI, TAU};
use std::time::Instant;

use avian2d::dynamics::integrator::{integrate_velocities, IntegrationSystems};
use avian2d::dynamics::rigid_body::forces::ForceSystems;
use avian2d::dynamics::solver::solver_body::SolverBody;
use avian2d::prelude::*;
use bevy::app::{App, TaskPoolPlugin};
use bevy::ecs::schedule::ScheduleLabel;
use bevy::math::DVec2;
use bevy::prelude::{Component, Entity, IntoScheduleConfigs, Query, Res, Resource, Time, World};

use pushval_engine::stepping::{
    Plate, PlateWorld, StepLayout, StepLoop, StepPlan, Stepped, Stepping, SupportForces,
};
use pushval_model::{ModelError, Problem, Push};

use crate::clock::Clock;
use crate::{Avian2dRun, Avian2dSettings};

/// Sliding speeds (m/s) at or below this give no friction force.
const MIN_SLIDING_SPEED: f64 = 1e-12;

/// The schedule the app runs once per step; Avian's `PhysicsSchedule` runs
/// inside it.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
struct Step;

/// The object's supports: position in the object frame relative to the
/// centre of mass (m) and friction magnitude `F_i = μ_i N_i` (N).
#[derive(Component)]
struct Supports(Vec<(DVec2, f64)>);

/// Whether the pusher has let go: the supports' friction is then the
/// implicit Coulomb impulses of the free slide
/// ([`pushval_engine::slide::coulomb_impulses`]).
#[derive(Resource, Default)]
struct Released(bool);

/// Adds, at the start of every substep, the impulse of each support's
/// Coulomb force over the substep, from the body's velocity and angle at
/// that substep (Avian's solver state: the pose so far this step is the
/// step-start pose turned by `delta_rotation`). After the release, the
/// impulses of the free slide: each within `F_i h`, jointly the ones that
/// leave the supports' slip zero where the caps allow (so the plate stops
/// instead of reversing its slip every substep).
fn support_friction(
    mut bodies: Query<(
        &mut SolverBody,
        &Rotation,
        &ComputedMass,
        &ComputedAngularInertia,
        &Supports,
    )>,
    time: Res<Time>,
    released: Res<Released>,
) {
    let h = time.delta_secs_f64();
    for (mut body, rotation, mass, inertia, supports) in &mut bodies {
        let rot = body.delta_rotation * *rotation;
        if released.0 {
            let rs: Vec<([f64; 2], f64)> = supports
                .0
                .iter()
                .map(|&(p, friction)| {
                    let r = rot * p;
                    ([r.x, r.y], friction.max(0.0) * h)
                })
                .collect();
            let v = body.linear_velocity;
            let acc = pushval_engine::slide::coulomb_impulses(
                1.0 / mass.inverse(),
                1.0 / inertia.inverse(),
                [v.x, v.y],
                body.angular_velocity,
                &rs,
            );
            let (mut impulse, mut moment) = (DVec2::ZERO, 0.0);
            for ((r, _), a) in rs.iter().zip(&acc) {
                let p = DVec2::new(a[0], a[1]);
                impulse += p;
                moment += DVec2::new(r[0], r[1]).perp_dot(p);
            }
            body.linear_velocity += impulse * mass.inverse();
            body.angular_velocity += moment * inertia.inverse();
            continue;
        }
        let (mut force, mut torque) = (DVec2::ZERO, 0.0);
        for &(p, friction) in &supports.0 {
            let r = rot * p;
            let u = body.linear_velocity + body.angular_velocity * r.perp();
            let speed = u.length();
            if speed > MIN_SLIDING_SPEED && friction > 0.0 {
                let f = u * (-friction / speed);
                force += f;
                torque += r.perp_dot(f);
            }
        }
        body.linear_velocity += force * (h * mass.inverse());
        body.angular_velocity += torque * (h * inertia.inverse());
    }
}

/// A bare app with Avian's plugins in the [`Step`] schedule, zero gravity,
/// the substep count, and the support friction in the substep loop before
/// Avian applies its own forces and integrates the velocities.
fn headless_app(substeps: u32) -> App {
    let mut app = App::new();
    app.add_plugins((TaskPoolPlugin::default(), PhysicsPlugins::new(Step)))
        .insert_resource(Time::<()>::default())
        .insert_resource(Gravity::ZERO)
        // Deliberately not Avian's default of 6: see `DEFAULT_SUBSTEPS`.
        .insert_resource(SubstepCount(substeps))
        .insert_resource(Released(false))
        .add_systems(
            SubstepSchedule,
            support_friction
                .in_set(IntegrationSystems::Velocity)
                .before(ForceSystems::ApplyLocalAcceleration)
                .before(integrate_velocities),
        );
    app.finish();
    app.cleanup();
    app
}

/// The two bodies and the joint.
struct Scene {
    object: Entity,
    pusher: Entity,
    /// The revolute joint (the pusher's constraint), despawned at the
    /// release.
    joint: Entity,
    /// Contact point in the object frame (m).
    contact: DVec2,
}

/// Spawns the object (mass properties set exactly, never recomputed: no
/// collider and the automatic computation off), the pusher on the contact
/// point, and the joint.
fn spawn(world: &mut World, problem: &Problem) -> Scene {
    let body = &problem.body;
    let init = problem.initial;
    let pc = DVec2::new(body.contact().x, body.contact().y);
    let supports = body
        .supports()
        .map(|s| (DVec2::new(s.position.x, s.position.y), s.friction))
        .collect();
    let rot0 = Rotation::radians(init.theta);
    // At rest, or moving with the first push at ω = initial.omega:
    // v_cm = R(θ)(v_c n_φ − ω D p_c), D p_c = (−p_c,y, p_c,x).
    let (v0, w0) = if init.from_rest {
        (DVec2::ZERO, 0.0)
    } else {
        let vc = problem.pushes[0].velocity();
        let local = DVec2::new(vc.x + init.omega * pc.y, vc.y - init.omega * pc.x);
        (rot0 * local, init.omega)
    };
    let p0 = DVec2::new(init.position.x, init.position.y);
    let object = world
        .spawn((
            RigidBody::Dynamic,
            Position(p0),
            rot0,
            LinearVelocity(v0),
            AngularVelocity(w0),
            NoAutoMass,
            NoAutoAngularInertia,
            NoAutoCenterOfMass,
            SleepingDisabled,
            Supports(supports),
        ))
        .id();
    {
        // Avian's `Mass` and `AngularInertia` are f32; the computed ones are
        // the solver's, in f64.
        let mut e = world.entity_mut(object);
        if let Some(mut m) = e.get_mut::<ComputedMass>() {
            *m = ComputedMass::new(body.mass());
        }
        if let Some(mut i) = e.get_mut::<ComputedAngularInertia>() {
            *i = ComputedAngularInertia::new(body.inertia_cm());
        }
    }
    let pusher = world
        .spawn((
            RigidBody::Kinematic,
            Position(p0 + rot0 * pc),
            LinearVelocity::ZERO,
            SleepingDisabled,
        ))
        .id();
    let joint = world
        .spawn(
            RevoluteJoint::new(pusher, object)
                .with_local_anchor1(DVec2::ZERO)
                .with_local_anchor2(pc),
        )
        .id();
    Scene {
        object,
        pusher,
        joint,
        contact: pc,
    }
}

/// The object's state as the engine has it.
#[derive(Clone, Copy)]
pub struct State {
    position: DVec2,
    rotation: Rotation,
    /// Unwrapped angle (rad).
    theta: f64,
    /// The engine's angular velocity (rad/s).
    omega: f64,
    /// The engine's velocity of the centre of mass (m/s).
    velocity: DVec2,
    /// The step's rotation over its length (rad/s): the ω recorded (at the
    /// start, the initial one).
    step_omega: f64,
}

fn read(world: &World, object: Entity, prev_theta: f64) -> State {
    let e = world.entity(object);
    let position = e.get::<Position>().map_or(DVec2::NAN, |p| p.0);
    let rotation = e.get::<Rotation>().copied().unwrap_or_default();
    let omega = e.get::<AngularVelocity>().map_or(f64::NAN, |w| w.0);
    let velocity = e.get::<LinearVelocity>().map_or(DVec2::NAN, |v| v.0);
    // Unwrap: the engine's angle lives in (−π, π].
    let d = (rotation.as_radians() - prev_theta.rem_euclid(TAU) + PI).rem_euclid(TAU) - PI;
    State {
        position,
        rotation,
        theta: prev_theta + d,
        omega,
        velocity,
        step_omega: omega,
    }
}

/// The scene as the shared stepping loop sees it: steps on Avian's clock
/// (whole ticks, [`Clock`]), the pusher's velocity set at the mid-step angle
/// the engine's θ and ω predict, the joint's drift measured after every step.
pub struct World2d {
    app: App,
    scene: Scene,
    clock: Clock,
    dt: f64,
    /// End time of the segments laid out so far (s).
    t_seg: f64,
    /// The current segment's steps in ticks.
    spans: Vec<(u64, u64)>,
    /// Index of the current step in its segment.
    index: usize,
    /// Length of the last step (s).
    h: f64,
    /// Largest distance between the pusher and the object's contact point
    /// after a step (m).
    pub(crate) max_drift: f64,
    /// Whether the pusher has let go (its steps are then laid out one by
    /// one, and its drift is no longer measured).
    released: bool,
}

impl PlateWorld for World2d {
    type State = State;

    fn plate(&self, st: &State) -> Plate {
        Plate {
            x: st.position.x,
            y: st.position.y,
            z: 0.0,
            theta: st.theta,
            omega: st.step_omega,
            tilt: 0.0,
        }
    }

    /// The segment's steps in whole ticks (see [`Clock`]).
    fn segment_steps(&mut self, push: &Push, _n: usize, _h: f64) -> Option<StepLayout> {
        let c = self.clock;
        let (a, b) = (c.ticks(self.t_seg), c.ticks(self.t_seg + push.duration));
        self.spans = c.steps(a, b, push.duration, self.dt);
        self.t_seg += push.duration;
        Some(StepLayout::Spans(
            self.spans
                .iter()
                .map(|&(k0, k1)| (c.seconds(k0), c.seconds(k1)))
                .collect(),
        ))
    }

    /// The commanded contact velocity turned by `θ + ω h/2`, θ and ω the
    /// engine's.
    fn drive_step(&mut self, st: &State, plan: &StepPlan) -> f64 {
        self.index = plan.index;
        let vc = plan.push.velocity();
        let v = Rotation::radians(st.theta + 0.5 * plan.h * st.omega) * DVec2::new(vc.x, vc.y);
        self.drive(st, [v.x, v.y], plan.h)
    }

    /// Sets the pusher's velocity (the joint holds it on the contact point);
    /// its drift is measured after the step.
    fn drive(&mut self, _: &State, velocity: [f64; 2], _h: f64) -> f64 {
        let world = self.app.world_mut();
        if let Some(mut v) = world
            .entity_mut(self.scene.pusher)
            .get_mut::<LinearVelocity>()
        {
            v.0 = DVec2::new(velocity[0], velocity[1]);
        }
        0.0
    }

    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError> {
        let (k0, k1) = if self.released {
            // The slide's steps, on the clock from its end back.
            let c = self.clock;
            (c.ticks(t1 - h), c.ticks(t1).max(c.ticks(t1 - h) + 1))
        } else {
            self.spans[self.index]
        };
        let world = self.app.world_mut();
        world
            .resource_mut::<Time>()
            .advance_by(self.clock.duration(k1 - k0));
        world.run_schedule(Step);
        self.h = h;
        Ok(())
    }

    fn state(&mut self, prev: &State) -> State {
        let mut st = read(self.app.world(), self.scene.object, prev.theta);
        // No step since the release (h = 0): the engine's ω as it is.
        if self.h > 0.0 {
            st.step_omega = (st.theta - prev.theta) / self.h;
        }
        st
    }

    fn finite(&self, st: &State) -> bool {
        st.position.is_finite() && st.theta.is_finite() && st.omega.is_finite()
    }

    fn after_step(&mut self, st: &State) {
        if self.released {
            return;
        }
        let anchor = self
            .app
            .world()
            .entity(self.scene.pusher)
            .get::<Position>()
            .map_or(DVec2::NAN, |p| p.0);
        let drift = (anchor - st.position - st.rotation * self.scene.contact).length();
        self.max_drift = self.max_drift.max(drift);
    }

    fn support_forces(&mut self, _: &State, _h: f64) -> Result<Option<SupportForces>, ModelError> {
        Ok(None)
    }

    fn cm_velocity(&self, st: &State) -> Option<[f64; 2]> {
        Some([st.velocity.x, st.velocity.y])
    }

    /// Despawns the revolute joint and stops the pusher; a throw sets the
    /// object's velocity and ω. From here the supports' friction is the
    /// free slide's implicit Coulomb impulses, substep by substep (see
    /// [`support_friction`]).
    fn release(&mut self, _st: &State, throw: Option<([f64; 2], f64)>) -> Result<(), ModelError> {
        let world = self.app.world_mut();
        world.despawn(self.scene.joint);
        if let Some(mut v) = world
            .entity_mut(self.scene.pusher)
            .get_mut::<LinearVelocity>()
        {
            v.0 = DVec2::ZERO;
        }
        if let Some((v, omega)) = throw {
            let mut e = world.entity_mut(self.scene.object);
            if let Some(mut lv) = e.get_mut::<LinearVelocity>() {
                lv.0 = DVec2::new(v[0], v[1]);
            }
            if let Some(mut w) = e.get_mut::<AngularVelocity>() {
                w.0 = omega;
            }
        }
        world.resource_mut::<Released>().0 = true;
        self.released = true;
        self.h = 0.0;
        Ok(())
    }
}

/// The scene of `problem` (checked by the caller) in the shared stepping
/// loop, the object moving with the first push of its schedule unless it
/// starts at rest.
pub(crate) fn start(
    problem: &Problem,
    s: &Avian2dSettings,
) -> Result<Stepping<World2d>, ModelError> {
    if !problem.initial.from_rest && problem.pushes.is_empty() {
        return Err(ModelError::EmptySchedule);
    }
    let mut app = headless_app(s.substeps);
    let scene = spawn(app.world_mut(), problem);
    let init = problem.initial;
    let mut state = read(app.world(), scene.object, init.theta);
    state.step_omega = if init.from_rest { 0.0 } else { init.omega };
    let world = World2d {
        app,
        scene,
        clock: Clock::new(s.substeps),
        dt: s.dt,
        t_seg: 0.0,
        spans: Vec::new(),
        index: 0,
        h: s.dt,
        max_drift: 0.0,
        released: false,
    };
    Ok(Stepping::new(
        world,
        problem,
        StepLoop::new(s.dt, 0, 0.0),
        state,
    ))
}

/// The run of the pushes applied (`problem`), from what the loop gathered.
pub(crate) fn finish(
    world: &World2d,
    run: Stepped,
    problem: &Problem,
    s: &Avian2dSettings,
    started: Instant,
) -> Avian2dRun {
    let history = run.records();
    Avian2dRun {
        trajectory: pushval_engine::trajectory_from_steps("avian2d", problem, &history),
        settings: *s,
        history,
        steps: run.steps,
        max_joint_drift: world.max_drift,
        wall_time: started.elapsed(),
    }
}
