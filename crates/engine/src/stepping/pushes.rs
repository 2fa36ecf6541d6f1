//! The loop one push at a time ([`Stepping::advance`]) and its end
//! ([`Stepping::finish`]).

use pushval_model::{ModelError, Problem, Push};

use super::slide::SlideOut;
use super::{
    Plate, PlateStep, PlateWorld, StepClock, StepLayout, StepLoop, StepPlan, Stepped, TailSteps,
    TailWeight, TAIL,
};
use crate::contact::LoadRecorder;

/// What the run tails need of one step, kept until [`Stepping::finish`]
/// (the run's last fifth depends on the pushes still to come).
#[derive(Debug, Clone)]
pub(super) struct StepLog {
    t0: f64,
    t1: f64,
    h: f64,
    rise: f64,
    in_tail: bool,
    normal: Option<Vec<f64>>,
}

/// The loop one push at a time: the world keeps its state
/// between pushes, so the caller decides the next push from the state the
/// last one left (see the module docs for what a push does).
///
/// The problem given to [`Stepping::new`] is the start's; its schedule is
/// never read (a step depends on the pushes applied, not on any announced
/// after them). What depends on the whole run (the run's last fifth, the
/// per-sample loads) is gathered at [`Stepping::finish`], on the pushes
/// applied.
pub struct Stepping<W: PlateWorld> {
    pub(super) world: W,
    pub(super) problem: Problem,
    pub(super) cfg: StepLoop,
    pub(super) state: W::State,
    pub(super) out: Stepped,
    pub(super) log: Vec<StepLog>,
    pub(super) applied: Vec<Push>,
    pub(super) t_seg: f64,
    pub(super) slide: Option<SlideOut>,
}

impl<W: PlateWorld> Stepping<W> {
    /// The loop over `world`, whose object is in `start` (set up, settled and
    /// given its start velocity by the engine), for `problem` (the start's:
    /// see the type's docs).
    pub fn new(world: W, problem: &Problem, cfg: StepLoop, start: W::State) -> Self {
        let mut out = Stepped {
            min_loads: vec![f64::INFINITY; cfg.supports],
            ..Default::default()
        };
        out.history
            .push(PlateStep::new(0, 0.0, 0.0, &world.plate(&start)));
        Self {
            world,
            problem: problem.clone(),
            cfg,
            state: start,
            out,
            log: Vec::new(),
            applied: Vec::new(),
            t_seg: 0.0,
            slide: None,
        }
    }

    /// The world.
    pub fn world(&self) -> &W {
        &self.world
    }

    /// The object as the world last read it.
    pub fn state(&self) -> &W::State {
        &self.state
    }

    /// The pushes applied so far.
    pub fn applied(&self) -> &[Push] {
        &self.applied
    }

    /// Time at the end of the pushes applied so far (s).
    pub fn time(&self) -> f64 {
        self.t_seg
    }

    /// Engine steps taken so far.
    pub fn steps(&self) -> usize {
        self.out.steps
    }

    /// The start's problem with the pushes applied as its schedule.
    pub fn applied_problem(&self) -> Problem {
        crate::session::with_pushes(&self.problem, self.applied.clone())
    }

    /// The object's state for a session: pose and ω from
    /// [`PlateWorld::plate`], the centre of mass's velocity from
    /// [`PlateWorld::cm_velocity`], else the one a rigid contact moving with
    /// the last push gives.
    pub fn engine_state(&self) -> crate::EngineState {
        if let Some(slide) = &self.slide {
            return slide.end;
        }
        let p = self.world.plate(&self.state);
        let v_cm = self.world.cm_velocity(&self.state).unwrap_or_else(|| {
            crate::rigid_cm_velocity(&self.problem, self.applied.last(), p.theta, p.omega)
        });
        crate::EngineState {
            t: self.t_seg,
            x: p.x,
            y: p.y,
            theta: p.theta,
            omega: p.omega,
            v_cm,
        }
    }

    /// Runs one push (see the module docs).
    pub fn advance(&mut self, push: &Push) -> Result<(), ModelError> {
        if self.slide.is_some() {
            return Err(crate::after_release());
        }
        let j = self.applied.len();
        let cfg = self.cfg;
        let n_sup = cfg.supports;
        let t_seg = self.t_seg;
        let n = (push.duration / cfg.dt * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let nominal_h = push.duration / n as f64;
        let layout = self.world.segment_steps(push, n, nominal_h);
        let n_steps = match &layout {
            None => n,
            Some(StepLayout::Lengths(l)) => l.len(),
            Some(StepLayout::Spans(s)) => s.len(),
        };
        let tail_from = match cfg.tail {
            TailSteps::Floor => ((1.0 - TAIL) * n_steps as f64).floor() as usize,
            TailSteps::LastFifth | TailSteps::ByTime => n_steps - (n_steps / 5).max(1),
        };
        // A tail by time: the steps whose middle is in the segment's last
        // fifth (of its duration, back from the end of its last step).
        let seg_end = match &layout {
            Some(StepLayout::Spans(s)) => s.last().map_or(t_seg, |s| s.1),
            _ => t_seg + push.duration,
        };
        let tail_time = seg_end - TAIL * push.duration;
        let (mut acc_w, mut acc_w2, mut acc_t) = (0.0, 0.0, 0.0);
        let mut acc_n = vec![0.0; n_sup];
        let mut acc_f = vec![0.0; n_sup];
        let mut min_slip = vec![f64::INFINITY; n_sup];
        let mut t_prev = t_seg;
        for k in 0..n_steps {
            let (t0, t1, h) = match &layout {
                None => {
                    let t0 = t_seg + k as f64 * nominal_h;
                    let t1 = if k + 1 == n {
                        t_seg + push.duration
                    } else {
                        match cfg.clock {
                            StepClock::FromStepStart => t0 + nominal_h,
                            StepClock::FromSegmentStart => t_seg + (k + 1) as f64 * nominal_h,
                        }
                    };
                    (t0, t1, nominal_h)
                }
                Some(StepLayout::Spans(spans)) => {
                    let (t0, t1) = spans[k];
                    (t0, t1, t1 - t0)
                }
                Some(StepLayout::Lengths(lengths)) => {
                    let t0 = t_prev;
                    let t1 = if k + 1 == n_steps {
                        t_seg + push.duration
                    } else {
                        t0 + lengths[k]
                    };
                    (t0, t1, t1 - t0)
                }
            };
            t_prev = t1;
            let w = match cfg.tail_weight {
                TailWeight::Time => h,
                TailWeight::Steps => 1.0,
            };
            let plan = StepPlan {
                segment: j,
                index: k,
                steps: n_steps,
                t0,
                t1,
                h,
                nominal_h,
                push: *push,
            };
            let drift = self.world.drive_step(&self.state, &plan);
            if k > 0 || j > 0 {
                self.out.max_joint_drift = self.out.max_joint_drift.max(drift);
            }
            let p = self.step(h, t1)?;
            let in_tail = match cfg.tail {
                TailSteps::ByTime => 0.5 * (t0 + t1) >= tail_time,
                _ => k >= tail_from,
            };
            // Forces are read on every step (for the per-sample loads); the
            // run tail and the smallest loads are taken at `finish`.
            let forces = self.world.support_forces(&self.state, h)?;
            if in_tail {
                acc_w += p.omega * w;
                acc_w2 += p.omega * p.omega * w;
                acc_t += w;
                if let Some(f) = &forces {
                    for (a, &l) in acc_n.iter_mut().zip(&f.normal) {
                        *a += l * w;
                    }
                    if let Some(fr) = &f.friction {
                        for (a, &l) in acc_f.iter_mut().zip(fr) {
                            *a += l * w;
                        }
                    }
                }
                for (i, m) in min_slip.iter_mut().enumerate() {
                    if let Some(u) = self.world.slip(&self.state, i) {
                        *m = m.min(u);
                    }
                }
                self.world.tail_step(&self.state, h)?;
            }
            self.log.push(StepLog {
                t0,
                t1,
                h,
                rise: p.z - cfg.z_rest,
                in_tail,
                normal: forces.map(|f| f.normal),
            });
            self.out.history.push(PlateStep::new(j, t0, t1, &p));
        }
        let out = &mut self.out;
        // Only a tail by time can be empty (the others hold a step at least).
        let acc_t = if acc_t > 0.0 {
            acc_t
        } else {
            f64::MIN_POSITIVE
        };
        let mean = acc_w / acc_t;
        out.segment_tail_omega.push(mean);
        out.segment_tail_omega_std
            .push((acc_w2 / acc_t - mean * mean).max(0.0).sqrt());
        out.segment_tail_loads
            .push(acc_n.iter().map(|a| a / acc_t).collect());
        out.segment_tail_friction
            .push(acc_f.iter().map(|a| a / acc_t).collect());
        out.segment_tail_min_slip.push(min_slip);
        self.t_seg += push.duration;
        self.applied.push(*push);
        self.world.end_segment(acc_t, self.t_seg)
    }

    /// One engine step of length `h` (s) ending at `t1`, of a push or of
    /// the slide: the step, the state read and checked, the largest tilt
    /// and lift; the object after it.
    pub(super) fn step(&mut self, h: f64, t1: f64) -> Result<Plate, ModelError> {
        self.world.step(h, t1)?;
        self.out.steps += 1;
        self.state = self.world.state(&self.state);
        if !self.world.finite(&self.state) {
            return Err(ModelError::NonFinite {
                t: t1,
                step: self.out.steps,
            });
        }
        self.world.after_step(&self.state);
        let p = self.world.plate(&self.state);
        self.out.max_tilt = self.out.max_tilt.max(p.tilt);
        self.out.max_lift = self.out.max_lift.max((p.z - self.cfg.z_rest).abs());
        Ok(p)
    }

    /// Ends the loop: the world, what the loop gathered (the run's last fifth
    /// and the per-sample loads over the pushes applied), and the start's
    /// problem with the pushes applied as its schedule (the one to resample
    /// on).
    pub fn finish(self) -> (W, Stepped, Problem) {
        let problem = self.applied_problem();
        let cfg = self.cfg;
        let mut out = self.out;
        // The run's last fifth (steps whose middle is past it), time-weighted.
        let run_from = (1.0 - TAIL) * problem.duration();
        let (mut run_n, mut run_t) = (vec![0.0; cfg.supports], 0.0);
        let mut recorder = LoadRecorder::new(&problem, cfg.supports, pushval_laws::GRAVITY);
        for s in &self.log {
            let in_run_tail = match cfg.clock {
                StepClock::FromStepStart => 0.5 * (s.t0 + s.t1) >= run_from,
                StepClock::FromSegmentStart => s.t1 - 0.5 * s.h >= run_from,
            };
            recorder.step(s.t1, s.h, s.normal.as_deref(), Some(s.rise));
            if let Some(normal) = &s.normal {
                // The smallest loads are taken where the world asks for them.
                if cfg.forces_every_step || s.in_tail || in_run_tail {
                    for (m, &l) in out.min_loads.iter_mut().zip(normal) {
                        *m = m.min(l);
                    }
                }
                if in_run_tail {
                    for (a, &l) in run_n.iter_mut().zip(normal) {
                        *a += l * s.h;
                    }
                    run_t += s.h;
                }
            }
        }
        // No step in the run's last fifth (a plate thrown without pushes):
        // no mean, NaN (null in the diagnostics).
        out.loads = run_n
            .iter()
            .map(|a| if run_t > 0.0 { a / run_t } else { f64::NAN })
            .collect();
        out.contact = recorder.finish();
        (self.world, out, problem)
    }
}
