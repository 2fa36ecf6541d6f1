//! Steps on Avian's clock.
//!
//! Avian advances time by [`Duration`]s, whole nanoseconds, and divides a
//! step into its substeps the same way. So the adapter plans steps in
//! *ticks* of `substeps` nanoseconds: a step of whole ticks splits into
//! substeps of whole nanoseconds, and the time the engine integrates is
//! exactly the time recorded. A segment `[t_a, t_b]` becomes the ticks
//! `[round(t_a / tick), round(t_b / tick)]`, cut into `n` steps whose
//! boundaries are `a + ⌊k (b − a) / n⌋`: the last one is the switch time, and
//! step lengths differ by at most one tick. Switch times that are multiples
//! of the tick (every time in whole microseconds, for a power-of-two
//! substep count up to 64) are hit exactly; others within half a tick.

use std::time::Duration;

/// Ticks of `substeps` nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Clock {
    tick_ns: u64,
}

impl Clock {
    /// The clock for `substeps` (≥ 1) substeps per step.
    pub fn new(substeps: u32) -> Self {
        Self {
            tick_ns: u64::from(substeps.max(1)),
        }
    }

    /// The tick nearest to `t` (s, ≥ 0).
    pub fn ticks(&self, t: f64) -> u64 {
        (t * 1e9 / self.tick_ns as f64).round() as u64
    }

    /// The time of tick `k` (s).
    pub fn seconds(&self, k: u64) -> f64 {
        (k * self.tick_ns) as f64 / 1e9
    }

    /// The duration of `k` ticks.
    pub fn duration(&self, k: u64) -> Duration {
        Duration::from_nanos(k * self.tick_ns)
    }

    /// The step boundaries `(start, end)` in ticks of a segment from tick `a`
    /// to tick `b`, cut into `ceil(duration / dt)` steps (at most one per
    /// tick, at least one).
    pub fn steps(&self, a: u64, b: u64, duration: f64, dt: f64) -> Vec<(u64, u64)> {
        let span = b.saturating_sub(a);
        let n = ((duration / dt) * (1.0 - 1e-12)).ceil().max(1.0) as u64;
        let n = n.min(span.max(1));
        (0..n)
            .map(|k| (a + k * span / n, a + (k + 1) * span / n))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 s segment at 1 ms, 16 substeps: 2000 steps of exactly 1 ms
    /// (62 500 ticks of 16 ns), ending on the switch.
    #[test]
    fn whole_steps_land_on_the_switch() {
        let c = Clock::new(16);
        let (a, b) = (c.ticks(2.0), c.ticks(4.0));
        let s = c.steps(a, b, 2.0, 1e-3);
        assert_eq!(s.len(), 2000);
        assert!(s.iter().all(|&(x, y)| y - x == 62_500));
        assert_eq!(s[0].0, a);
        assert_eq!(c.seconds(s.last().unwrap().1), 4.0);
    }

    /// dt = 1/60 s does not divide into ticks: the step lengths differ by at
    /// most one tick, contiguous, and the last one ends on the switch.
    #[test]
    fn uneven_steps_differ_by_one_tick() {
        let c = Clock::new(16);
        let (a, b) = (0, c.ticks(1.0));
        let s = c.steps(a, b, 1.0, 1.0 / 60.0);
        assert_eq!(s.len(), 60);
        let lengths: Vec<u64> = s.iter().map(|&(x, y)| y - x).collect();
        let (lo, hi) = (lengths.iter().min().unwrap(), lengths.iter().max().unwrap());
        assert!(hi - lo <= 1, "{lo} {hi}");
        assert!(s.windows(2).all(|w| w[0].1 == w[1].0));
        assert_eq!(c.seconds(s[59].1), 1.0);
        assert_eq!(c.duration(16).as_nanos(), 256);
    }
}
