//! Reading a protocol 3 answer's rows into the session: text or compact
//! rows, checked against the push (or the slide) and the rows before.

use pushval_engine::{rigid_cm_velocity, EngineState};
use pushval_model::SlideReport;

use super::stepping::{Span, Stepping};
use crate::check;
use crate::csv;

impl Stepping {
    /// The rows of one advance's answer (`text`: the header first in the
    /// first answer), checked against the rows before.
    pub(super) fn read(&mut self, text: &str, request: u64, push: Span) -> Result<(), String> {
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
