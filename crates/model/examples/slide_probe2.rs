use pushval_model::{slide_to_rest, Body, SlideOptions, SlideState, Support, Vec2};
fn main() {
    let a = 0.125;
    let sup = [(a, a, 3.0), (-a, a, 0.5), (-a, -a, 0.5), (a, -a, 0.5)];
    let s: Vec<Support> = sup.iter().map(|&(x, y, f)| Support { position: Vec2::new(x, y), friction: f }).collect();
    let body = Body::new(1.0, (2.0*a)*(2.0*a)/6.0, Vec2::new(-0.1, 0.0), &s).unwrap();
    let start = SlideState { t: 0.0, x: 0.0, y: 0.0, theta: 0.4, vx: 0.8, vy: 0.6, omega: 3.0 };
    let sl = slide_to_rest(&body, &start, &SlideOptions::default()).unwrap();
    println!("{:?} {} {} {:?}", sl.end, sl.steps, sl.rhs_evals, sl.pivots);
}
