//! The closed form of MuJoCo's steady creep (derivation: the module
//! [`super`]): impedance, reference acceleration, regulariser, and the creep
//! velocity and regime they give under a tangential load.

use crate::Cone;

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
