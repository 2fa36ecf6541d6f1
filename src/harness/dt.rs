//! The gated engine's time step (the dt ladder and its self-convergence
//! estimate) and the convergence check (2 dt / 4 dt reruns, observed order,
//! Richardson). Both go through [`Engine`] and name no engine.

use std::time::{Duration, Instant};

use pushval_engine::{rel_err, Engine, EngineRun};
use pushval_model::{ModelError, Problem, Trajectory};
use pushval_scenario::Scenario;

use super::figures::{ladder_targets, Figures};
use super::segments::{tail_omega, SegmentInfo};

/// The largest engine time step the automatic choice tries (s): 1/60 s,
/// rapier's own default step and the usual game-engine frame. Coarser steps
/// would put several 0.01 s samples inside one step and stop resolving the
/// relaxation times of the shipped scenes (τ ≈ 0.05–0.3 s).
pub const DT_LADDER_TOP: f64 = 1.0 / 60.0;

/// No rung of the automatic ladder is below this (s). Eight rungs, 1/60 s to
/// 1/7680 s ≈ 1.3e-4 s: at the bottom a second-order step is 16 000 times
/// more accurate than at the top and a 10 s scene takes 77 000 steps (about
/// 0.2 s); a scene that needs less than that has a problem worth seeing
/// rather than a step to shrink.
pub const DT_FLOOR: f64 = 1e-4;

/// The share of each `[tolerance]` figure the engine's own discretisation
/// error may use up at the automatic step. The gate compares engine and
/// model, so the engine's error eats into the tolerance a model error must
/// exceed to be caught: at 1/4 a model error of 5/4 of the tolerance always
/// fails the gate, and at most 1/4 is hidden. The margin also covers the
/// estimate itself, which assumes the asymptotic order: at the coarse rungs
/// the observed order can be off (the convergence check reports it) and the
/// estimate off by a factor of 2 or so.
pub const DT_FRACTION: f64 = 0.25;

/// The rungs of the automatic time-step ladder, largest first:
/// `DT_LADDER_TOP / 2^k` down to [`DT_FLOOR`].
pub fn dt_ladder() -> Vec<f64> {
    std::iter::successors(Some(DT_LADDER_TOP), |h| Some(h / 2.0))
        .take_while(|h| *h >= DT_FLOOR)
        .collect()
}

/// Where the engine's time step came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DtSource {
    /// `[engine] dt` in the scenario, kept exactly.
    Scenario,
    /// Chosen by [`choose_engine_dt`].
    Automatic,
}

impl DtSource {
    /// `"scenario"` or `"automatic"`, as summary.json writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            DtSource::Scenario => "scenario",
            DtSource::Automatic => "automatic",
        }
    }
}

/// The engine's self-convergence error estimate at one time step h, from
/// the runs at 2h and h alone (never against the model): Richardson's
/// `|X(2h) − X(h)| / (2^p − 1)` for the scheme's order p, for each
/// gated figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DtEstimate {
    /// The time step h (s).
    pub dt: f64,
    /// Largest centre-of-mass distance over the samples (m).
    pub position_max: f64,
    /// Largest angle difference over the samples (rad).
    pub theta_max: f64,
    /// Largest relative steady-ω difference over the segments the gate
    /// reads a steady ω from (tail means; denominator the run at h with
    /// [`rel_err`]'s floor); None when no segment settles.
    pub omega_steady_rel_max: Option<f64>,
    /// Where the problem releases the plate and the step is chosen
    /// automatically: the auto stop-time tolerance this rung would give (s,
    /// [`StopFloor::tolerance`]: never below its factor's number of steps,
    /// since the rest rule reads the stop at a step's end). None otherwise.
    pub stop_time: Option<f64>,
    /// Whether every figure is within its ladder target
    /// ([`DT_FRACTION`] of a number in `[tolerance]`, or the auto target),
    /// and the stop-time tolerance, where there is one, within its ceiling.
    pub meets: bool,
}

/// What the stop time asks of an automatic step where the problem
/// releases the plate: the auto stop-time tolerance a rung gives must be
/// within `ceiling`, or the gate would fail the row for its step alone (a
/// second-order engine's coarse step can be longer than the time the
/// plate takes to cover the position ceiling).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopFloor {
    /// The most the stop-time tolerance may be (s,
    /// [`stop_ceiling`](super::tolerance::stop_ceiling)).
    pub ceiling: f64,
    /// The dynamic model's own error in its stop time (s).
    pub model_error: f64,
    /// The auto tolerance's factor on the engine's estimate
    /// ([`AUTO_FACTOR`](super::tolerance::AUTO_FACTOR)).
    pub factor: f64,
}

impl StopFloor {
    /// The auto stop-time tolerance (s) at step `h` (s) for the engine's
    /// stop-time estimate `estimate` (s): the factor times the larger of the
    /// estimate and one step (the rest rule reads the stop at a step's end),
    /// plus the model's own error.
    pub fn tolerance(&self, estimate: f64, h: f64) -> f64 {
        self.factor * estimate.max(h) + self.model_error
    }
}

/// How the engine's time step was chosen, for the outputs.
#[derive(Debug, Clone)]
pub struct DtChoice {
    /// The time step the gated engine run uses (s).
    pub dt: f64,
    pub source: DtSource,
    /// Automatic only: every rung tried, largest first; the last one is the
    /// chosen one.
    pub rungs: Vec<DtEstimate>,
    /// Automatic only: false when not even the ladder's floor met the
    /// criterion (the floor is used then).
    pub met: bool,
    /// The scheme's order used in the estimate.
    pub order: f64,
    /// What each figure's estimate had to be within.
    pub targets: Figures,
    /// Wall time of the search's engine runs (the chosen run and its 2h
    /// partner included).
    pub search_time: Duration,
    /// The stop-time ceiling the rungs were held to (s), where the problem
    /// releases the plate and the step is automatic.
    pub stop_ceiling: Option<f64>,
}

impl DtChoice {
    /// One line saying which dt and why.
    pub fn reason(&self) -> String {
        let t = &self.targets;
        let figures = |e: &DtEstimate| {
            let stop = match (e.stop_time, self.stop_ceiling) {
                (Some(s), Some(c)) => {
                    format!("; stop-time tolerance {s:.2e} s (ceiling {c:.2e} s)")
                }
                _ => String::new(),
            };
            format!(
                "position {:.2e} m, theta {:.2e} rad, steady omega {} (targets {:.2e} m, {:.2e} rad, {:.2e}){stop}",
                e.position_max,
                e.theta_max,
                e.omega_steady_rel_max.map_or("-".into(), |w| format!("{w:.2e}")),
                t.position_max,
                t.theta_max,
                t.omega_steady_rel
            )
        };
        match (self.source, self.rungs.last()) {
            (DtSource::Scenario, last) => format!(
                "dt = {} s set by the scenario's [engine] dt{}",
                self.dt,
                last.map_or(String::new(), |e| format!("; estimate {}", figures(e)))
            ),
            (_, None) => format!("dt = {} s", self.dt),
            (DtSource::Automatic, Some(last)) => {
                let mut s = if self.met {
                    format!(
                        "dt = {:.4e} s: the largest ladder rung whose self-convergence estimate meets its targets: {}",
                        self.dt,
                        figures(last)
                    )
                } else {
                    format!(
                        "dt = {:.4e} s (the ladder's floor) although its estimate misses its targets: {}",
                        self.dt,
                        figures(last)
                    )
                };
                if self.rungs.len() >= 2 {
                    let prev = &self.rungs[self.rungs.len() - 2];
                    s.push_str(&format!("; {:.4e} s misses: {}", prev.dt, figures(prev)));
                }
                s
            }
        }
    }

    /// The record written into the engine's settings in `summary.json`.
    pub fn json(&self) -> serde_json::Value {
        use crate::outdir::json_num as num;
        let rungs: Vec<serde_json::Value> = self
            .rungs
            .iter()
            .map(|e| {
                serde_json::json!({
                    "dt": num(e.dt),
                    "position_max_estimate": num(e.position_max),
                    "theta_max_estimate": num(e.theta_max),
                    "omega_steady_rel_max_estimate": e.omega_steady_rel_max.map_or(serde_json::Value::Null, num),
                    "stop_time_tolerance": e.stop_time.map_or(serde_json::Value::Null, num),
                    "meets": e.meets,
                })
            })
            .collect();
        let t = &self.targets;
        serde_json::json!({
            "source": match self.source {
                DtSource::Scenario => "scenario",
                DtSource::Automatic => "automatic",
            },
            "reason": self.reason(),
            "criterion": "Richardson self-convergence estimate |X(2h) - X(h)| / (2^p - 1) of the run at h, each gated figure within its target: fraction x [tolerance] for a number, the auto target for \"auto\"; where the plate is released, the auto stop-time tolerance at h within its ceiling",
            "stop_time_ceiling": self.stop_ceiling.map_or(serde_json::Value::Null, num),
            "fraction": DT_FRACTION,
            "order": self.order,
            "ladder": dt_ladder(),
            "targets": {
                "position_max": num(t.position_max),
                "theta_max": num(t.theta_max),
                "omega_steady_rel": num(t.omega_steady_rel),
            },
            "met": self.met,
            "rungs": rungs,
            "search_wall_time_s": num(self.search_time.as_secs_f64()),
        })
    }
}

/// The self-convergence estimate of the run at h (`fine`) from it and the
/// run at 2h (`coarse`) of a scheme of order `order`.
pub fn dt_estimate(
    sc: &Scenario,
    segments: &[SegmentInfo],
    h: f64,
    coarse: &Trajectory,
    fine: &Trajectory,
    order: f64,
) -> DtEstimate {
    // Richardson: the finer run's error is |X(2h) − X(h)| / (2^p − 1).
    let k = 1.0 / (2f64.powf(order) - 1.0);
    let mut position_max: f64 = 0.0;
    let mut theta_max: f64 = 0.0;
    // Through a slide the two runs may stop at different times.
    let pairs = super::rest::paired(coarse, fine).unwrap_or_default();
    for (a, b) in &pairs {
        position_max = position_max.max(((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt());
        theta_max = theta_max.max((a.theta - b.theta).abs());
    }
    if pairs.is_empty() {
        position_max = f64::INFINITY;
        theta_max = f64::INFINITY;
    }
    let mut omega: Option<f64> = None;
    for s in segments.iter().filter(|s| s.settles()) {
        let (Some(wc), Some(wf)) = (
            tail_omega(coarse, s.t_start, s.t_end),
            tail_omega(fine, s.t_start, s.t_end),
        ) else {
            continue;
        };
        let e = rel_err(wc, wf, s.speed, sc.froude_length());
        omega = Some(omega.map_or(e, |m: f64| m.max(e)));
    }
    let (position_max, theta_max) = (k * position_max, k * theta_max);
    let omega_steady_rel_max = omega.map(|e| k * e);
    let t = ladder_targets(sc, DT_FRACTION);
    let meets = position_max <= t.position_max
        && theta_max <= t.theta_max
        && omega_steady_rel_max.is_none_or(|e| e <= t.omega_steady_rel);
    DtEstimate {
        dt: h,
        position_max,
        theta_max,
        omega_steady_rel_max,
        stop_time: None,
        meets,
    }
}

/// A gated engine's time step: the scenario's `[engine] dt` when
/// set, otherwise the largest rung of [`dt_ladder`] whose self-convergence
/// estimate ([`dt_estimate`], engine runs at 2h and h only) is within
/// [`DT_FRACTION`] of every `[tolerance]` figure, or the floor when none is.
/// `segments` (from the dynamic model's run) only say which segments the
/// gate reads a steady ω from. Where the problem releases the plate,
/// `stop` holds every automatic rung's stop-time tolerance to its ceiling
/// too. Returns the choice and every engine run made, for reuse.
pub fn choose_engine_dt(
    sc: &Scenario,
    engine: &dyn Engine,
    problem: &Problem,
    segments: &[SegmentInfo],
    stop: Option<StopFloor>,
) -> Result<(DtChoice, Vec<EngineRun>), ModelError> {
    let order = engine.order_for(problem);
    let targets = ladder_targets(sc, DT_FRACTION);
    let start = Instant::now();
    if let Some(dt) = sc.engine.dt {
        // Kept exactly; the run at 2 dt gives the estimate an auto tolerance
        // needs (and is the convergence check's first partner).
        // The two runs are independent: side by side (an outside engine's
        // are two processes).
        let (a, b) = rayon::join(|| engine.run(problem, 2.0 * dt), || engine.run(problem, dt));
        let (a, b) = (a?, b?);
        let est = dt_estimate(sc, segments, dt, &a.trajectory, &b.trajectory, order);
        return Ok((
            DtChoice {
                dt,
                source: DtSource::Scenario,
                met: est.meets,
                rungs: vec![est],
                order,
                targets,
                search_time: start.elapsed(),
                stop_ceiling: None,
            },
            vec![a, b],
        ));
    }
    let ladder = dt_ladder();
    let mut runs: Vec<EngineRun> = Vec::new();
    let mut rungs = Vec::new();
    let run_at = |dt: f64, runs: &mut Vec<EngineRun>| -> Result<usize, ModelError> {
        if let Some(i) = runs.iter().position(|r| r.dt == dt) {
            return Ok(i);
        }
        runs.push(engine.run(problem, dt)?);
        Ok(runs.len() - 1)
    };
    // The first rung's two runs are independent: side by side.
    if let [top, ..] = ladder[..] {
        let (a, b) = rayon::join(
            || engine.run(problem, 2.0 * top),
            || engine.run(problem, top),
        );
        for r in [a, b] {
            match r {
                Ok(r) => runs.push(r),
                // No rung will do better: the engine cannot run the problem.
                Err(e @ (ModelError::Adapter(_) | ModelError::NoRelease { .. })) => return Err(e),
                Err(_) => {}
            }
        }
    }
    let mut last_err = None;
    let mut announced = false;
    for (i, &h) in ladder.iter().enumerate() {
        if !announced && start.elapsed() > Duration::from_secs(2) {
            eprintln!(
                "pushval: {}: choosing the engine time step (trying dt = {h:.3e} s, rung {} of {})",
                sc.name,
                i + 1,
                ladder.len()
            );
            announced = true;
        }
        // A rung whose runs fail (blow up) does not meet the criterion.
        let pair = run_at(2.0 * h, &mut runs).and_then(|a| Ok((a, run_at(h, &mut runs)?)));
        let (a, b) = match pair {
            Ok(p) => p,
            // The engine could not run at all: no rung will do better.
            Err(e @ (ModelError::Adapter(_) | ModelError::NoRelease { .. })) => return Err(e),
            Err(e) => {
                last_err = Some(e);
                continue;
            }
        };
        let mut est = dt_estimate(
            sc,
            segments,
            h,
            &runs[a].trajectory,
            &runs[b].trajectory,
            order,
        );
        if let Some(f) = stop {
            let e = super::rest::stop_estimate(&runs[a].trajectory, &runs[b].trajectory, order);
            let s = f.tolerance(e, h);
            est.stop_time = Some(s);
            est.meets &= s <= f.ceiling;
        }
        rungs.push(est);
        if est.meets || i + 1 == ladder.len() {
            return Ok((
                DtChoice {
                    dt: h,
                    source: DtSource::Automatic,
                    rungs,
                    met: est.meets,
                    order,
                    targets,
                    search_time: start.elapsed(),
                    stop_ceiling: stop.map(|f| f.ceiling),
                },
                runs,
            ));
        }
    }
    Err(last_err.expect("the ladder's floor either returns or fails"))
}

/// The order in dt observed on the trajectory itself: the largest
/// centre-of-mass distance and the largest angle difference over the
/// samples between runs at 4k and 2k (`d_coarse`) and at 2k and k
/// (`d_fine`), `p = log2(d_coarse / d_fine)`, read at the finest triple of
/// the ladder's runs whose `d_fine` is at least the ladder's target for
/// that figure. Below the target the difference says nothing the verdict
/// needs (the estimate is on its floor) and may be the engine's rounding.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TrajectoryOrder {
    /// Position: the observed order and the steps (s) it was read at,
    /// largest first; None where no triple resolves it.
    pub position: Option<(f64, [f64; 3])>,
    /// The same for the angle.
    pub theta: Option<(f64, [f64; 3])>,
}

impl TrajectoryOrder {
    /// The lower of the two figures' orders (the one whose error the
    /// declared order would understate more); None when neither is resolved.
    pub fn observed(&self) -> Option<f64> {
        match (self.position, self.theta) {
            (Some(a), Some(b)) => Some(a.0.min(b.0)),
            (a, b) => a.or(b).map(|x| x.0),
        }
    }

    /// Each resolved figure's order and the steps it was read at.
    pub fn describe(&self) -> String {
        let one = |name: &str, f: Option<(f64, [f64; 3])>| {
            f.map(|(p, d)| {
                format!(
                    "{name} {p:.2} at dt {:.3e}, {:.3e}, {:.3e} s",
                    d[0], d[1], d[2]
                )
            })
        };
        [one("position", self.position), one("theta", self.theta)]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Largest centre-of-mass distance and angle difference between two runs
/// at their common samples (through a slide, each run's rest standing in
/// past its stop); None when they cannot be paired.
fn max_differences(a: &Trajectory, b: &Trajectory) -> Option<[f64; 2]> {
    let pairs = super::rest::paired(a, b)?;
    let mut d = [0.0f64; 2];
    for (s, r) in pairs {
        d[0] = d[0].max(((s.x - r.x).powi(2) + (s.y - r.y).powi(2)).sqrt());
        d[1] = d[1].max((s.theta - r.theta).abs());
    }
    d.iter().all(|x| x.is_finite()).then_some(d)
}

/// [`TrajectoryOrder`] from runs at any steps (`(dt, trajectory)`, in any
/// order; the triples are those whose steps halve exactly), with floors
/// `[m, rad]` on the finer difference.
pub fn trajectory_order(runs: &[(f64, &Trajectory)], floor: [f64; 2]) -> TrajectoryOrder {
    let mut runs: Vec<(f64, &Trajectory)> = runs.to_vec();
    runs.sort_by(|a, b| b.0.total_cmp(&a.0));
    runs.dedup_by(|a, b| a.0 == b.0);
    let half = |a: f64, b: f64| (a - 2.0 * b).abs() <= 1e-9 * a;
    let mut out = TrajectoryOrder::default();
    // Coarse to fine: a finer resolved triple overwrites a coarser one.
    for w in runs.windows(3) {
        let [(h4, t4), (h2, t2), (h1, t1)] = [w[0], w[1], w[2]];
        if !(half(h4, h2) && half(h2, h1)) {
            continue;
        }
        let (Some(c), Some(f)) = (max_differences(t4, t2), max_differences(t2, t1)) else {
            continue;
        };
        for k in 0..2 {
            if f[k] >= floor[k] && c[k] > 0.0 {
                let p = (c[k] / f[k]).log2();
                let slot = if k == 0 {
                    &mut out.position
                } else {
                    &mut out.theta
                };
                *slot = Some((p, [h4, h2, h1]));
            }
        }
    }
    out
}

/// How an engine's steady ω converges as its time step shrinks: runs at 4h,
/// 2h and h (h the gated run's step; runs the time-step search made are
/// reused), the observed order `p = log2(|ω(4h) − ω(2h)| / |ω(2h) − ω(h)|)`, and Richardson extrapolations
/// to dt → 0 with the scheme's expected order p: `ω(h) + (ω(h) − ω(2h)) / (2^p − 1)`,
/// and the same applied again for the order p + 1 term.
#[derive(Debug, Clone)]
pub struct Convergence {
    /// The order the friction-velocity scheme should show (1, or 2 for leapfrog).
    pub expected_order: f64,
    /// The three time steps (s), largest first.
    pub dts: [f64; 3],
    /// The order observed on the trajectory (positions and angle at the
    /// samples, every run of the ladder): [`trajectory_order`].
    pub trajectory: TrajectoryOrder,
    /// Observed order of the steady ω per settled segment.
    pub orders: Vec<(usize, f64)>,
    /// Largest relative error of the extrapolation at the expected order,
    /// against the dynamic model's tail-mean ω (within 1e-6 of ω*).
    pub richardson1_rel_max: f64,
    /// The same after removing the next order as well.
    pub richardson2_rel_max: f64,
    /// The same for the plain run at h.
    pub plain_rel_max: f64,
    /// Per settled segment, `|ω(2h) − ω(h)|` relative (with [`rel_err`]'s
    /// floor): below the auto target the order is not resolved (the
    /// difference is at the level of the tail mean's own noise).
    pub diff_rel: Vec<(usize, f64)>,
}

impl Convergence {
    /// Median observed order over the settled segments.
    pub fn order(&self) -> Option<f64> {
        self.order_resolved(0.0)
    }

    /// Median observed order over the settled segments whose
    /// `|ω(2h) − ω(h)|` (relative, [`Convergence::diff_rel`]) is at least
    /// `floor`.
    pub fn order_resolved(&self, floor: f64) -> Option<f64> {
        let mut o: Vec<f64> = self
            .orders
            .iter()
            .enumerate()
            .filter(|(i, _)| self.diff_rel.get(*i).is_none_or(|d| d.1 >= floor))
            .map(|(_, p)| p.1)
            .filter(|p| p.is_finite())
            .collect();
        o.sort_by(f64::total_cmp);
        (!o.is_empty()).then(|| o[o.len() / 2])
    }
}

/// Runs the engine at 2h and 4h beside the run at h and measures how its
/// steady ω converges, and how its trajectory does ([`trajectory_order`]
/// over every run of the ladder and these).
#[allow(clippy::too_many_arguments)]
pub fn engine_convergence(
    sc: &Scenario,
    engine: &dyn Engine,
    problem: &Problem,
    segments: &[SegmentInfo],
    fine: &Trajectory,
    reference: &Trajectory,
    h: f64,
    done: &[EngineRun],
) -> Result<Convergence, ModelError> {
    // Runs the search already made at 2h or 4h are reused (same settings,
    // deterministic: the same trajectory).
    let at = |dt: f64| -> Result<Trajectory, ModelError> {
        match done.iter().find(|r| r.dt == dt) {
            Some(r) => Ok(r.trajectory.clone()),
            None => engine.run(problem, dt).map(|r| r.trajectory),
        }
    };
    let mid = at(2.0 * h)?;
    let coarse = at(4.0 * h)?;
    let order = engine.order_for(problem);
    let mut ladder: Vec<(f64, &Trajectory)> = done.iter().map(|r| (r.dt, &r.trajectory)).collect();
    ladder.extend([(h, fine), (2.0 * h, &mid), (4.0 * h, &coarse)]);
    let t = ladder_targets(sc, DT_FRACTION);
    let trajectory = trajectory_order(&ladder, [t.position_max, t.theta_max]);
    let mut out = Convergence {
        expected_order: order,
        dts: [4.0 * h, 2.0 * h, h],
        trajectory,
        orders: Vec::new(),
        richardson1_rel_max: 0.0,
        richardson2_rel_max: 0.0,
        plain_rel_max: 0.0,
        diff_rel: Vec::new(),
    };
    for s in segments.iter().filter(|s| s.settles()) {
        // The same reading (tail mean) of the dynamic model: within 1e-6 of ω*
        // on a settled segment, and free of the residual transient.
        let Some(ws) = tail_omega(reference, s.t_start, s.t_end) else {
            continue;
        };
        let w = |tr: &Trajectory| tail_omega(tr, s.t_start, s.t_end);
        let (Some(w1), Some(w2), Some(w4)) = (w(fine), w(&mid), w(&coarse)) else {
            continue;
        };
        let p = ((w4 - w2).abs() / (w2 - w1).abs()).log2();
        out.orders.push((s.index, p));
        // Richardson with the scheme's order p, then once more for p + 1.
        let k1 = 2f64.powf(order) - 1.0;
        let k2 = 2f64.powf(order + 1.0) - 1.0;
        let r1 = w1 + (w1 - w2) / k1;
        let r1_coarse = w2 + (w2 - w4) / k1;
        let r2 = r1 + (r1 - r1_coarse) / k2;
        let e = |x: f64| rel_err(x, ws, s.speed, sc.froude_length());
        out.richardson1_rel_max = out.richardson1_rel_max.max(e(r1));
        out.richardson2_rel_max = out.richardson2_rel_max.max(e(r2));
        out.plain_rel_max = out.plain_rel_max.max(e(w1));
        out.diff_rel
            .push((s.index, rel_err(w2, w1, s.speed, sc.froude_length())));
    }
    Ok(out)
}
