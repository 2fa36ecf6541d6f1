//! The ellipsoidal limit-surface model (`pushval_model::limit_surface`)
//! against answers derived by hand, not read off the code.
//!
//! ## The derivation the expected values come from
//!
//! Quasi-static sliding: the support's friction wrench balances the pusher's,
//! so the friction wrench `(F, M)` (force, moment about the centre of
//! friction `o`) equals the pusher's `(f, p × f)`, `p` = contact − `o`.
//! The ellipsoidal limit surface (Goyal, Ruina & Papadopoulos; Lynch et al.)
//!
//! ```text
//! H(F, M) = |F|² / f_max² + M² / m_max² = 1
//! ```
//!
//! and the maximum-power principle makes the twist normal to it:
//! `(v_o, ω) = λ ∇H = 2λ (F / f_max², M / m_max²)`, `v_o` the velocity of the
//! material point at `o`. Eliminating λ and the force:
//! `ω m_max² = 2λ M = 2λ p × f = p × (v_o f_max²)`, i.e. with `c = m_max/f_max`
//!
//! ```text
//! ω c² = p × v_o                                     (1)
//! ```
//!
//! The contact sticks: its velocity is the pusher's,
//! `v_o + ω D p = v_c n_φ`, so `v_o = v_c n_φ − ω D p`, and with
//! `p × (D p) = |p|²`, (1) gives `ω (c² + |p|²) = v_c (p × n_φ)`.
//!
//! * Push line through `o` (`p ∥ n_φ`): `ω = 0`.
//! * Push perpendicular to the lever arm (`n_φ ⊥ p`, `|p| = r`):
//!   `ω = ± v_c r / (c² + r²)`, the sign of `p × n_φ`.
//!
//! `m_max`, for supports of fixed friction magnitude `F_i`: the largest
//! moment about `o` is reached in pure rotation about `o`, where support `i`
//! moves along `D (p_i − o)` and its friction moment about `o` is
//! `F_i |p_i − o|` (force ⊥ lever arm), so `m_max = Σ F_i |p_i − o|`; the
//! force `f_max = Σ F_i` in pure translation. For a square of half side `a`
//! with equal loads on its corners `o` is the centre, every `|p_i − o| = a√2`
//! and `c = a√2`; for `N` equal loads on a ring of radius `R`, `c = R`; for two
//! supports `2d` apart with friction `F₁`, `F₂`, `o` divides the segment in
//! the ratio `F₂ : F₁` and `m_max = F₁ · 2d F₂/(F₁+F₂) + F₂ · 2d F₁/(F₁+F₂)
//! = 4 d F₁ F₂ / (F₁ + F₂)`.

use pushval_model::limit_surface::{characteristic_length, omega};
use pushval_model::{
    Body, Initial, LimitSurfaceModel, Problem, Push, Simulator, Support, Switching, Vec2,
};
use std::f64::consts::{FRAC_PI_4, PI, SQRT_2};

fn body(contact: Vec2, supports: &[(f64, f64, f64)]) -> Body {
    let sup: Vec<Support> = supports
        .iter()
        .map(|&(x, y, friction)| Support {
            position: Vec2::new(x, y),
            friction,
        })
        .collect();
    Body::new(1.0, 0.01, contact, &sup).unwrap()
}

/// Square of half side `a`, equal friction `f` at the corners.
fn square(a: f64, f: f64, contact: Vec2) -> Body {
    body(contact, &[(-a, -a, f), (a, -a, f), (a, a, f), (-a, a, f)])
}

/// `n` equal supports on a ring of radius `r` about `centre`.
fn ring(n: usize, r: f64, centre: Vec2, contact: Vec2) -> Body {
    let s: Vec<(f64, f64, f64)> = (0..n)
        .map(|k| {
            let t = 2.0 * PI * (k as f64 + 0.5) / n as f64;
            (centre.x + r * t.cos(), centre.y + r * t.sin(), 0.7)
        })
        .collect();
    body(contact, &s)
}

fn push(speed: f64, phi: f64) -> Push {
    Push {
        duration: 1.0,
        speed,
        phi,
    }
}

#[track_caller]
fn close(got: f64, want: f64, rel: f64, scale: f64) {
    assert!(
        (got - want).abs() <= rel * want.abs().max(scale),
        "got {got}, want {want}"
    );
}

#[test]
fn characteristic_length_of_hand_computed_layouts() {
    let a = 0.125;
    close(
        characteristic_length(&square(a, 1.2, Vec2::new(-a, -a))),
        a * SQRT_2,
        1e-14,
        0.0,
    );
    close(
        characteristic_length(&ring(64, 0.2, Vec2::new(0.03, -0.01), Vec2::zeros())),
        0.2,
        1e-13,
        0.0,
    );
    let (d, f1, f2): (f64, f64, f64) = (0.3, 1.0, 3.0);
    close(
        characteristic_length(&body(Vec2::zeros(), &[(-d, 0.0, f1), (d, 0.0, f2)])),
        4.0 * d * f1 * f2 / (f1 + f2).powi(2),
        1e-14,
        0.0,
    );
}

#[test]
fn push_through_the_centre_of_friction_does_not_turn() {
    let a = 0.125;
    // The paper plate at its corner, pushed along the diagonal (into the
    // object and away from it).
    for phi in [FRAC_PI_4, FRAC_PI_4 + PI] {
        let w = omega(&square(a, 1.0, Vec2::new(-a, -a)), &push(1.0, phi));
        assert!(w.abs() < 1e-14, "φ = {phi}: ω = {w}");
    }
    // Unequal loads move the centre of friction off the centre of mass: the
    // line from the contact through the centre of friction, o = (F₂−F₁)/(F₁+F₂) d
    // on the x axis, gives ω = 0 and the line through the centre of mass does not.
    let (d, f1, f2) = (0.2, 1.0, 3.0);
    let o = Vec2::new(d * (f2 - f1) / (f1 + f2), 0.0);
    let pc = Vec2::new(-0.05, -0.15);
    let b = body(pc, &[(-d, 0.0, f1), (d, 0.0, f2), (0.0, 0.0, 0.0)]);
    let to_o = o - pc;
    let w = omega(&b, &push(0.8, to_o.y.atan2(to_o.x)));
    assert!(w.abs() < 1e-14, "through the centre of friction: ω = {w}");
    let w_cm = omega(&b, &push(0.8, (-pc.y).atan2(-pc.x)));
    assert!(w_cm.abs() > 0.1, "through the centre of mass: ω = {w_cm}");
}

#[test]
fn push_perpendicular_to_the_lever_arm() {
    let a = 0.125;
    let v = 0.7;
    // Square, contact at the middle of the bottom edge, pushed along +x:
    // r = a, c² = 2 a², ω = v a / (3 a²) = v / (3a), counter-clockwise.
    let b = square(a, 1.0, Vec2::new(0.0, -a));
    close(omega(&b, &push(v, 0.0)), v / (3.0 * a), 1e-14, 0.0);
    // Pushed along −x: the same magnitude, clockwise.
    close(omega(&b, &push(v, PI)), -v / (3.0 * a), 1e-14, 0.0);
    // Ring of radius R centred away from the centre of mass, contact on the
    // rim below the ring's centre, pushed along +x: r = c = R, ω = v / (2R).
    let (r, centre) = (0.2, Vec2::new(0.04, 0.02));
    let b = ring(48, r, centre, centre + Vec2::new(0.0, -r));
    close(omega(&b, &push(v, 0.0)), v / (2.0 * r), 1e-13, 0.0);
    // Contact 3R/2 from the ring's centre: ω = v (3R/2) / (R² + 9R²/4).
    let b = ring(48, r, centre, centre + Vec2::new(0.0, -1.5 * r));
    close(
        omega(&b, &push(v, 0.0)),
        v * 1.5 * r / (r * r + 2.25 * r * r),
        1e-13,
        0.0,
    );
    // Two unequal supports, contact h below the centre of friction, pushed along +x.
    let (d, f1, f2, h): (f64, f64, f64, f64) = (0.3, 1.0, 3.0, 0.1);
    let o = d * (f2 - f1) / (f1 + f2);
    let c = 4.0 * d * f1 * f2 / (f1 + f2).powi(2);
    let b = body(Vec2::new(o, -h), &[(-d, 0.0, f1), (d, 0.0, f2)]);
    close(
        omega(&b, &push(v, 0.0)),
        v * h / (c * c + h * h),
        1e-14,
        0.0,
    );
}

/// The defining conditions, for pushes in every direction on an irregular
/// support set: with the model's ω, the twist `(v_o, ω)` with
/// `v_o = v_c n_φ − ω D p` is normal to the ellipsoid at the pusher's wrench,
/// i.e. `ω c² = p × v_o` (equation (1)), with `c` and `o` computed here from
/// the supports.
#[test]
fn twist_is_normal_to_the_ellipsoid_at_the_pusher_wrench() {
    let sup = [
        (-0.11, -0.07, 1.3),
        (0.13, -0.05, 0.4),
        (0.09, 0.12, 2.1),
        (-0.06, 0.1, 0.9),
        (0.01, 0.0, 0.5),
    ];
    let ftot: f64 = sup.iter().map(|s| s.2).sum();
    let o = sup
        .iter()
        .fold(Vec2::zeros(), |acc, s| acc + Vec2::new(s.0, s.1) * s.2)
        / ftot;
    let mmax: f64 = sup
        .iter()
        .map(|s| s.2 * (Vec2::new(s.0, s.1) - o).norm())
        .sum();
    let c = mmax / ftot;
    let mut turned = 0;
    for (k, pc) in [
        Vec2::new(-0.12, -0.09),
        Vec2::new(0.14, 0.02),
        Vec2::new(0.0, 0.13),
    ]
    .into_iter()
    .enumerate()
    {
        let b = body(pc, &sup);
        let p = pc - o;
        for j in 0..24 {
            let phi = 2.0 * PI * j as f64 / 24.0 + 0.1 * k as f64;
            let (s, co) = phi.sin_cos();
            let v = 0.3 + 0.1 * j as f64;
            let w = omega(&b, &push(v, phi));
            let vo = Vec2::new(v * co, v * s) - Vec2::new(-p.y, p.x) * w;
            let cross = p.x * vo.y - p.y * vo.x;
            assert!(
                (w * c * c - cross).abs() <= 1e-14 * v * (c + p.norm()),
                "contact {k} φ = {phi}: ω c² = {}, p × v_o = {cross}",
                w * c * c
            );
            turned += usize::from(w.abs() > 1e-3);
        }
    }
    assert!(turned > 60, "only {turned} pushes turned the object");
}

/// The limit-surface model as a simulator turns at the closed-form ω from the
/// start of each segment (quasi-static: no transient), here v / (3a).
#[test]
fn limit_surface_model_turns_at_the_closed_form_rate() {
    let a = 0.125;
    let v = 0.5;
    let p = Problem {
        body: square(a, 1.0, Vec2::new(0.0, -a)),
        limits: Default::default(),
        pushes: vec![push(v, 0.0)],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.05,
        release: None,
    };
    let tr = LimitSurfaceModel.simulate(&p).unwrap();
    let w = v / (3.0 * a);
    for s in &tr.samples {
        close(s.omega, w, 1e-13, 0.0);
        close(s.theta, w * s.t, 1e-12, 1e-12);
    }
}
