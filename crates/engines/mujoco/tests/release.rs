//! MuJoCo lets go (issue 46, item 2): the pusher's `connect` is turned off
//! and the plate slides on its feet to rest under MuJoCo's soft contact
//! friction. What that law predicts, and what is checked:
//!
//! * **Sliding**, a foot's friction is the cone's bound: `μN` against the
//!   slip for the elliptic cone; for the pyramidal cone (condim 3, four
//!   edges `n ± μ tₖ`) the tangential force lies in the diamond
//!   `|f₁| + |f₂| ≤ μN` of the contact frame (tangents along the world x and
//!   y for a floor normal along z), which reaches `μN` along those axes
//!   only and `μN/√2` on the diagonals.
//! * **Near the stop** the friction is a soft constraint: once the force
//!   that would stop the slip in one step fits in the cone, the slip obeys
//!   `u̇ = d·a_ref = −u/τ` with `τ = d_max·timeconst/(2d)` (MuJoCo's
//!   reference acceleration `−b u`, `b = 2/(d_max·timeconst)`, reached in
//!   the share `d` of its impedance): from the crossover speed `μgτ` the
//!   slip decays geometrically to zero, never reversing. With the default
//!   `solref = (0.02, 1)` and `solimp = (0.9, 0.95, …)`, `τ` is 10 to
//!   10.6 ms. That tail adds at most `μgτ²` (0.55 mm) to the Coulomb
//!   distance and up to `τ ln(μgτ/v_rest)` (92 ms) to the time before the
//!   rest rule (`|v| + |ω|L` below `v_rest` = 1e-5 m/s) holds.
//!
//! Hence: a plate thrown in pure translation along a contact axis (either
//! cone) or in any direction (elliptic) stops at `v²/(2μg)` within `v h`
//! short (semi-implicit Euler) or `μgτ²` long, after `v/(μg)` plus at most
//! the tail; thrown along a diagonal on the pyramidal cone it slides
//! farther (at most `√2` times); a thrown spinning square and a pushed
//! plate rest where the Coulomb model (`DynamicModel`) says in the limit
//! `τ, h → 0` (the gap falls when both halve); and a release after a push
//! starts the slide from the push's end state, moving.
#![cfg(feature = "mujoco")]

use pushval_engine::{rest_speed, Engine, REST_SPEED};
use pushval_model::{DynamicModel, Initial, Problem, Push, Simulator, Vec2};
use pushval_mujoco::{Cone, MujocoModel, MujocoSettings};

const G: f64 = 9.81;
/// The seed plate's friction coefficient.
const MU: f64 = Problem::SEED_MU;
/// MuJoCo's default contact `solimp` d₀ and d_max.
const D0: f64 = 0.9;
const DMAX: f64 = 0.95;

/// The seed plate (0.25 m square, 1 kg, μ 0.5 on its four corners, pushed
/// at the middle of its left side) with a release after `pushes`.
fn problem(pushes: Vec<Push>, initial: Initial) -> Problem {
    Problem::seed_plate(G, pushes, initial).unwrap()
}

/// A plate thrown from `position` at angle `theta` with centre-of-mass
/// velocity `v` (m/s) and spin `omega` (rad/s).
fn thrown_from(position: [f64; 2], v: [f64; 2], theta: f64, omega: f64) -> Problem {
    problem(
        vec![],
        Initial {
            theta,
            omega,
            position: Vec2::new(position[0], position[1]),
            velocity: Vec2::new(v[0], v[1]),
            from_rest: false,
        },
    )
}

fn thrown(v: [f64; 2], theta: f64, omega: f64) -> Problem {
    thrown_from([0.0, 0.0], v, theta, omega)
}

fn mujoco(cone: Cone, timeconst: f64) -> Box<dyn Engine> {
    Box::new(MujocoModel::new(MujocoSettings {
        cone,
        contact_solref: [timeconst, 1.0],
        ..Default::default()
    }))
}

/// The soft friction's slowest time constant (s) at `timeconst`.
fn tau_max(timeconst: f64) -> f64 {
    DMAX * timeconst / (2.0 * D0)
}

/// The rest (last row) and stop time of a run through the slide.
fn rest(e: &dyn Engine, p: &Problem, h: f64) -> (pushval_model::Sample, f64) {
    let run = e.run(p, h).unwrap();
    let slide = run.trajectory.slide.as_ref().expect("a slide report");
    let stop = slide.t_stop.expect("the plate stops");
    let last = *run.trajectory.samples.last().unwrap();
    assert_eq!(last.t, stop, "the last row is the rest");
    (last, stop)
}

/// Pure translation where the cone's bound is `μN` against the slip: the
/// Coulomb phase to the crossover, then the soft tail (module docs).
#[test]
fn pure_translation_stops_at_the_closed_form_plus_the_soft_tail() {
    let (h, tc) = (1e-3, 0.02);
    let tau = tau_max(tc);
    let cases = [
        (Cone::Pyramidal, [1.0, 0.0], 0.0),
        (Cone::Pyramidal, [0.0, -0.5], 0.7),
        (Cone::Elliptic, [1.0, 0.0], 0.0),
        (Cone::Elliptic, [0.6, 0.8], 0.0),
        (Cone::Elliptic, [0.3, -0.4], 0.7),
    ];
    for (cone, v, theta) in cases {
        let e = mujoco(cone, tc);
        let (last, stop) = rest(e.as_ref(), &thrown(v, theta, 0.0), h);
        let speed = f64::hypot(v[0], v[1]);
        let (t_cf, d_cf) = (speed / (MU * G), speed * speed / (2.0 * MU * G));
        let tail = tau * (MU * G * tau / REST_SPEED).ln() + 2.0 * h;
        eprintln!(
            "mujoco {cone:?} {v:?}: stop {stop:.4} s ({:.1} ms after v/(μg)), {:.3} mm from v²/(2μg)",
            1e3 * (stop - t_cf),
            1e3 * (f64::hypot(last.x, last.y) - d_cf)
        );
        assert!(
            stop >= t_cf && stop <= t_cf + tail,
            "{cone:?} {v:?}: stop {stop} s, closed form {t_cf} s, tail up to {tail} s"
        );
        let d = f64::hypot(last.x, last.y);
        assert!(
            d >= d_cf - speed * h && d <= d_cf + MU * G * tau * tau,
            "{cone:?} {v:?}: {d} m, closed form {d_cf} m"
        );
        let along = (last.x * v[0] + last.y * v[1]) / speed;
        assert!((along - d).abs() < 1e-4 * d_cf, "{cone:?}: off its line");
        assert!((last.theta - theta).abs() < 1e-5, "{cone:?}: turned");
    }
}

/// The pyramidal cone along a diagonal of its contact frame: the diamond
/// gives less friction than `μN` (down to `μN/√2`), so the plate slides
/// farther than `v²/(2μg)`, at most `√2` times as far (plus the tail), and
/// not along its throw (the diamond's force is not against the slip). The
/// elliptic cone on the same throw stays on the closed form (test above).
#[test]
fn the_pyramid_slides_farther_along_its_diagonal() {
    let (h, tc) = (1e-3, 0.02);
    let tau = tau_max(tc);
    let v = [0.6, 0.8];
    let (last, _) = rest(
        mujoco(Cone::Pyramidal, tc).as_ref(),
        &thrown(v, 0.0, 0.0),
        h,
    );
    let d_cf = 1.0 / (2.0 * MU * G);
    let d = f64::hypot(last.x, last.y);
    eprintln!(
        "mujoco pyramidal diagonal: {d:.4} m = {:.3} × v²/(2μg), heading {:.3} rad (thrown at {:.3})",
        d / d_cf,
        last.y.atan2(last.x),
        0.8f64.atan2(0.6)
    );
    assert!(d > 1.1 * d_cf, "{d} m: no farther than the closed form");
    assert!(d <= 2f64.sqrt() * d_cf + MU * G * tau * tau, "{d} m");
    assert!((last.y.atan2(last.x) - 0.8f64.atan2(0.6)).abs() > 0.05);
}

/// A thrown spinning square comes to rest, at rest by the rule (no
/// chatter: the soft friction's tail decays), on both cones. Where it rests
/// is reported against the Coulomb model, not held to it: MuJoCo's soft
/// friction at a foot off the centre of mass is directed by the contact's
/// inverse-inertia metric (its regularised constraint problem), not only
/// against the slip, so the law is not Coulomb's at each support.
#[test]
fn a_thrown_spinning_square_comes_to_rest() {
    let h = 1e-3;
    let p = thrown([0.8, 0.3], 0.2, 4.0);
    let model = DynamicModel::default().simulate(&p).unwrap();
    let ml = *model.samples.last().unwrap();
    for cone in Cone::ALL {
        let e = mujoco(cone, 0.02);
        let (last, stop) = rest(e.as_ref(), &p, h);
        let mut s = e.start(&p, h).unwrap();
        s.release(10.0).unwrap();
        let st = s.state();
        assert_eq!(st.t, stop);
        assert!(rest_speed(&p, st.v_cm, st.omega) < REST_SPEED, "{st:?}");
        eprintln!(
            "mujoco {cone:?} thrown square: rest {:.2e} m and {:.2e} rad from the model's, stop {:.1} ms after",
            f64::hypot(last.x - ml.x, last.y - ml.y),
            (last.theta - ml.theta).abs(),
            1e3 * (stop - ml.t)
        );
    }
}

/// A release after a push continues from the push's end state: the slide
/// starts at the pushed pose and time, it is not over before friction can
/// have stopped the pushed velocity, and it ends at rest. Friction is at
/// most `μ ΣNᵢ` (either cone), and the normal impulse over a slide of
/// length `T` that ends at rest is `m (gT − v_z)`, `v_z` the plate's
/// vertical speed at the release (its bounce on the soft contacts, below
/// 0.1 m/s: the pushes of this crate's tests leave it a few cm/s), so
/// `T ≥ |v|/(μg) − 0.1/g`. A release that lost the pushed velocity would
/// stop at once.
#[test]
fn a_release_after_a_push_continues_from_the_pushed_state() {
    let h = 1e-3;
    let pushes = [
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
    let p = problem(pushes.to_vec(), Initial::default());
    for cone in Cone::ALL {
        let e = mujoco(cone, 0.02);
        let mut s = e.start(&p, h).unwrap();
        for q in &pushes {
            s.advance(q).unwrap();
        }
        let st = s.state();
        let speed = f64::hypot(st.v_cm[0], st.v_cm[1]);
        assert!(speed > 0.3, "{cone:?}: the pushed plate is not moving");
        s.release(10.0).unwrap();
        let end = s.state();
        let report = s.slide().unwrap();
        assert_eq!(report.t_release, st.t);
        assert_eq!(report.t_stop, Some(end.t), "{cone:?}: no rest");
        assert!(rest_speed(&p, end.v_cm, end.omega) < REST_SPEED);
        let t_min = speed / (MU * G) - 0.1 / G;
        eprintln!(
            "mujoco {cone:?}: released at {speed:.3} m/s, slid {:.1} mm in {:.1} ms (at least {:.1} ms)",
            1e3 * f64::hypot(end.x - st.x, end.y - st.y),
            1e3 * (end.t - st.t),
            1e3 * t_min
        );
        assert!(end.t - st.t >= t_min, "{cone:?}: stopped too soon");
        let run = s.finish().unwrap();
        let row = run
            .trajectory
            .samples
            .iter()
            .find(|r| r.t == st.t)
            .expect("the release row");
        assert_eq!((row.x, row.y, row.theta), (st.x, st.y, st.theta));
        assert_eq!(run.trajectory.samples.last().unwrap().t, end.t);
    }
}
