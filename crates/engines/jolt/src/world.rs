//! The simulation loop and the reading of Jolt's contact cache.

use std::f64::consts::{PI, TAU};

use pushval_engine::stepping::{
    Plate, PlateWorld, StepLoop, Stepped, Stepping, SupportForces, TAIL,
};
use pushval_model::{Body, ModelError, Problem, Vec2};

use crate::predict::{box_corners, friction_slip_angle};
use crate::sys::{BodyState, Collider, Spec, World};
use crate::{JoltRun, JoltSettings, Scene, SupportContact};

/// One manifold of the contact cache (`ContactConstraintManager::
/// ManifoldCache::SaveState`, Jolt 5.6.0).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CachedManifold {
    pub body1: u32,
    pub body2: u32,
    /// Contact normal in body 2's space.
    pub normal: [f32; 3],
    /// Impulses of the two linear friction rows (N s).
    pub friction: [f32; 2],
    /// Impulse of the twist row (N s).
    pub twist: f32,
    /// Per point: position on body 1 and on body 2 (each relative to that
    /// body's centre of mass, in its frame) and the normal impulse (N s).
    pub points: Vec<([f32; 3], [f32; 3], f32)>,
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let b = self.bytes.get(self.at..self.at + N)?;
        self.at += N;
        b.try_into().ok()
    }
    fn u8(&mut self) -> Option<u8> {
        self.take::<1>().map(|b| b[0])
    }
    fn u16(&mut self) -> Option<u16> {
        self.take().map(u16::from_ne_bytes)
    }
    fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_ne_bytes)
    }
    fn f32(&mut self) -> Option<f32> {
        self.take().map(f32::from_ne_bytes)
    }
    fn f3(&mut self) -> Option<[f32; 3]> {
        Some([self.f32()?, self.f32()?, self.f32()?])
    }
}

/// Parses the bytes of `PhysicsSystem::SaveState` with state `Contacts`:
/// the state byte, then per body pair its key (two body ids), the cached
/// pair (two `Float3`), its manifolds (key: body 1, sub-shape 1, body 2,
/// sub-shape 2; point count `u16`; normal `Float3`; friction `Vector<2>`;
/// twist `float`; per point two `Float3` and the normal `float`), then the
/// CCD manifold keys. `None` when the bytes do not have that shape.
pub(crate) fn parse_contacts(bytes: &[u8]) -> Option<Vec<CachedManifold>> {
    let mut r = Reader { bytes, at: 0 };
    let state = r.u8()?;
    if state != 4 {
        return None;
    }
    let pairs = r.u32()?;
    let mut out = Vec::new();
    for _ in 0..pairs {
        let (_a, _b) = (r.u32()?, r.u32()?);
        let (_dp, _dr) = (r.f3()?, r.f3()?);
        let manifolds = r.u32()?;
        for _ in 0..manifolds {
            let (body1, _s1, body2, _s2) = (r.u32()?, r.u32()?, r.u32()?, r.u32()?);
            let n = r.u16()? as usize;
            let normal = r.f3()?;
            let friction = [r.f32()?, r.f32()?];
            let twist = r.f32()?;
            let mut points = Vec::with_capacity(n);
            for _ in 0..n {
                points.push((r.f3()?, r.f3()?, r.f32()?));
            }
            out.push(CachedManifold {
                body1,
                body2,
                normal,
                friction,
                twist,
                points,
            });
        }
    }
    let ccd = r.u32()?;
    r.at += 16 * ccd as usize;
    (r.at == bytes.len()).then_some(out)
}

/// Jolt's first tangent of a unit normal (`Vec3::GetNormalizedPerpendicular`).
fn perpendicular(n: [f64; 3]) -> [f64; 3] {
    if n[0].abs() > n[1].abs() {
        let l = n[0].hypot(n[2]);
        [n[2] / l, 0.0, -n[0] / l]
    } else {
        let l = n[1].hypot(n[2]);
        [0.0, n[2] / l, -n[1] / l]
    }
}

/// The other branch of [`perpendicular`].
fn other_perpendicular(n: [f64; 3]) -> [f64; 3] {
    if n[0].abs() > n[1].abs() {
        let l = n[1].hypot(n[2]);
        [0.0, n[2] / l, -n[1] / l]
    } else {
        let l = n[0].hypot(n[2]);
        [n[2] / l, 0.0, -n[0] / l]
    }
}

fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Rotates `v` by the quaternion `q` (x, y, z, w).
fn rotate_q(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let u = [q[0], q[1], q[2]];
    let t = cross3(u, v).map(|x| 2.0 * x);
    let c = cross3(u, t);
    [
        v[0] + q[3] * t[0] + c[0],
        v[1] + q[3] * t[1] + c[1],
        v[2] + q[3] * t[2] + c[2],
    ]
}

fn yaw_of(q: [f64; 4]) -> f64 {
    let ex = rotate_q(q, [1.0, 0.0, 0.0]);
    ex[1].atan2(ex[0])
}

fn tilt_of(q: [f64; 4]) -> f64 {
    2.0 * q[0].hypot(q[1]).min(1.0).asin()
}

/// What one step's contact cache says, per support.
struct StepContacts {
    supports: Vec<SupportContact>,
    sizes: Vec<usize>,
    /// Per manifold: its friction force's angle from `−u` (rad) and the
    /// angle the effective-mass law gives for the same slip and point.
    angles: Vec<(f64, f64)>,
}

/// Reads the object–floor manifolds of the cache into per-support values:
/// every point goes to the nearest support (`targets`, object frame); the
/// impulses become forces over `dt`.
fn contacts(
    world: &World,
    (mass, inertia): (f64, f64),
    object: &BodyState,
    targets: &[Vec2],
    dt: f64,
) -> Result<StepContacts, ModelError> {
    let bytes = world.contact_state();
    let manifolds = parse_contacts(&bytes).ok_or_else(|| ModelError::Integration {
        t: 0.0,
        reason: "Jolt: the contact cache did not parse (oxijolt-sys / Jolt version?)".into(),
    })?;
    let mut out = vec![SupportContact::default(); targets.len()];
    let mut sizes = Vec::new();
    let mut angles = Vec::new();
    let q = object.rotation;
    for m in manifolds {
        let object_is_1 = m.body1 == world.object;
        if !(object_is_1 || m.body2 == world.object)
            || !(m.body1 == world.floor || m.body2 == world.floor)
        {
            continue;
        }
        sizes.push(m.points.len());
        let n_local = m.normal.map(|x| x as f64);
        // Normal in body 2's space: the floor's is the world's.
        let n = if object_is_1 {
            n_local
        } else {
            rotate_q(q, n_local)
        };
        // Force on body 2 is +λ t / dt; on body 1, −λ t / dt.
        let sign = if object_is_1 { -1.0 } else { 1.0 };
        let force = |t1: [f64; 3]| {
            let t2 = cross3(n, t1);
            [0, 1]
                .map(|k| sign * (m.friction[0] as f64 * t1[k] + m.friction[1] as f64 * t2[k]) / dt)
        };
        let twist = sign * m.twist as f64 * n[2] / dt;
        // Friction point: mean of the object-side points (COM frame).
        let pts: Vec<[f64; 3]> = m
            .points
            .iter()
            .map(|(p1, p2, _)| if object_is_1 { *p1 } else { *p2 }.map(|x| x as f64))
            .collect();
        let c = pts
            .iter()
            .fold([0.0; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]])
            .map(|x| x / pts.len().max(1) as f64);
        let cw = rotate_q(q, c);
        let w = object.angular;
        let wxr = cross3(w, cw);
        let slip = [object.linear[0] + wxr[0], object.linear[1] + wxr[1]];
        // Jolt's first tangent is world y or world x depending on which of
        // the normal's tiny horizontal components is larger (float noise of
        // the tilt): the two branches give forces 90° apart, so the reader
        // takes the branch whose force opposes the slip (the law's angle is
        // below 90° for any effective-mass ratio).
        let fa = force(perpendicular(n));
        let fb = force(other_perpendicular(n));
        let opposes = |f: [f64; 2]| -(f[0] * slip[0] + f[1] * slip[1]);
        let f = if opposes(fb) > opposes(fa) { fb } else { fa };
        let (fv, uv) = (Vec2::new(f[0], f[1]), Vec2::new(slip[0], slip[1]));
        if fv.norm() > 0.0 && uv.norm() > 1e-6 {
            let mx = 1.0 / (1.0 / mass + cw[1] * cw[1] / inertia);
            let my = 1.0 / (1.0 / mass + cw[0] * cw[0] / inertia);
            let law = -Vec2::new(mx * uv.x, my * uv.y);
            angles.push((friction_slip_angle(fv, uv), friction_slip_angle(law, uv)));
        }
        for (p, (_, _, lambda)) in pts.iter().zip(&m.points) {
            let local = Vec2::new(p[0], p[1]);
            let i = (0..targets.len())
                .min_by(|&a, &b| {
                    (targets[a] - local)
                        .norm()
                        .total_cmp(&(targets[b] - local).norm())
                })
                .unwrap_or(0);
            out[i].normal += *lambda as f64 / dt;
            out[i].friction = f;
            out[i].twist = twist;
            out[i].slip = slip;
        }
    }
    Ok(StepContacts {
        supports: out,
        sizes,
        angles,
    })
}

fn jolt_error(what: &str) -> ModelError {
    ModelError::Integration {
        t: 0.0,
        reason: format!("Jolt: {what}"),
    }
}

/// The scene of `problem` (checked by the caller) in Jolt, settled and
/// given its start velocity (moving with the first push of its schedule
/// unless it starts at rest), in the shared stepping loop.
pub(crate) fn start(problem: &Problem, s: &JoltSettings) -> Result<Stepping<Stepper>, ModelError> {
    let body = &problem.body;
    let init = problem.initial;
    let mass = body.mass();
    let iz = body.inertia_cm();
    let mu = body.total_friction() / (mass * s.gravity);
    let t = s.plate_thickness;
    let tilt = 0.5 * iz + mass * t * t / 12.0;
    let (collider, targets): (Collider, Vec<Vec2>) = match s.scene {
        Scene::Box => {
            let c = box_corners(body);
            (
                Collider::Box {
                    center: [0.5 * (c[0].x + c[2].x), 0.5 * (c[0].y + c[2].y), 0.5 * t],
                    half: [0.5 * (c[2].x - c[0].x), 0.5 * (c[2].y - c[0].y), 0.5 * t],
                },
                c.to_vec(),
            )
        }
        Scene::Feet => {
            let pts: Vec<Vec2> = body.supports().map(|p| p.position).collect();
            (
                Collider::Spheres {
                    centers: pts.iter().map(|p| [p.x, p.y, s.foot_radius]).collect(),
                    radius: s.foot_radius,
                },
                pts,
            )
        }
    };
    let pc = body.contact();
    let spec = Spec {
        collider,
        mass,
        inertia: [tilt, tilt, iz],
        friction: mu,
        manifold_reduction: s.scene == Scene::Box,
        gravity: s.gravity,
        velocity_steps: s.velocity_steps,
        position_steps: s.position_steps,
        penetration_slop: s.penetration_slop,
        floor_convex_radius: s.floor_convex_radius,
        position: [init.position.x, init.position.y, 0.0],
        theta: init.theta,
        anchor: [pc.x, pc.y, 0.0],
    };
    let mut world = World::new(&spec).ok_or_else(|| jolt_error("scene creation failed"))?;
    let n_sup = targets.len();
    let anchor = spec.anchor;

    // Settle with the pusher at rest.
    let mut st = world.state(world.object);
    let mut theta = init.theta;
    let settle_steps = (s.settle_time / s.dt).ceil() as usize;
    let settle_tail = ((1.0 - TAIL) * settle_steps as f64).floor() as usize;
    let mut rest_loads = vec![0.0; n_sup];
    let mut count = 0usize;
    let mut manifold_sizes = Vec::new();
    for k in 0..settle_steps {
        let a = world.anchor_world(st.com, theta, anchor);
        world.drive_pusher(a, [0.0; 3]);
        if !world.step(s.dt) {
            return Err(jolt_error("update failed while settling"));
        }
        st = world.state(world.object);
        theta = unwrap(theta, yaw_of(st.rotation));
        if k >= settle_tail {
            let c = contacts(&world, (mass, iz), &st, &targets, s.dt)?;
            for (a, x) in rest_loads.iter_mut().zip(&c.supports) {
                *a += x.normal;
            }
            manifold_sizes = c.sizes;
            count += 1;
        }
    }
    if count > 0 {
        rest_loads.iter_mut().for_each(|a| *a /= count as f64);
    }
    let z_rest = st.com[2];

    // Start moving with the first push at ω = initial.omega, unless from rest.
    if !init.from_rest {
        let vc = problem
            .pushes
            .first()
            .ok_or(ModelError::EmptySchedule)?
            .velocity();
        let local = [vc.x + init.omega * pc.y, vc.y - init.omega * pc.x];
        let (sn, cs) = theta.sin_cos();
        world.set_velocity(
            world.object,
            [
                cs * local[0] - sn * local[1],
                sn * local[0] + cs * local[1],
                st.linear[2],
            ],
            [0.0, 0.0, init.omega],
        );
        st = world.state(world.object);
    }

    let w = Stepper {
        world,
        anchor,
        mass_inertia: (mass, iz),
        targets,
        last: None,
        tail: Tail::new(n_sup),
        out: Tails::default(),
        mu,
        rest_loads,
        manifold_sizes,
    };
    let cfg = StepLoop {
        forces_every_step: false,
        ..StepLoop::new(s.dt, n_sup, z_rest)
    };
    Ok(Stepping::new(w, problem, cfg, (st, theta)))
}

/// The run of the pushes applied (`problem`), from what the loop gathered.
pub(crate) fn finish(w: Stepper, run: Stepped, problem: &Problem, s: &JoltSettings) -> JoltRun {
    let body = &problem.body;
    let history = run.records();
    let tails = w.out;
    let contact = run.contact.clone().map(|mut c| {
        c.loads = std::mem::take(&mut c.loads)
            .into_iter()
            .map(|l| support_loads(body, &w.targets, l))
            .collect::<Option<Vec<_>>>()
            .unwrap_or_default();
        c
    });
    JoltRun {
        trajectory: run.trajectory(problem),
        settings: *s,
        steps: run.steps,
        wall_time: Default::default(),
        mu: w.mu,
        rest_loads: w.rest_loads,
        loads: support_loads(body, &w.targets, run.loads),
        contact,
        manifold_sizes: w.manifold_sizes,
        segment_tail_omega: run.segment_tail_omega,
        segment_tail_omega_std: run.segment_tail_omega_std,
        segment_tail_contacts: tails.contacts,
        segment_tail_max_angle: tails.angle,
        segment_tail_max_angle_vs_law: tails.angle_law,
        segment_tail_load_range: tails.load_range,
        max_tilt: run.max_tilt,
        max_lift: run.max_lift,
        max_joint_drift: run.max_joint_drift,
        history,
    }
}

/// The sums of one segment's tail that only Jolt gathers.
struct Tail {
    contacts: Vec<SupportContact>,
    max_angle: f64,
    max_angle_vs_law: f64,
    load_range: Vec<[f64; 2]>,
}

impl Tail {
    fn new(n_sup: usize) -> Self {
        Self {
            contacts: vec![SupportContact::default(); n_sup],
            max_angle: 0.0,
            max_angle_vs_law: 0.0,
            load_range: vec![[f64::INFINITY, f64::NEG_INFINITY]; n_sup],
        }
    }
}

/// Per segment, what [`Tail`] gathered.
#[derive(Default)]
struct Tails {
    contacts: Vec<Vec<SupportContact>>,
    angle: Vec<f64>,
    angle_law: Vec<f64>,
    load_range: Vec<Vec<[f64; 2]>>,
}

/// The scene as the shared stepping loop sees it, with what the settle
/// phase found.
pub struct Stepper {
    world: World,
    /// The pusher's anchor in the object's frame.
    anchor: [f64; 3],
    mass_inertia: (f64, f64),
    /// Where the contact points are gathered (object frame).
    targets: Vec<Vec2>,
    /// The contacts read after the current step.
    last: Option<StepContacts>,
    tail: Tail,
    out: Tails,
    /// The friction coefficient of every contact.
    mu: f64,
    /// The supports' loads at rest (N).
    rest_loads: Vec<f64>,
    /// The object–floor manifolds' sizes after the settle phase.
    manifold_sizes: Vec<usize>,
}

impl PlateWorld for Stepper {
    /// The object's state and its unwrapped yaw (rad).
    type State = (BodyState, f64);

    fn plate(&self, (st, theta): &(BodyState, f64)) -> Plate {
        Plate {
            x: st.com[0],
            y: st.com[1],
            z: st.com[2],
            theta: *theta,
            omega: st.angular[2],
            tilt: tilt_of(st.rotation),
        }
    }

    fn drive(&mut self, (st, theta): &(BodyState, f64), vel: [f64; 2], _h: f64) -> f64 {
        let a = self.world.anchor_world(st.com, *theta, self.anchor);
        let p = self.world.state(self.world.pusher).com;
        let drift = (p[0] - a[0]).hypot(p[1] - a[1]);
        self.world.drive_pusher(a, [vel[0], vel[1], 0.0]);
        drift
    }

    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError> {
        self.last = None;
        if !self.world.step(h) {
            return Err(ModelError::Integration {
                t: t1,
                reason: "Jolt: update failed".into(),
            });
        }
        Ok(())
    }

    fn state(&mut self, (_, theta): &(BodyState, f64)) -> (BodyState, f64) {
        let st = self.world.state(self.world.object);
        (st, unwrap(*theta, yaw_of(st.rotation)))
    }

    fn support_forces(
        &mut self,
        (st, _): &(BodyState, f64),
        h: f64,
    ) -> Result<Option<SupportForces>, ModelError> {
        let c = contacts(&self.world, self.mass_inertia, st, &self.targets, h)?;
        let normal = c.supports.iter().map(|x| x.normal).collect();
        self.last = Some(c);
        Ok(Some(SupportForces {
            normal,
            friction: None,
        }))
    }

    fn tail_step(&mut self, _: &(BodyState, f64), h: f64) -> Result<(), ModelError> {
        let Some(c) = &self.last else {
            return Ok(());
        };
        let tail = &mut self.tail;
        for (r, x) in tail.load_range.iter_mut().zip(&c.supports) {
            r[0] = r[0].min(x.normal);
            r[1] = r[1].max(x.normal);
        }
        for &(a, l) in &c.angles {
            tail.max_angle = tail.max_angle.max(a.abs());
            tail.max_angle_vs_law = tail.max_angle_vs_law.max((a - l).abs());
        }
        for (a, x) in tail.contacts.iter_mut().zip(&c.supports) {
            a.normal += x.normal * h;
            a.twist += x.twist * h;
            for q in 0..2 {
                a.friction[q] += x.friction[q] * h;
                a.slip[q] += x.slip[q] * h;
            }
        }
        Ok(())
    }

    fn cm_velocity(&self, (st, _): &(BodyState, f64)) -> Option<[f64; 2]> {
        Some([st.linear[0], st.linear[1]])
    }

    fn end_segment(&mut self, acc_t: f64, _t: f64) -> Result<(), ModelError> {
        let tail = std::mem::replace(&mut self.tail, Tail::new(self.targets.len()));
        self.out.contacts.push(
            tail.contacts
                .iter()
                .map(|a| SupportContact {
                    normal: a.normal / acc_t,
                    friction: a.friction.map(|x| x / acc_t),
                    twist: a.twist / acc_t,
                    slip: a.slip.map(|x| x / acc_t),
                })
                .collect(),
        );
        self.out.angle.push(tail.max_angle);
        self.out.angle_law.push(tail.max_angle_vs_law);
        self.out.load_range.push(tail.load_range);
        Ok(())
    }

    /// Removes the pusher's six-DOF constraint and stops the pusher (it
    /// collides with nothing); a throw sets the object's horizontal
    /// velocity and its spin about the vertical. The slide is the engine's
    /// own: the contacts' friction on the floor (see the crate docs).
    fn release(
        &mut self,
        (st, _): &(BodyState, f64),
        throw: Option<([f64; 2], f64)>,
    ) -> Result<(), ModelError> {
        self.world.release_pusher();
        if let Some((v, omega)) = throw {
            let object = self.world.object;
            self.world.set_velocity(
                object,
                [v[0], v[1], st.linear[2]],
                [st.angular[0], st.angular[1], omega],
            );
        }
        Ok(())
    }
}

/// The loads of `targets` (feet, or the box's corners) in the problem's
/// support order: the feet's as they are; the box's corners' when every
/// support sits on a corner of its own (within 1e-9 m), else None (the
/// box's contact points are its corners, not the supports).
fn support_loads(body: &Body, targets: &[Vec2], loads: Vec<f64>) -> Option<Vec<f64>> {
    if targets.len() == body.len()
        && body
            .supports()
            .zip(targets)
            .all(|(s, t)| (s.position - t).norm() == 0.0)
    {
        return Some(loads);
    }
    let mut out = Vec::with_capacity(body.len());
    let mut used = vec![false; targets.len()];
    for s in body.supports() {
        let k = targets
            .iter()
            .position(|t| (s.position - t).norm() <= 1e-9)?;
        if used[k] {
            return None;
        }
        used[k] = true;
        out.push(loads[k]);
    }
    Some(out)
}

/// `prev` moved to the branch of `angle` nearest to it.
fn unwrap(prev: f64, angle: f64) -> f64 {
    let d = (angle - prev.rem_euclid(TAU) + PI).rem_euclid(TAU) - PI;
    prev + d
}
