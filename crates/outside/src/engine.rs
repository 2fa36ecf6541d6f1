//! [`OutsideEngine`]: an engine model that runs as a process.

use std::sync::Arc;
use std::time::{Duration, Instant};

use pushval_engine::{
    trajectory_from_steps, ContactRecord, Engine, EngineCrate, EngineInfo, EngineOptions,
    EngineRun, FrictionLaw, LoadRecorder, OptionKeys, StepRecord,
};
use pushval_model::{ModelError, Problem};

use crate::config::Spec;
use crate::csv;
use crate::document::{problem_document, problem_document_v2};
use crate::limits::Limits;
use crate::process::{last_lines, run_process, ProcessError};
use crate::session;

/// How many lines of a failed process's standard error a message quotes.
const STDERR_LINES: usize = 8;

/// An outside engine with a scenario's `[engine]` options: one process per
/// run (see the crate docs).
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
        let start = Instant::now();
        problem.check()?;
        let limits = Limits::for_problem(problem, dt);
        let doc = if self.spec.protocol >= 2 {
            problem_document_v2(&self.spec.name, problem, &self.options, dt, limits)
        } else {
            problem_document(&self.spec.name, problem, &self.options, dt)
        };
        let mut input = serde_json::to_vec(&doc).expect("a JSON value serialises");
        let timeout = Duration::from_secs_f64(self.spec.timeout_s);
        let broken = |e: ProcessError| {
            ModelError::Adapter(format!(
                "{}: {}; {}",
                self.who(),
                e.what,
                last_lines(&e.stderr, STDERR_LINES)
            ))
        };
        let input_bytes = input.len();
        let (stdout, stderr, process_time, served_by) = if self.spec.session {
            // One document per line (compact JSON holds no line break).
            input.push(b'\n');
            let a = session::answer(&self.spec, input, limits, timeout).map_err(broken)?;
            let about = serde_json::json!({"pid": a.pid, "answered_before": a.answered_before});
            (a.stdout, a.stderr, a.elapsed, Some(about))
        } else {
            let out = run_process(
                &self.spec.program(),
                &self.spec.command[1..],
                &self.spec.dir,
                &input,
                timeout,
                limits,
            )
            .map_err(broken)?;
            if !out.status.success() {
                return Err(broken(ProcessError {
                    what: match out.status.code() {
                        Some(c) => format!("exited with status {c}"),
                        None => format!("was ended by a signal ({})", out.status),
                    },
                    stderr: out.stderr,
                }));
            }
            (out.stdout, out.stderr, out.elapsed, None)
        };
        let fail = |what: String| {
            ModelError::Adapter(format!(
                "{}: {what}; {}",
                self.who(),
                last_lines(&stderr, STDERR_LINES)
            ))
        };
        let parse_start = Instant::now();
        let text = std::str::from_utf8(&stdout)
            .map_err(|e| fail(format!("wrote standard output that is not UTF-8 ({e})")))?;
        let rows = csv::read(text, problem.body.len())
            .map_err(|e| fail(format!("wrote a malformed row on its standard output: {e}")))?;
        let history = history_from_rows(problem, &rows)
            .map_err(|e| fail(format!("wrote rows that do not cover the run: {e}")))?;
        let trajectory = trajectory_from_steps(&self.spec.name, problem, &history);
        let contact = contact_from_rows(problem, &rows);
        let parse_time = parse_start.elapsed();
        Ok(EngineRun {
            trajectory,
            dt,
            steps: history.len() - 1,
            wall_time: start.elapsed(),
            diagnostics: serde_json::json!({
                "rows": rows.len(),
                "process_wall_time_s": process_time.as_secs_f64(),
                "parse_resample_time_s": parse_time.as_secs_f64(),
                "input_bytes": input_bytes,
                "output_bytes": stdout.len(),
                "protocol": self.spec.protocol,
                "session": served_by,
            }),
            contact,
        })
    }
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
