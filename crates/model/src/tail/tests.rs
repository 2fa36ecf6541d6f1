//! Unit tests of the series tail: the linearising map against closed
//! forms, the tail against the integrated transient, the sampling cursor
//! against single evaluations.

use super::*;

const TAU: f64 = 0.1;

/// Taylor coefficients of a polynomial `g(ω* + δ) = −δ/τ + q δ² + r δ³`.
fn poly_g(q: f64, r: f64) -> [f64; ORDER + 1] {
    let mut g = [0.0; ORDER + 1];
    g[1] = -1.0 / TAU;
    g[2] = q;
    g[3] = r;
    g
}

fn tail_for(q: f64, r: f64, omega: f64, delta: f64) -> Tail {
    let (a, k) = linearising_map(&poly_g(q, r), 0.0, 0.0);
    assert_eq!(k, ORDER);
    let mut tail = Tail::arc(0.25, Vec2::new(0.1, -0.2), 0.4, omega, Vec2::new(0.7, 0.7));
    tail.tau = TAU;
    tail.alpha = series_for(&a, ORDER, delta).expect("invertible");
    tail
}

/// Two closed forms of the linearising map: for the logistic
/// `δ̇ = −δ/τ + qδ²`, `h(z) = z/(1 + qτz)`, so `a_k = (−qτ)^{k−1}`; for
/// `δ̇ = −δ/τ + rδ³` (a Bernoulli equation in `δ⁻²`),
/// `h(z) = z (1 + rτz²)^{−1/2}`: odd powers only, binomial coefficients.
#[test]
fn linearising_map_matches_closed_forms() {
    let q = 0.8;
    let (a, _) = linearising_map(&poly_g(q, 0.0), 0.0, 0.0);
    for (k, ak) in a.iter().enumerate() {
        let want = (-q * TAU).powi(k as i32);
        assert!(
            (ak - want).abs() <= 1e-13 * want.abs(),
            "logistic a_{} = {ak:e}, want {want:e}",
            k + 1
        );
    }
    let r = -2.0;
    let (a, _) = linearising_map(&poly_g(0.0, r), 0.0, 0.0);
    let mut binom = 1.0; // C(−1/2, m)
    for m in 0..ORDER / 2 {
        let want = binom * (r * TAU).powi(m as i32);
        assert!(
            (a[2 * m] - want).abs() <= 1e-13 * want.abs(),
            "cubic a_{} = {:e}, want {want:e}",
            2 * m + 1,
            a[2 * m]
        );
        assert_eq!(a[2 * m + 1], 0.0);
        binom *= (-0.5 - m as f64) / (m as f64 + 1.0);
    }
}

/// The series tail against a fine RK4 integration of
/// `δ̇ = −δ/τ + qδ² + rδ³` with the angle and the position ODE
/// `ċ = R(θ) v`: to integration accuracy, not to some order in δ₀.
#[test]
fn tail_follows_the_integrated_transient() {
    for (q, r, omega, delta) in [
        (0.8, -2.0, -0.65, 0.3),
        (-1.5, 3.0, 0.0, -0.4),
        (0.8, 0.0, 0.5, 0.6),
    ] {
        let tail = tail_for(q, r, omega, delta);
        let f = |y: [f64; 4]| {
            let d = y[1] - omega;
            let (s, c) = y[0].sin_cos();
            [
                y[1],
                -d / TAU + q * d * d + r * d * d * d,
                c * tail.vel.x - s * tail.vel.y,
                s * tail.vel.x + c * tail.vel.y,
            ]
        };
        let mut y = [tail.theta, omega + delta, tail.c.x, tail.c.y];
        let h = 1e-4;
        let mut cur = TailCursor::new(tail);
        let (mut err_c, mut err_w, mut err_th): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for k in 1..=20_000 {
            let add = |a: [f64; 4], b: [f64; 4], s: f64| std::array::from_fn(|i| a[i] + s * b[i]);
            let k1 = f(y);
            let k2 = f(add(y, k1, h / 2.0));
            let k3 = f(add(y, k2, h / 2.0));
            let k4 = f(add(y, k3, h));
            y = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
            if k % 100 == 0 {
                let p = cur.eval(tail.t + k as f64 * h);
                err_c = err_c.max(((p.c.x - y[2]).powi(2) + (p.c.y - y[3]).powi(2)).sqrt());
                err_w = err_w.max((p.omega - y[1]).abs());
                err_th = err_th.max((p.theta - y[0]).abs());
            }
        }
        assert!(
            err_w < 1e-11 && err_th < 1e-12 && err_c < 1e-12,
            "q {q}, r {r}, δ₀ {delta}: ω {err_w:e}, θ {err_th:e}, c {err_c:e}"
        );
    }
}

/// The batched [`TailCursor::fill`] gives the same samples as one
/// [`TailCursor::eval`] per sample (same arithmetic, other order of
/// phasor steps and poses, terms cut per block), across block
/// boundaries, for a relaxing tail and for a steady arc with ω* = 0 (the
/// series branch of `A₀`).
#[test]
fn the_end_state_does_not_depend_on_the_samples() {
    // A fresh cursor's `end` is its first `eval` (phasors taken at once
    // either way); after 1,000 samples of advanced phasors the two differ
    // by rounding only, and `end` is the same before and after them.
    for (omega, delta) in [(-0.65, 0.2), (0.0, 0.0), (0.3, -0.05)] {
        let tail = tail_for(0.8, -2.0, omega, delta);
        let t1 = tail.t + 10.0;
        let fresh = TailCursor::new(tail).end(t1);
        let once = TailCursor::new(tail).eval(t1);
        assert_eq!(
            (fresh.c, fresh.theta, fresh.omega),
            (once.c, once.theta, once.omega)
        );
        let mut cur = TailCursor::new(tail);
        let times: Vec<f64> = (0..1000).map(|k| tail.t + 0.01 * k as f64).collect();
        cur.fill(&times, Vec2::new(-0.125, -0.125), &mut Vec::new());
        let after = cur.end(t1);
        assert_eq!(
            (after.c, after.theta, after.omega),
            (fresh.c, fresh.theta, fresh.omega)
        );
        let advanced = cur.eval(t1);
        assert!(
            (advanced.c - fresh.c).norm() < 1e-12 && (advanced.theta - fresh.theta).abs() < 1e-12
        );
    }
}

#[test]
fn fill_matches_eval() {
    for (omega, delta) in [(-0.65, 0.2), (0.0, 0.0), (0.3, -0.05)] {
        let tail = tail_for(0.8, -2.0, omega, delta);
        let pc = Vec2::new(-0.125, -0.125);
        let times: Vec<f64> = (0..100).map(|k| 0.25 + 0.01 * k as f64).collect();
        let mut batch = Vec::new();
        TailCursor::new(tail).fill(&times, pc, &mut batch);
        let mut one = TailCursor::new(tail);
        assert_eq!(batch.len(), times.len());
        for (smp, &t) in batch.iter().zip(&times) {
            let p = one.eval(t);
            let (sin, cos) = p.theta.sin_cos();
            let x = p.c.x - (cos * pc.x - sin * pc.y);
            let y = p.c.y - (sin * pc.x + cos * pc.y);
            assert_eq!(smp.t, t);
            assert!(
                (smp.x - x).abs() < 1e-14 && (smp.y - y).abs() < 1e-14,
                "t {t}: {:e} {:e}",
                smp.x - x,
                smp.y - y
            );
            assert!((smp.theta - p.theta).abs() < 1e-15 && (smp.omega - p.omega).abs() < 1e-15);
        }
        // And the arc itself: with δ = 0 the angle grows at exactly ω*.
        if delta == 0.0 {
            let last = batch.last().unwrap();
            assert!((last.theta - (0.4 + omega * 0.99)).abs() < 1e-14);
        }
    }
}

/// The tail's angle, ω and rotation against the logistic solution written
/// out directly: `θ = θ_s + ω* s − ln(1 − x)/q`, `ω = ω* + δ₀E/(1 − x)`,
/// `x = qτδ₀(1 − E)`, both signs of q and δ₀, δ₀ down to 1e-5, and q = 0.
/// The rotation is the series `e^{iθ} = e^{i(θ_s+ε∞)} P Σ γ_m E^m` that
/// [`TailCursor::fill`] uses: with the contact point at rest (`V = 0`)
/// and `p_c = (1, 0)` its samples are `c − (cos θ, sin θ)`.
#[test]
fn angle_and_rate_follow_the_logistic_solution() {
    for (q, delta) in [
        (2.5, 0.3),
        (-2.5, 0.3),
        (0.8, 0.05),
        (0.8, -0.05),
        (0.8, 1e-5),
        (0.0, 0.3),
    ] {
        let tail = tail_for(q, 0.0, -0.65, delta);
        let td = TAU * delta;
        let mut cur = TailCursor::new(tail);
        let times: Vec<f64> = (0..200).map(|k| tail.t + 0.005 * k as f64).collect();
        let mut turned = Vec::new();
        let at_rest = Tail {
            vel: Vec2::zeros(),
            ..tail
        };
        TailCursor::new(at_rest).fill(&times, Vec2::new(1.0, 0.0), &mut turned);
        for (k, at) in turned.iter().enumerate() {
            let s = 0.005 * k as f64;
            let p = cur.eval(tail.t + s);
            let e = (-s / TAU).exp();
            let x = q * td * (1.0 - e);
            let eps = if q == 0.0 {
                td * (1.0 - e)
            } else {
                -(-x).ln_1p() / q
            };
            let theta = tail.theta + tail.omega * s + eps;
            let omega = tail.omega + delta * e / (1.0 - x);
            assert!(
                (p.theta - theta).abs() <= 1e-14,
                "q {q}, δ₀ {delta}, s {s}: θ {} against {theta}",
                p.theta
            );
            assert!((p.omega - omega).abs() <= 1e-14, "q {q}, δ₀ {delta}, s {s}");
            let (x, y) = (tail.c.x - at.x, tail.c.y - at.y);
            assert!(
                (x - theta.cos()).abs() <= 1e-14 && (y - theta.sin()).abs() <= 1e-14,
                "q {q}, δ₀ {delta}, s {s}: rotation off by {:e}, {:e}",
                x - theta.cos(),
                y - theta.sin()
            );
        }
    }
}
