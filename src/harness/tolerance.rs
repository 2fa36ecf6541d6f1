//! The gate's tolerances: the scenario's numbers where it gives them, and
//! otherwise (`"auto"`, the default) derived from the gated engine's own
//! accuracy: [`AUTO_FACTOR`] times its self-convergence estimate at the
//! chosen time step (Richardson from the dt ladder), never below
//! [`AUTO_TARGET`], plus the dynamic model's own error.

use pushval_model::{DynamicModel, Integrator, Problem, Simulator, Trajectory};
use pushval_scenario::{Limit, Scenario};

use super::DtEstimate;

/// The three gated figures: largest centre-of-mass distance (m), largest
/// angle difference (rad), largest relative steady-ω error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Figures {
    /// m
    pub position_max: f64,
    /// rad
    pub theta_max: f64,
    /// relative
    pub omega_steady_rel: f64,
}

/// What the dt ladder aims for on an `"auto"` figure: the engine's
/// self-convergence estimate at the chosen step is at most this. Small enough
/// that model errors of a fraction of a per cent move the trajectory past the
/// resulting tolerance (results/gate_power.csv), large enough that a
/// second-order engine reaches it at 1/2000 s or so on the shipped scenes.
pub const AUTO_TARGET: Figures = Figures {
    position_max: 2e-6,
    theta_max: 2e-6,
    omega_steady_rel: 2e-6,
};

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
}

impl Resolved {
    /// The record written beside the model's figures in summary.json.
    pub fn json(&self) -> serde_json::Value {
        use crate::output::num;
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
            "rule": format!("auto = {AUTO_FACTOR} x max(engine self-convergence estimate at its dt, target) + model error"),
            "engine_estimate": self.engine_estimate.as_ref().map_or(serde_json::Value::Null, f),
            "model_error": f(&self.model_error),
        })
    }
}

/// The scenario's `[tolerance]` limits in [`Figures`] order.
fn limits(sc: &Scenario) -> [Limit; 3] {
    let t = &sc.tolerance;
    [t.position_max, t.theta_max, t.omega_steady_rel]
}

/// What the dt ladder aims for per figure: a share of the scenario's number,
/// or [`AUTO_TARGET`] for an auto figure.
pub fn ladder_targets(sc: &Scenario, fraction: f64) -> Figures {
    let l = limits(sc);
    let pick = |l: Limit, auto: f64| l.value().map_or(auto, |v| fraction * v);
    Figures {
        position_max: pick(l[0], AUTO_TARGET.position_max),
        theta_max: pick(l[1], AUTO_TARGET.theta_max),
        omega_steady_rel: pick(l[2], AUTO_TARGET.omega_steady_rel),
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
    let auto = |e: Option<f64>, target: f64, model: f64| {
        AUTO_FACTOR * e.unwrap_or(target).max(target) + model
    };
    let pick = |l: Limit, e: Option<f64>, target: f64, model: f64| match l {
        Limit::Value(v) => (v, Source::Scenario),
        Limit::Auto => (auto(e, target, model), Source::Auto),
    };
    let (p, sp) = pick(
        l[0],
        est.map(|e| e.position_max),
        AUTO_TARGET.position_max,
        model_error.position_max,
    );
    let (t, st) = pick(
        l[1],
        est.map(|e| e.theta_max),
        AUTO_TARGET.theta_max,
        model_error.theta_max,
    );
    let (w, sw) = pick(
        l[2],
        est.map(|e| e.omega_steady_rel),
        AUTO_TARGET.omega_steady_rel,
        model_error.omega_steady_rel,
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
    }
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
    for (a, b) in loose.samples.iter().zip(&reference.samples) {
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
        let e = super::rel_err(a.omega_end, b.omega_end, push.speed, length);
        f.omega_steady_rel = f.omega_steady_rel.max(e);
    }
    f
}
