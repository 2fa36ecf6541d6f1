//! The slide study's throws, runs and tables.

use anyhow::Context;
use pushval_engine::Engine;
use pushval_model::{DynamicModel, Integrator, ModelError, Problem, Simulator, Vec2};
use rayon::prelude::*;

use super::disc::Status;
use crate::harness::{rest_of, Rest};
use crate::outdir::{num, Csv};

/// The shipped scenario whose plate is thrown.
pub const SCENE: &str = "thrown-square.toml";

/// The throws of a study: every combination of a speed, a spin and a
/// direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Centre-of-mass speeds (m/s).
    pub speeds: Vec<f64>,
    /// Spins ω (rad/s).
    pub spins: Vec<f64>,
    /// Directions of the velocity (rad, world frame; the plate starts at
    /// θ = 0, so this is also the angle to its edge's normal).
    pub directions: Vec<f64>,
}

impl Grid {
    /// The study's grid: 3 speeds × 3 spins × 3 directions (the square's
    /// symmetry makes 0 to π/4 every direction), or 1 × 2 × 2 for `quick`.
    pub fn new(quick: bool) -> Self {
        use std::f64::consts::FRAC_PI_4;
        if quick {
            Self {
                speeds: vec![0.5],
                spins: vec![0.0, 4.0],
                directions: vec![0.0, FRAC_PI_4],
            }
        } else {
            Self {
                speeds: vec![0.25, 0.5, 1.0],
                spins: vec![0.0, 4.0, 10.0],
                directions: vec![0.0, FRAC_PI_4 / 2.0, FRAC_PI_4],
            }
        }
    }

    /// Every throw `(speed, spin, direction)`, speeds outermost.
    pub fn throws(&self) -> Vec<Throw> {
        let mut out = Vec::new();
        for &speed in &self.speeds {
            for &spin in &self.spins {
                for &direction in &self.directions {
                    out.push(Throw {
                        speed,
                        spin,
                        direction,
                    });
                }
            }
        }
        out
    }
}

/// One throw: the plate's state when the slide starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Throw {
    /// m/s
    pub speed: f64,
    /// rad/s
    pub spin: f64,
    /// rad, world frame
    pub direction: f64,
}

impl Throw {
    /// The scene's problem with this throw as its start.
    pub fn problem(&self, scene: &Problem) -> Problem {
        let mut p = scene.clone();
        p.initial.velocity = Vec2::new(
            self.speed * self.direction.cos(),
            self.speed * self.direction.sin(),
        );
        p.initial.omega = self.spin;
        p.initial.theta = 0.0;
        p.initial.position = Vec2::zeros();
        p
    }
}

/// One engine's rest for one throw at one step, beside the model's.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub engine: String,
    /// The engine's step (s).
    pub dt: f64,
    pub throw: Throw,
    /// The dynamic model's rest (None: not stopped within max_duration).
    pub model: Option<Rest>,
    /// The engine's rest (None: not stopped).
    pub engine_rest: Option<Rest>,
    /// Where the engine's plate was when the slide was cut at
    /// `max_duration` without a stop (its `t` that time), and the rest
    /// rule's speed `|v| + |ω| L` (m/s) over its last sample interval;
    /// None when it stopped.
    pub engine_end: Option<(Rest, f64)>,
}

impl Row {
    /// Distance between the two rest positions (m); NaN unless both stopped.
    pub fn d_position(&self) -> f64 {
        match (self.model, self.engine_rest) {
            (Some(m), Some(e)) => (e.x - m.x).hypot(e.y - m.y),
            _ => f64::NAN,
        }
    }
    /// The engine's rest angle minus the model's (rad).
    pub fn d_theta(&self) -> f64 {
        match (self.model, self.engine_rest) {
            (Some(m), Some(e)) => e.theta - m.theta,
            _ => f64::NAN,
        }
    }
    /// The engine's stop time minus the model's (s).
    pub fn d_t_stop(&self) -> f64 {
        match (self.model, self.engine_rest) {
            (Some(m), Some(e)) => e.t - m.t,
            _ => f64::NAN,
        }
    }
    /// Distance (m) from the model's rest to where an engine that did not
    /// stop was at `max_duration`; NaN otherwise.
    pub fn d_end(&self) -> f64 {
        match (self.model, self.engine_end) {
            (Some(m), Some((e, _))) => (e.x - m.x).hypot(e.y - m.y),
            _ => f64::NAN,
        }
    }
}

/// What one run through the slide gives the study: its rest, or where it
/// was at `max_duration` and its speed there (see [`Row::engine_end`]).
fn rest_or_end(
    problem: &Problem,
    tr: &pushval_model::Trajectory,
) -> (Option<Rest>, Option<(Rest, f64)>) {
    if let Some(r) = rest_of(tr) {
        return (Some(r), None);
    }
    let n = tr.samples.len();
    if n < 2 {
        return (None, None);
    }
    let (a, b) = (tr.samples[n - 2], tr.samples[n - 1]);
    let dt = b.t - a.t;
    let v = if dt > 0.0 {
        [(b.x - a.x) / dt, (b.y - a.y) / dt]
    } else {
        [f64::NAN; 2]
    };
    let speed = pushval_engine::rest_speed(problem, v, b.omega);
    let end = Rest {
        t: b.t,
        x: b.x,
        y: b.y,
        theta: b.theta,
    };
    (None, Some((end, speed)))
}

/// One engine of the study.
#[derive(Debug, Clone, PartialEq)]
pub struct EngineRow {
    pub name: String,
    /// The catalogue name of the law it declares, and the law's sentence
    /// (None: it declares none).
    pub law: Option<(String, String)>,
    /// Its default step (s).
    pub dt: f64,
    /// The order in the step it declares for a problem with a release
    /// (`order_for`).
    pub declared_order: f64,
    pub status: Status,
}

/// Everything the study measured.
#[derive(Debug, Clone)]
pub struct Study {
    pub grid: Grid,
    pub quick: bool,
    pub engines: Vec<EngineRow>,
    pub rows: Vec<Row>,
    /// The thrown disc's ratio `v/(Rω)` near the stop, per engine.
    pub disc: super::disc::DiscStudy,
}

/// The scene's problem: the shipped `thrown-square` scenario's.
pub fn scene() -> anyhow::Result<Problem> {
    Ok(crate::shipped::scenario(SCENE)?.problem())
}

/// The dynamic model's rest for `problem` (the gate's reference settings).
pub fn model_rest(problem: &Problem) -> Result<Option<Rest>, ModelError> {
    let model = DynamicModel {
        integrator: Integrator::Dop853 {
            tol: crate::inject::MODEL_TOL,
        },
        ..Default::default()
    };
    Ok(rest_of(&model.simulate(problem)?))
}

/// The law an engine declares: its catalogue name and sentence.
fn declared_law(name: &str) -> Option<(String, String)> {
    crate::registry::declarations()
        .into_iter()
        .find(|(_, engines)| engines.iter().any(|e| e == name))
        .map(|(entry, _)| (entry.name.to_string(), entry.about.to_string()))
}

/// A run's rest, or where it ended and its speed there when it did not
/// stop ([`rest_or_end`]).
type RestOrEnd = (Option<Rest>, Option<(Rest, f64)>);

/// Runs one engine on every throw at `h` and `h/2` (the model's rests
/// given, in throw order). An engine that refuses the release, or fails,
/// on the first throw is not run further.
pub fn run_engine(
    engine: &dyn Engine,
    throws: &[Throw],
    scene: &Problem,
    model: &[Option<Rest>],
) -> (Status, Vec<Row>) {
    let h = engine.default_dt();
    let one = |t: &Throw, dt: f64| -> Result<RestOrEnd, ModelError> {
        let p = t.problem(scene);
        Ok(rest_or_end(&p, &engine.run(&p, dt)?.trajectory))
    };
    if let Some(first) = throws.first() {
        match one(first, h) {
            Err(ModelError::NoRelease { reason, .. }) => return (Status::Refused(reason), vec![]),
            Err(e) => return (Status::Failed(e.to_string()), vec![]),
            Ok(_) => {}
        }
    }
    let jobs: Vec<(usize, f64)> = (0..throws.len())
        .flat_map(|i| [(i, h), (i, h / 2.0)])
        .collect();
    let results: Vec<Result<Row, ModelError>> = jobs
        .par_iter()
        .map(|&(i, dt)| {
            let (engine_rest, engine_end) = one(&throws[i], dt)?;
            Ok(Row {
                engine: engine.name().to_string(),
                dt,
                throw: throws[i],
                model: model[i],
                engine_rest,
                engine_end,
            })
        })
        .collect();
    let mut rows = Vec::new();
    for r in results {
        match r {
            Ok(r) => rows.push(r),
            Err(e) => return (Status::Failed(e.to_string()), vec![]),
        }
    }
    (Status::Released, rows)
}

/// Runs the study: the model on every throw, then every available engine
/// of the registry (compiled in, and the outside engines of the
/// `pushval.toml` in use).
pub fn measure(quick: bool) -> anyhow::Result<Study> {
    let grid = Grid::new(quick);
    let scene = scene()?;
    let throws = grid.throws();
    let model: Vec<Option<Rest>> = throws
        .iter()
        .map(|t| model_rest(&t.problem(&scene)))
        .collect::<Result<_, _>>()
        .context("the dynamic model's slide")?;
    let available: Vec<(String, Box<dyn Engine>)> = crate::registry::entries()
        .into_iter()
        .map(|entry| (entry.name.clone(), entry.default_engine()))
        .filter(|(_, e)| e.availability().is_ok())
        .collect();
    // The disc first: one run per engine, cheap.
    let engines_only: Vec<&dyn Engine> = available.iter().map(|(_, e)| e.as_ref()).collect();
    let disc = super::disc::measure_disc(&engines_only)?;
    let mut engines = Vec::new();
    let mut rows = Vec::new();
    for (name, engine) in &available {
        let (status, mut r) = run_engine(engine.as_ref(), &throws, &scene, &model);
        engines.push(EngineRow {
            name: name.clone(),
            law: declared_law(name),
            dt: engine.default_dt(),
            declared_order: engine.order_for(&scene),
            status,
        });
        rows.append(&mut r);
    }
    Ok(Study {
        grid,
        quick,
        engines,
        rows,
        disc,
    })
}

/// `throws.csv`: one row per engine, step and throw.
pub fn throws_csv(study: &Study) -> Csv {
    let mut csv = Csv::new(&[
        "engine",
        "dt",
        "speed",
        "spin",
        "direction",
        "model_t_stop",
        "model_x",
        "model_y",
        "model_theta",
        "engine_t_stop",
        "engine_x",
        "engine_y",
        "engine_theta",
        "d_position",
        "d_theta",
        "d_t_stop",
        "end_t",
        "end_x",
        "end_y",
        "end_theta",
        "end_speed",
    ]);
    let f = |r: Option<Rest>, k: fn(&Rest) -> f64| r.as_ref().map_or(String::new(), |r| num(k(r)));
    for r in &study.rows {
        csv.row(&[
            r.engine.clone(),
            num(r.dt),
            num(r.throw.speed),
            num(r.throw.spin),
            num(r.throw.direction),
            f(r.model, |r| r.t),
            f(r.model, |r| r.x),
            f(r.model, |r| r.y),
            f(r.model, |r| r.theta),
            f(r.engine_rest, |r| r.t),
            f(r.engine_rest, |r| r.x),
            f(r.engine_rest, |r| r.y),
            f(r.engine_rest, |r| r.theta),
            num(r.d_position()),
            num(r.d_theta()),
            num(r.d_t_stop()),
            f(r.engine_end.map(|e| e.0), |r| r.t),
            f(r.engine_end.map(|e| e.0), |r| r.x),
            f(r.engine_end.map(|e| e.0), |r| r.y),
            f(r.engine_end.map(|e| e.0), |r| r.theta),
            r.engine_end.map_or(String::new(), |e| num(e.1)),
        ]);
    }
    csv
}

/// `engines.csv`: one row per engine of the build.
pub fn engines_csv(study: &Study) -> Csv {
    let mut csv = Csv::new(&["engine", "law", "dt", "status", "note"]);
    for e in &study.engines {
        let (status, note) = match &e.status {
            Status::Released => ("released", String::new()),
            Status::Refused(why) => ("refused", why.clone()),
            Status::Failed(why) => ("failed", why.clone()),
        };
        csv.row(&[
            e.name.clone(),
            e.law.as_ref().map_or(String::new(), |l| l.0.clone()),
            num(e.dt),
            status.into(),
            note,
        ]);
    }
    csv
}
