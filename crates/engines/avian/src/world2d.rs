//! The `avian2d` scene: a headless app, the bodies, the support friction in
//! Avian's substep loop, and the stepping loop (see `Avian2dSettings`).

use std::f64::consts::{PI, TAU};
use std::time::Instant;

use avian2d::dynamics::integrator::{integrate_velocities, IntegrationSystems};
use avian2d::dynamics::rigid_body::forces::ForceSystems;
use avian2d::dynamics::solver::solver_body::SolverBody;
use avian2d::prelude::*;
use bevy::app::{App, TaskPoolPlugin};
use bevy::ecs::schedule::ScheduleLabel;
use bevy::math::DVec2;
use bevy::prelude::{Component, Entity, IntoScheduleConfigs, Query, Res, Time, World};

use pushval_engine::StepRecord;
use pushval_model::{ModelError, Problem};

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

/// Adds, at the start of every substep, the impulse of each support's
/// Coulomb force over the substep, from the body's velocity and angle at
/// that substep (Avian's solver state: the pose so far this step is the
/// step-start pose turned by `delta_rotation`).
fn support_friction(
    mut bodies: Query<(
        &mut SolverBody,
        &Rotation,
        &ComputedMass,
        &ComputedAngularInertia,
        &Supports,
    )>,
    time: Res<Time>,
) {
    let h = time.delta_secs_f64();
    for (mut body, rotation, mass, inertia, supports) in &mut bodies {
        let rot = body.delta_rotation * *rotation;
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

/// The two bodies.
struct Scene {
    object: Entity,
    pusher: Entity,
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
    world.spawn(
        RevoluteJoint::new(pusher, object)
            .with_local_anchor1(DVec2::ZERO)
            .with_local_anchor2(pc),
    );
    Scene {
        object,
        pusher,
        contact: pc,
    }
}

/// The object's state as the engine has it.
#[derive(Clone, Copy)]
struct State {
    position: DVec2,
    rotation: Rotation,
    /// Unwrapped angle (rad).
    theta: f64,
    omega: f64,
}

fn read(world: &World, object: Entity, prev_theta: f64) -> State {
    let e = world.entity(object);
    let position = e.get::<Position>().map_or(DVec2::NAN, |p| p.0);
    let rotation = e.get::<Rotation>().copied().unwrap_or_default();
    let omega = e.get::<AngularVelocity>().map_or(f64::NAN, |w| w.0);
    // Unwrap: the engine's angle lives in (−π, π].
    let d = (rotation.as_radians() - prev_theta.rem_euclid(TAU) + PI).rem_euclid(TAU) - PI;
    State {
        position,
        rotation,
        theta: prev_theta + d,
        omega,
    }
}

/// Runs the problem (checked by the caller).
pub(crate) fn run(problem: &Problem, s: &Avian2dSettings) -> Result<Avian2dRun, ModelError> {
    let start = Instant::now();
    let mut app = headless_app(s.substeps);
    let scene = spawn(app.world_mut(), problem);
    let init = problem.initial;
    let mut state = read(app.world(), scene.object, init.theta);
    let mut history = vec![StepRecord {
        segment: 0,
        t0: 0.0,
        t1: 0.0,
        x: state.position.x,
        y: state.position.y,
        theta: state.theta,
        omega: if init.from_rest { 0.0 } else { init.omega },
    }];
    let clock = Clock::new(s.substeps);
    let mut max_drift = 0.0f64;
    let mut t_seg = 0.0;
    for (j, push) in problem.pushes.iter().enumerate() {
        let (a, b) = (clock.ticks(t_seg), clock.ticks(t_seg + push.duration));
        let vc = push.velocity();
        let vc = DVec2::new(vc.x, vc.y);
        for (k0, k1) in clock.steps(a, b, push.duration, s.dt) {
            let (t0, t1) = (clock.seconds(k0), clock.seconds(k1));
            let h = t1 - t0;
            let world = app.world_mut();
            if let Some(mut v) = world.entity_mut(scene.pusher).get_mut::<LinearVelocity>() {
                v.0 = Rotation::radians(state.theta + 0.5 * h * state.omega) * vc;
            }
            world
                .resource_mut::<Time>()
                .advance_by(clock.duration(k1 - k0));
            world.run_schedule(Step);
            let prev = state.theta;
            state = read(app.world(), scene.object, prev);
            if !(state.position.is_finite() && state.theta.is_finite() && state.omega.is_finite()) {
                return Err(ModelError::NonFinite {
                    t: t1,
                    step: history.len(),
                });
            }
            let anchor = app
                .world()
                .entity(scene.pusher)
                .get::<Position>()
                .map_or(DVec2::NAN, |p| p.0);
            let drift = (anchor - state.position - state.rotation * scene.contact).length();
            max_drift = max_drift.max(drift);
            history.push(StepRecord {
                segment: j,
                t0,
                t1,
                x: state.position.x,
                y: state.position.y,
                theta: state.theta,
                omega: (state.theta - prev) / h,
            });
        }
        t_seg += push.duration;
    }
    let steps = history.len() - 1;
    Ok(Avian2dRun {
        trajectory: pushval_engine::trajectory_from_steps("avian2d", problem, &history),
        settings: *s,
        history,
        steps,
        max_joint_drift: max_drift,
        wall_time: start.elapsed(),
    })
}
