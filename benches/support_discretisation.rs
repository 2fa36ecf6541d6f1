//! The cheapest support discretisation of a uniform-pressure footprint for a
//! given error in ω*: a uniform grid of cell centres against a tensor
//! Gauss–Legendre rule over the 0.25 m square (paper plate, corner push at
//! φ = π/4 + 0.3, 1 m/s). Writes `results/support_discretisation.csv`.
//!
//! `cargo bench --bench support_discretisation`
//!
//! The reference is the 64 × 64 Gauss–Legendre rule (checked against the
//! grid, which converges to it at second order). The friction integrand is
//! smooth when the instantaneous centre of rotation lies off the footprint, as
//! here, and Gauss–Legendre converges spectrally; with the centre on the
//! footprint its kink would slow both rules.

use std::num::NonZeroUsize;
use std::time::Instant;

use gauss_quad::GaussLegendre;
use pushval::outdir::Csv;
use pushval_model::{Body, Push, SegmentDynamics, Support, Vec2};

const HALF: f64 = 0.125;
const MASS: f64 = 1.0;
const MU_G: f64 = 0.5 * 9.81;

fn body(points: Vec<(Vec2, f64)>) -> Body {
    let total: f64 = points.iter().map(|p| p.1).sum();
    let sup: Vec<Support> = points
        .into_iter()
        .map(|(p, w)| Support {
            position: p,
            friction: MU_G * MASS * w / total,
        })
        .collect();
    Body::new(
        MASS,
        MASS * (2.0 * HALF).powi(2) / 6.0,
        Vec2::new(-HALF, -HALF),
        &sup,
    )
    .unwrap()
}

fn grid(n: usize) -> Body {
    let h = 2.0 * HALF / n as f64;
    body(
        (0..n * n)
            .map(|k| {
                (
                    Vec2::new(
                        -HALF + h * ((k % n) as f64 + 0.5),
                        -HALF + h * ((k / n) as f64 + 0.5),
                    ),
                    1.0,
                )
            })
            .collect(),
    )
}

fn gauss(n: usize) -> Body {
    let rule = GaussLegendre::new(NonZeroUsize::new(n).unwrap());
    let nw: Vec<(f64, f64)> = rule.iter().map(|(x, w)| (*x * HALF, *w)).collect();
    body(
        nw.iter()
            .flat_map(|&(x, wx)| nw.iter().map(move |&(y, wy)| (Vec2::new(x, y), wx * wy)))
            .collect(),
    )
}

fn omega(b: &Body, v: f64) -> f64 {
    let push = Push {
        duration: 1.0,
        speed: v,
        phi: std::f64::consts::FRAC_PI_4 + 0.3,
    };
    SegmentDynamics::new(b, &push).steady_states()[0].omega
}

fn main() {
    let mut csv = Csv::new(&[
        "rule",
        "per_axis",
        "supports",
        "speed",
        "omega_steady",
        "rel_err",
        "steady_time_s",
    ]);
    for v in [0.2, 1.0] {
        let reference = omega(&gauss(64), v);
        let mut run = |name: &str, n: usize, b: Body| {
            let t0 = Instant::now();
            let reps = 20;
            let mut w = 0.0;
            for _ in 0..reps {
                w = omega(&b, v);
            }
            let t = t0.elapsed().as_secs_f64() / reps as f64;
            let err = ((w - reference) / reference).abs();
            csv.row(&[
                name.to_string(),
                n.to_string(),
                b.len().to_string(),
                v.to_string(),
                format!("{w:.15e}"),
                format!("{err:.3e}"),
                format!("{t:.3e}"),
            ]);
        };
        for n in [2, 4, 8, 16, 32, 64, 128] {
            run("grid", n, grid(n));
        }
        for n in [2, 3, 4, 6, 8, 12, 16, 24, 32] {
            run("gauss_legendre", n, gauss(n));
        }
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("results");
    std::fs::create_dir_all(&dir).unwrap();
    pushval::atomic::write_atomic(&dir.join("support_discretisation.csv"), csv.as_bytes()).unwrap();
    print!("{}", csv.text());
}
