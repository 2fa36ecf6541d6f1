//! The `avian3d` scene: a headless app, the floor, the plate on ball feet,
//! the pusher and its horizontal pin (a custom XPBD constraint), the settle
//! phase and the scene as the shared stepping loop sees it (see
//! `Avian3dSettings`).

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

use pushval_engine::stepping::{
    Plate, PlateWorld, StepLayout, StepLoop, StepPlan, Stepped, Stepping, SupportForces, TailSteps,
};
use pushval_model::{ModelError, Problem, Push};

use crate::clock::Clock;
use crate::{predict, Avian3dRun, Avian3dSettings};

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
    /// The pusher's pin ([`PlanarPin`]), despawned at the release.
    pin: Entity,
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
    let pin = world
        .spawn(PlanarPin {
            body1: pusher,
            body2: object,
            anchor2: anchor,
        })
        .id();
    Scene {
        object,
        pusher,
        pin,
        feet,
        anchor,
    }
}

/// The object's state as the engine has it.
#[derive(Clone, Copy)]
pub struct State {
    position: DVec3,
    rotation: DQuat,
    /// Unwrapped yaw (rad).
    theta: f64,
    /// Vertical angular velocity (rad/s).
    omega: f64,
    /// Angle between the body's vertical axis and the world's (rad).
    tilt: f64,
    /// The engine's velocity of the centre of mass (m/s).
    velocity: DVec3,
    /// The step's yaw change over its length (rad/s): the ω recorded (at the
    /// start, the engine's).
    step_omega: f64,
}

fn read(world: &World, object: Entity, prev_theta: f64) -> State {
    let e = world.entity(object);
    let position = e.get::<Position>().map_or(DVec3::NAN, |p| p.0);
    let rotation = e.get::<Rotation>().map_or(DQuat::IDENTITY, |r| r.0);
    let omega = e.get::<AngularVelocity>().map_or(f64::NAN, |w| w.0.z);
    let velocity = e.get::<LinearVelocity>().map_or(DVec3::NAN, |v| v.0);
    let ex = rotation * DVec3::X;
    let ez = rotation * DVec3::Z;
    let d = (ex.y.atan2(ex.x) - prev_theta.rem_euclid(TAU) + PI).rem_euclid(TAU) - PI;
    State {
        position,
        rotation,
        theta: prev_theta + d,
        omega,
        tilt: ez.z.clamp(-1.0, 1.0).acos(),
        velocity,
        step_omega: omega,
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

/// The feet's accumulated normal impulses after the last step (N s; see
/// [`loads`]).
fn impulses(world: &World, feet: &[Entity]) -> Vec<f64> {
    let graph = world.resource::<ContactGraph>();
    feet.iter()
        .map(|&foot| {
            graph
                .contact_pairs_with(foot)
                .flat_map(|pair| &pair.manifolds)
                .flat_map(|manifold| &manifold.points)
                .map(|p| p.normal_impulse)
                .sum::<f64>()
        })
        .collect()
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

/// What a step leaves for the run's last fifth (known at the end only):
/// its middle, its length and the feet's impulses.
struct StepImpulses {
    mid: f64,
    h: f64,
    impulses: Vec<f64>,
}

/// The scene as the shared stepping loop sees it: steps on Avian's clock
/// (whole ticks, [`Clock`]), the pusher's velocity set at the mid-step yaw
/// the engine's θ and ω predict, the pin's horizontal drift, the tilt and
/// the feet's loads measured after every step.
pub struct World3d {
    app: App,
    scene: Scene,
    clock: Clock,
    dt: f64,
    /// End time of the segments laid out so far (s).
    t_seg: f64,
    /// The current segment's steps in ticks.
    spans: Vec<(u64, u64)>,
    /// The current step: its index in its segment, start and end (s).
    index: usize,
    t0: f64,
    t1: f64,
    /// Length of the last step (s).
    h: f64,
    /// The current segment's time-weighted tail loads and tail length.
    acc: Vec<f64>,
    acc_t: f64,
    /// Per segment, the feet's mean normal force over its tail (N).
    tail_loads: Vec<Vec<f64>>,
    /// Every step's impulses, for the run's last fifth.
    log: Vec<StepImpulses>,
    max_tilt: f64,
    max_drift: f64,
    rest_loads: Vec<f64>,
    mu: Vec<f64>,
    /// Whether the pusher has let go (the slide's steps are laid out one
    /// by one and kept out of the pushes' records).
    released: bool,
}

impl PlateWorld for World3d {
    type State = State;

    fn plate(&self, st: &State) -> Plate {
        Plate {
            x: st.position.x,
            y: st.position.y,
            z: st.position.z,
            theta: st.theta,
            omega: st.step_omega,
            tilt: st.tilt,
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
        (self.t0, self.t1) = (plan.t0, plan.t1);
        let vc = plan.push.velocity();
        let v = DQuat::from_rotation_z(st.theta + 0.5 * plan.h * st.omega)
            * DVec3::new(vc.x, vc.y, 0.0);
        let world = self.app.world_mut();
        if let Some(mut lv) = world
            .entity_mut(self.scene.pusher)
            .get_mut::<LinearVelocity>()
        {
            lv.0 = v;
        }
        0.0
    }

    /// Sets the pusher's horizontal velocity (the pin holds it on the
    /// contact point); its drift is measured after the step.
    fn drive(&mut self, _: &State, velocity: [f64; 2], _h: f64) -> f64 {
        let world = self.app.world_mut();
        if let Some(mut v) = world
            .entity_mut(self.scene.pusher)
            .get_mut::<LinearVelocity>()
        {
            v.0 = DVec3::new(velocity[0], velocity[1], 0.0);
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
        self.max_tilt = self.max_tilt.max(st.tilt);
        if self.released {
            return;
        }
        let world = self.app.world();
        let anchor = world
            .entity(self.scene.pusher)
            .get::<Position>()
            .map_or(DVec3::NAN, |p| p.0);
        let gap = anchor - st.position - st.rotation * self.scene.anchor;
        self.max_drift = self.max_drift.max(gap.x.hypot(gap.y));
        self.log.push(StepImpulses {
            mid: 0.5 * (self.t0 + self.t1),
            h: self.h,
            impulses: impulses(world, &self.scene.feet),
        });
    }

    fn support_forces(&mut self, _: &State, h: f64) -> Result<Option<SupportForces>, ModelError> {
        Ok(Some(SupportForces {
            normal: loads(self.app.world(), &self.scene.feet, h),
            friction: None,
        }))
    }

    /// The segment's tail (steps whose middle is in its last fifth): the
    /// feet's loads, time-weighted.
    fn tail_step(&mut self, _: &State, h: f64) -> Result<(), ModelError> {
        add_loads(self.app.world(), &self.scene.feet, h, h, &mut self.acc);
        self.acc_t += h;
        Ok(())
    }

    fn end_segment(&mut self, _: f64, _t: f64) -> Result<(), ModelError> {
        let acc_t = std::mem::take(&mut self.acc_t);
        self.tail_loads.push(
            self.acc
                .iter_mut()
                .map(|a| std::mem::take(a) / acc_t.max(f64::MIN_POSITIVE))
                .collect(),
        );
        Ok(())
    }

    fn cm_velocity(&self, st: &State) -> Option<[f64; 2]> {
        Some([st.velocity.x, st.velocity.y])
    }

    /// Despawns the pusher's pin and stops the pusher; a throw sets the
    /// object's horizontal velocity and its spin about the vertical. The
    /// slide is the engine's own: the feet's contact friction on the floor
    /// (see the crate docs).
    fn release(&mut self, st: &State, throw: Option<([f64; 2], f64)>) -> Result<(), ModelError> {
        let world = self.app.world_mut();
        world.despawn(self.scene.pin);
        if let Some(mut v) = world
            .entity_mut(self.scene.pusher)
            .get_mut::<LinearVelocity>()
        {
            v.0 = DVec3::ZERO;
        }
        if let Some((v, omega)) = throw {
            let mut e = world.entity_mut(self.scene.object);
            if let Some(mut lv) = e.get_mut::<LinearVelocity>() {
                lv.0 = DVec3::new(v[0], v[1], st.velocity.z);
            }
            if let Some(mut w) = e.get_mut::<AngularVelocity>() {
                w.0.z = omega;
            }
        }
        self.released = true;
        self.h = 0.0;
        Ok(())
    }
}

/// The scene of `problem` (checked by the caller), settled, calibrated and
/// given its start velocity (moving with the first push of its schedule
/// unless it starts at rest), in the shared stepping loop.
pub(crate) fn start(
    problem: &Problem,
    s: &Avian3dSettings,
) -> Result<Stepping<World3d>, ModelError> {
    let body = &problem.body;
    let init = problem.initial;
    if !init.from_rest && problem.pushes.is_empty() {
        return Err(ModelError::EmptySchedule);
    }
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
            state.velocity = v.0;
        }
        if let Some(mut w) = e.get_mut::<AngularVelocity>() {
            w.0.z = init.omega;
        }
        state.omega = init.omega;
        state.step_omega = init.omega;
    }
    let n_feet = scene.feet.len();
    // Loads per sample and the rise, measured from the settled height.
    let z_rest = state.position.z;
    let world = World3d {
        app,
        scene,
        clock,
        dt: s.dt,
        t_seg: 0.0,
        spans: Vec::new(),
        index: 0,
        t0: 0.0,
        t1: 0.0,
        h: s.dt,
        acc: vec![0.0; n_feet],
        acc_t: 0.0,
        tail_loads: Vec::new(),
        log: Vec::new(),
        max_tilt: 0.0,
        max_drift: 0.0,
        rest_loads,
        mu,
        released: false,
    };
    let cfg = StepLoop {
        tail: TailSteps::ByTime,
        ..StepLoop::new(s.dt, n_feet, z_rest)
    };
    Ok(Stepping::new(world, problem, cfg, state))
}

/// The run of the pushes applied (`problem`), from what the loop gathered.
pub(crate) fn finish(
    world: World3d,
    run: Stepped,
    problem: &Problem,
    s: &Avian3dSettings,
    started: Instant,
) -> Avian3dRun {
    // The run's last fifth (steps whose middle is past it), time-weighted.
    let run_from = 0.8 * problem.duration();
    let (mut run_acc, mut run_t) = (vec![0.0; world.scene.feet.len()], 0.0);
    for step in world.log.iter().filter(|q| q.mid >= run_from) {
        for (a, impulse) in run_acc.iter_mut().zip(&step.impulses) {
            *a += step.h * impulse / (2.0 * step.h);
        }
        run_t += step.h;
    }
    let history = run.records();
    Avian3dRun {
        trajectory: pushval_engine::trajectory_from_steps("avian3d", problem, &history),
        settings: *s,
        history,
        rest_loads: world.rest_loads,
        mu: world.mu,
        segment_tail_loads: world.tail_loads,
        // No step in the run's last fifth (thrown without pushes): NaN.
        loads: run_acc
            .iter()
            .map(|a| if run_t > 0.0 { a / run_t } else { f64::NAN })
            .collect(),
        contact: run.contact,
        max_tilt: world.max_tilt,
        max_joint_drift: world.max_drift,
        steps: run.steps,
        wall_time: started.elapsed(),
    }
}
