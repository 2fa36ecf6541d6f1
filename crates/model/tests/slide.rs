//! The free slide to rest (issue 46, item 1) against known results: the
//! closed forms of pure translation and pure spin, the uniform disc's final
//! ratio v/(Rω) ≈ 0.653, translation and rotation stopping together, the
//! energy balance, mirror symmetry and a pivot about a heavily loaded foot.

use pushval_model::{
    slide_to_rest, Body, PivotEnd, Slide, SlideOptions, SlideState, Support, Vec2,
};

const G: f64 = 9.81;

/// A plate of mass `m` and inertia `inertia` on supports `(x, y, f)`.
fn plate(m: f64, inertia: f64, supports: &[(f64, f64, f64)]) -> Body {
    let s: Vec<Support> = supports
        .iter()
        .map(|&(x, y, f)| Support {
            position: Vec2::new(x, y),
            friction: f,
        })
        .collect();
    Body::new(m, inertia, Vec2::new(-0.1, 0.0), &s).unwrap()
}

/// A square plate of side 2a on its four corners, equal loads, μ.
fn square(m: f64, a: f64, mu: f64) -> Body {
    let f = mu * m * G / 4.0;
    plate(
        m,
        m * (2.0 * a) * (2.0 * a) / 6.0,
        &[(a, a, f), (-a, a, f), (-a, -a, f), (a, -a, f)],
    )
}

fn throw(x: f64, y: f64, theta: f64, vx: f64, vy: f64, omega: f64) -> SlideState {
    SlideState {
        t: 0.0,
        x,
        y,
        theta,
        vx,
        vy,
        omega,
    }
}

fn run(body: &Body, start: &SlideState) -> Slide {
    slide_to_rest(body, start, &SlideOptions::default()).unwrap()
}

/// Pure translation: with the supports symmetric about the centre of mass
/// and no spin, friction is μ m g against the motion and no moment, so the
/// plate decelerates uniformly: it stops after t = v/(μg) having travelled
/// d = v²/(2μg) along its velocity, without turning.
#[test]
fn pure_translation_stops_at_the_closed_form() {
    let (m, mu) = (1.7, 0.4);
    let body = square(m, 0.1, mu);
    for (vx, vy, theta) in [(1.0, 0.0, 0.0), (0.6, -0.9, 0.3), (-0.2, 0.05, 2.0)] {
        let v = f64::hypot(vx, vy);
        let sl = run(&body, &throw(0.2, -0.1, theta, vx, vy, 0.0));
        let t_stop = v / (mu * G);
        let d = v * v / (2.0 * mu * G);
        let stop = sl.stop.expect("stops");
        assert!((stop - t_stop).abs() < 1e-9, "t {stop} vs {t_stop}");
        assert!((sl.end.x - (0.2 + d * vx / v)).abs() < 1e-9, "{:?}", sl.end);
        assert!((sl.end.y - (-0.1 + d * vy / v)).abs() < 1e-9, "{:?}", sl.end);
        assert!((sl.end.theta - theta).abs() < 1e-9, "{:?}", sl.end);
        assert_eq!((sl.end.vx, sl.end.vy, sl.end.omega), (0.0, 0.0, 0.0));
        assert!(sl.pivots.is_empty());
    }
}
