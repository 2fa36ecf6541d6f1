//! An engine's run read against the friction law the engine declares
//! ([`pushval_engine::FrictionLaw`]): the tail mean of ω over whole periods
//! of an angle-dependent law, the law evaluated on the loads the engine
//! itself carried, and the row of numbers a run reduces to against
//! Coulomb and the law ([`run_row`]). What `pushval study` reports per run;
//! they compare a run with a model, as the rest of the harness does.

use pushval_engine::{tail_loads, tail_mean_omega, Engine, LawClass};
use pushval_model::{ModelError, Problem, SegmentDynamics, Trajectory};

/// The mean ω (rad/s) of the first segment over the longest part of its
/// tail (its last `tail` share) that ends at the segment's end and turns the
/// object by a whole number of `period`s (rad): the mean a law that depends
/// on the angle predicts (`FrictionLaw::angle_period`), which a tail cut
/// mid-period misses by up to a few per cent. The start is interpolated
/// linearly between samples. None where the tail turns less than a period.
pub fn whole_period_omega(p: &Problem, traj: &Trajectory, tail: f64, period: f64) -> Option<f64> {
    let (t0, t1) = p.segment_times()[0];
    let from = t1 - tail * (t1 - t0);
    let s: Vec<_> = traj
        .samples
        .iter()
        .filter(|s| s.t >= from - 1e-12 && s.t <= t1 + 1e-12)
        .collect();
    let (first, last) = (s.first()?, s.last()?);
    let turn = last.theta - first.theta;
    let n = (turn.abs() / period).floor();
    if n < 1.0 || !turn.is_finite() {
        return None;
    }
    let target = n * period;
    // The latest sample that has turned the target by the end, walking back.
    let k = (0..s.len())
        .rev()
        .find(|&k| (last.theta - s[k].theta).abs() >= target)?;
    let (a, b) = (s[k], s[(k + 1).min(s.len() - 1)]);
    let (da, db) = ((last.theta - a.theta).abs(), (last.theta - b.theta).abs());
    let start = if da > db {
        a.t + (b.t - a.t) * (da - target) / (da - db)
    } else {
        a.t
    };
    (last.t > start).then(|| turn.signum() * target / (last.t - start))
}

/// The most tail samples [`law_on_run_loads`] evaluates a law without
/// dynamics at (quasi-statically).
pub const LAW_RUN_SAMPLES: usize = 40;

/// The law on the run's own loads over the tail of segment `seg` (its
/// last `tail` share): the mean of the law's ω over the tail samples
/// (`omega_law_run`, rad/s) and the RMS of the engine's ω against it
/// (`law_run_rms`, rad/s). NaN where the engine's loads do not cover the
/// supports or the law has no value on them.
///
/// A law with dynamics ([`pushval_engine::FrictionLaw::dynamics_on_loads`],
/// Coulomb on the loads) is integrated in time: from the engine's ω at the
/// tail's first sample, each interval between samples under the loads the
/// engine carried over it (the recorder's interval means), so loads that
/// change faster than the law settles act through its transient. Any other
/// law is taken quasi-statically, at most [`LAW_RUN_SAMPLES`] samples evenly
/// spaced: at each, the steady ω its friction rule gives with that sample's
/// loads (an angle-dependent law's steady ω is a period mean that costs
/// hundreds of roots).
pub fn law_on_run_loads(
    law: &dyn pushval_engine::FrictionLaw,
    p: &Problem,
    seg: usize,
    dt: f64,
    tail: f64,
    run: &pushval_engine::EngineRun,
    contact: &pushval_engine::ContactRecord,
) -> (f64, f64) {
    let (t0, t1) = p.segment_times()[seg];
    let from = t1 - tail * (t1 - t0);
    let tail: Vec<_> = run
        .trajectory
        .samples
        .iter()
        .zip(&contact.loads)
        .filter(|(s, _)| s.t >= from - 1e-12 && s.t <= t1 + 1e-12)
        .collect();
    let Some(&(first, _)) = tail.first() else {
        return (f64::NAN, f64::NAN);
    };
    let mut pairs = Vec::with_capacity(tail.len());
    if law_integrates(law, p, seg, dt) {
        // Without load the law applies no friction: ω̇ = k ω / I_P, the
        // inertial term alone, exactly e^(k t / I_P).
        let free = SegmentDynamics::new(&p.body, &p.pushes[seg]);
        let rate = free.inertial_slope() / free.inertia_contact();
        let mut w = first.omega;
        pairs.push((first.omega, w));
        for pair in tail.windows(2) {
            let ((a, _), (b, loads)) = (pair[0], pair[1]);
            let span = b.t - a.t;
            let next = if loads.len() == p.body.len() && loads.iter().all(|&l| l == 0.0) {
                Some(w * (rate * span).exp())
            } else {
                law.dynamics_on_loads(p, seg, dt, loads)
                    .and_then(|d| d.advance(w, span))
            };
            let Some(next) = next else {
                return (f64::NAN, f64::NAN);
            };
            w = next;
            pairs.push((b.omega, w));
        }
    } else {
        let m = tail.len().min(LAW_RUN_SAMPLES);
        for j in 0..m {
            let k = if m < 2 {
                tail.len() - 1
            } else {
                j * (tail.len() - 1) / (m - 1)
            };
            let (s, loads) = tail[k];
            let Some(w) = law.steady_on_loads(p, seg, dt, loads) else {
                return (f64::NAN, f64::NAN);
            };
            pairs.push((s.omega, w.omega));
        }
    }
    let n = pairs.len() as f64;
    let mean = pairs.iter().map(|(_, w)| w).sum::<f64>() / n;
    let rms = (pairs.iter().map(|(e, w)| (e - w).powi(2)).sum::<f64>() / n).sqrt();
    (mean, rms)
}

/// Whether `law` has dynamics a study integrates along a run's loads
/// ([`pushval_engine::FrictionLaw::dynamics_on_loads`] on the problem's
/// rest loads, the statics of its weight).
pub fn law_integrates(
    law: &dyn pushval_engine::FrictionLaw,
    p: &Problem,
    seg: usize,
    dt: f64,
) -> bool {
    let body = &p.body;
    pushval_laws::mujoco::rest_loads(body, body.mass() * pushval_engine::GRAVITY)
        .is_some_and(|rest| law.dynamics_on_loads(p, seg, dt, &rest).is_some())
}

/// Supports whose loads a row carries (the plate's four).
pub const LOADS: usize = 4;

/// Values of a run's row: ω of the engine, of Coulomb and of the law
/// (rad/s), the law's class code ([`class_code`]) and its rest moments,
/// then [`LOADS`] support loads measured by the engine and as many
/// predicted by the law (N; NaN where unknown), the engine's angle at the
/// end of the run (rad), then what the run's own loads give
/// ([`LAW_RUN`]): the law's ω on them (tail mean, rad/s), the RMS of the
/// engine's ω against it over the tail (rad/s), the largest rise (m) and the
/// share of steps with a support out of contact, and the smallest and
/// largest per-step load of any support (N).
pub const RUN_WIDTH: usize = 14 + 2 * LOADS;

/// Index in a run's row of `omega_law_run`; `law_run_rms`, `max_rise_m`,
/// `contact_lost_share`, `load_min` and `load_max` follow it.
pub const LAW_RUN: usize = 8 + 2 * LOADS;

/// The code of a class in a row: 0 turns, 1 locked, 2 semi-stable; NaN none.
pub fn class_code(c: Option<LawClass>) -> [f64; 4] {
    match c {
        None => [f64::NAN; 4],
        Some(LawClass::Turns) => [0.0, f64::NAN, f64::NAN, f64::NAN],
        Some(LawClass::Locked) => [1.0, f64::NAN, f64::NAN, f64::NAN],
        Some(LawClass::SemiStable { moment, lock, hold }) => [2.0, moment, lock, hold],
    }
}

/// The class name of a code (empty for none).
pub fn class_name(code: f64) -> &'static str {
    ["turns", "locked", "semi_stable"]
        .into_iter()
        .enumerate()
        .find(|(i, _)| *i as f64 == code)
        .map_or("", |(_, n)| n)
}

/// The row of `engine` run on `p` at `dt` ([`RUN_WIDTH`] values), its
/// tail the last `tail` share of the last segment: the engine's tail-mean
/// ω and loads, Coulomb's ω*, the law's ω, class and loads, and the law on
/// the run's own loads; with the engine's error where the run failed (its
/// values then NaN, the models' still given).
pub fn run_row(
    engine: &dyn Engine,
    p: &Problem,
    dt: f64,
    tail: f64,
) -> (Vec<f64>, Option<ModelError>) {
    let (run, failed) = match engine.run(p, dt) {
        Ok(r) => (Some(r), None),
        Err(e) => (None, Some(e)),
    };
    // The last segment: the push, or the rest after a stop, where ω is the
    // mean |ω| over the tail (a signed mean hides a chattering stop).
    let seg = p.pushes.len() - 1;
    let law = engine.law();
    let period = law.and_then(|l| l.angle_period(p));
    let omega = run
        .as_ref()
        .and_then(|r| {
            if seg == 0 {
                let whole = period.and_then(|a| whole_period_omega(p, &r.trajectory, tail, a));
                return whole.or_else(|| tail_mean_omega(p, &r.trajectory, tail)[0]);
            }
            let t1 = p.segment_times()[seg].1;
            let w: Vec<f64> = r
                .trajectory
                .samples
                .iter()
                .filter(|s| s.t >= t1 - tail * p.pushes[seg].duration)
                .map(|s| s.omega.abs())
                .collect();
            Some(w.iter().sum::<f64>() / w.len() as f64)
        })
        .unwrap_or(f64::NAN);
    let coulomb = pushval_engine::coulomb_steady(p, seg).unwrap_or(f64::NAN);
    let steady = law.and_then(|l| l.steady(p, seg, dt));
    let mut row = vec![omega, coulomb, steady.map_or(f64::NAN, |l| l.omega)];
    row.extend(class_code(steady.map(|l| l.class)));
    for loads in [
        run.as_ref().and_then(tail_loads),
        law.and_then(|l| l.loads(p, seg, dt)),
    ] {
        let loads = loads.unwrap_or_default();
        row.extend((0..LOADS).map(|k| loads.get(k).copied().unwrap_or(f64::NAN)));
    }
    let end = run.as_ref().and_then(|r| r.trajectory.samples.last());
    row.push(end.map_or(f64::NAN, |s| s.theta));
    let contact = run.as_ref().and_then(|r| Some((r, r.contact.as_ref()?)));
    let (law_run, rms) = match (contact, law) {
        (Some((r, c)), Some(law)) => law_on_run_loads(law, p, seg, dt, tail, r, c),
        _ => (f64::NAN, f64::NAN),
    };
    row.extend([
        law_run,
        rms,
        contact.map_or(f64::NAN, |(_, c)| c.max_rise_m),
        contact.map_or(f64::NAN, |(_, c)| c.contact_lost_share),
        contact.map_or(f64::NAN, |(_, c)| c.load_range[0]),
        contact.map_or(f64::NAN, |(_, c)| c.load_range[1]),
    ]);
    (row, failed)
}
