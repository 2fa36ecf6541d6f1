//! The dynamic model asked for less: [`DynamicModel::final_state`] (the end
//! state alone) and [`DynamicModel::sample_at`] (the caller's times) against
//! the full sampled run they must agree with, and the final state against a
//! much tighter run (its error stays within the tolerance's bound); the
//! final state with the pushes' analysis cached against the one without.

use pushval_model::{
    DynamicModel, FinalState, Initial, Integrator, ModelError, Problem, Push, PushCache, Simulator,
    Switching, Trajectory,
};
use rstest::rstest;

mod common;
use common::*;

/// The paper-style schedule at 1 m/s: five 2 s segments, impulsive switches.
fn paper_problem() -> Problem {
    let pushes = [PHI, std::f64::consts::FRAC_PI_4, 0.485, 1.285, 0.935]
        .iter()
        .map(|&phi| Push {
            duration: 2.0,
            speed: 1.0,
            phi,
        })
        .collect();
    problem(
        paper_plate(),
        pushes,
        Initial::default(),
        Switching::Impulsive,
    )
}

/// The model-predictive controller's horizon: six 0.1 s pushes from rest
/// whose directions step about the diagonal.
fn short_horizon() -> Problem {
    let q = std::f64::consts::FRAC_PI_4;
    let pushes = [q + 0.3, q, q - 0.3, q + 0.5, q + 0.15, q - 0.1]
        .iter()
        .map(|&phi| Push {
            duration: 0.1,
            speed: 1.0,
            phi,
        })
        .collect();
    let mut p = problem(
        paper_plate(),
        pushes,
        Initial {
            from_rest: true,
            ..Default::default()
        },
        Switching::Impulsive,
    );
    p.sample_dt = 0.013;
    p
}

/// A schedule with a pivot (a heavily loaded corner), a held contact
/// (speed 0: the plate turns about the contact until friction stops it)
/// and a continuous switch.
fn pivot_and_hold() -> Problem {
    let pushes = vec![
        Push {
            duration: 0.4,
            speed: 0.3,
            phi: 0.0,
        },
        Push {
            duration: 0.2,
            speed: 0.0,
            phi: 0.0,
        },
        Push {
            duration: 0.5,
            speed: 0.5,
            phi: 0.6,
        },
    ];
    problem(
        pivot_body(),
        pushes,
        Initial {
            omega: 0.7,
            ..Default::default()
        },
        Switching::Continuous,
    )
}

fn model(integrator: Integrator, skip_settled: bool) -> DynamicModel {
    DynamicModel {
        integrator,
        skip_settled,
        check_assumptions: false,
        ..Default::default()
    }
}

/// Distance between the final state and a sample (m), and the angle and ω
/// differences.
fn gap(f: &FinalState, s: &pushval_model::Sample) -> (f64, f64, f64) {
    (
        ((f.x - s.x).powi(2) + (f.y - s.y).powi(2)).sqrt(),
        (f.theta - s.theta).abs(),
        (f.omega - s.omega).abs(),
    )
}

/// The final state is the full run's last sample, to within the
/// tolerance. Without the settled-arc shortcut both take the same steps and
/// differ only by rounding (≤ 1e-12 m, rad, rad/s). With it, a settling
/// segment ends by the series in δ where the sampled run follows the series
/// in E: two closed forms, each within a share of the tolerance of the
/// motion, and hand-overs at other steps, so they agree to within a few
/// tolerances (10 × tol here; RK4's tolerance is dt⁴) plus twice the
/// sampled run's own error against a DOP853 run at 1e-13 without closed
/// forms (what the integrator leaves between two hand-over points; it
/// matters for fixed-step RK4). Every integrator.
#[rstest]
fn final_state_is_the_last_sample(
    #[values(paper_problem(), short_horizon(), pivot_and_hold())] p: Problem,
    #[values(
        Integrator::Dop853 { tol: 1e-9 },
        Integrator::Dop853 { tol: 1e-12 },
        Integrator::Adaptive { tol: 1e-8 },
        Integrator::Rk4 { dt: 1e-3 }
    )]
    integrator: Integrator,
    #[values(true, false)] skip_settled: bool,
) {
    let m = model(integrator, skip_settled);
    let full = m.simulate(&p).unwrap();
    let f = m.final_state(&p).unwrap();
    let last = full.samples.last().unwrap();
    assert_eq!(f.t, last.t);
    let (dp, dth, dw) = gap(&f, last);
    let tol = match integrator {
        Integrator::Dop853 { tol } | Integrator::Adaptive { tol } => tol,
        Integrator::Rk4 { dt } => dt.powi(4),
    };
    let bound = if skip_settled {
        let reference = model(Integrator::Dop853 { tol: 1e-13 }, false)
            .simulate(&p)
            .unwrap();
        let r = reference.samples.last().unwrap();
        let own = ((last.x - r.x).hypot(last.y - r.y)).max((last.theta - r.theta).abs());
        10.0 * tol + 2.0 * own
    } else {
        1e-12
    };
    assert!(
        dp <= bound && dth <= bound && dw <= bound * (1.0 + last.omega.abs()),
        "{integrator:?}, skip {skip_settled}: {dp:e} m, {dth:e} rad, {dw:e} rad/s"
    );
    if skip_settled {
        // Never more work than the sampled run, less any dense output.
        assert!(f.stats.steps <= full.stats.steps);
    } else {
        assert_eq!(f.stats.steps, full.stats.steps);
    }
    assert!(f.stats.rhs_evals <= full.stats.rhs_evals);
}

/// At tolerance 1e-9 the final state is within ten times the tolerance of
/// a DOP853 run at 1e-13 that integrates every segment to its end (it
/// shares no closed form with the run it checks), the bound the sampled
/// run meets over all its samples.
#[rstest]
fn final_state_meets_its_tolerance(
    #[values(paper_problem(), short_horizon(), pivot_and_hold())] p: Problem,
    #[values(true, false)] eighth: bool,
) {
    let tol = 1e-9;
    let reference = model(Integrator::Dop853 { tol: 1e-13 }, false)
        .simulate(&p)
        .unwrap();
    let integrator = if eighth {
        Integrator::Dop853 { tol }
    } else {
        Integrator::Adaptive { tol }
    };
    let f = model(integrator, true).final_state(&p).unwrap();
    let (dp, dth, _) = gap(&f, reference.samples.last().unwrap());
    assert!(
        dp <= 10.0 * tol && dth <= 10.0 * tol,
        "{integrator:?}: {dp:e} m, {dth:e} rad"
    );
}

/// The centre of mass's velocity at the end is the derivative of its path:
/// a one-sided second-order difference of the positions sampled just
/// before the end, `(3 x(T) − 4 x(T − h) + x(T − 2h)) / 2h`, whose error is
/// O(h²) (≈ 1e-8 m/s here, against speeds of order 1 m/s).
#[rstest]
fn final_velocity_is_the_paths_derivative(
    #[values(paper_problem(), short_horizon(), pivot_and_hold())] p: Problem,
) {
    let m = model(Integrator::Dop853 { tol: 1e-13 }, true);
    let f = m.final_state(&p).unwrap();
    let h = 1e-4;
    let end = p.duration();
    let tr = m.sample_at(&p, &[end - 2.0 * h, end - h, end]).unwrap();
    let s = &tr.samples;
    assert_eq!(s.len(), 3);
    let d = |a: f64, b: f64, c: f64| (3.0 * c - 4.0 * b + a) / (2.0 * h);
    let (vx, vy) = (d(s[0].x, s[1].x, s[2].x), d(s[0].y, s[1].y, s[2].y));
    let err = ((f.vx - vx).powi(2) + (f.vy - vy).powi(2)).sqrt();
    assert!(
        err <= 1e-6 * (1.0 + vx.hypot(vy)),
        "({}, {}) against ({vx}, {vy})",
        f.vx,
        f.vy
    );
}

/// Samples at the caller's times are the full run's samples at those times
/// (every seventh of the grid, a switch time among them): the same run,
/// other times asked.
#[rstest]
fn sample_at_matches_the_full_run(
    #[values(paper_problem(), short_horizon(), pivot_and_hold())] p: Problem,
) {
    let m = DynamicModel::default();
    let full: Trajectory = m.simulate(&p).unwrap();
    let pick: Vec<_> = full.samples.iter().step_by(7).copied().collect();
    let times: Vec<f64> = pick.iter().map(|s| s.t).collect();
    let some = m.sample_at(&p, &times).unwrap();
    assert_eq!(some.samples.len(), pick.len());
    for (a, b) in some.samples.iter().zip(&pick) {
        assert_eq!(a.t, b.t);
        let dp = ((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt();
        assert!(dp <= 1e-12, "t {}: {dp:e} m", a.t);
        assert!((a.theta - b.theta).abs() <= 1e-12, "t {}", a.t);
    }
    assert_eq!(some.segments, full.segments);
    // No time asked: no sample, the same segments.
    let none = m.sample_at(&p, &[]).unwrap();
    assert!(none.samples.is_empty());
    assert_eq!(none.segments, full.segments);
}

/// Times out of order, past the end or not finite are refused, naming the
/// sample time.
#[test]
fn sample_at_refuses_bad_times() {
    let p = short_horizon();
    let m = DynamicModel::default();
    for times in [
        vec![0.2, 0.1],
        vec![0.0, p.duration() + 0.01],
        vec![-0.1],
        vec![f64::NAN],
    ] {
        match m.sample_at(&p, &times) {
            Err(ModelError::Parameter { name, .. }) => assert_eq!(name, "sample time"),
            other => panic!("{times:?}: {other:?}"),
        }
    }
}

/// A cache of the pushes' analysis spares work, never changes an answer:
/// over schedules that share pushes the way a planner's calls do (one
/// direction changed at a time, every duration scaled, another start, the
/// slide to rest after the last push), for several tolerances and a held
/// contact and a pivot, the cached final state equals the uncached one to
/// the bit, and the repeated pushes are found in the cache. A new body
/// empties it (the answer is the new body's).
#[test]
fn cached_final_state_is_the_uncached_one_to_the_bit() {
    let mut cache = PushCache::new();
    let mut calls = 0;
    for base in [short_horizon(), paper_problem(), pivot_and_hold()] {
        for tol in [1e-9, 1e-10, 3.162e-8] {
            let m = model(Integrator::Dop853 { tol }, true);
            let mut variants = vec![base.clone()];
            for k in 0..base.pushes.len() {
                let mut p = base.clone();
                p.pushes[k].phi += 1e-6;
                variants.push(p);
            }
            let mut longer = base.clone();
            longer.pushes.iter_mut().for_each(|q| q.duration *= 1.07);
            variants.push(longer);
            let mut moving = base.clone();
            moving.initial = Initial {
                omega: -0.4,
                ..Default::default()
            };
            variants.push(moving);
            let mut to_rest = base.clone();
            to_rest.release = Some(Default::default());
            variants.push(to_rest);
            for p in &variants {
                let cold = m.final_state(p).unwrap();
                let warm = m.final_state_cached(p, &mut cache).unwrap();
                assert_eq!(warm, cold, "tol {tol}");
                calls += 1;
            }
        }
    }
    let (hits, misses) = cache.hits_misses();
    assert!(
        hits > 4 * misses,
        "{hits} hits, {misses} misses in {calls} calls"
    );
    // Another body: the cache forgets the old one's roots and series.
    let mut p = short_horizon();
    p.body = square(0.3, 1.5, 0.4, 9.81);
    let m = model(Integrator::Dop853 { tol: 1e-9 }, true);
    assert_eq!(
        m.final_state_cached(&p, &mut cache).unwrap(),
        m.final_state(&p).unwrap()
    );
}

/// The end of a settling segment by the series in δ, over the ground it
/// must cover: one push on the paper plate and on a plate with a heavily
/// loaded corner, in eight directions, from starts on either side of the
/// root (and at rest: a root ω* = 0 among them, where the contact point's
/// sum takes its short form), at three speeds and over spans from a third
/// of τ to twenty τ. Against a DOP853 run at 1e-13 that takes no closed
/// form, the final state at tolerance 1e-10 is within 10 × tol (m, rad) of
/// what DOP853 at 1e-10 leaves without closed forms (the series add at
/// most that; a start beyond their radius is integrated until they hold,
/// never answered from them).
#[rstest]
fn a_settling_segments_end_meets_its_tolerance(
    #[values(paper_plate(), pivot_body())] body: pushval_model::Body,
    #[values(0.3, 1.0, 2.0)] speed: f64,
) {
    let tol = 1e-10;
    let m = model(Integrator::Dop853 { tol }, true);
    let reference = model(Integrator::Dop853 { tol: 1e-13 }, false);
    let mut worst: (f64, f64) = (0.0, 0.0);
    for k in 0..8 {
        let phi = -1.2 + 0.3 * k as f64;
        for omega in [-3.0, -1.0, -0.2, 0.0, 0.2, 1.0, 3.0] {
            for duration in [0.03, 0.3, 2.0] {
                let mut p = one_push(body.clone(), duration, speed, phi);
                p.initial = Initial {
                    omega,
                    ..Default::default()
                };
                let Ok(f) = m.final_state(&p) else { continue };
                let r = reference.simulate(&p).unwrap();
                let (dp, dth, _) = gap(&f, r.samples.last().unwrap());
                // What the integrator alone leaves, over the same span.
                let plain = model(Integrator::Dop853 { tol }, false)
                    .final_state(&p)
                    .unwrap();
                let (pp, pth, _) = gap(&plain, r.samples.last().unwrap());
                assert!(
                    dp <= 10.0 * tol + pp && dth <= 10.0 * tol + pth,
                    "phi {phi}, omega {omega}, duration {duration}, speed {speed}: {dp:e} m, {dth:e} rad"
                );
                worst = (worst.0.max(dp), worst.1.max(dth));
            }
        }
    }
    eprintln!("worst {:e} m, {:e} rad", worst.0, worst.1);
}
