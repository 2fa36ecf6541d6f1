use crate::{Body, ModelError, Push, Trajectory, Vec2};

/// What happens to ω when the pusher velocity jumps at a switch (or at the start
/// of an object at rest).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Switching {
    /// The contact impulse has no moment about the contact point, so the angular
    /// momentum about it, `H = I_P ω − m v_c (p_c × n_φ)`, is the same just
    /// before and just after the switch: ω jumps. What a rigid body does.
    #[default]
    Impulsive,
    /// ω is continuous across the switch (the seed paper's reading).
    Continuous,
}

/// The state of the object when the first push starts (without pushes: when
/// the free slide starts).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Initial {
    /// Object angle θ (rad).
    pub theta: f64,
    /// Angular velocity ω (rad/s); ignored when `from_rest`.
    pub omega: f64,
    /// World position of the centre of mass (m).
    pub position: Vec2,
    /// The object is at rest when the pusher starts: the start is a switch from
    /// zero velocity (with [`Switching::Impulsive`], ω jumps to the value
    /// `H = 0` gives). When false, the object already moves with the pusher at
    /// ω = `omega` (the seed paper's start).
    pub from_rest: bool,
    /// Velocity of the centre of mass (m/s, world frame); default zero. Only
    /// a problem without pushes may set it (a push prescribes the contact's
    /// velocity): the free slide then starts from it at t = 0.
    pub velocity: Vec2,
}

/// The pusher lets go: after the last push (or at t = 0 without pushes) it
/// withdraws without an impulse, and the plate slides on its supports until
/// it stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Release {
    /// Longest slide (s), > 0; default 10. A plate still moving then is
    /// reported as not stopped, never as at rest.
    pub max_duration: f64,
}

impl Default for Release {
    fn default() -> Self {
        Self { max_duration: 10.0 }
    }
}

/// What the contact can transmit, for the assumption checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactLimits {
    /// Inward unit normals of the polygon edges that meet at the contact
    /// (equal for a contact inside an edge). The pusher pushes when its force
    /// lies within 90° of this normal cone (m, object frame; unit vectors).
    pub normals: (Vec2, Vec2),
    /// Pusher–object friction coefficient; None: contact slip is not checked.
    pub mu: Option<f64>,
    /// Largest force the pusher can apply (N); None: not checked.
    pub max_force: Option<f64>,
}

impl Default for ContactLimits {
    /// No limits and a cone covering every direction (nothing is flagged).
    fn default() -> Self {
        Self {
            normals: (Vec2::zeros(), Vec2::zeros()),
            mu: None,
            max_force: None,
        }
    }
}

impl ContactLimits {
    /// Angle (rad) between `force` and the cone of inward normals: 0 inside it.
    /// With zero normals (unknown geometry) always 0.
    pub fn cone_angle(&self, force: &Vec2) -> f64 {
        let (mut a, mut b) = self.normals;
        if a.norm_squared() == 0.0 || force.norm_squared() == 0.0 {
            return 0.0;
        }
        if crate::cross(&a, &b) < 0.0 {
            std::mem::swap(&mut a, &mut b);
        }
        let inside = crate::cross(&a, force) >= 0.0 && crate::cross(force, &b) >= 0.0;
        if inside && crate::cross(&a, &b) > 0.0 {
            return 0.0;
        }
        let ang = |n: &Vec2| crate::cross(n, force).atan2(n.dot(force)).abs();
        ang(&a).min(ang(&b))
    }
}

/// A complete pushing problem: the body, the input schedule, the start.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// The pushed object, in its own frame (origin at the centre of mass).
    pub body: Body,
    /// Contact geometry and limits for the assumption checks.
    pub limits: ContactLimits,
    /// The piecewise-constant input, in order (at least one, unless
    /// `release` is set).
    pub pushes: Vec<Push>,
    /// The state when the first push starts.
    pub initial: Initial,
    /// What ω does at a switch.
    pub switching: Switching,
    /// Spacing of the output samples (s), > 0.
    pub sample_dt: f64,
    /// The free slide after the last push; None: the run ends with it.
    pub release: Option<Release>,
}

impl Problem {
    /// Side of the seed plate (m).
    pub const SEED_SIDE: f64 = 0.25;
    /// Mass of the seed plate (kg).
    pub const SEED_MASS: f64 = 1.0;
    /// Friction coefficient at each of the seed plate's supports.
    pub const SEED_MU: f64 = 0.5;

    /// The seed plate, released after `pushes`: a uniform square plate of
    /// side [`SEED_SIDE`](Self::SEED_SIDE) = 0.25 m and mass
    /// [`SEED_MASS`](Self::SEED_MASS) = 1 kg (I_cm = m s²/6 = 1/96 kg m²),
    /// its centre of mass at its centre, on four supports at its corners
    /// (±0.125 m, ±0.125 m), each carrying a quarter of its weight at
    /// μ = [`SEED_MU`](Self::SEED_MU) = 0.5 (friction force μ m `gravity` / 4
    /// each, N; `gravity` in m/s²), pushed at the middle of its left side
    /// (contact (−0.125, 0) m from the centre of mass). Impulsive switching,
    /// a sample every 0.01 s, no contact limits, and a release with the
    /// default `max_duration` after the last push (without pushes the plate
    /// is thrown from `initial`). A `gravity` that is not finite and > 0 is
    /// refused (it makes the supports' friction invalid).
    pub fn seed_plate(
        gravity: f64,
        pushes: Vec<Push>,
        initial: Initial,
    ) -> Result<Self, ModelError> {
        ModelError::require_positive("seed plate gravity", gravity)?;
        let a = 0.5 * Self::SEED_SIDE;
        let friction = Self::SEED_MU * Self::SEED_MASS * gravity / 4.0;
        let supports = [(-a, -a), (a, -a), (a, a), (-a, a)].map(|(x, y)| crate::Support {
            position: Vec2::new(x, y),
            friction,
        });
        let inertia = Self::SEED_MASS * Self::SEED_SIDE * Self::SEED_SIDE / 6.0;
        Ok(Self {
            body: Body::new(Self::SEED_MASS, inertia, Vec2::new(-a, 0.0), &supports)?,
            limits: ContactLimits::default(),
            pushes,
            initial,
            switching: Switching::Impulsive,
            sample_dt: 0.01,
            release: Some(Release::default()),
        })
    }

    /// Checks the schedule, the release and the sampling interval. An empty
    /// schedule is a problem only without a release; an initial velocity
    /// only without pushes.
    pub fn check(&self) -> Result<(), ModelError> {
        if self.pushes.is_empty() && self.release.is_none() {
            return Err(ModelError::EmptySchedule);
        }
        if let Some(r) = &self.release {
            ModelError::require_positive("release max_duration", r.max_duration)?;
        }
        let v = self.initial.velocity;
        for c in [v.x, v.y] {
            if !c.is_finite() {
                return Err(ModelError::Parameter {
                    name: "initial velocity",
                    requirement: "finite",
                    value: c,
                });
            }
        }
        if !self.pushes.is_empty() && v != Vec2::zeros() {
            return Err(ModelError::Parameter {
                name: "initial velocity",
                requirement: "zero when there are pushes (the pusher sets the velocity)",
                value: v.norm(),
            });
        }
        for p in &self.pushes {
            if !(p.duration.is_finite() && p.duration > 0.0) {
                return Err(ModelError::Parameter {
                    name: "push duration",
                    requirement: "finite and > 0",
                    value: p.duration,
                });
            }
            if !(p.speed.is_finite() && p.speed >= 0.0) {
                return Err(ModelError::Parameter {
                    name: "push speed",
                    requirement: "finite and >= 0",
                    value: p.speed,
                });
            }
            if !p.phi.is_finite() {
                return Err(ModelError::Parameter {
                    name: "push phi",
                    requirement: "finite",
                    value: p.phi,
                });
            }
        }
        if !(self.sample_dt.is_finite() && self.sample_dt > 0.0) {
            return Err(ModelError::Parameter {
                name: "sample_dt",
                requirement: "finite and > 0",
                value: self.sample_dt,
            });
        }
        Ok(())
    }

    /// Start and end time (s) of every push.
    pub fn segment_times(&self) -> Vec<(f64, f64)> {
        let mut t = 0.0;
        self.pushes
            .iter()
            .map(|p| {
                let t0 = t;
                t += p.duration;
                (t0, t)
            })
            .collect()
    }

    /// Total duration (s).
    pub fn duration(&self) -> f64 {
        self.pushes.iter().map(|p| p.duration).sum()
    }

    /// The output sample times: `k · sample_dt` up to the end (inclusive, within
    /// a relative 1e-9 of a step), plus the end time when it is not on the grid.
    /// With a release these are the pushes' samples only: the slide's go on
    /// on the same grid to its stop ([`Problem::sample_times_through`]).
    pub fn sample_times(&self) -> Vec<f64> {
        self.sample_times_through(self.duration())
    }

    /// The sample grid `k · sample_dt` up to `end` (s, inclusive within a
    /// relative 1e-9 of a step), plus `end` when it is not on the grid.
    pub fn sample_times_through(&self, end: f64) -> Vec<f64> {
        let n = (end / self.sample_dt * (1.0 + 1e-12) + 1e-9).floor() as usize;
        let mut times: Vec<f64> = (0..=n).map(|k| k as f64 * self.sample_dt).collect();
        if let Some(&last) = times.last() {
            if end - last > 1e-9 * self.sample_dt {
                times.push(end);
            } else if let Some(l) = times.last_mut() {
                *l = end;
            }
        }
        times
    }

    /// Angular momentum about the contact point (kg m²/s) of a body turning at
    /// `omega` while its contact point moves with `push` (`H = I_P ω − m v_c (p_c × n_φ)`).
    pub fn contact_momentum(body: &Body, push: Option<&Push>, omega: f64) -> f64 {
        let lin = push
            .map(|p| crate::cross(&body.contact(), &p.velocity()))
            .unwrap_or(0.0);
        body.inertia_contact() * omega - body.mass() * lin
    }

    /// ω just after a switch from `before` (None: at rest) to `after`, given ω
    /// just before.
    pub fn omega_after_switch(
        &self,
        before: Option<&Push>,
        after: &Push,
        omega_before: f64,
    ) -> f64 {
        self.omega_after_switch_at(before.map(Push::velocity), after.velocity(), omega_before)
    }

    /// [`Problem::omega_after_switch`] from the contact velocities
    /// (`None`: at rest) the caller already has (object frame, m/s).
    pub(crate) fn omega_after_switch_at(
        &self,
        before: Option<Vec2>,
        after: Vec2,
        omega_before: f64,
    ) -> f64 {
        match self.switching {
            Switching::Continuous => omega_before,
            Switching::Impulsive => {
                let pc = self.body.contact();
                let lin_before = before.map(|v| crate::cross(&pc, &v)).unwrap_or(0.0);
                let h = self.body.inertia_contact() * omega_before - self.body.mass() * lin_before;
                let lin = self.body.mass() * crate::cross(&pc, &after);
                (h + lin) / self.body.inertia_contact()
            }
        }
    }
}

/// Anything that turns a [`Problem`] into a sampled [`Trajectory`]: the analytic
/// models and every engine adapter answer this one trait, so comparing,
/// benchmarking and sweeping treat them alike.
pub trait Simulator {
    /// The model name used in outputs (`"dynamic"`, `"rapier2d"`, …).
    fn name(&self) -> String;
    /// Runs the problem; the trajectory is sampled at [`Problem::sample_times`].
    fn simulate(&self, problem: &Problem) -> Result<Trajectory, ModelError>;
}
