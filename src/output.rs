//! Output formats: `summary.json`, `trajectory.csv`, the terminal table.
//!
//! # `summary.json`
//! ```text
//! { "scenario": NAME, "file": PATH,
//!   "settings": {...},                       // what produced the numbers
//!   "segments": [{ "index", "t_start", "t_end", "speed", "phi", "froude",
//!                  "omega_kinematic", "omega_limit_surface", "omega_steady", "tau",
//!                  "steady_states": [{"omega", "stability", "tau"}] }],
//!   "models": { MODEL: { "position_max", "theta_max", "omega_steady_rel_max",
//!                        "pass", "gated", "settings", "wall_time_s",
//!                        "rest": {"t", "x", "y", "theta"} | null,
//!                        "rest_against_model": {"position", "theta", "stop_time"} | null,
//!                        ... } },
//!   "assumptions": { "all_hold", "pulling", "contact_slip", "force_limit",
//!                    "sticking", "pulling_impulse", "runaway", "max_force", ... } }
//! ```
//! SI units (m, rad, s, rad/s, N). Numbers that do not exist are `null`; no
//! NaN or infinity is ever written. `rest` is where and when the model came
//! to rest after a `[release]` (null without one, or when it did not stop
//! within `max_duration`); `rest_against_model` is that rest against the
//! dynamic model's (distance in m, angle in rad, the stop time's
//! difference in s, the run's minus the model's). On a gated row the rest
//! pose is held to the position and angle tolerances and the stop time to
//! `tolerance.stop_time`.
//!
//! # `trajectory.csv`
//! The one trajectory format ([`pushval_model::format`], which `compare`,
//! `fit` and `track` read): header `model,t,x,y,theta,omega`; one row per
//! model per sample time; x, y the centre of mass in the world frame (m),
//! theta unwrapped (rad).

use pushval_model::{RootKind, Violation};
use serde_json::{json, Value};

use crate::ScenarioReport;

use crate::outdir::json_num as num;

fn opt(v: Option<f64>) -> Value {
    v.map_or(Value::Null, num)
}

fn violation(v: &Option<Violation>) -> Value {
    match v {
        None => Value::Null,
        Some(v) => json!({
            "first_t": num(v.first_t), "worst_t": num(v.worst_t), "worst": num(v.worst),
            "segment": v.segment, "support": v.support,
        }),
    }
}

/// The `summary.json` document.
pub fn summary(report: &ScenarioReport) -> Value {
    let sc = &report.scenario;
    let segments: Vec<Value> = report
        .segments
        .iter()
        .map(|s| {
            json!({
                "index": s.index,
                "t_start": num(s.t_start),
                "t_end": num(s.t_end),
                "speed": num(s.speed),
                "phi": num(s.phi),
                "froude": num(s.froude),
                "omega_kinematic": opt(s.omega_kinematic),
                "kappa": opt(s.kappa),
                "kappa_slope": opt(s.kappa_slope),
                "omega_limit_surface": num(s.omega_limit_surface),
                "omega_steady": opt(s.omega_steady.map(|r| r.omega)),
                "tau": opt(s.tau()),
                "omega_start": num(s.omega_start),
                "settles": s.settles(),
                "steady_states": s.steady_states.iter().map(|r| json!({
                    "omega": num(r.omega),
                    "stability": match r.kind {
                        RootKind::Stable => "stable".to_string(),
                        RootKind::Unstable => "unstable".to_string(),
                        RootKind::Pivot { support, stable } =>
                            format!("pivot on support {support} ({})", if stable { "stable" } else { "unstable" }),
                    },
                    "tau": opt(r.tau),
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let mut models = serde_json::Map::new();
    for c in &report.comparisons {
        let run = report.runs.iter().find(|r| r.name == c.model);
        models.insert(
            c.model.clone(),
            json!({
                "position_max": num(c.position_max),
                "theta_max": num(c.theta_max),
                "omega_steady_rel_max": opt(c.omega_steady_rel_max),
                "pass": c.pass,
                "gated": c.pass.is_some(),
                "failed": c.failed,
                "error": c.error,
                "settings": run.map_or(Value::Null, |r| r.settings.clone()),
                "wall_time_s": run.map_or(Value::Null, |r| num(r.elapsed.as_secs_f64())),
                "rhs_evals": run.map(|r| r.trajectory.stats.rhs_evals),
                "diagnostics": run.map_or(Value::Null, |r| r.diagnostics.clone()),
                "tolerance": c.tolerance.as_ref().map_or(Value::Null, |t| t.json()),
                "loosened": c.pass.is_some() && !sc.tolerance.loosened().is_empty(),
                "warnings": if c.pass.is_some() { gate_warnings(sc) } else { Vec::new() },
                "convergence": c.convergence.as_ref().map_or(Value::Null, |v| json!({
                    "dts": v.dts,
                    "expected_order": v.expected_order,
                    "observed_order": opt(v.order()),
                    "orders": v.orders.iter().map(|(i, p)| json!({"segment": i, "order": num(*p)})).collect::<Vec<_>>(),
                    "omega_steady_rel_max_plain": num(v.plain_rel_max),
                    "omega_steady_rel_max_richardson1": num(v.richardson1_rel_max),
                    "omega_steady_rel_max_richardson2": num(v.richardson2_rel_max),
                })),
                "steps": run.map(|r| r.trajectory.stats.steps),
                "rest": run
                    .and_then(|r| crate::harness::rest_of(&r.trajectory))
                    .map_or(Value::Null, |r| r.json()),
                "rest_against_model": c.rest.as_ref().map_or(Value::Null, |r| json!({
                    "position": num(r.position),
                    "theta": num(r.theta),
                    "stop_time": num(r.stop_time),
                })),
            }),
        );
    }
    let a = &report.dynamic().trajectory.assumptions;
    json!({
        "scenario": sc.name,
        "file": sc.path.display().to_string(),
        "description": sc.description,
        "settings": {
            "switching": format!("{:?}", sc.switching).to_lowercase(),
            "from_rest": sc.initial.from_rest,
            "sample_dt": num(sc.sample_dt),
            "inertia_cm": num(sc.inertia_cm),
            "inertia_source": sc.inertia_source,
            "load_rule": sc.load_rule,
            "supports": sc.supports.len(),
            "froude_length": num(sc.froude_length()),
            "effective_mu": num(sc.effective_mu()),
            "tolerance": {
                "omega_steady_rel": limit(sc.tolerance.omega_steady_rel),
                "position_max": limit(sc.tolerance.position_max),
                "theta_max": limit(sc.tolerance.theta_max),
                "auto_ceiling": sc.tolerance.auto_ceiling.map(num),
                "loosened": sc.tolerance.loosened().iter().map(|l| json!({
                    "key": l.key, "value": num(l.value), "ceiling": num(l.ceiling),
                })).collect::<Vec<_>>(),
                "reason": sc.tolerance.reason,
            },
        },
        "segments": segments,
        "models": models,
        "assumptions": {
            "all_hold": a.all_hold(),
            "pulling": violation(&a.pulling),
            "contact_slip": violation(&a.contact_slip),
            "force_limit": violation(&a.force_limit),
            "sticking": violation(&a.sticking),
            "pulling_impulse": violation(&a.pulling_impulse),
            "runaway": violation(&a.runaway),
            "max_force": num(a.max_force),
            "max_cone_angle": num(a.max_cone_angle),
            "min_support_speed": num(a.min_support_speed),
        },
    })
}

/// What a gated row must say about the gate itself: a loosened tolerance
/// (a `[tolerance]` number above the default auto ceiling, with the file's
/// reason or the lack of one). The continuous-switching hint is on a
/// failing row whose engine switched impulsively only (the harness's).
pub fn gate_warnings(sc: &pushval_scenario::Scenario) -> Vec<String> {
    let mut out = Vec::new();
    let loose = sc.tolerance.loosened();
    if !loose.is_empty() {
        let keys: Vec<String> = loose
            .iter()
            .map(|l| format!("{} = {} > {}", l.key, fmt_e(l.value), fmt_e(l.ceiling)))
            .collect();
        out.push(format!(
            "LOOSENED {} ({})",
            keys.join(", "),
            sc.tolerance
                .reason
                .as_ref()
                .map_or("no reason given".to_string(), |r| format!("reason: {r}"))
        ));
    }
    out
}

/// Short names of the assumption checks that failed, for the table.
pub fn assumption_flags(report: &ScenarioReport) -> Vec<&'static str> {
    let a = &report.dynamic().trajectory.assumptions;
    let mut f = Vec::new();
    if a.pulling.is_some() {
        f.push("pulling");
    }
    if a.pulling_impulse.is_some() {
        f.push("pulling-impulse");
    }
    if a.contact_slip.is_some() {
        f.push("contact-slip");
    }
    if a.force_limit.is_some() {
        f.push("force-limit");
    }
    if a.sticking.is_some() {
        f.push("sticking");
    }
    if a.runaway.is_some() {
        f.push("runaway");
    }
    f
}

/// The `trajectory.csv` text.
pub fn trajectory_csv(report: &ScenarioReport) -> String {
    // Samples are finite: the models return an error on a blow-up.
    let runs: Vec<(&str, &[pushval_model::Sample])> = report
        .runs
        .iter()
        .map(|r| (r.name.as_str(), r.trajectory.samples.as_slice()))
        .collect();
    let mut out = Vec::new();
    pushval_model::format::write(&mut out, &runs).expect("writing to memory");
    String::from_utf8(out).expect("the format is ASCII")
}

fn fmt_e(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2e}")
    } else {
        "-".into()
    }
}

/// The human-readable table: one row per scenario and model.
pub fn table(reports: &[ScenarioReport]) -> String {
    let mut rows: Vec<[String; 7]> = vec![[
        "scenario".into(),
        "model".into(),
        "pos_max[m]".into(),
        "theta_max[rad]".into(),
        "omega_ss_rel".into(),
        "result".into(),
        "notes".into(),
    ]];
    for r in reports {
        let flags = assumption_flags(r);
        for c in &r.comparisons {
            let result = match (&c.error, c.pass) {
                (Some(_), _) => "n/a",
                (None, Some(true)) => "PASS",
                (None, Some(false)) => "FAIL",
                (None, None) if c.model == "dynamic" => "reference",
                (None, None) => "info",
            };
            let mut notes = Vec::new();
            if let Some(e) = &c.error {
                notes.push(e.clone());
            }
            notes.extend(c.failed.iter().cloned());
            if let Some(t) = &c.tolerance {
                if let Some((dt, source, met)) = t.dt {
                    notes.push(format!(
                        "dt {dt:.3e} s ({}, ladder {})",
                        source.as_str(),
                        if met {
                            "met its target"
                        } else {
                            "missed its target"
                        }
                    ));
                }
                if let Some(o) = &t.order {
                    notes.push(match o.observed {
                        Some(p) => format!("order {p:.2} observed, {} declared", o.declared),
                        None => format!("order not observed, {} declared", o.declared),
                    });
                }
                notes.extend(t.notes.iter().cloned());
                if let Some(k) = &t.catches {
                    let f = |c: &Option<(f64, &str)>| {
                        c.map_or("-".to_string(), |(m, _)| format!("{m:.1e}"))
                    };
                    notes.push(format!(
                        "catches relative errors of I_cm {}, mu {}",
                        f(&k.inertia_cm),
                        f(&k.mu_all)
                    ));
                }
            }
            if let (Some(t), true) = (&c.tolerance, c.failed.is_empty()) {
                let src = |k: usize| t.source[k].as_str();
                notes.push(format!(
                    "tolerance {} m ({}), {} rad ({}), {} ({})",
                    fmt_e(t.value.position_max),
                    src(0),
                    fmt_e(t.value.theta_max),
                    src(1),
                    fmt_e(t.value.omega_steady_rel),
                    src(2)
                ));
            }
            if let Some(rest) = &c.rest {
                match (rest.run, c.model == "dynamic") {
                    (Some(_), true) => {}
                    (Some(a), false) => notes.push(format!(
                        "rest at t = {:.4} s, {} m, {} rad and {:+.2e} s from the model's{}",
                        a.t,
                        fmt_e(rest.position),
                        fmt_e(rest.theta),
                        rest.stop_time,
                        c.tolerance.as_ref().and_then(|t| t.stop_time).map_or(
                            String::new(),
                            |s| format!(" (stop-time tolerance {} s)", fmt_e(s.value))
                        )
                    )),
                    (None, _) => {
                        notes.push("did not stop within the release's max_duration".into())
                    }
                }
            }
            if c.model == "dynamic" && !flags.is_empty() {
                notes.push(format!("assumptions fail: {}", flags.join(", ")));
            }
            if c.pass.is_some() {
                notes.extend(gate_warnings(&r.scenario));
            }
            rows.push([
                r.scenario.name.clone(),
                c.model.clone(),
                fmt_e(c.position_max),
                fmt_e(c.theta_max),
                c.omega_steady_rel_max.map_or("-".into(), fmt_e),
                result.into(),
                notes.join("; "),
            ]);
        }
    }
    let mut w = [0usize; 7];
    for row in &rows {
        for (i, c) in row.iter().enumerate() {
            w[i] = w[i].max(c.chars().count());
        }
    }
    let mut out = String::new();
    for (k, row) in rows.iter().enumerate() {
        let line: Vec<String> = row
            .iter()
            .enumerate()
            .map(|(i, c)| format!("{c:<width$}", width = w[i]))
            .collect();
        out.push_str(line.join("  ").trim_end());
        out.push('\n');
        if k == 0 {
            out.push_str(&"-".repeat(w.iter().sum::<usize>() + 12));
            out.push('\n');
        }
    }
    out
}

/// A JUnit XML report: one `<testsuite>` per scenario, one `<testcase>` per
/// model. Gated models that fail carry a `<failure>` naming the figure;
/// informational models pass with their figures in `<system-out>`; models
/// this build cannot run are `<skipped>`.
pub fn junit(reports: &[ScenarioReport]) -> String {
    use quick_xml::escape::escape;
    let mut cases = 0;
    let mut failures = 0;
    let mut body = String::new();
    for r in reports {
        let name = escape(r.scenario.name.as_str()).into_owned();
        let n = r.comparisons.len();
        let f = r
            .comparisons
            .iter()
            .filter(|c| c.pass == Some(false))
            .count();
        cases += n;
        failures += f;
        body.push_str(&format!(
            "  <testsuite name=\"{name}\" tests=\"{n}\" failures=\"{f}\" file=\"{}\">\n",
            escape(r.scenario.path.display().to_string())
        ));
        for c in &r.comparisons {
            let time = r
                .runs
                .iter()
                .find(|run| run.name == c.model)
                .map_or(0.0, |run| run.elapsed.as_secs_f64());
            body.push_str(&format!(
                "    <testcase classname=\"pushval.{name}\" name=\"{}\" time=\"{time:.6}\">\n",
                escape(c.model.as_str())
            ));
            let figures = format!(
                "position_max={} m theta_max={} rad omega_steady_rel_max={}",
                fmt_e(c.position_max),
                fmt_e(c.theta_max),
                c.omega_steady_rel_max.map_or("-".into(), fmt_e)
            );
            match (&c.error, c.pass) {
                (Some(e), None) => body.push_str(&format!(
                    "      <skipped message=\"{}\"/>\n",
                    escape(e.as_str())
                )),
                (_, Some(false)) => body.push_str(&format!(
                    "      <failure type=\"tolerance\" message=\"{}\">{}</failure>\n",
                    escape(c.failed.join("; ")),
                    escape(figures.as_str())
                )),
                _ => body.push_str(&format!(
                    "      <system-out>{}</system-out>\n",
                    escape(figures.as_str())
                )),
            }
            body.push_str("    </testcase>\n");
        }
        body.push_str("  </testsuite>\n");
    }
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"pushval\" tests=\"{cases}\" failures=\"{failures}\">\n{body}</testsuites>\n"
    )
}

/// A `[tolerance]` figure as the file gives it: its number, or `"auto"`.
fn limit(l: pushval_scenario::Limit) -> Value {
    l.value().map_or(Value::from("auto"), num)
}
