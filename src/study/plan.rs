//! A model's study, ready to run ([`Plan`]): its setups, its fixed list of
//! tasks ([`Task`]) and the row of numbers each task reduces to (an engine
//! run against Coulomb's ω* and the engine's own law, or a Coulomb fit).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::bail;
use pushval_engine::{Engine, EngineOptions, LawClass};
use pushval_model::{Problem, Push};

use crate::harness::law::{run_row, RUN_WIDTH};

use super::plate::{frs, paper_plate, phis, speed_of, PHI_TABLE, TABLE_SPEEDS};
use super::spec::{self, Spec};
use crate::fit::engine as fit;

/// One setup of a study: the study's own options or a variant's.
pub struct Setup {
    /// `""` for the study's own setup, else the variant's name.
    pub name: String,
    pub engine: Box<dyn Engine>,
    pub options: EngineOptions,
    pub supports_half: Option<f64>,
    /// Direction of its table (rad).
    pub phi: f64,
    /// Its step (s).
    pub dt: f64,
    pub map: bool,
}

/// One task: an engine run or a fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// Setup `s` at `TABLE_SPEEDS[v]` in its table direction.
    Table { s: usize, v: usize },
    /// The step ladder: `ladder[k]` at 0.5 m/s, φ = π/4 + 0.3.
    Ladder { k: usize },
    /// The creep ladder: `ladder[k]` at `TABLE_SPEEDS[v]`.
    Creep { v: usize, k: usize },
    /// Setup `s`'s map at `frs[i]`, `phis[j]`.
    Map { s: usize, i: usize, j: usize },
    /// The Coulomb fit on schedule `k`.
    Fit { k: usize },
    /// Sweep `w` at its `values[i]` and `speeds[v]`.
    Sweep { w: usize, i: usize, v: usize },
}

/// A sweep of the study file, ready to run.
pub struct SweepPlan {
    pub spec: spec::Sweep,
    /// One engine per value for an `[engine]` key sweep, else one.
    pub engines: Vec<Box<dyn Engine>>,
    /// Pusher speeds (m/s).
    pub speeds: Vec<f64>,
    pub phi: f64,
    pub dt: f64,
    pub t_run: f64,
    pub tail: f64,
}

impl SweepPlan {
    /// Speed (m/s), direction (rad), step (s), start θ (rad) and engine of
    /// value `i` at speed `v`.
    pub(super) fn push(&self, i: usize, v: usize) -> (f64, f64, f64, f64, &dyn Engine) {
        let x = self.spec.values[i];
        let mut p = (self.speeds[v], self.phi, self.dt, 0.0);
        match self.spec.over.as_str() {
            "speed" => p.0 = x,
            "phi" => p.1 = x,
            "dt" => p.2 = x,
            "theta0" => p.3 = x,
            _ => {}
        }
        let e = &self.engines[if self.engines.len() > 1 { i } else { 0 }];
        (p.0, p.1, p.2, p.3, e.as_ref())
    }
}

/// A model's study: its setups, steps and task list.
pub struct Plan {
    pub model: String,
    /// Engine runs that failed in this process: how many, and the first
    /// error (said on stderr at the end, never swallowed).
    failures: std::sync::Mutex<(usize, Option<String>)>,
    pub spec: Spec,
    pub setups: Vec<Setup>,
    pub quick: bool,
    /// Step of the tables and maps (s).
    pub dt: f64,
    pub ladder: Vec<f64>,
    pub t_run: f64,
    pub tail: f64,
    /// Table speeds (indices) at which the law locks: the creep ladder's.
    pub creep: Vec<usize>,
    pub fit: bool,
    pub sweeps: Vec<SweepPlan>,
}

fn build(model: &str, options: &EngineOptions) -> anyhow::Result<Box<dyn Engine>> {
    let e = crate::registry::entry(model).ok_or_else(|| {
        anyhow::anyhow!("unknown model `{model}`; known: {}", models().join(", "))
    })?;
    e.build(options)
        .map_err(|o| anyhow::anyhow!("{model}: {o}"))
}

/// Every engine model of the registry, in its order.
pub fn models() -> Vec<String> {
    crate::registry::entries()
        .iter()
        .map(|e| e.name.to_string())
        .collect()
}

impl Plan {
    /// The plan of `model` from its study file in `studies`.
    pub fn new(model: &str, studies: &Path, quick: bool) -> anyhow::Result<Self> {
        let spec = Spec::load(studies, model)?;
        let options = spec.options(&BTreeMap::new());
        let engine = build(model, &options)?;
        if let Err(why) = engine.availability() {
            bail!("the model `{model}` is not in this build: {why}");
        }
        // Every `[engine]` key of the file must be one the model reads:
        // (where the file names it, the key), from each `[engine]` table.
        let variants = spec.variant.iter().enumerate();
        let sweeps = spec.sweep.iter().enumerate();
        let tables = std::iter::once((String::new(), &spec.engine))
            .chain(variants.map(|(i, v)| (format!("variant[{i}]."), &v.engine)))
            .chain(
                sweeps
                    .clone()
                    .map(|(i, w)| (format!("sweep[{i}]."), &w.engine)),
            );
        let mut keys: Vec<(String, &str)> = tables
            .flat_map(|(at, t)| {
                t.keys()
                    .map(move |k| (format!("{at}engine.{k}"), k.as_str()))
            })
            .collect();
        keys.extend(sweeps.filter_map(|(i, w)| Some((format!("sweep[{i}].over"), w.key()?))));
        if let Some((at, k)) = keys.iter().find(|(_, k)| !engine.accepts_option(k)) {
            bail!(
                "{}: key `{at}`: the model `{model}` reads no [engine] key `{k}` (it reads: {})",
                studies.join(format!("{model}.toml")).display(),
                engine.option_keys().join(", ")
            );
        }
        let dt = spec.dt.unwrap_or(engine.default_dt());
        let mut setups = vec![Setup {
            name: String::new(),
            engine,
            options,
            supports_half: None,
            phi: PHI_TABLE,
            dt,
            map: true,
        }];
        // A model the file's options refuse, named by the file and key.
        let file = studies.join(format!("{model}.toml"));
        let built = |o: &EngineOptions, at: String| {
            build(model, o).map_err(|e| anyhow::anyhow!("{}: key `{at}`: {e}", file.display()))
        };
        for (i, v) in spec.variant.iter().enumerate() {
            let options = spec.options(&v.engine);
            setups.push(Setup {
                name: v.name.clone(),
                engine: built(&options, format!("variant[{i}].engine"))?,
                options,
                supports_half: v.supports_half,
                phi: v.phi.unwrap_or(PHI_TABLE),
                dt: v.dt.unwrap_or(dt),
                // A variant's map is the full grid's: under --quick (the
                // tests' grid) only the base setup is mapped, its table
                // row (`variants.csv`) is kept.
                map: v.map && !quick,
            });
        }
        let t_run = spec.t_run.unwrap_or(6.0);
        let law_locks = |v: usize| {
            let p = paper_plate(TABLE_SPEEDS[v], PHI_TABLE, t_run, None);
            setups[0]
                .engine
                .law()
                .and_then(|l| l.steady(&p, 0, dt))
                .is_some_and(|s| s.class != LawClass::Turns)
        };
        let creep = (0..TABLE_SPEEDS.len()).filter(|&v| law_locks(v)).collect();
        let tail = spec.tail.unwrap_or(0.2);
        let mut sweeps = Vec::new();
        for (n, w) in spec.sweep.iter().enumerate() {
            let engines = match w.key() {
                Some(key) => {
                    let mut e = Vec::new();
                    for (k, &x) in w.values.iter().enumerate() {
                        let mut o = w.engine.clone();
                        // A whole number as TOML's integer: counts are options too.
                        let v = if x.fract() == 0.0 && x.abs() < 9e15 {
                            (x as i64).into()
                        } else {
                            x.into()
                        };
                        o.insert(key.to_string(), v);
                        e.push(built(&spec.options(&o), format!("sweep[{n}].values[{k}]"))?);
                    }
                    e
                }
                None => vec![built(
                    &spec.options(&w.engine),
                    format!("sweep[{n}].engine"),
                )?],
            };
            sweeps.push(SweepPlan {
                engines,
                speeds: w.speeds.clone().unwrap_or(vec![0.5]),
                phi: w.phi.unwrap_or(PHI_TABLE),
                dt: w.dt.unwrap_or(dt),
                t_run: w.t_run.unwrap_or(t_run),
                tail: w.tail.unwrap_or(tail),
                spec: w.clone(),
            });
        }
        Ok(Self {
            model: model.to_string(),
            failures: std::sync::Mutex::new((0, None)),
            ladder: spec.ladder(dt, quick),
            tail,
            sweeps,
            fit: spec.fit.unwrap_or(true),
            spec,
            setups,
            quick,
            dt,
            t_run,
            creep,
        })
    }

    /// The task list (fixed by the grid and the study file).
    pub fn tasks(&self) -> Vec<Task> {
        let mut t = Vec::new();
        for s in 0..self.setups.len() {
            t.extend((0..TABLE_SPEEDS.len()).map(|v| Task::Table { s, v }));
        }
        t.extend((0..self.ladder.len()).map(|k| Task::Ladder { k }));
        for &v in &self.creep {
            t.extend((0..self.ladder.len()).map(|k| Task::Creep { v, k }));
        }
        for (s, setup) in self.setups.iter().enumerate() {
            if setup.map {
                for i in 0..frs(self.quick).len() {
                    t.extend((0..phis(self.quick).len()).map(|j| Task::Map { s, i, j }));
                }
            }
        }
        if self.fit {
            let n = if self.quick { 1 } else { fit::SCHEDULES.len() };
            t.extend((0..n).map(|k| Task::Fit { k }));
        }
        for (w, sw) in self.sweeps.iter().enumerate() {
            // A speed sweep sets the speed itself: one column of speeds.
            let nv = if sw.spec.over == "speed" {
                1
            } else {
                sw.speeds.len()
            };
            for i in 0..sw.spec.values.len() {
                t.extend((0..nv).map(|v| Task::Sweep { w, i, v }));
            }
        }
        t
    }

    /// The task's key: what it computes, so its hash shard never moves.
    pub fn key(&self, t: &Task) -> String {
        let m = &self.model;
        if let Task::Sweep { w, i, v } = *t {
            let sw = &self.sweeps[w];
            let (speed, phi, dt, theta0, _) = sw.push(i, v);
            return format!(
                "{m}/sweep/{}/{}={}/{:?}/v={speed}/phi={phi}/dt={dt}/theta0={theta0}/t={}/tail={}",
                sw.spec.name, sw.spec.over, sw.spec.values[i], sw.spec.engine, sw.t_run, sw.tail
            ) + &sw.spec.stop.map_or(String::new(), |s| format!("/stop={s}"));
        }
        let (speed, phi, dt, s) = self.push(t);
        match t {
            Task::Fit { k } => format!("{m}/fit/{}/{}", fit::SCHEDULES[*k], self.dt),
            _ => format!(
                "{m}/{}/{}/v={speed}/phi={phi}/dt={dt}/t={}/tail={}",
                self.setups[s].name,
                match t {
                    Task::Creep { .. } => "creep",
                    Task::Ladder { .. } => "ladder",
                    _ => "run",
                },
                self.t_run,
                self.tail
            ),
        }
    }

    /// Speed (m/s), direction (rad), step (s) and setup of a run task.
    fn push(&self, t: &Task) -> (f64, f64, f64, usize) {
        match *t {
            Task::Table { s, v } => (TABLE_SPEEDS[v], self.setups[s].phi, self.setups[s].dt, s),
            Task::Ladder { k } => (0.5, PHI_TABLE, self.ladder[k], 0),
            Task::Creep { v, k } => (TABLE_SPEEDS[v], PHI_TABLE, self.ladder[k], 0),
            Task::Map { s, i, j } => {
                let (fr, phi) = (frs(self.quick)[i], phis(self.quick)[j]);
                (speed_of(fr), phi, self.setups[s].dt, s)
            }
            Task::Fit { .. } | Task::Sweep { .. } => (f64::NAN, f64::NAN, self.dt, 0),
        }
    }

    /// Runs a task: a run's row is [`RUN_WIDTH`] values, a fit's
    /// [`fit::WIDTH`] (NaN where the engine or the fit fails).
    pub fn eval(&self, t: &Task) -> Vec<f64> {
        if let Task::Fit { k } = *t {
            return fit::fit_engine(self.setups[0].engine.as_ref(), k, self.dt).unwrap_or_else(
                |(stage, e)| {
                    // The row keeps the stage (its reason column); the
                    // error itself is said here.
                    eprintln!(
                        "study {}: coulomb fit of {}: {}: {e:#}",
                        self.model,
                        fit::SCHEDULES[k],
                        stage.reason()
                    );
                    fit::failed_row(stage)
                },
            );
        }
        if let Task::Sweep { w, i, v } = *t {
            let sw = &self.sweeps[w];
            let (speed, phi, dt, theta0, engine) = sw.push(i, v);
            let mut p = paper_plate(speed, phi, sw.t_run, None);
            p.initial.theta = theta0;
            if let Some(duration) = sw.spec.stop {
                p.pushes.push(Push {
                    duration,
                    speed: 0.0,
                    phi,
                });
            }
            return self.run(engine, &p, dt, sw.tail);
        }
        let (speed, phi, dt, s) = self.push(t);
        let setup = &self.setups[s];
        let p = paper_plate(speed, phi, self.t_run, setup.supports_half);
        self.run(setup.engine.as_ref(), &p, dt, self.tail)
    }

    /// A run's row ([`run_row`]), its failure counted.
    fn run(&self, engine: &dyn Engine, p: &Problem, dt: f64, tail: f64) -> Vec<f64> {
        let (row, failed) = run_row(engine, p, dt, tail);
        if let Some(e) = failed {
            let mut f = self.failures.lock().expect("not poisoned");
            f.0 += 1;
            f.1.get_or_insert_with(|| format!("v_c {} m/s, dt {dt} s: {e}", p.pushes[0].speed));
        }
        row
    }

    /// The note on the engine runs that failed (their rows are blank), if
    /// any: how many and the first error.
    pub fn failure_note(&self) -> Option<String> {
        let f = self.failures.lock().expect("not poisoned");
        (f.0 > 0).then(|| {
            format!(
                "study {}: {} engine run(s) failed, their cells left blank; the first: {}",
                self.model,
                f.0,
                f.1.as_deref().unwrap_or("-")
            )
        })
    }

    pub(super) fn width(&self, t: &Task) -> usize {
        match t {
            Task::Fit { .. } => fit::WIDTH,
            _ => RUN_WIDTH,
        }
    }
}
