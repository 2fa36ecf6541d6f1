use pushval_model::*;
fn main() {
    let a = 0.125;
    let m = 1.0;
    let pts = [(-a, -a), (a, -a), (a, a), (-a, a)];
    let sup: Vec<Support> = pts
        .iter()
        .map(|&(x, y)| Support {
            position: Vec2::new(x, y),
            friction: 0.5 * m * 9.81 / 4.0,
        })
        .collect();
    let body = Body::new(
        m,
        m * (0.25f64.powi(2) * 2.0) / 12.0,
        Vec2::new(-a, -a),
        &sup,
    )
    .unwrap();
    for v in [0.2, 0.6, 1.0] {
        let push = Push {
            duration: 1.0,
            speed: v,
            phi: std::f64::consts::FRAC_PI_4 + 0.3,
        };
        let seg = SegmentDynamics::new(&body, &push);
        println!(
            "v={v} roots={:?} kin={:?} ls={}",
            seg.steady_states(),
            kinematic::omega(&body, &push),
            limit_surface::omega(&body, &push)
        );
    }
    let phis = [0.0, 0.5, std::f64::consts::FRAC_PI_4, 1.2, 0.3];
    let pushes: Vec<Push> = phis
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
    };
    for tol in [1e-6, 1e-9, 1e-12] {
        let t0 = std::time::Instant::now();
        let tr = DynamicModel {
            integrator: Integrator::Adaptive { tol },
            ..Default::default()
        }
        .simulate(&pb)
        .unwrap();
        let el = t0.elapsed();
        let l = tr.samples.last().unwrap();
        println!(
            "tol {tol:e}: {:?} {el:?} last {:?} segs {:?}",
            tr.stats,
            l,
            tr.segments.iter().map(|s| s.settled_at).collect::<Vec<_>>()
        );
    }
}
