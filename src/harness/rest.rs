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
//! ([`super::tolerance::stop_tolerance`]).

use pushval_model::{Problem, Sample, Trajectory};

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

/// The self-convergence estimate of the stop time (s) of the run at h
/// (`fine`) from it and the run at 2h (`coarse`) of a scheme of order
/// `order`, `|t(2h) − t(h)| / (2^p − 1)`; infinite when either did not stop.
pub fn stop_estimate(coarse: &Trajectory, fine: &Trajectory, order: f64) -> f64 {
    match (rest_of(coarse), rest_of(fine)) {
        (Some(c), Some(f)) => (c.t - f.t).abs() / (2f64.powf(order) - 1.0),
        _ => f64::INFINITY,
    }
}
