//! The catalogue: every law of this crate by a stable name, with its
//! parameters. It names no engine: engines declare their laws
//! (`Engine::law`, or `law = "NAME"` for an outside engine) and the command
//! line's listing (`pushval laws`) joins the two.

use serde_json::{Map, Value};

use crate::avian::{Avian3dTilt, PlateParams};
use crate::box2d::Box2dMotorJoint;
use crate::drake::{Approximation, DrakeConvex};
use crate::idioms::{
    ImpulseBox, ImpulseDisk, RegularisedLinear, RegularisedTanh, RowsDisk, DEFAULT_SLIP_SPEED,
};
use crate::jolt::{JoltBox, JoltFeet};
use crate::mujoco::MujocoElliptic;
use crate::physx::{FootContacts, FrictionType, PhysxClamp};
use crate::rapier3d::{Rapier3dTilt, SceneParams};
use crate::{FrictionLaw, COULOMB};

/// Where a law's support loads come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Loads {
    /// The problem's: each support's friction magnitude `F_i = μ_i N_i` as
    /// the scenario's statics resolved it (the law predicts no loads).
    Problem,
    /// The law's own prediction ([`FrictionLaw::loads`]): it shares the
    /// weight from the problem's geometry and mass (and moves load by the
    /// tilting balance where the law has heights); `μ_i` is calibrated from
    /// the problem's `F_i` at rest.
    Law,
}

impl Loads {
    /// `"problem"` or `"law"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Loads::Problem => "problem",
            Loads::Law => "law",
        }
    }
}

/// What values a parameter takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamKind {
    /// A finite number > 0.
    Positive,
    /// A finite number ≥ 0.
    NonNegative,
    /// One of these strings.
    Choice(&'static [&'static str]),
}

/// One parameter of a law.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    /// Its key (snake_case).
    pub name: &'static str,
    /// Its default: a number or one of the choices.
    pub default: Value,
    /// Its unit (`"m"`, `"m/s"`, …; `""` for a choice).
    pub unit: &'static str,
    /// What it is, in one line.
    pub meaning: &'static str,
    /// What values it takes.
    pub kind: ParamKind,
}

impl ParamSpec {
    fn number(name: &'static str, default: f64, unit: &'static str, meaning: &'static str) -> Self {
        Self {
            name,
            default: Value::from(default),
            unit,
            meaning,
            kind: ParamKind::NonNegative,
        }
    }

    fn positive(mut self) -> Self {
        self.kind = ParamKind::Positive;
        self
    }

    fn choice(name: &'static str, choices: &'static [&'static str], meaning: &'static str) -> Self {
        Self {
            name,
            default: Value::from(choices[0]),
            unit: "",
            meaning,
            kind: ParamKind::Choice(choices),
        }
    }

    /// Checks `value`; the error names the key.
    fn check(&self, value: &Value) -> Result<(), ParamError> {
        let err = |problem: String| ParamError {
            key: self.name.to_string(),
            problem,
        };
        match self.kind {
            ParamKind::Positive | ParamKind::NonNegative => {
                let x = value
                    .as_f64()
                    .ok_or_else(|| err(format!("must be a number, got {value}")))?;
                let ok = x.is_finite()
                    && if self.kind == ParamKind::Positive {
                        x > 0.0
                    } else {
                        x >= 0.0
                    };
                if ok {
                    Ok(())
                } else if self.kind == ParamKind::Positive {
                    Err(err(format!("must be finite and > 0, got {x}")))
                } else {
                    Err(err(format!("must be finite and >= 0, got {x}")))
                }
            }
            ParamKind::Choice(choices) => match value.as_str() {
                Some(s) if choices.contains(&s) => Ok(()),
                _ => Err(err(format!(
                    "must be one of {}, got {value}",
                    choices
                        .iter()
                        .map(|c| format!("\"{c}\""))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))),
            },
        }
    }
}

/// A parameter a law refuses: its key and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParamError {
    /// The parameter's key.
    pub key: String,
    /// What is wrong with it.
    pub problem: String,
}

impl std::fmt::Display for ParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.key, self.problem)
    }
}

impl std::error::Error for ParamError {}

/// A law's parameters, checked and completed with the defaults.
struct Values(Map<String, Value>);

impl Values {
    fn num(&self, key: &str) -> f64 {
        self.0[key].as_f64().expect("checked: a number")
    }
    fn text(&self, key: &str) -> &str {
        self.0[key].as_str().expect("checked: a string")
    }
}

/// One law of the catalogue.
#[derive(Debug, Clone)]
pub struct LawEntry {
    /// Its stable name (snake_case), as `law = "NAME"` declares it.
    pub name: &'static str,
    /// Its parameters, with defaults.
    pub params: Vec<ParamSpec>,
    /// Where its support loads come from.
    pub loads: Loads,
    /// What it is, in one sentence.
    pub about: &'static str,
    make: fn(&Values) -> Box<dyn FrictionLaw>,
}

impl std::fmt::Debug for Values {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl LawEntry {
    /// The law with `params` (keys of [`LawEntry::params`]; absent ones take
    /// their defaults). An unknown key or a bad value is an error naming
    /// the key.
    pub fn build(&self, params: &Map<String, Value>) -> Result<Box<dyn FrictionLaw>, ParamError> {
        let mut values = Map::new();
        for (key, value) in params {
            let Some(spec) = self.params.iter().find(|p| p.name == key) else {
                let known = if self.params.is_empty() {
                    format!("the law \"{}\" takes no parameters", self.name)
                } else {
                    format!(
                        "known for \"{}\": {}",
                        self.name,
                        self.params
                            .iter()
                            .map(|p| p.name)
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                };
                return Err(ParamError {
                    key: key.clone(),
                    problem: format!("unknown parameter; {known}"),
                });
            };
            spec.check(value)?;
            values.insert(key.clone(), value.clone());
        }
        for spec in &self.params {
            values
                .entry(spec.name)
                .or_insert_with(|| spec.default.clone());
        }
        Ok((self.make)(&Values(values)))
    }

    /// The law with every parameter at its default.
    pub fn default_law(&self) -> Box<dyn FrictionLaw> {
        self.build(&Map::new())
            .expect("the defaults are valid for every law")
    }
}

/// The law called `name` in the [`catalog`], if there is one.
pub fn law_entry(name: &str) -> Option<LawEntry> {
    catalog().into_iter().find(|e| e.name == name)
}

const CM_HEIGHT: &str = "height of the centre of mass above the floor";
const PUSH_HEIGHT: &str = "height of the pusher above the floor";
const PLATE: &str = "plate thickness, for the tilt inertia I_cm/2 + m t²/12";
const GRAVITY: &str = "gravity; the weight m g the feet share";
const SLIP: &str = "slip speed v_s of the regularisation";

fn slip_speed() -> ParamSpec {
    ParamSpec::number("slip_speed", DEFAULT_SLIP_SPEED, "m/s", SLIP).positive()
}

fn gravity(default: f64) -> ParamSpec {
    ParamSpec::number("gravity", default, "m/s²", GRAVITY).positive()
}

fn physx(friction: FrictionType, v: &Values) -> Box<dyn FrictionLaw> {
    Box::new(PhysxClamp {
        friction,
        contacts: if v.text("contacts") == "separate" {
            FootContacts::Separate
        } else {
            FootContacts::Welded
        },
        plate_thickness: v.num("plate_thickness"),
        gravity: v.num("gravity"),
    })
}

fn physx_params() -> Vec<ParamSpec> {
    let d = PhysxClamp::new(FrictionType::Patch);
    vec![
        ParamSpec::choice(
            "contacts",
            &["welded", "separate"],
            "welded: every foot in one patch (PhysX's default); separate: a patch per foot",
        ),
        ParamSpec::number("plate_thickness", d.plate_thickness, "m", PLATE),
        gravity(d.gravity),
    ]
}

fn rapier3d_scene(v: &Values, compound_feet: bool) -> SceneParams {
    SceneParams {
        cm_height: v.num("cm_height"),
        push_height: v.num("push_height"),
        plate_thickness: v.num("plate_thickness"),
        gravity: v.num("gravity"),
        compound_feet,
    }
}

fn rapier3d_params() -> Vec<ParamSpec> {
    let d = SceneParams::default();
    vec![
        ParamSpec::number("cm_height", d.cm_height, "m", CM_HEIGHT),
        ParamSpec::number("push_height", d.push_height, "m", PUSH_HEIGHT),
        ParamSpec::number("plate_thickness", d.plate_thickness, "m", PLATE),
        gravity(d.gravity),
    ]
}

/// Every law, in a fixed order: Coulomb, the 2-D idioms, then the engines'
/// laws engine by engine.
pub fn catalog() -> Vec<LawEntry> {
    let mujoco = MujocoElliptic::default();
    let plate = PlateParams::default();
    vec![
        LawEntry {
            name: "coulomb",
            params: vec![],
            loads: Loads::Problem,
            about: "Coulomb friction −μN u/|u| at every support: the analytic model's own law.",
            make: |_| Box::new(COULOMB),
        },
        LawEntry {
            name: "impulse_disk",
            params: vec![],
            loads: Loads::Problem,
            about: "The friction joint of Box2D and Chipmunk at every support: the stopping impulse −K⁻¹u capped in length at μNΔt.",
            make: |_| Box::new(ImpulseDisk),
        },
        LawEntry {
            name: "impulse_box",
            params: vec![],
            loads: Loads::Problem,
            about: "The stopping impulse capped per world axis at μNΔt (joint motors, pyramid friction): depends on the object's angle, mean ω over a turn.",
            make: |_| Box::new(ImpulseBox),
        },
        LawEntry {
            name: "impulse_rows_disk",
            params: vec![],
            loads: Loads::Problem,
            about: "Bullet's contact friction: two world-axis rows per support, each with its own effective mass, the pair scaled back onto the disc μNΔt.",
            make: |_| Box::new(RowsDisk),
        },
        LawEntry {
            name: "regularised_linear",
            params: vec![slip_speed()],
            loads: Loads::Problem,
            about: "Coulomb made viscous below the slip speed: −μN u/v_s for |u| < v_s.",
            make: |v| {
                Box::new(RegularisedLinear {
                    slip_speed: v.num("slip_speed"),
                })
            },
        },
        LawEntry {
            name: "regularised_tanh",
            params: vec![slip_speed()],
            loads: Loads::Problem,
            about: "Coulomb smoothed everywhere: −μN tanh(|u|/v_s) u/|u|.",
            make: |v| {
                Box::new(RegularisedTanh {
                    slip_speed: v.num("slip_speed"),
                })
            },
        },
        LawEntry {
            name: "rapier3d_contact_disk",
            params: {
                let mut p = rapier3d_params();
                p.push(ParamSpec::choice(
                    "feet",
                    &["compound", "separate"],
                    "compound: all feet one collider (at most 4 points, one μ); separate: one each",
                ));
                p
            },
            loads: Loads::Law,
            about: "rapier3d's per-contact friction: each foot's force along −K⁻¹u capped at μN, the feet's loads shared as springs ∝ effective mass and moved by the tilting balance.",
            make: |v| {
                let compound = v.text("feet") == "compound";
                Box::new(Rapier3dTilt::contact_disk(rapier3d_scene(v, compound)))
            },
        },
        LawEntry {
            name: "rapier3d_simplified_twist",
            params: rapier3d_params(),
            loads: Loads::Law,
            about: "rapier3d's Simplified friction on one manifold: one disc μΣN at the feet's mean plus a twist limit μΣN|p−c|, loads from the tilting balance.",
            make: |v| Box::new(Rapier3dTilt::simplified_twist(rapier3d_scene(v, true))),
        },
        LawEntry {
            name: "mujoco_elliptic",
            params: vec![
                ParamSpec::number("cm_height", mujoco.cm_height, "m", CM_HEIGHT),
                ParamSpec::number("push_height", mujoco.push_height, "m", PUSH_HEIGHT),
                gravity(mujoco.gravity),
            ],
            loads: Loads::Law,
            about: "MuJoCo's elliptic cone: Coulomb at every foot calibrated at rest, the loads split least-norm and moved by the tilting balance when the centre of mass or the pusher is raised.",
            make: |v| {
                Box::new(MujocoElliptic {
                    cm_height: v.num("cm_height"),
                    push_height: v.num("push_height"),
                    gravity: v.num("gravity"),
                })
            },
        },
        LawEntry {
            name: "physx_patch",
            params: physx_params(),
            loads: Loads::Law,
            about: "PhysX's ePATCH friction: t0/t1 rows clamped on their own (a box, not a disc) at two anchors of the welded patch, each capped at half μΣN; loads of the PGS split at rest.",
            make: |v| physx(FrictionType::Patch, v),
        },
        LawEntry {
            name: "physx_two_directional",
            params: physx_params(),
            loads: Loads::Law,
            about: "PhysX's eTWO_DIRECTIONAL friction: at every foot a row along the centre of mass's velocity and one across it, each clamped at μN; loads of the PGS split at rest.",
            make: |v| physx(FrictionType::TwoDirectional, v),
        },
        LawEntry {
            name: "physx_one_directional",
            params: physx_params(),
            loads: Loads::Law,
            about: "PhysX's eONE_DIRECTIONAL friction: one clamped row per foot, along and across the centre of mass's velocity by turns on a welded patch, along it on separate feet.",
            make: |v| physx(FrictionType::OneDirectional, v),
        },
        LawEntry {
            name: "box2d_motor_joint",
            params: vec![],
            loads: Loads::Problem,
            about: "Box2D's top-down idiom: a motor joint to the ground whose force is capped at ΣμN and torque at ΣμN|p_i|, each on its own.",
            make: |_| Box::new(Box2dMotorJoint),
        },
        LawEntry {
            name: "avian3d_tilt",
            params: vec![
                ParamSpec::number("cm_height", plate.cm_height, "m", CM_HEIGHT),
                ParamSpec::number("plate_thickness", plate.plate_thickness, "m", PLATE),
                gravity(plate.gravity),
            ],
            loads: Loads::Law,
            about: "avian3d's contact friction: Coulomb along −u at every foot with its soft contacts' loads, moved by the couple −h_cm Σf when the centre of mass is raised.",
            make: |v| {
                Box::new(Avian3dTilt {
                    plate: PlateParams {
                        cm_height: v.num("cm_height"),
                        plate_thickness: v.num("plate_thickness"),
                        gravity: v.num("gravity"),
                    },
                })
            },
        },
        LawEntry {
            name: "jolt_box",
            params: vec![],
            loads: Loads::Problem,
            about: "Jolt on one box collider: one friction disc μΣN at the corners' unweighted mean with world-axis rows, plus a twist row clamped to μΣ d_i N_i.",
            make: |_| Box::new(JoltBox),
        },
        LawEntry {
            name: "jolt_feet",
            params: vec![],
            loads: Loads::Problem,
            about: "Jolt on sphere feet: a disc μN per foot along the effective-mass direction of world-axis rows (yaw-dependent, no twist row); the mean ω over the segment's last fifth.",
            make: |_| Box::new(JoltFeet),
        },
        LawEntry {
            name: "drake_sap",
            params: drake_params(Approximation::Sap),
            loads: Loads::Law,
            about: "Drake's SAP on sphere feet: Coulomb at every foot with the loads of the convex relaxation's lift (N = k(x + (δt+τ_d)(μ|v_t| − v_n))): a glide plane's twist while every foot penetrates, else hops and the statics' loads.",
            make: |v| drake(Approximation::Sap, v),
        },
        LawEntry {
            name: "drake_similar",
            params: drake_params(Approximation::Similar),
            loads: Loads::Law,
            about: "Drake's Similar on sphere feet: Coulomb at every foot with the loads of Hunt–Crossley at z = v_n − μ|v_t|: a glide plane's twist while every foot penetrates, else hops and the statics' loads.",
            make: |v| drake(Approximation::Similar, v),
        },
    ]
}

fn drake_params(a: Approximation) -> Vec<ParamSpec> {
    let d = DrakeConvex::new(a);
    let mut p = vec![ParamSpec::number(
        "penetration",
        d.penetration,
        "m",
        "rest penetration δ: each foot's stiffness is its load / δ",
    )
    .positive()];
    match a {
        Approximation::Sap => p.push(ParamSpec::number(
            "relaxation_time",
            d.relaxation_time,
            "s",
            "SAP's relaxation time τ_d (default: critical at δ = 1e-4 m, 2 sqrt(δ/g))",
        )),
        Approximation::Similar => p.push(ParamSpec::number(
            "hunt_crossley_dissipation",
            d.dissipation,
            "s/m",
            "Hunt–Crossley dissipation d (default: critical at δ = 1e-4 m, 2/sqrt(g δ))",
        )),
    }
    p.push(gravity(d.gravity));
    p
}

fn drake(a: Approximation, v: &Values) -> Box<dyn FrictionLaw> {
    let mut law = DrakeConvex::new(a);
    law.penetration = v.num("penetration");
    law.gravity = v.num("gravity");
    match a {
        Approximation::Sap => law.relaxation_time = v.num("relaxation_time"),
        Approximation::Similar => law.dissipation = v.num("hunt_crossley_dissipation"),
    }
    Box::new(law)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names are unique snake_case; every entry builds with its defaults.
    #[test]
    fn names_are_unique_and_defaults_build() {
        let c = catalog();
        for (i, e) in c.iter().enumerate() {
            assert!(
                e.name
                    .chars()
                    .all(|ch| ch.is_ascii_lowercase() || ch.is_ascii_digit() || ch == '_'),
                "{}",
                e.name
            );
            assert!(c[..i].iter().all(|o| o.name != e.name), "{}", e.name);
            e.default_law();
        }
    }

    /// An unknown key and a bad value are errors naming the key.
    #[test]
    fn bad_parameters_name_the_key() {
        let tanh = law_entry("regularised_tanh").unwrap();
        let mut p = Map::new();
        p.insert("slip".into(), Value::from(0.1));
        assert_eq!(tanh.build(&p).err().unwrap().key, "slip");
        let mut p = Map::new();
        p.insert("slip_speed".into(), Value::from(-1.0));
        let e = tanh.build(&p).err().unwrap();
        assert_eq!(e.key, "slip_speed");
        assert!(e.problem.contains("> 0"), "{e}");
        let mut p = Map::new();
        p.insert("contacts".into(), Value::from("glued"));
        let e = law_entry("physx_patch").unwrap().build(&p).err().unwrap();
        assert_eq!(e.key, "contacts");
        assert!(e.to_string().starts_with("contacts: must be one of"), "{e}");
        let mut p = Map::new();
        p.insert("x".into(), Value::from(1));
        let e = law_entry("jolt_feet").unwrap().build(&p).err().unwrap();
        assert!(e.problem.contains("takes no parameters"), "{e}");
    }

    /// The square plate (1 kg, side 0.25 m, μ = 0.5, equal loads) pushed at
    /// its corner at 0.5 m/s, φ = π/4 + 0.3: every support slides.
    fn plate_problem() -> pushval_model::Problem {
        use pushval_model::{Body, Problem, Push, Support, Switching, Vec2};
        let h = 0.125;
        let supports: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
            .iter()
            .map(|c| Support {
                position: Vec2::new(c[0], c[1]),
                friction: 0.5 * 9.81 / 4.0,
            })
            .collect();
        Problem {
            body: Body::new(1.0, 0.0625 * 2.0 / 12.0, Vec2::new(-h, -h), &supports).unwrap(),
            limits: Default::default(),
            pushes: vec![Push {
                duration: 2.0,
                speed: 0.5,
                phi: std::f64::consts::FRAC_PI_4 + 0.3,
            }],
            initial: Default::default(),
            switching: Switching::Impulsive,
            sample_dt: 0.01,
            release: None,
        }
    }

    /// Parameters reach the law: with the slip speed far below every
    /// support's slip (≳ 0.1 m/s here) the regularised laws are Coulomb's
    /// (the limit v_s → 0); with v_s = 1 m/s, above every slip, the force is
    /// well below μN at every support and ω is not Coulomb's.
    #[test]
    fn parameters_reach_the_law() {
        let p = plate_problem();
        let star = crate::coulomb_steady(&p, 0).unwrap();
        for name in ["regularised_linear", "regularised_tanh"] {
            let e = law_entry(name).unwrap();
            let omega = |v_s: f64| {
                let mut m = Map::new();
                m.insert("slip_speed".into(), Value::from(v_s));
                e.build(&m).unwrap().steady(&p, 0, 1e-3).unwrap().omega
            };
            let (sharp, soft) = (omega(1e-9), omega(1.0));
            assert!((sharp - star).abs() < 1e-8, "{name}: {sharp} vs {star}");
            assert!(
                (soft - star).abs() > 1e-3 * star.abs(),
                "{name}: {soft} vs {star}"
            );
        }
    }

    /// A law fed back its own predicted loads gives its own steady ω: the
    /// run's-loads evaluation and the law's load prediction meet at the
    /// law's fixed point. Checked on the plate with its centre of mass
    /// raised (the loads move) for every law whose loads are its own.
    #[test]
    fn a_law_on_its_own_loads_is_itself() {
        let p = plate_problem();
        let mut checked = 0;
        for e in catalog() {
            let mut params = Map::new();
            if e.params.iter().any(|s| s.name == "cm_height") {
                params.insert("cm_height".into(), Value::from(0.02));
            }
            let law = e.build(&params).unwrap();
            let (Some(own), Some(loads)) = (law.steady(&p, 0, 1e-3), law.loads(&p, 0, 1e-3)) else {
                continue;
            };
            let Some(fed) = law.steady_on_loads(&p, 0, 1e-3, &loads) else {
                panic!("{}: no steady state on its own loads {loads:?}", e.name);
            };
            assert!(
                (fed.omega - own.omega).abs() <= 1e-6 * own.omega.abs().max(1e-3),
                "{}: {} on its own loads vs {}",
                e.name,
                fed.omega,
                own.omega
            );
            checked += 1;
        }
        assert!(checked >= 5, "only {checked} laws predict loads");
    }

    /// The plate's own statics (m g / 4 a foot) as a run's loads change
    /// nothing; moving load onto the two feet nearest the pusher changes
    /// Coulomb's ω, and a load list of the wrong length is refused.
    #[test]
    fn coulomb_on_loads() {
        let p = plate_problem();
        let rest = vec![9.81 / 4.0; 4];
        let a = crate::COULOMB.steady(&p, 0, 1e-3).unwrap().omega;
        let b = crate::COULOMB
            .steady_on_loads(&p, 0, 1e-3, &rest)
            .unwrap()
            .omega;
        assert!((a - b).abs() < 1e-12 * a.abs(), "{a} vs {b}");
        // The pushed corner (−h, −h) and its neighbours carry more: the
        // friction moment about the contact shrinks, the plate turns faster.
        let moved = [3.0, 2.5, 1.905, 2.405];
        let c = crate::COULOMB
            .steady_on_loads(&p, 0, 1e-3, &moved)
            .unwrap()
            .omega;
        assert!(c.abs() > a.abs(), "{c} vs {a}");
        assert!(crate::COULOMB
            .steady_on_loads(&p, 0, 1e-3, &rest[..3])
            .is_none());
        assert!(crate::on_loads(&p, &[1.0, -1.0, 1.0, 1.0]).is_none());
    }

    /// A law with dynamics on a run's loads settles, from rest, where its
    /// steady state on those loads lies: the transient the study integrates
    /// and the steady ω it compares are one law. Checked on loads moved onto
    /// the pushed side for every catalogue law that has dynamics; Coulomb
    /// and the laws that are Coulomb on a run's loads must have them.
    #[test]
    fn a_laws_dynamics_settle_at_its_steady_state() {
        let p = plate_problem();
        let moved = [3.0, 2.5, 1.905, 2.405];
        let mut with = vec![];
        for e in catalog() {
            let law = e.default_law();
            let Some(seg) = law.dynamics_on_loads(&p, 0, 1e-3, &moved) else {
                continue;
            };
            let steady = law.steady_on_loads(&p, 0, 1e-3, &moved).unwrap().omega;
            let settled = seg.advance(0.0, 5.0).unwrap();
            assert!(
                (settled - steady).abs() < 1e-9 * steady.abs().max(1e-3),
                "{}: settles at {settled}, steady {steady}",
                e.name
            );
            with.push(e.name);
        }
        for name in [
            "coulomb",
            "mujoco_elliptic",
            "avian3d_tilt",
            "drake_sap",
            "drake_similar",
        ] {
            assert!(with.contains(&name), "{name} has no dynamics: {with:?}");
        }
    }

    /// The per-axis laws, as the catalogue builds them, repeat every quarter
    /// turn of the square plate (world-axis rows on a body symmetric under a
    /// quarter turn); the isotropic ones do not depend on the angle.
    #[test]
    fn per_axis_laws_declare_their_period() {
        let p = plate_problem();
        for (name, period) in [
            ("impulse_box", Some(std::f64::consts::FRAC_PI_2)),
            ("impulse_rows_disk", Some(std::f64::consts::FRAC_PI_2)),
            ("impulse_disk", None),
            ("coulomb", None),
            ("regularised_tanh", None),
        ] {
            let law = law_entry(name).unwrap().default_law();
            assert_eq!(law.angle_period(&p), period, "{name}");
        }
    }
}
