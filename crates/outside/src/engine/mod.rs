//! [`OutsideEngine`]: an engine model that runs as a process.

mod answers;
mod rows;
mod stepping;

use std::sync::Arc;
use std::time::{Duration, Instant};

use pushval_engine::{
    trajectory_from_steps, Engine, EngineCrate, EngineInfo, EngineOptions, EngineRun, FrictionLaw,
    OptionKeys, ReplaySession, Session,
};
use pushval_model::{ModelError, Problem};

use crate::check::{self, Bound};
use crate::config::Spec;
use crate::csv;
use crate::document::{problem_document, problem_document_v2};
use crate::limits::Limits;
use crate::process::{last_lines, run_process, ProcessError};
use crate::session::{Close, Lease};
use rows::engine_steps;
pub use rows::{contact_from_rows, history_from_rows};
use stepping::Stepping;

/// How many lines of a failed process's standard error a message quotes.
const STDERR_LINES: usize = 8;

/// An outside engine with a scenario's `[engine]` options: one process per
/// run, or a session (see the crate docs). With protocol 3 it steps: its
/// [`Engine::session`] keeps the adapter's world between pushes, and `run`
/// is `start`, one `advance` per push, `finish` (the requests written at
/// once, the answers read as a session reads them); with protocol 1 or 2,
/// its session replays the schedule applied so far.
#[derive(Clone)]
pub struct OutsideEngine {
    spec: Arc<Spec>,
    law: Option<Arc<dyn FrictionLaw>>,
    options: EngineOptions,
    info: EngineInfo,
}

impl std::fmt::Debug for OutsideEngine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OutsideEngine")
            .field("spec", &self.spec)
            .field("options", &self.options)
            .field("law", &self.law.as_ref().map(|l| l.law_name()))
            .finish()
    }
}

impl OutsideEngine {
    /// The engine `spec` declares, with the scenario's `[engine]` options
    /// (passed verbatim in the document's `options`).
    pub fn new(spec: Arc<Spec>, options: &EngineOptions) -> Self {
        let file = spec.file.file_name().map_or_else(
            || spec.file.display().to_string(),
            |f| f.to_string_lossy().into_owned(),
        );
        let adapter = format!("outside: {file}");
        let description = format!(
            "outside engine: `{}` run from {} (declared in {})",
            spec.command_line(),
            spec.dir.display(),
            spec.file.display()
        );
        // The protocol's crate: an outside engine links no engine crate.
        let engine_crate = EngineCrate {
            name: "pushval-outside",
            version: env!("CARGO_PKG_VERSION"),
        };
        let version = spec
            .version
            .clone()
            .unwrap_or_else(|| format!("unversioned ({adapter} gives no version)"));
        let info = EngineInfo::new(
            spec.name.clone(),
            description,
            adapter,
            engine_crate,
            spec.order,
            options.dt.unwrap_or(spec.dt),
        )
        .with_version(version)
        .with_availability(spec.availability())
        // Every key: the process receives the whole `[engine]` table.
        .with_options(OptionKeys::Any);
        Self {
            info,
            options: options.clone(),
            spec,
            law: None,
        }
    }

    /// The engine with the friction law its declaration names (the
    /// registry resolves `law = "NAME"`).
    pub fn with_law(mut self, law: Option<Arc<dyn FrictionLaw>>) -> Self {
        self.law = law;
        self
    }

    /// Its declaration.
    pub fn spec(&self) -> &Spec {
        &self.spec
    }

    /// The sentence that starts every error of a run: the engine and its
    /// command.
    fn who(&self) -> String {
        format!(
            "outside engine \"{}\" (command `{}`, run from {})",
            self.spec.name,
            self.spec.command_line(),
            self.spec.dir.display()
        )
    }
}

impl Engine for OutsideEngine {
    fn info(&self) -> &EngineInfo {
        &self.info
    }
    fn settings(&self, dt: f64) -> serde_json::Value {
        serde_json::json!({
            "engine": self.info.version,
            "dt": dt,
            "command": self.spec.command,
            "declared_in": self.spec.file.display().to_string(),
            "order": self.spec.order,
            "timeout_s": self.spec.timeout_s,
        })
    }
    fn law(&self) -> Option<&dyn FrictionLaw> {
        self.law.as_deref()
    }
    fn run(&self, problem: &Problem, dt: f64) -> Result<EngineRun, ModelError> {
        if self.steps() {
            return Stepping::run(Arc::new(self.clone()), problem, dt);
        }
        let start = Instant::now();
        problem.check()?;
        if problem.release.is_some() {
            return Err(ModelError::NoRelease {
                engine: self.spec.name.clone(),
                reason: format!(
                    "a protocol {} document is a whole run without a slide (only a protocol 3 session, session = true, can be asked to release)",
                    self.spec.protocol
                ),
            });
        }
        let limits = Limits::for_problem(problem, dt);
        let doc = if self.spec.protocol >= 2 {
            problem_document_v2(&self.spec.name, problem, &self.options, dt, limits)
        } else {
            problem_document(&self.spec.name, problem, &self.options, dt)
        };
        let timeout = Duration::from_secs_f64(self.spec.timeout_s);
        let (stdout, stderr, process_time, input_bytes, served_by) = if self.spec.session {
            let serde_json::Value::Object(doc) = doc else {
                unreachable!("the document is an object")
            };
            let mut lease = Lease::take(&self.spec).map_err(|e| self.broken(e))?;
            let a = lease
                .request(doc, "problem", Close::End, limits, timeout)
                .map_err(|e| self.broken(e))?;
            let about = serde_json::json!({
                "pid": a.pid,
                "answered_before": a.answered_before,
                "request": a.request,
            });
            let stderr = a.stderr();
            (a.stdout, stderr, a.elapsed, None, Some(about))
        } else {
            let input = serde_json::to_vec(&doc).expect("a JSON value serialises");
            let out = run_process(
                &self.spec.program(),
                &self.spec.command[1..],
                &self.spec.dir,
                &input,
                timeout,
                limits,
            )
            .map_err(|e| self.broken(e))?;
            if !out.status.success() {
                return Err(self.broken(ProcessError {
                    what: match out.status.code() {
                        Some(c) => format!("exited with status {c}"),
                        None => format!("was ended by a signal ({})", out.status),
                    },
                    stderr: out.stderr,
                }));
            }
            (out.stdout, out.stderr, out.elapsed, Some(input.len()), None)
        };
        let fail = |what: String| self.fail(what, &stderr);
        let parse_start = Instant::now();
        let text = std::str::from_utf8(&stdout)
            .map_err(|e| fail(format!("wrote standard output that is not UTF-8 ({e})")))?;
        let rows = csv::read(text, problem.body.len())
            .map_err(|e| fail(format!("wrote a malformed row on its standard output: {e}")))?;
        check::rows(&Bound::of(problem), None, &rows, |r| {
            format!("line {}", r.line)
        })
        .map_err(|e| fail(format!("wrote a row that is not a motion of the push: {e}")))?;
        let mut run = self
            .assemble(problem, dt, &rows)
            .map_err(|e| fail(format!("wrote rows that do not cover the run: {e}")))?;
        let parse_time = parse_start.elapsed();
        run.wall_time = start.elapsed();
        run.diagnostics = serde_json::json!({
            "rows": rows.len(),
            "process_wall_time_s": process_time.as_secs_f64(),
            "parse_resample_time_s": parse_time.as_secs_f64(),
            "input_bytes": input_bytes,
            "output_bytes": stdout.len(),
            "protocol": self.spec.protocol,
            "session": served_by,
        });
        Ok(run)
    }

    /// Protocol 3 in a session: the adapter's world, kept between pushes
    /// (the `start` request carries no schedule); otherwise a
    /// [`ReplaySession`] that re-runs the pushes applied so far. Either owns
    /// a copy of the engine (its declaration is shared).
    fn session(&self, problem: &Problem, dt: f64) -> Result<Session, ModelError> {
        let engine = Arc::new(self.clone());
        if !self.steps() {
            return Ok(Box::new(ReplaySession::new(engine, problem, dt)));
        }
        Stepping::start(engine, problem, dt).map(|s| Box::new(s) as Session)
    }
}

impl OutsideEngine {
    /// Whether the engine steps (protocol 3 in a session): its own
    /// [`EngineSession`](pushval_engine::EngineSession); else its session replays.
    fn steps(&self) -> bool {
        self.spec.session && self.spec.protocol >= 3
    }

    /// A process failure as the run's error.
    /// A failed `release` request: an `#error` answer is the adapter's
    /// refusal to release ([`ModelError::NoRelease`], naming the engine);
    /// anything else is [`OutsideEngine::broken`].
    fn refused(&self, e: ProcessError) -> ModelError {
        if e.what.contains("with `#error") {
            return ModelError::NoRelease {
                engine: self.spec.name.clone(),
                reason: e.what,
            };
        }
        self.broken(e)
    }

    fn broken(&self, e: ProcessError) -> ModelError {
        ModelError::Adapter(format!(
            "{}: {}; {}",
            self.who(),
            e.what,
            last_lines(&e.stderr, STDERR_LINES)
        ))
    }

    /// Bad output as the run's error.
    fn fail(&self, what: String, stderr: &[u8]) -> ModelError {
        ModelError::Adapter(format!(
            "{}: {what}; {}",
            self.who(),
            last_lines(stderr, STDERR_LINES)
        ))
    }

    /// The run of checked `rows` (diagnostics and wall time left to the
    /// caller).
    fn assemble(
        &self,
        problem: &Problem,
        dt: f64,
        rows: &[csv::Record],
    ) -> Result<EngineRun, String> {
        let history = history_from_rows(problem, rows)?;
        let mut trajectory = trajectory_from_steps(&self.spec.name, problem, &history);
        let steps = engine_steps(rows);
        trajectory.stats.steps = steps;
        trajectory.stats.rhs_evals = steps;
        Ok(EngineRun {
            trajectory,
            dt,
            steps,
            wall_time: Duration::ZERO,
            diagnostics: serde_json::Value::Null,
            contact: contact_from_rows(problem, rows),
        })
    }
}
