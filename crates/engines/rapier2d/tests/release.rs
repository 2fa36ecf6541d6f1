//! Every rapier2d model lets go, the friction idioms included, and each
//! comes to rest by its own law (`src/slide.rs`). Checked on the seed's
//! square (0.25 m, 1 kg, μ 0.5 on its corners) thrown from the origin at
//! angle 0, against closed forms of each law:
//!
//! * **impulse_box**: thrown along x, each support's x row is at its cap
//!   `F = μmg/4` while it slides, so the plate decelerates at μg (Coulomb's
//!   v²/(2μg) after v/(μg)); thrown along the diagonal both rows are at
//!   their caps, √2 μg against the motion (v²/(2√2μg)).
//! * **impulse_disk**: each support's force is `F` along `−Kᵢ⁻¹u`; thrown
//!   along the diagonal `u` is an eigenvector of every `Kᵢ` (Coulomb's stop);
//!   along x the share of `F` against the motion is
//!   `c = (1 + ¼)/√(2(1 + 1/16))` = 0.857 at every corner (eigen-masses m
//!   along the diagonal, m/4 across it), so it slides v²/(2cμg) after
//!   v/(cμg). A pure spin slides every corner across its diagonal (an
//!   eigenvector): Coulomb's θ = I ω²/(2 Σ Fᵢ|rᵢ|).
//! * **regularised_linear / _tanh** (slip speed `v_s`): Coulomb above `v_s`.
//!   Linear: the Coulomb stop to `v_s`, then the explicit step's geometric
//!   decay `v ← (1 − h μg/v_s) v`, which adds v_s²/(2μg) to the distance
//!   and the steps down to the rest rule's 1e-5 m/s to the time. Tanh:
//!   `v̇ = −μg tanh(v/v_s)` gives `sinh(v/v_s) = sinh(v₀/v_s) e^{−μg t/v_s}`
//!   (the time to any speed, the continuous bound of the explicit step,
//!   which decays faster) and v²/(2μg) + π² v_s²/(12 μg) in distance.
//!
//! Distances are held within `v h` (the semi-implicit position update's
//! first-order error) and stop times within two steps, except where a
//! bound is one-sided as said.

use pushval_engine::{Engine, EngineRun, REST_SPEED};
use pushval_model::{Initial, Problem, Vec2};
use pushval_rapier2d::{EngineSettings, FrictionModel, Rapier2dModel};

const G: f64 = 9.81;
const MU: f64 = Problem::SEED_MU;
/// Half the side of the seed plate (m).
const A: f64 = 0.5 * Problem::SEED_SIDE;
const H: f64 = 1e-3;
const V_S: f64 = 0.01;

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

fn engine(model: FrictionModel) -> Rapier2dModel {
    Rapier2dModel::new(
        "rapier2d_idiom",
        "a friction idiom",
        EngineSettings {
            dt: H,
            friction_model: model,
            ..Default::default()
        },
    )
}

/// The rest row and the stop time; the plate must stop within the
/// release's `max_duration`, and the rest is at rest by the rule.
fn rest(model: FrictionModel, p: &Problem) -> (pushval_model::Sample, f64) {
    let run: EngineRun = engine(model).run(p, H).unwrap();
    let slide = run.trajectory.slide.as_ref().expect("a slide report");
    let stop = slide
        .t_stop
        .unwrap_or_else(|| panic!("{model:?}: the plate does not stop"));
    let last = *run.trajectory.samples.last().unwrap();
    assert_eq!(last.t, stop, "{model:?}: the last row is the rest");
    (last, stop)
}

#[track_caller]
fn close(what: &str, got: f64, want: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: {got}, closed form {want} (tolerance {tol})"
    );
}

#[test]
fn the_impulse_box_stops_as_its_caps_per_axis_say() {
    let m = FrictionModel::ImpulseBox;
    let (r, t) = rest(m, &thrown([1.0, 0.0], 0.0));
    close("box along x: distance", r.x, 1.0 / (2.0 * MU * G), H);
    close("box along x: stop time", t, 1.0 / (MU * G), 2.0 * H);
    assert!(r.y.abs() < 1e-12 && r.theta.abs() < 1e-12, "{r:?}");
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let (r, t) = rest(m, &thrown([s, s], 0.0));
    let k = 2f64.sqrt() * MU * G;
    close(
        "box along the diagonal: distance",
        r.x.hypot(r.y),
        1.0 / (2.0 * k),
        H,
    );
    close("box along the diagonal: stop time", t, 1.0 / k, 2.0 * H);
}

#[test]
fn the_impulse_disk_stops_as_its_capped_stopping_impulse_says() {
    let m = FrictionModel::ImpulseDisk;
    let c = 1.25 / (2.0f64 * (1.0 + 1.0 / 16.0)).sqrt();
    let (r, t) = rest(m, &thrown([1.0, 0.0], 0.0));
    close("disk along x: distance", r.x, 1.0 / (2.0 * c * MU * G), H);
    close("disk along x: stop time", t, 1.0 / (c * MU * G), 2.0 * H);
    assert!(r.y.abs() < 1e-12 && r.theta.abs() < 1e-12, "{r:?}");
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let (r, t) = rest(m, &thrown([s, s], 0.0));
    close(
        "disk along the diagonal: distance",
        r.x.hypot(r.y),
        1.0 / (2.0 * MU * G),
        H,
    );
    close(
        "disk along the diagonal: stop time",
        t,
        1.0 / (MU * G),
        2.0 * H,
    );
    // Pure spin: Coulomb's closed form.
    let w = 10.0;
    let (r, t) = rest(m, &thrown([0.0, 0.0], w));
    let (i, lever) = ((2.0 * A) * (2.0 * A) / 6.0, A * 2f64.sqrt());
    let torque = MU * G * lever;
    close(
        "disk spin: angle",
        r.theta,
        i * w * w / (2.0 * torque),
        w * H,
    );
    close("disk spin: stop time", t, i * w / torque, 2.0 * H);
    assert!(r.x.hypot(r.y) < 1e-12, "{r:?}");
}

#[test]
fn the_regularised_laws_stop_with_their_creep_below_the_slip_speed() {
    let v0 = 1.0;
    let k = MU * G / V_S;
    // Linear: the Coulomb phase down to v_s, then the geometric decay.
    let (r, t) = rest(
        FrictionModel::RegularisedLinear { slip_speed: V_S },
        &thrown([v0, 0.0], 0.0),
    );
    close(
        "linear: distance",
        r.x,
        (v0 * v0 + V_S * V_S) / (2.0 * MU * G),
        v0 * H,
    );
    let decay_steps = ((REST_SPEED / V_S).ln() / (1.0 - H * k).ln()).ceil();
    close(
        "linear: stop time",
        t,
        (v0 - V_S) / (MU * G) + decay_steps * H,
        2.0 * H,
    );
    // Tanh: the continuous stop time bounds the explicit step's from above.
    let (r, t) = rest(
        FrictionModel::RegularisedTanh { slip_speed: V_S },
        &thrown([v0, 0.0], 0.0),
    );
    let pi2 = std::f64::consts::PI.powi(2);
    close(
        "tanh: distance",
        r.x,
        v0 * v0 / (2.0 * MU * G) + pi2 * V_S * V_S / (12.0 * MU * G),
        v0 * H,
    );
    // ln sinh(x) for x = 100 without overflow: x − ln 2 + ln(1 − e^{−2x}).
    let x0 = v0 / V_S;
    let ln_sinh0 = x0 - 2f64.ln() + (-(-2.0 * x0).exp()).ln_1p();
    let t_cont = (ln_sinh0 - (REST_SPEED / V_S).sinh().ln()) / k;
    assert!(
        t >= v0 / (MU * G) - H && t <= t_cont + 2.0 * H,
        "tanh: stop {t} s, Coulomb's {} s, continuous {t_cont} s",
        v0 / (MU * G)
    );
}

/// Every idiom brings a sliding, spinning throw to rest within the
/// release's ten seconds, not turning it into a drift (the rest lies
/// within the Coulomb slide's reach, v²/(2μg) scaled by the slowest law's
/// share of μg).
#[test]
fn every_idiom_stops_a_spinning_throw() {
    for m in [
        FrictionModel::ImpulseDisk,
        FrictionModel::ImpulseBox,
        FrictionModel::RegularisedLinear { slip_speed: V_S },
        FrictionModel::RegularisedTanh { slip_speed: V_S },
    ] {
        let (r, t) = rest(m, &thrown([0.8, 0.3], 4.0));
        let v2 = 0.8f64.powi(2) + 0.3f64.powi(2);
        assert!(t < 1.0, "{m:?}: stops at {t} s");
        assert!(
            r.x.hypot(r.y) < v2 / (2.0 * 0.5 * MU * G),
            "{m:?}: rests at {r:?}"
        );
    }
}
