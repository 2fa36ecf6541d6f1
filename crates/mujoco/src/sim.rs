//! Stepping the MuJoCo scene (feature `mujoco`).

use std::time::Instant;

use mujoco_rs::prelude::*;
use pushval_engine::StepRecord;
use pushval_model::{ModelError, Problem, Trajectory};

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

/// Runs the problem (see the crate docs for the scene).
pub(crate) fn run(problem: &Problem, settings: &MujocoSettings) -> Result<MujocoRun, ModelError> {
    let start = Instant::now();
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
    let first = problem.pushes[0];
    let command = |yaw: f64, push: &pushval_model::Push| -> [f64; 2] {
        let v = pushval_model::rotate(yaw, &push.velocity());
        [v.x, v.y]
    };
    {
        let yaw = s0.yaw;
        let (lin, w) = if init.from_rest {
            ([0.0, 0.0], 0.0)
        } else {
            let vc = first.velocity();
            let local =
                pushval_model::Vec2::new(vc.x + init.omega * pc.y, vc.y - init.omega * pc.x);
            let v = pushval_model::rotate(yaw, &local);
            ([v.x, v.y], init.omega)
        };
        let mat = s0.mat;
        // ω_local = Rᵀ (0, 0, w)
        let wl = [mat[6] * w, mat[7] * w, mat[8] * w];
        let c = command(yaw, &first);
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

    let total_steps: usize = problem
        .pushes
        .iter()
        .map(|p| {
            (p.duration / settings.timestep * (1.0 - 1e-12))
                .ceil()
                .max(1.0) as usize
        })
        .sum();
    let mut history = Vec::with_capacity(total_steps + 1);
    let tilt_of = |m: &[f64; 9]| m[8].clamp(-1.0, 1.0).acos();
    let foot_speed = |s: &ObjState| -> f64 {
        let mut best = f64::INFINITY;
        for &(px, py, _) in &supports {
            let l = [px, py, -h];
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
    };
    let mut theta = init.theta + wrap(s0.yaw - init.theta);
    history.push(MjStep {
        segment: 0,
        t: 0.0,
        x: s0.x,
        y: s0.y,
        theta,
        omega: if init.from_rest { 0.0 } else { init.omega },
        tilt: tilt_of(&s0.mat),
        min_foot_speed: f64::NAN,
    });

    let mut max_gap = 0.0f64;
    let mut max_pen = max_penetration(&data);
    let mut max_tilt = 0.0f64;
    let mut tail_loads = Vec::with_capacity(problem.pushes.len());
    let mut tail_omega = Vec::with_capacity(problem.pushes.len());
    let mut tail_std = Vec::with_capacity(problem.pushes.len());
    let mut loads = vec![0.0; n];
    // The run's last fifth (steps whose middle is past it), time-weighted.
    let run_from = 0.8 * problem.duration();
    let mut run_load_sum = vec![0.0; n];
    let mut run_load_t = 0.0;
    let mut t = 0.0;
    let mut steps = 0usize;
    for (j, push) in problem.pushes.iter().enumerate() {
        let nk = (push.duration / settings.timestep * (1.0 - 1e-12))
            .ceil()
            .max(1.0) as usize;
        let hk = push.duration / nk as f64;
        data.model_opt_mut().timestep = hk;
        let tail_from = nk - (nk / 5).max(1);
        let mut load_sum = vec![0.0; n];
        let (mut w_sum, mut w2_sum, mut cnt) = (0.0, 0.0, 0usize);
        let t_seg = t;
        for k in 0..nk {
            let s = read(&data);
            let mid = s.yaw + 0.5 * hk * s.w[2];
            let c = command(mid, push);
            {
                let qv = data.qvel_mut();
                qv[CARRIAGE_DOF] = c[0];
                qv[CARRIAGE_DOF + 1] = c[1];
            }
            data.step();
            steps += 1;
            t = if k + 1 == nk {
                t_seg + push.duration
            } else {
                t_seg + (k + 1) as f64 * hk
            };
            let s = read(&data);
            theta += wrap(s.yaw - theta);
            if !(s.x.is_finite() && s.y.is_finite() && theta.is_finite() && s.w[2].is_finite()) {
                return Err(ModelError::NonFinite { t, step: steps });
            }
            let tilt = tilt_of(&s.mat);
            max_tilt = max_tilt.max(tilt);
            let sx = data.site_xpos();
            let gap = ((sx[0][0] - sx[1][0]).powi(2)
                + (sx[0][1] - sx[1][1]).powi(2)
                + (sx[0][2] - sx[1][2]).powi(2))
            .sqrt();
            max_gap = max_gap.max(gap);
            max_pen = max_pen.max(max_penetration(&data));
            let in_run_tail = t - 0.5 * hk >= run_from;
            if k >= tail_from || in_run_tail {
                foot_loads(&data, n, &mut loads);
            }
            if in_run_tail {
                run_load_sum
                    .iter_mut()
                    .zip(&loads)
                    .for_each(|(a, b)| *a += b * hk);
                run_load_t += hk;
            }
            if k >= tail_from {
                load_sum.iter_mut().zip(&loads).for_each(|(a, b)| *a += b);
                w_sum += s.w[2];
                w2_sum += s.w[2] * s.w[2];
                cnt += 1;
            }
            history.push(MjStep {
                segment: j,
                t,
                x: s.x,
                y: s.y,
                theta,
                omega: s.w[2],
                tilt,
                min_foot_speed: foot_speed(&s),
            });
        }
        check_warnings(&data, t)?;
        let cntf = cnt.max(1) as f64;
        tail_loads.push(load_sum.iter().map(|v| v / cntf).collect());
        let mean = w_sum / cntf;
        tail_omega.push(mean);
        tail_std.push((w2_sum / cntf - mean * mean).max(0.0).sqrt());
    }

    // The shared resampler (pose at step ends, ω at step middles: MuJoCo's
    // Euler is semi-implicit, so the velocity after a step is the one held
    // over it).
    let records: Vec<StepRecord> = history
        .iter()
        .enumerate()
        .map(|(k, r)| StepRecord {
            segment: r.segment,
            t0: if k == 0 { r.t } else { history[k - 1].t },
            t1: r.t,
            x: r.x,
            y: r.y,
            theta: r.theta,
            omega: r.omega,
        })
        .collect();
    let (samples, segments) = pushval_engine::resample(problem, &records);
    let mut trajectory = Trajectory {
        model: String::new(),
        samples,
        segments,
        ..Default::default()
    };
    trajectory.stats.steps = steps;
    trajectory.stats.rhs_evals = steps;
    trajectory.assumptions.min_support_speed = history
        .iter()
        .skip(1)
        .map(|r| r.min_foot_speed)
        .fold(f64::INFINITY, f64::min);
    Ok(MujocoRun {
        trajectory,
        settings: *settings,
        history,
        rest_loads,
        mu,
        tail_loads,
        loads: run_load_sum
            .iter()
            .map(|a| a / run_load_t.max(f64::MIN_POSITIVE))
            .collect(),
        segment_tail_omega: tail_omega,
        segment_tail_omega_std: tail_std,
        max_pusher_gap: max_gap,
        max_penetration: max_pen,
        max_tilt,
        steps,
        wall_time: start.elapsed(),
    })
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
