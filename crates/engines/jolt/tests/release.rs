//! Jolt lets go (issue 46, item 2): the pusher's six-DOF constraint is
//! removed and the plate slides to rest under Jolt's own contact friction.
//! Jolt solves friction with sequential impulses at the velocity level:
//! per contact point two tangent impulses, their sum clamped to the disc
//! `μ λ` (Coulomb's cone, not a box). What that predicts, and what is
//! checked:
//!
//! * in pure translation every contact's friction is `μ̄ λ` against the
//!   motion: the plate stops at `v²/(2μg)` after `v/(μg)`; the pose is
//!   integrated from the step's end velocity (symplectic Euler), so the
//!   distance falls short by `v h/2` (within `v h`) and the stop lands
//!   within two steps (one to reach zero, one for the f32 velocity's last
//!   residual);
//! * the stop needs no chatter guard: an impulse that removes the whole
//!   slip within the disc is applied whole, so the plate sticks;
//! * a release after a push continues from the pushed state, and a thrown
//!   spinning square stops (gap to the Coulomb model printed: the box
//!   scene's four manifold points sit on the box's corners, the feet's on
//!   the supports, and Jolt adds its own torsion-free contact solve).
#![cfg(feature = "jolt")]

use pushval_engine::{rest_speed, Engine, EngineRun, REST_SPEED};
use pushval_jolt::predict::{Direction, Law};
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

fn engines() -> Vec<Box<dyn Engine>> {
    pushval_jolt::models()
        .iter()
        .map(|m| m.default_engine())
        .collect()
}

/// A throw in pure translation slid under Jolt's law in closed form
/// (`pushval_laws::jolt`, [`Direction::EffectiveMass`]): each manifold's
/// friction `μλ` along `−D u` at its point, `D` its rows' effective masses
/// in world axes. Integrated with steps of 1e-6 s (semi-implicit Euler)
/// until the plate's speed is below what one step's friction removes.
/// Returns the rest position (m) and the stop time (s).
fn law_slide(law: &Law, p: &Problem) -> ([f64; 2], f64) {
    let (m, inertia) = (p.body.mass(), p.body.inertia_cm());
    let i = p.initial;
    let (mut x, mut v, mut theta, mut omega) = (
        Vec2::new(i.position.x, i.position.y),
        Vec2::new(i.velocity.x, i.velocity.y),
        i.theta,
        i.omega,
    );
    let dt = 1e-6;
    let cap: f64 = law.manifolds.iter().map(|k| k.cap).sum();
    let mut t = 0.0;
    while v.norm() > cap / m * dt || omega.abs() > 1e-9 {
        let (mut f, mut tau) = (Vec2::zeros(), 0.0);
        let vb = pushval_model::rotate(-theta, &v);
        for (k, man) in law.manifolds.iter().enumerate() {
            let r = man.point;
            let u = vb + Vec2::new(-r.y, r.x) * omega;
            let fk = law.force(k, u, theta);
            f += fk;
            tau += r.x * fk.y - r.y * fk.x;
        }
        v += pushval_model::rotate(theta, &f) * (dt / m);
        omega += tau / inertia * dt;
        x += v * dt;
        theta += omega * dt;
        t += dt;
        assert!(t < 10.0, "the law's slide does not stop");
    }
    ([x.x, x.y], t)
}

/// Pure translation. Where the feet's rows have equal effective masses
/// (the plate square to the world axes, `jolt_box`'s one manifold at the
/// centre of mass) the friction is Coulomb's: the plate stops at
/// `v²/(2μg)` after `v/(μg)`. The `jolt_feet` plate turned by 0.7 rad
/// has unequal ones: its friction is not against the slip, so it curves
/// and slides farther, as the law integrated says ([`law_slide`]). Either
/// way the engine stops within `v h` short of the law's distance (the
/// symplectic pose update) and within two steps of its stop. Where it
/// rests is printed against the law: on the turned feet the law's path
/// bends about 0.05 rad away from Jolt's (1.6 mm at the rest), which the
/// steady law (derived for a pushed plate) does not settle, and its stop
/// up to 1.5 % from Jolt's.
#[test]
fn pure_translation_stops_where_the_law_says() {
    for e in engines() {
        for h in [1e-3, 5e-4] {
            for (v, theta) in [([1.0, 0.0], 0.0), ([0.3, -0.4], 0.7)] {
                let p = thrown(v, theta, 0.0);
                let (last, stop) = rest(&e.run(&p, h).unwrap());
                let speed = f64::hypot(v[0], v[1]);
                let (t_cf, d_cf) = (speed / (MU * G), speed * speed / (2.0 * MU * G));
                let law = if e.name() == "jolt_feet" {
                    Law::jolt_feet(&p.body, None, Direction::EffectiveMass)
                } else {
                    Law::jolt_box(&p.body, None, Direction::EffectiveMass)
                };
                let (x_law, t_law) = law_slide(&law, &p);
                let d = f64::hypot(last.x, last.y);
                let d_law = f64::hypot(x_law[0], x_law[1]);
                let gap = f64::hypot(last.x - x_law[0], last.y - x_law[1]);
                eprintln!(
                    "{} h {h} {v:?} θ {theta}: {d:.5} m (law {d_law:.5}, Coulomb {d_cf:.5}), {gap:.2e} m from the law's rest, stop {stop:.4} s (law {t_law:.4}, Coulomb {t_cf:.4})",
                    e.name()
                );
                // The turned feet: the law's path bends differently (see
                // above), which moves its stop by up to 1.5 %.
                let slack = if theta == 0.0 || e.name() == "jolt_box" {
                    0.0
                } else {
                    0.015 * t_law
                };
                assert!(
                    stop >= t_law - h - slack && stop <= t_law + 2.0 * h + slack,
                    "{}: stop {stop} s, law {t_law} s",
                    e.name()
                );
                assert!(
                    d <= d_law && d >= d_law - speed * h,
                    "{}: {d} m, law {d_law} m",
                    e.name()
                );
                assert!((last.theta - theta).abs() < 1e-3, "{}: turned", e.name());
                if theta == 0.0 || e.name() == "jolt_box" {
                    assert!((t_law - t_cf).abs() < 1e-5 && (d_law - d_cf).abs() < 1e-5);
                }
            }
        }
    }
}

#[test]
fn a_release_after_a_push_continues_from_the_pushed_state() {
    for e in engines() {
        continues_from_the_pushed_state(e.as_ref(), 1e-3, MU * G, true);
    }
}

#[test]
fn a_thrown_spinning_square_stops() {
    for e in engines() {
        thrown_square(e.as_ref(), 1e-3, true);
    }
}
