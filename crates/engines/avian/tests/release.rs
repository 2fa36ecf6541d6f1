//! Avian lets go (issue 46, item 2). What each scene's law predicts for the
//! slide, and what is checked:
//!
//! * `avian2d`: the revolute joint is despawned and the supports' friction,
//!   applied by hand in Avian's substep loop, becomes the free slide's
//!   implicit Coulomb impulses (`pushval_engine::slide::coulomb_impulses`,
//!   substep by substep: each within its disc `μᵢNᵢ h_s`, jointly the ones
//!   that leave the slip zero where the discs allow), so a plate a substep
//!   can stop comes to rest instead of its slip reversing every substep. In
//!   pure translation it stops at `v²/(2μg)` after `v/(μg)`: the rest is
//!   seen at the end of the step in which the velocity reaches zero (within
//!   a step), the distance within `v h_s` (first order in the substep
//!   `h_s = h/16`); a thrown spinning square and a pushed plate rest where
//!   the dynamic model says, within a first-order error in the substep.
//! * `avian3d`: the pin is despawned and the plate slides on Avian's own
//!   contact friction, Coulomb's at every foot (a 2-D impulse per contact
//!   point clamped to the disc `μλ`, solved implicitly every substep, so a
//!   slip a substep can remove is removed and the plate sticks): the closed
//!   form in translation; a thrown spinning square's rest is printed
//!   against the model's.
//! * Both: a release after a push continues from the pushed state.
#![cfg(feature = "avian")]

use pushval_engine::{rest_speed, Engine, EngineRun, REST_SPEED};
use pushval_model::{DynamicModel, Initial, Problem, Push, Sample, Simulator, Vec2};

const G: f64 = 9.81;
/// The seed plate's friction coefficient.
const MU: f64 = Problem::SEED_MU;

/// The seed plate (0.25 m square, 1 kg, μ 0.5 on its four corners, pushed
/// at the middle of its left side) with a release after `pushes`.
fn problem(pushes: Vec<Push>, initial: Initial) -> Problem {
    Problem::seed_plate(G, pushes, initial).unwrap()
}

/// A plate thrown from the origin at angle `theta` with centre-of-mass
/// velocity `v` (m/s) and spin `omega` (rad/s).
fn thrown(v: [f64; 2], theta: f64, omega: f64) -> Problem {
    problem(
        vec![],
        Initial {
            theta,
            omega,
            position: Vec2::new(0.0, 0.0),
            velocity: Vec2::new(v[0], v[1]),
            from_rest: false,
        },
    )
}

/// The rest (last row) and stop time of a run through the slide.
fn rest(run: &EngineRun) -> (Sample, f64) {
    let slide = run.trajectory.slide.as_ref().expect("a slide report");
    let stop = slide.t_stop.expect("the plate stops");
    let last = *run.trajectory.samples.last().unwrap();
    assert_eq!(last.t, stop, "the last row is the rest");
    (last, stop)
}

/// Two pushes from rest (the second turned), for the releases after a push.
const PUSHES: [Push; 2] = [
    Push {
        duration: 0.3,
        speed: 0.6,
        phi: 0.0,
    },
    Push {
        duration: 0.2,
        speed: 0.8,
        phi: 0.4,
    },
];

/// A release after [`PUSHES`] continues from the pushed state: the slide
/// starts at the push's end (its row in the run is that state), and over
/// its first `n` steps (`T = n h`) the plate moves on with the velocity it
/// had: friction slows the centre of mass by at most `a_max` (m/s²), so the
/// displacement differs from `v T` by at most `a_max T²` (twice the
/// semi-implicit Euler bound `½ a T² (1 + 1/n)`). A full release from the
/// same push must then come to rest when `stops`.
fn continues_from_the_pushed_state(e: &dyn Engine, h: f64, a_max: f64, stops: bool) {
    let p = problem(PUSHES.to_vec(), Initial::default());
    let t = 10.0 * h;
    let mut s = e.start(&p, h).unwrap();
    for q in &PUSHES {
        s.advance(q).unwrap();
    }
    let st = s.state();
    let speed = f64::hypot(st.v_cm[0], st.v_cm[1]);
    assert!(speed > 0.3, "{}: the pushed plate is not moving", e.name());
    s.release(t).unwrap();
    let report = s.slide().unwrap();
    assert_eq!(report.t_release, st.t, "{}", e.name());
    assert_eq!(report.t_stop, None, "{}", e.name());
    let after = s.state();
    assert!((after.t - st.t - t).abs() < 1e-9, "{}", e.name());
    let dev = f64::hypot(
        after.x - st.x - st.v_cm[0] * t,
        after.y - st.y - st.v_cm[1] * t,
    );
    eprintln!(
        "{}: released at {speed:.3} m/s; after {t} s {dev:.2e} m from the pushed motion (bound {:.2e})",
        e.name(),
        a_max * t * t
    );
    assert!(dev <= a_max * t * t, "{}: {dev} m", e.name());
    assert!(dev > 0.0, "{}: no friction", e.name());
    let run = s.finish().unwrap();
    let row = run
        .trajectory
        .samples
        .iter()
        .find(|r| r.t == st.t)
        .expect("the release row");
    assert_eq!((row.x, row.y, row.theta), (st.x, st.y, st.theta));
    drop(run);

    let mut s = e.start(&p, h).unwrap();
    for q in &PUSHES {
        s.advance(q).unwrap();
    }
    s.release(10.0).unwrap();
    let end = s.state();
    let stop = s.slide().unwrap().t_stop;
    eprintln!(
        "{}: after the push slid {:.1} mm, stop {:?}",
        e.name(),
        1e3 * f64::hypot(end.x - st.x, end.y - st.y),
        stop.map(|t| t - st.t)
    );
    if stops {
        assert_eq!(stop, Some(end.t), "{}: no rest", e.name());
        assert!(rest_speed(&p, end.v_cm, end.omega) < REST_SPEED);
    }
}

/// A thrown spinning square: it stops (at rest by the rule) when `stops`;
/// its gap to the Coulomb model's rest is printed (the engines' laws are
/// not Coulomb's at each support, so it is reported, not held).
fn thrown_square(e: &dyn Engine, h: f64, stops: bool) {
    let p = thrown([0.8, 0.3], 0.2, 4.0);
    let model = DynamicModel::default().simulate(&p).unwrap();
    let ml = *model.samples.last().unwrap();
    let run = e.run(&p, h).unwrap();
    let last = *run.trajectory.samples.last().unwrap();
    let stop = run.trajectory.slide.as_ref().unwrap().t_stop;
    eprintln!(
        "{} thrown square: rest {:.2e} m and {:.2e} rad from the model's, stop {:?} (model {:.4} s)",
        e.name(),
        f64::hypot(last.x - ml.x, last.y - ml.y),
        (last.theta - ml.theta).abs(),
        stop,
        ml.t
    );
    if stops {
        assert_eq!(stop, Some(last.t), "{}: no rest", e.name());
    }
}

fn engine(name: &str) -> Box<dyn Engine> {
    pushval_avian::models()
        .into_iter()
        .find(|m| m.name == name)
        .expect("registered")
        .default_engine()
}

/// The substeps per step (Avian's solver loop; `DEFAULT_SUBSTEPS`).
const SUBSTEPS: f64 = pushval_avian::DEFAULT_SUBSTEPS as f64;

#[test]
fn avian2d_pure_translation_stops_at_the_closed_form() {
    let e = engine("avian2d");
    let h = 1e-3;
    for (v, theta) in [([1.0, 0.0], 0.0), ([0.3, -0.4], 0.7)] {
        let (last, stop) = rest(&e.run(&thrown(v, theta, 0.0), h).unwrap());
        let speed = f64::hypot(v[0], v[1]);
        let (t_cf, d_cf) = (speed / (MU * G), speed * speed / (2.0 * MU * G));
        let d = f64::hypot(last.x, last.y);
        eprintln!("avian2d {v:?}: {d:.6} m ({d_cf:.6}), stop {stop:.4} s ({t_cf:.4})");
        assert!(
            stop >= t_cf - 1e-9 && stop <= t_cf + h + 1e-9,
            "stop {stop} s"
        );
        assert!(
            (d - d_cf).abs() <= speed * h / SUBSTEPS,
            "{d} m, closed form {d_cf} m"
        );
        let along = (last.x * v[0] + last.y * v[1]) / speed;
        assert!((along - d).abs() < 1e-9, "off its line");
        assert!((last.theta - theta).abs() < 1e-9, "turned");
    }
}

/// The gaps of avian2d's rest to the dynamic model's on `p`: position (m),
/// angle (rad), stop time (s).
fn gaps(p: &Problem, h: f64) -> (f64, f64, f64) {
    let model = DynamicModel::default().simulate(p).unwrap();
    let m_stop = model.slide.as_ref().unwrap().t_stop.unwrap();
    let ml = *model.samples.last().unwrap();
    let (last, stop) = rest(&engine("avian2d").run(p, h).unwrap());
    (
        f64::hypot(last.x - ml.x, last.y - ml.y),
        (last.theta - ml.theta).abs(),
        (stop - m_stop).abs(),
    )
}

/// A thrown spinning square and a pushed plate: avian2d rests where the
/// model says within a first-order error in the substep (the friction's
/// slip is taken once per substep), and the error falls when the step does.
#[test]
fn avian2d_rests_where_the_model_says() {
    let push = Push {
        duration: 0.4,
        speed: 0.5,
        phi: 0.3,
    };
    for p in [
        thrown([0.8, 0.3], 0.2, 4.0),
        problem(vec![push], Initial::default()),
    ] {
        let h = 1e-3;
        let (dx, dth, dt) = gaps(&p, h);
        let (dx2, dth2, _) = gaps(&p, h / 2.0);
        eprintln!(
            "avian2d rest gap {dx:.2e} → {dx2:.2e} m, {dth:.2e} → {dth2:.2e} rad, stop {dt:.2e} s"
        );
        let hs = h / SUBSTEPS;
        assert!(
            dx <= 2.0 * hs && dth <= 20.0 * hs && dt <= h + 1e-9,
            "{dx} {dth} {dt}"
        );
        assert!(
            dx2 <= 0.7 * dx + 1e-9 && dth2 <= 0.7 * dth + 1e-9,
            "no convergence"
        );
    }
}

#[test]
fn a_release_after_a_push_continues_from_the_pushed_state() {
    for name in ["avian2d", "avian3d"] {
        continues_from_the_pushed_state(engine(name).as_ref(), 1e-3, MU * G, true);
    }
}

#[test]
fn a_thrown_spinning_square_stops() {
    for name in ["avian2d", "avian3d"] {
        thrown_square(engine(name).as_ref(), 1e-3, true);
    }
}

/// avian3d in pure translation: Avian's contact friction is Coulomb's at
/// every foot (`pushval_laws::avian`: a 2-D impulse per contact point,
/// clamped to the disc `μλ`, along the slip), solved implicitly every
/// substep, so the plate stops at `v²/(2μg)` (within `v h_s`) and, the
/// contact solver's last residual taking one more step to fall below the
/// rest speed, within two steps of `v/(μg)`.
#[test]
fn avian3d_pure_translation_stops_at_the_closed_form() {
    let e = engine("avian3d");
    let h = 1e-3;
    for (v, theta) in [([1.0, 0.0], 0.0), ([0.3, -0.4], 0.7)] {
        let (last, stop) = rest(&e.run(&thrown(v, theta, 0.0), h).unwrap());
        let speed = f64::hypot(v[0], v[1]);
        let (t_cf, d_cf) = (speed / (MU * G), speed * speed / (2.0 * MU * G));
        let d = f64::hypot(last.x, last.y);
        eprintln!("avian3d {v:?}: {d:.6} m ({d_cf:.6}), stop {stop:.4} s ({t_cf:.4})");
        assert!(
            stop >= t_cf - 1e-9 && stop <= t_cf + 2.0 * h + 1e-9,
            "stop {stop} s"
        );
        assert!(
            (d - d_cf).abs() <= speed * h / SUBSTEPS,
            "{d} m, closed form {d_cf} m"
        );
        let along = (last.x * v[0] + last.y * v[1]) / speed;
        assert!((along - d).abs() < 1e-6 * d_cf, "off its line");
        assert!((last.theta - theta).abs() < 1e-6, "turned");
    }
}
