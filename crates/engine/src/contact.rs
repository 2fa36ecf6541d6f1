//! What a run measured at its supports, sample by sample: each support's
//! normal load, how far the object rose above its resting height and how
//! often a support lost contact. The study evaluates an engine's friction
//! law on these loads (`omega_law_run`), so a law is judged on the loads the
//! engine actually had, not on the problem's statics.

use pushval_model::Problem;

/// A support carries no load when its normal force is at most this share of
/// the object's weight `m g`.
pub const LOST_SHARE_OF_WEIGHT: f64 = 1e-6;

/// The per-sample contact record of one run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ContactRecord {
    /// Each support's normal force (N, the problem's support order) at each
    /// of the problem's sample times: the time-weighted mean over the steps
    /// that ended after the previous sample and at or before this one. The
    /// first sample (t = 0) takes the first step's loads; a sample no step
    /// ended at takes the previous one's.
    pub loads: Vec<Vec<f64>>,
    /// Largest rise of the centre of mass above its resting height (m;
    /// negative where it only sank); NaN where the engine gives no height.
    pub max_rise_m: f64,
    /// Share of the steps with loads in which at least one support carried
    /// no load ([`LOST_SHARE_OF_WEIGHT`]).
    pub contact_lost_share: f64,
    /// The smallest and the largest normal force any support carried on any
    /// step (N): the spread of the per-step loads.
    pub load_range: [f64; 2],
}

/// Builds a [`ContactRecord`] from the steps of a run, in time order.
#[derive(Debug, Clone)]
pub struct LoadRecorder {
    times: Vec<f64>,
    supports: usize,
    /// Per sample: Σ N_i h and Σ h.
    acc: Vec<(Vec<f64>, f64)>,
    next: usize,
    threshold: f64,
    steps: usize,
    lost: usize,
    max_rise: f64,
    range: [f64; 2],
}

impl LoadRecorder {
    /// A recorder for `problem`'s sample times and `supports` supports; a
    /// support is lost below [`LOST_SHARE_OF_WEIGHT`] of `m g` with `g`
    /// (m/s²).
    pub fn new(problem: &Problem, supports: usize, g: f64) -> Self {
        let times = problem.sample_times();
        let acc = vec![(vec![0.0; supports], 0.0); times.len()];
        Self {
            times,
            supports,
            acc,
            next: 0,
            threshold: LOST_SHARE_OF_WEIGHT * problem.body.mass() * g,
            steps: 0,
            lost: 0,
            max_rise: f64::NAN,
            range: [f64::INFINITY, f64::NEG_INFINITY],
        }
    }

    /// One step of length `h` (s) ending at `t1` (s) with the supports'
    /// normal forces `normal` (N; ignored unless one per support) and the
    /// rise `rise` (m) of the centre of mass above rest at its end.
    pub fn step(&mut self, t1: f64, h: f64, normal: Option<&[f64]>, rise: Option<f64>) {
        if let Some(r) = rise {
            self.max_rise = if self.max_rise.is_nan() {
                r
            } else {
                self.max_rise.max(r)
            };
        }
        let Some(normal) = normal.filter(|n| n.len() == self.supports) else {
            return;
        };
        self.steps += 1;
        if normal.iter().any(|&n| n <= self.threshold) {
            self.lost += 1;
        }
        for &n in normal {
            self.range = [self.range[0].min(n), self.range[1].max(n)];
        }
        // The sample this step ends in: the first at or after t1 (a step
        // ending within 1e-9 h of a sample time ends at it).
        let tol = 1e-9 * h.max(f64::MIN_POSITIVE);
        while self.next < self.times.len() && self.times[self.next] < t1 - tol {
            self.next += 1;
        }
        let k = self.next.min(self.times.len().saturating_sub(1));
        if let Some((sum, w)) = self.acc.get_mut(k) {
            for (a, &n) in sum.iter_mut().zip(normal) {
                *a += n * h;
            }
            *w += h;
        }
    }

    /// The record; None where no step carried loads.
    pub fn finish(self) -> Option<ContactRecord> {
        if self.steps == 0 {
            return None;
        }
        let mut loads: Vec<Option<Vec<f64>>> = self
            .acc
            .into_iter()
            .map(|(sum, w)| (w > 0.0).then(|| sum.iter().map(|a| a / w).collect()))
            .collect();
        // Samples no step ended at: the next one's loads for the leading
        // ones (t = 0), the previous one's after.
        let first = loads.iter().position(Option::is_some)?;
        let lead = loads[first].clone();
        for l in loads.iter_mut().take(first) {
            *l = lead.clone();
        }
        let mut last = lead;
        for l in loads.iter_mut() {
            match l {
                Some(v) => last = Some(v.clone()),
                None => *l = last.clone(),
            }
        }
        Some(ContactRecord {
            loads: loads.into_iter().map(|l| l.unwrap_or_default()).collect(),
            max_rise_m: self.max_rise,
            contact_lost_share: self.lost as f64 / self.steps as f64,
            load_range: self.range,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushval_model::{Body, Push, Support, Switching, Vec2};

    fn problem(duration: f64, sample_dt: f64) -> Problem {
        let s = [
            Support {
                position: Vec2::new(-0.1, 0.0),
                friction: 1.0,
            },
            Support {
                position: Vec2::new(0.1, 0.0),
                friction: 1.0,
            },
        ];
        Problem {
            body: Body::new(1.0, 0.01, Vec2::new(-0.1, -0.1), &s).unwrap(),
            limits: Default::default(),
            pushes: vec![Push {
                duration,
                speed: 0.1,
                phi: 0.0,
            }],
            initial: Default::default(),
            switching: Switching::Impulsive,
            sample_dt,
            release: None,
        }
    }

    /// Loads that ramp linearly in time, stepped at dt = 1e-3 and sampled
    /// every 1e-2 s: each sample holds the mean over its interval, i.e. the
    /// ramp at the interval's middle step (exact for a linear ramp).
    #[test]
    fn samples_hold_interval_means() {
        let p = problem(0.1, 0.01);
        let mut r = LoadRecorder::new(&p, 2, 9.81);
        let dt = 1e-3;
        for k in 1..=100 {
            let t1 = k as f64 * dt;
            r.step(t1, dt, Some(&[t1, 2.0 - t1]), Some(1e-4 * t1));
        }
        let c = r.finish().unwrap();
        assert_eq!(c.loads.len(), p.sample_times().len());
        // Sample k (t = k/100) holds steps ending at (k−1)/100 + j/1000,
        // j = 1..10: mean t1 = (k − 1)/100 + 0.0055.
        for (k, l) in c.loads.iter().enumerate().skip(1) {
            let mean = (k as f64 - 1.0) / 100.0 + 0.0055;
            assert!((l[0] - mean).abs() < 1e-12, "sample {k}: {l:?}");
            assert!((l[1] - (2.0 - mean)).abs() < 1e-12, "sample {k}: {l:?}");
        }
        // t = 0: no step ended there; it takes the first interval's.
        assert_eq!(c.loads[0], c.loads[1]);
        assert!((c.max_rise_m - 1e-5).abs() < 1e-15);
        assert_eq!(c.contact_lost_share, 0.0);
        assert!((c.load_range[0] - 1e-3).abs() < 1e-15 && c.load_range[1] == 2.0 - 1e-3);
    }

    /// A support with no load in a quarter of the steps; steps longer than
    /// the sample interval leave samples that take the previous loads.
    #[test]
    fn lost_contact_and_sparse_steps() {
        let p = problem(0.1, 0.01);
        let mut r = LoadRecorder::new(&p, 2, 9.81);
        let dt = 0.025;
        for k in 1..=4 {
            let n0 = if k == 2 { 0.0 } else { 1.0 };
            r.step(k as f64 * dt, dt, Some(&[n0, 1.0]), None);
        }
        let c = r.finish().unwrap();
        assert_eq!(c.contact_lost_share, 0.25);
        assert_eq!(c.load_range, [0.0, 1.0]);
        assert!(c.max_rise_m.is_nan());
        // Steps end at 0.025 (sample 3), 0.05 (sample 5), 0.075 (8), 0.1 (10).
        let n0: Vec<f64> = c.loads.iter().map(|l| l[0]).collect();
        assert_eq!(
            n0,
            vec![1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0]
        );
        // No loads at all: no record.
        let mut r = LoadRecorder::new(&p, 2, 9.81);
        r.step(0.1, 0.1, None, Some(0.0));
        assert!(r.finish().is_none());
    }
}
