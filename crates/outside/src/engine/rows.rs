//! An outside engine's rows as what the engine crate reads: samples, a
//! step history, a contact record, a count of steps.

use pushval_engine::{ContactRecord, LoadRecorder, StepRecord};
use pushval_model::{Problem, Sample};

use crate::csv;

/// A row as a sample.
pub(super) fn sample_of(r: &csv::Record) -> Sample {
    let n = r.numbers;
    Sample {
        t: n[0],
        x: n[1],
        y: n[2],
        theta: n[3],
        omega: n[4],
    }
}

/// The engine steps `rows` took: their `steps` column where they have one
/// (rows at the sample times), else one a row after the first.
pub(super) fn engine_steps(rows: &[csv::Record]) -> usize {
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
