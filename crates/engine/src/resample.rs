//! The one resampler: an engine's step history turned into samples.
//!
//! The engines pushval runs integrate with symplectic (semi-implicit) Euler: a
//! step first updates the velocities, then moves the poses with the new
//! velocities. So the pose after a step is a value *at* the step's end, while
//! the angular velocity after a step is the one the body held *over* the step,
//! best read as the value at the step's middle. Samples are built accordingly:
//!
//! * `x`, `y`, `θ` at a sample time: linear interpolation between the poses at
//!   the two step ends around it (exact for the engine's piecewise-linear motion);
//! * `ω` at a sample time: linear interpolation between the step velocities
//!   placed at the step middles, **within the segment the sample belongs to**,
//!   extrapolated linearly from the segment's first (last) two steps near its
//!   start (end). A sample at a switch time belongs to the segment that starts
//!   there, so its ω is the engine's ω just after the switch impulse.

use pushval_model::{Problem, Sample, SegmentReport, Trajectory};

/// One engine step, or (the first record of a history) the initial state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepRecord {
    /// Index of the push segment the step belongs to.
    pub segment: usize,
    /// Start time of the step (s); equal to `t1` for the initial-state record.
    pub t0: f64,
    /// End time of the step (s).
    pub t1: f64,
    /// World x of the centre of mass at `t1` (m).
    pub x: f64,
    /// World y of the centre of mass at `t1` (m).
    pub y: f64,
    /// Object angle at `t1`, unwrapped (rad).
    pub theta: f64,
    /// Angular velocity the engine held over the step (rad/s); for the
    /// initial-state record, the initial angular velocity.
    pub omega: f64,
}

impl StepRecord {
    /// False for the initial-state record (zero length).
    pub fn is_step(&self) -> bool {
        self.t1 > self.t0
    }
    fn mid(&self) -> f64 {
        0.5 * (self.t0 + self.t1)
    }
}

/// The segment a time belongs to: a switch time belongs to the segment that
/// starts there; the end time to the last segment.
fn segment_of(times: &[(f64, f64)], t: f64) -> usize {
    let tol = 1e-12 * times.last().map(|s| s.1).unwrap_or(1.0).max(1.0);
    times
        .iter()
        .position(|&(_, t1)| t < t1 - tol)
        .unwrap_or(times.len() - 1)
}

/// Range of history indices of the (non-initial) steps of each segment.
fn segment_ranges(n_segments: usize, history: &[StepRecord]) -> Vec<std::ops::Range<usize>> {
    let mut ranges = vec![0..0; n_segments];
    for (j, range) in ranges.iter_mut().enumerate() {
        let a = history.partition_point(|r| r.segment < j || !r.is_step());
        let b = history.partition_point(|r| r.segment <= j);
        *range = a..b.max(a);
    }
    ranges
}

/// ω at time `t` from the steps `steps` of one segment (see the module docs).
fn omega_in(steps: &[StepRecord], t: f64) -> f64 {
    match steps.len() {
        0 => f64::NAN,
        1 => steps[0].omega,
        n => {
            // Index of the first step whose middle is after t, clamped so that
            // (k-1, k) is a valid pair of neighbouring nodes.
            let k = steps.partition_point(|r| r.mid() <= t).clamp(1, n - 1);
            let (a, b) = (&steps[k - 1], &steps[k]);
            let s = (t - a.mid()) / (b.mid() - a.mid());
            a.omega + s * (b.omega - a.omega)
        }
    }
}

/// Samples at `problem.sample_times()` from a history whose first record is
/// the initial state (see the module docs for the reading).
pub fn sample(problem: &Problem, history: &[StepRecord]) -> Vec<Sample> {
    let times = problem.segment_times();
    if times.is_empty() || history.is_empty() {
        // No push (a plate thrown at once): no samples of pushes.
        return Vec::new();
    }
    let ranges = segment_ranges(times.len(), history);
    problem
        .sample_times()
        .into_iter()
        .map(|t| {
            // Pose: the last node at or before t, and the one after it.
            let k = history.partition_point(|r| r.t1 <= t);
            let (x, y, theta) = if k == 0 {
                let r = &history[0];
                (r.x, r.y, r.theta)
            } else if k >= history.len() {
                let r = &history[history.len() - 1];
                (r.x, r.y, r.theta)
            } else {
                let (a, b) = (&history[k - 1], &history[k]);
                let s = if b.t1 > a.t1 {
                    (t - a.t1) / (b.t1 - a.t1)
                } else {
                    1.0
                };
                (
                    a.x + s * (b.x - a.x),
                    a.y + s * (b.y - a.y),
                    a.theta + s * (b.theta - a.theta),
                )
            };
            let j = segment_of(&times, t);
            let omega = omega_in(&history[ranges[j].clone()], t);
            Sample {
                t,
                x,
                y,
                theta,
                omega,
            }
        })
        .collect()
}

/// One report per segment: ω just after the switch into it and at its end.
pub fn segment_reports(problem: &Problem, history: &[StepRecord]) -> Vec<SegmentReport> {
    let times = problem.segment_times();
    let ranges = segment_ranges(times.len(), history);
    times
        .iter()
        .enumerate()
        .map(|(j, &(t0, t1))| {
            let steps = &history[ranges[j].clone()];
            SegmentReport {
                index: j,
                t_start: t0,
                t_end: t1,
                omega_start: omega_in(steps, t0),
                omega_end: omega_in(steps, t1),
                settled_at: None,
            }
        })
        .collect()
}

/// Per segment, the time-weighted mean of the step ω over the steps that lie
/// in the last `fraction` of the segment: a cheap steady-ω estimate.
pub fn step_tail_omega(problem: &Problem, history: &[StepRecord], fraction: f64) -> Vec<f64> {
    let times = problem.segment_times();
    let ranges = segment_ranges(times.len(), history);
    times
        .iter()
        .enumerate()
        .map(|(j, &(t0, t1))| {
            let from = t1 - fraction * (t1 - t0);
            let steps = &history[ranges[j].clone()];
            let (mut w, mut sum) = (0.0, 0.0);
            for r in steps.iter().filter(|r| r.mid() >= from) {
                let h = r.t1 - r.t0;
                w += h;
                sum += h * r.omega;
            }
            if w > 0.0 {
                sum / w
            } else {
                steps.last().map(|r| r.omega).unwrap_or(f64::NAN)
            }
        })
        .collect()
}

/// Samples and segment reports of a history ([`sample`], [`segment_reports`]).
pub fn resample(problem: &Problem, history: &[StepRecord]) -> (Vec<Sample>, Vec<SegmentReport>) {
    (sample(problem, history), segment_reports(problem, history))
}

/// A trajectory named `model` from a history, with the step count in its
/// statistics.
pub fn trajectory_from_steps(model: &str, problem: &Problem, history: &[StepRecord]) -> Trajectory {
    let (samples, segments) = resample(problem, history);
    let mut trajectory = Trajectory {
        model: model.to_string(),
        samples,
        segments,
        ..Default::default()
    };
    let steps = history.iter().filter(|r| r.is_step()).count();
    trajectory.stats.steps = steps;
    trajectory.stats.rhs_evals = steps;
    trajectory
}

/// Per segment of `problem`, the mean of ω over the last `fraction` of the
/// segment, from any trajectory's samples (trapezoidal rule over the samples in
/// `[t_end − fraction·duration, t_end]`; the sample at a switch time belongs to
/// the segment it starts, so the segment's end value is read just before it).
/// `None` where fewer than two samples fall in the window.
pub fn tail_mean_omega(
    problem: &Problem,
    trajectory: &Trajectory,
    fraction: f64,
) -> Vec<Option<f64>> {
    problem
        .segment_times()
        .iter()
        .enumerate()
        .map(|(j, &(t0, t1))| {
            let from = t1 - fraction * (t1 - t0);
            let last = j + 1 == problem.pushes.len();
            let tol = 1e-9 * (t1 - t0).max(1.0);
            let pts: Vec<(f64, f64)> = trajectory
                .samples
                .iter()
                .filter(|s| s.t >= from - tol && (s.t < t1 - tol || (last && s.t <= t1 + tol)))
                .map(|s| (s.t, s.omega))
                .collect();
            if pts.len() < 2 {
                return None;
            }
            let span = pts[pts.len() - 1].0 - pts[0].0;
            if span <= 0.0 {
                return None;
            }
            let area: f64 = pts
                .windows(2)
                .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
                .sum();
            Some(area / span)
        })
        .collect()
}

/// Continues `trajectory` (sampled up to the release at `release.t`)
/// through an engine's free slide: `steps` are the slide's steps (each its
/// end time and pose, with the ω held over it), `end` the rest state (or
/// the state at the release's `max_duration`). Samples go on on the
/// problem's grid (`k · sample_dt`, the pose linear between step ends, ω
/// the step's) after the release and before the end; the last row is
/// `end`; [`Trajectory::slide`] is set to `report`. The release row itself
/// is added when the trajectory does not end there (a throw: no pushes).
pub fn extend_through_slide(
    problem: &Problem,
    trajectory: &mut Trajectory,
    release: Sample,
    steps: &[Sample],
    end: Sample,
    report: pushval_model::SlideReport,
) {
    let eps = 1e-9 * problem.sample_dt;
    if trajectory
        .samples
        .last()
        .is_none_or(|l| l.t < release.t - eps)
    {
        trajectory.samples.push(release);
    }
    let nodes: Vec<Sample> = std::iter::once(release)
        .chain(steps.iter().copied())
        .filter(|s| s.t <= end.t + eps)
        .collect();
    for ts in problem.sample_times_through(end.t) {
        if nodes.len() < 2 || ts <= release.t + eps || ts >= end.t - eps {
            continue;
        }
        let k = nodes
            .partition_point(|r| r.t <= ts)
            .clamp(1, nodes.len() - 1);
        let (a, b) = (nodes[k - 1], nodes[k]);
        let w = if b.t > a.t {
            ((ts - a.t) / (b.t - a.t)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        trajectory.samples.push(Sample {
            t: ts,
            x: a.x + w * (b.x - a.x),
            y: a.y + w * (b.y - a.y),
            theta: a.theta + w * (b.theta - a.theta),
            omega: b.omega,
        });
    }
    match trajectory.samples.last_mut() {
        Some(l) if l.t >= end.t - eps => *l = end,
        _ => trajectory.samples.push(end),
    }
    trajectory.slide = Some(report);
}
