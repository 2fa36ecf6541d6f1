//! The rapier3d scene and its stepping loop (see the crate docs).

use std::f64::consts::{PI, TAU};

use pushval_engine::stepping::{Plate, PlateWorld, StepLoop, Stepped, Stepping, SupportForces};
use pushval_model::{ModelError, Problem};
use rapier3d_f64::prelude::*;

use crate::predict::{Scene, SceneParams};
use crate::{ContactFriction, FeetColliders, Rapier3dRun, Rapier3dSettings};

/// Natural frequency (Hz) of the pusher joint's softness: rigid at every
/// step length used here (rapier's default, 1e6 Hz, leaves it slightly soft
/// over very short steps).
const JOINT_FREQUENCY: f64 = 1.0e9;

/// Half-size (m) of the ground cuboid's top face, around the start position.
const GROUND_HALF: f64 = 1.0e3;

/// The prediction scene of `problem` (μ_i from the rest loads): the law
/// crate's [`Scene::of`] with the settings' plain parameters.
pub(crate) fn scene_of(problem: &Problem, s: &Rapier3dSettings) -> Result<Scene, ModelError> {
    Scene::of(problem, &SceneParams::from(s))
}

fn v3(x: f64, y: f64, z: f64) -> Vector {
    Vector::new(x, y, z)
}

/// The object's state as read from the engine.
#[derive(Clone, Copy)]
pub struct State {
    pose: Pose,
    theta: f64,
    omega: f64,
    tilt: f64,
}

fn read(world: &PhysicsWorld, object: RigidBodyHandle, prev_theta: f64) -> State {
    let rb = &world.bodies[object];
    let pose = *rb.position();
    let ex = pose.rotation * Vector::X;
    let ez = pose.rotation * Vector::Z;
    let a = ex.y.atan2(ex.x);
    let mut d = a - prev_theta.rem_euclid(TAU);
    d = (d + PI).rem_euclid(TAU) - PI;
    State {
        pose,
        theta: prev_theta + d,
        omega: rb.angvel().z,
        tilt: ez.z.clamp(-1.0, 1.0).acos(),
    }
}

/// The colliders whose contacts with the ground are read.
struct Feet {
    mode: FeetColliders,
    /// One handle (compound) or one per foot (separate).
    handles: Vec<ColliderHandle>,
    ground: ColliderHandle,
    points: Vec<[f64; 2]>,
}

impl Feet {
    /// Normal force and friction force magnitude (N) of every foot over the
    /// last step of length `h`, and the number of solver manifolds and points.
    fn forces(&self, world: &PhysicsWorld, h: f64) -> (Vec<f64>, Vec<f64>, usize, usize) {
        let n = self.points.len();
        let mut normal = vec![0.0; n];
        let mut friction = vec![0.0; n];
        let mut manifolds = 0;
        let mut points = 0;
        for (hi, &handle) in self.handles.iter().enumerate() {
            let Some(pair) = world.narrow_phase.contact_pair(handle, self.ground) else {
                continue;
            };
            let Some(rigid) = pair.rigid() else { continue };
            let object_first = pair.collider1 == handle;
            for m in rigid.solver_manifolds() {
                if !m.data.solver_contacts.is_empty() {
                    manifolds += 1;
                    points += m.data.solver_contacts.len();
                }
                for pt in &m.points {
                    let foot = match self.mode {
                        FeetColliders::Separate => hi,
                        FeetColliders::Compound => {
                            let local = if object_first {
                                m.subshape_pos1()
                                    .map_or(pt.local_p1, |p| p.transform_point(pt.local_p1))
                            } else {
                                m.subshape_pos2()
                                    .map_or(pt.local_p2, |p| p.transform_point(pt.local_p2))
                            };
                            nearest(&self.points, local.x, local.y)
                        }
                    };
                    normal[foot] += pt.data.impulse.abs() / h;
                    friction[foot] += pt.data.tangent_impulse.norm() / h;
                }
            }
        }
        (normal, friction, manifolds, points)
    }
}

fn nearest(points: &[[f64; 2]], x: f64, y: f64) -> usize {
    let mut best = (0, f64::INFINITY);
    for (i, p) in points.iter().enumerate() {
        let d = (p[0] - x).powi(2) + (p[1] - y).powi(2);
        if d < best.1 {
            best = (i, d);
        }
    }
    best.0
}

/// The scene as the shared stepping loop sees it.
pub struct Scene3d {
    world: PhysicsWorld,
    object: RigidBodyHandle,
    pusher: RigidBodyHandle,
    /// The pusher's joint, removed at the release.
    joint: ImpulseJointHandle,
    /// The pusher joint's anchor in the object's frame.
    anchor_local: Vector,
    feet: Feet,
    /// Height of the centre of mass above the ground (m).
    h_cm: f64,
}

impl PlateWorld for Scene3d {
    type State = State;

    fn plate(&self, st: &State) -> Plate {
        let tr = st.pose.translation;
        Plate {
            x: tr.x,
            y: tr.y,
            z: tr.z,
            theta: st.theta,
            omega: st.omega,
            tilt: st.tilt,
        }
    }

    /// Re-pins the pusher on the object's contact point and sets its velocity.
    fn drive(&mut self, st: &State, vel: [f64; 2], _h: f64) -> f64 {
        self.pin(st, v3(vel[0], vel[1], 0.0))
    }

    fn step(&mut self, h: f64, _t1: f64) -> Result<(), ModelError> {
        self.world.integration_parameters.dt = h;
        self.world.step();
        Ok(())
    }

    fn state(&mut self, prev: &State) -> State {
        read(&self.world, self.object, prev.theta)
    }

    fn support_forces(&mut self, _st: &State, h: f64) -> Result<Option<SupportForces>, ModelError> {
        let (normal, friction, _, _) = self.feet.forces(&self.world, h);
        Ok(Some(SupportForces {
            normal,
            friction: Some(friction),
        }))
    }

    fn slip(&self, st: &State, i: usize) -> Option<f64> {
        let rb = &self.world.bodies[self.object];
        let p = self.feet.points[i];
        let wp = st.pose.transform_point(v3(p[0], p[1], -self.h_cm));
        let u = rb.velocity_at_point(wp);
        Some((u.x * u.x + u.y * u.y).sqrt())
    }

    fn cm_velocity(&self, _st: &State) -> Option<[f64; 2]> {
        let v = self.world.bodies[self.object].linvel();
        Some([v.x, v.y])
    }

    /// Removes the pusher's joint and stops the pusher; a throw sets the
    /// object's horizontal velocity and its spin about the vertical. The
    /// slide is the engine's own: the feet's contact friction on the floor
    /// (nothing is applied besides).
    fn release(&mut self, _st: &State, throw: Option<([f64; 2], f64)>) -> Result<(), ModelError> {
        self.world.remove_impulse_joint(self.joint);
        {
            let p = &mut self.world.bodies[self.pusher];
            p.set_linvel(Vector::ZERO, true);
            p.set_angvel(Vector::ZERO, true);
        }
        if let Some((v, omega)) = throw {
            let rb = &mut self.world.bodies[self.object];
            let (vz, w) = (rb.linvel().z, rb.angvel());
            rb.set_linvel(v3(v[0], v[1], vz), true);
            rb.set_angvel(v3(w.x, w.y, omega), true);
        }
        Ok(())
    }
}

impl Scene3d {
    /// Re-pins the pusher on the object's contact point and sets its
    /// velocity; returns how far it was from that point (m, horizontal).
    fn pin(&mut self, st: &State, vel: Vector) -> f64 {
        let anchor = st.pose.transform_point(self.anchor_local);
        let p = &mut self.world.bodies[self.pusher];
        let before = p.translation();
        let drift = ((before.x - anchor.x).powi(2) + (before.y - anchor.y).powi(2)).sqrt();
        p.set_translation(anchor, true);
        p.set_linvel(vel, true);
        p.set_angvel(Vector::ZERO, true);
        drift
    }
}

/// What the set-up measured, for the run's outputs.
pub(crate) struct SetUp {
    settings: Rapier3dSettings,
    mu: Vec<f64>,
    nominal_loads: Vec<f64>,
    rest_loads: Vec<f64>,
    manifolds: usize,
    manifold_points: usize,
}

/// Builds the scene, settles it and hands it to the shared loop; an object
/// not starting at rest starts with the first push of `problem`'s schedule.
pub(crate) fn start(
    problem: &Problem,
    s: &Rapier3dSettings,
) -> Result<(Stepping<Scene3d>, SetUp), ModelError> {
    let scene = scene_of(problem, s)?;
    let nominal_loads = scene.rest_loads();
    let init = problem.initial;
    let n_feet = scene.points.len();
    let pc = scene.contact;
    let h_cm = s.cm_height;

    let mut world = PhysicsWorld::new();
    world.gravity = v3(0.0, 0.0, -s.gravity);
    {
        let ip = &mut world.integration_parameters;
        ip.num_solver_iterations = s.solver_iterations;
        ip.num_internal_pgs_iterations = s.pgs_iterations;
        ip.friction_model = match s.friction {
            ContactFriction::Coulomb => FrictionModel::Coulomb,
            ContactFriction::Simplified => FrictionModel::Simplified,
        };
        ip.contact_recycling = s.contact_recycling;
        ip.dt = s.dt;
    }

    // Ground: top face at z = 0.
    let ground = world.insert_body(RigidBodyBuilder::fixed().translation(v3(
        init.position.x,
        init.position.y,
        -0.5,
    )));
    let ground_col = world.insert_collider(
        ColliderBuilder::cuboid(GROUND_HALF, GROUND_HALF, 0.5)
            .friction(1.0)
            .friction_combine_rule(CoefficientCombineRule::Multiply)
            .restitution(0.0),
        Some(ground),
    );

    // Object: origin at the centre of mass, feet just touching the ground.
    let rot0 = Rotation::from_rotation_z(init.theta);
    let object = world.insert_body(
        RigidBodyBuilder::dynamic()
            .pose(Pose::from_parts(
                v3(init.position.x, init.position.y, h_cm),
                rot0,
            ))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                scene.mass,
                v3(scene.ixx, scene.iyy, scene.inertia_z),
            ))
            .can_sleep(false),
    );
    let r = s.foot_radius;
    let foot_pos = |p: [f64; 2]| v3(p[0], p[1], -h_cm + r);
    let handles: Vec<ColliderHandle> = match s.feet {
        FeetColliders::Compound => {
            let shapes: Vec<(Pose, SharedShape)> = scene
                .points
                .iter()
                .map(|&p| (Pose::from_translation(foot_pos(p)), SharedShape::ball(r)))
                .collect();
            vec![world.insert_collider(
                ColliderBuilder::compound(shapes)
                    .density(0.0)
                    .friction(scene.mu[0])
                    .friction_combine_rule(CoefficientCombineRule::Multiply)
                    .restitution(0.0),
                Some(object),
            )]
        }
        FeetColliders::Separate => scene
            .points
            .iter()
            .zip(&scene.mu)
            .map(|(&p, &mu)| {
                world.insert_collider(
                    ColliderBuilder::ball(r)
                        .translation(foot_pos(p))
                        .density(0.0)
                        .friction(mu)
                        .friction_combine_rule(CoefficientCombineRule::Multiply)
                        .restitution(0.0),
                    Some(object),
                )
            })
            .collect(),
    };
    let feet = Feet {
        mode: s.feet,
        handles,
        ground: ground_col,
        points: scene.points.clone(),
    };

    // Pusher: a horizontal-only joint at (p_c, push_height).
    let anchor_local = v3(pc[0], pc[1], s.push_height - h_cm);
    let anchor0 = Pose::from_parts(v3(init.position.x, init.position.y, h_cm), rot0)
        .transform_point(anchor_local);
    let pusher = world.insert_body(
        RigidBodyBuilder::kinematic_velocity_based()
            .translation(anchor0)
            .can_sleep(false),
    );
    let joint = GenericJointBuilder::new(JointAxesMask::LIN_X | JointAxesMask::LIN_Y)
        .local_anchor1(Vector::ZERO)
        .local_anchor2(anchor_local)
        .contacts_enabled(false)
        .softness(SpringCoefficients::new(JOINT_FREQUENCY, 1.0));
    let joint = world.insert_impulse_joint(pusher, object, joint);
    let mut w = Scene3d {
        world,
        object,
        pusher,
        joint,
        anchor_local,
        feet,
        h_cm,
    };

    // Settle with the pusher at rest.
    let mut state = read(&w.world, object, init.theta);
    let settle_steps = (s.settle_time / s.dt).ceil() as usize;
    let mut rest = (vec![0.0; n_feet], vec![0.0; n_feet], 0, 0);
    w.world.integration_parameters.dt = s.dt;
    for _ in 0..settle_steps {
        w.pin(&state, Vector::ZERO);
        w.world.step();
        state = read(&w.world, object, state.theta);
        rest = w.feet.forces(&w.world, s.dt);
    }
    let (rest_loads, _, manifolds, manifold_points) = rest;
    let z_rest = state.pose.translation.z;

    // Start: moving with the first push at ω = initial.omega, unless from rest.
    if !init.from_rest {
        let p = *problem.pushes.first().ok_or(ModelError::EmptySchedule)?;
        let vc = p.velocity();
        let local = [vc.x + init.omega * pc[1], vc.y - init.omega * pc[0]];
        let (sn, cs) = state.theta.sin_cos();
        let rb = &mut w.world.bodies[object];
        let vz = rb.linvel().z;
        rb.set_linvel(
            v3(
                cs * local[0] - sn * local[1],
                sn * local[0] + cs * local[1],
                vz,
            ),
            true,
        );
        rb.set_angvel(v3(0.0, 0.0, init.omega), true);
        state.omega = init.omega;
    }

    let cfg = StepLoop::new(s.dt, n_feet, z_rest);
    let set_up = SetUp {
        settings: *s,
        mu: scene.mu.clone(),
        nominal_loads,
        rest_loads,
        manifolds,
        manifold_points,
    };
    Ok((Stepping::new(w, problem, cfg, state), set_up))
}

/// The run of the pushes applied (`problem`'s schedule), from what the loop
/// gathered.
pub(crate) fn finish(set_up: SetUp, run: Stepped, problem: &Problem) -> Rapier3dRun {
    Rapier3dRun {
        trajectory: run.trajectory(problem),
        settings: set_up.settings,
        steps: run.steps,
        wall_time: Default::default(),
        mu: set_up.mu,
        nominal_loads: set_up.nominal_loads,
        rest_loads: set_up.rest_loads,
        segment_tail_omega: run.segment_tail_omega,
        segment_tail_loads: run.segment_tail_loads,
        loads: run.loads,
        contact: run.contact,
        segment_tail_friction: run.segment_tail_friction,
        segment_tail_min_slip: run.segment_tail_min_slip,
        min_loads: run.min_loads,
        max_tilt: run.max_tilt,
        max_lift: run.max_lift,
        max_joint_drift: run.max_joint_drift,
        manifolds: set_up.manifolds,
        manifold_points: set_up.manifold_points,
        history: run.history,
    }
}
