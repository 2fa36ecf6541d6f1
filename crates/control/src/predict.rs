//! Predictors: what a plan and the loop believe the plate will do.
//!
//! A [`Predictor`] gives the final pose of a push schedule from a start
//! state (the one call the planner makes, many times), the trajectory of a
//! schedule (for checks and figures), and the scene it predicts on, which a
//! caller may replace (a predictor on estimated parameters). The three
//! models of `pushval_model` are predictors through [`ModelPredictor`].

use pushval_model::{
    cross, Body, DynamicModel, Initial, Integrator, ModelError, Problem, Push, PushCache,
    Simulator, Switching, Trajectory, Vec2,
};

use crate::At;

/// Which of pushval's models predicts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash, PartialOrd, Ord)]
pub enum ModelKind {
    /// The dynamic model (inertia, impulsive switches).
    #[default]
    Dynamic,
    /// The quasi-static kinematic model (ω constant per push).
    Kinematic,
    /// The ellipsoidal limit-surface model (ω constant per push).
    LimitSurface,
}

impl ModelKind {
    /// Every model, in order.
    pub const ALL: [ModelKind; 3] = [
        ModelKind::Dynamic,
        ModelKind::Kinematic,
        ModelKind::LimitSurface,
    ];

    /// The model's name in outputs.
    pub fn as_str(&self) -> &'static str {
        match self {
            ModelKind::Dynamic => "dynamic",
            ModelKind::Kinematic => "kinematic",
            ModelKind::LimitSurface => "limit_surface",
        }
    }

    /// The model named `name` ([`ModelKind::as_str`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.as_str() == name)
    }
}

/// The state a plan starts from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// Object angle (rad).
    pub theta: f64,
    /// World position of the centre of mass (m).
    pub position: Vec2,
    /// How it moves when the plan starts.
    pub motion: Motion,
}

/// How the object moves when a plan starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// At rest: the first push is a switch from rest.
    Rest,
    /// Moving: ω (rad/s) and the angular momentum about the world point
    /// under the contact (kg m²/s), which an impulsive switch keeps.
    Moving {
        /// Angular velocity just before the plan's first push (rad/s).
        omega: f64,
        /// `I_cm ω + m (r_cm − r_P) × v_cm` (kg m²/s).
        momentum: f64,
    },
}

impl Start {
    /// The problem's own start.
    pub fn of_problem(problem: &Problem) -> Self {
        let i = &problem.initial;
        Self {
            theta: i.theta,
            position: i.position,
            motion: if i.from_rest {
                Motion::Rest
            } else {
                Motion::Moving {
                    omega: i.omega,
                    momentum: f64::NAN,
                }
            },
        }
    }
}

/// What a plan and the loop believe: final poses of push schedules.
///
/// `Send`, so that a loop holding one can move to another thread; cloned
/// through [`Predictor::box_clone`] (a planner is cloned per goal).
pub trait Predictor: Send {
    /// The predictor's name in outputs (`dynamic`, `kinematic`,
    /// `limit_surface`, or one of them on estimated parameters).
    fn name(&self) -> &str;
    /// The scene it predicts on: body, contact, switching rule (the
    /// schedule and start are the caller's).
    fn problem(&self) -> &Problem;
    /// Replaces the body it predicts with (a scene on estimated parameters).
    fn set_body(&mut self, body: Body);
    /// The final pose (x (m), y (m), θ (rad)) of `pushes` from `start`.
    fn final_pose(&mut self, start: &Start, pushes: &[Push]) -> Result<[f64; 3], ModelError>;
    /// The trajectory of `pushes` from `start`, sampled every `sample_dt` s.
    fn trajectory(
        &self,
        start: &Start,
        pushes: &[Push],
        sample_dt: f64,
    ) -> Result<Trajectory, ModelError>;
    /// Model runs so far (the cost of the calls made).
    fn runs(&self) -> usize;
    /// A boxed copy.
    fn box_clone(&self) -> Box<dyn Predictor>;
}

impl Clone for Box<dyn Predictor> {
    fn clone(&self) -> Self {
        self.box_clone()
    }
}

/// One of pushval's models as a predictor: the model, a working copy of the
/// problem (only its schedule and start change between calls), the count
/// of model runs, and the dynamic model's analysis of the pushes it has
/// seen (a plan's calls share most pushes: a finite-difference Jacobian
/// changes one direction at a time, a re-plan starts from the last plan's).
#[derive(Clone)]
pub struct ModelPredictor {
    problem: Problem,
    model: DynamicModel,
    kind: ModelKind,
    runs: usize,
    cache: PushCache,
}

impl ModelPredictor {
    /// `kind` on `problem`'s body, contact and switching rule.
    pub fn new(problem: &Problem, kind: ModelKind) -> Self {
        Self {
            problem: problem.clone(),
            // 1e-9 per step: the pose it predicts is good to well under a
            // millimetre, far inside any goal tolerance, at a third of the
            // cost of the default 1e-10.
            model: DynamicModel {
                integrator: Integrator::Dop853 { tol: 1e-9 },
                skip_settled: true,
                check_assumptions: false,
                ..DynamicModel::default()
            },
            kind,
            runs: 0,
            cache: PushCache::new(),
        }
    }

    /// Which model it runs.
    pub fn kind(&self) -> ModelKind {
        self.kind
    }

    /// The predictor judged `at` the release or at rest. At rest the
    /// dynamic model slides on after the last push until the plate stops
    /// (the scene's own `[release]`, else 10 s at most); the quasi-static
    /// models do not slide: in them the plate stops when the pusher does,
    /// so their rest is their release pose.
    pub fn judged_at(mut self, at: At) -> Self {
        self.problem.release = match (at, self.kind) {
            (At::Rest, ModelKind::Dynamic) => Some(self.problem.release.unwrap_or_default()),
            _ => None,
        };
        self
    }

    /// The problem of `pushes` from `start`, sampled at its start and end
    /// only (or every `sample_dt` s when given).
    pub fn problem_of(&self, start: &Start, pushes: &[Push], sample_dt: Option<f64>) -> Problem {
        problem_of(&self.problem, start, pushes, sample_dt)
    }

    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError> {
        simulate(self.kind, &self.model, problem)
    }
}

/// `problem` run by the model of `kind` (`model` for the dynamic one).
fn simulate(
    kind: ModelKind,
    model: &DynamicModel,
    problem: &Problem,
) -> Result<Trajectory, ModelError> {
    match kind {
        ModelKind::Dynamic => model.simulate(problem),
        ModelKind::Kinematic => pushval_model::KinematicModel.simulate(problem),
        ModelKind::LimitSurface => pushval_model::LimitSurfaceModel.simulate(problem),
    }
}

impl Predictor for ModelPredictor {
    fn name(&self) -> &str {
        self.kind.as_str()
    }

    fn problem(&self) -> &Problem {
        &self.problem
    }

    fn set_body(&mut self, body: Body) {
        self.problem.body = body;
    }

    fn final_pose(&mut self, start: &Start, pushes: &[Push]) -> Result<[f64; 3], ModelError> {
        set_start(&mut self.problem, start, pushes, None);
        let p = &self.problem;
        // The dynamic model's end state alone (no samples; through the
        // slide when judged at rest; the pushes' analysis kept); the
        // quasi-static ones sample their closed-form arcs at the end.
        let out = match self.kind {
            ModelKind::Dynamic => self
                .model
                .final_state_cached(p, &mut self.cache)
                .map(|f| [f.t, f.x, f.y, f.theta]),
            _ => simulate(self.kind, &self.model, p).and_then(|tr| {
                tr.samples
                    .last()
                    .map(|s| [s.t, s.x, s.y, s.theta])
                    .ok_or(ModelError::EmptySchedule)
            }),
        };
        self.runs += 1;
        let [t, x, y, theta] = out?;
        if !(x.is_finite() && y.is_finite() && theta.is_finite()) {
            return Err(ModelError::NonFinite { t, step: 0 });
        }
        Ok([x, y, theta])
    }

    fn trajectory(
        &self,
        start: &Start,
        pushes: &[Push],
        sample_dt: f64,
    ) -> Result<Trajectory, ModelError> {
        self.simulate(&self.problem_of(start, pushes, Some(sample_dt)))
    }

    fn runs(&self) -> usize {
        self.runs
    }

    fn box_clone(&self) -> Box<dyn Predictor> {
        Box::new(self.clone())
    }
}

/// `scene` with `pushes` as its schedule from `start`, sampled at its start
/// and end only (or every `sample_dt` s when given).
pub fn problem_of(
    scene: &Problem,
    start: &Start,
    pushes: &[Push],
    sample_dt: Option<f64>,
) -> Problem {
    let mut p = scene.clone();
    set_start(&mut p, start, pushes, sample_dt);
    p
}

fn set_start(p: &mut Problem, start: &Start, pushes: &[Push], sample_dt: Option<f64>) {
    p.pushes.clear();
    p.pushes.extend_from_slice(pushes);
    let total: f64 = pushes.iter().map(|q| q.duration).sum();
    p.sample_dt = sample_dt.unwrap_or(total);
    p.initial = match start.motion {
        Motion::Rest => Initial {
            theta: start.theta,
            omega: 0.0,
            position: start.position,
            from_rest: true,
            velocity: Vec2::zeros(),
        },
        Motion::Moving { omega, momentum } => {
            let first = &pushes[0];
            let w = match p.switching {
                Switching::Impulsive if momentum.is_finite() => {
                    let body = &p.body;
                    (momentum + body.mass() * cross(&body.contact(), &first.velocity()))
                        / body.inertia_contact()
                }
                _ => omega,
            };
            Initial {
                theta: start.theta,
                omega: w,
                position: start.position,
                from_rest: false,
                velocity: Vec2::zeros(),
            }
        }
    };
}
