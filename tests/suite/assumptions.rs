//! The assumption checks flag what they should, and only that (issue "Gate
//! power", item 4): each check has a positive case with an independently
//! known answer and a negative twin that differs in the one condition.
//!
//! Scenes are loaded from TOML text (`pushval::registry::from_toml`), run
//! through the harness, and read both from `Trajectory::assumptions` and from
//! `summary.json`'s `assumptions`.
//!
//! The closed forms used (object frame, `n` the push direction, `F_i = μ_i N_i`):
//!
//! * A push whose line runs through the centre of friction of a symmetric
//!   support set, started at ω = 0, keeps ω = 0: every support slides at
//!   `v n`, their friction sums to `−(Σ F_i) n` with zero moment about the
//!   contact, and `a_cm = 0`. So the pusher force is `f_c = (Σ F_i) n = μ m g n`
//!   exactly, along the push.
//! * At a steady state ω* (ω̇ = 0) the centre of mass moves on a circle:
//!   `a_cm = v ω* D n + ω*² p_c` and `f_c = m a_cm + Σ F_i u_i / |u_i|`,
//!   `u_i = v n + ω* D (p_i − p_c)`; ω* is found here by integrating the
//!   moment balance written out below (RK4), not by the model's root finder.
//! * At a switch of speed only, along a line through the centre (ω = 0 before
//!   and after: `p_c × n = 0` keeps the angular momentum about the contact at
//!   zero), the contact impulse is `J = m (v₂ − v₁) n`.
//!
//! The contact of a rectangle at its corner (−a, −b) has the inward normals
//! (0, 1) (bottom edge) and (1, 0) (left edge). A force pulls when it lies
//! more than 90° from both; the model reports the angle to the nearer one.

use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

use pushval::{output, run_scenario, RunOptions};
use pushval_model::Vec2;
use pushval_scenario::Scenario;
use serde_json::Value;

const G: f64 = 9.81;
const MU: f64 = 0.5;
const MASS: f64 = 1.0;

/// One push segment: duration (s), speed (m/s), φ (rad).
type Seg = (f64, f64, f64);

/// A rectangle of half sides `a` × `b`, centred on its centre of mass, on
/// four equally loaded corner supports (μ = 0.5), pushed at the corner (−a, −b).
struct Scene {
    a: f64,
    b: f64,
    pushes: Vec<Seg>,
    omega0: f64,
    from_rest: bool,
    max_force: Option<f64>,
}

impl Scene {
    fn new(a: f64, b: f64, pushes: &[Seg]) -> Self {
        Self {
            a,
            b,
            pushes: pushes.to_vec(),
            omega0: 0.0,
            from_rest: false,
            max_force: None,
        }
    }

    fn toml(&self) -> String {
        let (a, b) = (self.a, self.b);
        let mut s = format!(
            "name = \"assumption-check\"\n\
             description = \"rectangle pushed at a corner\"\n\
             [object]\n\
             mass = {MASS:?}\n\
             polygon = [[{:?}, {:?}], [{a:?}, {:?}], [{a:?}, {b:?}], [{:?}, {b:?}]]\n\
             [supports]\n\
             points = [[{:?}, {:?}], [{a:?}, {:?}], [{a:?}, {b:?}], [{:?}, {b:?}]]\n\
             mu = {MU:?}\n\
             load = \"equal\"\n\
             gravity = {G:?}\n\
             [contact]\n\
             point = [{:?}, {:?}]\n",
            -a, -b, -b, -a, -a, -b, -b, -a, -a, -b
        );
        if let Some(f) = self.max_force {
            s += &format!("max_force = {f:?}\n");
        }
        s += &format!(
            "[initial]\nomega = {:?}\nfrom_rest = {}\n",
            self.omega0, self.from_rest
        );
        for (d, v, phi) in &self.pushes {
            s += &format!("[[push]]\nduration = {d:?}\nspeed = {v:?}\nphi = {phi:?}\n");
        }
        s += "[run]\nmodels = [\"dynamic\"]\nsample_dt = 0.01\nswitching = \"impulsive\"\n";
        s
    }

    fn load(&self) -> Scenario {
        pushval::registry::from_toml(&self.toml(), Path::new("assumption-check.toml"))
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// The dynamic model's assumption checks and summary.json's `assumptions`.
    fn run(&self) -> (pushval_model::Assumptions, Value) {
        let sc = self.load();
        let report = run_scenario(&sc, &RunOptions::default()).unwrap();
        let a = report.dynamic().trajectory.assumptions.clone();
        let summary = output::summary(&report);
        (a, summary["assumptions"].clone())
    }

    /// Direction (rad) from the contact through the centre: into the object.
    fn inward(&self) -> f64 {
        self.b.atan2(self.a)
    }
}

/// The rectangle the checks mostly use: 0.4 m × 0.1 m, so the diagonal
/// is far from both edge normals.
const A: f64 = 0.2;
const B: f64 = 0.05;

/// Angle (rad) from a force at polar angle `alpha` to the corner's normal
/// cone, spanned by the directions 0 and π/2: zero inside, else the distance
/// to the nearer edge direction.
fn corner_cone_angle(alpha: f64) -> f64 {
    let d = |x: f64| (x.sin().atan2(x.cos())).abs();
    let a = alpha.sin().atan2(alpha.cos());
    if (0.0..=FRAC_PI_2).contains(&a) {
        0.0
    } else {
        d(alpha).min(d(alpha - FRAC_PI_2))
    }
}

#[test]
fn corner_cone_angle_by_hand() {
    // The helper above, on directions whose answer is plain.
    let eps = 1e-15;
    assert!(corner_cone_angle(0.3).abs() < eps);
    assert!((corner_cone_angle(PI) - FRAC_PI_2).abs() < eps);
    assert!((corner_cone_angle(-FRAC_PI_2) - FRAC_PI_2).abs() < eps);
    assert!((corner_cone_angle(5.0 * PI / 4.0) - 3.0 * PI / 4.0).abs() < 1e-14);
    assert!((corner_cone_angle(PI - 0.2) - (FRAC_PI_2 - 0.2)).abs() < 1e-14);
}

#[track_caller]
fn flagged(v: &Value, key: &str) -> f64 {
    let x = &v[key];
    assert!(
        x.is_object(),
        "summary.json assumptions.{key} = {x}, want a violation"
    );
    x["worst"].as_f64().unwrap()
}

// ---------------------------------------------------------------- pulling

/// Pulled along the diagonal, away from the object: the object still moves
/// (with the pusher, ω = 0) and `f_c = μ m g n_out` points π/2 + atan(b/a)
/// from the bottom edge's normal and π − atan(b/a) from the left edge's: the
/// pusher would have to pull, by the smaller of the two angles.
#[test]
fn pulling_flagged_when_the_pusher_drags_the_object() {
    let sc = Scene::new(A, B, &[]);
    let out = sc.inward() + PI;
    let sc = Scene::new(A, B, &[(1.0, 0.3, out)]);
    let (a, json) = sc.run();
    let want = FRAC_PI_2 + (B / A).atan();
    let v = a.pulling.expect("a pull along the diagonal is flagged");
    assert!(
        (v.worst - want).abs() < 1e-9,
        "angle {} want {want}",
        v.worst
    );
    assert_eq!((v.first_t, v.segment), (0.0, 0));
    assert!((flagged(&json, "pulling") - want).abs() < 1e-9);
    assert_eq!(json["all_hold"], false);
    // The force the check saw is the closed form μ m g.
    assert!((a.max_force - MU * MASS * G).abs() < 1e-9 * MU * MASS * G);
}

/// The twin: the same line pushed the other way, into the object. The
/// closed-form force `μ m g n_in` lies inside the corner's cone: no pulling,
/// cone angle 0.
#[test]
fn pushing_into_the_object_is_not_pulling() {
    let sc = Scene::new(A, B, &[]);
    let sc = Scene::new(A, B, &[(1.0, 0.3, sc.inward())]);
    let (a, json) = sc.run();
    assert!(a.pulling.is_none(), "{:?}", a.pulling);
    assert!(a.max_cone_angle < 1e-9, "cone angle {}", a.max_cone_angle);
    assert!(json["pulling"].is_null());
    assert!((a.max_force - MU * MASS * G).abs() < 1e-9 * MU * MASS * G);
}

/// Friction moment about the contact plus the inertial term, `I_P ω̇`, written
/// out from the model's definition (docs/architecture.md, "The model"), one support at a time.
fn moment(sc: &Scene, v: f64, phi: f64, w: f64) -> f64 {
    let (a, b) = (sc.a, sc.b);
    let pc = Vec2::new(-a, -b);
    let n = Vec2::new(phi.cos(), phi.sin());
    let f = MU * MASS * G / 4.0;
    let mut m = MASS * v * w * pc.dot(&n);
    for p in [(-a, -b), (a, -b), (a, b), (-a, b)] {
        let r = Vec2::new(p.0, p.1) - pc;
        let u = n * v + Vec2::new(-r.y, r.x) * w;
        if u.norm() > 0.0 {
            m -= f * (r.x * u.y - r.y * u.x) / u.norm();
        }
    }
    m
}

/// The steady ω* reached from ω = 0: fixed-step RK4 of `I_P ω̇ = moment(ω)`
/// (any I_P > 0 has the same attractor) until ω̇ no longer changes ω.
fn steady_omega(sc: &Scene, v: f64, phi: f64) -> f64 {
    let ip = MASS * (sc.a * sc.a + sc.b * sc.b) * (1.0 / 3.0 + 1.0);
    let g = |w: f64| moment(sc, v, phi, w) / ip;
    let h = 1e-3;
    let mut w = 0.0;
    for _ in 0..200_000 {
        let k1 = g(w);
        let k2 = g(w + 0.5 * h * k1);
        let k3 = g(w + 0.5 * h * k2);
        let k4 = g(w + h * k3);
        let next = w + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        if (next - w).abs() <= 4e-16 * w.abs() {
            break;
        }
        w = next;
    }
    assert!(g(w).abs() < 1e-10, "not settled: ω̇({w}) = {}", g(w));
    w
}

/// The pusher force at a steady state ω* (ω̇ = 0), object frame, and its
/// inertial part `m a_cm`.
fn steady_force_parts(sc: &Scene, v: f64, phi: f64, w: f64) -> (Vec2, Vec2) {
    let (a, b) = (sc.a, sc.b);
    let pc = Vec2::new(-a, -b);
    let n = Vec2::new(phi.cos(), phi.sin());
    let acm = Vec2::new(-n.y, n.x) * (v * w) + pc * (w * w);
    let f = MU * MASS * G / 4.0;
    let mut fc = acm * MASS;
    for p in [(-a, -b), (a, -b), (a, b), (-a, b)] {
        let r = Vec2::new(p.0, p.1) - pc;
        let u = n * v + Vec2::new(-r.y, r.x) * w;
        fc += u * (f / u.norm());
    }
    (fc, acm * MASS)
}

fn steady_force(sc: &Scene, v: f64, phi: f64, w: f64) -> Vec2 {
    steady_force_parts(sc, v, phi, w).0
}

/// A pull that turns the object: the paper plate dragged by its corner
/// away from the object at φ = 5π/4 + 0.2, started on its steady state ω*
/// (≠ 0, found here by RK4). The pusher force and its angle to the corner's
/// cone, computed here from the steady motion, say it pulls; the check
/// agrees and reports that angle.
#[test]
fn pulling_flagged_on_a_turning_steady_pull() {
    let (v, phi) = (0.3, 5.0 * PI / 4.0 + 0.2);
    let mut sc = Scene::new(0.125, 0.125, &[(1.0, v, phi)]);
    let w = steady_omega(&sc, v, phi);
    assert!(w.abs() > 0.1, "ω* = {w}: not a turning case");
    let f = steady_force(&sc, v, phi, w);
    let want = corner_cone_angle(f.y.atan2(f.x));
    assert!(want > FRAC_PI_2 + 0.1, "not a clear pull: {want}");
    sc.omega0 = w;
    let (a, json) = sc.run();
    let got = a.pulling.expect("flagged").worst;
    assert!((got - want).abs() < 1e-7, "angle {got}, want {want}");
    assert!((flagged(&json, "pulling") - want).abs() < 1e-7);
    assert!((a.max_force - f.norm()).abs() < 1e-7 * f.norm());
}

// ------------------------------------------------------- pulling impulse

/// Slowing down along the diagonal (0.6 → 0.2 m/s): the contact must take
/// momentum `m Δv = −0.4 m n_in` out of the object, an impulse pointing out
/// of it, π/2 + atan(b/a) from the nearer normal. Flagged at the switch, and
/// only there: the start from rest (+0.6 m n_in) pushes.
#[test]
fn pulling_impulse_flagged_when_the_pusher_brakes() {
    let sc = Scene::new(A, B, &[]);
    let phi = sc.inward();
    let mut sc = Scene::new(A, B, &[(0.5, 0.6, phi), (0.5, 0.2, phi)]);
    sc.from_rest = true;
    let (a, json) = sc.run();
    let want = FRAC_PI_2 + (B / A).atan();
    let v = a.pulling_impulse.expect("braking needs a pulling impulse");
    assert!(
        (v.worst - want).abs() < 1e-9,
        "angle {} want {want}",
        v.worst
    );
    assert_eq!(v.segment, 1);
    assert!((v.first_t - 0.5).abs() < 1e-12);
    assert!((flagged(&json, "pulling_impulse") - want).abs() < 1e-9);
    // Between switches the force is the push μ m g n_in.
    assert!(a.pulling.is_none());
}

/// The twin: speeding up (0.2 → 0.6 m/s) along the same line needs
/// `+0.4 m n_in`, into the object: no pulling impulse anywhere.
#[test]
fn speeding_up_needs_no_pulling_impulse() {
    let sc = Scene::new(A, B, &[]);
    let phi = sc.inward();
    let mut sc = Scene::new(A, B, &[(0.5, 0.2, phi), (0.5, 0.6, phi)]);
    sc.from_rest = true;
    let (a, json) = sc.run();
    assert!(a.pulling_impulse.is_none(), "{:?}", a.pulling_impulse);
    assert!(json["pulling_impulse"].is_null());
    assert_eq!(json["all_hold"], true);
}

// ------------------------------------------------------------ force limit

/// `[contact] max_force` just below and just above the independently known
/// peak force: flagged, with that force as the worst value, and not flagged.
fn force_limit_brackets(sc: &mut Scene, peak: f64) {
    sc.max_force = Some(peak * (1.0 - 1e-6));
    let (a, json) = sc.run();
    let v = a.force_limit.expect("force above max_force is flagged");
    assert!(
        (v.worst - peak).abs() < 1e-8 * peak,
        "{} vs {peak}",
        v.worst
    );
    assert!((flagged(&json, "force_limit") - peak).abs() < 1e-8 * peak);
    sc.max_force = Some(peak * (1.0 + 1e-6));
    let (a, json) = sc.run();
    assert!(a.force_limit.is_none(), "{:?}", a.force_limit);
    assert!(json["force_limit"].is_null());
}

/// Pushed through the centre from ω = 0: `|f_c| = μ m g` throughout.
#[test]
fn force_limit_at_the_straight_push_force() {
    let sc = Scene::new(A, B, &[]);
    let mut sc = Scene::new(A, B, &[(1.0, 0.5, sc.inward())]);
    force_limit_brackets(&mut sc, MU * MASS * G);
}

/// The paper plate turning on its steady state (v = 1 m/s, φ = π/4 + 0.3,
/// started at ω*): the force is constant, `|m a_cm + Σ F_i u_i/|u_i||` with
/// `a_cm` the steady motion's acceleration (`v ω* D n + ω*² p_c`). Here
/// `|m a_cm|` is about 13 % of `|f_c|` and moves `|f_c|` by 0.8 %, thousands
/// of times the ±1e-6 bracket: the friction sum alone would not do.
#[test]
fn force_limit_at_the_steady_state_force() {
    let (v, phi) = (1.0, std::f64::consts::FRAC_PI_4 + 0.3);
    let mut sc = Scene::new(0.125, 0.125, &[(1.0, v, phi)]);
    let w = steady_omega(&sc, v, phi);
    let (f, inertial) = steady_force_parts(&sc, v, phi, w);
    let peak = f.norm();
    // Without m a_cm the force would differ by far more than the bracket.
    let friction_only = (f - inertial).norm();
    assert!(
        inertial.norm() > 0.1 * peak && (friction_only / peak - 1.0).abs() > 1e-3,
        "|f_c| = {peak}, |m a_cm| = {}, friction alone {friction_only}: inertia too small to matter",
        inertial.norm()
    );
    sc.omega0 = w;
    force_limit_brackets(&mut sc, peak);
}
