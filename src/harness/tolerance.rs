//! The gate's tolerances: the scenario's numbers where it gives them, and
//! otherwise (`"auto"`, the default) derived from the gated engine's own
//! accuracy: [`AUTO_FACTOR`] times its self-convergence estimate at the
//! chosen time step (Richardson from the dt ladder), never below
//! [`AUTO_TARGET`], plus the dynamic model's own error; and the check of
//! the engine's declared order against the one its trajectory shows
//! ([`check_order`]), which decides the order that estimate is made at.

use pushval_model::{DynamicModel, Integrator, Problem, Simulator, Trajectory};
use pushval_scenario::{Limit, Scenario};

use super::dt::{Convergence, DtEstimate, DtSource, StopFloor, TrajectoryOrder};
use super::figures::limits;
pub use super::figures::{ladder_targets, Figures, AUTO_TARGET};
use super::rest::{rest_of, stop_estimate};

/// An `"auto"` tolerance is this multiple of the engine's self-convergence
/// estimate (itself not trusted below [`AUTO_TARGET`]): the estimate assumes
/// the asymptotic order, and at the rungs the ladder stops at the observed
/// order can be off by a few tenths, the estimate by a factor of 2 or so.
pub const AUTO_FACTOR: f64 = 4.0;

/// Where a resolved tolerance came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The scenario's `[tolerance]` number.
    Scenario,
    /// Derived from the engine's accuracy (`"auto"` or absent).
    Auto,
}

impl Source {
    /// `"scenario"` or `"auto"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Source::Scenario => "scenario",
            Source::Auto => "auto",
        }
    }
}

/// A gated engine's tolerances, with where each came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolved {
    /// The tolerances the gate asserts.
    pub value: Figures,
    /// Per figure (position, theta, omega): scenario number or auto.
    pub source: [Source; 3],
    /// The engine's self-convergence estimate at its step (None: not measured).
    pub engine_estimate: Option<Figures>,
    /// The dynamic model's own error estimate.
    pub model_error: Figures,
    /// The ceiling no auto figure may pass (`[tolerance] auto_ceiling`).
    pub ceiling: Figures,
    /// Why the gate cannot stand on its auto tolerances (the engine's
    /// accuracy at its dt misses the ceiling, or its observed order strays
    /// from the declared one): each a sentence; any makes the row FAIL.
    pub problems: Vec<String>,
    /// The smallest relative errors in I_cm and in every μ the tolerances
    /// would catch (linear estimate from the model's sensitivities); None
    /// until [`super::catchable`] fills it.
    pub catches: Option<Catches>,
    /// The gated engine's time step (s), where it came from and whether the
    /// ladder's estimate met its targets there; None outside `validate`.
    pub dt: Option<(f64, DtSource, bool)>,
    /// The order the engine declares, the order its trajectory shows over
    /// the ladder (None: not observed) and the order the self-convergence
    /// estimate used ([`check_order`]); None outside `validate`.
    pub order: Option<OrderCheck>,
    /// What the row must say without failing: the order not observed, the
    /// ladder that missed its target and what that means for the verdict.
    pub notes: Vec<String>,
    /// With a `[release]`: the stop time's tolerance (always auto).
    pub stop_time: Option<StopTolerance>,
}

impl Resolved {
    /// The record written beside the model's figures in summary.json.
    pub fn json(&self) -> serde_json::Value {
        use crate::outdir::json_num as num;
        let f = |x: &Figures| {
            serde_json::json!({
                "position_max": num(x.position_max),
                "theta_max": num(x.theta_max),
                "omega_steady_rel": num(x.omega_steady_rel),
            })
        };
        serde_json::json!({
            "position_max": num(self.value.position_max),
            "theta_max": num(self.value.theta_max),
            "omega_steady_rel": num(self.value.omega_steady_rel),
            "source": {
                "position_max": self.source[0].as_str(),
                "theta_max": self.source[1].as_str(),
                "omega_steady_rel": self.source[2].as_str(),
            },
            "rule": format!("auto = {AUTO_FACTOR} x max(engine self-convergence estimate at its dt, target) + model error; never above auto_ceiling (the row fails instead)"),
            "engine_estimate": self.engine_estimate.as_ref().map_or(serde_json::Value::Null, f),
            "model_error": f(&self.model_error),
            "auto_ceiling": f(&self.ceiling),
            "problems": self.problems,
            "catches": self.catches.as_ref().map_or(serde_json::Value::Null, |c| c.json()),
            "dt": self.dt.map_or(serde_json::Value::Null, |d| num(d.0)),
            "dt_source": self.dt.map_or(serde_json::Value::Null, |d| d.1.as_str().into()),
            "ladder_met": self.dt.map(|d| d.2),
            "declared_order": self.order.as_ref().map(|o| o.declared),
            "observed_order": self.order.as_ref().and_then(|o| o.observed).map(num),
            "observed_order_on": self.order.as_ref().map(|o| o.on.clone()),
            "estimate_order": self.order.as_ref().map(|o| o.estimate_order),
            "notes": self.notes,
            "stop_time": self.stop_time.as_ref().map_or(serde_json::Value::Null, |t| t.json()),
        })
    }
}

/// The smallest model errors a gated row's tolerances would catch, from
/// the model's sensitivities: each error is injected at ±[`CATCH_PROBE`]
/// (relative) into the dynamic model ([`crate::inject::inject`]), each gated
/// figure's change divided by the probe is its sensitivity `|∂X/∂p|`, and
/// `tolerance / |∂X/∂p|` is the error that moves that figure past its
/// tolerance. Any figure failing fails the row, so the most sensitive
/// figure decides. Linear: `pushval power` bisects the same question with
/// the engine in the loop (results/gate_power.csv, column
/// `linear_estimate`, compares the two).
#[derive(Debug, Clone, PartialEq)]
pub struct Catches {
    /// Smallest relative error in I_cm caught, and the figure that catches
    /// it; None where no figure sees I_cm.
    pub inertia_cm: Option<(f64, &'static str)>,
    /// The same for every support's μ scaled together.
    pub mu_all: Option<(f64, &'static str)>,
}

/// The relative probe of [`Catches`]: small enough to stay linear (the
/// figures are smooth in the parameters except at a switch of sticking),
/// large enough to sit far above the model's own error (about 1e-10 m).
pub const CATCH_PROBE: f64 = 1e-4;

impl Catches {
    /// The record in summary.json.
    pub fn json(&self) -> serde_json::Value {
        let one = |c: &Option<(f64, &str)>| match c {
            Some((m, by)) => {
                serde_json::json!({"relative": crate::outdir::json_num(*m), "figure": by})
            }
            None => serde_json::Value::Null,
        };
        serde_json::json!({
            "method": format!("linear: tolerance / |dX/dp| per gated figure, the smallest deciding; probe ±{CATCH_PROBE} relative"),
            "inertia_cm": one(&self.inertia_cm),
            "mu_all": one(&self.mu_all),
        })
    }
}

/// The tolerances the gate asserts for an engine whose self-convergence
/// estimate at its step is `estimate` (None: not measured, then an auto
/// figure takes `AUTO_FACTOR × AUTO_TARGET`).
pub fn resolve(sc: &Scenario, estimate: Option<&DtEstimate>, model_error: Figures) -> Resolved {
    let l = limits(sc);
    let est = estimate.map(|e| Figures {
        position_max: e.position_max,
        theta_max: e.theta_max,
        omega_steady_rel: e.omega_steady_rel_max.unwrap_or(0.0),
    });
    let c = sc.tolerance.auto_ceiling;
    let ceiling = Figures {
        position_max: c[0],
        theta_max: c[1],
        omega_steady_rel: c[2],
    };
    let auto = |e: Option<f64>, target: f64, model: f64| {
        AUTO_FACTOR * e.unwrap_or(target).max(target) + model
    };
    let mut problems = Vec::new();
    let dt = estimate.map_or(String::new(), |e| format!(" at dt = {:.4e} s", e.dt));
    let mut pick = |l: Limit,
                    e: Option<f64>,
                    target: f64,
                    model: f64,
                    cap: f64,
                    key: &str,
                    unit: &str| {
        match l {
            Limit::Value(v) => (v, Source::Scenario),
            Limit::Auto => {
                let a = auto(e, target, model);
                if a > cap {
                    problems.push(format!(
                            "the engine cannot back an auto {key}{dt}: {AUTO_FACTOR} x its self-convergence estimate {:.2e} {unit} + model error {model:.2e} = {a:.2e} {unit} is above the auto ceiling {cap:.2e} {unit}; set a finer [engine] dt, or write the number the gate should assert as [tolerance] {key}",
                            e.unwrap_or(target)
                        ));
                    (cap, Source::Auto)
                } else {
                    (a, Source::Auto)
                }
            }
        }
    };
    let (p, sp) = pick(
        l[0],
        est.map(|e| e.position_max),
        AUTO_TARGET.position_max,
        model_error.position_max,
        ceiling.position_max,
        "position_max",
        "m",
    );
    let (t, st) = pick(
        l[1],
        est.map(|e| e.theta_max),
        AUTO_TARGET.theta_max,
        model_error.theta_max,
        ceiling.theta_max,
        "theta_max",
        "rad",
    );
    let (w, sw) = pick(
        l[2],
        est.map(|e| e.omega_steady_rel),
        AUTO_TARGET.omega_steady_rel,
        model_error.omega_steady_rel,
        ceiling.omega_steady_rel,
        "omega_steady_rel",
        "(relative)",
    );
    Resolved {
        value: Figures {
            position_max: p,
            theta_max: t,
            omega_steady_rel: w,
        },
        source: [sp, st, sw],
        engine_estimate: est,
        model_error,
        ceiling,
        problems,
        catches: None,
        dt: None,
        order: None,
        notes: Vec::new(),
        stop_time: None,
    }
}

/// The order the self-convergence estimate falls back on where the
/// trajectory shows none: Richardson divides `|X(2h) − X(h)|` by `2^p − 1`,
/// 1 at first order, the largest estimate any convergent scheme gets.
pub const SAFE_ORDER: f64 = 1.0;

/// The declared order against the one the ladder's runs show on the
/// trajectory ([`super::TrajectoryOrder`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OrderCheck {
    /// What the engine declares (`order` in its table, or its registry row).
    pub declared: f64,
    /// The lower of position's and angle's observed orders; None when no
    /// triple of runs resolves either (every difference below the targets).
    pub observed: Option<f64>,
    /// Which figures and steps gave it (empty when not observed).
    pub on: String,
    /// The order the estimate behind the step and the auto tolerances uses:
    /// the declared one, or [`SAFE_ORDER`] when nothing is observed and the
    /// declared order is higher.
    pub estimate_order: f64,
    /// Set when the observed order is below the declared one by more than
    /// [`ORDER_BAND`]: the sentence that fails the row, naming both.
    pub problem: Option<String>,
    /// Set when no order is observed: the sentence the row carries.
    pub note: Option<String>,
}

/// Checks the declared order against the trajectory's. Only an observed
/// order below the declared one fails: the estimate then understates the
/// engine's error by `(2^declared − 1) / (2^observed − 1)`; one above it
/// only overstates the error, and the gate stays sound.
pub fn check_order(declared: f64, observed: &TrajectoryOrder) -> OrderCheck {
    let on = observed.describe();
    match observed.observed() {
        Some(p) if p < declared - ORDER_BAND => {
            let understated = (2f64.powf(declared) - 1.0) / (2f64.powf(p.max(0.01)) - 1.0);
            OrderCheck {
                declared,
                observed: Some(p),
                problem: Some(format!(
                    "the engine declares order {declared} in dt but its trajectory shows order {p:.2} ({on}), lower by more than {ORDER_BAND}: the self-convergence estimate behind its step and tolerances understates its error about {understated:.1}x; declare order = {} in its table (pushval.toml) or fix its step",
                    p.round().max(1.0)
                )),
                on,
                estimate_order: declared,
                note: None,
            }
        }
        Some(p) => OrderCheck {
            declared,
            observed: Some(p),
            on,
            estimate_order: declared,
            problem: None,
            note: None,
        },
        None => {
            let estimate_order = declared.min(SAFE_ORDER);
            OrderCheck {
                declared,
                observed: None,
                on,
                estimate_order,
                problem: None,
                note: Some(format!(
                    "order not observed: the runs at successive steps differ by less than the ladder's targets, so the trajectory cannot confirm the declared order {declared}; the error estimate uses order {estimate_order}"
                )),
            }
        }
    }
}

/// The estimate `e` (made at order `from`) as order `to` would make it.
pub fn reorder(e: &DtEstimate, from: f64, to: f64) -> DtEstimate {
    let k = (2f64.powf(from) - 1.0) / (2f64.powf(to) - 1.0);
    DtEstimate {
        position_max: k * e.position_max,
        theta_max: k * e.theta_max,
        omega_steady_rel_max: e.omega_steady_rel_max.map(|w| k * w),
        ..*e
    }
}

/// What a ladder that missed its target means for the verdict: the
/// engine's own error at the step it ran is above what the gate meant to
/// allow, so the gate sees less than it should. None when it met it.
pub fn ladder_note(res: &Resolved, met: bool, targets: &Figures) -> Option<String> {
    if met {
        return None;
    }
    let e = res.engine_estimate.as_ref()?;
    let dt = res
        .dt
        .map_or(String::new(), |d| format!(" at dt {:.3e} s", d.0));
    Some(format!(
        "ladder missed its target: the engine's own error{dt} is estimated at {:.2e} m, {:.2e} rad (targets {:.2e} m, {:.2e} rad), so the comparison carries that error: a PASS bounds the model's error only to within it, and a FAIL by less than it may be the engine's own; a finer [engine] dt or a higher-order step removes the doubt",
        e.position_max, e.theta_max, targets.position_max, targets.theta_max
    ))
}

/// How far an engine's observed order in dt may stray from the order it
/// declares before its auto tolerances are refused: the Richardson estimate
/// behind them divides by `2^p − 1` with the declared p, so an engine
/// converging at p − 0.5 has its error underestimated by up to 40 % per
/// halving, and one not converging at all not estimated.
pub const ORDER_BAND: f64 = 0.5;

/// The sentence that refuses auto tolerances when the observed order
/// (median over the settled segments whose `|ω(2h) − ω(h)|` is at least
/// the auto target, runs at 4h, 2h, h) strays from the
/// declared one by more than [`ORDER_BAND`]; None when it does not, or when
/// no figure is auto, or no segment settles.
pub fn order_problem(res: &Resolved, conv: &Convergence) -> Option<String> {
    if !res.source.contains(&Source::Auto) {
        return None;
    }
    // Only segments whose ω(2h) − ω(h) is resolved: below the auto target
    // the auto tolerance sits on its floor whatever the order, and the
    // ratio of two differences at the tail mean's noise level is no order.
    let observed = conv.order_resolved(AUTO_TARGET.omega_steady_rel)?;
    let declared = conv.expected_order;
    (!((observed - declared).abs() <= ORDER_BAND)).then(|| {
        format!(
            "the engine's observed order in dt is {observed:.2} (steady omega at dt {:.3e}, {:.3e}, {:.3e} s), not the declared {declared} within {ORDER_BAND}: its self-convergence estimate cannot back an auto tolerance; write the numbers the gate should assert in [tolerance], or fix the engine's declared order",
            conv.dts[0], conv.dts[1], conv.dts[2]
        )
    })
}

/// The dynamic model's own error, bounded by its distance from a run at a
/// 100 times looser tolerance (which is the less accurate of the two).
pub fn model_error(problem: &Problem, reference: &Trajectory, model_tol: f64) -> Figures {
    let loose = DynamicModel {
        integrator: Integrator::Dop853 {
            tol: 100.0 * model_tol,
        },
        ..Default::default()
    }
    .simulate(problem);
    let Ok(loose) = loose else {
        return Figures {
            position_max: 0.0,
            theta_max: 0.0,
            omega_steady_rel: 0.0,
        };
    };
    let mut f = Figures {
        position_max: 0.0,
        theta_max: 0.0,
        omega_steady_rel: 0.0,
    };
    let pairs = super::rest::paired(&loose, reference).unwrap_or_default();
    for (a, b) in pairs {
        f.position_max = f
            .position_max
            .max(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt());
        f.theta_max = f.theta_max.max((a.theta - b.theta).abs());
    }
    let length = problem.body.contact().norm();
    for ((a, b), push) in loose
        .segments
        .iter()
        .zip(&reference.segments)
        .zip(&problem.pushes)
    {
        let e = pushval_engine::rel_err(a.omega_end, b.omega_end, push.speed, length);
        f.omega_steady_rel = f.omega_steady_rel.max(e);
    }
    f
}

/// The stop time's tolerance for a gated engine, with what it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopTolerance {
    /// The tolerance on `|t_stop(run) − t_stop(model)|` (s).
    pub value: f64,
    /// The engine's self-convergence estimate of its stop time at its
    /// step, `|t(2h) − t(h)| / (2^p − 1)` (s); infinite when one of the two
    /// runs did not stop.
    pub estimate: f64,
    /// The step h (s): the rest rule reads the stop at a step's end, so no
    /// estimate below it is trusted.
    pub resolution: f64,
    /// The dynamic model's own error in its stop time (s): its distance from
    /// a run at a 100 times looser tolerance.
    pub model_error: f64,
    /// The most the tolerance may be (s): the time in which the plate, at
    /// its speed when released, covers the position ceiling.
    pub ceiling: f64,
}

impl StopTolerance {
    /// The record in summary.json.
    pub fn json(&self) -> serde_json::Value {
        use crate::outdir::json_num as num;
        serde_json::json!({
            "value": num(self.value),
            "source": "auto",
            "rule": format!("auto = {AUTO_FACTOR} x max(engine self-convergence estimate of its stop time at its dt, dt) + model error; never above the ceiling (position ceiling / the plate's speed at the release; the row fails instead)"),
            "engine_estimate": num(self.estimate),
            "resolution": num(self.resolution),
            "model_error": num(self.model_error),
            "ceiling": num(self.ceiling),
        })
    }
}

/// The plate's speed when the pusher lets go (m/s): `|v_cm| + |ω| L`, `L`
/// the farthest support from the centre of mass (the rest rule's speed).
/// `omega` is ω at the release (the model's).
pub fn release_speed(problem: &Problem, omega: f64) -> f64 {
    let body = &problem.body;
    let v = match problem.pushes.last() {
        // The contact moves with the pusher: v_cm = v_c n_φ − ω D p_c (object frame).
        Some(p) => {
            let pc = body.contact();
            p.velocity() - omega * pushval_model::Vec2::new(-pc.y, pc.x)
        }
        None => problem.initial.velocity,
    };
    let reach = body
        .supports()
        .map(|s| s.position.norm())
        .fold(0.0, f64::max);
    v.norm() + omega.abs() * reach
}

/// The most a stop-time tolerance may be (s), with the plate's speed at
/// the release (m/s): the time in which the plate, at that speed, covers the
/// position ceiling (`[tolerance] auto_ceiling`). None when the problem has
/// no release or the model (`reference`) did not stop.
pub fn stop_ceiling(
    sc: &Scenario,
    problem: &Problem,
    reference: &Trajectory,
) -> Option<(f64, f64)> {
    problem.release?;
    rest_of(reference)?;
    let omega0 = reference
        .samples
        .iter()
        .rev()
        .find(|s| s.t <= reference.slide.as_ref().map_or(0.0, |s| s.t_release) + 1e-12)
        .map_or(problem.initial.omega, |s| s.omega);
    let speed = release_speed(problem, omega0);
    let ceiling = if speed > 0.0 {
        sc.tolerance.auto_ceiling[0] / speed
    } else {
        f64::INFINITY
    };
    Some((ceiling, speed))
}

/// What a thrown plate's stop time asks of the engine's step (the
/// automatic step's rungs are held to it, [`choose_engine_dt`]): its
/// ceiling, the model's own error in its stop time (a run at a 100 times
/// looser `model_tol`) and [`AUTO_FACTOR`]. None when the problem has no
/// release or the model did not stop.
///
/// [`choose_engine_dt`]: super::dt::choose_engine_dt
pub fn stop_floor(
    sc: &Scenario,
    problem: &Problem,
    reference: &Trajectory,
    model_tol: f64,
) -> Option<StopFloor> {
    let (ceiling, _) = stop_ceiling(sc, problem, reference)?;
    Some(StopFloor {
        ceiling,
        model_error: stop_model_error(problem, reference, model_tol),
        factor: AUTO_FACTOR,
    })
}

/// The stop time's tolerance for an engine of order `order` whose runs at
/// `h` and `2h` are `fine` and `coarse`; with the sentence that fails the
/// row when the engine's accuracy cannot back it below its ceiling. None
/// when the problem has no release or the model did not stop.
#[allow(clippy::too_many_arguments)]
pub fn stop_tolerance(
    sc: &Scenario,
    problem: &Problem,
    reference: &Trajectory,
    h: f64,
    coarse: &Trajectory,
    fine: &Trajectory,
    order: f64,
    model_error: f64,
) -> Option<(StopTolerance, Option<String>)> {
    let (ceiling, speed) = stop_ceiling(sc, problem, reference)?;
    let estimate = stop_estimate(coarse, fine, order);
    let auto = StopFloor {
        ceiling,
        model_error,
        factor: AUTO_FACTOR,
    }
    .tolerance(estimate, h);
    let problem_text = (!(auto <= ceiling)).then(|| {
        format!(
            "the engine cannot back an auto stop_time at dt = {h:.4e} s: {AUTO_FACTOR} x max(its self-convergence estimate {estimate:.2e} s, dt) + model error {model_error:.2e} s = {auto:.2e} s is above the stop-time ceiling {ceiling:.2e} s (the position ceiling {:.2e} m at the release speed {speed:.3} m/s); set a finer [engine] dt",
            sc.tolerance.auto_ceiling[0]
        )
    });
    Some((
        StopTolerance {
            value: auto.min(ceiling),
            estimate,
            resolution: h,
            model_error,
            ceiling,
        },
        problem_text,
    ))
}

/// The dynamic model's own error in its stop time (s): its distance from a
/// run at a 100 times looser tolerance; 0 when either does not stop.
pub fn stop_model_error(problem: &Problem, reference: &Trajectory, model_tol: f64) -> f64 {
    if problem.release.is_none() {
        return 0.0;
    }
    let loose = DynamicModel {
        integrator: Integrator::Dop853 {
            tol: 100.0 * model_tol,
        },
        ..Default::default()
    }
    .simulate(problem);
    match (loose.ok().as_ref().and_then(rest_of), rest_of(reference)) {
        (Some(a), Some(b)) => (a.t - b.t).abs(),
        _ => 0.0,
    }
}
