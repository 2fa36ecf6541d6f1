use pushval_model::{slide_to_rest, Body, SlideOptions, SlideState, Support, Vec2};
fn body(m: f64, i: f64, sup: &[(f64, f64, f64)]) -> Body {
    let s: Vec<Support> = sup.iter().map(|&(x, y, f)| Support { position: Vec2::new(x, y), friction: f }).collect();
    Body::new(m, i, Vec2::new(-0.1, 0.0), &s).unwrap()
}
fn main() {
    let a = 0.125;
    let f = 0.5 * 9.81 / 4.0;
    let seed = body(1.0, (2.0*a)*(2.0*a)/6.0, &[(a, a, f), (-a, a, f), (-a, -a, f), (a, -a, f)]);
    let uneven = body(1.3, 0.011, &[(0.12, 0.08, 2.0), (-0.1, 0.09, 0.9), (-0.11, -0.07, 1.6), (0.09, -0.1, 0.4), (0.02, 0.01, 1.1)]);
    let heavy = body(1.0, (2.0*a)*(2.0*a)/6.0, &[(a, a, 3.0), (-a, a, 0.5), (-a, -a, 0.5), (a, -a, 0.5)]);
    let st = |vx, vy, w| SlideState { t: 0.0, x: 0.0, y: 0.0, theta: 0.4, vx, vy, omega: w };
    for (name, b, s0) in [("seed", &seed, st(0.8, 0.6, 2.3)), ("seed35", &seed, st(0.6, -0.8, -3.5)), ("uneven", &uneven, st(1.0, 0.2, 3.0)), ("uneven2", &uneven, st(-0.3, 0.5, -20.0)), ("heavy", &heavy, st(0.8, 0.6, 3.0))] {
        let r = slide_to_rest(b, &s0, &SlideOptions { tol: 1e-14, ..Default::default() }).unwrap();
        for tol in [1e-8, 1e-9, 1e-10, 1e-11] {
            let sl = slide_to_rest(b, &s0, &SlideOptions { tol, ..Default::default() }).unwrap();
            let dx = (sl.end.x - r.end.x).hypot(sl.end.y - r.end.y);
            println!("{name} tol {tol:e}: dpos {dx:.1e} dth {:.1e} dt {:.1e} steps {} rej {} evals {} piv {}", (sl.end.theta - r.end.theta).abs(), (sl.stop.unwrap() - r.stop.unwrap()).abs(), sl.steps, sl.rejected, sl.rhs_evals, sl.pivots.len());
        }
    }
}
