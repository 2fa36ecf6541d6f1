//! The estimators on the truth: thread CPU time per update, the time to
//! converge against noise and rate, and the efficiency against the
//! Cramér–Rao bound.

use super::setup::*;

// ---------------------------------------------------------------- cost

pub(super) fn cost(grid: &Grid) -> anyhow::Result<Csv> {
    let sc = load(SCENARIOS[2])?;
    let rate = 1000.0;
    let data = noise::add_noise(&truth_samples(&sc, rate), 1e-3, 1e-3, 7);
    let data = measurements(&data[..data.len().min(grid.cost_updates)]);
    // The clock pair alone.
    let mut pair: Vec<f64> = (0..data.len())
        .map(|_| {
            let a = thread_cpu_time();
            thread_cpu_time() - a
        })
        .collect();
    pair.sort_by(f64::total_cmp);
    let overhead = pair[pair.len() / 2];
    let mut csv = Csv::new(&[
        "method",
        "rate_hz",
        "updates",
        "median_us",
        "p99_us",
        "max_us",
        "with_resultant_median_us",
        "with_resultant_p99_us",
        "clock_pair_median_us",
    ]);
    for method in [Method::Ekf, Method::Rls] {
        let times = |with_resultant: bool| {
            let mut est = estimator(&sc, method, rate, 1e-3, 1e-3);
            let mut t: Vec<f64> = data
                .iter()
                .map(|m| {
                    let a = thread_cpu_time();
                    est.update(m).expect("valid samples");
                    if with_resultant {
                        std::hint::black_box(est.resultant());
                    }
                    thread_cpu_time() - a
                })
                .collect();
            t.sort_by(f64::total_cmp);
            t
        };
        let plain = times(false);
        let full = times(true);
        let q = |v: &[f64], f: f64| v[((v.len() - 1) as f64 * f).round() as usize] * 1e6;
        let mut f = vec![
            method.name().to_string(),
            rate.to_string(),
            plain.len().to_string(),
        ];
        let us = [
            q(&plain, 0.5),
            q(&plain, 0.99),
            q(&plain, 1.0),
            q(&full, 0.5),
            q(&full, 0.99),
        ];
        f.extend(
            us.into_iter()
                .chain([overhead * 1e6])
                .map(|v| format!("{v:.3}")),
        );
        csv.row(&f);
    }
    Ok(csv)
}

// --------------------------------------------------------- convergence

#[derive(Debug, Clone)]
pub(super) struct ConvRow {
    pub(super) scenario: String,
    pub(super) method: Method,
    pub(super) rate: f64,
    pub(super) sp: f64,
    pub(super) st: f64,
    /// Per seed: μ, cof, I, all settle times.
    pub(super) times: Vec<[Option<f64>; 4]>,
    /// Per seed: final relative errors μ, I and cof error (m).
    pub(super) errors: Vec<[f64; 3]>,
}

pub(super) fn median_opt(v: &[Option<f64>]) -> Option<f64> {
    let mut x: Vec<f64> = v.iter().map(|o| o.unwrap_or(f64::INFINITY)).collect();
    x.sort_by(f64::total_cmp);
    let m = x[x.len() / 2];
    m.is_finite().then_some(m)
}

pub(super) fn convergence(grid: &Grid) -> anyhow::Result<(Vec<ConvRow>, Csv)> {
    let mut cells = Vec::new();
    for name in &grid.scenarios {
        let sc = load(name)?;
        for &rate in &grid.rates {
            let clean = truth_samples(&sc, rate);
            for &(sp, st) in &grid.noise {
                for method in [Method::Ekf, Method::Rls] {
                    cells.push((sc.clone(), clean.clone(), rate, sp, st, method));
                }
            }
        }
    }
    let rows: Vec<ConvRow> = cells
        .par_iter()
        .map(|(sc, clean, rate, sp, st, method)| {
            let (_, _, tr) = truth(sc);
            let mut times = Vec::new();
            let mut errors = Vec::new();
            for seed in 0..grid.seeds {
                let data = measurements(&noise::add_noise(clean, *sp, *st, 1000 + seed));
                let mut est = estimator(sc, *method, *rate, *sp, *st);
                let hist = run(est.as_mut(), &data);
                let mu_ok = |v: &[f64; 4]| (v[0] / tr[0] - 1.0).abs() <= 0.01;
                let cof_ok =
                    |v: &[f64; 4]| (v[1] - tr[1]).abs() <= 1e-3 && (v[2] - tr[2]).abs() <= 1e-3;
                let i_ok = |v: &[f64; 4]| (v[3] / tr[3] - 1.0).abs() <= 0.02;
                times.push([
                    settled(&hist, mu_ok),
                    settled(&hist, cof_ok),
                    settled(&hist, i_ok),
                    settled(&hist, |v| mu_ok(v) && cof_ok(v) && i_ok(v)),
                ]);
                let v = hist.last().expect("samples").1;
                errors.push([
                    v[0] / tr[0] - 1.0,
                    v[3] / tr[3] - 1.0,
                    ((v[1] - tr[1]).powi(2) + (v[2] - tr[2]).powi(2)).sqrt(),
                ]);
            }
            ConvRow {
                scenario: sc.name.clone(),
                method: *method,
                rate: *rate,
                sp: *sp,
                st: *st,
                times,
                errors,
            }
        })
        .collect();
    let mut csv = Csv::new(&[
        "scenario",
        "method",
        "rate_hz",
        "sigma_position_m",
        "sigma_theta_rad",
        "seeds",
        "mu_within_1pc_s",
        "cof_within_1mm_s",
        "inertia_within_2pc_s",
        "all_s",
        "seeds_all_converged",
        "mu_rel_error_rms",
        "inertia_rel_error_rms",
        "cof_error_rms_m",
    ]);
    let f = |o: Option<f64>| o.map_or(String::new(), |v| format!("{v:.3}"));
    for r in &rows {
        let col = |k: usize| median_opt(&r.times.iter().map(|t| t[k]).collect::<Vec<_>>());
        let n = r.errors.len() as f64;
        let rms = |k: usize| (r.errors.iter().map(|e| e[k] * e[k]).sum::<f64>() / n).sqrt();
        let mut fields = vec![
            r.scenario.to_string(),
            r.method.name().to_string(),
            r.rate.to_string(),
            r.sp.to_string(),
            r.st.to_string(),
            r.times.len().to_string(),
        ];
        fields.extend((0..4).map(|k| f(col(k))));
        fields.push(
            r.times
                .iter()
                .filter(|t| t[3].is_some())
                .count()
                .to_string(),
        );
        fields.extend((0..3).map(|k| format!("{:.3e}", rms(k))));
        csv.row(&fields);
    }
    Ok((rows, csv))
}

// ---------------------------------------------------------- efficiency

#[derive(Debug, Clone)]
pub(super) struct EffRow {
    pub(super) scenario: String,
    pub(super) method: Method,
    pub(super) rate: f64,
    pub(super) component: &'static str,
    pub(super) truth: f64,
    pub(super) mean: f64,
    pub(super) std: f64,
    pub(super) reported: f64,
    pub(super) crb: f64,
    pub(super) crb_known: f64,
}

/// The Cramér–Rao bound of `[mu_scale, c_x, c_y, I_cm]` (c from the centre
/// of mass) when the start is measured, not known: the whitened Jacobian of
/// the trajectory (x, y, θ at every sample) with respect to the parameters
/// and the start `[x0, y0, θ0, ω0]` (central differences), information
/// `JᵀJ` plus the filter's priors (the start's std `[σ_p, σ_p, σ_θ, 0.01]`,
/// the parameters' `prior` as in [`EkfSettings::prior`]), inverted. For the
/// known-start filter this is a looser bound than it is told (it is told
/// the start exactly): the table gives `pushval fit`'s known-start bound
/// beside it.
pub(super) fn crb_measured_start(
    pm: &Parametrised,
    v: &[f64],
    sp: f64,
    st: f64,
    prior: [f64; 3],
) -> anyhow::Result<[f64; 4]> {
    let base = pm.problem(v).map_err(|e| anyhow::anyhow!("{e}"))?;
    let traj = |dv: &[f64; 8]| -> Vec<Sample> {
        let vals: Vec<f64> = (0..4).map(|i| v[i] + dv[i]).collect();
        let mut p = pm.problem(&vals).expect("near the truth");
        p.initial.position += Vec2::new(dv[4], dv[5]);
        p.initial.theta += dv[6];
        p.initial.omega += dv[7];
        simulate(&p)
    };
    let scales = pm.scales();
    let steps = [
        1e-5 * scales[0],
        1e-5 * scales[1],
        1e-5 * scales[2],
        1e-5 * scales[3],
        1e-6,
        1e-6,
        1e-6,
        1e-5,
    ];
    let k = base.sample_times().len();
    let mut jac = nalgebra::DMatrix::<f64>::zeros(3 * k, 8);
    for j in 0..8 {
        let mut d = [0.0; 8];
        d[j] = steps[j];
        let a = traj(&d);
        d[j] = -steps[j];
        let b = traj(&d);
        for i in 0..k {
            jac[(3 * i, j)] = (a[i].x - b[i].x) / (2.0 * steps[j] * sp);
            jac[(3 * i + 1, j)] = (a[i].y - b[i].y) / (2.0 * steps[j] * sp);
            jac[(3 * i + 2, j)] = (a[i].theta - b[i].theta) / (2.0 * steps[j] * st);
        }
    }
    let mut info = jac.transpose() * &jac;
    // Parametrised order: c_x, c_y (scale: its size), I_cm, mu_scale.
    let prior_std = [
        prior[1] * scales[0],
        prior[1] * scales[1],
        prior[2] * v[2] / INERTIA_FACTOR,
        prior[0],
        sp,
        sp,
        st,
        1e-2,
    ];
    for (j, s) in prior_std.iter().enumerate() {
        info[(j, j)] += 1.0 / (s * s);
    }
    let d: Vec<f64> = (0..8).map(|j| info[(j, j)].sqrt()).collect();
    let unit = nalgebra::DMatrix::from_fn(8, 8, |a, b| info[(a, b)] / (d[a] * d[b]));
    let inv = unit
        .cholesky()
        .context("the information with a measured start is singular")?
        .inverse();
    let sd = |j: usize| inv[(j, j)].sqrt() / d[j];
    Ok([sd(3), sd(0), sd(1), sd(2)])
}

pub(super) fn efficiency(grid: &Grid) -> anyhow::Result<(Vec<EffRow>, Csv)> {
    let (sp, st) = (1e-3, 1e-3);
    let mut out = Vec::new();
    let rates = [100.0, 1000.0];
    for name in &grid.scenarios {
        for rate in rates {
            let mut sc = load(name)?;
            sc.sample_dt = 1.0 / rate;
            let (pm, v, tr) = truth(&sc);
            let settings = Settings {
                sigma_position: sp,
                sigma_theta: st,
                ..Default::default()
            };
            let fisher = fisher_at(&pm, &v, &settings)
                .map_err(|e| anyhow::anyhow!("{name}: Fisher information: {e}"))?;
            // Parametrised order: c_x, c_y, I_cm, mu_scale → estimator order.
            let crb_p = fisher.std();
            let crb_known = [crb_p[3], crb_p[0], crb_p[1], crb_p[2]];
            let crb_default = crb_measured_start(&pm, &v, sp, st, EkfSettings::default().prior)?;
            let crb_broad = crb_measured_start(&pm, &v, sp, st, BROAD_PRIOR)?;
            let clean = simulate(&pm.problem(&v).expect("truth"));
            for method in [
                Method::Ekf,
                Method::EkfBroadPrior,
                Method::EkfKnownStart,
                Method::EkfKnownStartAtTruth,
                Method::Rls,
            ] {
                let crb = if method == Method::EkfBroadPrior {
                    crb_broad
                } else {
                    crb_default
                };
                let finals: Vec<([f64; 4], [f64; 4])> = (0..grid.seeds_efficiency)
                    .into_par_iter()
                    .map(|seed| {
                        let data = measurements(&noise::add_noise(&clean, sp, st, 5000 + seed));
                        let mut est = estimator(&sc, method, rate, sp, st);
                        let h = run(est.as_mut(), &data);
                        let last = h.last().expect("samples");
                        (last.1, last.2)
                    })
                    .collect();
                let n = finals.len() as f64;
                for (k, component) in [
                    "mu_scale",
                    "center_of_friction_x",
                    "center_of_friction_y",
                    "inertia_cm",
                ]
                .into_iter()
                .enumerate()
                {
                    let mean = finals.iter().map(|f| f.0[k]).sum::<f64>() / n;
                    let std = (finals.iter().map(|f| (f.0[k] - mean).powi(2)).sum::<f64>()
                        / (n - 1.0))
                        .sqrt();
                    let reported = finals.iter().map(|f| f.1[k]).sum::<f64>() / n;
                    out.push(EffRow {
                        scenario: sc.name.clone(),
                        method,
                        rate,
                        component,
                        truth: tr[k],
                        mean,
                        std,
                        reported,
                        crb: crb[k],
                        crb_known: crb_known[k],
                    });
                }
            }
        }
    }
    let mut csv = Csv::new(&[
        "scenario",
        "method",
        "rate_hz",
        "sigma_position_m",
        "sigma_theta_rad",
        "seeds",
        "component",
        "truth",
        "mean",
        "empirical_std",
        "reported_std",
        "crb_std",
        "efficiency",
        "bias_over_crb",
        "crb_std_known_start",
        "efficiency_known_start",
    ]);
    for r in &out {
        csv.row(&[
            r.scenario.to_string(),
            r.method.name().to_string(),
            r.rate.to_string(),
            sp.to_string(),
            st.to_string(),
            grid.seeds_efficiency.to_string(),
            r.component.to_string(),
            format!("{:.6e}", r.truth),
            format!("{:.6e}", r.mean),
            format!("{:.4e}", r.std),
            format!("{:.4e}", r.reported),
            format!("{:.4e}", r.crb),
            format!("{:.3}", (r.crb / r.std).powi(2)),
            format!("{:.2}", (r.mean - r.truth) / r.crb),
            format!("{:.4e}", r.crb_known),
            format!("{:.3}", (r.crb_known / r.std).powi(2)),
        ]);
    }
    Ok((out, csv))
}
