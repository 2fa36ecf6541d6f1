//! The cap on one run's output, from the problem's length.
//!
//! An adapter writes one row per engine step or per sample, so a run of
//! duration T at step dt writes about `T / min(dt, sample_dt)` rows. The cap
//! allows [`ROW_MARGIN`] times that (plus [`ROW_SLACK`] rows: a row per
//! segment boundary, a short problem), and [`BYTES_PER_ROW`] bytes a row
//! (five numbers at full precision take about 125; the rest is room for
//! further columns) plus [`HEADER_BYTES`]. Past either, the process is
//! killed and the run is an error naming the cap; pushval never holds more
//! than the cap of one run's output in memory.

use pushval_model::Problem;

/// How many times the expected row count the cap allows.
pub const ROW_MARGIN: f64 = 4.0;
/// Rows allowed on top of the margin (segment boundaries, short problems).
pub const ROW_SLACK: u64 = 1000;
/// Bytes allowed a row.
pub const BYTES_PER_ROW: u64 = 512;
/// Bytes allowed on top of the rows (the header and its extra columns).
pub const HEADER_BYTES: u64 = 4096;

/// The cap on one run's standard output (one answer, in a session).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Data rows: lines after the header (blank lines count).
    pub max_rows: u64,
    /// Bytes, the header and line ends included.
    pub max_bytes: u64,
}

impl Limits {
    /// The cap of a run of `problem` at step `dt` (s).
    pub fn for_problem(problem: &Problem, dt: f64) -> Self {
        Self::of(
            problem.duration(),
            problem.pushes.len(),
            problem.sample_dt,
            dt,
        )
    }

    /// The cap of one push of `problem`'s lasting `duration` (s) at step
    /// `dt`: [`Limits::for_problem`] of the problem with that push as its
    /// schedule (a protocol 3 advance), without building it.
    pub fn for_push(problem: &Problem, duration: f64, dt: f64) -> Self {
        Self::of(duration, 1, problem.sample_dt, dt)
    }

    fn of(duration: f64, pushes: usize, sample_dt: f64, dt: f64) -> Self {
        let step = if dt.is_finite() && dt > 0.0 {
            dt.min(sample_dt)
        } else {
            sample_dt
        };
        // Saturating: an absurd dt gives a huge cap, never a wrapped one.
        // A whole number of steps stays whole despite rounding (10 / 0.002).
        let expected = (duration / step * (1.0 - 1e-12)).ceil() + 1.0;
        let rows = ((ROW_MARGIN * expected) as u64)
            .saturating_add(ROW_SLACK)
            .saturating_add(pushes as u64);
        Self {
            max_rows: rows,
            max_bytes: rows
                .saturating_mul(BYTES_PER_ROW)
                .saturating_add(HEADER_BYTES),
        }
    }
}

/// Counts one output against its [`Limits`] as it arrives.
#[derive(Debug, Clone)]
pub(crate) struct Meter {
    limits: Limits,
    bytes: u64,
    lines: u64,
}

impl Meter {
    pub(crate) fn new(limits: Limits) -> Self {
        Self {
            limits,
            bytes: 0,
            lines: 0,
        }
    }

    /// Adds `chunk`; an error sentence once the output passes a cap.
    pub(crate) fn add(&mut self, chunk: &[u8]) -> Result<(), String> {
        self.bytes += chunk.len() as u64;
        self.lines += chunk.iter().filter(|&&b| b == b'\n').count() as u64;
        let rows = self.lines.saturating_sub(1);
        if rows > self.limits.max_rows {
            return Err(format!(
                "wrote more than {} rows, this run's output cap (max_rows, {ROW_MARGIN} times the rows the problem's length needs): killed",
                self.limits.max_rows
            ));
        }
        if self.bytes > self.limits.max_bytes {
            return Err(format!(
                "wrote more than {} bytes, this run's output cap (max_bytes, {BYTES_PER_ROW} bytes a row of max_rows): killed",
                self.limits.max_bytes
            ));
        }
        Ok(())
    }
}
