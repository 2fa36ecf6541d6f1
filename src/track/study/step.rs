//! μ stepping by +20 % mid-push: when the lack-of-fit test fires and when
//! the estimate follows, with and without re-opening.

use super::setup::*;

/// The 1 m/s push with μ × (1 + [`STEP`]) from [`STEP_AT`] on, sampled at
/// `rate`: the first part's end state starts the second part.
pub(super) fn step_samples(sc: &Scenario, rate: f64) -> Vec<Sample> {
    let mut sc = sc.clone();
    sc.sample_dt = 1.0 / rate;
    let pm = Parametrised::new(&sc, &[Param::MuScale]).expect("mu_scale");
    let before = pm.problem(&[1.0]).expect("file values");
    let after = pm.problem(&[1.0 + STEP]).expect("stepped");
    let mut first = before.clone();
    let mut rest = after.clone();
    let mut t = 0.0;
    first.pushes.clear();
    rest.pushes.clear();
    for p in &before.pushes {
        let (a, b) = (t, t + p.duration);
        if b <= STEP_AT + 1e-12 {
            first.pushes.push(*p);
        } else if a >= STEP_AT - 1e-12 {
            rest.pushes.push(*p);
        } else {
            first.pushes.push(pushval_model::Push {
                duration: STEP_AT - a,
                ..*p
            });
            rest.pushes.push(pushval_model::Push {
                duration: b - STEP_AT,
                ..*p
            });
        }
        t = b;
    }
    let a = simulate(&first);
    let end = *a.last().expect("samples");
    rest.initial = Initial {
        theta: end.theta,
        omega: end.omega,
        position: Vec2::new(end.x, end.y),
        from_rest: false,
        velocity: pushval_model::Vec2::zeros(),
    };
    let b = simulate(&rest);
    a.into_iter()
        .chain(b.into_iter().skip(1).map(|s| Sample {
            t: s.t + STEP_AT,
            ..s
        }))
        .collect()
}

#[derive(Debug, Clone)]
pub(super) struct StepRow {
    pub(super) rate: f64,
    pub(super) reopen: bool,
    pub(super) detect: Option<f64>,
    pub(super) follow: Option<f64>,
    pub(super) final_mu: f64,
    pub(super) hist: History,
}

pub(super) fn step(grid: &Grid) -> anyhow::Result<(Vec<StepRow>, Csv)> {
    let sc = load(SCENARIOS[2])?;
    let mut rows = Vec::new();
    for &rate in &grid.rates {
        let data = measurements(&noise::add_noise(&step_samples(&sc, rate), 1e-3, 1e-3, 77));
        for reopen in [true, false] {
            let md = track_model(&sc)?;
            let mut ekf = Ekf::new(
                md,
                Free::default(),
                EkfSettings {
                    reopen,
                    ..Default::default()
                },
                None,
            );
            let mut detect = None;
            let mut hist = Vec::new();
            for m in &data {
                let r = ekf.update(m).expect("valid samples");
                if r.lack_of_fit && m.t >= STEP_AT && detect.is_none() {
                    detect = Some(m.t - STEP_AT);
                }
                let e = ekf.estimate();
                hist.push((m.t, e.value, e.std()));
            }
            let target = 1.0 + STEP;
            let follow = settled(&hist, |v| (v[0] / target - 1.0).abs() <= 0.01)
                .filter(|t| *t >= STEP_AT)
                .map(|t| t - STEP_AT);
            let final_mu = hist.last().expect("samples").1[0];
            rows.push(StepRow {
                rate,
                reopen,
                detect,
                follow,
                final_mu,
                hist,
            });
        }
    }
    let mut csv = Csv::new(&[
        "rate_hz",
        "reopen",
        "step_at_s",
        "step",
        "detected_after_s",
        "within_1pc_after_s",
        "final_mu_scale",
    ]);
    let f = |o: Option<f64>| o.map_or(String::new(), |v| format!("{v:.3}"));
    for r in &rows {
        csv.row(&[
            r.rate.to_string(),
            r.reopen.to_string(),
            STEP_AT.to_string(),
            STEP.to_string(),
            f(r.detect),
            f(r.follow),
            format!("{:.5}", r.final_mu),
        ]);
    }
    Ok((rows, csv))
}
