//! The MJCF text of the scene (built without MuJoCo, so it can be read and
//! tested in any build).
//!
//! Bodies, in MuJoCo's order: 0 world, 1 `object` (free joint: qpos 0..7,
//! qvel 0..6, angular velocity in the body frame), 2 `carriage` (slide x,
//! slide y: qpos/qvel 7, 8 and 6, 7), 3 `tip` (slide z: qpos 9, qvel 8).
//! Geoms: 0 the floor, then one foot per support, in support order.

use std::fmt::Write as _;

use pushval_model::{rotate, Problem};

use crate::MujocoSettings;

/// Body index of the object.
pub const OBJECT: usize = 1;
/// Body index of the pusher's carriage.
pub const CARRIAGE: usize = 2;
/// Body index of the pusher's tip.
pub const TIP: usize = 3;
/// qvel index of the carriage's x slide (y is the next one).
pub const CARRIAGE_DOF: usize = 6;
/// Carriage mass over object mass.
pub const CARRIAGE_MASS_RATIO: f64 = 1e6;
/// Tip mass over object mass (the tip is gravity-compensated).
pub const TIP_MASS_RATIO: f64 = 1e-3;

/// Time constant of the connect constraint (s): `2 · timestep`, the stiffest
/// MuJoCo accepts without its `refsafe` clamp.
pub fn connect_timeconst(settings: &MujocoSettings) -> f64 {
    2.0 * settings.timestep
}

/// The scene for `problem` at its initial pose, with foot friction
/// coefficients `mu` (one per support).
pub fn mjcf(problem: &Problem, settings: &MujocoSettings, mu: &[f64]) -> String {
    let body = &problem.body;
    let init = problem.initial;
    let m = body.mass();
    let i_z = body.inertia_cm();
    let h = settings.cm_height;
    let r = settings.foot_radius;
    let pc = body.contact();
    let c0 = rotate(init.theta, &pc);
    let (cx, cy) = (init.position.x + c0.x, init.position.y + c0.y);
    let (s, c) = (0.5 * init.theta).sin_cos();
    let tc = connect_timeconst(settings);
    let [sr0, sr1] = settings.contact_solref;
    let si = settings.contact_solimp;

    let mut x = String::new();
    let _ = writeln!(x, r#"<mujoco model="pushval">"#);
    let _ = writeln!(x, r#"  <compiler angle="radian"/>"#);
    let _ = writeln!(
        x,
        r#"  <option timestep="{}" gravity="0 0 {}" cone="{}" impratio="{}" iterations="{}" noslip_iterations="{}" integrator="{}"/>"#,
        settings.timestep,
        -settings.gravity,
        settings.cone.as_str(),
        settings.impratio,
        settings.iterations,
        settings.noslip_iterations,
        settings.integrator.as_str()
    );
    let _ = writeln!(x, "  <worldbody>");
    let _ = writeln!(
        x,
        r#"    <geom name="floor" type="plane" size="0 0 1" friction="0 0 0" condim="3" solref="{sr0} {sr1}" solimp="{} {} {} {} {}"/>"#,
        si[0], si[1], si[2], si[3], si[4]
    );
    let _ = writeln!(
        x,
        r#"    <body name="object" pos="{} {} {}" quat="{} 0 0 {}">"#,
        init.position.x, init.position.y, h, c, s
    );
    let _ = writeln!(x, r#"      <freejoint name="object"/>"#);
    let _ = writeln!(
        x,
        r#"      <inertial pos="0 0 0" mass="{m}" diaginertia="{} {} {i_z}"/>"#,
        0.5 * i_z,
        0.5 * i_z
    );
    for (k, sup) in body.supports().enumerate() {
        let _ = writeln!(
            x,
            r#"      <geom name="foot{k}" type="sphere" size="{r}" pos="{} {} {}" mass="0" friction="{} 0 0" condim="3" priority="1" solref="{sr0} {sr1}" solimp="{} {} {} {} {}"/>"#,
            sup.position.x,
            sup.position.y,
            r - h,
            mu.get(k).copied().unwrap_or(1.0),
            si[0],
            si[1],
            si[2],
            si[3],
            si[4]
        );
    }
    let _ = writeln!(
        x,
        r#"      <site name="contact" pos="{} {} {}"/>"#,
        pc.x,
        pc.y,
        settings.push_height - h
    );
    let _ = writeln!(x, "    </body>");
    let mc = CARRIAGE_MASS_RATIO * m;
    let _ = writeln!(x, r#"    <body name="carriage" pos="{cx} {cy} 0">"#);
    let _ = writeln!(
        x,
        r#"      <joint name="carriage_x" type="slide" axis="1 0 0"/>"#
    );
    let _ = writeln!(
        x,
        r#"      <joint name="carriage_y" type="slide" axis="0 1 0"/>"#
    );
    let _ = writeln!(
        x,
        r#"      <inertial pos="0 0 0" mass="{mc}" diaginertia="{mc} {mc} {mc}"/>"#
    );
    let mt = TIP_MASS_RATIO * m;
    let _ = writeln!(
        x,
        r#"      <body name="tip" pos="0 0 {}" gravcomp="1">"#,
        settings.push_height
    );
    let _ = writeln!(
        x,
        r#"        <joint name="tip_z" type="slide" axis="0 0 1"/>"#
    );
    let _ = writeln!(
        x,
        r#"        <inertial pos="0 0 0" mass="{mt}" diaginertia="{} {} {}"/>"#,
        mt * 1e-4,
        mt * 1e-4,
        mt * 1e-4
    );
    let _ = writeln!(x, r#"        <site name="tip"/>"#);
    let _ = writeln!(x, "      </body>");
    let _ = writeln!(x, "    </body>");
    let _ = writeln!(x, "  </worldbody>");
    let _ = writeln!(x, "  <equality>");
    let _ = writeln!(
        x,
        r#"    <connect site1="contact" site2="tip" solref="{tc} 1" solimp="0.99 0.999 0.001 0.5 2"/>"#
    );
    let _ = writeln!(x, "  </equality>");
    let _ = writeln!(x, "</mujoco>");
    x
}
