//! The rapier world for one precision. This file is compiled twice (see
//! `lib.rs`): `super::rapier` is `rapier2d-f64` in one build and `rapier2d`
//! (f32) in the other, and `Real` follows it. Everything outside this file
//! works in f64.

// `as Real` is a no-op in the f64 build and a narrowing in the f32 one.
#![allow(clippy::unnecessary_cast)]

use super::rapier::prelude::*;

use crate::history::{RawRun, StepRecord};
use crate::{EngineSettings, FrictionVelocity};
use pushval_model::{ModelError, Problem, Push};

/// Sliding speeds (m/s) at or below this give no friction force (the direction
/// is undefined there); it keeps every force finite.
const MIN_SLIDING_SPEED: f64 = 1e-12;

/// Natural frequency (Hz) of the pin joint's softness. rapier's default (1e6 Hz)
/// leaves the joint about 2 % soft over the short switch step (a visible
/// shortfall in the switch impulse); at 1e9 Hz the joint is rigid for every
/// step length used here and drift is corrected fully at each substep.
const JOINT_FREQUENCY: Real = 1.0e9;

fn v(x: f64, y: f64) -> Vector {
    Vector::new(x as Real, y as Real)
}

/// `R(θ) a` in f64.
fn rot(theta: f64, a: [f64; 2]) -> [f64; 2] {
    let (s, c) = theta.sin_cos();
    [c * a[0] - s * a[1], s * a[0] + c * a[1]]
}

/// The object's state as read from the engine, in f64.
#[derive(Clone, Copy)]
struct State {
    x: f64,
    y: f64,
    /// Unwrapped angle.
    theta: f64,
    omega: f64,
}

/// Runs the problem in this precision's rapier build.
pub(crate) fn simulate(problem: &Problem, settings: &EngineSettings) -> Result<RawRun, ModelError> {
    let body = &problem.body;
    let init = problem.initial;
    let pc = [body.contact().x, body.contact().y];
    let supports: Vec<([f64; 2], f64)> = body
        .supports()
        .map(|s| ([s.position.x, s.position.y], s.friction))
        .collect();

    let mut world = PhysicsWorld::new();
    world.gravity = Vector::ZERO;
    world.integration_parameters.num_solver_iterations = settings.solver_iterations;
    world.integration_parameters.num_internal_pgs_iterations = settings.pgs_iterations;

    // Initial velocities: at rest, or moving with the first push at ω = initial.omega.
    let (v0, w0) = if init.from_rest {
        ([0.0, 0.0], 0.0)
    } else {
        let p = problem.pushes[0];
        let vc = p.velocity();
        // v_cm = R(θ)(v n_φ − ω D p_c), D p_c = (−p_c,y, p_c,x)
        let local = [vc.x + init.omega * pc[1], vc.y - init.omega * pc[0]];
        (rot(init.theta, local), init.omega)
    };

    let object = world.insert_body(
        RigidBodyBuilder::dynamic()
            .translation(v(init.position.x, init.position.y))
            .rotation(init.theta as Real)
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                body.mass() as Real,
                body.inertia_cm() as Real,
            ))
            .linvel(v(v0[0], v0[1]))
            .angvel(w0 as Real)
            .can_sleep(false),
    );
    let rc0 = rot(init.theta, pc);
    let pusher = world.insert_body(
        RigidBodyBuilder::kinematic_velocity_based()
            .translation(v(init.position.x + rc0[0], init.position.y + rc0[1]))
            .can_sleep(false),
    );
    let joint = RevoluteJointBuilder::new()
        .local_anchor1(Vector::ZERO)
        .local_anchor2(v(pc[0], pc[1]))
        .contacts_enabled(false)
        .softness(SpringCoefficients::new(JOINT_FREQUENCY, 1.0));
    world.insert_impulse_joint(pusher, object, joint);

    // Mass properties take effect only inside a step: a zero-length one.
    world.integration_parameters.dt = 0.0;
    world.step();

    let read = |world: &PhysicsWorld, prev_theta: f64| -> State {
        let rb = &world.bodies[object];
        let t = rb.translation();
        let a = rb.rotation().angle() as f64;
        // Unwrap: the engine's angle lives in (−π, π].
        let mut d = a - prev_theta.rem_euclid(std::f64::consts::TAU);
        d = (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        State {
            x: t.x as f64,
            y: t.y as f64,
            theta: prev_theta + d,
            omega: rb.angvel() as f64,
        }
    };

    let mut state = read(&world, init.theta);
    let mut history = Vec::with_capacity(16);
    history.push(StepRecord {
        segment: 0,
        t0: 0.0,
        t1: 0.0,
        x: state.x,
        y: state.y,
        theta: state.theta,
        omega: state.omega,
    });
    let mut steps = 0usize;
    let mut max_drift = 0.0f64;
    let mut min_speed = f64::INFINITY;
    let mut t_seg = 0.0;

    for (j, push) in problem.pushes.iter().enumerate() {
        let n = (push.duration / settings.dt * (1.0 - 1e-12))
            .ceil()
            .max(1.0) as usize;
        let h = push.duration / n as f64;
        // Step lengths of this segment: an optional switch step, then n steps
        // whose first one is shortened by the switch step's length.
        let eps = settings.switch_step_fraction * h;
        let mut lengths: Vec<f64> = Vec::with_capacity(n + 1);
        if eps > 0.0 {
            lengths.push(eps);
            lengths.push(h - eps);
        } else {
            lengths.push(h);
        }
        lengths.extend(std::iter::repeat_n(h, n - 1));

        // Step velocities of this segment, placed at step middles, for the
        // midpoint extrapolation.
        let mut nodes: [(f64, f64); 2] = [(f64::NAN, f64::NAN); 2];
        let mut t = t_seg;
        let seg_end = t_seg + push.duration;
        for (k, &len) in lengths.iter().enumerate() {
            let t1 = if k + 1 == lengths.len() {
                seg_end
            } else {
                t + len
            };
            let hk = t1 - t;
            let omega_at = |tq: f64| -> f64 {
                // k = number of steps of this segment already taken.
                match k {
                    0 => state.omega,
                    1 => nodes[1].1,
                    _ => {
                        let (a, b) = (nodes[0], nodes[1]);
                        b.1 + (b.1 - a.1) * (tq - b.0) / (b.0 - a.0)
                    }
                }
            };
            let (omega_f, heading) = match settings.friction_velocity {
                FrictionVelocity::Body | FrictionVelocity::Constraint => (state.omega, state.theta),
                FrictionVelocity::Midpoint => {
                    let w_mid = omega_at(t + 0.5 * hk);
                    (omega_at(t), state.theta + 0.5 * hk * w_mid)
                }
            };
            apply_step_forces(
                &mut world,
                object,
                pusher,
                push,
                &supports,
                pc,
                &state,
                omega_f,
                heading,
                settings.friction_velocity,
                &mut min_speed,
            );
            world.integration_parameters.dt = hk as Real;
            world.step();
            steps += 1;

            state = read(&world, state.theta);
            if !(state.x.is_finite()
                && state.y.is_finite()
                && state.theta.is_finite()
                && state.omega.is_finite())
            {
                return Err(ModelError::NonFinite { t: t1, step: steps });
            }
            let anchor = world.bodies[pusher].translation();
            let rc = rot(state.theta, pc);
            let drift = ((anchor.x as f64 - state.x - rc[0]).powi(2)
                + (anchor.y as f64 - state.y - rc[1]).powi(2))
            .sqrt();
            max_drift = max_drift.max(drift);
            history.push(StepRecord {
                segment: j,
                t0: t,
                t1,
                x: state.x,
                y: state.y,
                theta: state.theta,
                omega: state.omega,
            });
            nodes[0] = nodes[1];
            nodes[1] = (0.5 * (t + t1), state.omega);
            t = t1;
        }
        t_seg = seg_end;
    }
    Ok(RawRun {
        history,
        steps,
        max_drift,
        min_support_speed: if min_speed.is_finite() {
            min_speed
        } else {
            0.0
        },
    })
}

/// Sets the pusher velocity for the coming step and the support friction forces.
#[allow(clippy::too_many_arguments)]
fn apply_step_forces(
    world: &mut PhysicsWorld,
    object: RigidBodyHandle,
    pusher: RigidBodyHandle,
    push: &Push,
    supports: &[([f64; 2], f64)],
    pc: [f64; 2],
    state: &State,
    omega: f64,
    heading: f64,
    mode: FrictionVelocity,
    min_speed: &mut f64,
) {
    let vc = push.velocity();
    let vp = rot(heading, [vc.x, vc.y]);
    {
        let p = &mut world.bodies[pusher];
        p.set_linvel(v(vp[0], vp[1]), true);
        p.set_angvel(0.0, true);
    }
    let rb = &mut world.bodies[object];
    rb.reset_forces(false);
    rb.reset_torques(false);
    let rc = rot(state.theta, pc);
    // The contact velocity the friction sees: the commanded one at the
    // object's current angle (equal to `vp` except in midpoint mode, where
    // `vp` is taken at the mid-step angle).
    let vf = rot(state.theta, [vc.x, vc.y]);
    for &(p, friction) in supports {
        let r = rot(state.theta, p);
        let point = v(state.x + r[0], state.y + r[1]);
        let u = match mode {
            FrictionVelocity::Body => {
                let u = rb.velocity_at_point(point);
                [u.x as f64, u.y as f64]
            }
            FrictionVelocity::Constraint | FrictionVelocity::Midpoint => {
                // commanded contact velocity + ω × (p_i − p_c), world frame
                let d = [r[0] - rc[0], r[1] - rc[1]];
                [vf[0] - omega * d[1], vf[1] + omega * d[0]]
            }
        };
        let speed = (u[0] * u[0] + u[1] * u[1]).sqrt();
        *min_speed = min_speed.min(speed);
        if speed > MIN_SLIDING_SPEED && friction > 0.0 {
            let k = -friction / speed;
            rb.add_force_at_point(v(k * u[0], k * u[1]), point, true);
        }
    }
}
