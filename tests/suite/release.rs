//! Every engine lets go (issue 46, item 2): an engine session releases the
//! plate, which slides on its supports to rest. Checked against physics and
//! the dynamic model (`DynamicModel`, which goes on through the slide on the
//! same problem):
//!
//! * pure translation on supports symmetric about the centre of mass stops
//!   after t = v/(μg), having travelled d = v²/(2μg), without turning;
//! * a square plate thrown sliding and spinning rests where the model says,
//!   at the model's stop time, within a first-order error in the step
//!   (the engines' friction is integrated once per step: implicit or
//!   semi-implicit Euler), which halves with the step;
//! * the engine's rest state is at rest (its speed below the rest rule's),
//!   the run's last row is the rest, and a slide cut short by
//!   `max_duration` is reported as not stopped;
//! * an engine that cannot release refuses, naming the engine and the
//!   release.

use pushval_engine::{rest_speed, Engine, EngineRun, REST_SPEED};
use pushval_model::{
    Body, ContactLimits, DynamicModel, Initial, ModelError, Problem, Push, Release, Simulator,
    Support, Switching, Vec2,
};

const G: f64 = 9.81;
/// The seed plate's friction coefficient.
const MU: f64 = 0.5;
/// Half the side of the seed plate (m).
const A: f64 = 0.125;

/// The seed plate (0.25 m square, 1 kg, μ 0.5 on its four corners) with a
/// release after `pushes` from `initial`.
fn problem(pushes: Vec<Push>, initial: Initial) -> Problem {
    let f = MU * G / 4.0;
    let sup: Vec<Support> = [(-A, -A), (A, -A), (A, A), (-A, A)]
        .iter()
        .map(|&(x, y)| Support {
            position: Vec2::new(x, y),
            friction: f,
        })
        .collect();
    Problem {
        body: Body::new(1.0, (2.0 * A) * (2.0 * A) / 6.0, Vec2::new(-A, 0.0), &sup).unwrap(),
        limits: ContactLimits::default(),
        pushes,
        initial,
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: Some(Release::default()),
    }
}

/// A plate thrown from the origin at angle `theta` with centre-of-mass
/// velocity `v` and spin `omega`.
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

fn engine(name: &str) -> Box<dyn Engine> {
    crate::common::use_repo_engines();
    pushval::registry::entry(name)
        .unwrap_or_else(|| panic!("{name} is not registered"))
        .default_engine()
}

/// The engines that release with Coulomb friction at every support, with
/// their steps (s): rapier2d, Box2D and the outside pure_python (protocol 3).
fn releasing() -> Vec<(Box<dyn Engine>, f64)> {
    ["rapier2d", "box2d", "pure_python"]
        .iter()
        .map(|n| {
            let e = engine(n);
            let dt = e.default_dt();
            (e, dt)
        })
        .collect()
}

/// The last row and the stop time of a run through the slide.
fn rest(run: &EngineRun) -> (pushval_model::Sample, f64) {
    let slide = run.trajectory.slide.as_ref().expect("a slide report");
    let stop = slide.t_stop.expect("the plate stops");
    let last = *run.trajectory.samples.last().unwrap();
    assert_eq!(
        last.t, stop,
        "{}: the last row is the rest",
        run.trajectory.model
    );
    (last, stop)
}

/// Pure translation: the supports are symmetric about the centre of mass
/// and carry equal loads, so friction is μmg against the motion with no
/// moment: the plate stops after v/(μg) at v²/(2μg) along its velocity,
/// not turning. A step's friction is applied once per step of h: the stop
/// lands within a step of v/(μg) (the rest is seen at the end of the step
/// in which the velocity reaches zero) and the distance within v h (the
/// semi-implicit position update's first-order error, at most one step at
/// the start speed).
#[test]
fn pure_translation_stops_at_the_closed_form() {
    for (e, h) in releasing() {
        for (v, theta) in [([1.0, 0.0], 0.0), ([0.3, -0.4], 0.7)] {
            let p = thrown(v, theta, 0.0);
            let run = e.run(&p, h).unwrap();
            let (last, stop) = rest(&run);
            let speed = f64::hypot(v[0], v[1]);
            let (t_exact, d_exact) = (speed / (MU * G), speed * speed / (2.0 * MU * G));
            assert!(
                stop >= t_exact - 1e-9 && stop <= t_exact + h + 1e-9,
                "{}: stop {stop} s, closed form {t_exact} s",
                e.name()
            );
            let d = f64::hypot(last.x, last.y);
            assert!(
                (d - d_exact).abs() <= speed * h,
                "{}: {d} m, closed form {d_exact} m",
                e.name()
            );
            // Along the velocity, not turning (to single precision: Box2D
            // keeps its velocities and rotation in f32).
            let along = (last.x * v[0] + last.y * v[1]) / speed;
            let first = run.trajectory.samples[0];
            assert!((along - d).abs() < 1e-6 * d_exact, "{}", e.name());
            assert!(
                (last.theta - first.theta).abs() < 1e-6,
                "{}: turned {} rad",
                e.name(),
                last.theta - first.theta
            );
        }
    }
}

/// The gaps of an engine's rest to the model's: position (m), angle (rad),
/// stop time (s).
fn gaps(e: &dyn Engine, p: &Problem, h: f64) -> (f64, f64, f64) {
    let model = DynamicModel::default().simulate(p).unwrap();
    let m_stop = model.slide.as_ref().unwrap().t_stop.unwrap();
    let m_last = *model.samples.last().unwrap();
    let run = e.run(p, h).unwrap();
    let (last, stop) = rest(&run);
    (
        f64::hypot(last.x - m_last.x, last.y - m_last.y),
        (last.theta - m_last.theta).abs(),
        (stop - m_stop).abs(),
    )
}

/// A square plate thrown sliding and spinning: the engine rests where the
/// model puts it, at the model's stop time, within a first-order error in
/// the step (each step's friction is taken once, from one velocity), and
/// the error halves (within 0.7) when the step does.
#[test]
fn a_thrown_square_rests_where_the_model_says() {
    for (e, h) in releasing() {
        for (v, omega) in [([0.8, 0.3], 4.0), ([-0.5, 0.6], -6.0)] {
            let p = thrown(v, 0.2, omega);
            let speed = f64::hypot(v[0], v[1]) + omega.abs() * A * 2f64.sqrt();
            let (dx, dth, dt) = gaps(e.as_ref(), &p, h);
            eprintln!(
                "{} h {h}: rest gap {dx:.3e} m, {dth:.3e} rad, stop {dt:.3e} s",
                e.name()
            );
            assert!(dx <= 2.0 * speed * h, "{}: {dx} m", e.name());
            assert!(dth <= 2.0 * omega.abs() * h, "{}: {dth} rad", e.name());
            assert!(dt <= 2.0 * h, "{}: {dt} s", e.name());
            let (dx2, dth2, _) = gaps(e.as_ref(), &p, h / 2.0);
            eprintln!("{} h {}: {dx2:.3e} m, {dth2:.3e} rad", e.name(), h / 2.0);
            assert!(
                dx2 <= 0.7 * dx + 1e-9 && dth2 <= 0.7 * dth + 1e-9,
                "{}: no first-order convergence: {dx} → {dx2} m, {dth} → {dth2} rad",
                e.name()
            );
        }
    }
}

/// After a push the plate slides on from the pushed state: the engine's
/// rest is the model's within the first-order bounds above.
#[test]
fn a_pushed_plate_released_rests_where_the_model_says() {
    let push = Push {
        duration: 0.4,
        speed: 0.5,
        phi: 0.3,
    };
    for (e, h) in releasing() {
        let p = problem(vec![push], Initial::default());
        let (dx, dth, dt) = gaps(e.as_ref(), &p, h);
        eprintln!(
            "{} pushed: rest gap {dx:.3e} m, {dth:.3e} rad, stop {dt:.3e} s",
            e.name()
        );
        assert!(
            dx <= 2.0 * h && dth <= 10.0 * h && dt <= 2.0 * h,
            "{}",
            e.name()
        );
    }
}

/// The session's rest state is at rest (speed below the rule's threshold),
/// its time the stop time; no push follows a release; a slide cut short
/// is reported as not stopped, its state still moving.
#[test]
fn the_rest_state_is_at_rest_and_a_short_slide_is_not_rest() {
    for (e, h) in releasing() {
        let p = thrown([0.8, 0.3], 0.2, 4.0);
        let mut s = e.start(&p, h).unwrap();
        assert!(s.slide().is_none());
        s.release(10.0).unwrap();
        let st = s.state();
        let report = s.slide().expect("a report");
        assert_eq!(report.t_stop, Some(st.t), "{}", e.name());
        assert!(
            rest_speed(&p, st.v_cm, st.omega) < REST_SPEED,
            "{}: {st:?}",
            e.name()
        );
        let push = Push {
            duration: 0.1,
            speed: 0.1,
            phi: 0.0,
        };
        assert!(s.advance(&push).is_err(), "{}", e.name());
        let run = s.finish().unwrap();
        assert_eq!(run.trajectory.samples.last().unwrap().t, st.t);
        assert_eq!(run.trajectory.model, e.name());

        let mut short = p.clone();
        short.release = Some(Release { max_duration: 0.05 });
        let run = e.run(&short, h).unwrap();
        let slide = run.trajectory.slide.as_ref().unwrap();
        assert_eq!(slide.t_stop, None, "{}", e.name());
        let last = run.trajectory.samples.last().unwrap();
        assert!((last.t - 0.05).abs() < 1e-12, "{}: {}", e.name(), last.t);
        let mut s = e.start(&short, h).unwrap();
        s.release(0.05).unwrap();
        let st = s.state();
        assert!(
            rest_speed(&p, st.v_cm, st.omega) > 0.1,
            "{}: {st:?}",
            e.name()
        );
    }
}

/// An engine that cannot release refuses a release problem, naming itself
/// and the release; it never runs the pushes and stops there. Every
/// compiled-in engine releases, so the engine here is an outside one
/// declared without a session: a whole-run document has no slide.
#[test]
fn an_engine_that_cannot_release_refuses_naming_it() {
    let p = problem(
        vec![Push {
            duration: 0.2,
            speed: 0.5,
            phi: 0.0,
        }],
        Initial::default(),
    );
    let adapter = crate::common::root().join("adapters/python/pure_python.py");
    let file = crate::common::root().join("pushval.toml");
    let text = format!(
        "[engine.whole_run]\ncommand = [\"python3\", {:?}]\n",
        adapter.display().to_string()
    );
    let config = pushval_outside::Config::from_toml(&text, &file).unwrap();
    let spec = std::sync::Arc::new(config.engines[0].clone());
    let e = pushval_outside::OutsideEngine::new(spec, &Default::default());
    match e.run(&p, 1e-3) {
        Err(err @ ModelError::NoRelease { .. }) => {
            let text = err.to_string();
            assert!(text.contains("whole_run"), "{text}");
            assert!(text.contains("release"), "{text}");
        }
        other => panic!("not refused: {other:?}"),
    }
}

/// rapier3d slides on its own contact friction (the feet on a floor): it
/// must stop (its rest state at rest); where it rests is reported against
/// the model, not held to it (its friction is the engine's contact
/// solver's, not Coulomb's law at each support).
#[test]
fn rapier3d_stops_after_a_throw_and_a_push() {
    let e = engine("rapier3d");
    let h = e.default_dt();
    let push = Push {
        duration: 0.4,
        speed: 0.5,
        phi: 0.3,
    };
    for p in [
        thrown([0.8, 0.3], 0.2, 4.0),
        thrown([1.0, 0.0], 0.0, 0.0),
        problem(vec![push], Initial::default()),
    ] {
        let mut s = e.start(&p, h).unwrap();
        for q in &p.pushes {
            s.advance(q).unwrap();
        }
        s.release(10.0).unwrap();
        let st = s.state();
        assert_eq!(
            s.slide().unwrap().t_stop,
            Some(st.t),
            "rapier3d does not stop"
        );
        assert!(rest_speed(&p, st.v_cm, st.omega) < REST_SPEED, "{st:?}");
        let (dx, dth, dt) = gaps(e.as_ref(), &p, h);
        eprintln!("rapier3d: rest gap {dx:.3e} m, {dth:.3e} rad, stop {dt:.3e} s");
    }
}
