//! A protocol 3 session ([`Stepping`]): the adapter keeps its world
//! between pushes; the requests it writes and how it closes.

use std::sync::Arc;
use std::time::{Duration, Instant};

use pushval_engine::{
    after_release, extend_through_slide, with_pushes, EngineRun, EngineSession, EngineState,
};
use pushval_model::{ModelError, Problem, Push, Sample, SlideReport, Trajectory};

use super::rows::{engine_steps, sample_of};
use super::OutsideEngine;
use crate::check::Bound;
use crate::csv;
use crate::document::problem_document_v2;
use crate::limits::{Limits, HEADER_BYTES};
use crate::process::ProcessError;
use crate::session::{Answer, Close, Lease};

/// A protocol 3 session: the adapter keeps its world between pushes. It
/// owns a share of its engine.
pub(super) struct Stepping {
    pub(super) engine: Arc<OutsideEngine>,
    /// The problem at `start` (its schedule replaced by the pushes applied).
    pub(super) problem: Problem,
    pub(super) dt: f64,
    pub(super) lease: Lease,
    pub(super) applied: Vec<Push>,
    /// The header line, once the first advance has given it.
    pub(super) header: Option<String>,
    /// Where compact rows put their numbers (from `header`), once read.
    pub(super) columns: Option<csv::Columns>,
    /// The end of the pushes applied (s), summed in order as
    /// [`Problem::segment_times`] sums it.
    pub(super) end: f64,
    /// The largest motion between two rows the pushes applied allow.
    pub(super) bound: Bound,
    pub(super) rows: Vec<csv::Record>,
    pub(super) state: EngineState,
    pub(super) started: Instant,
    pub(super) process_time: Duration,
    pub(super) parse_time: Duration,
    pub(super) output_bytes: usize,
    /// The request number of each answer, for messages.
    pub(super) requests: Vec<u64>,
    pub(super) answered_before: u64,
    /// Set once a request failed: the adapter's world is no longer the
    /// pushes applied, so the session takes no further request.
    pub(super) failed: bool,
    /// The slide's rows after the release (the rows of `rows` end at the
    /// release).
    pub(super) slide_rows: Vec<csv::Record>,
    /// What the release found, once released.
    pub(super) slide: Option<SlideReport>,
}

/// What an answer's rows cover: a push, or the slide after the release
/// (its `max_duration`, s).
#[derive(Clone, Copy)]
pub(super) enum Span<'a> {
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

    pub(super) fn start(
        engine: Arc<OutsideEngine>,
        problem: &Problem,
        dt: f64,
    ) -> Result<Self, ModelError> {
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
    pub(super) fn run(
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
