//! MuJoCo's creep law (`pushval_mujoco::creep`, issue 28 item 3): the closed
//! form's own limits (no MuJoCo needed) and, with the `mujoco` feature, the closed form against the
//! engine on a few cells of the ladder (within 5 %). Expected values come
//! from the closed form's derivation (MuJoCo's regularised constraint
//! formulation), from limits and from MuJoCo's documented impedance curve,
//! never from a run's output.

use approx::assert_relative_eq;
use pushval_mujoco::creep::{creep, impedance, reference, CreepInput, CreepRegime};
use pushval_mujoco::Cone;

const MU: f64 = 0.5;
const N: f64 = 9.81 / 4.0;

/// One corner foot of the 1 kg paper plate under `lambda · μN` along t₁.
fn input(cone: Cone, lambda: f64) -> CreepInput {
    CreepInput {
        cone,
        impratio: 1.0,
        solref: [0.02, 1.0],
        solimp: [0.9, 0.95, 0.001, 0.5, 2.0],
        timestep: 1e-3,
        mu: MU,
        normal_load: N,
        inv_weight: 1.0,
        load: [lambda * MU * N, 0.0],
    }
}

fn speed(i: &CreepInput) -> f64 {
    creep(i).speed()
}

/// MuJoCo's impedance curve at its defining points: d0 at zero penetration,
/// d_width from the width on, and halfway at the midpoint (power 2).
#[test]
fn impedance_hits_its_defining_points() {
    let s = [0.8, 0.95, 0.002, 0.5, 2.0];
    assert_eq!(impedance(&s, 0.0), 0.8);
    assert_eq!(impedance(&s, -0.002), 0.95);
    assert_eq!(impedance(&s, -0.01), 0.95);
    assert_relative_eq!(impedance(&s, -0.001), 0.875, epsilon = 1e-15);
    // Symmetric in the sign of the distance, monotone in between.
    assert_eq!(impedance(&s, 0.0005), impedance(&s, -0.0005));
    let mut last = 0.0;
    for k in 0..=20 {
        let d = impedance(&s, -0.0001 * k as f64);
        assert!(d >= last);
        last = d;
    }
}

/// Creep falls as 1/impratio and vanishes as impratio → ∞ (elliptic: exactly,
/// the penetration does not depend on impratio; pyramidal: the penetration
/// shrinks but d stays at d0).
#[test]
fn creep_vanishes_as_impratio_grows() {
    for cone in Cone::ALL {
        let base = speed(&input(cone, 0.5));
        assert!(base > 0.0);
        for imp in [10.0, 100.0, 1e4] {
            let u = speed(&CreepInput {
                impratio: imp,
                ..input(cone, 0.5)
            });
            assert_relative_eq!(u * imp, base, max_relative = 1e-3);
        }
        let u = speed(&CreepInput {
            impratio: 1e12,
            ..input(cone, 0.5)
        });
        assert!(u < 1e-11 * base, "{cone:?}: {u}");
    }
}

/// Creep vanishes with the solref time constant (with the step small enough
/// that MuJoCo's refsafe clamp t_c ≥ 2 dt does not bind), proportionally to
/// it once the penetration sits where d = d0.
#[test]
fn creep_vanishes_with_the_time_constant() {
    for cone in Cone::ALL {
        let at = |tc: f64| {
            speed(&CreepInput {
                solref: [tc, 1.0],
                timestep: tc / 10.0,
                ..input(cone, 0.5)
            })
        };
        let (u1, u2) = (at(1e-3), at(1e-4));
        assert_relative_eq!(u1 / u2, 10.0, max_relative = 1e-3);
        assert!(at(1e-7) < 1e-4 * at(0.02));
    }
}

/// The refsafe clamp: above dt = t_c/2 the effective time constant is 2 dt,
/// so B halves and the creep doubles when dt doubles (elliptic, flat solimp
/// so that d is fixed).
#[test]
fn refsafe_clamp_sets_the_time_constant_at_large_steps() {
    let flat = [0.9, 0.9, 0.001, 0.5, 2.0];
    let at = |dt: f64| {
        speed(&CreepInput {
            solimp: flat,
            timestep: dt,
            ..input(Cone::Elliptic, 0.5)
        })
    };
    assert_relative_eq!(at(1e-3), at(1e-2), max_relative = 1e-12);
    assert_relative_eq!(at(4e-2) / at(2e-2), 2.0, max_relative = 1e-12);
    assert_eq!(reference(&[0.02, 1.0], &flat, 0.02).timeconst, 0.04);
}

/// Elliptic: linear in the load up to the cone, then no steady state; the
/// slip scale is ε = μ N R_t / B with R_t = (1 − d)/d Â and B = 2/(d_max t_c).
#[test]
fn elliptic_creep_is_linear_in_the_load() {
    let e = |l: f64| speed(&input(Cone::Elliptic, l));
    assert_relative_eq!(e(0.9) / e(0.5), 1.8, max_relative = 1e-12);
    assert_relative_eq!(e(0.25) / e(0.5), 0.5, max_relative = 1e-12);
    let p = creep(&input(Cone::Elliptic, 0.5));
    let d = p.impedance;
    let eps = MU * N * (1.0 - d) / d / (2.0 / (0.95 * 0.02));
    assert_relative_eq!(e(0.5), 0.5 * eps, max_relative = 1e-12);
    assert_eq!(
        creep(&input(Cone::Elliptic, 1.01)).regime,
        CreepRegime::Slides
    );
}

/// Pyramidal along a tangent axis: linear up to λ = 1/2, then 3λ − 1
/// (continuous at 1/2), no steady state from λ = 1; along the diagonal it
/// lets go at λ = 1/√2. With a flat solimp (d fixed) it creeps (1 + μ²)
/// times faster than the ellipse below λ = 1/2.
#[test]
fn pyramidal_creep_follows_its_lifted_edge_branch() {
    let flat = [0.9, 0.9, 0.001, 0.5, 2.0];
    let p = |l: f64| {
        speed(&CreepInput {
            solimp: flat,
            ..input(Cone::Pyramidal, l)
        })
    };
    let e = |l: f64| {
        speed(&CreepInput {
            solimp: flat,
            ..input(Cone::Elliptic, l)
        })
    };
    assert_relative_eq!(p(0.25) / e(0.25), 1.0 + MU * MU, max_relative = 1e-12);
    assert_relative_eq!(p(0.25) / p(0.5), 0.5, max_relative = 1e-12);
    assert_relative_eq!(
        p(0.9) / p(0.5),
        (3.0 * 0.9 - 1.0) / 0.5,
        max_relative = 1e-12
    );
    assert_relative_eq!(p(0.5 - 1e-9), p(0.5 + 1e-9), max_relative = 1e-7);
    let regime = |l: f64, a: f64| {
        creep(&CreepInput {
            load: [l * MU * N * a.cos(), l * MU * N * a.sin()],
            ..input(Cone::Pyramidal, l)
        })
        .regime
    };
    assert_eq!(regime(0.4, 0.0), CreepRegime::Interior);
    assert_eq!(regime(0.6, 0.0), CreepRegime::EdgeLifted);
    assert_eq!(regime(1.0, 0.0), CreepRegime::Slides);
    let diag = std::f64::consts::FRAC_PI_4;
    assert_eq!(regime(0.70, diag), CreepRegime::Interior);
    assert_eq!(regime(0.71, diag), CreepRegime::Slides);
}

#[cfg(feature = "mujoco")]
mod engine {
    use std::f64::consts::FRAC_PI_4;

    use pushval_mujoco::creep::{measure, CreepCase, CreepScene, CHATTER_HEIGHT_STD};
    use pushval_mujoco::{Cone, MujocoSettings};

    fn scene(cone: Cone, impratio: f64, dt: f64) -> CreepScene {
        CreepScene {
            settings: MujocoSettings {
                cone,
                impratio,
                timestep: dt,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// Measured against closed-form creep, along and across the load.
    #[track_caller]
    fn check(scene: &CreepScene, case: CreepCase, load: f64, direction: f64) {
        let m = measure(scene, case, load, direction, 1.5).unwrap();
        let ([along, across], p) = scene.predicted(load, direction, m.tangents);
        let err = (m.creep - along).hypot(m.lateral - across) / along.hypot(across);
        assert!(
            err < 0.05,
            "{:?} λ={load}: measured ({}, {}), closed form ({along}, {across}), {:?}",
            scene.settings.cone,
            m.creep,
            m.lateral,
            p.regime
        );
        assert!(m.height_std < CHATTER_HEIGHT_STD, "{}", m.height_std);
        assert_eq!(m.contacts, scene.feet_positions().len());
    }

    #[test]
    fn closed_form_matches_mujoco_on_ladder_cells() {
        // Elliptic, MuJoCo's defaults; pyramidal on its lifted-edge branch.
        check(&scene(Cone::Elliptic, 1.0, 1e-3), CreepCase::Held, 0.5, 0.0);
        check(
            &scene(Cone::Pyramidal, 10.0, 1e-3),
            CreepCase::Held,
            0.9,
            0.0,
        );
        // The refsafe clamp (dt = t_c), approached from sliding.
        check(
            &scene(Cone::Elliptic, 100.0, 0.02),
            CreepCase::Sliding(0.1),
            0.9,
            0.0,
        );
        // d set by the penetration inside the solimp width.
        let mut s = scene(Cone::Pyramidal, 1.0, 1e-3);
        s.settings.contact_solimp = [0.5, 0.95, 0.004, 0.5, 2.0];
        check(&s, CreepCase::Held, 0.5, 0.0);
        // Eight feet; the pyramid off its axes (creep turns off the load).
        let mut s = scene(Cone::Elliptic, 10.0, 1e-3);
        s.feet = 8;
        check(&s, CreepCase::Held, 0.75, 0.0);
        check(
            &scene(Cone::Pyramidal, 1.0, 1e-3),
            CreepCase::Held,
            0.6,
            FRAC_PI_4 / 3.0,
        );
    }

    /// Â of the law is MuJoCo's translational invweight0 of the plate, 1/m.
    #[test]
    fn invweight_is_the_inverse_mass() {
        let mut s = scene(Cone::Elliptic, 1.0, 1e-3);
        s.mass = 2.5;
        let m = measure(&s, CreepCase::Held, 0.5, 0.0, 0.2).unwrap();
        assert!((m.inv_weight - 0.4).abs() < 1e-12, "{}", m.inv_weight);
    }

    /// Where the law stops: an underdamped contact (ζ = 0.3) never lets the
    /// unloaded plate settle, and the loaded plate then creeps faster than
    /// the law.
    #[test]
    fn underdamped_contacts_chatter_and_break_the_law() {
        let mut s = scene(Cone::Elliptic, 1.0, 1e-3);
        s.settings.contact_solref = [0.02, 0.3];
        let m = measure(&s, CreepCase::Held, 0.0, 0.0, 1.0).unwrap();
        assert!(m.height_std > CHATTER_HEIGHT_STD, "{}", m.height_std);
        let m = measure(&s, CreepCase::Held, 0.5, 0.0, 1.0).unwrap();
        let ([along, _], _) = s.predicted(0.5, 0.0, m.tangents);
        assert!(m.creep > 1.2 * along, "{} vs {along}", m.creep);
    }
}
