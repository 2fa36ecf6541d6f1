//! The `avian3d` scene: a headless app, the floor, the plate on ball feet,
//! the pusher and its horizontal pin (a custom XPBD constraint), the settle
//! phase and the stepping loop (see `Avian3dSettings`).

use std::f64::consts::{PI, TAU};
use std::time::Instant;

use avian3d::dynamics::joints::EntityConstraint;
use avian3d::dynamics::solver::schedule::SolverSystems;
use avian3d::dynamics::solver::solver_body::{SolverBody, SolverBodyInertia};
use avian3d::dynamics::solver::xpbd::{
    compute_lagrange_update, prepare_xpbd_joint, solve_xpbd_joint, PositionConstraint,
    XpbdConstraint, XpbdConstraintSolverData, XpbdSolverSystems,
};
use avian3d::math::{Scalar, Vector};
use avian3d::prelude::*;
use bevy::app::{App, TaskPoolPlugin};
use bevy::ecs::entity::{EntityMapper, MapEntities};
use bevy::ecs::schedule::ScheduleLabel;
use bevy::math::{DQuat, DVec3};
use bevy::prelude::{ChildOf, Component, Entity, IntoScheduleConfigs, Time, Transform, World};

use pushval_engine::StepRecord;
use pushval_model::{ModelError, Problem};

use crate::clock::Clock;
use crate::{predict, Avian3dRun, Avian3dSettings};

/// Share of a segment, at its end, over which the tail loads are averaged.
const TAIL: f64 = 0.2;

/// The schedule the app runs once per step.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
struct Step;

/// Holds the horizontal (world x, y) position of the point `anchor2` of
/// `body2` (object frame) on the origin of `body1`; z and every rotation are
/// free. An XPBD position constraint like Avian's point constraint with the
/// vertical component of the separation removed: each substep it moves the
/// bodies along the horizontal separation by the generalized inverse masses.
#[derive(Component, Clone, Copy, Debug)]
#[require(PlanarPinData)]
struct PlanarPin {
    body1: Entity,
    body2: Entity,
    anchor2: Vector,
}

/// What [`PlanarPin`] prepares once per step: the anchors relative to the
/// centres of mass and the centres' offset (world frame), and the total
/// Lagrange multiplier of the step.
#[derive(Component, Clone, Copy, Debug, Default)]
struct PlanarPinData {
    r1: Vector,
    r2: Vector,
    center_difference: Vector,
    total_lagrange: Vector,
}

impl XpbdConstraintSolverData for PlanarPinData {
    fn clear_lagrange_multipliers(&mut self) {
        self.total_lagrange = Vector::ZERO;
    }
    fn total_position_lagrange(&self) -> Vector {
        self.total_lagrange
    }
}

impl EntityConstraint<2> for PlanarPin {
    fn entities(&self) -> [Entity; 2] {
        [self.body1, self.body2]
    }
}

impl MapEntities for PlanarPin {
    fn map_entities<M: EntityMapper>(&mut self, mapper: &mut M) {
        self.body1 = mapper.get_mapped(self.body1);
        self.body2 = mapper.get_mapped(self.body2);
    }
}

impl PositionConstraint for PlanarPin {}

impl XpbdConstraint<2> for PlanarPin {
    type SolverData = PlanarPinData;

    fn prepare(&mut self, bodies: [&RigidBodyQueryReadOnlyItem; 2], data: &mut PlanarPinData) {
        let [b1, b2] = bodies;
        data.r1 = b1.rotation * (-b1.center_of_mass.0);
        data.r2 = b2.rotation * (self.anchor2 - b2.center_of_mass.0);
        data.center_difference = (b2.position.0 - b1.position.0)
            + (b2.rotation * b2.center_of_mass.0 - b1.rotation * b1.center_of_mass.0);
    }

    fn solve(
        &mut self,
        bodies: [&mut SolverBody; 2],
        inertias: [&SolverBodyInertia; 2],
        data: &mut PlanarPinData,
        dt: Scalar,
    ) {
        let [body1, body2] = bodies;
        let [inertia1, inertia2] = inertias;
        let r1 = body1.delta_rotation * data.r1;
        let r2 = body2.delta_rotation * data.r2;
        let separation =
            (body2.delta_position - body1.delta_position) + (r2 - r1) + data.center_difference;
        let horizontal = Vector::new(separation.x, separation.y, 0.0);
        let c = horizontal.length();
        if c == 0.0 {
            return;
        }
        let dir = -horizontal / c;
        let w1 = self.compute_generalized_inverse_mass(
            inertia1.effective_inv_mass().max_element(),
            inertia1.effective_inv_angular_inertia(),
            r1,
            dir,
        );
        let w2 = self.compute_generalized_inverse_mass(
            inertia2.effective_inv_mass().max_element(),
            inertia2.effective_inv_angular_inertia(),
            r2,
            dir,
        );
        let impulse = compute_lagrange_update(0.0, c, &[w1, w2], 0.0, dt) * dir;
        data.total_lagrange += impulse;
        self.apply_positional_impulse(body1, body2, inertia1, inertia2, impulse, r1, r2);
    }
}

/// A bare app with Avian's plugins in the [`Step`] schedule, gravity −g z,
/// the substep count, and the pin solved with Avian's user constraints.
fn headless_app(s: &Avian3dSettings) -> App {
    let mut app = App::new();
    app.add_plugins((TaskPoolPlugin::default(), PhysicsPlugins::new(Step)))
        .insert_resource(Time::<()>::default())
        .insert_resource(Gravity(DVec3::new(0.0, 0.0, -s.gravity)))
        // Deliberately not Avian's default of 6: see `DEFAULT_SUBSTEPS`.
        .insert_resource(SubstepCount(s.substeps))
        .add_systems(
            PhysicsSchedule,
            prepare_xpbd_joint::<PlanarPin>.in_set(SolverSystems::PrepareJoints),
        )
        .add_systems(
            SubstepSchedule,
            solve_xpbd_joint::<PlanarPin>.in_set(XpbdSolverSystems::SolveUserConstraints),
        );
    app.finish();
    app.cleanup();
    app
}

/// The bodies and colliders.
struct Scene {
    object: Entity,
    pusher: Entity,
    /// One collider per support, in support order.
    feet: Vec<Entity>,
    /// The pinned point in the object frame (m): the contact point at the
    /// centre of mass's height.
    anchor: DVec3,
}

fn friction(mu: f64) -> Friction {
    Friction::new(mu).with_combine_rule(CoefficientCombine::Multiply)
}

/// Spawns the floor, the object with its feet (friction 1 until the
/// calibration after settling), the pusher and the pin.
fn spawn(world: &mut World, problem: &Problem, s: &Avian3dSettings) -> Scene {
    let body = &problem.body;
    let init = problem.initial;
    let (m, h) = (body.mass(), s.cm_height);
    let tilt = predict::tilt_inertia(body.inertia_cm(), m, s.plate_thickness);
    world.spawn((
        RigidBody::Static,
        Position(DVec3::new(init.position.x, init.position.y, 0.0)),
        Collider::half_space(DVec3::Z),
        friction(1.0),
        Restitution::new(0.0).with_combine_rule(CoefficientCombine::Min),
    ));
    let p0 = DVec3::new(init.position.x, init.position.y, h);
    let rot0 = DQuat::from_rotation_z(init.theta);
    let object = world
        .spawn((
            RigidBody::Dynamic,
            Position(p0),
            Rotation(rot0),
            NoAutoMass,
            NoAutoAngularInertia,
            NoAutoCenterOfMass,
            SleepingDisabled,
        ))
        .id();
    {
        let mut e = world.entity_mut(object);
        if let Some(mut c) = e.get_mut::<ComputedMass>() {
            *c = ComputedMass::new(m);
        }
        if let Some(mut c) = e.get_mut::<ComputedAngularInertia>() {
            *c = ComputedAngularInertia::new(DVec3::new(tilt, tilt, body.inertia_cm()));
        }
    }
    let feet = body
        .supports()
        .map(|q| {
            let centre = DVec3::new(q.position.x, q.position.y, s.foot_radius - h);
            world
                .spawn((
                    Collider::sphere(s.foot_radius),
                    Transform::from_translation(centre.as_vec3()),
                    friction(1.0),
                    Restitution::new(0.0).with_combine_rule(CoefficientCombine::Min),
                    ChildOf(object),
                ))
                .id()
        })
        .collect();
    let pc = body.contact();
    let anchor = DVec3::new(pc.x, pc.y, 0.0);
    let pusher = world
        .spawn((
            RigidBody::Kinematic,
            Position(p0 + rot0 * anchor),
            LinearVelocity::ZERO,
            SleepingDisabled,
        ))
        .id();
    world.spawn(PlanarPin {
        body1: pusher,
        body2: object,
        anchor2: anchor,
    });
    Scene {
        object,
        pusher,
        feet,
        anchor,
    }
}

/// The object's state as the engine has it.
#[derive(Clone, Copy)]
struct State {
    position: DVec3,
    rotation: DQuat,
    /// Unwrapped yaw (rad).
    theta: f64,
    /// Vertical angular velocity (rad/s).
    omega: f64,
    /// Angle between the body's vertical axis and the world's (rad).
    tilt: f64,
}

fn read(world: &World, object: Entity, prev_theta: f64) -> State {
    let e = world.entity(object);
    let position = e.get::<Position>().map_or(DVec3::NAN, |p| p.0);
    let rotation = e.get::<Rotation>().map_or(DQuat::IDENTITY, |r| r.0);
    let omega = e.get::<AngularVelocity>().map_or(f64::NAN, |w| w.0.z);
    let ex = rotation * DVec3::X;
    let ez = rotation * DVec3::Z;
    let d = (ex.y.atan2(ex.x) - prev_theta.rem_euclid(TAU) + PI).rem_euclid(TAU) - PI;
    State {
        position,
        rotation,
        theta: prev_theta + d,
        omega,
        tilt: ez.z.clamp(-1.0, 1.0).acos(),
    }
}

/// The mean normal force of each foot over the last step of length `h` (N).
/// Avian adds a contact's accumulated normal impulse to its
/// `normal_impulse` after each of the two passes of every substep (the
/// biased solve and the relaxation), so the step's mean force is
/// `normal_impulse / (2 h)` (the loads then sum to m g: checked by a test).
fn loads(world: &World, feet: &[Entity], h: f64) -> Vec<f64> {
    let mut out = vec![0.0; feet.len()];
    add_loads(world, feet, h, 1.0, &mut out);
    out
}

/// Adds `weight` times each foot's mean normal force over the last step of
/// length `h` (N, see [`loads`]) to `acc` (no allocation).
fn add_loads(world: &World, feet: &[Entity], h: f64, weight: f64, acc: &mut [f64]) {
    let graph = world.resource::<ContactGraph>();
    for (a, &foot) in acc.iter_mut().zip(feet) {
        let impulse: f64 = graph
            .contact_pairs_with(foot)
            .flat_map(|pair| &pair.manifolds)
            .flat_map(|manifold| &manifold.points)
            .map(|p| p.normal_impulse)
            .sum();
        *a += weight * impulse / (2.0 * h);
    }
}

/// Runs `steps` steps of `ticks` each with the pusher at rest.
fn settle(app: &mut App, scene: &Scene, clock: &Clock, ticks: u64, steps: usize) {
    for _ in 0..steps {
        let world = app.world_mut();
        if let Some(mut v) = world.entity_mut(scene.pusher).get_mut::<LinearVelocity>() {
            v.0 = DVec3::ZERO;
        }
        world
            .resource_mut::<Time>()
            .advance_by(clock.duration(ticks));
        world.run_schedule(Step);
    }
}

/// Runs the problem (checked by the caller).
pub(crate) fn run(problem: &Problem, s: &Avian3dSettings) -> Result<Avian3dRun, ModelError> {
    let start = Instant::now();
    let body = &problem.body;
    let init = problem.initial;
    let mut app = headless_app(s);
    let scene = spawn(app.world_mut(), problem, s);
    let clock = Clock::new(s.substeps);

    // Settle at rest, read the loads, calibrate μ_i = F_i / N_i.
    let settle_ticks = clock.ticks(s.dt).max(1);
    let settle_steps = (s.settle_time / s.dt).ceil() as usize;
    settle(&mut app, &scene, &clock, settle_ticks, settle_steps.max(1));
    let rest_loads = loads(app.world(), &scene.feet, clock.seconds(settle_ticks));
    let mut mu = Vec::with_capacity(rest_loads.len());
    for (i, (support, &n)) in body.supports().zip(&rest_loads).enumerate() {
        if !(n > 0.0) && support.friction > 0.0 {
            return Err(ModelError::Parameter {
                name: "avian3d rest load of a support with friction (the foot does not touch the floor at rest)",
                requirement: "> 0",
                value: n,
            });
        }
        let m_i = if n > 0.0 { support.friction / n } else { 0.0 };
        mu.push(m_i);
        if let Some(mut f) = app
            .world_mut()
            .entity_mut(scene.feet[i])
            .get_mut::<Friction>()
        {
            *f = friction(m_i);
        }
    }

    let mut state = read(app.world(), scene.object, init.theta);
    if !init.from_rest {
        // Moving with the first push at ω = initial.omega (vertical velocity kept).
        let vc = problem.pushes[0].velocity();
        let pc = body.contact();
        let local = DVec3::new(vc.x + init.omega * pc.y, vc.y - init.omega * pc.x, 0.0);
        let mut e = app.world_mut().entity_mut(scene.object);
        if let Some(mut v) = e.get_mut::<LinearVelocity>() {
            v.0 = DQuat::from_rotation_z(state.theta) * local + DVec3::Z * v.0.z;
        }
        if let Some(mut w) = e.get_mut::<AngularVelocity>() {
            w.0.z = init.omega;
        }
        state.omega = init.omega;
    }
    let mut history = vec![StepRecord {
        segment: 0,
        t0: 0.0,
        t1: 0.0,
        x: state.position.x,
        y: state.position.y,
        theta: state.theta,
        omega: state.omega,
    }];
    let n_feet = scene.feet.len();
    // Loads per sample and the rise, measured from the settled height.
    let z_rest = state.position.z;
    let mut recorder = pushval_engine::LoadRecorder::new(problem, n_feet, pushval_laws::GRAVITY);
    let mut tail_loads = Vec::with_capacity(problem.pushes.len());
    // The run's last fifth (steps whose middle is past it), time-weighted.
    let run_from = 0.8 * problem.duration();
    let (mut run_acc, mut run_t) = (vec![0.0; n_feet], 0.0);
    let (mut max_tilt, mut max_drift) = (0.0f64, 0.0f64);
    let mut t_seg = 0.0;
    for (j, push) in problem.pushes.iter().enumerate() {
        let (a, b) = (clock.ticks(t_seg), clock.ticks(t_seg + push.duration));
        let vc = push.velocity();
        let vc = DVec3::new(vc.x, vc.y, 0.0);
        let tail_from = clock.seconds(b) - TAIL * push.duration;
        let (mut acc, mut acc_t) = (vec![0.0; n_feet], 0.0);
        for (k0, k1) in clock.steps(a, b, push.duration, s.dt) {
            let (t0, t1) = (clock.seconds(k0), clock.seconds(k1));
            let h = t1 - t0;
            let world = app.world_mut();
            if let Some(mut v) = world.entity_mut(scene.pusher).get_mut::<LinearVelocity>() {
                v.0 = DQuat::from_rotation_z(state.theta + 0.5 * h * state.omega) * vc;
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
            max_tilt = max_tilt.max(state.tilt);
            let anchor = app
                .world()
                .entity(scene.pusher)
                .get::<Position>()
                .map_or(DVec3::NAN, |p| p.0);
            let gap = anchor - state.position - state.rotation * scene.anchor;
            max_drift = max_drift.max(gap.x.hypot(gap.y));
            recorder.step(
                t1,
                h,
                Some(&loads(app.world(), &scene.feet, h)),
                Some(state.position.z - z_rest),
            );
            if 0.5 * (t0 + t1) >= tail_from {
                add_loads(app.world(), &scene.feet, h, h, &mut acc);
                acc_t += h;
            }
            if 0.5 * (t0 + t1) >= run_from {
                add_loads(app.world(), &scene.feet, h, h, &mut run_acc);
                run_t += h;
            }
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
        tail_loads.push(
            acc.iter()
                .map(|a| a / acc_t.max(f64::MIN_POSITIVE))
                .collect(),
        );
        t_seg += push.duration;
    }
    let steps = history.len() - 1;
    Ok(Avian3dRun {
        trajectory: pushval_engine::trajectory_from_steps("avian3d", problem, &history),
        settings: *s,
        history,
        rest_loads,
        mu,
        segment_tail_loads: tail_loads,
        loads: run_acc
            .iter()
            .map(|a| a / run_t.max(f64::MIN_POSITIVE))
            .collect(),
        contact: recorder.finish(),
        max_tilt,
        max_joint_drift: max_drift,
        steps,
        wall_time: start.elapsed(),
    })
}
