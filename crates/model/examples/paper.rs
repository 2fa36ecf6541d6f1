//! Work and error of the dynamic model on the 10 s paper trajectory
//! (0.25 m plate, 1 m/s, five 2 s segments), against a run at 1e-13.
use pushval_model::*;
fn main() {
    let a = 0.125;
    let sup: Vec<Support> = [(-a, -a), (a, -a), (a, a), (-a, a)]
        .iter()
        .map(|&(x, y)| Support {
            position: Vec2::new(x, y),
            friction: 0.5 * 9.81 / 4.0,
        })
        .collect();
    let body = Body::new(1.0, 0.25f64.powi(2) / 6.0, Vec2::new(-a, -a), &sup).unwrap();
    let q = std::f64::consts::FRAC_PI_4;
    let pushes: Vec<Push> = [q + 0.3, q, q - 0.3, q + 0.5, q + 0.15]
        .iter()
        .map(|&phi| Push {
            duration: 2.0,
            speed: 1.0,
            phi,
        })
        .collect();
    let pb = Problem {
        body,
        limits: ContactLimits::default(),
        pushes,
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    };
    let reference = DynamicModel {
        integrator: Integrator::Dop853 { tol: 1e-14 },
        ..Default::default()
    }
    .simulate(&pb)
    .unwrap();
    for skip in [true, false] {
        for (name, mk) in [("dp5", 0), ("dop853", 1)] {
            for tol in [1e-6, 1e-8, 1e-9, 1e-10, 1e-12] {
                let integrator = if mk == 0 {
                    Integrator::Adaptive { tol }
                } else {
                    Integrator::Dop853 { tol }
                };
                let m = DynamicModel {
                    integrator,
                    skip_settled: skip,
                    ..Default::default()
                };
                let t0 = std::time::Instant::now();
                let n = 50;
                let mut tr = None;
                for _ in 0..n {
                    tr = Some(m.simulate(&pb).unwrap());
                }
                let el = t0.elapsed() / n;
                let tr = tr.unwrap();
                let err = tr
                    .samples
                    .iter()
                    .zip(&reference.samples)
                    .map(|(p, q)| ((p.x - q.x).powi(2) + (p.y - q.y).powi(2)).sqrt())
                    .fold(0.0, f64::max);
                println!(
                    "skip={skip} {name} tol={tol:e}: rhs {} steps {} err {err:.2e} m  {el:?}",
                    tr.stats.rhs_evals, tr.stats.steps
                );
            }
        }
    }
}
