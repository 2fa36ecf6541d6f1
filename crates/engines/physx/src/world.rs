//! The PhysX scene in the shared stepping loop (see the crate docs).

use std::f64::consts::{PI, TAU};
use std::sync::{Arc, Mutex, MutexGuard};

use physx::material::Material;
use physx::prelude::*;
use physx::traits::Class;
use pushval_engine::stepping::{
    Plate, PlateWorld, StepLoop, Stepped, Stepping, SupportForces, TAIL,
};
use pushval_model::{ModelError, Problem};

use crate::sys;
use crate::{FootContacts, FrictionType, PhysxRun, PhysxSettings};

type PxMaterial = physx::material::PxMaterial<()>;
/// Shape user data: the foot's index + 1 (0 for the ground).
type PxShape = physx::shape::PxShape<usize, PxMaterial>;
type PxArticulationLink = physx::articulation_link::PxArticulationLink<(), PxShape>;
type PxRigidStatic = physx::rigid_static::PxRigidStatic<(), PxShape>;
/// Actor user data: [`OBJECT`] or [`PUSHER`].
type PxRigidDynamic = physx::rigid_dynamic::PxRigidDynamic<usize, PxShape>;
type PxArticulation =
    physx::articulation_reduced_coordinate::PxArticulationReducedCoordinate<(), PxArticulationLink>;
type PxScene = physx::scene::PxScene<
    (),
    PxArticulationLink,
    PxRigidStatic,
    PxRigidDynamic,
    PxArticulation,
    OnCollision,
    NoTrigger,
    NoConstraintBreak,
    NoWakeSleep,
    NoAdvance,
>;

const OBJECT: usize = 1;
const PUSHER: usize = 2;

/// PhysX keeps one foundation per process: runs take turns.
static FOUNDATION: Mutex<()> = Mutex::new(());

/// Normal impulses (N s) of the feet over the last step, from the contact
/// reports (indexed by foot).
#[derive(Default)]
struct ContactLog {
    /// Shape pointer of each foot, to match the reported pairs.
    feet: Vec<usize>,
    impulse: Vec<f64>,
}

struct OnCollision(Arc<Mutex<ContactLog>>);

impl CollisionCallback for OnCollision {
    fn on_collision(
        &mut self,
        _header: &physx_sys::PxContactPairHeader,
        pairs: &[physx_sys::PxContactPair],
    ) {
        let mut log = self.0.lock().unwrap_or_else(|e| e.into_inner());
        for pair in pairs {
            let foot = pair
                .shapes
                .iter()
                .find_map(|&s| log.feet.iter().position(|&f| f == s as usize));
            if let Some(i) = foot {
                log.impulse[i] += sys::normal_impulse(pair);
            }
        }
    }
}

struct NoTrigger;
impl TriggerCallback for NoTrigger {
    fn on_trigger(&mut self, _pairs: &[physx_sys::PxTriggerPair]) {}
}
struct NoConstraintBreak;
impl ConstraintBreakCallback for NoConstraintBreak {
    fn on_constraint_break(&mut self, _constraints: &[physx_sys::PxConstraintInfo]) {}
}
struct NoWakeSleep;
impl WakeSleepCallback<PxArticulationLink, PxRigidStatic, PxRigidDynamic> for NoWakeSleep {
    fn on_wake_sleep(
        &mut self,
        _actors: &[&physx::actor::ActorMap<PxArticulationLink, PxRigidStatic, PxRigidDynamic>],
        _is_waking: bool,
    ) {
    }
}
struct NoAdvance;
impl AdvanceCallback<PxArticulationLink, PxRigidDynamic> for NoAdvance {
    fn on_advance(
        &self,
        _actors: &[&physx::rigid_body::RigidBodyMap<PxArticulationLink, PxRigidDynamic>],
        _transforms: &[PxTransform],
    ) {
    }
}

fn v3(x: f64, y: f64, z: f64) -> PxVec3 {
    PxVec3::new(x as f32, y as f32, z as f32)
}

fn yaw(theta: f64) -> PxQuat {
    let (s, c) = (0.5 * theta).sin_cos();
    PxQuat::new(0.0, 0.0, s as f32, c as f32)
}

fn raw(t: PxTransform) -> physx_sys::PxTransform {
    t.into()
}

/// The object's state as read from the engine.
#[derive(Clone, Copy)]
pub struct State {
    pose: PxTransform,
    vel: [f64; 3],
    theta: f64,
    omega: f64,
    tilt: f64,
}

impl State {
    fn position(&self) -> [f64; 3] {
        let p = self.pose.translation();
        [p.x() as f64, p.y() as f64, p.z() as f64]
    }

    /// A point given in the object's frame, in the world (m).
    fn world(&self, local: PxVec3) -> [f64; 3] {
        let p = self.pose.transform_vector(&local);
        [p.x() as f64, p.y() as f64, p.z() as f64]
    }
}

fn actor(scene: &mut PxScene, tag: usize) -> &mut PxRigidDynamic {
    scene
        .get_dynamic_actors()
        .into_iter()
        .find(|a| *a.get_user_data() == tag)
        .expect("the scene holds the object and the pusher")
}

fn read(scene: &mut PxScene, prev_theta: f64) -> State {
    let a = actor(scene, OBJECT);
    let pose = a.get_global_pose();
    let q = pose.rotation();
    let ex = q.get_basis_vector_x();
    let angle = (ex.y() as f64).atan2(ex.x() as f64);
    let mut d = angle - prev_theta.rem_euclid(TAU);
    d = (d + PI).rem_euclid(TAU) - PI;
    let v = a.get_linear_velocity();
    State {
        pose,
        vel: [v.x() as f64, v.y() as f64, v.z() as f64],
        theta: prev_theta + d,
        omega: a.get_angular_velocity().z() as f64,
        // cos(tilt) = 1 − 2 (q_x² + q_y²), in f64 from the components.
        tilt: 2.0 * ((q.x() as f64).hypot(q.y() as f64)).min(1.0).asin(),
    }
}

fn physx_error(what: &str) -> ModelError {
    ModelError::Integration {
        t: 0.0,
        reason: format!("PhysX: {what}"),
    }
}

/// The scene of `problem` (checked by the caller) in PhysX, settled and
/// given its start velocity (moving with the first push of its schedule
/// unless it starts at rest), in the shared stepping loop. The loop's world
/// holds PhysX's turn (one foundation per process) until it is dropped.
pub(crate) fn start(problem: &Problem, s: &PhysxSettings) -> Result<Stepping<Stepper>, ModelError> {
    let turn = FOUNDATION.lock().unwrap_or_else(|e| e.into_inner());
    let body = &problem.body;
    let mu = body.total_friction() / (body.mass() * s.gravity);
    let mut physics = PhysicsFoundation::<physx::foundation::DefaultAllocator, PxShape>::default();
    // Dropped before `physics` on an early return (declared after it).
    let mut world = World::new(&mut physics, problem, s, mu)?;
    let settled = world.settle(problem, s)?;
    let (state, cfg) = world.start(problem, s, settled.state)?;
    let w = Stepper {
        world,
        _physics: physics,
        _turn: turn,
        loads: Vec::new(),
        acc_f: [0.0; 2],
        tail_force: Vec::new(),
        mu,
        rest_loads: settled.loads,
    };
    Ok(Stepping::new(w, problem, cfg, state))
}

/// The run of the pushes applied (`problem`), from what the loop gathered.
pub(crate) fn finish(w: Stepper, run: Stepped, problem: &Problem, s: &PhysxSettings) -> PhysxRun {
    let mu = w.mu;
    PhysxRun {
        trajectory: run.trajectory(problem),
        settings: *s,
        steps: run.steps,
        wall_time: Default::default(),
        mu,
        engine_friction: w.rest_loads.iter().map(|n| mu * n).collect(),
        rest_loads: w.rest_loads.clone(),
        segment_tail_omega: run.segment_tail_omega,
        segment_tail_omega_std: run.segment_tail_omega_std,
        segment_tail_loads: run.segment_tail_loads,
        loads: run.loads,
        contact: run.contact,
        segment_tail_pusher_force: w.tail_force.clone(),
        min_loads: run.min_loads,
        max_tilt: run.max_tilt,
        max_lift: run.max_lift,
        max_joint_drift: run.max_joint_drift,
        history: run.history,
    }
}

/// A built scene. Dropped in PhysX's order: the joint, the scene with its
/// actors, the CPU dispatcher it ran on, then the materials.
struct World {
    joint: Option<sys::D6Joint>,
    scene: Option<Owner<PxScene>>,
    dispatcher: Option<sys::Dispatcher>,
    materials: Vec<Owner<PxMaterial>>,
    log: Arc<Mutex<ContactLog>>,
    /// The pusher joint's anchor in the object's frame.
    anchor_local: PxVec3,
}

impl Drop for World {
    fn drop(&mut self) {
        drop(self.joint.take());
        drop(self.scene.take());
        if let Some(d) = self.dispatcher.take() {
            d.release();
        }
    }
}

/// The end of the settle phase.
struct Settled {
    state: State,
    /// Mean normal force of each foot over the last 20 % of the phase (N).
    loads: Vec<f64>,
}

impl World {
    /// The scene of `problem` with friction coefficient `mu` on every foot.
    fn new(
        physics: &mut PhysicsFoundation<physx::foundation::DefaultAllocator, PxShape>,
        problem: &Problem,
        s: &PhysxSettings,
        mu: f64,
    ) -> Result<Self, ModelError> {
        let body = &problem.body;
        let init = problem.initial;
        let pc = body.contact();
        let h_cm = s.cm_height;
        let mass = body.mass();
        let iz = body.inertia_cm();
        let tilt_inertia = 0.5 * iz + mass * s.plate_thickness * s.plate_thickness / 12.0;

        let log = Arc::new(Mutex::new(ContactLog {
            feet: Vec::new(),
            impulse: vec![0.0; body.len()],
        }));
        let scene: Owner<PxScene> = physics
            .create(SceneDescriptor {
                gravity: v3(0.0, 0.0, -s.gravity),
                friction_type: match s.friction {
                    FrictionType::Patch => physx_sys::PxFrictionType::Patch,
                    FrictionType::TwoDirectional => physx_sys::PxFrictionType::TwoDirectional,
                    FrictionType::OneDirectional => physx_sys::PxFrictionType::OneDirectional,
                },
                solver_type: SolverType::Pgs,
                // Tasks run on the calling thread: deterministic, no workers.
                thread_count: 0,
                on_collide: Some(OnCollision(log.clone())),
                simulation_filter_shader: FilterShaderDescriptor::Custom(sys::report_contacts),
                ..SceneDescriptor::new(())
            })
            .ok_or_else(|| physx_error("scene creation failed"))?;
        // Owned by `world` from here on, so that an early return still
        // releases everything in order.
        let mut world = World {
            joint: None,
            dispatcher: Some(sys::Dispatcher::of(scene.as_ref())),
            scene: Some(scene),
            materials: Vec::new(),
            log,
            anchor_local: v3(pc.x, pc.y, s.push_height - h_cm),
        };
        let mut material = |mu: f64| -> Result<Owner<PxMaterial>, ModelError> {
            let mut m = physics
                .create_material(mu as f32, mu as f32, 0.0, ())
                .ok_or_else(|| physx_error("material creation failed"))?;
            m.set_friction_combined_mode(physx_sys::PxCombineMode::Multiply);
            Ok(m)
        };
        // The ground's, and the one every foot shares.
        world.materials = vec![material(1.0)?, material(mu)?];

        let ground = physics
            .create_plane(v3(0.0, 0.0, 1.0), 0.0, world.materials[0].as_mut(), ())
            .ok_or_else(|| physx_error("ground creation failed"))?;
        world.scene().add_static_actor(ground);

        // Object: origin at the centre of mass, feet just touching the ground.
        let pose0 = PxTransform::from_translation_rotation(
            &v3(init.position.x, init.position.y, h_cm),
            &yaw(init.theta),
        );
        let mut object = physics
            .create_dynamic(&pose0, OBJECT)
            .ok_or_else(|| physx_error("object creation failed"))?;
        let r = s.foot_radius;
        let mut feet = Vec::with_capacity(body.len());
        for (i, sup) in body.supports().enumerate() {
            let p = sup.position;
            let mut shape = physics
                .create_shape(
                    &PxSphereGeometry::new(r as f32),
                    &mut [world.materials[1].as_mut()],
                    true,
                    ShapeFlags::SimulationShape,
                    i + 1,
                )
                .ok_or_else(|| physx_error("shape creation failed"))?;
            if s.contacts == FootContacts::Separate {
                shape.set_simulation_filter_data(
                    CollisionLayers::empty(),
                    CollisionLayers::empty(),
                    0,
                    sys::UNWELDED,
                );
            }
            sys::set_local_pose(
                shape.as_mut(),
                raw(PxTransform::from_translation(&v3(p.x, p.y, -h_cm + r))),
            );
            object.attach_shape(shape.as_mut());
            feet.push(Class::<physx_sys::PxShape>::as_ptr(shape.as_ref()) as usize);
        }
        world.log.lock().unwrap_or_else(|e| e.into_inner()).feet = feet;
        object.set_mass(mass as f32);
        object.set_mass_space_inertia_tensor(&v3(tilt_inertia, tilt_inertia, iz));
        object.set_linear_damping(0.0);
        object.set_angular_damping(0.0);
        object.set_max_angular_velocity(1.0e4);
        object.set_sleep_threshold(0.0);
        object.set_solver_iteration_counts(s.position_iterations, s.velocity_iterations);

        // Pusher: kinematic, no shapes, on the contact point at push height.
        let mut pusher = physics
            .create_dynamic(
                &PxTransform::from_translation(&pose0.transform_vector(&world.anchor_local)),
                PUSHER,
            )
            .ok_or_else(|| physx_error("pusher creation failed"))?;
        pusher.set_rigid_body_flag(RigidBodyFlag::Kinematic, true);
        pusher.set_sleep_threshold(0.0);
        world.joint = Some(
            sys::D6Joint::new(
                physics,
                pusher.as_mut(),
                raw(PxTransform::default()),
                object.as_mut(),
                raw(PxTransform::from_translation(&world.anchor_local)),
            )
            .ok_or_else(|| physx_error("joint creation failed"))?,
        );
        world.scene().add_dynamic_actor(object);
        world.scene().add_dynamic_actor(pusher);
        Ok(world)
    }

    fn scene(&mut self) -> &mut PxScene {
        self.scene.as_mut().expect("built in World::new")
    }

    /// Puts the pusher back on the object's contact point and gives it the
    /// kinematic target that moves it at `vel` (m/s, world) over `h` (s).
    /// Returns how far it was from the contact point (m, horizontal).
    fn drive(&mut self, st: &State, vel: [f64; 2], h: f64) -> f64 {
        let a = st.world(self.anchor_local);
        let p = actor(self.scene(), PUSHER);
        let before = p.get_global_position();
        let drift =
            ((before.x() as f64 - a[0]).powi(2) + (before.y() as f64 - a[1]).powi(2)).sqrt();
        p.set_global_pose(&PxTransform::from_translation(&v3(a[0], a[1], a[2])), true);
        p.set_kinematic_target(&PxTransform::from_translation(&v3(
            a[0] + vel[0] * h,
            a[1] + vel[1] * h,
            a[2],
        )));
        drift
    }

    /// One engine step of length `h` ending at `t`; returns the feet's normal
    /// forces (N).
    fn step(&mut self, h: f64, t: f64) -> Result<Vec<f64>, ModelError> {
        let log = self.log.clone();
        log.lock()
            .unwrap_or_else(|e| e.into_inner())
            .impulse
            .iter_mut()
            .for_each(|x| *x = 0.0);
        self.scene()
            .step(h as f32, None::<&mut physx_sys::PxBaseTask>, None, true)
            .map_err(|code| ModelError::Integration {
                t,
                reason: format!("PhysX fetchResults failed (error {code})"),
            })?;
        let log = log.lock().unwrap_or_else(|e| e.into_inner());
        Ok(log.impulse.iter().map(|j| j / h).collect())
    }

    /// Settles with the pusher at rest for `settle_time`.
    fn settle(&mut self, problem: &Problem, s: &PhysxSettings) -> Result<Settled, ModelError> {
        let n_feet = problem.body.len();
        let mut state = read(self.scene(), problem.initial.theta);
        let steps = (s.settle_time / s.dt).ceil() as usize;
        let tail = ((1.0 - TAIL) * steps as f64).floor() as usize;
        let mut loads = vec![0.0; n_feet];
        let mut count = 0usize;
        for k in 0..steps {
            self.drive(&state, [0.0, 0.0], s.dt);
            let step = self.step(s.dt, 0.0)?;
            state = read(self.scene(), state.theta);
            if k >= tail {
                for (a, l) in loads.iter_mut().zip(&step) {
                    *a += l;
                }
                count += 1;
            }
        }
        if count > 0 {
            loads.iter_mut().for_each(|a| *a /= count as f64);
        }
        Ok(Settled { state, loads })
    }

    /// The start of the push from the settled state `state`: moving with
    /// the first push at ω = initial.omega, unless from rest. Returns the
    /// state and the loop's settings.
    fn start(
        &mut self,
        problem: &Problem,
        s: &PhysxSettings,
        mut state: State,
    ) -> Result<(State, StepLoop), ModelError> {
        let init = problem.initial;
        let n_feet = problem.body.len();
        let pc = problem.body.contact();
        let z_rest = state.position()[2];

        if !init.from_rest {
            let vc = problem
                .pushes
                .first()
                .ok_or(ModelError::EmptySchedule)?
                .velocity();
            let local = [vc.x + init.omega * pc.y, vc.y - init.omega * pc.x];
            let (sn, cs) = state.theta.sin_cos();
            let o = actor(self.scene(), OBJECT);
            o.set_linear_velocity(
                &v3(
                    cs * local[0] - sn * local[1],
                    sn * local[0] + cs * local[1],
                    state.vel[2],
                ),
                true,
            );
            o.set_angular_velocity(&v3(0.0, 0.0, init.omega), true);
            state.omega = init.omega;
        }
        Ok((state, StepLoop::new(s.dt, n_feet, z_rest)))
    }
}

/// The scene as the shared stepping loop sees it: the world, the
/// foundation it was built in and PhysX's turn (dropped in that order), and
/// what the settle phase found.
pub struct Stepper {
    world: World,
    /// Dropped after the world.
    _physics: PhysicsFoundation<physx::foundation::DefaultAllocator, PxShape>,
    /// Released last.
    _turn: MutexGuard<'static, ()>,
    /// The feet's normal forces over the last step (N).
    loads: Vec<f64>,
    /// The current segment's tail integral of the pusher's force on the
    /// object (object frame, N s).
    acc_f: [f64; 2],
    /// Per segment, that force's tail mean (N).
    tail_force: Vec<[f64; 2]>,
    /// The friction coefficient of every foot.
    mu: f64,
    /// Mean normal force of each foot over the last 20 % of the settle
    /// phase (N).
    rest_loads: Vec<f64>,
}

impl PlateWorld for Stepper {
    type State = State;

    fn plate(&self, st: &State) -> Plate {
        let p = st.position();
        Plate {
            x: p[0],
            y: p[1],
            z: p[2],
            theta: st.theta,
            omega: st.omega,
            tilt: st.tilt,
        }
    }

    fn drive(&mut self, st: &State, vel: [f64; 2], h: f64) -> f64 {
        self.world.drive(st, vel, h)
    }

    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError> {
        self.loads = self.world.step(h, t1)?;
        Ok(())
    }

    fn state(&mut self, prev: &State) -> State {
        read(self.world.scene(), prev.theta)
    }

    fn support_forces(&mut self, _: &State, _h: f64) -> Result<Option<SupportForces>, ModelError> {
        Ok(Some(SupportForces {
            normal: self.loads.clone(),
            friction: None,
        }))
    }

    fn tail_step(&mut self, st: &State, h: f64) -> Result<(), ModelError> {
        // The object feels the opposite of the force on the pusher; turned
        // into the object frame.
        let f = self
            .world
            .joint
            .as_ref()
            .map_or([0.0; 3], |j| j.force_on_pusher());
        let (sn, cs) = st.theta.sin_cos();
        self.acc_f[0] -= (cs * f[0] + sn * f[1]) * h;
        self.acc_f[1] -= (-sn * f[0] + cs * f[1]) * h;
        Ok(())
    }

    fn cm_velocity(&self, st: &State) -> Option<[f64; 2]> {
        Some([st.vel[0], st.vel[1]])
    }

    fn end_segment(&mut self, acc_t: f64, _t: f64) -> Result<(), ModelError> {
        self.tail_force
            .push([self.acc_f[0] / acc_t, self.acc_f[1] / acc_t]);
        self.acc_f = [0.0; 2];
        Ok(())
    }

    /// Releases the pusher's D6 joint (the kinematic pusher, which has no
    /// shapes, stays where it is); a throw sets the object's horizontal
    /// velocity and its spin about the vertical. The slide is the engine's
    /// own: the feet's contact friction on the ground (see the crate docs).
    fn release(&mut self, _st: &State, throw: Option<([f64; 2], f64)>) -> Result<(), ModelError> {
        drop(self.world.joint.take());
        if let Some((v, omega)) = throw {
            let o = actor(self.world.scene(), OBJECT);
            let (vz, w) = (o.get_linear_velocity().z(), o.get_angular_velocity());
            o.set_linear_velocity(&PxVec3::new(v[0] as f32, v[1] as f32, vz), true);
            o.set_angular_velocity(&PxVec3::new(w.x(), w.y(), omega as f32), true);
        }
        Ok(())
    }
}
