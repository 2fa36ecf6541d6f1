//! The scaling factor κ = ω* / (v_c ψ) and its Froude series
//! (`pushval_model::kappa`). Expected values come from the exact steady root
//! of the dynamic model (through `kappa_exact`, i.e. the existing root
//! finder) and from the moment by `SegmentDynamics`, never from the series.

use pushval_model::kappa::{
    first_order_froude_limit, froude_length, froude_number, kappa_exact, kappa_series,
    reduced_moment, second_order_froude_limit, speed_for_froude,
};
use pushval_model::{Body, Push, SegmentDynamics, Support, Vec2};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

const G: f64 = 9.81;

/// The paper's plate: 0.25 m square, four corner supports with equal loads,
/// μ = 0.5, pushed at the corner (−0.125, −0.125); `gravity` in m/s².
fn paper_plate_in(mass: f64, gravity: f64) -> Body {
    let h = 0.125;
    let sup: Vec<Support> = [(-h, -h), (h, -h), (h, h), (-h, h)]
        .iter()
        .map(|&(x, y)| Support {
            position: Vec2::new(x, y),
            friction: 0.5 * mass * gravity / 4.0,
        })
        .collect();
    Body::new(mass, mass * 0.25 * 0.25 / 6.0, Vec2::new(-h, -h), &sup).unwrap()
}

fn paper_plate() -> Body {
    paper_plate_in(1.0, G)
}

/// The paper plate's push directions used below (rad): the brief's
/// π/4 + 0.3, and two others inside the corner's cone.
const PLATE_PHIS: [f64; 3] = [FRAC_PI_4 + 0.3, 0.2, 1.2];

/// A triangle on its three vertices with unequal loads (statics: the loads
/// are the barycentric weights 0.5, 0.3, 0.2 of the centre of mass) and
/// unequal μ (0.4, 0.6, 0.5), pushed on edge AB. `mirror` reflects it in the
/// x axis (y → −y).
fn triangle(mass: f64, gravity: f64, mirror: bool) -> Body {
    let v = [
        Vec2::new(-0.15, -0.1),
        Vec2::new(0.2, -0.05),
        Vec2::new(0.0, 0.18),
    ];
    let w = [0.5, 0.3, 0.2];
    let mu = [0.4, 0.6, 0.5];
    let cm = v[0] * w[0] + v[1] * w[1] + v[2] * w[2];
    let flip = |p: Vec2| if mirror { Vec2::new(p.x, -p.y) } else { p };
    let sup: Vec<Support> = (0..3)
        .map(|i| Support {
            position: flip(v[i] - cm),
            friction: mu[i] * w[i] * mass * gravity,
        })
        .collect();
    let contact = flip(v[0] * 0.6 + v[1] * 0.4 - cm);
    Body::new(mass, 0.013 * mass, contact, &sup).unwrap()
}

/// Push directions for the triangle: the inward normal of AB and ±0.5 rad.
fn triangle_phis() -> [f64; 3] {
    let phi0 = 0.35f64.atan2(-0.05);
    [phi0, phi0 - 0.5, phi0 + 0.5]
}

/// The cases the coefficient tests run: (name, body, φ).
fn cases() -> Vec<(&'static str, Body, f64)> {
    let mut c: Vec<_> = PLATE_PHIS
        .iter()
        .map(|&p| ("plate", paper_plate(), p))
        .collect();
    c.extend(
        triangle_phis()
            .iter()
            .map(|&p| ("triangle", triangle(1.0, G, false), p)),
    );
    c
}

fn exact(body: &Body, phi: f64, fr: f64) -> f64 {
    kappa_exact(body, phi, fr).unwrap_or_else(|| panic!("no κ at φ {phi}, Fr {fr}"))
}

/// `(κ₁, κ₂)` from the exact root alone: `K(Fr) = (κ(Fr) − 1) / Fr =
/// κ₁ + κ₂ Fr + …` sampled at `Fr = j h`, `j = 1 … n`, interpolated by a
/// polynomial (Newton's divided differences) whose constant and linear
/// coefficients are returned.
fn finite_difference_coefficients(body: &Body, phi: f64, h: f64, n: usize) -> (f64, f64) {
    let xs: Vec<f64> = (1..=n).map(|j| j as f64 * h).collect();
    let mut d: Vec<f64> = xs
        .iter()
        .map(|&x| (exact(body, phi, x) - 1.0) / x)
        .collect();
    for k in 1..n {
        for i in (k..n).rev() {
            d[i] = (d[i] - d[i - 1]) / (xs[i] - xs[i - k]);
        }
    }
    // p(x) = Σ d_k Π_{i<k} (x − x_i); keep the x⁰ and x¹ coefficients.
    let (mut c0, mut c1) = (0.0, 0.0);
    for k in 0..n {
        let (mut a0, mut a1) = (1.0, 0.0);
        for &x in &xs[..k] {
            (a0, a1) = (-x * a0, a0 - x * a1);
        }
        c0 += d[k] * a0;
        c1 += d[k] * a1;
    }
    (c0, c1)
}

/// κ₁ and κ₂ of the closed form against a degree-7 fit of the exact root
/// over Fr = 0.01 … 0.08. The fit's own error (truncation and rounding),
/// found by varying the step and degree, is below 1e-10 relative for κ₁
/// and 3e-7 for κ₂; the rounding is largest for the triangle pushed at
/// φ₀ − 0.5, whose ψ is small.
#[test]
fn series_coefficients_match_finite_differences_of_the_exact_root() {
    for (name, body, phi) in cases() {
        let s = kappa_series(&body, phi).expect("a series");
        let (k1, k2) = finite_difference_coefficients(&body, phi, 1e-2, 8);
        assert!(
            (s.kappa1 - k1).abs() <= 1e-9 * k1.abs(),
            "{name} φ {phi}: κ₁ {} against {k1}",
            s.kappa1
        );
        assert!(
            (s.kappa2 - k2).abs() <= 1e-6 * k2.abs(),
            "{name} φ {phi}: κ₂ {} against {k2}",
            s.kappa2
        );
    }
}

/// `h`, `h'`, `h''` in closed form against the friction moment of
/// `SegmentDynamics` (divided by Σ F_i) and its central differences.
#[test]
fn reduced_moment_derivatives_match_differences_of_the_moment() {
    for (name, body, phi) in cases() {
        let seg = SegmentDynamics::new(
            &body,
            &Push {
                duration: 1.0,
                speed: 1.0,
                phi,
            },
        );
        let total = body.total_friction();
        let h = |s: f64| seg.friction_moment_at(1.0, s) / total;
        for s in [-5.0, -1.1, 0.0, 0.7, 3.0] {
            let [h0, h1, h2] = reduced_moment(&body, phi, s);
            assert!((h0 - h(s)).abs() <= 1e-14, "{name} φ {phi} s {s}: h");
            let d = 1e-4;
            let fd1 = (h(s + d) - h(s - d)) / (2.0 * d);
            let fd2 = (h(s + d) - 2.0 * h(s) + h(s - d)) / (d * d);
            assert!(
                (h1 - fd1).abs() <= 1e-7 * h1.abs().max(1e-3),
                "{name} φ {phi} s {s}: h' {h1} against {fd1}"
            );
            assert!(
                (h2 - fd2).abs() <= 1e-4 * h2.abs().max(1e-3),
                "{name} φ {phi} s {s}: h'' {h2} against {fd2}"
            );
            // Friction only resists: h is non-increasing.
            assert!(h1 <= 0.0, "{name} φ {phi} s {s}: h' {h1}");
        }
    }
}

/// κ → 1 as Fr → 0, and linearly: each decade of Fr takes a decade off
/// `κ − 1`.
#[test]
fn kappa_tends_to_one_as_the_froude_number_vanishes() {
    for (name, body, phi) in cases() {
        assert_eq!(kappa_exact(&body, phi, 0.0), Some(1.0));
        let k = exact(&body, phi, 1e-12);
        assert!((k - 1.0).abs() <= 1e-11, "{name} φ {phi}: κ(1e-12) = {k}");
        for fr in [1e-7, 1e-6, 1e-5, 1e-4, 1e-3] {
            let ratio = (exact(&body, phi, fr) - 1.0) / (exact(&body, phi, 0.1 * fr) - 1.0);
            assert!(
                (ratio - 10.0).abs() <= 0.1,
                "{name} φ {phi} Fr {fr}: (κ − 1) ratio per decade {ratio}"
            );
        }
    }
}

/// At a fixed Froude number κ does not depend on the mass, the inertia or
/// gravity (the speed is chosen to keep Fr): mass cancels from the steady
/// state, and v_c² enters only through Fr.
#[test]
fn kappa_is_independent_of_mass_at_fixed_froude() {
    let phis = [PLATE_PHIS[0], triangle_phis()[1]];
    let make = |which: usize, m: f64, g: f64| {
        if which == 0 {
            paper_plate_in(m, g)
        } else {
            triangle(m, g, false)
        }
    };
    for (which, &phi) in phis.iter().enumerate() {
        let reference = make(which, 1.0, G);
        let s0 = kappa_series(&reference, phi).unwrap();
        for (m, g) in [(0.05, G), (40.0, G), (3.0, 1.62)] {
            let body = make(which, m, g);
            let s = kappa_series(&body, phi).unwrap();
            assert!((s.kappa1 - s0.kappa1).abs() <= 1e-12 * s0.kappa1.abs());
            assert!((s.kappa2 - s0.kappa2).abs() <= 1e-12 * s0.kappa2.abs());
            for fr in [0.01, 0.3, 2.0] {
                let (k, k0) = (exact(&body, phi, fr), exact(&reference, phi, fr));
                assert!(
                    (k - k0).abs() <= 1e-12 * k0,
                    "case {which} m {m} g {g} Fr {fr}: {k} against {k0}"
                );
                // The speed differs (g) or not (m), the Froude number is the same.
                let v = speed_for_froude(&body, fr);
                assert!((froude_number(&body, v) - fr).abs() <= 1e-14 * fr);
            }
        }
    }
}

/// Mirrored geometry pushed in the mirrored direction turns the other way
/// at the same rate: ψ changes sign, κ and its coefficients do not. The
/// plate is its own mirror image in the diagonal y = x (φ → π/2 − φ); the
/// triangle (unequal loads) is mirrored in the x axis (φ → −φ).
#[test]
fn mirrored_geometry_gives_the_same_kappa() {
    let plate = paper_plate();
    let tri = triangle(1.0, G, false);
    let tri_m = triangle(1.0, G, true);
    let pairs: Vec<(&Body, f64, &Body, f64)> = PLATE_PHIS
        .iter()
        .map(|&p| (&plate, p, &plate, FRAC_PI_2 - p))
        .chain(triangle_phis().iter().map(|&p| (&tri, p, &tri_m, -p)))
        .collect();
    for (a, pa, b, pb) in pairs {
        let (sa, sb) = (kappa_series(a, pa).unwrap(), kappa_series(b, pb).unwrap());
        assert!((sa.psi + sb.psi).abs() <= 1e-12 * sa.psi.abs(), "φ {pa}");
        assert!((sa.kappa1 - sb.kappa1).abs() <= 1e-12 * sa.kappa1.abs());
        assert!((sa.kappa2 - sb.kappa2).abs() <= 1e-12 * sa.kappa2.abs());
        for fr in [0.001, 0.1, 1.0, 5.0] {
            let (ka, kb) = (exact(a, pa, fr), exact(b, pb, fr));
            assert!(
                (ka - kb).abs() <= 1e-12 * ka,
                "φ {pa} Fr {fr}: {ka} against {kb}"
            );
        }
    }
}

/// At small Fr the second-order formula beats the first-order one, and the
/// errors scale as the next terms say: the first-order error like Fr²
/// (with the coefficient κ₂), the ratio of the two errors like Fr.
#[test]
fn second_order_beats_first_order_at_small_froude() {
    for (name, body, phi) in cases() {
        let s = kappa_series(&body, phi).unwrap();
        let errors = |fr: f64| {
            let k = exact(&body, phi, fr);
            (
                (s.first_order(fr) - k).abs() / k,
                (s.second_order(fr) - k).abs() / k,
            )
        };
        let mut prev_ratio = None;
        for fr in [0.02, 0.01, 0.005, 0.0025] {
            let (e1, e2) = errors(fr);
            assert!(e2 < 0.1 * e1, "{name} φ {phi} Fr {fr}: {e2} vs {e1}");
            let c2 = e1 / (fr * fr);
            assert!(
                (c2 / s.kappa2.abs() - 1.0).abs() <= 0.1,
                "{name} φ {phi} Fr {fr}: e₁/Fr² {c2}, κ₂ {}",
                s.kappa2
            );
            let ratio = e2 / e1;
            if let Some(p) = prev_ratio {
                let halving = p / ratio;
                assert!(
                    (1.8..=2.2).contains(&halving),
                    "{name} φ {phi} Fr {fr}: e₂/e₁ fell by {halving} when Fr halved"
                );
            }
            prev_ratio = Some(ratio);
        }
    }
}

/// The 1 % limit of the first-order formula: below it the error is within
/// 1 % everywhere, just above it is not; the second-order formula lasts
/// longer; for a small tolerance ε the limit tends to √(ε/|κ₂|).
#[test]
fn first_order_limit_bounds_the_error() {
    for (name, body, phi) in cases() {
        let s = kappa_series(&body, phi).unwrap();
        let err = |fr: f64| {
            let k = exact(&body, phi, fr);
            (s.first_order(fr) - k).abs() / k
        };
        let limit = first_order_froude_limit(&body, phi, 0.01).unwrap();
        assert!(limit.is_finite() && limit > 0.0, "{name} φ {phi}: {limit}");
        for j in 1..=50 {
            let fr = limit * j as f64 / 50.0;
            assert!(
                err(fr) <= 0.01,
                "{name} φ {phi}: error {} at Fr {fr}",
                err(fr)
            );
        }
        assert!(err(limit * 1.001) > 0.01, "{name} φ {phi}: limit {limit}");
        let limit2 = second_order_froude_limit(&body, phi, 0.01).unwrap();
        assert!(limit2 > limit, "{name} φ {phi}: {limit2} vs {limit}");
        let small = first_order_froude_limit(&body, phi, 1e-6).unwrap();
        let predicted = (1e-6 / s.kappa2.abs()).sqrt();
        assert!(
            (small / predicted - 1.0).abs() <= 0.05,
            "{name} φ {phi}: {small} against √(ε/|κ₂|) = {predicted}"
        );
    }
}

/// Pushing along a line perpendicular to the lever arm (`p_c · n_φ = 0`)
/// has no inertial moment: κ = 1 at every Fr, κ₁ = κ₂ = 0 and the first-order
/// formula never fails.
#[test]
fn a_push_perpendicular_to_the_lever_arm_has_kappa_one() {
    let h = 0.125;
    let plate = paper_plate();
    let sup: Vec<Support> = plate.supports().collect();
    let contact = Vec2::new(-h, -0.06);
    let body = Body::new(1.0, 0.01, contact, &sup).unwrap();
    let phi = contact.x.atan2(-contact.y); // n ∝ (0.06, −0.125)
    assert!(phi.cos() > 0.0);
    let s = kappa_series(&body, phi).unwrap();
    assert!(s.kappa1.abs() <= 1e-14 && s.kappa2.abs() <= 1e-14, "{s:?}");
    for fr in [1e-3, 1.0, 100.0] {
        let k = exact(&body, phi, fr);
        assert!((k - 1.0).abs() <= 1e-12, "Fr {fr}: {k}");
    }
    assert_eq!(
        first_order_froude_limit(&body, phi, 0.01),
        Some(f64::INFINITY)
    );
}

/// Pushing away from the centre of mass (`p_c · n_φ > 0`) makes κ₁ > 0: the
/// inertial moment drives the rotation, and at a finite Fr the steady state
/// connected to ψ folds away (ω runs off; `kappa_exact` is None). The series
/// still matches the exact root below the fold, and the limit lies below it.
#[test]
fn pushing_away_from_the_centre_of_mass_folds() {
    let plate = paper_plate();
    let sup: Vec<Support> = plate.supports().collect();
    let body = Body::new(1.0, 0.01, Vec2::new(-0.125, 0.1), &sup).unwrap();
    let phi: f64 = 1.4;
    assert!(body.contact().dot(&Vec2::new(phi.cos(), phi.sin())) > 0.0);
    let s = kappa_series(&body, phi).unwrap();
    assert!(s.kappa1 > 0.0, "{s:?}");
    let (k1, k2) = finite_difference_coefficients(&body, phi, 3e-3, 6);
    assert!(
        (s.kappa1 - k1).abs() <= 1e-9 * k1.abs(),
        "{} vs {k1}",
        s.kappa1
    );
    assert!(
        (s.kappa2 - k2).abs() <= 1e-6 * k2.abs(),
        "{} vs {k2}",
        s.kappa2
    );
    assert!(exact(&body, phi, 1.0) > 1.0);
    assert_eq!(kappa_exact(&body, phi, 10.0), None);
    // κ grows monotonically up to the fold.
    let mut prev = 1.0;
    let mut fr = 0.01;
    while let Some(k) = kappa_exact(&body, phi, fr) {
        assert!(k > prev, "Fr {fr}: {k} after {prev}");
        prev = k;
        fr *= 1.1;
    }
    let limit = first_order_froude_limit(&body, phi, 0.01).unwrap();
    assert!(limit < fr, "limit {limit}, fold before {fr}");
}

/// No series where none exists: ψ = 0 (a push along the plate's diagonal
/// through the centre of mass), the contact at the centre of mass (L = 0),
/// a kinematic root that is a pivot about a support, and `h'(ψ) = 0` (every
/// support on the line through the contact perpendicular to the push).
#[test]
fn degenerate_cases_have_no_series() {
    let plate = paper_plate();
    assert_eq!(kappa_series(&plate, FRAC_PI_4), None);
    assert_eq!(kappa_exact(&plate, FRAC_PI_4, 0.1), None);
    assert_eq!(first_order_froude_limit(&plate, FRAC_PI_4, 0.01), None);

    let sup: Vec<Support> = plate.supports().collect();
    let centred = Body::new(1.0, 0.01, Vec2::zeros(), &sup).unwrap();
    assert_eq!(froude_length(&centred), 0.0);
    assert_eq!(kappa_series(&centred, 0.3), None);
    assert_eq!(kappa_exact(&centred, 0.3, 0.1), None);

    // Pushed along +y at the corner (−0.125, −0.125) with most of the
    // friction at (0.125, −0.125): the object pivots about that support,
    // ψ = −1 / 0.25 rad/m.
    let pivot = Body::new(
        1.0,
        0.01,
        Vec2::new(-0.125, -0.125),
        &[
            Support {
                position: Vec2::new(0.125, -0.125),
                friction: 10.0,
            },
            Support {
                position: Vec2::new(0.125, 0.125),
                friction: 0.1,
            },
            Support {
                position: Vec2::new(-0.125, 0.125),
                friction: 0.1,
            },
        ],
    )
    .unwrap();
    let psi = pushval_model::kinematic::psi(&pivot, FRAC_PI_2).unwrap();
    assert!((psi + 4.0).abs() <= 1e-9, "{psi}");
    assert_eq!(kappa_series(&pivot, FRAC_PI_2), None);

    // Supports at r = (0, 0.125) and (0, −0.25) from the contact, friction
    // 2 and 1 N, push along +x (n_φ = (1, 0) exactly): both have
    // r · n_φ = 0, so h is piecewise constant, zero for −4 < s < 8 rad/m,
    // and h' = 0 there. (Dyadic numbers: h is exactly 0 there, not
    // rounding noise, so ψ lands inside the interval.)
    let pc = Vec2::new(-0.125, -0.125);
    let flat = Body::new(
        1.0,
        0.01,
        pc,
        &[
            Support {
                position: pc + Vec2::new(0.0, 0.125),
                friction: 2.0,
            },
            Support {
                position: pc + Vec2::new(0.0, -0.25),
                friction: 1.0,
            },
        ],
    )
    .unwrap();
    let psi = pushval_model::kinematic::psi(&flat, 0.0).unwrap();
    assert!(psi > -4.0 && psi < 8.0, "{psi}");
    let [h0, h1, _] = reduced_moment(&flat, 0.0, psi);
    assert!(h0 == 0.0 && h1 == 0.0, "ψ {psi}: h {h0}, h' {h1}");
    assert_eq!(kappa_series(&flat, 0.0), None);
}

/// The numbers for the report: κ₁, κ₂ and the 1 % limits of the paper
/// plate (printed with `--nocapture`), pinned loosely so a change shows.
#[test]
fn paper_plate_numbers() {
    let plate = paper_plate();
    for phi in PLATE_PHIS {
        let s = kappa_series(&plate, phi).unwrap();
        let l1 = first_order_froude_limit(&plate, phi, 0.01).unwrap();
        let l2 = second_order_froude_limit(&plate, phi, 0.01).unwrap();
        println!(
            "φ {phi:.4}: ψ {:.6} rad/m, κ₁ {:.6}, κ₂ {:.6}, L {:.6} m, 1% limit Fr {:.4} (first order), {:.4} (second order)",
            s.psi, s.kappa1, s.kappa2, s.froude_length, l1, l2
        );
        assert!(s.kappa1 < 0.0 && s.kappa2 > 0.0);
        assert!((0.05..0.5).contains(&l1), "{l1}");
    }
}
