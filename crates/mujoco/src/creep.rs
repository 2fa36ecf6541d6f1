//! MuJoCo's creep law: the steady slip of a body held by a tangential load
//! below the friction limit, in closed form from MuJoCo's regularised
//! constraint formulation (no MuJoCo needed here; the engine side is in the
//! feature-gated `creep_sim`).
//!
//! # Derivation
//!
//! MuJoCo finds the constraint forces f of a step from the convex problem
//! whose dual reads `min ½ fᵀ(A + R)f + fᵀ(a₀ − a_ref)` over the friction
//! cone, with `A = J M⁻¹ Jᵀ`, a₀ the unconstrained constraint-space
//! acceleration, R the diagonal regulariser and the reference acceleration
//! `a_ref = −B v − K d (pos − margin)` row by row. Inside the cone (MuJoCo's
//! "bottom zone", every row quadratic) the optimum is the linear solve
//! `(A + R) f = a_ref − a₀`, so the constraint acceleration `a = A f + a₀`
//! obeys
//!
//! ```text
//! a = a_ref − R f .
//! ```
//!
//! In a steady creep every contact row has `a = 0` (constant velocity, constant
//! penetration): **`R f = a_ref`, whatever A is** — the mass matrix drops
//! out, and so does the time step of the semi-implicit Euler update
//! `v ← v + h a` (a fixed point of it has `a = 0`). What is left is MuJoCo's
//! own bookkeeping (`mj_makeImpedance`, `engine_core_constraint.c`):
//!
//! * impedance `d = d(δ)` of the contact from `solimp` at the penetration δ
//!   ([`impedance`]);
//! * `B = 2/(d_max t_c)`, `K = 1/(d_max² t_c² ζ²)` from `solref = (t_c, ζ)`,
//!   with `t_c` raised to `2h` (the `refsafe` clamp) and `d_max = solimp[1]`;
//! * `R = (1 − d)/d · Â`, Â MuJoCo's approximate diagonal of A: for a contact
//!   of one free body on the world, the body's translational `invweight0`,
//!   `1/m` (the whole body's, not a share per contact);
//! * elliptic cone: `R_t = R_n / impratio` on the two friction rows, and
//!   friction rows have `K = 0`, so `a_ref,t = −B u` (u the slip velocity);
//! * pyramidal cone: the 4 edge rows `n ± μ t_j` carry Â(1 + μ²) and all get
//!   `R_py = 2 μ² R_edge / impratio = 2 μ²(1 + μ²) (1 − d)/d · Â / impratio`.
//!
//! **Elliptic.** `R_t f_t = −B u` with `f_t` balancing the tangential load F
//! of the contact: `u = F R_t / B`, i.e.
//!
//! ```text
//! u* = F · (1 − d)/d · Â · d_max t_c / (2 impratio)        (|F| < μN)
//! ```
//!
//! The penetration δ (hence d) comes from the normal row, `R_n N = K d δ`
//! (independent of F).
//!
//! **Pyramidal.** Edge forces `f_{j±} ≥ 0` along `n ± μ t_j`; the edge rows'
//! `a_ref = −B(±μ u_j) + K d δ`. With all four edges active,
//! `R_py f_{j±} = K d δ ∓ B μ u_j`, so each pair carries `N/2` and
//! `F_j = μ(f_{j−} − f_{j+}) = 2 B μ² u_j / R_py`:
//!
//! ```text
//! u_j = F_j R_py / (2 μ² B) = F_j (1 + μ²) (1 − d)/d · Â / (B impratio)
//! ```
//!
//! — the elliptic law times `(1 + μ²)`, valid while `|F_j| ≤ μN/2` on both
//! tangent axes (the opposing edge keeps a non-negative force). Beyond, the
//! edge `n + μ t_1` (for `F_1 > 0`) lifts off (`f = 0`); with the other three
//! active, `f_{1−} = F_1/μ`, the cross pair shares `N − F_1/μ`, and
//!
//! ```text
//! u_1 = R_py (3 F_1/μ − N) / (2 B μ),   u_2 = F_2 R_py / (2 μ² B),
//! K d δ = R_py (N − F_1/μ) / 2 ,
//! ```
//!
//! continuous at `F_1 = μN/2` and three times steeper: along a tangent axis
//! the creep is `ε (1 + μ²) g(λ)` with `g = λ` up to `λ = 1/2` and
//! `g = 3λ − 1` above. It holds while `|F_1| + |F_2| < μN` (the pyramid's L1
//! diamond); beyond, there is no steady state: the body slides. (The
//! penetration changes with the load here, so d does too.)
//!
//! In the regularised-friction picture `f = μN u / max(|u|, ε)`, the elliptic
//! law is a slip scale **`ε = μ N R_t / B`** ([`slip_scale`]): `u* = λ ε` for
//! a load `λ μ N`. With `Â = 1/m` and `N = m g / n` for n equal contacts,
//! `ε = μ g (1 − d) d_max t_c / (2 n d impratio)`: creep falls as 1/impratio,
//! grows with the time constant, and falls with the number of contacts that
//! share the body's weight.
//!
//! Units: SI (m, s, N, kg).

use std::fmt::Write as _;

use crate::{Cone, MujocoSettings};

/// MuJoCo's lower clamp of `solimp[0]`, `solimp[1]`, `solimp[3]` (`mjMINIMP`).
pub const MJ_MINIMP: f64 = 0.0001;
/// MuJoCo's upper clamp of `solimp[0]`, `solimp[1]`, `solimp[3]` (`mjMAXIMP`).
pub const MJ_MAXIMP: f64 = 0.9999;

/// MuJoCo's `solimp` with its clamps applied (`getsolparam`).
pub fn clamped_solimp(solimp: &[f64; 5]) -> [f64; 5] {
    let c = |v: f64| v.clamp(MJ_MINIMP, MJ_MAXIMP);
    [
        c(solimp[0]),
        c(solimp[1]),
        solimp[2].max(0.0),
        c(solimp[3]),
        solimp[4].max(1.0),
    ]
}

/// Constraint impedance d (dimensionless, in (0, 1)) at constraint position
/// `pos` (m; a contact's signed distance, negative in penetration), margin
/// 0: MuJoCo's `getimpedance`. `solimp = (d0, d_width, width (m), midpoint,
/// power)`; d runs from d0 at `pos = 0` to d_width at `|pos| ≥ width` along
/// two power-law pieces joined at the midpoint.
pub fn impedance(solimp: &[f64; 5], pos: f64) -> f64 {
    let s = clamped_solimp(solimp);
    if s[0] == s[1] || s[2] <= f64::MIN_POSITIVE {
        return 0.5 * (s[0] + s[1]);
    }
    let x = (pos / s[2]).abs();
    if x >= 1.0 {
        return s[1];
    }
    if x <= 0.0 {
        return s[0];
    }
    let p = s[4];
    let y = if p == 1.0 {
        x
    } else if x <= s[3] {
        x.powf(p) / s[3].powf(p - 1.0)
    } else {
        1.0 - (1.0 - x).powf(p) / (1.0 - s[3]).powf(p - 1.0)
    };
    s[0] + y * (s[1] - s[0])
}

/// MuJoCo's reference-acceleration coefficients of a contact row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reference {
    /// Time constant after the `refsafe` clamp, `max(solref[0], 2h)` (s).
    pub timeconst: f64,
    /// Damping coefficient `B = 2/(d_max t_c)` (1/s).
    pub b: f64,
    /// Stiffness `K = 1/(d_max² t_c² ζ²)` (1/s²); the reference acceleration
    /// of a normal row is `K d δ` at penetration δ.
    pub k: f64,
}

/// B and K of a contact from `solref = (t_c (s), ζ)` in MuJoCo's standard
/// (positive) format, `solimp` and the time step `h` (s).
pub fn reference(solref: &[f64; 2], solimp: &[f64; 5], timestep: f64) -> Reference {
    let dmax = clamped_solimp(solimp)[1];
    let tc = solref[0].max(2.0 * timestep);
    Reference {
        timeconst: tc,
        b: 2.0 / (dmax * tc),
        k: 1.0 / (dmax * dmax * tc * tc * solref[1] * solref[1]),
    }
}

/// What the closed form needs about one contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CreepInput {
    /// Friction cone.
    pub cone: Cone,
    /// MuJoCo's `impratio` (dimensionless, > 0).
    pub impratio: f64,
    /// Contact `solref` (t_c in s, damping ratio ζ), standard format.
    pub solref: [f64; 2],
    /// Contact `solimp` (d0, d_width, width in m, midpoint, power).
    pub solimp: [f64; 5],
    /// Time step h (s); enters only through the `refsafe` clamp `t_c ≥ 2h`.
    pub timestep: f64,
    /// Sliding friction coefficient μ of the contact.
    pub mu: f64,
    /// Normal force N the contact carries (N).
    pub normal_load: f64,
    /// MuJoCo's approximate inverse mass of the contact rows, Â (1/kg): the
    /// sum of the two bodies' translational `body_invweight0` (`1/m` for a
    /// free body on the world).
    pub inv_weight: f64,
    /// Tangential load the contact's friction must balance, in the
    /// contact's tangent frame (t₁, t₂) (N).
    pub load: [f64; 2],
}

/// Which solution of the steady problem applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CreepRegime {
    /// Every friction row active, inside the cone: the linear law.
    Interior,
    /// Pyramidal cone only: one edge has lifted off (`|F_j| > μN/2` on a
    /// tangent axis): the steeper `3λ − 1` branch.
    EdgeLifted,
    /// The load reaches the cone (elliptic `|F| ≥ μN`, pyramidal
    /// `|F₁| + |F₂| ≥ μN`): no steady state, the body slides.
    Slides,
}

impl CreepRegime {
    /// `"interior"`, `"edge_lifted"` or `"slides"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            CreepRegime::Interior => "interior",
            CreepRegime::EdgeLifted => "edge_lifted",
            CreepRegime::Slides => "slides",
        }
    }
}

/// The closed form's answer for one contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CreepPrediction {
    /// Regime of the steady state.
    pub regime: CreepRegime,
    /// Steady slip velocity in the tangent frame (m/s), along the load
    /// (NaN when the body slides).
    pub velocity: [f64; 2],
    /// Steady penetration δ (m).
    pub penetration: f64,
    /// Impedance d at that penetration.
    pub impedance: f64,
    /// Regulariser of the friction rows (1/kg): `R_t` (elliptic) or `R_py`
    /// (pyramidal).
    pub r_friction: f64,
    /// Reference coefficients (B, K, clamped t_c).
    pub reference: Reference,
}

impl CreepPrediction {
    /// Steady slip speed |u| (m/s; NaN when the body slides).
    pub fn speed(&self) -> f64 {
        self.velocity[0].hypot(self.velocity[1])
    }
}

/// `(1 − d)/d · Â`, MuJoCo's base regulariser (1/kg).
fn base_r(d: f64, inv_weight: f64) -> f64 {
    (1.0 - d) / d * inv_weight
}

/// The penetration δ ≥ 0 (m) solving `K d(δ) δ = c · (1 − d(δ))/d(δ)`:
/// the steady normal balance of a row whose regulariser is
/// `c/(share) · (1 − d)/d` (the left side grows with δ, the right side
/// falls, so the root is unique; bisection).
fn penetration(solimp: &[f64; 5], k: f64, c: f64) -> f64 {
    if c <= 0.0 {
        return 0.0;
    }
    let g = |delta: f64| {
        let d = impedance(solimp, -delta);
        k * d * delta - c * (1.0 - d) / d
    };
    let mut hi = 1e-9;
    while g(hi) < 0.0 {
        hi *= 2.0;
        if hi > 1e6 {
            return f64::NAN;
        }
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// MuJoCo's steady creep of one contact (see the module docs for the
/// derivation and the regimes).
pub fn creep(input: &CreepInput) -> CreepPrediction {
    let reference = reference(&input.solref, &input.solimp, input.timestep);
    let (b, k) = (reference.b, reference.k);
    let (mu, n, aw) = (input.mu, input.normal_load, input.inv_weight);
    let [f1, f2] = input.load;
    let nan = [f64::NAN; 2];
    match input.cone {
        Cone::Elliptic => {
            // Normal row: R_n N = K d δ.
            let delta = penetration(&input.solimp, k, n * aw);
            let d = impedance(&input.solimp, -delta);
            let rt = base_r(d, aw) / input.impratio;
            let slides = f1.hypot(f2) >= mu * n;
            CreepPrediction {
                regime: if slides {
                    CreepRegime::Slides
                } else {
                    CreepRegime::Interior
                },
                velocity: if slides {
                    nan
                } else {
                    [f1 * rt / b, f2 * rt / b]
                },
                penetration: delta,
                impedance: d,
                r_friction: rt,
                reference,
            }
        }
        Cone::Pyramidal => {
            let scale = 2.0 * mu * mu * (1.0 + mu * mu) / input.impratio;
            let half = 0.5 * mu * n;
            let (a1, a2) = (f1.abs(), f2.abs());
            let regime = if a1 + a2 >= mu * n || (a1 > half && a2 > half) {
                CreepRegime::Slides
            } else if a1 > half || a2 > half {
                CreepRegime::EdgeLifted
            } else {
                CreepRegime::Interior
            };
            // Normal share of the edges: N/4 each (interior), or the cross
            // pair's (N − |F_lifted|/μ)/2.
            let share = match regime {
                CreepRegime::Interior => 0.25 * n,
                CreepRegime::EdgeLifted => 0.5 * (n - a1.max(a2) / mu),
                CreepRegime::Slides => 0.25 * n,
            };
            let delta = penetration(&input.solimp, k, share * scale * aw);
            let d = impedance(&input.solimp, -delta);
            let rpy = scale * base_r(d, aw);
            let linear = |f: f64| f * rpy / (2.0 * mu * mu * b);
            let lifted = |f: f64| f.signum() * rpy * (3.0 * f.abs() / mu - n) / (2.0 * b * mu);
            let velocity = match regime {
                CreepRegime::Interior => [linear(f1), linear(f2)],
                CreepRegime::EdgeLifted if a1 > half => [lifted(f1), linear(f2)],
                CreepRegime::EdgeLifted => [linear(f1), lifted(f2)],
                CreepRegime::Slides => nan,
            };
            CreepPrediction {
                regime,
                velocity,
                penetration: delta,
                impedance: d,
                r_friction: rpy,
                reference,
            }
        }
    }
}

/// The regularised-friction slip scale of a contact, evaluated for the
/// elliptic cone (its d, at the elliptic penetration, whatever `input.cone`),
/// `ε = μ N R_t / B` (m/s): the steady creep under a load `λ μ N` is `λ ε`
/// (pyramidal: `(1 + μ²) λ ε` up to `λ = 1/2` along a tangent axis).
pub fn slip_scale(input: &CreepInput) -> f64 {
    let p = creep(&CreepInput {
        cone: Cone::Elliptic,
        load: [0.0, 0.0],
        ..*input
    });
    input.mu * input.normal_load * p.r_friction / p.reference.b
}

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

/// The CSV columns of `creep_law.csv`, in order.
pub const CSV_COLUMNS: [&str; 25] = [
    "group",
    "impratio",
    "cone",
    "solref",
    "solimp",
    "dt",
    "feet",
    "noslip",
    "direction",
    "load_fraction",
    "case",
    "regime",
    "creep_measured",
    "creep_closed_form",
    "rel_err",
    "steadiness",
    "lateral_measured",
    "lateral_closed_form",
    "hold_time",
    "contacts",
    "height_std",
    "penetration_measured",
    "penetration_closed_form",
    "impedance",
    "slip_scale",
];

/// Parses `creep_law.csv` text into rows of (column → text).
pub fn parse_csv(text: &str) -> Result<Vec<Vec<(String, String)>>, String> {
    let mut lines = text.lines();
    let head: Vec<&str> = lines
        .next()
        .ok_or("creep_law.csv: empty file")?
        .split(',')
        .collect();
    if head != CSV_COLUMNS {
        return Err(format!(
            "creep_law.csv: header is {head:?}, expected {CSV_COLUMNS:?}"
        ));
    }
    let mut rows = Vec::new();
    for (i, l) in lines.enumerate() {
        let cells: Vec<&str> = l.split(',').collect();
        if cells.len() != head.len() {
            return Err(format!(
                "creep_law.csv line {}: {} cells, expected {}",
                i + 2,
                cells.len(),
                head.len()
            ));
        }
        rows.push(
            head.iter()
                .zip(&cells)
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect(),
        );
    }
    Ok(rows)
}

/// The value of `key` in a parsed row ("" when absent).
pub fn cell<'a>(row: &'a [(String, String)], key: &str) -> &'a str {
    row.iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .unwrap_or("")
}

/// The number in `key` of a parsed row (NaN when empty or not a number).
pub fn num(row: &[(String, String)], key: &str) -> f64 {
    cell(row, key).parse().unwrap_or(f64::NAN)
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

/// Runs the creep scene in MuJoCo: settles the plate, switches on the load
/// `load_fraction · μ W` along world angle `direction` (rad) at the centre of
/// mass (for [`CreepCase::Sliding`] the plate also gets that speed along the
/// load), holds it for `hold_time` s and measures the slip over the last
/// 40 %. Without the `mujoco` feature:
/// [`ModelError::Integration`](pushval_model::ModelError::Integration) with
/// [`crate::UNAVAILABLE`].
pub fn measure(
    scene: &CreepScene,
    case: CreepCase,
    load_fraction: f64,
    direction: f64,
    hold_time: f64,
) -> Result<CreepMeasurement, pushval_model::ModelError> {
    #[cfg(feature = "mujoco")]
    {
        crate::creep_sim::measure(scene, case, load_fraction, direction, hold_time)
    }
    #[cfg(not(feature = "mujoco"))]
    {
        let _ = (scene, case, load_fraction, direction, hold_time);
        Err(pushval_model::ModelError::Integration {
            t: 0.0,
            reason: crate::UNAVAILABLE.into(),
        })
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

type Row = Vec<(String, String)>;

fn fmt_e(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$e}")
    } else {
        "–".into()
    }
}

/// Height standard deviation (m) above which a run counts as chattering:
/// the plate does not settle on its feet (settled runs stay below 3e-7 m,
/// chattering ones above 9e-6 m in the ladder).
pub const CHATTER_HEIGHT_STD: f64 = 1e-6;

/// Whether the plate of a row settled on its feet (its height varied by
/// less than [`CHATTER_HEIGHT_STD`] over the measuring window).
pub fn settles(row: &[(String, String)]) -> bool {
    num(row, "height_std") < CHATTER_HEIGHT_STD
}

/// Whether a row lies in the closed form's domain: a steady state exists
/// (regime not `slides`) and MuJoCo's noslip pass is off.
pub fn in_domain(row: &[(String, String)]) -> bool {
    cell(row, "regime") != "slides" && num(row, "noslip") == 0.0
}

/// The generated README section `creep_law.md`, every number taken from
/// the text of `creep_law.csv` (a test regenerates it from the committed
/// CSV and compares).
pub fn report_markdown(csv: &str) -> Result<String, String> {
    let rows = parse_csv(csv)?;
    if rows.is_empty() {
        return Err("creep_law.csv: no rows".into());
    }
    let d = CreepScene::default();
    let ds = &d.settings;
    let solref0 = format!("{} {}", ds.contact_solref[0], ds.contact_solref[1]);
    let si = ds.contact_solimp;
    let solimp0 = format!("{} {} {} {} {}", si[0], si[1], si[2], si[3], si[4]);
    let base = |r: &Row| {
        cell(r, "solref") == solref0
            && cell(r, "solimp") == solimp0
            && num(r, "feet") == 4.0
            && num(r, "noslip") == 0.0
            && num(r, "direction") == 0.0
    };
    let find = |pred: &dyn Fn(&Row) -> bool| rows.iter().find(|r| pred(r));
    let mut o = String::new();
    let _ = writeln!(o, "# MuJoCo's creep law\n");
    let _ = writeln!(
        o,
        "Generated by `cargo run --release -p pushval-mujoco --features mujoco --example creep_law` \
         (environment: `eval \"$(scripts/setup-mujoco.sh)\"`) from `creep_law.csv` (one row per run, \
         the closed form beside each measurement); do not edit by hand."
    );
    let _ = writeln!(
        o,
        "\nScene: a {} kg square plate ({} m side) on {} sphere feet (radius {} m, μ {}, condim 3) \
         at its corners, centre of mass at floor height, g {}; the load λ μ W is a horizontal force \
         at the centre of mass (`xfrc_applied`; no pusher body, so only the contacts resist it). \
         After settling {} s at rest the load is switched on and held: `held` starts at rest, \
         `sliding` starts with the plate moving at {} m/s along the load (Coulomb friction would stop \
         it). Creep = mean slip velocity along the load over the hold's last 40 % (`hold_time` per \
         row); `steadiness` compares its two halves. Defaults: solref ({solref0}), solimp ({solimp0}), \
         Newton solver, {} iterations, Euler.",
        d.mass,
        2.0 * d.half_side,
        d.feet,
        ds.foot_radius,
        d.mu,
        ds.gravity,
        ds.settle_time,
        SLIDING_SPEED,
        ds.iterations
    );

    // The closed form.
    let def = |cone: &str| {
        find(&|r: &Row| {
            cell(r, "group") == "ladder"
                && base(r)
                && cell(r, "cone") == cone
                && cell(r, "impratio") == "1"
                && cell(r, "dt") == "0.001"
                && cell(r, "load_fraction") == "0.5"
                && cell(r, "case") == "held"
        })
    };
    let ell = def("elliptic");
    let pyr = def("pyramidal");
    let _ = writeln!(o, "\n## The closed form\n");
    let _ = writeln!(
        o,
        "Derived in `crates/mujoco/src/creep.rs` from MuJoCo's regularised constraint problem. Inside the \
         friction cone MuJoCo's solver returns the linear solution (A + R) f = a_ref − a₀, so the \
         constraint acceleration is a = a_ref − R f. A steady creep has a = 0 on every contact row, hence \
         **R f = a_ref**: the mass matrix A and the time step drop out. With MuJoCo's bookkeeping \
         (impedance d from solimp at the penetration δ, B = 2/(d_max t_c) and K = 1/(d_max² t_c² ζ²) from \
         solref with t_c ≥ 2 dt, R = (1 − d)/d · Â with Â the body's translational invweight0 = 1/m):\n\n\
         * elliptic: friction rows R_t = R_n/impratio and a_ref = −B u, so for a contact loaded by F \
         (λ μ N): **u* = F R_t / B = λ ε**, ε = μ N (1 − d) Â d_max t_c / (2 d impratio); δ from \
         R_n N = K d δ;\n\
         * pyramidal: edges n ± μ t_j with Â(1 + μ²) and R_py = 2 μ² (1 + μ²)(1 − d)/d Â / impratio, \
         a_ref = −B(±μ u_j) + K d δ: **u_j = F_j R_py / (2 μ² B) = (1 + μ²) λ_j ε** while |F_j| ≤ μN/2 on \
         both tangent axes (δ from K d δ = R_py N/4); beyond, the edge n + μ t₁ (for F₁ > 0 the one \
         whose friction would push along the load) lifts off and \
         **u₁ = R_py (3F₁/μ − N)/(2 B μ)**, i.e. (1 + μ²) ε (3λ − 1) along an axis (δ from \
         K d δ = R_py (N − F₁/μ)/2), until |F₁| + |F₂| = μN.\n\n\
         In the regularised-friction picture f = μN u / max(|u|, ε) this is the slip scale ε = μ N R_t / B. \
         With equal loads N = m g / n it reads ε = μ g (1 − d) d_max t_c / (2 n d impratio): 1/impratio, \
         ∝ t_c, ∝ (1 − d)/d, and ∝ 1/n, the number of contacts sharing the weight. Defaults (impratio 1, \
         dt 0.001 s): elliptic d = {}, ε = {} m/s; pyramidal d = {} (its edges penetrate less).",
        ell.map(|r| cell(r, "impedance")).unwrap_or("–"),
        ell.map(|r| fmt_e(num(r, "slip_scale"), 4)).unwrap_or("–".into()),
        pyr.map(|r| cell(r, "impedance")).unwrap_or("–"),
    );

    // Accuracy.
    let dom: Vec<&Row> = rows.iter().filter(|r| in_domain(r)).collect();
    let max_by = |v: &[&Row]| -> (f64, Option<usize>) {
        let mut best = (f64::NEG_INFINITY, None);
        for (i, r) in v.iter().enumerate() {
            let e = num(r, "rel_err");
            if e > best.0 {
                best = (e, Some(i));
            }
        }
        best
    };
    let settled: Vec<&Row> = dom.iter().copied().filter(|r| settles(r)).collect();
    let chatter: Vec<&Row> = dom.iter().copied().filter(|r| !settles(r)).collect();
    let (emax, imax) = max_by(&settled);
    let describe = |r: &Row| {
        format!(
            "{} cone, impratio {}, solref ({}), solimp ({}), dt {}, {} feet, λ {}, direction {}, {}",
            cell(r, "cone"),
            cell(r, "impratio"),
            cell(r, "solref"),
            cell(r, "solimp"),
            cell(r, "dt"),
            cell(r, "feet"),
            cell(r, "load_fraction"),
            cell(r, "direction"),
            cell(r, "case")
        )
    };
    let _ = writeln!(o, "\n## Accuracy\n");
    let _ = writeln!(
        o,
        "{} runs in all; {} lie in the closed form's domain (a steady state exists: the load is inside \
         the cone, and MuJoCo's noslip pass is off). Of these, {} settle on their feet (height standard \
         deviation over the measuring window below {:e} m) and over them the largest relative error \
         |u_measured − u_closed| / |u_closed| (the vector of along- and across-load slip) is **{}** \
         ({}). The other {} **chatter**: the plate never comes to rest on its feet (below, \
         \"Where the law stops holding\"), and there the error reaches {}.",
        rows.len(),
        dom.len(),
        settled.len(),
        CHATTER_HEIGHT_STD,
        fmt_e(emax, 1),
        imax.map(|i| describe(settled[i])).unwrap_or_default(),
        chatter.len(),
        fmt_e(max_by(&chatter).0, 1)
    );
    let _ = writeln!(
        o,
        "\n| group | runs in domain | settle | max rel err (settled) | max steadiness (settled) | chatter | max rel err (chatter) |"
    );
    let _ = writeln!(o, "|---|---|---|---|---|---|---|");
    let mut groups: Vec<&str> = Vec::new();
    for r in &rows {
        let g = cell(r, "group");
        if !groups.contains(&g) {
            groups.push(g);
        }
    }
    for g in &groups {
        let v: Vec<&Row> = dom
            .iter()
            .copied()
            .filter(|r| cell(r, "group") == *g)
            .collect();
        if v.is_empty() {
            continue;
        }
        let ok: Vec<&Row> = v.iter().copied().filter(|r| settles(r)).collect();
        let bad: Vec<&Row> = v.iter().copied().filter(|r| !settles(r)).collect();
        let st = ok
            .iter()
            .filter(|r| num(r, "load_fraction") > 0.0)
            .map(|r| num(r, "steadiness"))
            .fold(f64::NEG_INFINITY, f64::max);
        let _ = writeln!(
            o,
            "| {g} | {} | {} | {} | {} | {} | {} |",
            v.len(),
            ok.len(),
            fmt_e(max_by(&ok).0, 1),
            fmt_e(st, 1),
            bad.len(),
            fmt_e(max_by(&bad).0, 1)
        );
    }

    // Core ladder.
    let _ = writeln!(
        o,
        "\n## The ladder at dt = 0.001 s, default solref/solimp (`held`)\n"
    );
    let _ = writeln!(
        o,
        "Creep speed u* (m/s) measured / closed form; the load along world x, which is a tangent axis \
         of MuJoCo's plane contact frame.\n"
    );
    let loads = ["0.25", "0.5", "0.75", "0.9"];
    let _ = writeln!(o, "| cone | impratio | d | {} |", {
        loads
            .iter()
            .map(|l| format!("λ = {l}"))
            .collect::<Vec<_>>()
            .join(" | ")
    });
    let _ = writeln!(o, "|---|---|---|{}", "---|".repeat(loads.len()));
    for cone in ["pyramidal", "elliptic"] {
        for imp in ["1", "10", "100"] {
            let mut line = format!("| {cone} | {imp} |");
            let mut first = true;
            for l in loads {
                let r = find(&|r: &Row| {
                    cell(r, "group") == "ladder"
                        && base(r)
                        && cell(r, "cone") == cone
                        && cell(r, "impratio") == imp
                        && cell(r, "dt") == "0.001"
                        && cell(r, "load_fraction") == l
                        && cell(r, "case") == "held"
                });
                if first {
                    line += &format!(" {} |", r.map(|r| cell(r, "impedance")).unwrap_or("–"));
                    first = false;
                }
                line += &match r {
                    Some(r) => format!(
                        " {} / {} ({}) |",
                        fmt_e(num(r, "creep_measured"), 4),
                        fmt_e(num(r, "creep_closed_form"), 4),
                        cell(r, "regime")
                    ),
                    None => " – |".into(),
                };
            }
            let _ = writeln!(o, "{line}");
        }
    }
    // impratio scaling.
    let at = |cone: &str, imp: &str, l: &str| {
        find(&|r: &Row| {
            cell(r, "group") == "ladder"
                && base(r)
                && cell(r, "cone") == cone
                && cell(r, "impratio") == imp
                && cell(r, "dt") == "0.001"
                && cell(r, "load_fraction") == l
                && cell(r, "case") == "held"
        })
        .map(|r| num(r, "creep_measured"))
        .unwrap_or(f64::NAN)
    };
    let _ = writeln!(
        o,
        "\n**impratio.** Measured u*(1)/u*(10) and u*(10)/u*(100) at λ = 0.5: pyramidal {:.4} and \
         {:.4}, elliptic {:.4} and {:.4} — the exact 1/impratio of the law (R_t = R_n/impratio; the \
         elliptic penetration does not depend on impratio, the pyramidal one falls with it but stays \
         where d = d0). **Load.** Elliptic u* is linear in λ up to the cone (u*(0.9)/u*(0.5) = {:.4}); \
         pyramidal u* is linear up to λ = 1/2 along a tangent axis and then follows 3λ − 1 \
         (u*(0.9)/u*(0.5) = {:.4}, the closed form's (3·0.9 − 1)/0.5 = 3.4), because the edge \
         `n + μ t` lifts off. The pyramid creeps (1 + μ²) times faster than the ellipse below λ = 1/2 \
         (u*_pyr/u*_ell at λ = 0.25, impratio 1: {:.4}; d differs slightly: the pyramid penetrates less).",
        at("pyramidal", "1", "0.5") / at("pyramidal", "10", "0.5"),
        at("pyramidal", "10", "0.5") / at("pyramidal", "100", "0.5"),
        at("elliptic", "1", "0.5") / at("elliptic", "10", "0.5"),
        at("elliptic", "10", "0.5") / at("elliptic", "100", "0.5"),
        at("elliptic", "1", "0.9") / at("elliptic", "1", "0.5"),
        at("pyramidal", "1", "0.9") / at("pyramidal", "1", "0.5"),
        at("pyramidal", "1", "0.25") / at("elliptic", "1", "0.25"),
    );

    // dt.
    let mut dts: Vec<&str> = Vec::new();
    for r in rows.iter().filter(|r| cell(r, "group") == "ladder") {
        let v = cell(r, "dt");
        if !dts.contains(&v) {
            dts.push(v);
        }
    }
    let _ = writeln!(
        o,
        "\n## Time step (impratio 1, λ = 0.5, `held`)\n\nThe steady state has a = 0, so the step \
         drops out, except through MuJoCo's `refsafe` clamp t_c ≥ 2 dt: above dt = t_c/2 the \
         effective time constant is 2 dt and the creep grows with it.\n"
    );
    let _ = writeln!(
        o,
        "| dt (s) | pyramidal measured | closed form | elliptic measured | closed form |"
    );
    let _ = writeln!(o, "|---|---|---|---|---|");
    for dt in &dts {
        let g = |cone: &str| {
            find(&|r: &Row| {
                cell(r, "group") == "ladder"
                    && base(r)
                    && cell(r, "cone") == cone
                    && cell(r, "impratio") == "1"
                    && cell(r, "dt") == *dt
                    && cell(r, "load_fraction") == "0.5"
                    && cell(r, "case") == "held"
            })
        };
        let f = |r: Option<&Row>, k: &str| r.map(|r| fmt_e(num(r, k), 4)).unwrap_or("–".into());
        let _ = writeln!(
            o,
            "| {dt} | {} | {} | {} | {} |",
            f(g("pyramidal"), "creep_measured"),
            f(g("pyramidal"), "creep_closed_form"),
            f(g("elliptic"), "creep_measured"),
            f(g("elliptic"), "creep_closed_form")
        );
    }

    // held vs sliding.
    let mut worst = 0.0f64;
    let mut pairs = 0usize;
    for r in rows
        .iter()
        .filter(|r| cell(r, "case") == "held" && in_domain(r) && settles(r))
    {
        // A run's settings: the CSV's columns up to `case`.
        let key = |x: &Row| -> Vec<String> {
            CSV_COLUMNS[..10]
                .iter()
                .map(|k| cell(x, k).to_string())
                .collect()
        };
        let k = key(r);
        if let Some(s) = find(&|x: &Row| cell(x, "case") == "sliding" && settles(x) && key(x) == k)
        {
            pairs += 1;
            let a = num(r, "creep_measured");
            let b = num(s, "creep_measured");
            worst = worst.max((a - b).abs() / a.abs());
        }
    }
    let _ = writeln!(
        o,
        "\n## Held and sliding\n\nThe steady state is memoryless (the friction rows have no position \
         term: K = 0 on elliptic friction rows, equal on paired pyramid edges): over {pairs} pairs that \
         settle, the `held` and `sliding` creep differ by at most {} relative. Coulomb friction would \
         stop the sliding plate; MuJoCo decays into the same creep from above.",
        fmt_e(worst, 1)
    );

    // solref / solimp / feet.
    let _ = writeln!(
        o,
        "\n## solref, solimp, number of feet (dt = 0.001 s, λ = 0.5, `held`)\n"
    );
    let _ = writeln!(o, "| group | solref | solimp | feet | cone | impratio | d | u* measured | closed form | rel err | height std (m) |");
    let _ = writeln!(o, "|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows.iter().filter(|r| {
        matches!(cell(r, "group"), "solref" | "solimp" | "feet")
            && matches!(cell(r, "impratio"), "1" | "100")
            && cell(r, "load_fraction") == "0.5"
            && cell(r, "case") == "held"
    }) {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            cell(r, "group"),
            cell(r, "solref"),
            cell(r, "solimp"),
            cell(r, "feet"),
            cell(r, "cone"),
            cell(r, "impratio"),
            cell(r, "impedance"),
            fmt_e(num(r, "creep_measured"), 4),
            fmt_e(num(r, "creep_closed_form"), 4),
            fmt_e(num(r, "rel_err"), 1),
            fmt_e(num(r, "height_std"), 1)
        );
    }
    let _ = writeln!(
        o,
        "\nWhere the plate settles: the damping ratio ζ leaves the elliptic creep unchanged (B = 2/(d_max t_c) \
         has no ζ; ζ moves only the penetration, hence d); the time constant scales the creep; a stiffer \
         solimp (larger d) shrinks it through (1 − d)/d. Eight feet creep at half the speed of four: Â is \
         the whole body's 1/m at every contact while each contact carries W/n."
    );

    // Direction.
    let _ = writeln!(
        o,
        "\n## Load direction (pyramidal anisotropy, `held`, dt = 0.001 s)\n\nThe pyramid's tangent axes \
         are fixed in the world (MuJoCo builds a plane contact's frame from the plane's normal alone; \
         the load at direction 0, world x, runs along one of them); off an axis the edge that lifts first turns the creep away from the load, and along the \
         diagonal the pyramid holds only λ < 1/√2.\n"
    );
    let _ = writeln!(o, "| cone | impratio | direction (rad) | λ | regime | along: measured / closed | across: measured / closed | rel err |");
    let _ = writeln!(o, "|---|---|---|---|---|---|---|---|");
    for r in rows
        .iter()
        .filter(|r| cell(r, "group") == "direction" && cell(r, "case") == "held")
    {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} / {} | {} / {} | {} |",
            cell(r, "cone"),
            cell(r, "impratio"),
            cell(r, "direction"),
            cell(r, "load_fraction"),
            cell(r, "regime"),
            fmt_e(num(r, "creep_measured"), 3),
            fmt_e(num(r, "creep_closed_form"), 3),
            fmt_e(num(r, "lateral_measured"), 2),
            fmt_e(num(r, "lateral_closed_form"), 2),
            fmt_e(num(r, "rel_err"), 1)
        );
    }

    // Where it stops.
    let _ = writeln!(o, "\n## Where the law stops holding\n");
    let unl: Vec<&Row> = rows
        .iter()
        .filter(|r| cell(r, "group") == "unloaded")
        .collect();
    let _ = writeln!(
        o,
        "**1. Chatter (underdamped contacts).** With a low damping ratio the plate never settles on its \
         feet, even with no load: it keeps bouncing with a height standard deviation of the order of the \
         penetration (group `unloaded`, λ = 0):\n"
    );
    let _ = writeln!(
        o,
        "| cone | solref | impratio | height std (m) | foot contacts at the end |"
    );
    let _ = writeln!(o, "|---|---|---|---|---|");
    for r in &unl {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} |",
            cell(r, "cone"),
            cell(r, "solref"),
            cell(r, "impratio"),
            fmt_e(num(r, "height_std"), 2),
            cell(r, "contacts")
        );
    }
    let ratios: Vec<f64> = chatter
        .iter()
        .map(|r| num(r, "creep_measured") / num(r, "creep_closed_form"))
        .filter(|v| v.is_finite())
        .collect();
    let (rmin, rmax) = ratios
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let zeta = |cone: &str, z: &str, imp: &str| {
        find(&|r: &Row| {
            cell(r, "group") == "solref"
                && cell(r, "cone") == cone
                && cell(r, "solref") == z
                && cell(r, "impratio") == imp
                && cell(r, "load_fraction") == "0.5"
                && cell(r, "case") == "held"
        })
        .map(|r| num(r, "creep_measured"))
        .unwrap_or(f64::NAN)
    };
    let _ = writeln!(
        o,
        "\nThe closed form assumes a steady contact; in the {} chattering runs the mean creep is {:.2}–{:.1} \
         times the law. It stays proportional to the load but no longer falls as 1/impratio: elliptic, \
         solref (0.02 0.3), λ = 0.5: u* = {} at impratio 1 and {} at impratio 100; pyramidal, solref \
         (0.02 0.7): {} and {}. The pyramid chatters at higher ζ than the ellipse and more at large \
         impratio, since its single regulariser R_py, which also softens the normal, shrinks as \
         1/impratio; the elliptic normal's R does not depend on impratio. (The mechanism of the limit \
         cycle is not derived here.)",
        chatter.len(),
        rmin,
        rmax,
        fmt_e(zeta("elliptic", "0.02 0.3", "1"), 3),
        fmt_e(zeta("elliptic", "0.02 0.3", "100"), 3),
        fmt_e(zeta("pyramidal", "0.02 0.7", "1"), 3),
        fmt_e(zeta("pyramidal", "0.02 0.7", "100"), 3),
    );
    let slides: Vec<&Row> = rows
        .iter()
        .filter(|r| cell(r, "regime") == "slides")
        .collect();
    let hop = slides
        .iter()
        .filter(|r| num(r, "contacts") < num(r, "feet"))
        .count();
    let _ = writeln!(
        o,
        "\n**2. At and past the friction limit** there is no steady state: the plate accelerates (the \
         table's u is the mean speed over the window) and it hops — {hop} of the {} sliding-regime runs \
         end with fewer foot contacts than feet. Elliptic: the limit is μN in every direction (λ = 0.99 \
         still creeps as the law says, group `limit`). Pyramidal: the limit is the L1 diamond \
         |F₁| + |F₂| ≤ μN in the world-fixed tangent axes, so along the diagonal the pyramid lets go at \
         λ = 1/√2, and 15° off an axis at λ = 1/(cos 15° + sin 15°) ≈ 0.816.",
        slides.len()
    );
    let _ = writeln!(
        o,
        "\n**3. MuJoCo's noslip pass** (noslip_iterations = 10) is outside the formulation the law is \
         derived from: it removes the elliptic creep (u below 1e-7 m/s) and cuts the pyramidal creep at \
         λ = 0.5, but leaves the pyramidal creep at λ = 0.9 (edge lifted) exactly on the law.\n"
    );
    let _ = writeln!(o, "| group | cone | impratio | direction | λ | case | noslip | regime | u measured (m/s) | closed form | foot contacts |");
    let _ = writeln!(o, "|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows.iter().filter(|r| !in_domain(r)) {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            cell(r, "group"),
            cell(r, "cone"),
            cell(r, "impratio"),
            cell(r, "direction"),
            cell(r, "load_fraction"),
            cell(r, "case"),
            cell(r, "noslip"),
            cell(r, "regime"),
            fmt_e(num(r, "creep_measured"), 3),
            fmt_e(num(r, "creep_closed_form"), 3),
            cell(r, "contacts")
        );
    }
    let _ = writeln!(
        o,
        "\n**4. Not covered:** a contact that turns while it creeps (the pushing problem: the law is per \
         contact and needs the contact's slip to be steady), foot loads that differ (give each contact \
         its own N; the scene keeps them equal), solref in MuJoCo's direct (negative) format, a set \
         `solreffriction`, and bodies whose contacts involve two moving bodies (Â is then the sum of both \
         bodies' invweight0)."
    );

    Ok(o)
}
