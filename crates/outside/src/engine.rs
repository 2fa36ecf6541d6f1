//! [`OutsideEngine`]: an engine model that runs as a process.

use std::sync::Arc;
use std::time::{Duration, Instant};

use pushval_engine::{
    after_release, extend_through_slide, rigid_cm_velocity, trajectory_from_steps, with_pushes,
    ContactRecord, Engine, EngineCrate, EngineInfo, EngineOptions, EngineRun, EngineSession,
    EngineState, FrictionLaw, LoadRecorder, OptionKeys, ReplaySession, Session, StepRecord,
};
use pushval_model::{ModelError, Problem, Push, Sample, SlideReport, Trajectory};

use crate::check::{self, Bound};
use crate::config::Spec;
use crate::csv;
use crate::document::{problem_document, problem_document_v2};
use crate::limits::{Limits, HEADER_BYTES};
use crate::process::{last_lines, run_process, ProcessError};
use crate::session::{Answer, Close, Lease};

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
    /// [`EngineSession`]; else its session replays.
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

/// A protocol 3 session: the adapter keeps its world between pushes. It
/// owns a share of its engine.
struct Stepping {
    engine: Arc<OutsideEngine>,
    /// The problem at `start` (its schedule replaced by the pushes applied).
    problem: Problem,
    dt: f64,
    lease: Lease,
    applied: Vec<Push>,
    /// The header line, once the first advance has given it.
    header: Option<String>,
    /// Where compact rows put their numbers (from `header`), once read.
    columns: Option<csv::Columns>,
    /// The end of the pushes applied (s), summed in order as
    /// [`Problem::segment_times`] sums it.
    end: f64,
    /// The largest motion between two rows the pushes applied allow.
    bound: Bound,
    rows: Vec<csv::Record>,
    state: EngineState,
    started: Instant,
    process_time: Duration,
    parse_time: Duration,
    output_bytes: usize,
    /// The request number of each answer, for messages.
    requests: Vec<u64>,
    answered_before: u64,
    /// Set once a request failed: the adapter's world is no longer the
    /// pushes applied, so the session takes no further request.
    failed: bool,
    /// The slide's rows after the release (the rows of `rows` end at the
    /// release).
    slide_rows: Vec<csv::Record>,
    /// What the release found, once released.
    slide: Option<SlideReport>,
}

/// What an answer's rows cover: a push, or the slide after the release
/// (its `max_duration`, s).
#[derive(Clone, Copy)]
enum Span<'a> {
    Push(&'a Push),
    Release(f64),
}

impl Stepping {
    /// The cap of an answer that holds only its closing line.
    const SMALL: Limits = Limits {
        max_rows: 0,
        max_bytes: HEADER_BYTES,
    };

    /// The `start` request of `problem` at `dt`.
    fn start_doc(
        engine: &OutsideEngine,
        problem: &Problem,
        dt: f64,
    ) -> serde_json::Map<String, serde_json::Value> {
        let spec = &engine.spec;
        let limits = Limits::for_problem(problem, dt);
        let mut doc = problem_document_v2(&spec.name, problem, &engine.options, dt, limits);
        let o = doc.as_object_mut().expect("the document is an object");
        // The schedule is given push by push; the cap is per answer.
        o.remove("pushes");
        o.remove("limits");
        let mut request = serde_json::Map::new();
        request.insert("op".into(), "start".into());
        request.insert("rows".into(), spec.rows.as_str().into());
        // pushval reads compact lines in answers (the kit writes them).
        request.insert("compact".into(), true.into());
        request.insert("problem".into(), doc);
        request
    }

    /// The `advance` request of `push`, and the cap of its answer.
    fn advance_doc(
        problem: &Problem,
        dt: f64,
        push: &Push,
    ) -> (serde_json::Map<String, serde_json::Value>, Limits) {
        let mut request = serde_json::Map::new();
        request.insert("op".into(), "advance".into());
        request.insert("speed".into(), push.speed.into());
        request.insert("phi".into(), push.phi.into());
        request.insert("duration".into(), push.duration.into());
        (request, Limits::for_push(problem, push.duration, dt))
    }

    /// The `release` request, and the cap of its answer (a run as long as
    /// the longest slide).
    fn release_doc(
        problem: &Problem,
        dt: f64,
        max_duration: f64,
    ) -> (serde_json::Map<String, serde_json::Value>, Limits) {
        let mut request = serde_json::Map::new();
        request.insert("op".into(), "release".into());
        request.insert("max_duration".into(), max_duration.into());
        (request, Limits::for_push(problem, max_duration, dt))
    }

    fn finish_doc() -> serde_json::Map<String, serde_json::Value> {
        let mut request = serde_json::Map::new();
        request.insert("op".into(), "finish".into());
        request
    }

    fn timeout(&self) -> Duration {
        Duration::from_secs_f64(self.engine.spec.timeout_s)
    }

    fn start(engine: Arc<OutsideEngine>, problem: &Problem, dt: f64) -> Result<Self, ModelError> {
        let started = Instant::now();
        let mut lease = Lease::take(&engine.spec).map_err(|e| engine.broken(e))?;
        let timeout = Duration::from_secs_f64(engine.spec.timeout_s);
        let a = lease
            .request(
                Self::start_doc(&engine, problem, dt),
                "start",
                Close::Ok,
                Self::SMALL,
                timeout,
            )
            .map_err(|e| engine.broken(e))?;
        Ok(Self::new(engine, problem, dt, lease, &a, started))
    }

    fn new(
        engine: Arc<OutsideEngine>,
        problem: &Problem,
        dt: f64,
        lease: Lease,
        started_by: &Answer,
        started: Instant,
    ) -> Self {
        Self {
            engine,
            problem: with_pushes(problem, Vec::new()),
            dt,
            lease,
            applied: Vec::new(),
            header: None,
            columns: None,
            end: 0.0,
            bound: Bound::of(&with_pushes(problem, Vec::new())),
            rows: Vec::new(),
            state: EngineState::initial(problem),
            started,
            process_time: started_by.elapsed,
            parse_time: Duration::ZERO,
            output_bytes: 0,
            requests: vec![started_by.request],
            answered_before: started_by.answered_before,
            failed: false,
            slide_rows: Vec::new(),
            slide: None,
        }
    }

    /// A whole run: start, an advance per push and finish, the documents
    /// written at once and the answers read in order (no wait between
    /// requests), each answer read as [`EngineSession::advance`] and
    /// [`EngineSession::finish`] read it.
    fn run(
        engine: Arc<OutsideEngine>,
        problem: &Problem,
        dt: f64,
    ) -> Result<EngineRun, ModelError> {
        problem.check()?;
        let started = Instant::now();
        let mut lease = Lease::take(&engine.spec).map_err(|e| engine.broken(e))?;
        let timeout = Duration::from_secs_f64(engine.spec.timeout_s);
        let mut docs = vec![(
            Self::start_doc(&engine, problem, dt),
            "start",
            Close::Ok,
            Self::SMALL,
        )];
        for push in &problem.pushes {
            let (doc, limits) = Self::advance_doc(problem, dt, push);
            docs.push((doc, "advance", Close::End, limits));
        }
        if let Some(r) = &problem.release {
            let (doc, limits) = Self::release_doc(problem, dt, r.max_duration);
            docs.push((doc, "release", Close::End, limits));
        }
        docs.push((Self::finish_doc(), "finish", Close::End, Self::SMALL));
        let mut answers = lease.pipeline(docs, timeout).into_iter();
        let mut next = |what: &str| {
            answers.next().unwrap_or_else(|| {
                Err(ProcessError {
                    what: format!("no answer to the {what} request (the session ended earlier)"),
                    stderr: Vec::new(),
                })
            })
        };
        let a = next("start").map_err(|e| engine.broken(e))?;
        let mut s = Self::new(Arc::clone(&engine), problem, dt, lease, &a, started);
        for push in &problem.pushes {
            let a = next("advance").map_err(|e| engine.broken(e))?;
            s.applied.push(*push);
            s.absorb(a, Span::Push(push))?;
        }
        if let Some(r) = &problem.release {
            let a = next("release").map_err(|e| engine.refused(e))?;
            s.absorb(a, Span::Release(r.max_duration))?;
        }
        let a = next("finish").map_err(|e| engine.broken(e))?;
        s.close(a)
    }

    /// The rows of one advance's answer (`text`: the header first in the
    /// first answer), checked against the rows before.
    fn read(&mut self, text: &str, request: u64, push: Span) -> Result<(), String> {
        let supports = self.problem.body.len();
        let first = self.header.is_none();
        if text
            .lines()
            .any(|l| l.trim_start().starts_with(csv::COMPACT))
        {
            return self.read_compact(text, request, push);
        }
        let (rows, offset) = if first {
            let header = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
            self.header = Some(header.trim().to_string());
            (csv::read(text, supports), 0)
        } else {
            let full = format!("{}\n{text}", self.header.as_deref().unwrap_or(""));
            (csv::read(&full, supports), 1)
        };
        let where_ =
            |line: usize| format!("line {} of its answer to request {request}", line - offset);
        let mut rows = rows.map_err(|e| {
            let at = if e.line > offset {
                where_(e.line)
            } else {
                format!("request {request}")
            };
            format!("wrote a malformed row ({at}): {}", e.problem)
        })?;
        for r in &mut rows {
            // Lines counted in the answer.
            r.line -= offset;
        }
        self.take(rows, first, request, push)
    }

    /// An answer of compact lines (the header first, in the first answer).
    fn read_compact(&mut self, text: &str, request: u64, push: Span) -> Result<(), String> {
        let first = self.header.is_none();
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        if first {
            let (_, header) = lines.next().unwrap_or((0, ""));
            self.header = Some(header.trim().to_string());
        }
        if self.columns.is_none() {
            let header = self.header.as_deref().unwrap_or("");
            let columns = csv::Columns::of(header, self.problem.body.len()).map_err(|e| {
                format!("wrote a header its compact rows cannot use (request {request}): {e}")
            })?;
            self.columns = Some(columns);
        }
        let columns = self.columns.as_ref().expect("just read");
        let mut rows = Vec::new();
        for (i, l) in lines {
            let Some(hex) = l.trim().strip_prefix(csv::COMPACT) else {
                return Err(format!(
                    "wrote a malformed row (line {} of its answer to request {request}): a text row among compact lines",
                    i + 1
                ));
            };
            rows.extend(csv::read_compact(hex, columns, i + 1).map_err(|e| {
                format!("wrote a malformed compact row (answer to request {request}): {e}")
            })?);
        }
        self.take(rows, first, request, push)
    }

    /// Checks an advance's rows against the push (the last of `applied`)
    /// and the rows before, and keeps them.
    fn take(
        &mut self,
        rows: Vec<csv::Record>,
        first: bool,
        request: u64,
        span: Span,
    ) -> Result<(), String> {
        let push = match span {
            Span::Push(p) => p,
            Span::Release(max_duration) => {
                return self.take_slide(rows, first, request, max_duration)
            }
        };
        let where_ = |line: usize| format!("line {line} of its answer to request {request}");
        let t0 = self.end;
        let t1 = t0 + push.duration;
        let mut bound = self.bound;
        bound.widen(push.speed);
        let tol = 1e-9 * t1.max(1.0);
        if rows.is_empty() {
            return Err(format!(
                "answered request {request} (advance {} s to {t1} s) with no row",
                t0
            ));
        }
        if first && rows[0].numbers[0].abs() > tol {
            return Err(format!(
                "{}: the first row is at t = {} s, not at 0 (the first advance's answer starts with the header and the row at t = 0)",
                where_(rows[0].line),
                rows[0].numbers[0]
            ));
        }
        let last = rows.last().expect("not empty");
        if (last.numbers[0] - t1).abs() > tol {
            return Err(format!(
                "{}: the answer to request {request} (advance {t0} s to {t1} s) ends at t = {} s, not at the push's end",
                where_(last.line),
                last.numbers[0]
            ));
        }
        check::rows(&bound, self.rows.last(), &rows, |r| where_(r.line))
            .map_err(|e| format!("wrote a row that is not a motion of the push: {e}"))?;
        let s = rows.last().expect("not empty").numbers;
        self.state = EngineState {
            t: s[0],
            x: s[1],
            y: s[2],
            theta: s[3],
            omega: s[4],
            v_cm: rigid_cm_velocity(&self.problem, Some(push), s[3], s[4]),
        };
        self.end = t1;
        self.bound = bound;
        self.rows.extend(rows);
        Ok(())
    }

    /// Checks the release's rows (the row at t = 0 first for a plate
    /// thrown without pushes) and keeps them: they start after the release
    /// and end at the rest, before `t_release + max_duration`, or at it
    /// (the plate has not stopped).
    fn take_slide(
        &mut self,
        mut rows: Vec<csv::Record>,
        first: bool,
        request: u64,
        max_duration: f64,
    ) -> Result<(), String> {
        let where_ = |line: usize| format!("line {line} of its answer to request {request}");
        let t0 = self.end;
        let t_max = t0 + max_duration;
        let tol = 1e-9 * t_max.max(1.0);
        if rows.is_empty() || (first && rows.len() < 2) {
            return Err(format!(
                "answered request {request} (release at {t0} s) with no row of the slide"
            ));
        }
        if first && rows[0].numbers[0].abs() > tol {
            return Err(format!(
                "{}: the first row is at t = {} s, not at 0 (a release without pushes starts with the header and the row at t = 0)",
                where_(rows[0].line),
                rows[0].numbers[0]
            ));
        }
        let last = rows.last().expect("not empty").clone();
        let t_end = last.numbers[0];
        if !(t_end > t0 + tol && t_end <= t_max + tol) {
            return Err(format!(
                "{}: the slide released at {t0} s ends at t = {t_end} s, not within its max_duration ({t_max} s)",
                where_(last.line)
            ));
        }
        let init = &self.problem.initial;
        let (speed, omega) = if first {
            (init.velocity.norm(), init.omega)
        } else {
            (
                self.state.v_cm[0].hypot(self.state.v_cm[1]),
                self.state.omega,
            )
        };
        let mut bound = self.bound;
        bound.widen_slide(speed, omega);
        check::rows(&bound, self.rows.last(), &rows, |r| where_(r.line))
            .map_err(|e| format!("wrote a row that is not a motion of the slide: {e}"))?;
        let stopped = t_end < t_max - tol;
        let s = last.numbers;
        let v_cm = match (stopped, rows.len()) {
            (false, n) if n >= 2 => {
                let p = rows[n - 2].numbers;
                let dt = (s[0] - p[0]).max(f64::MIN_POSITIVE);
                [(s[1] - p[1]) / dt, (s[2] - p[2]) / dt]
            }
            _ => [0.0, 0.0],
        };
        self.state = EngineState {
            t: s[0],
            x: s[1],
            y: s[2],
            theta: s[3],
            omega: s[4],
            v_cm,
        };
        if first {
            self.rows.push(rows.remove(0));
        }
        self.slide = Some(SlideReport {
            t_release: t0,
            t_stop: stopped.then_some(t_end),
            pivots: Vec::new(),
        });
        self.end = t_end;
        self.bound = bound;
        self.slide_rows.extend(rows);
        Ok(())
    }
}

/// A row as a sample.
fn sample_of(r: &csv::Record) -> Sample {
    let n = r.numbers;
    Sample {
        t: n[0],
        x: n[1],
        y: n[2],
        theta: n[3],
        omega: n[4],
    }
}

impl Stepping {
    /// Reads an advance's answer for `push` (already in `applied`), or the
    /// release's.
    fn absorb(&mut self, a: Answer, push: Span) -> Result<(), ModelError> {
        let engine = Arc::clone(&self.engine);
        self.failed = true;
        self.process_time += a.elapsed;
        self.output_bytes += a.stdout.len();
        self.requests.push(a.request);
        let parse = Instant::now();
        let text = std::str::from_utf8(&a.stdout).map_err(|e| {
            engine.fail(
                format!(
                    "wrote an answer to request {} that is not UTF-8 ({e})",
                    a.request
                ),
                &a.stderr(),
            )
        })?;
        self.read(text, a.request, push)
            .map_err(|e| engine.fail(e, &a.stderr()))?;
        self.parse_time += parse.elapsed();
        self.failed = false;
        Ok(())
    }

    /// Reads the finish's answer and returns the run.
    fn close(mut self, a: Answer) -> Result<EngineRun, ModelError> {
        let engine = Arc::clone(&self.engine);
        if !a.stdout.iter().all(u8::is_ascii_whitespace) {
            return Err(engine.fail(
                format!(
                    "wrote {} bytes before `#end {}` in its answer to request {} (finish), which holds nothing but that line",
                    a.stdout.len(),
                    a.request,
                    a.request
                ),
                &a.stderr(),
            ));
        }
        self.process_time += a.elapsed;
        self.requests.push(a.request);
        let mut problem = with_pushes(&self.problem, self.applied.clone());
        problem.release = None;
        let parse = Instant::now();
        let mut run = if self.applied.is_empty() {
            // A plate thrown: the run is the slide alone.
            let steps = engine_steps(&self.rows) + engine_steps(&self.slide_rows);
            let mut trajectory = Trajectory {
                model: engine.spec.name.clone(),
                ..Default::default()
            };
            trajectory.stats.steps = steps;
            trajectory.stats.rhs_evals = steps;
            EngineRun {
                trajectory,
                dt: self.dt,
                steps,
                wall_time: Duration::ZERO,
                diagnostics: serde_json::Value::Null,
                contact: None,
            }
        } else {
            problem.check()?;
            engine
                .assemble(&problem, self.dt, &self.rows)
                .map_err(|e| {
                    engine.fail(
                        format!("wrote rows that do not cover the run: {e}"),
                        &a.stderr(),
                    )
                })?
        };
        if let Some(report) = self.slide.take() {
            let release =
                self.rows.last().map(sample_of).ok_or_else(|| {
                    engine.fail("wrote no row before its slide".into(), &a.stderr())
                })?;
            let steps: Vec<Sample> = self.slide_rows.iter().map(sample_of).collect();
            let end = *steps.last().expect("a slide has a row");
            if !self.applied.is_empty() {
                let n = engine_steps(&self.slide_rows);
                run.steps += n;
                run.trajectory.stats.steps += n;
                run.trajectory.stats.rhs_evals += n;
            }
            extend_through_slide(&problem, &mut run.trajectory, release, &steps, end, report);
        } else if self.applied.is_empty() {
            return Err(ModelError::EmptySchedule);
        }
        self.parse_time += parse.elapsed();
        run.wall_time = self.started.elapsed();
        run.diagnostics = serde_json::json!({
            "rows": self.rows.len(),
            "process_wall_time_s": self.process_time.as_secs_f64(),
            "parse_resample_time_s": self.parse_time.as_secs_f64(),
            "input_bytes": serde_json::Value::Null,
            "output_bytes": self.output_bytes,
            "protocol": engine.spec.protocol,
            "rows_asked": engine.spec.rows.as_str(),
            "session": {
                "pid": self.lease.pid(),
                "answered_before": self.answered_before,
                "requests": self.requests,
            },
            "replays": false,
        });
        Ok(run)
    }

    /// An error once a request of this session has failed.
    fn usable(&self) -> Result<(), ModelError> {
        if self.failed {
            return Err(ModelError::Adapter(format!(
                "{}: an earlier request of this stepping session failed (its world is no longer the pushes applied): start a new session",
                self.engine.who()
            )));
        }
        Ok(())
    }
}

impl EngineSession for Stepping {
    fn state(&self) -> EngineState {
        self.state
    }

    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        self.usable()?;
        if self.slide.is_some() {
            return Err(after_release());
        }
        self.failed = true;
        let engine = Arc::clone(&self.engine);
        let (doc, limits) = Self::advance_doc(&self.problem, self.dt, push);
        let timeout = self.timeout();
        let a = self
            .lease
            .request(doc, "advance", Close::End, limits, timeout)
            .map_err(|e| engine.broken(e))?;
        self.applied.push(*push);
        self.absorb(a, Span::Push(push))
    }

    /// The `release` request: the adapter steps its plate free to rest and
    /// answers the slide's rows (see the protocol in
    /// docs/outside-engines.md); an adapter that cannot release answers
    /// `#error`, which is the release's refusal.
    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        self.usable()?;
        if self.slide.is_some() {
            return Err(after_release());
        }
        self.failed = true;
        let engine = Arc::clone(&self.engine);
        let (doc, limits) = Self::release_doc(&self.problem, self.dt, max_duration);
        let timeout = self.timeout();
        let a = self
            .lease
            .request(doc, "release", Close::End, limits, timeout)
            .map_err(|e| engine.refused(e))?;
        self.absorb(a, Span::Release(max_duration))
    }

    fn slide(&self) -> Option<SlideReport> {
        self.slide.clone()
    }

    fn finish(mut self: Box<Self>) -> Result<EngineRun, ModelError> {
        self.usable()?;
        let engine = Arc::clone(&self.engine);
        let timeout = self.timeout();
        let a = self
            .lease
            .request(
                Self::finish_doc(),
                "finish",
                Close::End,
                Self::SMALL,
                timeout,
            )
            .map_err(|e| engine.broken(e))?;
        self.close(a)
    }

    fn steps_taken(&self) -> usize {
        engine_steps(&self.rows)
    }
}

/// The engine steps `rows` took: their `steps` column where they have one
/// (rows at the sample times), else one a row after the first.
fn engine_steps(rows: &[csv::Record]) -> usize {
    rows.iter()
        .skip(1)
        .map(|r| r.steps.map_or(1, |n| n.round().max(0.0) as usize))
        .sum()
}

/// The contact record of an engine's rows where they carry `load_i`
/// columns: each row after the first is a step ending at its `t`.
pub fn contact_from_rows(problem: &Problem, rows: &[csv::Record]) -> Option<ContactRecord> {
    let mut recorder = LoadRecorder::new(problem, problem.body.len(), pushval_engine::GRAVITY);
    for pair in rows.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        recorder.step(
            b.numbers[0],
            b.numbers[0] - a.numbers[0],
            b.loads.as_deref(),
            b.rise,
        );
    }
    recorder.finish()
}

/// An outside engine's rows (`t, x, y, theta, omega`) as a step history for
/// the shared resampler: the first row is the state at t = 0, each further
/// row the end of one step whose ω is the one the engine held over it (a
/// semi-implicit Euler engine's ω after the step; for rows per sample, the
/// sample's ω). A step belongs to the segment holding its middle. The rows
/// must start at t = 0, increase strictly and reach the problem's end.
pub fn history_from_rows(
    problem: &Problem,
    rows: &[csv::Record],
) -> Result<Vec<StepRecord>, String> {
    let end = problem.duration();
    let tol = 1e-9 * end.max(1.0);
    let times = problem.segment_times();
    let Some(first) = rows.first() else {
        return Err("a header and no rows".into());
    };
    if first.numbers[0].abs() > tol {
        return Err(format!(
            "line {}: the first row is at t = {} s, not at 0",
            first.line, first.numbers[0]
        ));
    }
    let segment_of = |t: f64| {
        times
            .iter()
            .position(|&(_, t1)| t < t1 - tol)
            .unwrap_or(times.len() - 1)
    };
    let mut history = Vec::with_capacity(rows.len());
    let r = &first.numbers;
    history.push(StepRecord {
        segment: 0,
        t0: 0.0,
        t1: 0.0,
        x: r[1],
        y: r[2],
        theta: r[3],
        omega: r[4],
    });
    let mut t_prev = 0.0;
    for row in &rows[1..] {
        let r = &row.numbers;
        if !(r[0] > t_prev) {
            return Err(format!(
                "line {}: column `t`: {} s does not increase (the row before is at {} s)",
                row.line, r[0], t_prev
            ));
        }
        history.push(StepRecord {
            segment: segment_of(0.5 * (t_prev + r[0])),
            t0: t_prev,
            t1: r[0],
            x: r[1],
            y: r[2],
            theta: r[3],
            omega: r[4],
        });
        t_prev = r[0];
    }
    if t_prev < end - 1e-6 * end.max(1.0) {
        return Err(format!(
            "the last row (line {}) is at t = {t_prev} s, before the end of the problem at {end} s",
            rows[rows.len() - 1].line
        ));
    }
    Ok(history)
}
