//! An engine's own friction law in closed form: what steady ω it predicts
//! for a push, and whether the law turns the object, locks its orientation
//! or holds it only from one side.
//!
//! An engine whose friction is not Coulomb's at every support (a capped
//! joint, per-axis rows, a twist limit, …) declares the law it follows
//! through `pushval_engine::Engine::law`; `pushval study MODEL` compares the
//! engine with it and with Coulomb. An engine that applies Coulomb's law
//! returns [`COULOMB`], an engine with no closed form returns `None`.

use pushval_model::{Body, Problem, SegmentDynamics, Support};

/// What ω = 0 is under a law, for a run that starts there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LawClass {
    /// The object turns: the law's steady ω is an ordinary root.
    Turns,
    /// The law holds ω = 0 from both sides (the orientation locks).
    Locked,
    /// ω = 0 holds from one side only: sticking friction can balance the
    /// moment at rest (`|moment| ≤ hold`) but does not pull ω back to 0 from
    /// the side the moment points to (`|moment| > lock`). Which a run shows
    /// depends on the solver's disturbances, not on the law.
    SemiStable {
        /// The sliding rows' moment about the contact at ω = 0, M₀ (N m).
        moment: f64,
        /// The largest |M₀| that locks from both sides, H (N m).
        lock: f64,
        /// The largest |M₀| sticking rows can hold at rest, S ≥ H (N m).
        hold: f64,
    },
}

impl LawClass {
    /// `"turns"`, `"locked"` or `"semi_stable"` (the `class` column of a
    /// study's `map.csv`).
    pub fn as_str(&self) -> &'static str {
        match self {
            LawClass::Turns => "turns",
            LawClass::Locked => "locked",
            LawClass::SemiStable { .. } => "semi_stable",
        }
    }

    /// The class named by [`LawClass::as_str`] (rest moments unknown: NaN).
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "turns" => Some(LawClass::Turns),
            "locked" => Some(LawClass::Locked),
            "semi_stable" => Some(LawClass::SemiStable {
                moment: f64::NAN,
                lock: f64::NAN,
                hold: f64::NAN,
            }),
            _ => None,
        }
    }
}

/// A law's steady state for one push segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawSteady {
    /// The steady ω the law predicts for a run that starts the segment at
    /// ω = 0 (rad/s); 0 where it locks or holds. For a law that depends on
    /// the object's angle, the mean ω over a turn.
    pub omega: f64,
    /// What ω = 0 is under the law.
    pub class: LawClass,
}

/// An engine's friction law in closed form (no engine needed to evaluate).
pub trait FrictionLaw: Send + Sync {
    /// One line naming the law and where its closed form lives, e.g.
    /// `"motor joint: force and torque capped apart (pushval_box2d::predict)"`.
    fn law_name(&self) -> &'static str;
    /// The law's entry in the [`crate::catalog`], for laws whose
    /// [`FrictionLaw::law_name`] another entry's law shares (the regularised
    /// idioms); None (the default): the name alone tells the entry.
    fn catalog_name(&self) -> Option<&'static str> {
        None
    }
    /// The steady state of segment `segment` of `problem` under the law, for
    /// a run at time step `dt` (s; laws whose caps scale with the step read
    /// it), or None where the law has no steady state there.
    fn steady(&self, problem: &Problem, segment: usize, dt: f64) -> Option<LawSteady>;
    /// The normal load of each support (N, in the problem's support order)
    /// the law predicts in the steady state of segment `segment`, for laws
    /// under which the push moves load between the supports (a raised
    /// centre of mass or pusher, sticking rows that hold a rest moment).
    /// None by default: the problem's own loads.
    fn loads(&self, _problem: &Problem, _segment: usize, _dt: f64) -> Option<Vec<f64>> {
        None
    }
    /// The angle (rad) over which the law repeats as the object turns, for a
    /// law that depends on the object's angle and whose steady ω is the mean
    /// over a turn: a run compares with it over a whole number of these
    /// periods. None (the default) for laws that do not depend on the angle.
    fn angle_period(&self, _problem: &Problem) -> Option<f64> {
        None
    }
    /// Whether the law's friction is Coulomb's once the supports carry a
    /// run's own loads (its departures from Coulomb are all in how it
    /// predicts the loads: MuJoCo's and avian3d's load transfer, Drake's
    /// lift). Such a law is judged on a run's loads as Coulomb on them, with
    /// Coulomb's dynamics; false by default.
    fn coulomb_on_run_loads(&self) -> bool {
        false
    }
    /// The steady state of segment `segment` with the supports carrying
    /// `loads` (N, the problem's support order) instead of the problem's
    /// statics: the law's friction rule fed a run's own loads. The default
    /// is Coulomb on [`on_loads`] for a law that is Coulomb on a run's loads
    /// ([`FrictionLaw::coulomb_on_run_loads`]), else [`FrictionLaw::steady`]
    /// on [`on_loads`], which suits laws that take their loads from the
    /// problem. A law with another rule at given loads overrides it or
    /// returns None.
    fn steady_on_loads(
        &self,
        problem: &Problem,
        segment: usize,
        dt: f64,
        loads: &[f64],
    ) -> Option<LawSteady> {
        let p = on_loads(problem, loads)?;
        if self.coulomb_on_run_loads() {
            COULOMB.steady(&p, segment, dt)
        } else {
            self.steady(&p, segment, dt)
        }
    }
    /// The law's own ω dynamics for segment `segment` with the supports
    /// carrying `loads` (N), for a law that is Coulomb on a run's loads
    /// ([`FrictionLaw::coulomb_on_run_loads`]): the analytic model's segment
    /// on them. A study integrates it between a run's samples
    /// ([`SegmentDynamics::advance`]), so loads that change faster than the
    /// law settles (a hopping plate) are judged with the law's transient.
    /// None for any other law: it has steady states only and is taken
    /// quasi-statically.
    fn dynamics_on_loads(
        &self,
        problem: &Problem,
        segment: usize,
        _dt: f64,
        loads: &[f64],
    ) -> Option<SegmentDynamics> {
        if !self.coulomb_on_run_loads() {
            return None;
        }
        let push = problem.pushes.get(segment)?;
        Some(SegmentDynamics::new(&on_loads(problem, loads)?.body, push))
    }
}

/// Gravity (m/s²) of every engine scene pushval builds, and so the weight
/// `m g` whose statics give a problem's rest loads.
pub const GRAVITY: f64 = 9.81;

/// Whether `loads` (N) are one finite, non-negative number for each of `n`
/// supports: what a law evaluated on a run's loads accepts.
pub(crate) fn usable_loads(loads: &[f64], n: usize) -> bool {
    loads.len() == n && loads.iter().all(|l| l.is_finite() && *l >= 0.0)
}

/// `problem` with its supports carrying `loads` (N) instead of their rest
/// loads: each support's friction `μ_i N_i` is scaled by `N_i / N_i^rest`,
/// the rest loads being the statics of the weight `m g`
/// ([`crate::mujoco::rest_loads`], the split every engine scene is
/// calibrated with), so each support keeps its μ. None where the loads are
/// not one finite, non-negative number per support or a support with
/// friction has no load at rest.
pub fn on_loads(problem: &Problem, loads: &[f64]) -> Option<Problem> {
    let body = &problem.body;
    if !usable_loads(loads, body.len()) {
        return None;
    }
    let rest = crate::mujoco::rest_loads(body, body.mass() * GRAVITY)?;
    let mut supports = Vec::with_capacity(body.len());
    for ((s, &n), &r) in body.supports().zip(loads).zip(&rest) {
        let friction = if s.friction == 0.0 {
            0.0
        } else if r > 0.0 {
            s.friction * n / r
        } else {
            return None;
        };
        supports.push(Support {
            position: s.position,
            friction,
        });
    }
    // A support may carry no load; the body needs some friction somewhere.
    if supports.iter().all(|s| s.friction == 0.0) {
        return None;
    }
    let body = Body::new(body.mass(), body.inertia_cm(), body.contact(), &supports).ok()?;
    Some(Problem {
        body,
        ..problem.clone()
    })
}

/// Coulomb friction at every support: the analytic model's own law.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Coulomb;

/// The law of an engine that applies Coulomb friction at every support.
pub const COULOMB: Coulomb = Coulomb;

impl FrictionLaw for Coulomb {
    fn law_name(&self) -> &'static str {
        "Coulomb at every support (the analytic model, pushval_model::SegmentDynamics)"
    }
    fn steady(&self, problem: &Problem, segment: usize, _dt: f64) -> Option<LawSteady> {
        coulomb_steady(problem, segment).map(|omega| LawSteady {
            omega,
            class: if omega == 0.0 {
                LawClass::Locked
            } else {
                LawClass::Turns
            },
        })
    }
    fn coulomb_on_run_loads(&self) -> bool {
        true
    }
}

/// The Coulomb model's steady ω (rad/s) of segment `segment`: the stable
/// root the flow reaches from ω = 0. None where there is none.
pub fn coulomb_steady(problem: &Problem, segment: usize) -> Option<f64> {
    let push = problem.pushes.get(segment)?;
    let seg = SegmentDynamics::new(&problem.body, push);
    let roots = seg.steady_states();
    seg.attractor(&roots, 0.0).map(|s| s.omega)
}
