//! The Box2D world of one run: set-up, then one stage per step (read the
//! state, set the pusher velocity and the friction, step, record).

use std::time::{Duration, Instant};

use boxdd::{
    BodyId, BodyType, ConstraintTuning, Foundation, JointId, MassData, MotorJointDef, Position,
    RevoluteJointDef, Vec2, World,
};
use pushval_engine::stepping::{
    Plate, PlateWorld, StepLoop, StepPlan, Stepped, Stepping, SupportForces,
};
use pushval_engine::StepRecord;
use pushval_model::{ModelError, Problem};

use crate::{Box2dSettings, Friction, JOINT_DAMPING_RATIO};

/// Sliding speeds (m/s) at or below this give no friction force (the
/// direction is undefined there); it keeps every force finite.
const MIN_SLIDING_SPEED: f64 = 1e-12;

/// What the stepping hands back.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct RawRun {
    pub history: Vec<StepRecord>,
    pub steps: usize,
    /// Time spent inside `b2World_Step`.
    pub step_time: Duration,
    pub max_drift: f64,
    pub min_support_speed: f64,
}

/// A Box2D error as a model error at time `t` (s).
fn engine_error(t: f64) -> impl Fn(boxdd::Error) -> ModelError {
    move |e| ModelError::Integration {
        t,
        reason: format!("Box2D: {e}"),
    }
}

/// `R a` for a rotation given by its cosine and sine.
fn rot(c: f64, s: f64, a: [f64; 2]) -> [f64; 2] {
    [c * a[0] - s * a[1], s * a[0] + c * a[1]]
}

/// The object's state as Box2D holds it, in f64.
#[derive(Debug, Clone, Copy)]
pub struct State {
    /// Centre of mass (m, world).
    x: f64,
    y: f64,
    /// Unwrapped angle (rad).
    theta: f64,
    /// Box2D's rotation (its f32 cosine and sine).
    c: f64,
    s: f64,
    /// Linear velocity of the centre of mass (m/s, world).
    v: [f64; 2],
    /// Angular velocity (rad/s).
    omega: f64,
}

/// The bodies of the scene and what the stepping needs about the problem.
struct Scene {
    world: World,
    object: BodyId,
    pusher: BodyId,
    /// The pin joint (the pusher's constraint), destroyed at the release.
    joint: JointId,
    /// Contact point (m, object frame).
    pc: [f64; 2],
    /// Support positions (m, object frame) and friction magnitudes `F_i` (N).
    supports: Vec<([f64; 2], f64)>,
    friction: Friction,
    /// Mass (kg) and inertia about the centre of mass (kg m²).
    mass: f64,
    inertia_cm: f64,
}

impl Scene {
    /// Builds the world: gravity zero, sleeping and continuous collision off
    /// (nothing has a shape), the object, the pusher and their pin joint,
    /// and for [`Friction::MotorJoint`] the ground body and its motor joint.
    fn new(problem: &Problem, settings: &Box2dSettings) -> Result<Self, ModelError> {
        let err = engine_error(0.0);
        let foundation = Foundation::initialize_default().map_err(&err)?;
        let body = &problem.body;
        let init = problem.initial;
        let pc = [body.contact().x, body.contact().y];
        let supports: Vec<([f64; 2], f64)> = body
            .supports()
            .map(|s| ([s.position.x, s.position.y], s.friction))
            .collect();

        let def = foundation
            .world_builder()
            .gravity(Vec2::new(0.0, 0.0))
            .enable_sleep(false)
            .enable_continuous(false)
            .build()
            .map_err(&err)?;
        let mut world = foundation.create_world(def).map_err(&err)?;

        // Initial velocities: at rest, or moving with the first push at
        // ω = initial.omega: v_cm = R(θ)(v_c n_φ − ω D p_c).
        let (s0, c0) = init.theta.sin_cos();
        let (v0, w0) = if init.from_rest {
            ([0.0, 0.0], 0.0)
        } else {
            let vc = problem
                .pushes
                .first()
                .ok_or(ModelError::EmptySchedule)?
                .velocity();
            let local = [vc.x + init.omega * pc[1], vc.y - init.omega * pc[0]];
            (rot(c0, s0, local), init.omega)
        };
        let object_def = world
            .body_builder()
            .body_type(BodyType::Dynamic)
            .position(Position::new(init.position.x, init.position.y))
            .angle(init.theta as f32)
            .linear_velocity(Vec2::new(v0[0] as f32, v0[1] as f32))
            .angular_velocity(w0 as f32)
            .enable_sleep(false)
            .allow_fast_rotation(true)
            .build()
            .map_err(&err)?;
        let object = world.create_body(object_def).map_err(&err)?;
        let mass = MassData::new(
            body.mass() as f32,
            Vec2::new(0.0, 0.0),
            body.inertia_cm() as f32,
        )
        .map_err(&err)?;
        world
            .body(object)
            .map_err(&err)?
            .set_mass_data(mass)
            .map_err(&err)?;

        let rc = rot(c0, s0, pc);
        let pusher_def = world
            .body_builder()
            .body_type(BodyType::Kinematic)
            .position(Position::new(
                init.position.x + rc[0],
                init.position.y + rc[1],
            ))
            .enable_sleep(false)
            .build()
            .map_err(&err)?;
        let pusher = world.create_body(pusher_def).map_err(&err)?;
        let base = world
            .joint_base(pusher, object)
            .map_err(&err)?
            .with_local_frame_components(
                Vec2::new(0.0, 0.0),
                0.0,
                Vec2::new(pc[0] as f32, pc[1] as f32),
                0.0,
            )
            .map_err(&err)?
            .with_constraint_tuning(
                ConstraintTuning::new(settings.joint_hertz as f32, JOINT_DAMPING_RATIO as f32)
                    .map_err(&err)?,
            );
        let joint = world
            .create_revolute_joint(&RevoluteJointDef::new(base))
            .map_err(&err)?;

        if settings.friction == Friction::MotorJoint {
            let (force, torque) = crate::predict::motor_joint_limits(body);
            let ground_def = world.body_builder().build().map_err(&err)?;
            let ground = world.create_body(ground_def).map_err(&err)?;
            // Identity local frames, as in Box2D's top-down friction sample:
            // the joint acts on the object's origin, its centre of mass.
            let base = world.joint_base(ground, object).map_err(&err)?;
            let def = MotorJointDef::new(base)
                .max_velocity_force(force as f32)
                .max_velocity_torque(torque as f32);
            world.create_motor_joint(&def).map_err(&err)?;
        }

        Ok(Self {
            world,
            object,
            pusher,
            joint,
            pc,
            supports,
            friction: settings.friction,
            mass: body.mass(),
            inertia_cm: body.inertia_cm(),
        })
    }

    /// The object's state; `prev_theta` unwraps the angle.
    fn read(&mut self, prev_theta: f64, t: f64) -> Result<State, ModelError> {
        let err = engine_error(t);
        let b = self.world.body(self.object).map_err(&err)?;
        let p = b.position().map_err(&err)?;
        let r = b.rotation().map_err(&err)?;
        let v = b.linear_velocity().map_err(&err)?;
        let omega = b.angular_velocity().map_err(&err)? as f64;
        let (c, s) = (r.cosine() as f64, r.sine() as f64);
        // The angle in f64 from Box2D's f32 rotation (Box2D's own angle is a
        // polynomial atan2 good to about 1e-4 rad), unwrapped.
        let a = s.atan2(c);
        let tau = std::f64::consts::TAU;
        let d = (a - prev_theta + std::f64::consts::PI).rem_euclid(tau) - std::f64::consts::PI;
        Ok(State {
            x: p.x,
            y: p.y,
            theta: prev_theta + d,
            c,
            s,
            v: [v.x as f64, v.y as f64],
            omega,
        })
    }

    /// Distance (m) between the pusher and the object's contact point.
    fn drift(&mut self, state: &State, t: f64) -> Result<f64, ModelError> {
        let p = self
            .world
            .body(self.pusher)
            .map_err(engine_error(t))?
            .position()
            .map_err(engine_error(t))?;
        let rc = rot(state.c, state.s, self.pc);
        Ok(((p.x - state.x - rc[0]).powi(2) + (p.y - state.y - rc[1]).powi(2)).sqrt())
    }

    /// Sets the pusher velocity `v_c R(θ) n_φ` (θ Box2D's angle at the step
    /// start) and, for Coulomb friction, the support forces for the coming
    /// step. Returns the smallest support sliding speed (m/s), for either
    /// friction law.
    fn apply_step_inputs(
        &mut self,
        state: &State,
        vc: [f64; 2],
        t: f64,
    ) -> Result<f64, ModelError> {
        let err = engine_error(t);
        let vp = rot(state.c, state.s, vc);
        self.world
            .body(self.pusher)
            .map_err(&err)?
            .set_linear_velocity(Vec2::new(vp[0] as f32, vp[1] as f32))
            .map_err(&err)?;
        // u_i = v + ω D r_i from Box2D's velocities (what
        // b2Body_GetWorldPointVelocity returns, evaluated in f64). The forces
        // are summed here into their resultant and its moment about the
        // centre of mass, which is what b2Body_ApplyForce accumulates per
        // force; one hand-over rounds once.
        let mut force = [0.0f64; 2];
        let mut torque = 0.0f64;
        let mut min_speed = f64::INFINITY;
        for &(p, friction) in &self.supports {
            let r = rot(state.c, state.s, p);
            let u = [
                state.v[0] - state.omega * r[1],
                state.v[1] + state.omega * r[0],
            ];
            let speed = (u[0] * u[0] + u[1] * u[1]).sqrt();
            min_speed = min_speed.min(speed);
            if self.friction == Friction::Coulomb && speed > MIN_SLIDING_SPEED && friction > 0.0 {
                let k = -friction / speed;
                let f = [k * u[0], k * u[1]];
                force[0] += f[0];
                force[1] += f[1];
                torque += r[0] * f[1] - r[1] * f[0];
            }
        }
        if self.friction == Friction::Coulomb {
            let mut b = self.world.body(self.object).map_err(&err)?;
            b.apply_force_to_center(Vec2::new(force[0] as f32, force[1] as f32), true)
                .map_err(&err)?;
            b.apply_torque(torque as f32, true).map_err(&err)?;
        }
        Ok(min_speed)
    }
}

/// The Box2D scene as the shared stepping loop sees it (a 2-D world: height
/// and tilt zero).
pub struct Stepper {
    scene: Scene,
    /// Whether the pusher has let go.
    released: bool,
    substeps: i32,
    /// The object after the last step (read inside `step`, where an engine
    /// error can be returned).
    last: State,
    /// The current step's start time (s), for the errors.
    t0: f64,
    /// An error of the pusher's or the friction's set-up, returned by the
    /// step it was for.
    error: Option<ModelError>,
    max_drift: f64,
    min_support_speed: f64,
    step_time: Duration,
}

/// Builds the world of `problem` and hands it to the shared loop; an object
/// not starting at rest starts with the first push of `problem`'s schedule.
pub(crate) fn start(
    problem: &Problem,
    settings: &Box2dSettings,
) -> Result<Stepping<Stepper>, ModelError> {
    if !problem.initial.from_rest && problem.pushes.is_empty() {
        return Err(ModelError::EmptySchedule);
    }
    let mut scene = Scene::new(problem, settings)?;
    let state = scene.read(problem.initial.theta, 0.0)?;
    let w = Stepper {
        scene,
        released: false,
        substeps: settings.substeps as i32,
        last: state,
        t0: 0.0,
        error: None,
        max_drift: 0.0,
        min_support_speed: f64::INFINITY,
        step_time: Duration::ZERO,
    };
    // No supports' forces are read: the loop's per-support vectors are empty.
    let cfg = StepLoop::new(settings.dt, 0, 0.0);
    Ok(Stepping::new(w, problem, cfg, state))
}

/// What the stepping hands back once the loop is done.
pub(crate) fn raw_run(world: Stepper, stepped: &Stepped) -> RawRun {
    RawRun {
        history: stepped.records(),
        steps: stepped.steps,
        step_time: world.step_time,
        max_drift: world.max_drift,
        min_support_speed: if world.min_support_speed.is_finite() {
            world.min_support_speed
        } else {
            0.0
        },
    }
}

impl PlateWorld for Stepper {
    type State = State;

    fn plate(&self, s: &State) -> Plate {
        Plate {
            x: s.x,
            y: s.y,
            z: 0.0,
            theta: s.theta,
            omega: s.omega,
            tilt: 0.0,
        }
    }

    /// The pusher velocity `v_c R(θ) n_φ` at Box2D's angle at the step start,
    /// and the support forces for the step.
    fn drive_step(&mut self, state: &State, plan: &StepPlan) -> f64 {
        let vc = plan.push.velocity();
        self.t0 = plan.t0;
        match self.scene.apply_step_inputs(state, [vc.x, vc.y], plan.t0) {
            Ok(speed) => self.min_support_speed = self.min_support_speed.min(speed),
            Err(e) => self.error = Some(e),
        }
        // The drift is measured after the step.
        0.0
    }

    fn drive(&mut self, _state: &State, _velocity: [f64; 2], _h: f64) -> f64 {
        unreachable!("the Box2D world drives its pusher in drive_step")
    }

    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let before = Instant::now();
        // The step's events (none: nothing has a shape) are not read.
        drop(
            self.scene
                .world
                .step(h as f32, self.substeps)
                .map_err(engine_error(self.t0))?,
        );
        self.step_time += before.elapsed();
        self.last = self.scene.read(self.last.theta, t1)?;
        if !self.released {
            let drift = self.scene.drift(&self.last, t1)?;
            self.max_drift = self.max_drift.max(drift);
        }
        Ok(())
    }

    fn state(&mut self, _prev: &State) -> State {
        self.last
    }

    fn support_forces(&mut self, _: &State, _h: f64) -> Result<Option<SupportForces>, ModelError> {
        Ok(None)
    }

    fn finite(&self, s: &State) -> bool {
        s.x.is_finite() && s.y.is_finite() && s.theta.is_finite() && s.omega.is_finite()
    }

    fn cm_velocity(&self, s: &State) -> Option<[f64; 2]> {
        Some(s.v)
    }

    /// Destroys the pin joint and stops the pusher; a throw sets the
    /// object's velocity. Both laws slide: Coulomb through
    /// [`slide_step`](PlateWorld::slide_step), the motor-joint idiom under
    /// its motor joint, which stays (it is the friction, not the pusher).
    fn release(
        &mut self,
        _state: &State,
        throw: Option<([f64; 2], f64)>,
    ) -> Result<(), ModelError> {
        let err = engine_error(self.t0);
        let w = &mut self.scene.world;
        w.joint(self.scene.joint)
            .map_err(&err)?
            .destroy(true)
            .map_err(&err)?;
        w.body(self.scene.pusher)
            .map_err(&err)?
            .set_linear_velocity(Vec2::new(0.0, 0.0))
            .map_err(&err)?;
        if let Some((v, omega)) = throw {
            let mut b = w.body(self.scene.object).map_err(&err)?;
            b.set_linear_velocity(Vec2::new(v[0] as f32, v[1] as f32))
                .map_err(&err)?;
            b.set_angular_velocity(omega as f32).map_err(&err)?;
        }
        self.last = self.scene.read(self.last.theta, self.t0)?;
        self.released = true;
        Ok(())
    }

    /// The supports' implicit Coulomb impulses of
    /// [`pushval_engine::slide`] (no chatter at the stop), applied as a
    /// constant force at the centre of mass and a torque over the step.
    /// Under the motor-joint idiom nothing: the motor joint, solved by
    /// Box2D, holds the plate's velocity at zero within its force and
    /// torque caps, so it decelerates the translation at `F_max/m` and the
    /// spin at `T_max/I` each on its own and stops each within a step once
    /// the cap suffices (crate docs).
    fn slide_step(&mut self, state: &State, h: f64) {
        if self.scene.friction == Friction::MotorJoint {
            return;
        }
        let sup: Vec<([f64; 2], f64)> = self
            .scene
            .supports
            .iter()
            .map(|&(p, f)| (rot(state.c, state.s, p), f.max(0.0) * h))
            .collect();
        let p = pushval_engine::slide::coulomb_impulses(
            self.scene.mass,
            self.scene.inertia_cm,
            state.v,
            state.omega,
            &sup,
        );
        let (mut force, mut torque) = ([0.0f64; 2], 0.0f64);
        for ((r, _), q) in sup.iter().zip(&p) {
            force[0] += q[0] / h;
            force[1] += q[1] / h;
            torque += (r[0] * q[1] - r[1] * q[0]) / h;
        }
        let err = engine_error(self.t0);
        let r = self
            .scene
            .world
            .body(self.scene.object)
            .map_err(&err)
            .and_then(|mut b| {
                b.apply_force_to_center(Vec2::new(force[0] as f32, force[1] as f32), true)
                    .map_err(&err)?;
                b.apply_torque(torque as f32, true).map_err(&err)
            });
        if let Err(e) = r {
            self.error = Some(e);
        }
    }
}
