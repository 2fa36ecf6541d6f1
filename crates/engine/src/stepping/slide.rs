//! The slide after the pusher lets go ([`Stepping::release`]).

use pushval_model::{ModelError, Sample, SlideReport};

use super::{PlateWorld, Stepping};

/// What [`Stepping::release`] gathered: the slide's steps (to the first step
/// of the rest), the rest state (or the state at `max_duration`) and the
/// report.
#[derive(Debug, Clone)]
pub(super) struct SlideOut {
    pub(super) release: Sample,
    pub(super) steps: Vec<Sample>,
    pub(super) end: crate::EngineState,
    pub(super) report: SlideReport,
}

pub(super) fn row(s: &crate::EngineState) -> Sample {
    Sample {
        t: s.t,
        x: s.x,
        y: s.y,
        theta: s.theta,
        omega: s.omega,
    }
}

impl<W: PlateWorld> Stepping<W> {
    /// What the release found (None before it).
    pub fn slide(&self) -> Option<&SlideReport> {
        self.slide.as_ref().map(|s| &s.report)
    }

    /// Lets go ([`crate::EngineSession::release`]): the world removes the
    /// pusher's constraint ([`PlateWorld::release`]; without a push applied
    /// it throws the plate with the problem's `initial.velocity` and ω),
    /// then steps of the loop's `dt` (the last one ending at
    /// `max_duration`), each after [`PlateWorld::slide_step`], until the
    /// plate is at rest by the rule of [`crate::REST_SPEED`] and
    /// [`crate::REST_STEPS`]. The slide's steps are kept apart from the
    /// pushes' (the tails, loads and extremes stay the pushes'; the largest
    /// tilt and lift take the slide's too).
    pub fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        if self.slide.is_some() {
            return Err(crate::after_release());
        }
        let throw = self.applied.is_empty().then(|| {
            let i = &self.problem.initial;
            ([i.velocity.x, i.velocity.y], i.omega)
        });
        self.world.release(&self.state, throw)?;
        self.state = self.world.state(&self.state);
        let t_rel = self.t_seg;
        let mut prev = self.world.plate(&self.state);
        let v0 = self.world.cm_velocity(&self.state).unwrap_or_else(|| {
            if throw.is_some() {
                throw.map_or([0.0, 0.0], |t| t.0)
            } else {
                crate::rigid_cm_velocity(&self.problem, self.applied.last(), prev.theta, prev.omega)
            }
        });
        let start = crate::EngineState {
            t: t_rel,
            x: prev.x,
            y: prev.y,
            theta: prev.theta,
            omega: prev.omega,
            v_cm: v0,
        };
        let h = self.cfg.dt;
        let n = (max_duration / h * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let mut steps = Vec::new();
        let mut last = start;
        let mut rest: Option<(usize, crate::EngineState)> = None;
        let mut held = 0;
        for k in 0..n {
            let t0 = t_rel + k as f64 * h;
            let t1 = if k + 1 == n {
                t_rel + max_duration
            } else {
                t0 + h
            };
            let hk = t1 - t0;
            self.world.slide_step(&self.state, hk);
            let p = self.step(hk, t1)?;
            let v_cm = self
                .world
                .cm_velocity(&self.state)
                .unwrap_or([(p.x - prev.x) / hk, (p.y - prev.y) / hk]);
            prev = p;
            last = crate::EngineState {
                t: t1,
                x: p.x,
                y: p.y,
                theta: p.theta,
                omega: p.omega,
                v_cm,
            };
            steps.push(row(&last));
            if crate::rest_speed(&self.problem, v_cm, p.omega) < crate::REST_SPEED {
                if rest.is_none() {
                    rest = Some((steps.len(), last));
                }
                held += 1;
                if held >= crate::REST_STEPS {
                    break;
                }
            } else {
                rest = None;
                held = 0;
            }
        }
        let (end, t_stop) = match rest.filter(|_| held >= crate::REST_STEPS) {
            Some((k, st)) => {
                steps.truncate(k);
                (st, Some(st.t))
            }
            None => (last, None),
        };
        self.t_seg = end.t;
        self.slide = Some(SlideOut {
            release: row(&start),
            steps,
            end,
            report: SlideReport {
                t_release: t_rel,
                t_stop,
                pivots: Vec::new(),
            },
        });
        Ok(())
    }
}
