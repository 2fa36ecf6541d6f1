use pushval_model::{slide_to_rest, Body, SlideOptions, SlideState, Support, Vec2};
fn main() {
    let sup = [
        (0.12, 0.08, 2.0),
        (-0.1, 0.09, 0.9),
        (-0.11, -0.07, 1.6),
        (0.09, -0.1, 0.4),
        (0.02, 0.01, 1.1),
    ];
    let s: Vec<Support> = sup.iter().map(|&(x, y, f)| Support { position: Vec2::new(x, y), friction: f }).collect();
    let body = Body::new(1.3, 0.011, Vec2::new(-0.1, 0.0), &s).unwrap();
    let rho = (0.011f64 / 1.3).sqrt();
    let start = SlideState { t: 0.0, x: 0.0, y: 0.0, theta: 1.0, vx: -0.3, vy: 0.5, omega: -20.0 };
    let sl = slide_to_rest(&body, &start, &SlideOptions::default()).unwrap();
    let stop = sl.stop.unwrap();
    println!("stop {stop} steps {} rej {} evals {} end {:?}", sl.steps, sl.rejected, sl.rhs_evals, sl.end);
    let fr: Vec<f64> = (1..=28).map(|k| 10f64.powf(-0.5 * k as f64)).collect();
    let ts: Vec<f64> = fr.iter().map(|f| stop * (1.0 - f)).collect();
    let sl = slide_to_rest(&body, &start, &SlideOptions { sample_times: &ts, ..Default::default() }).unwrap();
    for (s, f) in sl.samples.iter().zip(&fr) {
        let (sn, cs) = s.theta.sin_cos();
        let vb = Vec2::new(cs * s.vx + sn * s.vy, -sn * s.vx + cs * s.vy);
        let sp = (vb.norm_squared() + (rho * s.omega).powi(2)).sqrt();
        // slip of each support relative
        let slips: Vec<String> = sup.iter().map(|&(x, y, _)| format!("{:.3}", Vec2::new(vb.x - s.omega * y, vb.y + s.omega * x).norm() / sp)).collect();
        println!("{f:.1e} ratio {:.6} q ({:.4},{:.4},{:.4}) slips {:?}", vb.norm() / (rho * s.omega.abs()), vb.x / sp, vb.y / sp, rho * s.omega / sp, slips);
    }
    for tol in [1e-9, 1e-10, 1e-11, 1e-12, 1e-13] {
        let sl = slide_to_rest(&body, &start, &SlideOptions { tol, ..Default::default() }).unwrap();
        println!("tol {tol:e}: stop {:.15} x {:.15} y {:.15} th {:.15} steps {} rej {}", sl.stop.unwrap(), sl.end.x, sl.end.y, sl.end.theta, sl.steps, sl.rejected);
    }
}
