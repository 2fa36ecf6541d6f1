//! The dynamic model's final state ([`DynamicModel::final_state`], what a
//! predictor asks for) on every shipped scenario: the full sampled run's
//! last sample (≤ 1e-12 m, rad), or the same error when the run fails.

use std::path::PathBuf;

use pushval_model::{DynamicModel, Integrator, Simulator};
use pushval_scenario::Scenario;
use rstest::rstest;

#[rstest]
fn final_state_is_the_last_sample_of_every_scenario(
    #[files("scenarios/*.toml")] path: PathBuf,
    #[values(1e-9, 1e-12)] tol: f64,
) {
    let sc = Scenario::from_path(&path).unwrap();
    let problem = sc.problem();
    let model = DynamicModel {
        integrator: Integrator::Dop853 { tol },
        ..Default::default()
    };
    match (model.simulate(&problem), model.final_state(&problem)) {
        (Ok(full), Ok(end)) => {
            let last = full.samples.last().expect("a sample at the end");
            assert_eq!(end.t, last.t);
            let dp = (end.x - last.x).hypot(end.y - last.y);
            let dth = (end.theta - last.theta).abs();
            let dw = (end.omega - last.omega).abs();
            assert!(
                dp <= 1e-12 && dth <= 1e-12 && dw <= 1e-12 * (1.0 + last.omega.abs()),
                "{}: {dp:e} m, {dth:e} rad, {dw:e} rad/s",
                path.display()
            );
        }
        (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string(), "{}", path.display()),
        (a, b) => panic!(
            "{}: the full run {:?}, the final state {:?}",
            path.display(),
            a.map(|t| t.samples.len()),
            b
        ),
    }
}
