//! A study's files from its rows, and its README from those files: every
//! number of a README is read back from the CSV text written beside it.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;

use super::figure::cell_errors;
use super::plan::{Plan, Task};
use super::plate::{err, frs, phis, PHI_TABLE, TABLE_SPEEDS};
use crate::fit::engine as fit;
use crate::harness::law::{class_name, law_integrates, LAW_RUN, LOADS};
use crate::outdir::{field_num as num, records, Csv, Records, Writer};

/// Shares of a map's cells: `(cells, within 1e-2 of Coulomb, with a law,
/// within 1e-2 of the law, turns, locked, semi_stable, with the law on the
/// run's loads, within 1e-2 of it)`.
pub fn map_stats(map: &Records) -> [usize; 9] {
    let mut s = [0; 9];
    for r in map {
        let [ec, el, er] = cell_errors(r);
        s[0] += 1;
        s[1] += usize::from(ec.is_some_and(|e| e <= 1e-2));
        for (e, k) in [(el, 2), (er, 7)] {
            s[k] += usize::from(e.is_some());
            s[k + 1] += usize::from(e.is_some_and(|e| e <= 1e-2));
        }
        match r.get("class").map(String::as_str) {
            Some("turns") => s[4] += 1,
            Some("locked") => s[5] += 1,
            Some("semi_stable") => s[6] += 1,
            _ => {}
        }
    }
    s
}

fn pct(a: usize, b: usize) -> String {
    if b == 0 {
        "–".into()
    } else {
        format!("{a}/{b} ({:.0} %)", 100.0 * a as f64 / b as f64)
    }
}

/// Where the law locks and the engine turns anyway: the cells of class
/// `locked` whose engine |ω| exceeds 1e-2 |ω*| (Coulomb's), their share and
/// median |ω|, and the range of φ they span. None without locked cells.
fn locked_turning(map: &Records) -> Option<String> {
    let locked: Vec<_> = map
        .iter()
        .filter(|r| r.get("class").map(String::as_str) == Some("locked"))
        .collect();
    if locked.is_empty() {
        return None;
    }
    let mut turning: Vec<(f64, f64)> = locked
        .iter()
        .filter(|r| num(r, "omega_engine").abs() > 1e-2 * num(r, "omega_coulomb").abs())
        .map(|r| (num(r, "omega_engine").abs(), num(r, "phi")))
        .collect();
    if turning.is_empty() {
        return Some(format!(
            "\nWhere the law locks ({} cells) the engine stays within 1e-2 |ω*| of rest in every one.\n",
            locked.len()
        ));
    }
    turning.sort_by(|a, b| a.0.total_cmp(&b.0));
    let median = turning[turning.len() / 2].0;
    let (lo, hi) = turning
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
            (a.min(t.1), b.max(t.1))
        });
    Some(format!(
        "\nWhere the law locks, the engine turns anyway (|ω| above 1e-2 |ω*|) in {} of the cells, φ from {lo:.2} to {hi:.2} rad, at a median |ω| of {} rad/s: a creep the law does not predict.\n",
        pct(turning.len(), locked.len()),
        sig(median)
    ))
}

/// `v` written by `f`, `–` where undefined (README cells).
fn dash(v: f64, f: impl Fn(f64) -> String) -> String {
    if v.is_finite() {
        f(v)
    } else {
        "–".into()
    }
}

/// A record's per-step load range, `min – max` (N), `–` where unknown.
fn load_range(r: &std::collections::BTreeMap<String, String>) -> String {
    let (lo, hi) = (num(r, "load_min"), num(r, "load_max"));
    // The sum is finite where both are.
    dash(lo + hi, |_| format!("{lo:.3} – {hi:.3}"))
}

/// A share as a percentage.
fn share(v: f64) -> String {
    dash(v, |v| format!("{:.2} %", 100.0 * v))
}

/// `v` to 4 significant digits.
fn sig(v: f64) -> String {
    dash(v, |v| format!("{v:.4e}"))
}

/// The header of a run's table: `lead`, [`RUN_HEAD`], `class`, `tail`.
fn run_head(lead: &[&'static str], tail: &[&'static str]) -> Vec<&'static str> {
    [lead, &RUN_HEAD, &["class"], tail].concat()
}

/// A run's fields after `lead`: those of [`RUN_HEAD`], then its class.
fn run_cells(mut lead: Vec<String>, r: &[f64]) -> Vec<String> {
    lead.extend(run_fields(r));
    lead.push(class_name(r[3]).into());
    lead
}

/// The columns of the engine's, Coulomb's and the law's ω.
const RUN_HEAD: [&str; 3] = ["omega_engine", "omega_coulomb", "omega_law"];

/// The columns of what the run's own loads give (empty where the engine
/// measures no loads).
const LAW_RUN_HEAD: [&str; 6] = [
    "omega_law_run",
    "law_run_rms",
    "max_rise_m",
    "contact_lost_share",
    "load_min",
    "load_max",
];

/// ω of the engine, Coulomb and the law: the fields of [`RUN_HEAD`].
fn run_fields(r: &[f64]) -> impl Iterator<Item = String> + '_ {
    r[..3].iter().map(|v| opt(*v))
}

/// The fields of [`LAW_RUN_HEAD`].
fn law_run_fields(r: &[f64]) -> impl Iterator<Item = String> + '_ {
    r[LAW_RUN..LAW_RUN + 6].iter().map(|v| opt(*v))
}

fn map_csv(plan: &Plan, tasks: &[Task], rows: &[Vec<f64>], setup: usize) -> Csv {
    let mut csv = Csv::new(&run_head(&["froude", "phi"], &LAW_RUN_HEAD));
    for (t, r) in tasks.iter().zip(rows) {
        if let Task::Map { s: k, i, j } = *t {
            if k == setup {
                let lead = [frs(plan.quick)[i], phis(plan.quick)[j]];
                let mut f = run_cells(lead.map(|x| x.to_string()).into(), r);
                f.extend(law_run_fields(r));
                csv.row(&f);
            }
        }
    }
    csv
}

/// Writes every file of the study and its README.
pub fn write(plan: &Plan, tasks: &[Task], rows: &[Vec<f64>], w: &mut Writer) -> anyhow::Result<()> {
    let rows_of = |pick: &dyn Fn(&Task) -> bool| -> Vec<(Task, &Vec<f64>)> {
        tasks
            .iter()
            .zip(rows)
            .filter(|(t, _)| pick(t))
            .map(|(t, r)| (*t, r))
            .collect()
    };
    let mut paper = Csv::new(&[&["speed"][..], &RUN_HEAD, &LAW_RUN_HEAD].concat());
    for (t, r) in rows_of(&|t| matches!(t, Task::Table { s: 0, .. })) {
        if let Task::Table { v, .. } = t {
            let mut f = vec![TABLE_SPEEDS[v].to_string()];
            f.extend(run_fields(r).chain(law_run_fields(r)));
            paper.row(&f);
        }
    }
    w.file("paper_plate.csv", paper.as_bytes())?;
    let map = map_csv(plan, tasks, rows, 0);
    w.file("map.csv", map.as_bytes())?;
    w.figure(
        "map.svg",
        &super::figure::map_figure(&plan.model, map.text())?,
    )?;

    // The step ladder: change from the next coarser step, the observed
    // order from three steps, Richardson at the declared order.
    let p = plan.setups[0].engine.order();
    // The ladder's step ratio (2 for the default ladders).
    let ratio = plan.ladder[0] / plan.ladder[1];
    let ladder_csv = |sel: &dyn Fn(&Task) -> bool,
                      lead: &dyn Fn(&Task) -> Vec<String>,
                      first: &[&'static str]| {
        let tail = ["change", "observed_order", "richardson"];
        let mut csv = Csv::new(&run_head(&[first, &["dt"]].concat(), &tail));
        let rs = rows_of(sel);
        for (n, (t, r)) in rs.iter().enumerate() {
            let same = |m: usize| n >= m && lead(&rs[n - m].0) == lead(t);
            let change = if same(1) {
                r[0] - rs[n - 1].1[0]
            } else {
                f64::NAN
            };
            let order = if same(2) {
                ((rs[n - 1].1[0] - rs[n - 2].1[0]) / change).abs().ln() / ratio.ln()
            } else {
                f64::NAN
            };
            let dt = match *t {
                Task::Ladder { k } | Task::Creep { k, .. } => plan.ladder[k],
                _ => f64::NAN,
            };
            let rich = r[0] + change / (ratio.powf(p) - 1.0);
            let mut f = run_cells([lead(t), vec![dt.to_string()]].concat(), r);
            f.extend([change, order, rich].map(opt));
            csv.row(&f);
        }
        csv
    };
    let ladder = ladder_csv(&|t| matches!(t, Task::Ladder { .. }), &|_| Vec::new(), &[]);
    w.file("dt_ladder.csv", ladder.as_bytes())?;
    let creep = (!plan.creep.is_empty()).then(|| {
        ladder_csv(
            &|t| matches!(t, Task::Creep { .. }),
            &|t| match t {
                Task::Creep { v, .. } => vec![TABLE_SPEEDS[*v].to_string()],
                _ => Vec::new(),
            },
            &["speed"],
        )
    });
    if let Some(c) = &creep {
        w.file("creep.csv", c.as_bytes())?;
    }
    let lead = ["variant", "options", "supports_half", "phi", "dt", "speed"];
    let mut variants = Csv::new(&run_head(
        &lead,
        &[&LAW_RUN_HEAD[..], &["theta_end"]].concat(),
    ));
    let mut variant_maps = Vec::new();
    for (k, s) in plan.setups.iter().enumerate().skip(1) {
        let options: Vec<String> = s
            .options
            .values
            .iter()
            .map(|(a, b)| format!("{a}={b}"))
            .collect();
        for (t, r) in rows_of(&|t| matches!(t, Task::Table { s, .. } if *s == k)) {
            if let Task::Table { v, .. } = t {
                let lead = vec![
                    s.name.clone(),
                    // One field: its commas read as `;` (as they always have).
                    options.join(" ").replace(',', ";"),
                    s.supports_half.map_or(String::new(), |h| h.to_string()),
                    s.phi.to_string(),
                    s.dt.to_string(),
                    TABLE_SPEEDS[v].to_string(),
                ];
                let mut f = run_cells(lead, r);
                f.extend(law_run_fields(r));
                f.push(opt(r[LAW_RUN - 1]));
                variants.row(&f);
            }
        }
        if s.map {
            let csv = map_csv(plan, tasks, rows, k);
            w.file(&format!("map_{}.csv", s.name), csv.as_bytes())?;
            variant_maps.push((s.name.clone(), csv.text().to_string()));
        }
    }
    if plan.setups.len() > 1 {
        w.file("variants.csv", variants.as_bytes())?;
    }
    let mut fits = Csv::new(&[&["schedule"][..], &fit::COLUMNS, &["verdict", "reason"]].concat());
    for (t, r) in rows_of(&|t| matches!(t, Task::Fit { .. })) {
        if let Task::Fit { k } = t {
            let mut f = vec![fit::SCHEDULES[k].to_string()];
            f.extend(r.iter().take(fit::WIDTH - 3).map(|v| opt(*v)));
            f.extend(fit::judged(r));
            fits.row(&f);
        }
    }
    if plan.fit {
        w.file("coulomb_fit.csv", fits.as_bytes())?;
    }
    let mut more = sweeps(plan, tasks, rows, w)?;
    more.push_str(&rest_moments(plan, tasks, rows, w)?);
    let mut text = readme(
        plan,
        paper.text(),
        map.text(),
        ladder.text(),
        creep.as_ref().map(Csv::text),
        variants.text(),
        &variant_maps,
        fits.text(),
    )?;
    text.push_str(&more);
    w.file("README.md", text.as_bytes())
}

/// `v` to 3 decimals.
fn dec3(v: &f64) -> String {
    dash(*v, |v| format!("{v:.3}"))
}

/// `[engine]` options as TOML reads them: `k = v, …`.
fn options_text(o: &std::collections::BTreeMap<String, serde_json::Value>) -> String {
    o.iter()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// `sweep_NAME.csv` of every sweep, and their README sections.
fn sweeps(
    plan: &Plan,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<String> {
    let mut md = String::new();
    for (n, sw) in plan.sweeps.iter().enumerate() {
        let sel: Vec<_> = tasks
            .iter()
            .zip(rows)
            .filter(|(t, _)| matches!(t, Task::Sweep { w, .. } if *w == n))
            .collect();
        let has_loads = sel
            .iter()
            .any(|(_, r)| r[7..7 + 2 * LOADS].iter().any(|v| v.is_finite()));
        let tail = ["err_vs_coulomb", "err_vs_law", "theta_end"];
        let mut columns: Vec<String> = run_head(&["value", "speed", "phi", "dt", "theta0"], &tail)
            .iter()
            .map(|c| c.to_string())
            .collect();
        if has_loads {
            for who in ["engine", "law"] {
                columns.extend((1..=LOADS).map(|k| format!("load_{who}_{k}")));
            }
        }
        let mut csv = Csv::new(&columns);
        let name = &sw.spec.name;
        let _ = write!(
            md,
            "\n## Sweep {name} (`sweep_{name}.csv`)\n\n`{}` over {:?}{}; {}{}.\n\n\
             | {} | v_c (m/s) | ω engine | ω* Coulomb | ω law | class | vs Coulomb | vs law |{}\n|---|---|---|---|---|---|---|---|{}\n",
            sw.spec.over,
            sw.spec.values,
            if sw.spec.engine.is_empty() { String::new() } else { format!(", `[engine]` {}", options_text(&sw.spec.engine)) },
            match sw.spec.stop {
                Some(s) => format!("{} s pushes, then the pusher at rest for {s} s: ω engine is the mean |ω| over the rest's last {} s, the models' ω at rest", sw.t_run, sw.tail * s),
                None => format!("{} s runs, ω the mean over the last {} %", sw.t_run, 100.0 * sw.tail),
            },
            if has_loads { "; loads in N, supports in the problem's order, the engine's averaged over the run's last fifth" } else { "" },
            sw.spec.over,
            if has_loads { " loads engine | loads law |" } else { "" },
            if has_loads { "---|---|" } else { "" },
        );
        for (t, r) in sel {
            let Task::Sweep { i, v, .. } = *t else {
                continue;
            };
            let (speed, phi, dt, theta0, _) = sw.push(i, v);
            // After a stop ω is a mean |ω| at rest, against no turning rate.
            let (ec, el, class) = match sw.spec.stop {
                Some(_) => (f64::NAN, f64::NAN, ""),
                None => (
                    err(r[0], r[1], r[1], speed),
                    err(r[0], r[2], r[1], speed),
                    class_name(r[3]),
                ),
            };
            let mut f: Vec<String> = [sw.spec.values[i], speed, phi, dt, theta0]
                .map(|v| v.to_string())
                .into();
            f.extend(run_fields(r));
            f.push(class.into());
            f.extend([ec, el, r[LAW_RUN - 1]].map(opt));
            let _ = write!(
                md,
                "| {} | {speed} | {} | {} | {} | {} | {} | {} |",
                sw.spec.values[i],
                sig(r[0]),
                sig(r[1]),
                sig(r[2]),
                class,
                sig(ec),
                sig(el)
            );
            if has_loads {
                // Loads: `LOADS` engine then as many law columns.
                f.extend(r[7..7 + 2 * LOADS].iter().map(|v| opt(*v)));
                let fmt = |x: &[f64]| x.iter().map(dec3).collect::<Vec<_>>().join(" ");
                let _ = write!(
                    md,
                    " {} | {} |",
                    fmt(&r[7..7 + LOADS]),
                    fmt(&r[7 + LOADS..7 + 2 * LOADS])
                );
            }
            csv.row(&f);
            md.push('\n');
        }
        w.file(&format!("sweep_{name}.csv"), csv.as_bytes())?;
    }
    Ok(md)
}

/// `rest_moments.csv`, where the law holds some map cell from one side:
/// M₀, H and S (N m) of every cell of every map.
fn rest_moments(
    plan: &Plan,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<String> {
    let mut csv = Csv::new(&[
        "variant", "froude", "phi", "class", "moment", "lock", "hold",
    ]);
    let (mut semi, mut cells) = (0usize, 0usize);
    for (t, r) in tasks.iter().zip(rows) {
        if let Task::Map { s, i, j } = *t {
            cells += 1;
            csv.row(&[
                plan.setups[s].name.clone(),
                frs(plan.quick)[i].to_string(),
                phis(plan.quick)[j].to_string(),
                class_name(r[3]).into(),
                opt(r[4]),
                opt(r[5]),
                opt(r[6]),
            ]);
            semi += usize::from(r[4].is_finite());
        }
    }
    if semi == 0 {
        return Ok(String::new());
    }
    w.file("rest_moments.csv", csv.as_bytes())?;
    Ok(format!(
        "\n## Rest moments (`rest_moments.csv`)\n\nWhere the law holds ω = 0 from one side only (H < |M₀| ≤ S) it gives the sliding rows' moment at ω = 0, M₀, the largest |M₀| they lock, H, \
         and the largest that sticking rows hold, S (N m). The file lists every cell of every map of the study ({cells}); {semi} are semi-stable and carry M₀, H and S.\n"
    ))
}

#[allow(clippy::too_many_arguments)]
fn readme(
    plan: &Plan,
    paper: &str,
    map: &str,
    ladder: &str,
    creep: Option<&str>,
    variants: &str,
    variant_maps: &[(String, String)],
    fits: &str,
) -> anyhow::Result<String> {
    let (paper, map, ladder) = (records(paper)?, records(map)?, records(ladder)?);
    let (variants, fits) = (records(variants)?, records(fits)?);
    let creep = creep.map(records).transpose()?;
    let e = plan.setups[0].engine.as_ref();
    let m = &plan.model;
    let mut s = format!(
        "# {m}: friction against Coulomb\n\n\
         Generated by `pushval study {m}` ({}); do not edit by hand. Study file: `studies/{m}.toml`{}.\n\n",
        e.version(),
        if plan.spec.about.is_some() || !plan.spec.variant.is_empty() { "" } else { " (none: defaults)" }
    );
    if plan.quick {
        s.push_str("**Quick run: reduced grids (for tests).**\n\n");
    }
    let law = e
        .law()
        .map_or("none declared".to_string(), |l| l.law_name().to_string());
    let p = super::plate::paper_plate(0.5, PHI_TABLE, plan.t_run, None);
    let _ = write!(
        s,
        "Model: {}. Engine law in closed form: {law}. Scene: the seed paper's plate (0.25 m square, 1 kg, μ = 0.5 on four corner supports), \
         pushed at a corner from ω = 0 for {} s; ω is the mean over the last {} % of the run{}, at Δt = {} s{}.\n\n",
        e.description(),
        plan.t_run,
        100.0 * plan.tail,
        match e.law().and_then(|l| l.angle_period(&p)) {
            Some(a) => format!(
                ", cut to the whole number of the law's periods in the object's angle ({a:.4} rad) that the tail turns through, where it turns through one or more"
            ),
            None => String::new(),
        },
        plan.dt,
        if plan.setups[0].options.values.is_empty() {
            String::new()
        } else {
            format!(", `[engine]` {}", options_text(&plan.setups[0].options.values))
        }
    );
    if let Some(a) = &plan.spec.about {
        s.push_str(a.trim());
        s.push_str("\n\n");
    }
    // A law with dynamics is integrated along the run's loads where the
    // engine measured them (the rows' rise), else taken quasi-statically.
    let integrated = paper.iter().any(|r| num(r, "max_rise_m").is_finite())
        && e.law().is_some_and(|l| law_integrates(l, &p, 0, plan.dt));
    let _ = write!(
        s,
        "## Paper plate (`paper_plate.csv`)\n\nφ = π/4 + 0.3 = {PHI_TABLE:.4} rad. Error against Coulomb: relative to ω*; against the law: relative, or |ω|/|ω*| where the law holds ω = 0.\n\n\
         ω law is the law with the problem's statics (`omega_law`); ω law, run's loads (`omega_law_run`) is {}, and RMS its RMS distance from the engine's ω(t) there{}. \
         Rise: the centre of mass's largest height above its resting height; lost: the share of steps with a support carrying no load (≤ 1e-6 m g); per-step loads: the smallest and largest normal force of any support on any step (N; the plate's weight is 9.81 N). Empty where the engine measures no loads.\n\n\
         | v_c (m/s) | ω engine (rad/s) | ω* Coulomb | ω law | vs Coulomb | vs law | ω law, run's loads | vs it | RMS (rad/s) | rise (m) | lost | per-step loads (N) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        if integrated {
            "the law integrated in time along the tail with the loads the engine carried between samples (from the engine's ω at the tail's first sample; this law is Coulomb on the loads, with the analytic model's transient), averaged over the tail"
        } else {
            "the law's steady ω at each sample's loads as the engine measured them, averaged over the tail (at up to 40 samples evenly spaced)"
        },
        if integrated { "" } else { " (quasi-static: no transient between samples)" },
    );
    for r in &paper {
        let (v, we, wc, wl, wr) = (
            num(r, "speed"),
            num(r, "omega_engine"),
            num(r, "omega_coulomb"),
            num(r, "omega_law"),
            num(r, "omega_law_run"),
        );
        let _ = writeln!(
            s,
            "| {v} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            sig(we),
            sig(wc),
            sig(wl),
            sig(err(we, wc, wc, v)),
            sig(err(we, wl, wc, v)),
            sig(wr),
            sig(err(we, wr, wc, v)),
            sig(num(r, "law_run_rms")),
            sig(num(r, "max_rise_m")),
            share(num(r, "contact_lost_share")),
            load_range(r)
        );
    }
    let mut map_section = |name: &str, file: &str, map: &Records| {
        let st = map_stats(map);
        let _ = write!(
            s,
            "\n## (Fr, φ) map{name} (`{file}`)\n\n{} cells, Fr from {} to {} (log), φ from {:.2} to {:.2} rad. \
             Within 1e-2 of Coulomb: {}. Within 1e-2 of the engine's law with the problem's loads (`omega_law`): {}; with the run's own loads (`omega_law_run`): {}. The law's class: turns {}, locked {}, semi_stable {}.\n",
            st[0],
            frs(plan.quick)[0],
            frs(plan.quick)[frs(plan.quick).len() - 1],
            phis(plan.quick)[0],
            phis(plan.quick)[phis(plan.quick).len() - 1],
            pct(st[1], st[0]),
            pct(st[3], st[2]),
            pct(st[8], st[7]),
            st[4],
            st[5],
            st[6]
        );
        if let Some(line) = locked_turning(map) {
            s.push_str(&line);
        }
        if name.is_empty() {
            s.push_str(if st[7] > 0 {
                "\nFigure: [`map.svg`](map.svg), drawn from `map.csv`: the error against Coulomb, against the law with the problem's loads and against the law on the run's own loads, by decade; the law's locked cells outlined.\n"
            } else {
                "\nFigure: [`map.svg`](map.svg), drawn from `map.csv`: the error against Coulomb and against the law by decade; the law's locked cells outlined.\n"
            });
        }
    };
    map_section("", "map.csv", &map);
    for (n, t) in variant_maps {
        map_section(
            &format!(", variant {n}"),
            &format!("map_{n}.csv"),
            &records(t)?,
        );
    }
    let ladder_table = |s: &mut String, rows: &Records| {
        s.push_str("| v_c | Δt (s) | ω engine | change | observed order | Richardson |\n|---|---|---|---|---|---|\n");
        for r in rows {
            let v = r.get("speed").cloned().unwrap_or_else(|| "0.5".into());
            let _ = writeln!(
                s,
                "| {v} | {} | {} | {} | {} | {} |",
                num(r, "dt"),
                sig(num(r, "omega_engine")),
                sig(num(r, "change")),
                dash(num(r, "observed_order"), |o| format!("{o:.2}")),
                sig(num(r, "richardson"))
            );
        }
    };
    let _ = write!(
        s,
        "\n## Step ladder (`dt_ladder.csv`)\n\nv_c = 0.5 m/s, φ = π/4 + 0.3. Declared order {}; Richardson at it.\n\n",
        e.order()
    );
    ladder_table(&mut s, &ladder);
    if let Some(c) = &creep {
        s.push_str("\n## Creep where the law locks (`creep.csv`)\n\nThe law holds ω = 0 at these table pushes; the engine's |ω| over the step ladder:\n\n");
        ladder_table(&mut s, c);
    }
    if plan.setups.len() > 1 {
        s.push_str("\n## Variants (`variants.csv`)\n\n| variant | options | supports half side (m) | φ (rad) | Δt (s) | v_c | ω engine | ω* Coulomb | ω law | class | ω law, run's loads | per-step loads (N) | θ at the end (rad) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for r in &variants {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                r["variant"],
                r["options"],
                r["supports_half"],
                r["phi"],
                r["dt"],
                r["speed"],
                sig(num(r, "omega_engine")),
                sig(num(r, "omega_coulomb")),
                sig(num(r, "omega_law")),
                r["class"],
                sig(num(r, "omega_law_run")),
                load_range(r),
                sig(num(r, "theta_end"))
            );
        }
    }
    if plan.fit {
        s.push_str("\n## Coulomb fit (`coulomb_fit.csv`)\n\nThe dynamic model fitted to the engine's trajectory (`pushval fit`'s Levenberg–Marquardt); verdict against ten times the engine's own step error.\n\n\
                    | schedule | fitted | μ scale | residual position (m) | residual θ (rad) | verdict |\n|---|---|---|---|---|---|\n");
        for r in &fits {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} |",
                r["schedule"],
                r["fitted"],
                sig(num(r, "mu_scale")),
                sig(num(r, "position_rms")),
                sig(num(r, "theta_rms")),
                if r["reason"].is_empty() {
                    r["verdict"].to_string()
                } else {
                    format!("{}: {}", r["verdict"], r["reason"])
                }
            );
        }
    }
    Ok(s)
}

/// The index of every model's study, `OUT/README.md`, read from the
/// models' folders (a model this build lacks keeps its folder and row).
pub fn index(root: &Path, models: &[String], quick: bool, w: &mut Writer) -> anyhow::Result<()> {
    let mut s = String::from(
        "# Engine friction against Coulomb: every engine model\n\n\
         Generated by `pushval study all`; do not edit by hand. One folder per model (`pushval study MODEL`), \
         each with its README; this table reads their `paper_plate.csv` (v_c = 0.5 m/s, φ = π/4 + 0.3) and `map.csv`.\n\n",
    );
    if quick {
        s.push_str("**Quick run: reduced grids (for tests).**\n\n");
    }
    s.push_str("| model | ω engine (rad/s) | ω* Coulomb | ω law | map within 1e-2 of Coulomb | of the law | of the law on the run's loads | locked / semi-stable cells |\n|---|---|---|---|---|---|---|---|\n");
    for m in models {
        let read = |f: &str| std::fs::read_to_string(root.join(m).join(f)).ok();
        let (Some(paper), Some(map)) = (read("paper_plate.csv"), read("map.csv")) else {
            continue;
        };
        let rows = records(&paper).with_context(|| format!("{m}/paper_plate.csv"))?;
        let Some(r) = rows.iter().find(|r| num(r, "speed") == 0.5) else {
            continue;
        };
        // The model's figure, redrawn from its map.csv (no engine run).
        w.figure(
            &format!("{m}/map.svg"),
            &super::figure::map_figure(m, &map)?,
        )?;
        let st = map_stats(&records(&map).with_context(|| format!("{m}/map.csv"))?);
        let _ = writeln!(
            s,
            "| [{m}]({m}/README.md) | {} | {} | {} | {} | {} | {} | {} / {} |",
            sig(num(r, "omega_engine")),
            sig(num(r, "omega_coulomb")),
            sig(num(r, "omega_law")),
            pct(st[1], st[0]),
            pct(st[3], st[2]),
            pct(st[8], st[7]),
            st[5],
            st[6]
        );
    }
    w.file("README.md", s.as_bytes())
}

/// A number for a data file, blank where it is NaN (undefined).
pub fn opt(v: f64) -> String {
    if v.is_nan() {
        String::new()
    } else {
        format!("{v}")
    }
}
