//! An engine's run read against the friction law the engine declares
//! ([`pushval_engine::FrictionLaw`]): the tail mean of ω over whole periods
//! of an angle-dependent law, and the law evaluated on the loads the engine
//! itself carried. What `pushval study` reports per run; they compare a
//! run with a model, as the rest of the harness does.

use pushval_model::{Problem, SegmentDynamics, Trajectory};

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
