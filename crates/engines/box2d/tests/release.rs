//! `box2d_motor_joint` lets go: the pusher's joint is destroyed and the
//! motor joint to the ground, which is the idiom's friction, keeps acting.
//! Its velocity constraints target zero with the linear impulse capped in
//! length at `F_max h` (`F_max = Σ μᵢNᵢ` = μmg) and the angular one at
//! `T_max h` (`T_max = Σ μᵢNᵢ|rᵢ|`), each on its own, acting at the centre
//! of mass. So the translation decelerates at μg against the velocity and
//! the spin at `T_max/I`, independently: the plate slides along a straight
//! line, stops translating after v/(μg) at v²/(2μg), and stops turning after
//! `I ω/T_max` at `I ω²/(2 T_max)` — not at the same instant, unlike
//! Coulomb friction at the supports (Goyal, Ruina & Papadopoulos 1991).
//! Each stops within a step once its cap can hold it. Distances are held
//! within `v h` (the first-order step), the angle within `ω h`, the stop
//! within two steps.

use pushval_box2d::{Box2dModel, Box2dSettings, Friction};
use pushval_engine::Engine;
use pushval_model::{Initial, Problem, Vec2};

const G: f64 = 9.81;
const MU: f64 = Problem::SEED_MU;
/// Half the side of the seed plate (m).
const A: f64 = 0.5 * Problem::SEED_SIDE;
const H: f64 = 1e-3;

fn thrown(v: [f64; 2], omega: f64) -> Problem {
    Problem::seed_plate(
        G,
        vec![],
        Initial {
            theta: 0.0,
            omega,
            position: Vec2::new(0.0, 0.0),
            velocity: Vec2::new(v[0], v[1]),
            from_rest: false,
        },
    )
    .unwrap()
}

/// The run's rows and its stop time; it must stop within the release's
/// `max_duration`.
fn slide(p: &Problem) -> (Vec<pushval_model::Sample>, f64) {
    let e = Box2dModel::new(Box2dSettings {
        friction: Friction::MotorJoint,
        dt: H,
        ..Default::default()
    });
    let run = e.run(p, H).unwrap();
    let stop = run
        .trajectory
        .slide
        .as_ref()
        .expect("a slide report")
        .t_stop
        .expect("the plate stops");
    let rows = run.trajectory.samples.clone();
    assert_eq!(rows.last().unwrap().t, stop, "the last row is the rest");
    (rows, stop)
}

#[track_caller]
fn close(what: &str, got: f64, want: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: {got}, closed form {want} (tolerance {tol})"
    );
}

#[test]
fn pure_translation_stops_at_the_force_caps_closed_form() {
    for v in [[1.0, 0.0], [0.3, -0.4]] {
        let (rows, stop) = slide(&thrown(v, 0.0));
        let r = rows.last().unwrap();
        let speed = f64::hypot(v[0], v[1]);
        let d = speed * speed / (2.0 * MU * G);
        close("distance", r.x.hypot(r.y), d, speed * H);
        close("along the throw", r.x * v[1] - r.y * v[0], 0.0, 1e-6);
        close("stop time", stop, speed / (MU * G), 2.0 * H);
        assert!(r.theta.abs() < 1e-6, "{r:?}");
    }
}

/// Thrown sliding and spinning, the translation and the spin stop each at
/// its own cap's time: the path is straight and the angle is the pure
/// spin's.
#[test]
fn translation_and_spin_stop_on_their_own_caps() {
    let (v, w) = ([0.8, 0.3], 6.0);
    let (rows, stop) = slide(&thrown(v, w));
    let r = rows.last().unwrap();
    let speed = f64::hypot(v[0], v[1]);
    let i = (2.0 * A) * (2.0 * A) / 6.0;
    let t_max = MU * G * A * 2f64.sqrt();
    close(
        "distance",
        r.x.hypot(r.y),
        speed * speed / (2.0 * MU * G),
        speed * H,
    );
    close("along the throw", r.x * v[1] - r.y * v[0], 0.0, 1e-6);
    close("angle", r.theta, i * w * w / (2.0 * t_max), w * H);
    let (t_lin, t_rot) = (speed / (MU * G), i * w / t_max);
    close("stop time", stop, t_lin.max(t_rot), 2.0 * H);
    // The spin stops first (t_rot < t_lin here): 20 ms after its stop the
    // plate no longer turns but is still far from its rest.
    assert!(t_rot + 0.04 < t_lin, "{t_rot} s, {t_lin} s");
    let row = rows
        .iter()
        .find(|s| s.t >= t_rot + 0.02)
        .expect("a row after the spin's stop");
    assert!(row.omega.abs() < 1e-4, "still turning: {row:?}");
    assert!(
        row.x.hypot(row.y) < 0.95 * r.x.hypot(r.y),
        "already at rest: {row:?}"
    );
}
