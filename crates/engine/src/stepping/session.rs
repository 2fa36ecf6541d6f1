//! An engine's typed session over the loop ([`PlateSession`]).

use pushval_model::{ModelError, Problem, Push, SlideReport, SolverStats, Trajectory};

use super::slide::row;
use super::{PlateWorld, Stepped, Stepping};
use crate::{DetailedRun, DetailedSession};

/// An engine's session over the shared loop: a [`Stepping`] and how the
/// engine turns what it gathered into its record of the run `R`. It owns
/// its world: it is `Send` where the world and its state are.
pub struct PlateSession<W: PlateWorld, R> {
    stepping: Stepping<W>,
    finish: PlateFinish<W, R>,
}

/// How a [`PlateSession`] ends: the world, what the loop gathered and the
/// problem of the pushes applied in, the engine's record of the run out.
/// It owns what it needs (no borrow of the engine).
pub type PlateFinish<W, R> = Box<dyn FnOnce(W, Stepped, &Problem) -> Result<R, ModelError> + Send>;

impl<W: PlateWorld, R> PlateSession<W, R> {
    /// The session of `stepping`, ended by `finish`.
    pub fn new(stepping: Stepping<W>, finish: PlateFinish<W, R>) -> Self {
        Self { stepping, finish }
    }
}

impl<W: PlateWorld, R: DetailedRun> DetailedSession for PlateSession<W, R> {
    type Run = R;

    fn state(&self) -> crate::EngineState {
        self.stepping.engine_state()
    }
    fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        self.stepping.advance(push)
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
    /// The engine's record of the pushes, its trajectory continued through
    /// the slide when the plate was released
    /// ([`crate::extend_through_slide`]); of a plate thrown without pushes,
    /// the record has the slide alone as its trajectory.
    fn finish(self) -> Result<R, ModelError> {
        let Self {
            mut stepping,
            finish,
        } = self;
        let slide = stepping.slide.take();
        let thrown = stepping.applied.is_empty();
        if thrown && slide.is_none() {
            return Err(ModelError::EmptySchedule);
        }
        let (world, stepped, problem) = stepping.finish();
        let steps = stepped.steps;
        let mut run = finish(world, stepped, &problem)?;
        let Some(slide) = slide else {
            return Ok(run);
        };
        let trajectory = run.trajectory_mut();
        if thrown {
            *trajectory = Trajectory {
                stats: SolverStats {
                    rhs_evals: steps,
                    steps,
                    rejected: 0,
                },
                ..Default::default()
            };
        }
        crate::extend_through_slide(
            &problem,
            trajectory,
            slide.release,
            &slide.steps,
            row(&slide.end),
            slide.report,
        );
        Ok(run)
    }
}
