//! The filter run on every engine of the build (and the dynamic model):
//! lack-of-fit episodes and the apparent parameters at each segment's end.

use super::setup::*;

#[derive(Debug, Clone)]
pub(super) struct EngineRow {
    pub(super) model: String,
    pub(super) version: String,
    pub(super) dt: f64,
    /// The filter's state left the finite numbers at this time.
    pub(super) diverged: Option<f64>,
    pub(super) episodes: usize,
    pub(super) first_lack: Option<f64>,
    /// Per segment end: t, value, std.
    pub(super) ends: Vec<(f64, [f64; 4], [f64; 4])>,
    pub(super) position_rms: f64,
}

pub(super) fn engines() -> anyhow::Result<(Vec<EngineRow>, Csv)> {
    let sc = load(SCENARIOS[2])?;
    let problem = sc.problem();
    let mut runs: Vec<(String, String, f64, Vec<Sample>)> =
        vec![("dynamic".into(), "analytic".into(), 0.0, simulate(&problem))];
    for e in crate::registry::entries() {
        let engine = e.default_engine();
        if engine.availability().is_err() {
            continue;
        }
        let dt = engine.default_dt();
        let run = engine
            .run(&problem, dt)
            .with_context(|| format!("running {} on {}", e.name, sc.name))?;
        runs.push((
            e.name.to_string(),
            engine.version(),
            dt,
            run.trajectory.samples,
        ));
    }
    let times = problem.segment_times();
    let reference = simulate(&problem);
    let rows: Vec<EngineRow> = runs
        .into_iter()
        .map(|(model, version, dt, samples)| {
            let md = track_model(&sc).expect("loads");
            let mut ekf = Ekf::new(md, Free::default(), EkfSettings::default(), None);
            let mut episodes = 0;
            let mut first_lack = None;
            let mut in_ep = false;
            let mut ends = Vec::new();
            let mut k = 0;
            let mut diverged = None;
            for m in measurements(&samples) {
                let r = match ekf.update(&m) {
                    Ok(r) => r,
                    Err(_) => {
                        diverged = Some(m.t);
                        break;
                    }
                };
                if r.lack_of_fit && !in_ep {
                    episodes += 1;
                    first_lack.get_or_insert(m.t);
                }
                in_ep = r.lack_of_fit;
                // The sample just before each switch, and the last one.
                while k < times.len() && m.t >= times[k].1 - 1e-9 {
                    let e = ekf.estimate();
                    ends.push((m.t, e.value, e.std()));
                    k += 1;
                }
            }
            let n = samples.len().min(reference.len());
            let position_rms = (samples[..n]
                .iter()
                .zip(&reference[..n])
                .map(|(a, b)| (a.x - b.x).powi(2) + (a.y - b.y).powi(2))
                .sum::<f64>()
                / n as f64)
                .sqrt();
            EngineRow {
                model,
                version,
                dt,
                diverged,
                episodes,
                first_lack,
                ends,
                position_rms,
            }
        })
        .collect();
    let mut csv = Csv::new(&[
        "model",
        "version",
        "dt_s",
        "position_rms_vs_dynamic_m",
        "lack_of_fit_episodes",
        "first_lack_of_fit_s",
        "diverged_at_s",
        "explained",
        "segment",
        "t",
        "mu_scale",
        "mu_scale_std",
        "center_of_friction_x",
        "center_of_friction_y",
        "center_of_friction_std",
        "inertia_cm",
        "inertia_cm_std",
    ]);
    let s2 = |t: Option<f64>| t.map_or(String::new(), |t| format!("{t:.2}"));
    for r in &rows {
        for (i, (t, v, s)) in r.ends.iter().enumerate() {
            csv.row(&[
                r.model.to_string(),
                r.version.to_string(),
                r.dt.to_string(),
                format!("{:.3e}", r.position_rms),
                r.episodes.to_string(),
                s2(r.first_lack),
                s2(r.diverged),
                (r.episodes == 0 && r.diverged.is_none()).to_string(),
                (i + 1).to_string(),
                t.to_string(),
                format!("{:.5}", v[0]),
                format!("{:.2e}", s[0]),
                format!("{:.5}", v[1] + sc.center_of_mass.x),
                format!("{:.5}", v[2] + sc.center_of_mass.y),
                format!("{:.2e}", s[1].max(s[2])),
                format!("{:.6e}", v[3]),
                format!("{:.2e}", s[3]),
            ]);
        }
    }
    Ok((rows, csv))
}
