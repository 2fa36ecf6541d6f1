//! The creep scene (a plate on sphere feet, loaded at its centre of mass),
//! how the load meets it, and what a run of it measures.

use std::fmt::Write as _;

use super::law::{creep, CreepInput, CreepPrediction};
use crate::MujocoSettings;

/// The creep scene: a square plate on sphere feet on a floor, pushed by a
/// force at its centre of mass (no pusher body: the load is MuJoCo's
/// `xfrc_applied`, so nothing but the contacts resists it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CreepScene {
    /// MuJoCo options and contact parameters; used: `timestep`, `cone`,
    /// `impratio`, `noslip_iterations`, `iterations`, `integrator`,
    /// `foot_radius`, `gravity`, `contact_solref`, `contact_solimp`,
    /// `settle_time`. The centre of mass is at floor height (no tilt moment
    /// from the load, equal foot loads).
    pub settings: MujocoSettings,
    /// Number of feet: 4 (the corners) or 8 (corners and edge midpoints).
    pub feet: usize,
    /// Mass of the plate (kg); default 1.
    pub mass: f64,
    /// Half side of the square plate (m); default 0.125 (the paper plate).
    pub half_side: f64,
    /// Friction coefficient of every foot; default 0.5.
    pub mu: f64,
}

impl Default for CreepScene {
    fn default() -> Self {
        Self {
            settings: MujocoSettings::default(),
            feet: 4,
            mass: 1.0,
            half_side: 0.125,
            mu: 0.5,
        }
    }
}

impl CreepScene {
    /// Foot positions in the plate's frame (m).
    pub fn feet_positions(&self) -> Vec<[f64; 2]> {
        let h = self.half_side;
        let mut p = vec![[-h, -h], [h, -h], [h, h], [-h, h]];
        if self.feet == 8 {
            p.extend([[0.0, -h], [h, 0.0], [0.0, h], [-h, 0.0]]);
        }
        p
    }

    /// Weight of the plate (N).
    pub fn weight(&self) -> f64 {
        self.mass * self.settings.gravity
    }

    /// The closed form's input for one foot under a total load
    /// `load_fraction · μ W` along world angle `direction` (rad), the
    /// contact's tangents t₁, t₂ given by their world (x, y): equal foot loads
    /// `W/n`, `Â = 1/m`.
    pub fn creep_input(
        &self,
        load_fraction: f64,
        direction: f64,
        tangents: [[f64; 2]; 2],
    ) -> CreepInput {
        let n = self.feet_positions().len() as f64;
        let per = load_fraction * self.mu * self.weight() / n;
        let (sy, sx) = direction.sin_cos();
        let along = |t: [f64; 2]| per * (sx * t[0] + sy * t[1]);
        let s = &self.settings;
        CreepInput {
            cone: s.cone,
            impratio: s.impratio,
            solref: s.contact_solref,
            solimp: s.contact_solimp,
            timestep: s.timestep,
            mu: self.mu,
            normal_load: self.weight() / n,
            inv_weight: 1.0 / self.mass,
            load: [along(tangents[0]), along(tangents[1])],
        }
    }

    /// The closed form's steady creep of the plate as (along the load,
    /// across it: the left normal of the load) in m/s (NaN when it slides),
    /// with the prediction itself.
    pub fn predicted(
        &self,
        load_fraction: f64,
        direction: f64,
        tangents: [[f64; 2]; 2],
    ) -> ([f64; 2], CreepPrediction) {
        let p = creep(&self.creep_input(load_fraction, direction, tangents));
        let w = [
            p.velocity[0] * tangents[0][0] + p.velocity[1] * tangents[1][0],
            p.velocity[0] * tangents[0][1] + p.velocity[1] * tangents[1][1],
        ];
        let (sy, sx) = direction.sin_cos();
        ([w[0] * sx + w[1] * sy, -w[0] * sy + w[1] * sx], p)
    }

    /// The MJCF text: body 1 `plate` (free joint), geom 0 the floor, geoms
    /// 1..=n the feet.
    pub fn mjcf(&self) -> String {
        let s = &self.settings;
        let r = s.foot_radius;
        let m = self.mass;
        let side = 2.0 * self.half_side;
        let i_z = m * 2.0 * side * side / 12.0;
        let [sr0, sr1] = s.contact_solref;
        let si = s.contact_solimp;
        let solimp = format!("{} {} {} {} {}", si[0], si[1], si[2], si[3], si[4]);
        let mut x = String::new();
        let _ = writeln!(x, r#"<mujoco model="pushval_creep">"#);
        let _ = writeln!(
            x,
            r#"  <option timestep="{}" gravity="0 0 {}" cone="{}" impratio="{}" iterations="{}" noslip_iterations="{}" integrator="{}"/>"#,
            s.timestep,
            -s.gravity,
            s.cone.as_str(),
            s.impratio,
            s.iterations,
            s.noslip_iterations,
            s.integrator.as_str()
        );
        let _ = writeln!(x, "  <worldbody>");
        let _ = writeln!(
            x,
            r#"    <geom name="floor" type="plane" size="0 0 1" friction="0 0 0" condim="3" solref="{sr0} {sr1}" solimp="{solimp}"/>"#
        );
        let _ = writeln!(x, r#"    <body name="plate" pos="0 0 {r}">"#);
        let _ = writeln!(x, r#"      <freejoint name="plate"/>"#);
        let _ = writeln!(
            x,
            r#"      <inertial pos="0 0 {}" mass="{m}" diaginertia="{} {} {i_z}"/>"#,
            -r,
            0.5 * i_z,
            0.5 * i_z
        );
        for (k, p) in self.feet_positions().iter().enumerate() {
            let _ = writeln!(
                x,
                r#"      <geom name="foot{k}" type="sphere" size="{r}" pos="{} {} 0" mass="0" friction="{} 0 0" condim="3" priority="1" solref="{sr0} {sr1}" solimp="{solimp}"/>"#,
                p[0], p[1], self.mu
            );
        }
        let _ = writeln!(x, "    </body>");
        let _ = writeln!(x, "  </worldbody>");
        let _ = writeln!(x, "</mujoco>");
        x
    }
}

/// How the load meets the plate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CreepCase {
    /// Pushed, then held: the plate rests (settled), the load is switched on
    /// and held; the creep is approached from below.
    Held,
    /// Sliding: when the load is switched on the plate already slides along
    /// it at the given speed (m/s); Coulomb friction would stop it, MuJoCo
    /// decays into its creep from above.
    Sliding(f64),
}

impl CreepCase {
    /// `"held"` or `"sliding"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            CreepCase::Held => "held",
            CreepCase::Sliding(_) => "sliding",
        }
    }
}

/// What a creep run measured.
#[derive(Debug, Clone, PartialEq)]
pub struct CreepMeasurement {
    /// Mean slip velocity along the load over the hold's last 40 % (m/s).
    pub creep: f64,
    /// The same over the hold's 60–80 % (m/s).
    pub creep_early: f64,
    /// The same over the hold's last 20 % (m/s).
    pub creep_late: f64,
    /// Mean slip velocity across the load over the last 40 % (m/s).
    pub lateral: f64,
    /// Mean penetration of the feet touching the floor at the end (m; NaN
    /// when none does).
    pub penetration: f64,
    /// Number of foot contacts at the end (fewer than the feet: the plate
    /// hops).
    pub contacts: usize,
    /// Standard deviation of the plate's height over the measuring window
    /// (m): 0 in a steady creep, large when the plate chatters on its feet.
    pub height_std: f64,
    /// Normal force of each foot at the end (N).
    pub loads: Vec<f64>,
    /// World (x, y) of the first foot contact's tangents t₁ and t₂ after
    /// settling (MuJoCo
    /// builds a plane contact's frame from the plane's normal alone, so every
    /// foot has the same).
    pub tangents: [[f64; 2]; 2],
    /// The plate's translational `body_invweight0` in MuJoCo (1/kg).
    pub inv_weight: f64,
    /// Change of the plate's yaw over the hold (rad).
    pub yaw_change: f64,
}

impl CreepMeasurement {
    /// `|late − early| / |creep|`: 0 for a steady creep.
    pub fn steadiness(&self) -> f64 {
        (self.creep_late - self.creep_early).abs() / self.creep.abs()
    }
}

/// Speed of the plate along the load when the load is switched on in the
/// [`CreepCase::Sliding`] runs of the ladder (m/s).
pub const SLIDING_SPEED: f64 = 0.1;

/// Hold time of a ladder run (s): 1 s, plus 1.5 times the Coulomb stopping
/// time `v₀ / ((1 − λ) μ g)` when the plate starts sliding below the limit,
/// so that the measuring window (the last 40 %) starts after it.
pub fn hold_time(case: CreepCase, load_fraction: f64, mu: f64, gravity: f64) -> f64 {
    match case {
        CreepCase::Sliding(v0) if load_fraction < 1.0 => {
            1.0 + 1.5 * v0 / ((1.0 - load_fraction) * mu * gravity)
        }
        _ => 1.0,
    }
}

/// Height standard deviation (m) above which a run counts as chattering:
/// the plate does not settle on its feet (settled runs stay below 3e-7 m,
/// chattering ones above 9e-6 m in the ladder).
pub const CHATTER_HEIGHT_STD: f64 = 1e-6;
