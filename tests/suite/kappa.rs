//! `summary.json`'s κ = ω*/ω_kinematic and its closed-form slope dκ/dFr
//! (`kappa`, `kappa_slope` in `segments[]`), checked against the exact
//! steady root at shrinking speeds: (κ − 1)/Fr must tend to the slope, with
//! an error that halves when Fr halves.

use pushval::harness::analyse_segments;
use pushval::{run_scenario, RunOptions};
use pushval_model::{DynamicModel, Simulator};

use crate::common::{load, root};

#[test]
fn kappa_slope_is_the_small_froude_limit_of_the_exact_kappa() {
    let base = load(&root().join("scenarios/paper-square-v1.0.toml"));
    // Only the analytic models: κ does not involve an engine.
    let at = |speed: f64| {
        let mut sc = base.clone();
        sc.models = vec!["dynamic".into()];
        sc.gate.clear();
        for p in &mut sc.pushes {
            p.speed = speed;
        }
        let problem = sc.problem();
        let tr = DynamicModel::default().simulate(&problem).unwrap();
        (sc.froude(speed), analyse_segments(&sc, &problem, &tr))
    };
    let (fr1, s1) = at(0.02);
    let (fr2, s2) = at(0.02 / 2f64.sqrt());
    assert!((fr1 / fr2 - 2.0).abs() < 1e-12);
    let mut checked = 0;
    for (a, b) in s1.iter().zip(&s2) {
        let (Some(k1), Some(k2), Some(slope)) = (a.kappa, b.kappa, a.kappa_slope) else {
            continue;
        };
        assert_eq!(
            a.kappa_slope, b.kappa_slope,
            "the slope does not depend on speed"
        );
        let e1 = ((k1 - 1.0) / fr1 - slope).abs();
        let e2 = ((k2 - 1.0) / fr2 - slope).abs();
        // (κ − 1)/Fr − κ1 = κ2 Fr + O(Fr²): halves with Fr.
        assert!(
            e1 < 0.05 * slope.abs(),
            "segment {}: {e1} vs slope {slope}",
            a.index
        );
        assert!(
            (e1 / e2 - 2.0).abs() < 0.05,
            "segment {}: ratio {}",
            a.index,
            e1 / e2
        );
        checked += 1;
    }
    assert!(checked >= 3, "only {checked} segments with a kinematic ω");
}

#[test]
fn summary_carries_kappa_where_the_kinematic_omega_exists() {
    // Its second segment pushes through the centre (φ = π/4): ω_kinematic = 0.
    let sc = load(&root().join("scenarios/paper-square-v0.2.toml"));
    let r = run_scenario(&sc, &RunOptions::default()).unwrap();
    let summary = pushval::output::summary(&r);
    let mut nulls = 0;
    for (s, j) in r
        .segments
        .iter()
        .zip(summary["segments"].as_array().unwrap())
    {
        let l = sc.froude_length();
        match (s.omega_kinematic, s.omega_steady) {
            (Some(k), _) if k.abs() * l <= 1e-12 * s.speed || k.abs() * l >= 1e-9 * s.speed => {}
            _ => panic!(
                "segment {}: ω_kinematic within rounding of the threshold",
                s.index
            ),
        }
        match (s.omega_kinematic, s.omega_steady) {
            (Some(k), Some(w)) if k.abs() * l > 1e-12 * s.speed => {
                let kappa = j["kappa"].as_f64().unwrap();
                assert!((kappa - w.omega / k).abs() <= 1e-12 * kappa.abs());
                assert!(j["kappa_slope"].is_number());
            }
            _ => {
                nulls += 1;
                assert!(j["kappa"].is_null());
                assert!(j["kappa_slope"].is_null());
            }
        }
    }
    assert_eq!(nulls, 1, "the through-centre segment has no κ");
}
