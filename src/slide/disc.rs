//! The uniform disc's ratio `v/(Rω)` near the stop, per engine.
//!
//! A uniform disc sliding and spinning on a plane stops translating and
//! turning at the same instant, and `ε = v/(Rω)` tends to 0.653 at the stop
//! whatever the throw (Farkas, Bartels, Unger & Wolf, PRL 90, 248302, 2003).
//! Coulomb friction does not depend on the speed, so near the stop `ε`
//! follows `dε/d ln s = g(ε)` and converges to the root geometrically in
//! `ln s`: three readings at equal steps of the log of the time left to the
//! stop extrapolate to the limit by Aitken's Δ² (as the model's own test
//! does, `crates/model/tests/slide.rs`).
//!
//! Each engine runs the shipped `thrown-disc` scenario at its default step
//! `h`, its rows taken at every step; `ε` is read at 40, 20 and 10 steps
//! before its stop (`v` from the last step's displacement, the velocity a
//! semi-implicit step moves with, `ω` the row's), far enough from the stop
//! for a step's friction to be small against the speed. The dynamic model
//! is read at the same times before its own stop, and its limit on the
//! scenario's support grid at 1e-4, 1e-6 and 1e-8 of its stop time. The
//! shipped disc is a coarse grid (20 mm cells in a 0.1 m radius), whose
//! jagged rim moves the limit off the continuous disc's 0.653.

use anyhow::Context;
use pushval_engine::Engine;
use pushval_model::{slide_to_rest, Problem, SlideOptions, SlideState};

use crate::outdir::{num, Csv};

/// What became of one engine in the study.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// It released on every throw.
    Released,
    /// It refused the release (it cannot let go): not applicable.
    Refused(String),
    /// It failed to run (its error).
    Failed(String),
}

/// The shipped scenario of the thrown disc.
pub const DISC_SCENE: &str = "thrown-disc.toml";

/// Steps before the stop at which `ε` is read: equal steps in the log of
/// the time left.
pub const READ_STEPS: [f64; 3] = [40.0, 20.0, 10.0];

/// One engine's disc.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscRow {
    pub engine: String,
    /// Its step (s).
    pub dt: f64,
    pub status: Status,
    /// Its stop time (s; None: not stopped within max_duration).
    pub t_stop: Option<f64>,
    /// `ε` at [`READ_STEPS`] steps before its stop (NaN where not read).
    pub ratios: [f64; 3],
    /// The model's `ε` at the same times before the model's stop.
    pub model_ratios: [f64; 3],
}

impl DiscRow {
    /// The Aitken extrapolation of [`DiscRow::ratios`].
    pub fn extrapolated(&self) -> f64 {
        aitken(self.ratios)
    }
    /// The Aitken extrapolation of [`DiscRow::model_ratios`].
    pub fn model_extrapolated(&self) -> f64 {
        aitken(self.model_ratios)
    }
}

/// The disc's study: the model's limit and one row per engine.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscStudy {
    /// The disc's radius (m): its outline's farthest vertex from the centre
    /// of mass.
    pub radius: f64,
    /// Supports of the scenario's grid.
    pub supports: usize,
    /// The model's stop time (s).
    pub model_t_stop: f64,
    /// The model's limit of `ε` at the stop on this grid.
    pub model_limit: f64,
    pub rows: Vec<DiscRow>,
}

/// `e₂ − d₂²/(d₂ − d₁)` for readings converging geometrically; the last
/// reading where the differences do not shrink by a common ratio in (0, 1)
/// (no geometric convergence to extrapolate).
pub fn aitken(e: [f64; 3]) -> f64 {
    let (d1, d2) = (e[1] - e[0], e[2] - e[1]);
    let q = d2 / d1;
    if d1 == 0.0 || !(q > 0.0 && q < 1.0) {
        return e[2];
    }
    e[2] - d2 * d2 / (d2 - d1)
}

/// The scene: the shipped scenario's problem and its radius.
fn disc_scene() -> anyhow::Result<(Problem, f64)> {
    let sc = crate::shipped::scenario(DISC_SCENE)?;
    let c = sc.center_of_mass;
    let radius = sc
        .polygon
        .iter()
        .map(|p| (p - c).norm())
        .fold(0.0, f64::max);
    Ok((sc.problem(), radius))
}

/// The model's slide states at the times `times(stop)` (s), and its stop.
fn model_states(
    problem: &Problem,
    times: &dyn Fn(f64) -> Vec<f64>,
) -> anyhow::Result<(Vec<SlideState>, f64)> {
    let i = &problem.initial;
    let start = SlideState {
        t: 0.0,
        x: i.position.x,
        y: i.position.y,
        theta: i.theta,
        vx: i.velocity.x,
        vy: i.velocity.y,
        omega: i.omega,
    };
    let max_duration = problem.release.map_or(10.0, |r| r.max_duration);
    let stop = slide_to_rest(
        &problem.body,
        &start,
        &SlideOptions {
            max_duration,
            ..Default::default()
        },
    )?
    .stop
    .context("the model's disc does not stop")?;
    let ts = times(stop);
    let sl = slide_to_rest(
        &problem.body,
        &start,
        &SlideOptions {
            // The velocities' direction near the stop asks for a tolerance
            // far below the pose's (the model's test does the same).
            tol: 1e-13,
            max_duration,
            sample_times: &ts,
        },
    )?;
    Ok((sl.samples, stop))
}

fn ratio(s: &SlideState, radius: f64) -> f64 {
    s.vx.hypot(s.vy) / (radius * s.omega.abs())
}

/// One engine's row (its run at its default step, every step a row).
pub fn run_disc(engine: &dyn Engine, problem: &Problem, radius: f64) -> DiscRow {
    let h = engine.default_dt();
    let mut row = DiscRow {
        engine: engine.name().to_string(),
        dt: h,
        status: Status::Released,
        t_stop: None,
        ratios: [f64::NAN; 3],
        model_ratios: [f64::NAN; 3],
    };
    let mut p = problem.clone();
    p.sample_dt = h;
    let run = match engine.run(&p, h) {
        Ok(r) => r,
        Err(pushval_model::ModelError::NoRelease { reason, .. }) => {
            row.status = Status::Refused(reason);
            return row;
        }
        Err(e) => {
            row.status = Status::Failed(e.to_string());
            return row;
        }
    };
    let tr = &run.trajectory;
    let Some(stop) = tr.slide.as_ref().and_then(|s| s.t_stop) else {
        return row;
    };
    row.t_stop = Some(stop);
    let rows = &tr.samples;
    for (k, &n) in READ_STEPS.iter().enumerate() {
        let t = stop - n * h;
        let Some(i) = (1..rows.len())
            .min_by(|&a, &b| (rows[a].t - t).abs().total_cmp(&(rows[b].t - t).abs()))
        else {
            continue;
        };
        let (a, b) = (rows[i - 1], rows[i]);
        if (b.t - t).abs() > 0.5 * h || b.t <= a.t {
            continue;
        }
        let v = (b.x - a.x).hypot(b.y - a.y) / (b.t - a.t);
        row.ratios[k] = v / (radius * b.omega.abs());
    }
    row
}

/// The model's readings at an engine's times before the stop.
fn model_at_engine_times(problem: &Problem, radius: f64, h: f64) -> anyhow::Result<[f64; 3]> {
    let (s, _) = model_states(problem, &|stop| {
        READ_STEPS.iter().map(|n| stop - n * h).collect()
    })?;
    Ok([
        ratio(&s[0], radius),
        ratio(&s[1], radius),
        ratio(&s[2], radius),
    ])
}

/// Runs the disc in every engine of `engines` (one that refuses the
/// release or fails is reported so, as in the square's study).
pub fn measure_disc(engines: &[&dyn Engine]) -> anyhow::Result<DiscStudy> {
    let (problem, radius) = disc_scene()?;
    let (deep, stop) = model_states(&problem, &|stop| {
        [1e-4, 1e-6, 1e-8]
            .iter()
            .map(|f| stop * (1.0 - f))
            .collect()
    })
    .context("the dynamic model's slide of the disc")?;
    let model_limit = aitken([
        ratio(&deep[0], radius),
        ratio(&deep[1], radius),
        ratio(&deep[2], radius),
    ]);
    let mut rows = Vec::new();
    for engine in engines {
        let mut row = run_disc(*engine, &problem, radius);
        if row.status == Status::Released {
            row.model_ratios = model_at_engine_times(&problem, radius, row.dt)?;
        }
        rows.push(row);
    }
    Ok(DiscStudy {
        radius,
        supports: problem.body.supports().count(),
        model_t_stop: stop,
        model_limit,
        rows,
    })
}

/// `disc.csv`: one row per engine.
pub fn disc_csv(study: &DiscStudy) -> Csv {
    let mut csv = Csv::new(&[
        "engine",
        "dt",
        "status",
        "t_stop",
        "model_t_stop",
        "ratio_40",
        "ratio_20",
        "ratio_10",
        "ratio_extrapolated",
        "model_ratio_40",
        "model_ratio_20",
        "model_ratio_10",
        "model_ratio_extrapolated",
        "model_limit",
    ]);
    for r in &study.rows {
        let status = match &r.status {
            Status::Released if r.t_stop.is_some() => "stopped",
            Status::Released => "not stopped",
            Status::Refused(_) => "refused",
            Status::Failed(_) => "failed",
        };
        csv.row(&[
            r.engine.clone(),
            num(r.dt),
            status.into(),
            r.t_stop.map_or(String::new(), num),
            num(study.model_t_stop),
            num(r.ratios[0]),
            num(r.ratios[1]),
            num(r.ratios[2]),
            num(r.extrapolated()),
            num(r.model_ratios[0]),
            num(r.model_ratios[1]),
            num(r.model_ratios[2]),
            num(r.model_extrapolated()),
            num(study.model_limit),
        ]);
    }
    csv
}

#[cfg(test)]
mod tests {
    use super::aitken;

    /// Readings `L + c qᵏ` at k = 0, 1, 2 extrapolate to L exactly;
    /// readings that do not converge geometrically give the last one.
    #[test]
    fn aitken_finds_the_limit_of_a_geometric_sequence() {
        let (l, c, q) = (0.653, 0.3, 0.4);
        let e = [l + c, l + c * q, l + c * q * q];
        assert!((aitken(e) - l).abs() < 1e-12, "{}", aitken(e));
        assert_eq!(aitken([0.7, 0.6, 0.65]), 0.65);
        assert_eq!(aitken([0.7, 0.7, 0.7]), 0.7);
    }
}
