//! The rapier world for one precision. This file is compiled twice (see
//! `lib.rs`): `super::rapier` is `rapier2d-f64` in one build and `rapier2d`
//! (f32) in the other, and `Real` follows it. Everything outside this file
//! works in f64.

// `as Real` is a no-op in the f64 build and a narrowing in the f32 one.
#![allow(clippy::unnecessary_cast)]

use std::time::{Duration, Instant};

use super::rapier::prelude::*;

use crate::idioms::{support_force, LawContext};
use crate::RawRun;
use crate::{EngineSettings, FrictionModel, FrictionVelocity};
use pushval_engine::stepping::{
    Plate, PlateWorld, StepLayout, StepLoop, StepPlan, Stepped, Stepping, SupportForces,
};
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
    Rot::new(theta).apply(a)
}

/// A rotation as `(cos, sin)`, so that a step's rotations cost no
/// trigonometry.
#[derive(Clone, Copy)]
struct Rot {
    c: f64,
    s: f64,
}

impl Rot {
    fn new(theta: f64) -> Self {
        let (s, c) = theta.sin_cos();
        Self { c, s }
    }

    /// The rotation by `atan(x)`: the one rapier applies over a step with
    /// `x = h ω`.
    fn atan(x: f64) -> Self {
        let k = 1.0 / (1.0 + x * x).sqrt();
        Self { c: k, s: x * k }
    }

    /// This rotation followed by `other`.
    fn then(self, other: Rot) -> Self {
        Self {
            c: self.c * other.c - self.s * other.s,
            s: self.s * other.c + self.c * other.s,
        }
    }

    fn apply(self, a: [f64; 2]) -> [f64; 2] {
        [self.c * a[0] - self.s * a[1], self.s * a[0] + self.c * a[1]]
    }
}

/// The object's state as read from the engine, in f64.
#[derive(Clone, Copy)]
pub struct State {
    x: f64,
    y: f64,
    /// Unwrapped angle.
    theta: f64,
    /// The engine's rotation (its `cos θ`, `sin θ`).
    rot: Rot,
    omega: f64,
    /// World velocity of the centre of mass (m/s).
    v: [f64; 2],
}

/// Radius (m) of the pusher's collider when the scene has colliders.
const PUSHER_RADIUS: Real = 0.005;

/// The rapier world of one run and what its steps carry from one to the
/// next, as the shared loop's [`PlateWorld`] (a 2-D world: height and tilt
/// zero).
pub struct World2d {
    world: PhysicsWorld,
    object: RigidBodyHandle,
    pusher: RigidBodyHandle,
    /// The pin joint (the pusher's constraint), removed at the release.
    joint: ImpulseJointHandle,
    /// Whether the pusher has let go.
    released: bool,
    /// Contact point (m, object frame).
    pc: [f64; 2],
    /// Support positions (m, object frame) and friction magnitudes `F_i` (N).
    supports: Vec<([f64; 2], f64)>,
    mass: f64,
    inertia_cm: f64,
    friction_velocity: FrictionVelocity,
    friction_model: FrictionModel,
    switch_step_fraction: f64,
    /// The segment's friction-law constants (the impulse cap uses its
    /// nominal step).
    law: LawContext,
    /// Whether the segment ends with a closing step (leapfrog, a switch
    /// step length above zero).
    closing: bool,
    /// The segment's switch-step length (s).
    eps: f64,
    /// Step velocities of this segment, placed at step middles, for the
    /// midpoint extrapolation.
    nodes: [(f64, f64); 2],
    /// Leapfrog: the time the object's current velocity stands for (s).
    v_time: f64,
    /// The current step's start and end times (s).
    span: (f64, f64),
    max_drift: f64,
    min_speed: f64,
    step_time: Duration,
    loop_start: Instant,
}

/// Builds the world of `problem` in this precision's rapier build and hands
/// it to the shared loop; `outline` is the object's outline for its collider
/// (see `RapierSimulator::start_with_outline`). An object not starting at rest
/// starts with the first push of `problem`'s schedule (the first push
/// applied: see `pushval_engine::on_first_push`).
pub(crate) fn start(
    problem: &Problem,
    settings: &EngineSettings,
    outline: &[[f64; 2]],
) -> Result<Stepping<World2d>, ModelError> {
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
        let p = *problem.pushes.first().ok_or(ModelError::EmptySchedule)?;
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
    let joint = world.insert_impulse_joint(pusher, object, joint);
    if settings.colliders {
        attach_colliders(&mut world, object, pusher, outline, &supports, pc)?;
    }

    // Mass properties take effect only inside a step: a zero-length one.
    world.integration_parameters.dt = 0.0;
    world.step();

    let state = read(&world, object, init.theta);
    let w = World2d {
        world,
        object,
        pusher,
        joint,
        released: false,
        pc,
        supports,
        mass: body.mass(),
        inertia_cm: body.inertia_cm(),
        friction_velocity: settings.friction_velocity,
        friction_model: settings.friction_model,
        switch_step_fraction: settings.switch_step_fraction,
        law: LawContext {
            mass: body.mass(),
            inertia_cm: body.inertia_cm(),
            dt: settings.dt,
        },
        closing: false,
        eps: 0.0,
        nodes: [(f64::NAN, f64::NAN); 2],
        v_time: 0.0,
        span: (0.0, 0.0),
        max_drift: 0.0,
        min_speed: f64::INFINITY,
        step_time: Duration::ZERO,
        loop_start: Instant::now(),
    };
    // No supports' forces are read: the loop's per-support vectors are empty.
    let cfg = StepLoop::new(settings.dt, 0, 0.0);
    Ok(Stepping::new(w, problem, cfg, state))
}

/// What the engine code hands back once the loop is done.
pub(crate) fn raw_run(world: World2d, stepped: &Stepped) -> RawRun {
    RawRun {
        history: stepped.records(),
        steps: stepped.steps,
        step_time: world.step_time,
        loop_time: world.loop_start.elapsed(),
        max_drift: world.max_drift,
        min_support_speed: if world.min_speed.is_finite() {
            world.min_speed
        } else {
            0.0
        },
    }
}

/// The object's state; `prev_theta` unwraps the angle.
fn read(world: &PhysicsWorld, object: RigidBodyHandle, prev_theta: f64) -> State {
    let rb = &world.bodies[object];
    let t = rb.translation();
    let r = rb.rotation();
    let a = r.angle() as f64;
    // Unwrap: the engine's angle lives in (−π, π].
    let mut d = a - prev_theta.rem_euclid(std::f64::consts::TAU);
    d = (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    let lv = rb.linvel();
    State {
        x: t.x as f64,
        y: t.y as f64,
        theta: prev_theta + d,
        rot: Rot {
            c: r.re as f64,
            s: r.im as f64,
        },
        omega: rb.angvel() as f64,
        v: [lv.x as f64, lv.y as f64],
    }
}

impl PlateWorld for World2d {
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

    /// An optional switch step, then `n` steps whose first one is shortened
    /// by the switch step's length. In leapfrog mode every segment also ends
    /// with a closing step of the same length, taken off the step before it,
    /// whether or not a switch follows (the world is not told), so that
    /// the velocity at the segment's end is the one at its end time.
    fn segment_steps(&mut self, _push: &Push, n: usize, h: f64) -> Option<StepLayout> {
        let leapfrog = self.friction_velocity == FrictionVelocity::Leapfrog;
        let eps = self.switch_step_fraction * h;
        let closing = leapfrog && eps > 0.0;
        let mut lengths: Vec<f64> = Vec::with_capacity(n + 2);
        if eps > 0.0 {
            lengths.push(eps);
            lengths.push(h - eps);
        } else {
            lengths.push(h);
        }
        lengths.extend(std::iter::repeat_n(h, n - 1));
        if closing {
            *lengths.last_mut().expect("n >= 1") -= eps;
            lengths.push(eps);
        }
        // The friction law's constants; the impulse cap uses the nominal step.
        self.law = LawContext {
            mass: self.mass,
            inertia_cm: self.inertia_cm,
            dt: h,
        };
        self.closing = closing;
        self.eps = eps;
        self.nodes = [(f64::NAN, f64::NAN); 2];
        Some(StepLayout::Lengths(lengths))
    }

    fn drive_step(&mut self, state: &State, plan: &StepPlan) -> f64 {
        let (k, t, t1, hk) = (plan.index, plan.t0, plan.t1, plan.h);
        let eps = self.eps;
        let closing_step = self.closing && k + 1 == plan.steps;
        let nodes = self.nodes;
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
        let pc = self.pc;
        let vc = plan.push.velocity();
        let vc = [vc.x, vc.y];
        // ω the friction sees, the pusher velocity, and the factor on the
        // friction forces.
        let (omega_f, vp, friction_scale) = match self.friction_velocity {
            FrictionVelocity::Body | FrictionVelocity::Constraint => {
                (state.omega, state.rot.apply(vc), 1.0)
            }
            FrictionVelocity::Midpoint => {
                let w_mid = omega_at(t + 0.5 * hk);
                (omega_at(t), rot(state.theta + 0.5 * hk * w_mid, vc), 1.0)
            }
            FrictionVelocity::Leapfrog => {
                // The time the coming step's velocity stands for: the
                // switch time for the switch step (the velocity just
                // after the impulse) and for the closing step (the
                // velocity just before the next switch), the step's
                // middle otherwise.
                let (t_v, reach) = if k == 0 && eps > 0.0 {
                    (t, 0.0)
                } else if closing_step {
                    (t1, hk)
                } else {
                    (t + 0.5 * hk, 0.5 * hk)
                };
                let w = omega_at(t_v);
                // rapier turns the body by atan(h ω) over a step.
                let rot_v = state.rot.then(Rot::atan(reach * w));
                let a = rot_v.apply(vc);
                let c0 = state.rot.apply(pc);
                let c1 = rot_v.apply(pc);
                // v_c R(θ_v) n_φ + ω D (R(θ) − R(θ_v)) p_c: the joint,
                // whose lever arm is R(θ) p_c, then gives the centre of
                // mass the velocity R(θ_v)(v_c n_φ − ω D p_c) it has at
                // t_v: for a mid-step t_v, the chord of the arc it
                // should follow over the step.
                let vp = [a[0] - w * (c0[1] - c1[1]), a[1] + w * (c0[0] - c1[0])];
                // The friction impulse takes the velocity from the time
                // the previous one stands for to t_v (a half kick at the
                // start of a segment, a full step's in its body).
                let scale = (t_v - self.v_time) / hk;
                self.v_time = t_v;
                (omega_at(t), vp, scale)
            }
        };
        if self.friction_velocity == FrictionVelocity::Leapfrog {
            // Pin the pusher on the object's contact point: no position
            // error for the joint's bias to correct, so the body moves
            // with the velocity the joint solved for.
            let rc = state.rot.apply(pc);
            self.world.bodies[self.pusher]
                .set_translation(v(state.x + rc[0], state.y + rc[1]), true);
        }
        apply_step_forces(
            &mut self.world,
            self.object,
            self.pusher,
            vc,
            vp,
            &self.supports,
            pc,
            state,
            omega_f,
            self.friction_velocity,
            friction_scale,
            &mut self.min_speed,
            (self.friction_model, &self.law),
        );
        self.span = (t, t1);
        // The drift is measured after the step (`after_step`).
        0.0
    }

    fn drive(&mut self, _state: &State, _velocity: [f64; 2], _h: f64) -> f64 {
        unreachable!("the rapier2d world drives its pusher in drive_step")
    }

    fn step(&mut self, h: f64, _t1: f64) -> Result<(), ModelError> {
        self.world.integration_parameters.dt = h as Real;
        let before = Instant::now();
        self.world.step();
        self.step_time += before.elapsed();
        Ok(())
    }

    fn state(&mut self, prev: &State) -> State {
        read(&self.world, self.object, prev.theta)
    }

    fn support_forces(&mut self, _: &State, _h: f64) -> Result<Option<SupportForces>, ModelError> {
        Ok(None)
    }

    fn finite(&self, s: &State) -> bool {
        s.x.is_finite() && s.y.is_finite() && s.theta.is_finite() && s.omega.is_finite()
    }

    fn after_step(&mut self, state: &State) {
        if self.released {
            return;
        }
        let anchor = self.world.bodies[self.pusher].translation();
        let rc = state.rot.apply(self.pc);
        let drift = ((anchor.x as f64 - state.x - rc[0]).powi(2)
            + (anchor.y as f64 - state.y - rc[1]).powi(2))
        .sqrt();
        self.max_drift = self.max_drift.max(drift);
        let (t, t1) = self.span;
        let leapfrog = self.friction_velocity == FrictionVelocity::Leapfrog;
        self.nodes[0] = self.nodes[1];
        self.nodes[1] = (
            if leapfrog {
                self.v_time
            } else {
                0.5 * (t + t1)
            },
            state.omega,
        );
    }

    fn cm_velocity(&self, s: &State) -> Option<[f64; 2]> {
        Some(s.v)
    }

    /// Removes the pin joint and stops the pusher; a throw sets the
    /// object's velocity. Every friction model slides (see
    /// [`slide_step`](PlateWorld::slide_step)).
    fn release(
        &mut self,
        _state: &State,
        throw: Option<([f64; 2], f64)>,
    ) -> Result<(), ModelError> {
        self.world.remove_impulse_joint(self.joint);
        {
            let p = &mut self.world.bodies[self.pusher];
            p.set_linvel(v(0.0, 0.0), true);
            p.set_angvel(0.0, true);
        }
        if let Some((vel, omega)) = throw {
            let rb = &mut self.world.bodies[self.object];
            rb.set_linvel(v(vel[0], vel[1]), true);
            rb.set_angvel(omega as Real, true);
        }
        self.released = true;
        Ok(())
    }

    /// The supports' friction over a step of the slide, applied as the
    /// constant forces `Pᵢ / h` at the supports (the impulses `Pᵢ` of the
    /// step). Coulomb: the implicit impulses of [`pushval_engine::slide`]
    /// (each support's impulse capped at what leaves its slip zero at the
    /// step's end: no chatter at the stop). The impulse idioms: their
    /// joints solved together by sequential impulses
    /// ([`crate::slide::idiom_impulses`]), which stop the plate within a
    /// step once their caps allow it. The regularised laws: each support's
    /// force on the step's start velocity, as in the pushing steps (module
    /// docs of [`crate::slide`]).
    fn slide_step(&mut self, state: &State, h: f64) {
        let rs: Vec<([f64; 2], f64)> = self
            .supports
            .iter()
            .map(|s| (state.rot.apply(s.0), s.1.max(0.0)))
            .collect();
        let law = LawContext {
            mass: self.mass,
            inertia_cm: self.inertia_cm,
            dt: h,
        };
        let impulses = match self.friction_model {
            FrictionModel::Coulomb => {
                let caps: Vec<([f64; 2], f64)> = rs.iter().map(|&(r, f)| (r, f * h)).collect();
                pushval_engine::slide::coulomb_impulses(
                    self.mass,
                    self.inertia_cm,
                    state.v,
                    state.omega,
                    &caps,
                )
            }
            model => crate::slide::idiom_impulses(model, &law, state.v, state.omega, &rs)
                .unwrap_or_else(|| {
                    rs.iter()
                        .map(|&(r, f)| {
                            let u = [
                                state.v[0] - state.omega * r[1],
                                state.v[1] + state.omega * r[0],
                            ];
                            let force = support_force(model, u, r, f, &law);
                            [force[0] * h, force[1] * h]
                        })
                        .collect()
                }),
        };
        let rb = &mut self.world.bodies[self.object];
        rb.reset_forces(false);
        rb.reset_torques(false);
        for ((r, _), a) in rs.iter().zip(&impulses) {
            if *a != [0.0, 0.0] {
                let point = v(state.x + r[0], state.y + r[1]);
                rb.add_force_at_point(v(a[0] / h, a[1] / h), point, true);
            }
        }
    }
}

/// Attaches the massless, non-interacting colliders of
/// `EngineSettings::colliders`: the convex hull of `outline` (or, when it is
/// empty, of the supports and the contact point) on the object and a small
/// ball on the pusher. The object is in group 1 and sees only group 1, the
/// pusher in group 2 and sees only group 2, so the pair is never tested for
/// contact; no solver group either, so no contact could push; density 0, so
/// the mass properties set on the body stay exact.
fn attach_colliders(
    world: &mut PhysicsWorld,
    object: RigidBodyHandle,
    pusher: RigidBodyHandle,
    outline: &[[f64; 2]],
    supports: &[([f64; 2], f64)],
    pc: [f64; 2],
) -> Result<(), ModelError> {
    let points: Vec<Vector> = if outline.is_empty() {
        supports
            .iter()
            .map(|s| s.0)
            .chain([pc])
            .map(|p| v(p[0], p[1]))
            .collect()
    } else {
        outline.iter().map(|p| v(p[0], p[1])).collect()
    };
    let hull = ColliderBuilder::convex_hull(&points).ok_or(ModelError::Parameter {
        name: "engine collider outline",
        requirement: "at least three points not on one line",
        value: points.len() as f64,
    })?;
    let own = |group: Group| InteractionGroups::new(group, group, InteractionTestMode::And);
    world.insert_collider(
        hull.density(0.0)
            .collision_groups(own(Group::GROUP_1))
            .solver_groups(InteractionGroups::none()),
        Some(object),
    );
    world.insert_collider(
        ColliderBuilder::ball(PUSHER_RADIUS)
            .density(0.0)
            .collision_groups(own(Group::GROUP_2))
            .solver_groups(InteractionGroups::none()),
        Some(pusher),
    );
    Ok(())
}

/// Sets the pusher velocity for the coming step and the support friction forces.
#[allow(clippy::too_many_arguments)]
fn apply_step_forces(
    world: &mut PhysicsWorld,
    object: RigidBodyHandle,
    pusher: RigidBodyHandle,
    vc: [f64; 2],
    vp: [f64; 2],
    supports: &[([f64; 2], f64)],
    pc: [f64; 2],
    state: &State,
    omega: f64,
    mode: FrictionVelocity,
    friction_scale: f64,
    min_speed: &mut f64,
    (model, law): (FrictionModel, &LawContext),
) {
    {
        let p = &mut world.bodies[pusher];
        p.set_linvel(v(vp[0], vp[1]), true);
        p.set_angvel(0.0, true);
    }
    let rb = &mut world.bodies[object];
    rb.reset_forces(false);
    rb.reset_torques(false);
    let rc = state.rot.apply(pc);
    // The contact velocity the friction sees: the commanded one at the
    // object's current angle (equal to `vp` in body and constraint modes).
    let vf = state.rot.apply(vc);
    for &(p, friction) in supports {
        let r = state.rot.apply(p);
        let point = v(state.x + r[0], state.y + r[1]);
        let u = match mode {
            FrictionVelocity::Body => {
                let u = rb.velocity_at_point(point);
                [u.x as f64, u.y as f64]
            }
            FrictionVelocity::Constraint
            | FrictionVelocity::Midpoint
            | FrictionVelocity::Leapfrog => {
                // commanded contact velocity + ω × (p_i − p_c), world frame
                let d = [r[0] - rc[0], r[1] - rc[1]];
                [vf[0] - omega * d[1], vf[1] + omega * d[0]]
            }
        };
        let speed = (u[0] * u[0] + u[1] * u[1]).sqrt();
        *min_speed = min_speed.min(speed);
        if model != FrictionModel::Coulomb {
            // A game-engine idiom (see `idioms`): r from the centre of mass.
            let f = support_force(model, u, r, friction, law);
            if f != [0.0, 0.0] {
                let f = [friction_scale * f[0], friction_scale * f[1]];
                rb.add_force_at_point(v(f[0], f[1]), point, true);
            }
        } else if speed > MIN_SLIDING_SPEED && friction > 0.0 {
            let k = -friction_scale * friction / speed;
            rb.add_force_at_point(v(k * u[0], k * u[1]), point, true);
        }
    }
}
