//! The slide study's throws, runs and tables.

use anyhow::Context;
use pushval_engine::Engine;
use pushval_model::{DynamicModel, Integrator, ModelError, Problem, Simulator, Vec2};
use rayon::prelude::*;

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
}

/// What became of one engine in the study.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// It released on every throw.
    Released,
    /// It refused the release (it cannot let go): not applicable.
    Refused(String),
    /// It failed to run (its error).
    Failed(String),
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
    let one = |t: &Throw, dt: f64| -> Result<Option<Rest>, ModelError> {
        Ok(rest_of(&engine.run(&t.problem(scene), dt)?.trajectory))
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
            Ok(Row {
                engine: engine.name().to_string(),
                dt,
                throw: throws[i],
                model: model[i],
                engine_rest: one(&throws[i], dt)?,
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
    let mut engines = Vec::new();
    let mut rows = Vec::new();
    for entry in crate::registry::entries() {
        let engine = entry.default_engine();
        if engine.availability().is_err() {
            continue;
        }
        let (status, mut r) = run_engine(engine.as_ref(), &throws, &scene, &model);
        engines.push(EngineRow {
            name: entry.name.clone(),
            law: declared_law(&entry.name),
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
