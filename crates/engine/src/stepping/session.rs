//! An engine's session over the loop ([`PlateSession`]).

use std::time::Instant;

use pushval_model::{ModelError, Problem, Push, SlideReport, SolverStats, Trajectory};

use super::slide::row;
use super::{PlateWorld, Stepped, Stepping};

/// An engine's session over the shared loop: a [`Stepping`] and how the
/// engine turns what it gathered into its [`EngineRun`](crate::EngineRun).
/// It owns its world: it is `Send` where the world and its state are.
pub struct PlateSession<W: PlateWorld> {
    stepping: Stepping<W>,
    finish: PlateFinish<W>,
    started: Instant,
}

/// How a [`PlateSession`] ends: the world, what the loop gathered and the
/// problem of the pushes applied in, the engine's run out. It owns what it
/// needs (no borrow of the engine).
pub type PlateFinish<W> =
    Box<dyn FnOnce(W, Stepped, &Problem) -> Result<crate::EngineRun, ModelError> + Send>;

impl<W: PlateWorld> PlateSession<W> {
    /// The session of `stepping`, ended by `finish`.
    pub fn new(stepping: Stepping<W>, finish: PlateFinish<W>) -> Self {
        Self {
            stepping,
            finish,
            started: Instant::now(),
        }
    }
}

impl<W: PlateWorld> crate::EngineSession for PlateSession<W> {
    fn state(&self) -> crate::EngineState {
        self.stepping.engine_state()
    }
    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        self.stepping.advance(push)
    }
    /// The engine's run of the pushes, continued through the slide when
    /// the plate was released ([`crate::extend_through_slide`]); a plate
    /// thrown without pushes gives the slide alone (diagnostics: the steps).
    fn finish(self: Box<Self>) -> Result<crate::EngineRun, ModelError> {
        let mut this = *self;
        let slide = this.stepping.slide.take();
        if this.stepping.applied.is_empty() {
            let Some(slide) = slide else {
                return Err(ModelError::EmptySchedule);
            };
            let problem = this.stepping.applied_problem();
            let steps = this.stepping.out.steps;
            let mut trajectory = Trajectory {
                stats: SolverStats {
                    rhs_evals: steps,
                    steps,
                    rejected: 0,
                },
                ..Default::default()
            };
            crate::extend_through_slide(
                &problem,
                &mut trajectory,
                slide.release,
                &slide.steps,
                row(&slide.end),
                slide.report,
            );
            return Ok(crate::EngineRun {
                trajectory,
                dt: this.stepping.cfg.dt,
                steps,
                wall_time: this.started.elapsed(),
                diagnostics: serde_json::json!({ "steps": steps }),
                contact: None,
            });
        }
        let (world, stepped, problem) = this.stepping.finish();
        let mut run = (this.finish)(world, stepped, &problem)?;
        if let Some(slide) = slide {
            crate::extend_through_slide(
                &problem,
                &mut run.trajectory,
                slide.release,
                &slide.steps,
                row(&slide.end),
                slide.report,
            );
        }
        Ok(run)
    }
    fn steps_taken(&self) -> usize {
        self.stepping.steps()
    }
    fn release(&mut self, max_duration: f64) -> Result<(), ModelError> {
        self.stepping.release(max_duration)
    }
    fn slide(&self) -> Option<SlideReport> {
        self.stepping.slide().cloned()
    }
}
