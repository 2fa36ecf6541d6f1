//! `pushval track`: online estimation of μ, the centre of friction and
//! I_cm, sample by sample, and the resultant friction force; and
//! `pushval track-study`: what the estimator costs and how well it does.
//!
//! # Method
//!
//! The extended Kalman filter of [`pushval_model::track::Ekf`] on the
//! scenario's dynamic model (its pushes, start and switching rule), fed the
//! pose `x, y, θ` of each row (and `fx, fy` when the CSV has them; ω only
//! with `--sigma-omega`). Noise levels as `pushval fit`'s (1 mm, 1 mrad by
//! default). The lack-of-fit test: the normalised innovations squared over
//! the last 25 samples against χ²'s upper 1e-6 quantile; when it rejects,
//! a line goes to standard error at once and the free parameters are
//! re-opened to their prior (the estimate can follow a change of surface).
//!
//! # Format
//!
//! `DIR/track.csv`, one row per sample: `t`, then per chosen parameter (in
//! the order `center_of_friction`, `inertia_cm`, `mu_scale`, as `fit.json`)
//! its value and `_std` (`center_of_friction_x`, `center_of_friction_x_std`,
//! `center_of_friction_y`, `center_of_friction_y_std`), then
//! `friction_force` (N), `friction_moment` (N m, about the centre of mass),
//! `friction_point_x`, `friction_point_y` (m, the file's object frame: where
//! the line of action enters the outline followed along the force; empty
//! when it misses it), their std (`friction_force_std`, …,
//! `friction_point_y_std`), `nis` (this sample's normalised innovation
//! squared) and `lack_of_fit` (0/1).
//!
//! `DIR/track.json`:
//!
//! ```json
//! {"scenario": "paper-square-v1.0", "method": "ekf", "samples": 1001,
//!  "parameters": {"mu_scale": {"value": 1.1, "std": 0.001, "converged_at": 2.31}, ...},
//!  "converged_at": {"mu_scale": 2.31, ...},
//!  "friction": {"force": 5.4, "force_std": 0.005, "moment": 0.1, "moment_std": 0.001,
//!               "point": [0.125, 0.01], "point_std": [0.0, 0.001]},
//!  "update_time_median_s": 1.1e-6, "update_time_p99_s": 2.0e-6,
//!  "lack_of_fit": [{"t_first": 4.1, "t_last": 4.3}], "lack_of_fit_at_end": false,
//!  "diverged_at": null, "converged": true, "not_converged": [], "settings": {...}}
//! ```
//!
//! `lack_of_fit`: the episodes in which the test rejected (first and last
//! rejecting sample, s); `diverged_at`: the time the filter's state left the
//! finite numbers (the rest of the input is then not read; exit 1);
//! `not_converged`: the parameters whose final std exceeds the tolerances
//! below; `degenerate`: why the final estimate explains nothing, by the
//! rule `fit` applies (a μ scale or I_cm at or below 5 % of the file's
//! value, or not positive: a frictionless or massless plate; exit 1);
//! `settings`: the noise levels, priors and numerics used.
//!
//! `converged_at` (s): the first sample time after which the estimate stays
//! within 1 % (`mu_scale`, `inertia_cm`) or 1 mm (each component of
//! `center_of_friction`) of its final value. Update times are the thread
//! CPU time of each estimator update. `converged` (exit 0): every chosen
//! parameter's final std is within those tolerances, the last test window
//! does not reject the model, and it rejected at most [`MAX_EPISODES`]
//! times.

pub mod study;

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use pushval_model::track::{
    Ekf, EkfSettings, Estimator, Free, Measurement, TrackError, TrackModel,
};
use pushval_model::{format, Vec2};
use pushval_scenario::Scenario;
use serde_json::{json, Value};

use crate::fit::{parse_list, Param};

/// More lack-of-fit episodes than this and the model is taken not to
/// explain the data (exit 1) even when the last window passes.
pub const MAX_EPISODES: usize = 3;
/// Relative tolerance of `mu_scale` and `inertia_cm` for `converged_at`.
pub const REL_TOL: f64 = 0.01;
/// Tolerance of each centre-of-friction component for `converged_at` (m).
pub const COF_TOL: f64 = 1e-3;

/// CPU time of the calling thread (s), `CLOCK_THREAD_CPUTIME_ID`.
pub fn thread_cpu_time() -> f64 {
    let ts = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Where the rows come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// A CSV file.
    File(PathBuf),
    /// Standard input, read as the rows arrive.
    Stdin,
}

impl Source {
    /// `-` is standard input.
    pub fn parse(s: &Path) -> Self {
        if s.as_os_str() == "-" {
            Source::Stdin
        } else {
            Source::File(s.to_path_buf())
        }
    }

    fn name(&self) -> String {
        match self {
            Source::File(p) => p.display().to_string(),
            Source::Stdin => "<stdin>".into(),
        }
    }
}

/// What `pushval track` was asked.
#[derive(Debug, Clone)]
pub struct Request {
    /// The scenario file.
    pub scenario: PathBuf,
    /// The trajectory rows.
    pub trajectory: Source,
    /// `NAME[,NAME...]` among mu_scale, center_of_friction, inertia_cm.
    pub params: String,
    /// Output folder (created if missing).
    pub out: PathBuf,
    /// Which run of the CSV's `model` column; None: the only one.
    pub model: Option<String>,
    /// The filter's noise levels and numerics.
    pub settings: EkfSettings,
}

/// The parameters `track` can estimate, parsed from `--params`.
pub fn parse_params(list: &str) -> Result<(Vec<Param>, Free), String> {
    let params = parse_list(list)?;
    if params.contains(&Param::Contact) {
        return Err(
            "`contact` is not estimated online (known: mu_scale, center_of_friction, inertia_cm)"
                .into(),
        );
    }
    let free = Free {
        mu_scale: params.contains(&Param::MuScale),
        center_of_friction: params.contains(&Param::CenterOfFriction),
        inertia_cm: params.contains(&Param::InertiaCm),
    };
    Ok((params, free))
}

/// The estimator's model of a scenario: its problem and its outline
/// relative to the centre of mass.
pub fn track_model(sc: &Scenario) -> anyhow::Result<TrackModel> {
    let outline: Vec<Vec2> = sc.polygon.iter().map(|p| p - sc.center_of_mass).collect();
    TrackModel::new(&sc.problem(), &outline)
        .map_err(|e| anyhow::anyhow!("{}: {e}", sc.path.display()))
}

/// One output row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Sample time (s).
    pub t: f64,
    /// `[mu_scale, c_x, c_y, I_cm]`, the centre of friction in the file's frame.
    pub value: [f64; 4],
    /// Their std.
    pub std: [f64; 4],
    /// Friction magnitude (N), moment about the centre of mass (N m).
    pub force: f64,
    /// Moment about the centre of mass (N m).
    pub moment: f64,
    /// Entry point of the line of action (m, file frame), NaN when none.
    pub point: Vec2,
    /// Std of force, moment, point x, point y.
    pub friction_std: [f64; 4],
    /// This sample's NIS.
    pub nis: f64,
    /// The test rejected at this sample.
    pub lack_of_fit: bool,
    /// Thread CPU time of the update (s).
    pub update_time: f64,
}

/// The header of `track.csv` for `params`.
pub fn header(params: &[Param]) -> Vec<String> {
    let mut h = vec!["t".to_string()];
    for p in params {
        match p {
            Param::CenterOfFriction => {
                for a in ["x", "y"] {
                    h.push(format!("center_of_friction_{a}"));
                    h.push(format!("center_of_friction_{a}_std"));
                }
            }
            _ => {
                h.push(p.name().into());
                h.push(format!("{}_std", p.name()));
            }
        }
    }
    for c in [
        "friction_force",
        "friction_moment",
        "friction_point_x",
        "friction_point_y",
        "friction_force_std",
        "friction_moment_std",
        "friction_point_x_std",
        "friction_point_y_std",
        "nis",
        "lack_of_fit",
    ] {
        h.push(c.into());
    }
    h
}

fn cell(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.9e}")
    } else {
        String::new()
    }
}

/// The fields of one `track.csv` record for `row`.
pub fn line(params: &[Param], row: &Row) -> Vec<String> {
    let mut f = vec![format!("{}", row.t)];
    for p in params {
        let idx: &[usize] = match p {
            Param::CenterOfFriction => &[1, 2],
            Param::InertiaCm => &[3],
            Param::MuScale => &[0],
            Param::Contact => &[],
        };
        for &i in idx {
            f.push(cell(row.value[i]));
            f.push(cell(row.std[i]));
        }
    }
    f.extend([row.force, row.moment, row.point.x, row.point.y].map(cell));
    f.extend(row.friction_std.map(cell));
    f.push(format!("{:.4}", row.nis));
    f.push(format!("{}", row.lack_of_fit as u8));
    f
}

/// What a streamed run produced.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Every row, in order.
    pub rows: Vec<Row>,
    /// Lack-of-fit episodes: first and last rejecting sample time (s).
    pub episodes: Vec<(f64, f64)>,
    /// The test rejected at the last sample.
    pub lack_at_end: bool,
    /// The estimate left the finite numbers at this time (the rest of the
    /// input was not read).
    pub diverged: Option<f64>,
    /// Whether the input had an `omega` column (else the filter estimates
    /// ω from θ as a state).
    pub omega_read: bool,
}

/// Streams `reader` through the filter: one [`Row`] per sample, each
/// written to `csv` and, when given, to `echo` (flushed) as it is made;
/// lack of fit reported on standard error as it happens.
#[allow(clippy::too_many_arguments)]
pub fn stream(
    sc: &Scenario,
    params: &[Param],
    free: Free,
    settings: EkfSettings,
    model_name: Option<&str>,
    reader: &mut dyn BufRead,
    src: &str,
    csv: &mut dyn Write,
    echo: Option<&mut dyn Write>,
) -> anyhow::Result<Outcome> {
    let md = track_model(sc)?;
    if free.center_of_friction && !md.center_of_friction_free() {
        bail!(
            "--params: center_of_friction needs at least three supports not on one line ({} has {})",
            sc.path.display(),
            md.supports()
        );
    }
    let mut ekf = Ekf::new(md, free, settings, None);
    let origin = sc.center_of_mass;
    let head = header(params);
    let mut csv = csv::Writer::from_writer(csv);
    csv.write_record(&head)?;
    let mut echo = echo.map(csv::Writer::from_writer);
    let select = match model_name {
        Some(m) => format::Select::Model(m.to_string()),
        None => format::Select::One,
    };
    let mut rd = format::Reader::new(reader, src, pushval_scenario::MAX_SAMPLES as usize)
        .select(select)
        .extra(&["fx", "fy"]);
    let h = rd.header()?;
    if h.has("fx") != h.has("fy") {
        bail!(
            "{src}: line {}: the header has only one of `fx`, `fy` (both or neither)",
            h.line
        );
    }
    let omega_read = h.has_omega();
    if settings.sigma_omega.is_some() && !omega_read {
        bail!(
            "{src}: line {}: --sigma-omega needs an `omega` column (without one the filter estimates omega from theta itself; an omega derived from theta would count theta twice)",
            h.line
        );
    }
    // The input's header is good: the estimate's header goes out.
    if let Some(e) = echo.as_mut() {
        e.write_record(&head)?;
        e.flush()?;
    }
    let mut out = Outcome {
        rows: Vec::new(),
        episodes: Vec::new(),
        lack_at_end: false,
        diverged: None,
        omega_read,
    };
    let mut in_episode = false;
    while let Some(r) = rd.next_row()? {
        let lineno = r.line;
        let m = Measurement {
            t: r.t,
            x: r.x,
            y: r.y,
            theta: r.theta,
            omega: r.omega,
            force: match (r.extra[0], r.extra[1]) {
                (Some(fx), Some(fy)) => Some(Vec2::new(fx, fy)),
                _ => None,
            },
        };
        let t0 = thread_cpu_time();
        let rep = match ekf.update(&m) {
            Ok(r) => r,
            Err(e @ (TrackError::TimeOrder { .. } | TrackError::OutsideSchedule { .. })) => {
                bail!("{src}: line {lineno}: column `t`: {e}")
            }
            Err(TrackError::Diverged { t }) => {
                // Not bad input: the model cannot follow the data.
                eprintln!("lack of fit at t = {t} s ({src} line {lineno}): the estimate left the finite numbers; stopped");
                out.diverged = Some(t);
                break;
            }
            Err(e) => bail!("{src}: line {lineno}: {e}"),
        };
        let update_time = thread_cpu_time() - t0;
        let est = ekf.estimate();
        let (res, rsd) = ekf.resultant();
        let mut value = est.value;
        value[1] += origin.x;
        value[2] += origin.y;
        let point = res
            .point
            .map_or(Vec2::new(f64::NAN, f64::NAN), |p| p + origin);
        let row = Row {
            t: m.t,
            value,
            std: est.std(),
            force: res.magnitude,
            moment: res.moment,
            point,
            friction_std: [rsd.magnitude, rsd.moment, rsd.point.x, rsd.point.y],
            nis: rep.nis,
            lack_of_fit: rep.lack_of_fit,
            update_time,
        };
        let l = line(params, &row);
        csv.write_record(&l)?;
        if let Some(e) = echo.as_mut() {
            e.write_record(&l)?;
            e.flush()?;
        }
        if rep.lack_of_fit {
            if in_episode {
                if let Some(ep) = out.episodes.last_mut() {
                    ep.1 = m.t;
                }
            } else {
                eprintln!(
                    "lack of fit at t = {} s ({src} line {lineno}): the last {} samples' innovations exceed χ²'s 1e-6 quantile for the stated noise; parameters re-opened",
                    m.t, settings.window
                );
                out.episodes.push((m.t, m.t));
            }
        }
        in_episode = rep.lack_of_fit;
        out.lack_at_end = rep.lack_of_fit;
        out.rows.push(row);
    }
    csv.flush()?;
    if out.rows.is_empty() {
        bail!(
            "{src}: no data rows{}",
            model_name.map_or(String::new(), |m| format!(" for model `{m}`"))
        );
    }
    Ok(out)
}

/// The first time after which `series` stays within `tol` of its last value.
pub fn converged_at(times: &[f64], series: &[f64], tol: f64) -> Option<f64> {
    let last = *series.last()?;
    let mut at = None;
    for (t, v) in times.iter().zip(series).rev() {
        if (v - last).abs() <= tol {
            at = Some(*t);
        } else {
            break;
        }
    }
    at
}

/// `track.json` for `outcome`, the names of the parameters that did not
/// converge, and why the final estimate is degenerate (empty when not).
pub fn summary(
    sc: &Scenario,
    params: &[Param],
    settings: &EkfSettings,
    out: &Outcome,
) -> (Value, Vec<String>, Vec<String>) {
    let num = crate::outdir::json_num;
    let times: Vec<f64> = out.rows.iter().map(|r| r.t).collect();
    let last = out.rows.last().expect("at least one row");
    let mut parameters = serde_json::Map::new();
    let mut conv = serde_json::Map::new();
    let mut not_converged = Vec::new();
    for p in params {
        let idx: Vec<usize> = match p {
            Param::CenterOfFriction => vec![1, 2],
            Param::InertiaCm => vec![3],
            Param::MuScale => vec![0],
            Param::Contact => vec![],
        };
        let tol = |i: usize| {
            if i == 1 || i == 2 {
                COF_TOL
            } else {
                REL_TOL * last.value[i].abs()
            }
        };
        let mut at: Option<f64> = Some(f64::NEG_INFINITY);
        let mut ok = true;
        for &i in &idx {
            let series: Vec<f64> = out.rows.iter().map(|r| r.value[i]).collect();
            at = match (at, converged_at(&times, &series, tol(i))) {
                (Some(a), Some(b)) => Some(a.max(b)),
                _ => None,
            };
            ok &= last.std[i] <= tol(i);
        }
        if !ok {
            not_converged.push(p.name().to_string());
        }
        let (value, std) = if idx.len() == 1 {
            (num(last.value[idx[0]]), num(last.std[idx[0]]))
        } else {
            (
                json!([num(last.value[1]), num(last.value[2])]),
                json!([num(last.std[1]), num(last.std[2])]),
            )
        };
        let at = at.map_or(Value::Null, num);
        parameters.insert(
            p.name().into(),
            json!({"value": value, "std": std, "converged_at": at}),
        );
        conv.insert(p.name().into(), at);
    }
    let mut times_u: Vec<f64> = out.rows.iter().map(|r| r.update_time).collect();
    times_u.sort_by(f64::total_cmp);
    let q = |f: f64| times_u[((times_u.len() - 1) as f64 * f).round() as usize];
    // The final μ scale and I_cm by the fit's degeneracy rule.
    let scalar: Vec<(Param, usize)> = params
        .iter()
        .filter_map(|p| match p {
            Param::MuScale => Some((*p, 0)),
            Param::InertiaCm => Some((*p, 3)),
            _ => None,
        })
        .collect();
    let values: Vec<f64> = scalar.iter().map(|(_, i)| last.value[*i]).collect();
    let file: Vec<f64> = scalar
        .iter()
        .map(|(p, _)| match p {
            Param::InertiaCm => sc.problem().body.inertia_cm(),
            _ => 1.0,
        })
        .collect();
    let degenerate = crate::fit::degenerate_reasons(&scalar, &values, &file);
    let converged = not_converged.is_empty()
        && degenerate.is_empty()
        && !out.lack_at_end
        && out.episodes.len() <= MAX_EPISODES;
    let v = json!({
        "scenario": sc.name,
        "method": "ekf",
        "samples": out.rows.len(),
        "parameters": parameters,
        "converged_at": conv,
        "friction": {
            "force": num(last.force), "force_std": num(last.friction_std[0]),
            "moment": num(last.moment), "moment_std": num(last.friction_std[1]),
            "point": [num(last.point.x), num(last.point.y)],
            "point_std": [num(last.friction_std[2]), num(last.friction_std[3])],
        },
        "update_time_median_s": q(0.5),
        "update_time_p99_s": q(0.99),
        "lack_of_fit": out.episodes.iter().map(|(a, b)| json!({"t_first": a, "t_last": b})).collect::<Vec<_>>(),
        "lack_of_fit_at_end": out.lack_at_end,
        "diverged_at": out.diverged.map_or(Value::Null, num),
        "converged": converged,
        "not_converged": not_converged,
        "degenerate": degenerate,
        "settings": {
            "sigma_position": settings.sigma_position,
            "sigma_theta": settings.sigma_theta,
            "sigma_omega": settings.sigma_omega,
            "omega": if out.omega_read { "read" } else { "absent: estimated by the filter from theta" },
            "sigma_force": settings.sigma_force,
            "prior_relative": settings.prior,
            "initial_std": settings.initial_std,
            "max_step_s": settings.max_step,
            "window": settings.window,
            "z": settings.z,
        },
    });
    (v, not_converged, degenerate)
}

/// The parameters `track` can estimate that the scenario's pushes do not
/// identify to its convergence thresholds ([`REL_TOL`] of the value, or
/// [`COF_TOL`] for the centre of friction), each with why: unidentifiable
/// by `pushval fit`'s rules, or a Fisher std above the threshold (the
/// Fisher information of the dynamic model at the file's values, at the
/// noise levels given, [`crate::fit::fisher_at`]). One push through a fixed
/// contact, for instance, leaves the centre of friction and I_cm trading
/// off against each other.
pub fn unidentifiable(
    sc: &Scenario,
    sigma_position: f64,
    sigma_theta: f64,
) -> Result<Vec<(Param, String)>, String> {
    let all = [Param::MuScale, Param::CenterOfFriction, Param::InertiaCm];
    let model = crate::fit::Parametrised::new(sc, &all)?;
    let settings = crate::fit::Settings {
        sigma_position,
        sigma_theta,
        ..Default::default()
    };
    let values = model.file_values();
    let f = crate::fit::fisher_at(&model, &values, &settings)?;
    let std = f.std();
    let mut out: Vec<(Param, String)> = Vec::new();
    for (j, (p, _)) in model.slots().into_iter().enumerate() {
        if out.iter().any(|(q, _)| *q == p) {
            continue;
        }
        let limit = match p {
            Param::CenterOfFriction => COF_TOL,
            _ => REL_TOL * values[j].abs(),
        };
        if f.unidentifiable[j] {
            out.push((p, "unidentifiable (Fisher information)".into()));
        } else if !(std[j] <= limit) {
            out.push((
                p,
                format!(
                    "Fisher std {:.1e} above the {limit:.1e} it must reach",
                    std[j]
                ),
            ));
        }
    }
    Ok(out)
}

/// `pushval track`: exit 0 converged, 1 not converged or the model does
/// not explain the data, Err (exit 2) on bad input with nothing written.
pub fn cli(req: &Request) -> anyhow::Result<ExitCode> {
    let sc = crate::registry::load(&req.scenario)?;
    let (params, free) = parse_params(&req.params).map_err(|e| anyhow::anyhow!("--params: {e}"))?;
    for (what, v) in [
        ("--sigma-position", req.settings.sigma_position),
        ("--sigma-theta", req.settings.sigma_theta),
        ("--sigma-omega", req.settings.sigma_omega.unwrap_or(1.0)),
        ("--sigma-force", req.settings.sigma_force.unwrap_or(1.0)),
    ] {
        if !(v.is_finite() && v > 0.0) {
            bail!("{what}: must be a finite number > 0, got {v}");
        }
    }
    let src = req.trajectory.name();
    // A file holding several models and no --model is refused before any
    // row is used, listing every model (standard input can only list the
    // ones seen when the second arrives).
    if let (Source::File(p), None) = (&req.trajectory, &req.model) {
        let f = std::fs::File::open(p).with_context(|| format!("{}: cannot read", p.display()))?;
        format::require_one_model(
            std::io::BufReader::new(f),
            &src,
            pushval_scenario::MAX_SAMPLES as usize,
        )?;
    }
    let mut reader: Box<dyn BufRead> = match &req.trajectory {
        Source::File(p) => Box::new(std::io::BufReader::new(
            std::fs::File::open(p).with_context(|| format!("{}: cannot read", p.display()))?,
        )),
        Source::Stdin => Box::new(std::io::stdin().lock()),
    };
    // Everything is written at the end, so bad input leaves nothing behind.
    let mut csv: Vec<u8> = Vec::new();
    let stdout = std::io::stdout();
    let mut lock = stdout.lock();
    let echo: Option<&mut dyn Write> = match req.trajectory {
        Source::Stdin => Some(&mut lock),
        Source::File(_) => None,
    };
    let out = stream(
        &sc,
        &params,
        free,
        req.settings,
        req.model.as_deref(),
        &mut *reader,
        &src,
        &mut csv,
        echo,
    )?;
    drop(lock);
    if !out.omega_read {
        eprintln!("note: {src}: no `omega` column: the filter estimates omega from theta");
    }
    let (mut json, not_converged, degenerate) = summary(&sc, &params, &req.settings, &out);
    // What the pushes cannot identify, asked for or not: said, never hidden.
    let blind = unidentifiable(&sc, req.settings.sigma_position, req.settings.sigma_theta)
        .unwrap_or_default();
    json["unidentifiable"] = json!(blind
        .iter()
        .map(|(p, why)| json!({"parameter": p.name(), "why": why, "estimated": params.contains(p)}))
        .collect::<Vec<_>>());
    for (p, why) in &blind {
        eprintln!(
            "note: {}: its pushes do not identify {} ({why}){}",
            sc.name,
            p.name(),
            if params.contains(p) {
                ": its estimate cannot converge on this trajectory"
            } else {
                ": not estimated here (kept at the file's value)"
            }
        );
    }
    std::fs::create_dir_all(&req.out).with_context(|| format!("creating {}", req.out.display()))?;
    let csv_path = req.out.join("track.csv");
    crate::atomic::write_atomic(&csv_path, &csv)?;
    let json_path = req.out.join("track.json");
    crate::atomic::write_atomic(&json_path, serde_json::to_string_pretty(&json)?.as_bytes())?;
    eprintln!("wrote {} and {}", csv_path.display(), json_path.display());
    let mut code = ExitCode::SUCCESS;
    if !not_converged.is_empty() {
        eprintln!(
            "FAIL {}: not converged (final std above 1 % or 1 mm): {}",
            sc.name,
            not_converged.join(", ")
        );
        code = ExitCode::from(1);
    }
    for why in &degenerate {
        eprintln!("FAIL {}: degenerate estimate: {why}", sc.name);
        code = ExitCode::from(1);
    }
    if out.lack_at_end || out.diverged.is_some() || out.episodes.len() > MAX_EPISODES {
        eprintln!(
            "FAIL {}: the model does not explain the data ({} lack-of-fit episode(s){})",
            sc.name,
            out.episodes.len(),
            if out.lack_at_end {
                ", the last at the end"
            } else {
                ""
            }
        );
        code = ExitCode::from(1);
    }
    Ok(code)
}
