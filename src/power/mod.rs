//! `pushval power`: the smallest model error the CI gate catches.
//!
//! For each scenario that gates an engine (the project's `scenarios/`, else
//! the shipped ones; `--engines FILE` names the project), and each engine variant
//! (the scenario's gate as shipped, rapier2d in its body-velocity mode, and
//! every other Coulomb engine in the registry that this build has), the gate
//! is run once: the engine at the time step and with the tolerances
//! `validate` resolves. Then each kind of error is injected into the model
//! (the engine stays right), and the smallest magnitude that makes the gate
//! fail is found by bisection on a log scale, for either sign; the same
//! perturbed trajectory is also handed to `compare` as an outside trajectory
//! (gated against the dynamic model and the engine, with `compare`'s
//! tolerances). Writes `OUT/gate_power.csv` and `OUT/gate_power.svg`.

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use pushval_model::Trajectory;
use pushval_scenario::Scenario;

use crate::harness::{
    compare_trajectory, run_scenario, Figures, Resolved, RunOptions, SegmentInfo, SteadyRead,
};
use crate::outdir::Csv;
use crate::plot::{Axis, Figure, Legend, Panel, Series, Stroke, PALETTE};

use crate::inject::inject;
pub use crate::inject::ErrorKind;

/// A gate that refuses its auto tolerances (the engine's accuracy misses
/// the ceiling, or its order strays): `validate` fails it as it stands.
#[derive(Debug)]
pub struct Refused(pub String);

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the gate refuses its auto tolerances: {}", self.0)
    }
}

impl std::error::Error for Refused {}

fn refused(e: &anyhow::Error) -> bool {
    e.downcast_ref::<Refused>().is_some()
}

/// One gate as `validate` runs it: the true model, the engine's run and the
/// tolerances it is held to.
pub struct Gate {
    sc: Scenario,
    engine: String,
    segments: Vec<SegmentInfo>,
    reference: Trajectory,
    engine_run: Trajectory,
    tolerance: Resolved,
    outside_tolerance: Resolved,
    dt: f64,
    seconds: f64,
}

impl Gate {
    /// Runs the gate of `sc` (its first gated engine).
    pub fn new(sc: &Scenario) -> anyhow::Result<Self> {
        let start = Instant::now();
        let report = run_scenario(sc, &RunOptions::default())
            .with_context(|| format!("{}: running the gate", sc.name))?;
        let seconds = start.elapsed().as_secs_f64();
        let name = sc.gate.first().context("the scenario gates no engine")?;
        let c = report
            .comparisons
            .iter()
            .find(|c| &c.model == name)
            .context("the gated engine ran")?;
        if let Some(t) = c.tolerance.as_ref().filter(|t| !t.problems.is_empty()) {
            return Err(Refused(t.problems.join("; ")).into());
        }
        anyhow::ensure!(
            c.pass == Some(true),
            "{}: the gate fails without any injected error: {:?}",
            sc.name,
            c.failed
        );
        let run = report
            .runs
            .iter()
            .find(|r| &r.name == name)
            .context("engine run")?;
        let outside_tolerance = crate::compare::outside_tolerance(sc, &report);
        Ok(Self {
            sc: sc.clone(),
            engine: name.clone(),
            segments: report.segments.clone(),
            reference: report.dynamic().trajectory.clone(),
            engine_run: run.trajectory.clone(),
            tolerance: c
                .tolerance
                .clone()
                .context("a gated row has its tolerance")?,
            outside_tolerance,
            dt: run.settings["dt"].as_f64().unwrap_or(f64::NAN),
            seconds,
        })
    }

    /// The gate with the perturbed model as its reference: does it fail?
    pub fn catches(&self, pert: &Trajectory) -> bool {
        self.check(pert).pass == Some(false)
    }

    /// The gate's comparison with the perturbed model as its reference.
    pub fn check(&self, pert: &Trajectory) -> crate::harness::Comparison {
        let mut segs = self.segments.clone();
        for s in segs.iter_mut() {
            if let (Some(root), Some(r)) = (s.omega_steady.as_mut(), pert.segments.get(s.index)) {
                root.omega = r.omega_end;
            }
        }
        compare_trajectory(
            &self.sc,
            &segs,
            pert,
            &self.engine,
            &self.engine_run,
            SteadyRead::TailMean,
            Some(&self.tolerance.value),
        )
    }

    /// `compare` with the perturbed trajectory as the outside one: does it fail?
    pub fn compare_catches(&self, pert: &Trajectory) -> bool {
        let fails = |reference: &Trajectory, tol: &Figures| {
            compare_trajectory(
                &self.sc,
                &self.segments,
                reference,
                "outside",
                pert,
                SteadyRead::TailMean,
                Some(tol),
            )
            .pass
                == Some(false)
        };
        fails(&self.reference, &self.outside_tolerance.value)
            || fails(&self.engine_run, &self.tolerance.value)
    }

    /// The smallest magnitude of `sign` × kind that `caught` flags, assuming
    /// every larger one is caught too (bisection on a log scale, `iters`
    /// halvings); None when the largest searched is not caught.
    fn smallest(
        &self,
        kind: ErrorKind,
        sign: f64,
        iters: usize,
        caught: &dyn Fn(&Self, &Trajectory) -> bool,
    ) -> Option<f64> {
        let test = |m: f64| inject(&self.sc, kind, sign * m).is_some_and(|t| caught(self, &t));
        let (lo, hi) = kind.range();
        if !test(hi) {
            return None;
        }
        if lo == hi || test(lo) {
            return Some(lo);
        }
        let (mut a, mut b) = (lo.ln(), hi.ln());
        for _ in 0..iters {
            let m = 0.5 * (a + b);
            if test(m.exp()) {
                b = m;
            } else {
                a = m;
            }
        }
        Some(b.exp())
    }
}

/// One row of gate_power.csv.
#[derive(Debug, Clone)]
pub struct Row {
    /// Scenario name.
    pub scenario: String,
    /// The gated engine and its mode.
    pub engine: String,
    /// The error kind.
    pub kind: ErrorKind,
    /// Smallest magnitude `validate` catches with + and − sign.
    pub plus: Option<f64>,
    /// See `plus`.
    pub minus: Option<f64>,
    /// The same for `compare` (both signs; the larger).
    pub compare: Option<f64>,
    /// The gate's tolerances.
    pub tolerance: Figures,
    /// The engine's time step (s).
    pub dt: f64,
    /// Wall time of the gate (the engine runs, the ladder, the comparison) (s).
    pub gate_seconds: f64,
    /// The linear estimate `validate` prints for the same kind
    /// ([`crate::harness::Catches`]; I_cm and every μ only).
    pub linear: Option<f64>,
}

impl Row {
    /// The smallest magnitude caught with either sign (the larger of the two).
    pub fn both(&self) -> Option<f64> {
        if self.kind.signed() {
            Some(self.plus?.max(self.minus?))
        } else {
            self.plus
        }
    }
}

/// The engine variants of a scenario: its gate as shipped, rapier2d's
/// body-velocity mode (independent of the model's contact kinematics), and
/// every other engine named in `extra` that this build has.
fn variants(sc: &Scenario, extra: &[&str]) -> Vec<(String, Scenario)> {
    let mut out = Vec::new();
    let Some(first) = sc.gate.first() else {
        return out;
    };
    let label = |s: &Scenario, name: &str| {
        let mode = s
            .engine
            .values
            .get("friction_velocity")
            .and_then(|v| v.as_str());
        match (name, mode) {
            ("rapier2d", m) => format!("rapier2d[{}]", m.unwrap_or("leapfrog")),
            (n, _) => n.to_string(),
        }
    };
    out.push((label(sc, first), sc.clone()));
    if first == "rapier2d" && !sc.engine.values.contains_key("friction_velocity") {
        let mut body = sc.clone();
        body.engine
            .values
            .insert("friction_velocity".into(), serde_json::json!("body"));
        // First order: at the ladder's floor its self-convergence estimate
        // is a few mm on the 1 m/s scenes, so `validate` refuses auto
        // tolerances for it (the 1e-3 ceiling). Measured here as a gate
        // that states the uncapped auto rule's numbers, for the comparison
        // with leapfrog; its tolerance columns show how loose that is.
        body.tolerance.auto_ceiling = [f64::MAX; 3];
        out.push((label(&body, "rapier2d"), body));
    }
    // The shipped gate is already the first variant.
    for name in extra.iter().filter(|n| **n != first.as_str()) {
        if let Some(e) = crate::registry::entry(name) {
            if e.default_engine().availability().is_ok() {
                let mut s = sc.clone();
                s.gate = vec![name.to_string()];
                if !s.models.iter().any(|m| m == name) {
                    s.models.push(name.to_string());
                }
                out.push((name.to_string(), s));
            }
        }
    }
    out
}

/// The gate-power table for the given scenarios.
pub fn measure(scenarios: &[Scenario], extra: &[&str], iters: usize) -> anyhow::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for sc in scenarios.iter().filter(|s| !s.gate.is_empty()) {
        for (label, variant) in variants(sc, extra) {
            let mut v = variant.clone();
            // Only what the gate needs: the model and the gated engine.
            v.models = std::iter::once("dynamic".to_string())
                .chain(v.gate.iter().cloned())
                .collect();
            // A gate whose engine cannot back its auto tolerances (the
            // ceiling, the order) refuses to run at all: nothing to measure.
            let gate = match Gate::new(&v) {
                Ok(g) => g,
                Err(e) if refused(&e) => {
                    eprintln!("pushval power: {} / {label}: skipped: {e:#}", sc.name);
                    continue;
                }
                Err(e) => return Err(e),
            };
            for kind in ErrorKind::ALL.into_iter().filter(|k| applies(sc, *k)) {
                let (plus, minus) = (
                    gate.smallest(kind, 1.0, iters, &Gate::catches),
                    if kind.signed() {
                        gate.smallest(kind, -1.0, iters, &Gate::catches)
                    } else {
                        None
                    },
                );
                let compare = {
                    let p = gate.smallest(kind, 1.0, iters, &Gate::compare_catches);
                    if kind.signed() {
                        p.zip(gate.smallest(kind, -1.0, iters, &Gate::compare_catches))
                            .map(|(a, b)| a.max(b))
                    } else {
                        p
                    }
                };
                rows.push(Row {
                    scenario: sc.name.clone(),
                    engine: label.clone(),
                    kind,
                    plus,
                    minus,
                    compare,
                    tolerance: gate.tolerance.value,
                    dt: gate.dt,
                    gate_seconds: gate.seconds,
                    linear: gate.tolerance.catches.as_ref().and_then(|c| match kind {
                        ErrorKind::InertiaCm => c.inertia_cm.map(|x| x.0),
                        ErrorKind::MuAll => c.mu_all.map(|x| x.0),
                        _ => None,
                    }),
                });
            }
        }
    }
    Ok(rows)
}

fn opt(v: Option<f64>) -> String {
    v.map_or("not caught".into(), |x| format!("{x:.3e}"))
}

/// Whether the kind can show at all in the scenario: switching needs a
/// switch (more than one push, or a start from rest).
pub fn applies(sc: &Scenario, kind: ErrorKind) -> bool {
    kind != ErrorKind::Switching || sc.pushes.len() > 1 || sc.initial.from_rest
}

/// The CSV text.
pub fn csv(rows: &[Row]) -> String {
    let mut csv = Csv::new(&[
        "scenario",
        "engine",
        "kind",
        "unit",
        "smallest_caught",
        "smallest_caught_plus",
        "smallest_caught_minus",
        "smallest_caught_by_compare",
        "at_search_floor",
        "target",
        "meets_target",
        "tolerance_position_m",
        "tolerance_theta_rad",
        "tolerance_omega_rel",
        "engine_dt_s",
        "gate_wall_time_s",
        "linear_estimate",
    ]);
    for r in rows {
        let meets = match (r.kind.target(), r.both()) {
            (Some(t), Some(b)) => (b <= t).to_string(),
            (Some(_), None) => "false".into(),
            (None, _) => "".into(),
        };
        csv.row(&[
            r.scenario.clone(),
            r.engine.clone(),
            r.kind.name().to_string(),
            r.kind.unit().to_string(),
            opt(r.both()),
            opt(r.plus),
            if r.kind.signed() {
                opt(r.minus)
            } else {
                String::new()
            },
            opt(r.compare),
            // Caught at the smallest magnitude searched: the true threshold
            // is at or below it.
            (r.kind != ErrorKind::Switching
                && r.both()
                    .is_some_and(|b| b <= r.kind.range().0 * (1.0 + 1e-12)))
            .to_string(),
            r.kind.target().map_or(String::new(), |t| format!("{t:e}")),
            meets,
            format!("{:.3e}", r.tolerance.position_max),
            format!("{:.3e}", r.tolerance.theta_max),
            format!("{:.3e}", r.tolerance.omega_steady_rel),
            format!("{:.4e}", r.dt),
            format!("{:.3}", r.gate_seconds),
            r.linear.map_or(String::new(), |x| format!("{x:.3e}")),
        ]);
    }
    csv.text().to_string()
}

/// One panel per kind: the smallest magnitude caught (log) per scenario,
/// one series per engine variant; the target as a grey line where there is
/// one.
pub fn figure(rows: &[Row]) -> anyhow::Result<String> {
    let mut scenarios: Vec<&str> = rows.iter().map(|r| r.scenario.as_str()).collect();
    scenarios.dedup();
    let mut engines: Vec<&str> = Vec::new();
    for r in rows {
        if !engines.contains(&r.engine.as_str()) {
            engines.push(&r.engine);
        }
    }
    let mut panels = Vec::new();
    for kind in ErrorKind::ALL
        .into_iter()
        .filter(|k| *k != ErrorKind::Switching)
    {
        let mut p = Panel::new(
            format!("{} ({})", kind.name(), kind.unit()),
            Axis::lin("scenario # (key on the right)"),
            Axis::log("smallest magnitude caught"),
        )
        .legend(Legend::Outside);
        for (k, e) in engines.iter().enumerate() {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.kind == kind && r.engine == *e)
                .filter_map(|r| {
                    let i = scenarios.iter().position(|s| *s == r.scenario)? as f64;
                    r.both().map(|m| (i, m))
                })
                .collect();
            // Markers only (a scenario is a category, not a curve): one
            // colour per gated engine and mode, so that markers tell apart.
            p = p.series(Series::new(*e, PALETTE[k % PALETTE.len()], Stroke::Dots).points(pts));
        }
        if let Some(t) = kind.target() {
            let n = scenarios.len().max(2) as f64 - 1.0;
            p = p.series(
                Series::new("target (power goal)", crate::plot::GREY, Stroke::Dashed)
                    .points(vec![(0.0, t), (n, t)]),
            );
        }
        panels.push(p);
    }
    crate::plot::render(&Figure {
        size: (2000, 760),
        cols: 5,
        panels,
        key: Some(crate::plot::Key {
            title: "scenario #".into(),
            notes: scenarios
                .iter()
                .enumerate()
                .map(|(i, s)| format!("{i}: {s}"))
                .collect(),
            ..Default::default()
        }),
    })
}

/// The rows of a `gate_power.csv` this module wrote (for `--replot`): every
/// figure the chart draws, read back at the precision the file keeps.
pub fn read_csv(path: &Path) -> anyhow::Result<Vec<Row>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader
        .headers()
        .with_context(|| format!("{}: line 1", path.display()))?
        .clone();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .with_context(|| format!("{}: line 1: no column `{name}`", path.display()))
    };
    let (isc, ien, iki, ipl, imi, ico, itp, itt, ito, idt, iwa, ili) = (
        col("scenario")?,
        col("engine")?,
        col("kind")?,
        col("smallest_caught_plus")?,
        col("smallest_caught_minus")?,
        col("smallest_caught_by_compare")?,
        col("tolerance_position_m")?,
        col("tolerance_theta_rad")?,
        col("tolerance_omega_rel")?,
        col("engine_dt_s")?,
        col("gate_wall_time_s")?,
        col("linear_estimate")?,
    );
    let mut rows = Vec::new();
    for f in reader.records() {
        let f = f.with_context(|| format!("{}: reading", path.display()))?;
        let line = f.position().map_or(0, |p| p.line());
        let at = |i: usize| f.get(i).unwrap_or_default();
        let num = |i: usize| at(i).parse::<f64>().ok();
        let kind = ErrorKind::ALL
            .into_iter()
            .find(|k| k.name() == at(iki))
            .with_context(|| {
                format!(
                    "{}: line {}: column `kind`: unknown `{}`",
                    path.display(),
                    line,
                    at(iki)
                )
            })?;
        rows.push(Row {
            scenario: at(isc).to_string(),
            engine: at(ien).to_string(),
            kind,
            plus: num(ipl),
            minus: num(imi),
            compare: num(ico),
            tolerance: Figures {
                position_max: num(itp).unwrap_or(f64::NAN),
                theta_max: num(itt).unwrap_or(f64::NAN),
                omega_steady_rel: num(ito).unwrap_or(f64::NAN),
            },
            dt: num(idt).unwrap_or(f64::NAN),
            gate_seconds: num(iwa).unwrap_or(f64::NAN),
            linear: num(ili),
        });
    }
    Ok(rows)
}

/// `pushval power --replot`: OUT/gate_power.svg drawn again from
/// OUT/gate_power.csv, nothing measured.
pub fn replot(out: &Path) -> anyhow::Result<std::process::ExitCode> {
    let rows = read_csv(&out.join("gate_power.csv"))?;
    crate::atomic::write_atomic(&out.join("gate_power.svg"), figure(&rows)?.as_bytes())?;
    println!("wrote {}", out.join("gate_power.svg").display());
    Ok(std::process::ExitCode::SUCCESS)
}

/// `pushval power`: measure and write OUT/gate_power.{csv,svg}.
pub fn cli(out: &Path, quick: bool) -> anyhow::Result<std::process::ExitCode> {
    let dir = crate::scenario_dir::default_scenario_dir();
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    let mut scenarios = files
        .iter()
        .map(crate::registry::load)
        .collect::<Result<Vec<_>, _>>()?;
    scenarios.retain(|s| !s.gate.is_empty());
    if quick {
        // The paper scenario where the folder has it (the shipped ones),
        // else the project's first gating scenario (an init project's one).
        let paper = scenarios
            .iter()
            .position(|s| s.path.ends_with("paper-square-v1.0.toml"))
            .unwrap_or(0);
        scenarios = scenarios.into_iter().skip(paper).take(1).collect();
    }
    if scenarios.is_empty() {
        eprintln!(
            "pushval power: no scenario in {} gates an engine: nothing to measure, nothing written",
            dir.display()
        );
        return Ok(std::process::ExitCode::from(1));
    }
    let start = Instant::now();
    // The other Coulomb engines are compared on pushval's own scenarios; a
    // project's scenarios measure the engines they gate, nothing else.
    let (ours, theirs): (Vec<Scenario>, Vec<Scenario>) = scenarios.into_iter().partition(|s| {
        s.path
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| crate::shipped::scenario_text(n).is_some())
    });
    let iters = if quick { 8 } else { 16 };
    let mut rows = measure(&ours, &["box2d", "avian2d"], iters)?;
    rows.extend(measure(&theirs, &[], iters)?);
    if rows.is_empty() {
        eprintln!(
            "pushval power: no rows: every gate of {} refused its auto tolerances (the reasons are above); nothing written",
            dir.display()
        );
        return Ok(std::process::ExitCode::from(1));
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    crate::atomic::write_atomic(&out.join("gate_power.csv"), csv(&rows).as_bytes())?;
    crate::atomic::write_atomic(&out.join("gate_power.svg"), figure(&rows)?.as_bytes())?;
    for r in rows.iter().filter(|r| r.kind.target().is_some()) {
        println!(
            "{:24} {:20} {:20} caught from {} (target {:e})",
            r.scenario,
            r.engine,
            r.kind.name(),
            opt(r.both()),
            r.kind.target().unwrap_or(f64::NAN)
        );
    }
    println!(
        "{} rows in {:.1} s; wrote {} and {}",
        rows.len(),
        start.elapsed().as_secs_f64(),
        out.join("gate_power.csv").display(),
        out.join("gate_power.svg").display()
    );
    Ok(std::process::ExitCode::SUCCESS)
}
