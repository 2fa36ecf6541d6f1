//! The slide to rest in the gate: the rest pose and the stop time of a run
//! through a `[release]`, measured against the dynamic model's, and the
//! tolerance the stop time is held to.
//!
//! Two runs through a slide stop at different times, so their sample lists
//! differ in length: both are on the grid `k · sample_dt` up to their stop,
//! with the stop itself as the last row. A plate at rest stays there, so
//! the shorter run is compared beyond its end by its rest ([`paired`]):
//! the position and angle figures then include the rest pose.
//!
//! The stop time has no `[tolerance]` key: it is always derived from the
//! gated engine's own accuracy, as an `"auto"` figure is
//! ([`stop_tolerance`]).

use pushval_model::{Problem, Sample, Trajectory};
use pushval_scenario::Scenario;

use super::tolerance::AUTO_FACTOR;

/// Where and when a run came to rest (SI: s, m, rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rest {
    /// The stop time (s).
    pub t: f64,
    /// Centre of mass x (m, world frame).
    pub x: f64,
    /// Centre of mass y (m, world frame).
    pub y: f64,
    /// Angle (rad, unwrapped).
    pub theta: f64,
}

impl Rest {
    /// The `{t, x, y, theta}` record of summary.json.
    pub fn json(&self) -> serde_json::Value {
        use crate::outdir::json_num as num;
        serde_json::json!({"t": num(self.t), "x": num(self.x), "y": num(self.y), "theta": num(self.theta)})
    }
}

/// The rest of a run that went through a slide and stopped (its last row);
/// None when it has no slide or did not stop within `max_duration`.
pub fn rest_of(tr: &Trajectory) -> Option<Rest> {
    let t = tr.slide.as_ref()?.t_stop?;
    let last = tr.samples.last()?;
    Some(Rest {
        t,
        x: last.x,
        y: last.y,
        theta: last.theta,
    })
}

/// The samples of two runs side by side: index by index when they have as
/// many, and when both stopped after a release, the shorter one's rest
/// standing in for its samples past its stop. None when the lengths differ
/// otherwise (the runs cannot be compared sample by sample).
pub fn paired<'a>(a: &'a Trajectory, b: &'a Trajectory) -> Option<Vec<(&'a Sample, &'a Sample)>> {
    let (n, m) = (a.samples.len(), b.samples.len());
    if n == m {
        return Some(a.samples.iter().zip(&b.samples).collect());
    }
    if n == 0 || m == 0 || rest_of(a).is_none() || rest_of(b).is_none() {
        return None;
    }
    Some(
        (0..n.max(m))
            .map(|i| (&a.samples[i.min(n - 1)], &b.samples[i.min(m - 1)]))
            .collect(),
    )
}

/// A run's rest against the dynamic model's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestDiff {
    /// The dynamic model's rest (None: it did not stop within
    /// `max_duration`).
    pub reference: Option<Rest>,
    /// The run's rest (None: it did not stop).
    pub run: Option<Rest>,
    /// Distance between the two rest positions (m); infinite when only one
    /// of them stopped, NaN when neither did.
    pub position: f64,
    /// Angle between the two rest poses (rad), as `position`.
    pub theta: f64,
    /// The run's stop time minus the model's (s), as `position`.
    pub stop_time: f64,
}

/// [`RestDiff`] of `run` against `reference`; None when the problem has no
/// release.
pub fn rest_diff(problem: &Problem, reference: &Trajectory, run: &Trajectory) -> Option<RestDiff> {
    problem.release?;
    let (a, b) = (rest_of(run), rest_of(reference));
    let (position, theta, stop_time) = match (a, b) {
        (Some(a), Some(b)) => (
            (a.x - b.x).hypot(a.y - b.y),
            (a.theta - b.theta).abs(),
            a.t - b.t,
        ),
        (None, None) => (f64::NAN, f64::NAN, f64::NAN),
        _ => (f64::INFINITY, f64::INFINITY, f64::INFINITY),
    };
    Some(RestDiff {
        reference: b,
        run: a,
        position,
        theta,
        stop_time,
    })
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
    problem.release?;
    rest_of(reference)?;
    let estimate = match (rest_of(coarse), rest_of(fine)) {
        (Some(c), Some(f)) => (c.t - f.t).abs() / (2f64.powf(order) - 1.0),
        _ => f64::INFINITY,
    };
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
    let auto = AUTO_FACTOR * estimate.max(h) + model_error;
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
    use pushval_model::{DynamicModel, Integrator, Simulator};
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
