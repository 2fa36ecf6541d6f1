//! The rapier3d scene and its stepping loop (see the crate docs).

use std::f64::consts::{PI, TAU};

use pushval_engine::StepRecord;
use pushval_model::{ModelError, Problem, SolverStats, Trajectory};
use rapier3d_f64::prelude::*;

use crate::predict::{Scene, SceneParams};
use crate::{ContactFriction, FeetColliders, Rapier3dRun, Rapier3dSettings, Step3d};

/// Natural frequency (Hz) of the pusher joint's softness: rigid at every
/// step length used here (rapier's default, 1e6 Hz, leaves it slightly soft
/// over very short steps).
const JOINT_FREQUENCY: f64 = 1.0e9;

/// Half-size (m) of the ground cuboid's top face, around the start position.
const GROUND_HALF: f64 = 1.0e3;

/// Fraction of a segment's steps, at its end, over which tail means are taken.
const TAIL: f64 = 0.2;

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
struct State {
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

/// Runs the problem.
pub(crate) fn simulate(problem: &Problem, s: &Rapier3dSettings) -> Result<Rapier3dRun, ModelError> {
    let scene = scene_of(problem, s)?;
    let nominal_loads = scene.rest_loads();
    let body = &problem.body;
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
    world.insert_impulse_joint(pusher, object, joint);

    // Re-pins the pusher on the object's contact point and sets its velocity.
    let drive = |world: &mut PhysicsWorld, st: &State, vel: Vector| -> f64 {
        let anchor = st.pose.transform_point(anchor_local);
        let p = &mut world.bodies[pusher];
        let before = p.translation();
        let drift = ((before.x - anchor.x).powi(2) + (before.y - anchor.y).powi(2)).sqrt();
        p.set_translation(anchor, true);
        p.set_linvel(vel, true);
        p.set_angvel(Vector::ZERO, true);
        drift
    };

    // Settle with the pusher at rest.
    let mut state = read(&world, object, init.theta);
    let settle_steps = (s.settle_time / s.dt).ceil() as usize;
    let mut rest = (vec![0.0; n_feet], vec![0.0; n_feet], 0, 0);
    world.integration_parameters.dt = s.dt;
    for _ in 0..settle_steps {
        drive(&mut world, &state, Vector::ZERO);
        world.step();
        state = read(&world, object, state.theta);
        rest = feet.forces(&world, s.dt);
    }
    let (rest_loads, _, manifolds, manifold_points) = rest;
    let z_rest = state.pose.translation.z;

    // Start: moving with the first push at ω = initial.omega, unless from rest.
    if !init.from_rest {
        let p = problem.pushes[0];
        let vc = p.velocity();
        let local = [vc.x + init.omega * pc[1], vc.y - init.omega * pc[0]];
        let (sn, cs) = state.theta.sin_cos();
        let rb = &mut world.bodies[object];
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

    let mut history = Vec::new();
    history.push(Step3d {
        segment: 0,
        t0: 0.0,
        t1: 0.0,
        x: state.pose.translation.x,
        y: state.pose.translation.y,
        z: state.pose.translation.z,
        theta: state.theta,
        omega: state.omega,
        tilt: state.tilt,
    });
    let mut steps = 0usize;
    let mut max_tilt = 0.0f64;
    let mut max_lift = 0.0f64;
    let mut max_drift = 0.0f64;
    let mut min_loads = vec![f64::INFINITY; n_feet];
    let mut tail_omega = Vec::new();
    let mut tail_loads = Vec::new();
    let mut tail_friction = Vec::new();
    let mut tail_slip = Vec::new();
    // The run's last fifth (steps whose middle is past it), time-weighted.
    let run_from = (1.0 - TAIL) * problem.duration();
    let (mut run_n, mut run_t) = (vec![0.0; n_feet], 0.0);
    let mut t_seg = 0.0;
    for (j, push) in problem.pushes.iter().enumerate() {
        let n = (push.duration / s.dt * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let h = push.duration / n as f64;
        world.integration_parameters.dt = h;
        let tail_from = ((1.0 - TAIL) * n as f64).floor() as usize;
        let mut acc_w = 0.0;
        let mut acc_t = 0.0;
        let mut acc_n = vec![0.0; n_feet];
        let mut acc_f = vec![0.0; n_feet];
        let mut min_slip = vec![f64::INFINITY; n_feet];
        let vc = push.velocity();
        for k in 0..n {
            let t0 = t_seg + k as f64 * h;
            let t1 = if k + 1 == n {
                t_seg + push.duration
            } else {
                t0 + h
            };
            let (sn, cs) = (state.theta + 0.5 * h * state.omega).sin_cos();
            let vel = v3(cs * vc.x - sn * vc.y, sn * vc.x + cs * vc.y, 0.0);
            let drift = drive(&mut world, &state, vel);
            if k > 0 || j > 0 {
                max_drift = max_drift.max(drift);
            }
            world.step();
            steps += 1;
            state = read(&world, object, state.theta);
            let tr = state.pose.translation;
            if !(tr.x.is_finite()
                && tr.y.is_finite()
                && tr.z.is_finite()
                && state.omega.is_finite())
            {
                return Err(ModelError::NonFinite { t: t1, step: steps });
            }
            let (normal, friction, _, _) = feet.forces(&world, h);
            for (m, &f) in min_loads.iter_mut().zip(&normal) {
                *m = m.min(f);
            }
            max_tilt = max_tilt.max(state.tilt);
            max_lift = max_lift.max((tr.z - z_rest).abs());
            if 0.5 * (t0 + t1) >= run_from {
                for (a, &f) in run_n.iter_mut().zip(&normal) {
                    *a += f * h;
                }
                run_t += h;
            }
            if k >= tail_from {
                acc_w += state.omega * h;
                acc_t += h;
                let rb = &world.bodies[object];
                for i in 0..n_feet {
                    acc_n[i] += normal[i] * h;
                    acc_f[i] += friction[i] * h;
                    let p = scene.points[i];
                    let wp = state.pose.transform_point(v3(p[0], p[1], -h_cm));
                    let u = rb.velocity_at_point(wp);
                    min_slip[i] = min_slip[i].min((u.x * u.x + u.y * u.y).sqrt());
                }
            }
            history.push(Step3d {
                segment: j,
                t0,
                t1,
                x: tr.x,
                y: tr.y,
                z: tr.z,
                theta: state.theta,
                omega: state.omega,
                tilt: state.tilt,
            });
        }
        tail_omega.push(acc_w / acc_t);
        tail_loads.push(acc_n.iter().map(|a| a / acc_t).collect());
        tail_friction.push(acc_f.iter().map(|a| a / acc_t).collect());
        tail_slip.push(min_slip);
        t_seg += push.duration;
    }
    let records: Vec<StepRecord> = history.iter().map(record).collect();
    let (samples, segments) = pushval_engine::resample(problem, &records);
    let trajectory = Trajectory {
        model: String::new(),
        samples,
        segments,
        stats: SolverStats {
            rhs_evals: steps,
            steps,
            rejected: 0,
        },
        ..Default::default()
    };
    let _ = body;
    Ok(Rapier3dRun {
        trajectory,
        settings: *s,
        steps,
        wall_time: Default::default(),
        mu: scene.mu.clone(),
        nominal_loads,
        rest_loads,
        segment_tail_omega: tail_omega,
        segment_tail_loads: tail_loads,
        loads: run_n
            .iter()
            .map(|a| a / run_t.max(f64::MIN_POSITIVE))
            .collect(),
        segment_tail_friction: tail_friction,
        segment_tail_min_slip: tail_slip,
        min_loads,
        max_tilt,
        max_lift,
        max_joint_drift: max_drift,
        manifolds,
        manifold_points,
        history,
    })
}

/// The shared resampler's view of a step.
fn record(r: &Step3d) -> StepRecord {
    StepRecord {
        segment: r.segment,
        t0: r.t0,
        t1: r.t1,
        x: r.x,
        y: r.y,
        theta: r.theta,
        omega: r.omega,
    }
}
