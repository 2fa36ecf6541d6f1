//! Stepping the MuJoCo scene (feature `mujoco`).

use std::time::Instant;

use mujoco_rs::prelude::*;
use pushval_engine::stepping::{
    Plate, PlateWorld, StepClock, StepLoop, Stepped, Stepping, SupportForces, TailSteps, TailWeight,
};
use pushval_model::{ModelError, Problem};

use crate::scene::{self, CARRIAGE_DOF, OBJECT};
use crate::{MjStep, MujocoRun, MujocoSettings};

type Data = MjData<Box<MjModel>>;

fn fail(t: f64, reason: String) -> ModelError {
    ModelError::Integration { t, reason }
}

/// The object's pose and velocities as read from MuJoCo.
#[derive(Clone, Copy)]
struct ObjState {
    x: f64,
    y: f64,
    z: f64,
    /// Yaw in (−π, π].
    yaw: f64,
    /// Rotation matrix (row major).
    mat: [f64; 9],
    /// World linear velocity of the centre of mass.
    v: [f64; 3],
    /// World angular velocity.
    w: [f64; 3],
}

fn read(data: &Data) -> ObjState {
    let q = data.qpos();
    let qv = data.qvel();
    let mat = data.xmat()[OBJECT];
    let wl = [qv[3], qv[4], qv[5]];
    // Free joint: angular velocity in the body frame; world = R ω_local.
    let w = [
        mat[0] * wl[0] + mat[1] * wl[1] + mat[2] * wl[2],
        mat[3] * wl[0] + mat[4] * wl[1] + mat[5] * wl[2],
        mat[6] * wl[0] + mat[7] * wl[1] + mat[8] * wl[2],
    ];
    ObjState {
        x: q[0],
        y: q[1],
        z: q[2],
        yaw: mat[3].atan2(mat[0]),
        mat,
        v: [qv[0], qv[1], qv[2]],
        w,
    }
}

/// Normal force of each foot (N): sums over the contacts of geom `k + 1`.
fn foot_loads(data: &Data, n: usize, out: &mut [f64]) {
    out.iter_mut().for_each(|v| *v = 0.0);
    for (i, c) in data.contact().iter().enumerate() {
        let g = c.geom[0].max(c.geom[1]) as usize;
        if g >= 1 && g <= n {
            out[g - 1] += data.contact_force(i)[0];
        }
    }
}

fn max_penetration(data: &Data) -> f64 {
    data.contact()
        .iter()
        .map(|c| -c.dist)
        .fold(0.0f64, f64::max)
}

fn check_warnings(data: &Data, t: f64) -> Result<(), ModelError> {
    let w = data.warning();
    for (k, name) in [
        (MjtWarning::mjWARN_BADQACC, "bad qacc"),
        (MjtWarning::mjWARN_BADQVEL, "bad qvel"),
        (MjtWarning::mjWARN_BADQPOS, "bad qpos"),
    ] {
        if w[k as usize].number > 0 {
            return Err(fail(
                t,
                format!("MuJoCo warned '{name}' (it resets the state): the run is unstable"),
            ));
        }
    }
    Ok(())
}

/// The scene of `problem` (checked by the caller; see the crate docs),
/// settled, calibrated and given its start velocity (moving with the first
/// push of its schedule unless it starts at rest; the carriage moving with
/// it), in the shared stepping loop.
pub(crate) fn start(
    problem: &Problem,
    settings: &MujocoSettings,
) -> Result<Stepping<Stepper>, ModelError> {
    let body = &problem.body;
    let n = body.len();
    let supports: Vec<(f64, f64, f64)> = body
        .supports()
        .map(|s| (s.position.x, s.position.y, s.friction))
        .collect();
    let pc = body.contact();
    let h = settings.cm_height;

    // 1. Settle at rest with placeholder friction; read the loads.
    let xml = scene::mjcf(problem, settings, &vec![1.0; n]);
    let model = MjModel::from_xml_string(&xml)
        .map_err(|e| fail(0.0, format!("MuJoCo refused the scene: {e:?}")))?;
    {
        let f = model.ffi();
        if f.nq != 10 || f.nv != 9 || f.ngeom as usize != n + 1 || f.nbody != 4 {
            return Err(fail(0.0, "unexpected MuJoCo scene layout".into()));
        }
    }
    let mut data: Data = MjData::new(Box::new(model));
    let settle_steps = (settings.settle_time / settings.timestep).ceil() as usize;
    for _ in 0..settle_steps {
        data.step();
    }
    check_warnings(&data, 0.0)?;
    let mut rest_loads = vec![0.0; n];
    if settle_steps > 0 {
        foot_loads(&data, n, &mut rest_loads);
    } else {
        data.forward();
        foot_loads(&data, n, &mut rest_loads);
    }
    let mut mu = Vec::with_capacity(n);
    for (k, (&load, s)) in rest_loads.iter().zip(&supports).enumerate() {
        if s.2 == 0.0 {
            mu.push(0.0);
            continue;
        }
        if !(load > 1e-9) {
            return Err(fail(
                0.0,
                format!("support {k} carries no load at rest in MuJoCo ({load} N)"),
            ));
        }
        mu.push(s.2 / load);
    }
    let mut calibrated: MjModel = data.model().clone();
    for (k, &m) in mu.iter().enumerate() {
        calibrated.geom_friction_mut()[k + 1][0] = m;
    }
    data.swap_model(Box::new(calibrated));

    // 2. The start: the only time the object's state is written.
    let init = problem.initial;
    let s0 = read(&data);
    // Moving with the first push (the first push applied: the session is
    // started at it), or at rest with the carriage at rest (every step sets
    // the carriage's velocity before it is taken).
    let first = if init.from_rest {
        None
    } else {
        Some(*problem.pushes.first().ok_or(ModelError::EmptySchedule)?)
    };
    let command = |yaw: f64, push: &pushval_model::Push| -> [f64; 2] {
        let v = pushval_model::rotate(yaw, &push.velocity());
        [v.x, v.y]
    };
    {
        let yaw = s0.yaw;
        let (lin, w) = match &first {
            None => ([0.0, 0.0], 0.0),
            Some(first) => {
                let vc = first.velocity();
                let local =
                    pushval_model::Vec2::new(vc.x + init.omega * pc.y, vc.y - init.omega * pc.x);
                let v = pushval_model::rotate(yaw, &local);
                ([v.x, v.y], init.omega)
            }
        };
        let mat = s0.mat;
        // ω_local = Rᵀ (0, 0, w)
        let wl = [mat[6] * w, mat[7] * w, mat[8] * w];
        let c = first.map_or([0.0, 0.0], |p| command(yaw, &p));
        let qv = data.qvel_mut();
        qv[0] = lin[0];
        qv[1] = lin[1];
        qv[2] = 0.0;
        qv[3] = wl[0];
        qv[4] = wl[1];
        qv[5] = wl[2];
        qv[CARRIAGE_DOF] = c[0];
        qv[CARRIAGE_DOF + 1] = c[1];
        qv[CARRIAGE_DOF + 2] = 0.0;
    }

    let theta = init.theta + wrap(s0.yaw - init.theta);
    let start = MjState {
        s: read(&data),
        theta,
        omega: if init.from_rest { 0.0 } else { init.omega },
    };
    let max_pen = max_penetration(&data);
    let w = Stepper {
        data,
        supports,
        h,
        loads: vec![0.0; n],
        max_gap: 0.0,
        max_pen,
        foot_speeds: Vec::new(),
        rest_loads,
        mu,
        released: false,
    };
    let cfg = StepLoop {
        forces_every_step: false,
        tail: TailSteps::LastFifth,
        tail_weight: TailWeight::Steps,
        clock: StepClock::FromSegmentStart,
        ..StepLoop::new(settings.timestep, n, 0.0)
    };
    Ok(Stepping::new(w, problem, cfg, start))
}

/// The run of the pushes applied (`problem`), from what the loop gathered;
/// `started` is when the run began.
pub(crate) fn finish(
    w: Stepper,
    run: Stepped,
    problem: &Problem,
    settings: &MujocoSettings,
    started: Instant,
) -> MujocoRun {
    let (max_gap, max_pen) = (w.max_gap, w.max_pen);
    let history: Vec<MjStep> = run
        .history
        .iter()
        .zip(std::iter::once(f64::NAN).chain(w.foot_speeds.iter().copied()))
        .map(|(r, min_foot_speed)| MjStep {
            segment: r.segment,
            t: r.t1,
            x: r.x,
            y: r.y,
            theta: r.theta,
            omega: r.omega,
            tilt: r.tilt,
            min_foot_speed,
        })
        .collect();

    // The shared resampler (pose at step ends, ω at step middles: MuJoCo's
    // Euler is semi-implicit, so the velocity after a step is the one held
    // over it).
    let mut trajectory = run.trajectory(problem);
    trajectory.assumptions.min_support_speed = history
        .iter()
        .skip(1)
        .map(|r| r.min_foot_speed)
        .fold(f64::INFINITY, f64::min);
    MujocoRun {
        trajectory,
        settings: *settings,
        history,
        rest_loads: w.rest_loads,
        mu: w.mu,
        tail_loads: run.segment_tail_loads,
        loads: run.loads,
        contact: run.contact,
        segment_tail_omega: run.segment_tail_omega,
        segment_tail_omega_std: run.segment_tail_omega_std,
        max_pusher_gap: max_gap,
        max_penetration: max_pen,
        max_tilt: run.max_tilt,
        steps: run.steps,
        wall_time: started.elapsed(),
    }
}

/// The object as the stepping loop reads it.
#[derive(Clone, Copy)]
pub struct MjState {
    s: ObjState,
    /// Yaw, unwrapped (rad).
    theta: f64,
    /// The angular velocity recorded for the state (rad/s): MuJoCo's, or at
    /// the start the initial one.
    omega: f64,
}

/// The scene as the shared stepping loop sees it, with what the settle
/// phase found.
pub struct Stepper {
    data: Data,
    /// Position and friction of each foot.
    supports: Vec<(f64, f64, f64)>,
    /// Height of the centre of mass (m).
    h: f64,
    /// The feet's normal forces after the last step (N).
    loads: Vec<f64>,
    max_gap: f64,
    max_pen: f64,
    /// Per step, the smallest horizontal speed over the feet (m/s).
    foot_speeds: Vec<f64>,
    /// Normal force of each foot at rest (N).
    rest_loads: Vec<f64>,
    /// The calibrated friction coefficient of each foot.
    mu: Vec<f64>,
    /// Whether the pusher has let go (its connect is off; the tip's gap to
    /// the contact point no longer measures the pusher).
    released: bool,
}

impl Stepper {
    /// The smallest horizontal speed (m/s) over the feet.
    fn foot_speed(&self, s: &ObjState) -> f64 {
        let mut best = f64::INFINITY;
        for &(px, py, _) in &self.supports {
            let l = [px, py, -self.h];
            let r = [
                s.mat[0] * l[0] + s.mat[1] * l[1] + s.mat[2] * l[2],
                s.mat[3] * l[0] + s.mat[4] * l[1] + s.mat[5] * l[2],
                s.mat[6] * l[0] + s.mat[7] * l[1] + s.mat[8] * l[2],
            ];
            let ux = s.v[0] + s.w[1] * r[2] - s.w[2] * r[1];
            let uy = s.v[1] + s.w[2] * r[0] - s.w[0] * r[2];
            best = best.min((ux * ux + uy * uy).sqrt());
        }
        best
    }
}

impl PlateWorld for Stepper {
    type State = MjState;

    fn plate(&self, st: &MjState) -> Plate {
        Plate {
            x: st.s.x,
            y: st.s.y,
            z: st.s.z,
            theta: st.theta,
            omega: st.omega,
            tilt: tilt_of(&st.s.mat),
        }
    }

    /// MuJoCo's yaw (in (−π, π]) at mid-step.
    fn heading(&self, st: &MjState, h: f64) -> f64 {
        st.s.yaw + 0.5 * h * st.s.w[2]
    }

    /// The carriage's velocity; it has no drift to report.
    fn drive(&mut self, _: &MjState, vel: [f64; 2], _h: f64) -> f64 {
        let qv = self.data.qvel_mut();
        qv[CARRIAGE_DOF] = vel[0];
        qv[CARRIAGE_DOF + 1] = vel[1];
        0.0
    }

    fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError> {
        self.data.model_opt_mut().timestep = h;
        self.data.step();
        if self.released {
            // The slide has no segment ends: its steps are checked here.
            check_warnings(&self.data, t1)?;
        }
        Ok(())
    }

    fn state(&mut self, prev: &MjState) -> MjState {
        let s = read(&self.data);
        MjState {
            s,
            theta: prev.theta + wrap(s.yaw - prev.theta),
            omega: s.w[2],
        }
    }

    fn finite(&self, st: &MjState) -> bool {
        st.s.x.is_finite() && st.s.y.is_finite() && st.theta.is_finite() && st.s.w[2].is_finite()
    }

    fn after_step(&mut self, st: &MjState) {
        let sx = self.data.site_xpos();
        let gap = ((sx[0][0] - sx[1][0]).powi(2)
            + (sx[0][1] - sx[1][1]).powi(2)
            + (sx[0][2] - sx[1][2]).powi(2))
        .sqrt();
        if !self.released {
            self.max_gap = self.max_gap.max(gap);
        }
        self.max_pen = self.max_pen.max(max_penetration(&self.data));
        let speed = self.foot_speed(&st.s);
        self.foot_speeds.push(speed);
    }

    fn support_forces(
        &mut self,
        _: &MjState,
        _h: f64,
    ) -> Result<Option<SupportForces>, ModelError> {
        foot_loads(&self.data, self.supports.len(), &mut self.loads);
        Ok(Some(SupportForces {
            normal: self.loads.clone(),
            friction: None,
        }))
    }

    fn cm_velocity(&self, st: &MjState) -> Option<[f64; 2]> {
        Some([st.s.v[0], st.s.v[1]])
    }

    fn end_segment(&mut self, _count: f64, t: f64) -> Result<(), ModelError> {
        check_warnings(&self.data, t)
    }

    /// Turns the pusher's `connect` off (MuJoCo's `eq_active`) and stops
    /// the carriage; a throw sets the object's horizontal velocity and its
    /// spin about the vertical (the free joint's angular velocity is in the
    /// body frame: `Rᵀ (0, 0, ω)`). The slide is the engine's own: the
    /// feet's soft contact friction on the floor, nothing applied besides.
    fn release(&mut self, st: &MjState, throw: Option<([f64; 2], f64)>) -> Result<(), ModelError> {
        self.data.eq_active_mut()[0] = false;
        self.released = true;
        let qv = self.data.qvel_mut();
        qv[CARRIAGE_DOF] = 0.0;
        qv[CARRIAGE_DOF + 1] = 0.0;
        if let Some((v, omega)) = throw {
            let mat = st.s.mat;
            let w = [st.s.w[0], st.s.w[1], omega];
            qv[0] = v[0];
            qv[1] = v[1];
            qv[3] = mat[0] * w[0] + mat[3] * w[1] + mat[6] * w[2];
            qv[4] = mat[1] * w[0] + mat[4] * w[1] + mat[7] * w[2];
            qv[5] = mat[2] * w[0] + mat[5] * w[1] + mat[8] * w[2];
        }
        Ok(())
    }
}

fn tilt_of(m: &[f64; 9]) -> f64 {
    m[8].clamp(-1.0, 1.0).acos()
}

/// `a` wrapped into (−π, π].
fn wrap(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let r = (a + PI).rem_euclid(TAU) - PI;
    if r == -PI {
        PI
    } else {
        r
    }
}
