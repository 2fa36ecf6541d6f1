//! The dynamic model's final state ([`DynamicModel::final_state`], what a
//! predictor asks for) on every shipped scenario: the full sampled run's
//! last sample to within the tolerance (its settling segments end by the
//! series in δ, the sampled run's by the series in E), or the same error
//! when the run fails.

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
            // Ten tolerances, plus twice what the sampled run itself is off
            // from a DOP853 run at 1e-13 with no closed form (the
            // integrator's error between two hand-over points).
            let reference = DynamicModel {
                integrator: Integrator::Dop853 { tol: 1e-13 },
                skip_settled: false,
                ..Default::default()
            }
            .simulate(&problem)
            .unwrap();
            let r = reference.samples.last().unwrap();
            let own = (last.x - r.x)
                .hypot(last.y - r.y)
                .max((last.theta - r.theta).abs());
            let bound = 10.0 * tol + 2.0 * own;
            assert!(
                dp <= bound && dth <= bound && dw <= bound * (1.0 + last.omega.abs()),
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
