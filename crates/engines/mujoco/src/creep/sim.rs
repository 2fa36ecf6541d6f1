//! Measuring MuJoCo's creep on the creep scene (feature `mujoco`).

use mujoco_rs::prelude::*;
use pushval_model::ModelError;

use super::scene::{CreepCase, CreepMeasurement, CreepScene};

type Data = MjData<Box<MjModel>>;

/// Body index of the plate.
const PLATE: usize = 1;

fn fail(t: f64, reason: String) -> ModelError {
    ModelError::Integration { t, reason }
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

/// Runs the creep scene: settle, switch the load on, hold it for
/// `hold_time` s, and measure the slip over the hold's last 40 %.
pub(crate) fn measure(
    scene: &CreepScene,
    case: CreepCase,
    load_fraction: f64,
    direction: f64,
    hold_time: f64,
) -> Result<CreepMeasurement, ModelError> {
    let s = &scene.settings;
    s.check()?;
    let n = scene.feet_positions().len();
    let xml = scene.mjcf();
    let model = MjModel::from_xml_string(&xml)
        .map_err(|e| fail(0.0, format!("MuJoCo refused the creep scene: {e:?}")))?;
    if model.ffi().nbody != 2 || model.ffi().ngeom as usize != n + 1 {
        return Err(fail(0.0, "unexpected MuJoCo creep scene layout".into()));
    }
    let inv_weight = model.body_invweight0()[PLATE][0];
    let mut data: Data = MjData::new(Box::new(model));
    let settle = (s.settle_time / s.timestep).ceil() as usize;
    for _ in 0..settle {
        data.step();
    }
    check_warnings(&data, 0.0)?;

    // The contact frame (the same for every foot on the plane).
    let tangents = match data.contact().first() {
        Some(c) => [[c.frame[3], c.frame[4]], [c.frame[6], c.frame[7]]],
        None => return Err(fail(0.0, "no foot touches the floor after settling".into())),
    };
    let (dy, dx) = direction.sin_cos();
    let force = load_fraction * scene.mu * scene.weight();
    data.xfrc_applied_mut()[PLATE] = [force * dx, force * dy, 0.0, 0.0, 0.0, 0.0];
    if let CreepCase::Sliding(v0) = case {
        let qv = data.qvel_mut();
        qv[0] += v0 * dx;
        qv[1] += v0 * dy;
    }
    let steps = (hold_time / s.timestep).round().max(10.0) as usize;
    let along = |d: &Data| d.qpos()[0] * dx + d.qpos()[1] * dy;
    let across = |d: &Data| -d.qpos()[0] * dy + d.qpos()[1] * dx;
    let k0 = (0.6 * steps as f64).round() as usize;
    let k1 = (0.8 * steps as f64).round() as usize;
    let (mut s0, mut s1, mut c0) = (0.0, 0.0, 0.0);
    let yaw0 = {
        let m = data.xmat()[PLATE];
        m[3].atan2(m[0])
    };
    let (mut zs, mut zz, mut zn) = (0.0, 0.0, 0usize);
    for k in 1..=steps {
        data.step();
        if k > k0 {
            let z = data.qpos()[2];
            zs += z;
            zz += z * z;
            zn += 1;
        }
        if k == k0 {
            s0 = along(&data);
            c0 = across(&data);
        }
        if k == k1 {
            s1 = along(&data);
        }
    }
    check_warnings(&data, hold_time)?;
    let h = s.timestep;
    let s2 = along(&data);
    let c2 = across(&data);
    let t_window = (steps - k0) as f64 * h;
    let creep = (s2 - s0) / t_window;
    let early = (s1 - s0) / ((k1 - k0) as f64 * h);
    let late = (s2 - s1) / ((steps - k1) as f64 * h);

    // Contacts at the end: one per foot.
    let mut loads = vec![0.0; n];
    let mut pen = 0.0;
    let mut count = 0usize;
    for (i, c) in data.contact().iter().enumerate() {
        let g = c.geom[0].max(c.geom[1]) as usize;
        if g >= 1 && g <= n {
            loads[g - 1] += data.contact_force(i)[0];
            pen += -c.dist;
            count += 1;
        }
    }
    let penetration = if count > 0 {
        pen / count as f64
    } else {
        f64::NAN
    };
    let m = data.xmat()[PLATE];
    let yaw = m[3].atan2(m[0]);
    Ok(CreepMeasurement {
        creep,
        creep_early: early,
        creep_late: late,
        lateral: (c2 - c0) / t_window,
        penetration,
        contacts: count,
        height_std: {
            let mean = zs / zn.max(1) as f64;
            (zz / zn.max(1) as f64 - mean * mean).max(0.0).sqrt()
        },
        loads,
        tangents,
        inv_weight,
        yaw_change: yaw - yaw0,
    })
}
