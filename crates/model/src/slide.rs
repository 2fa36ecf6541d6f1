//! The free slide: the pusher has let go and the plate slides on its
//! Coulomb supports until it stops.
//!
//! With `uᵢ = v + ω D rᵢ` the sliding velocity of support i (world frame,
//! `rᵢ` its position relative to the centre of mass) and `fᵢ = μᵢ Nᵢ`:
//!
//! ```text
//! m dv/dt   = −Σ fᵢ uᵢ/|uᵢ|
//! I dω/dt   = −Σ fᵢ rᵢ × uᵢ/|uᵢ|
//! ```
//!
//! # Why ln s is the independent variable
//!
//! Friction forces do not depend on speed, so the right-hand side depends
//! only on the *direction* of the generalised velocity `q = (v, ρω)/s`,
//! `s = |(v, ρω)|`, `ρ = √(I/m)` the radius of gyration. The kinetic energy
//! `½ m s²` falls at the rate `Σ fᵢ |uᵢ| = s P(q)`, so `ds/dt = −P(q)/m`:
//! bounded away from zero (P vanishes only while the plate turns about a
//! single support, a pivot, handled apart). In time the stop is a
//! singularity (q may turn by O(1) in the last instants); in σ = −ln s it is
//! σ → ∞ and the flow is regular: `dq/dσ` is a bounded function of q (plus
//! an O(s²) term from the turning frame), the time and the pose are
//! quadratures `dt/dσ = m s²/(s P)`, `dθ/dσ = ω dt/dσ`, whose integrands fall
//! like e^(−σ) and e^(−2σ). The integration stops once the remaining motion
//! with q frozen — time `m s/P(q)`, displacement `v m s/(2P)` — is below the
//! tolerance, and adds that remainder: the stop time is the integral of
//! dt/dσ, not a threshold crossed late. (Integrating with s itself as the
//! variable lands on s = 0 too, but q(s) behaves like q* + c s^λ there,
//! which no polynomial step follows to 8th order.)
//!
//! The state is `[V_x, V_y, ρω, t, θ, x, y, cos θ, sin θ]` with `V` the
//! centre of mass's velocity in the object frame (the support geometry is
//! fixed there, so the friction sum needs no rotation) and `(cos θ, sin θ)`
//! carried as a state (the world position needs `R(θ)`; integrating it
//! spares a `sin_cos` per stage). The integrator is the crate's DOP853
//! ([`crate::integrate::dop853`]).
//!
//! # Pivots: a support that sticks while the others slide
//!
//! Where `uᵢ = 0` for one support the plate turns about it and the friction
//! there is set-valued: any reaction within `|Rᵢ| ≤ fᵢ`. In q this is an
//! attracting point the direction flow reaches in finite σ when the reaction
//! that keeps the support still fits in its cone; an integrator there
//! chatters. After every step each support about to stop is tested: its
//! sliding velocity's linear prediction gives the σ where it reaches zero,
//! the next step is aimed there, and once it is closer than
//! `SNAP √tol` (in σ) the state is advanced by that much and the support stuck.
//! The pivot is then closed form: `I_p ω̇ = −sgn ω Σ_{j≠i} fⱼ |rⱼ − rᵢ|`
//! (`I_p = I + m |rᵢ|²`), constant deceleration, while the required
//! reaction `Rᵢ = m a_cm − Σ_{j≠i} Fⱼ = A + m ω² rᵢ` (A constant) stays in
//! the cone. It ends at rest, or where `|Rᵢ| = fᵢ` (a quadratic in ω²): the
//! support slips again in the direction `−Rᵢ/|Rᵢ|` (friction is continuous
//! there) and the integration resumes. Each phase is reported
//! ([`PivotPhase`]).
//!
//! # References
//! - Goyal, Ruina & Papadopoulos, "Planar sliding with dry friction",
//!   Wear 143 (1991): translation and rotation stop together.
//! - Farkas, Bartels, Unger & Wolf, "Frictional coupling between sliding and
//!   spinning motion", Phys. Rev. Lett. 90, 248302 (2003): a uniform disc
//!   stops with `v/(Rω)` → 0.653 whatever its start.

use crate::integrate::{dop853, next_step8};
use crate::{perp, rotate, Body, ModelError, Problem, Release, Sample, Trajectory, Vec2};

/// The plate's state in the world frame (SI): time, pose, velocities.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SlideState {
    /// Time (s).
    pub t: f64,
    /// Centre of mass x (m).
    pub x: f64,
    /// Centre of mass y (m).
    pub y: f64,
    /// Object angle (rad, unwrapped).
    pub theta: f64,
    /// Centre of mass velocity x (m/s).
    pub vx: f64,
    /// Centre of mass velocity y (m/s).
    pub vy: f64,
    /// Angular velocity (rad/s).
    pub omega: f64,
}

/// How [`slide_to_rest`] runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlideOptions<'a> {
    /// Per-step error tolerance (m in the position, rad in θ; the time
    /// relative to the slide's duration); default 1e-9, which puts the rest
    /// pose within about 2e-11 m and 4e-11 rad of a converged one (seed,
    /// uneven and pivoting plates; `benches/slide.rs`). The velocities are
    /// held to what the pose and the stop time need (about tol × the
    /// throw's speed), not to their own size: near the stop their direction
    /// needs a far smaller tolerance to be read from samples.
    pub tol: f64,
    /// Longest slide (s) from the start; default 10. A plate still moving
    /// then ends the slide with [`Slide::stop`] None.
    pub max_duration: f64,
    /// Times (s, non-decreasing, none before the start) at which to sample
    /// the state; default none (nothing is allocated for samples). Times
    /// after the stop, or after the start plus `max_duration`, are not
    /// sampled: [`Slide::samples`] then has fewer entries.
    pub sample_times: &'a [f64],
}

impl Default for SlideOptions<'_> {
    fn default() -> Self {
        Self {
            tol: 1e-9,
            max_duration: 10.0,
            sample_times: &[],
        }
    }
}

/// How a pivot phase ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PivotEnd {
    /// The plate stopped while turning about the support.
    Rest,
    /// The reaction the support needed reached its friction limit: it
    /// slips again.
    Slip,
    /// The slide reached its `max_duration` while pivoting.
    MaxDuration,
}

/// A phase where one support stuck and the plate turned about it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PivotPhase {
    /// The support's index in the body.
    pub support: usize,
    /// Start (s).
    pub t_start: f64,
    /// End (s).
    pub t_end: f64,
    /// Largest `|Rᵢ| / fᵢ` over the phase: the required reaction's share of
    /// the support's friction limit (≤ 1 while stuck).
    pub max_load: f64,
    /// How it ended.
    pub end: PivotEnd,
}

/// The result of [`slide_to_rest`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Slide {
    /// The last state: the rest pose (zero velocities) when `stop` is Some,
    /// else the state at the start plus `max_duration`.
    pub end: SlideState,
    /// When the plate stopped (s); None: still moving after `max_duration`.
    pub stop: Option<f64>,
    /// The states at [`SlideOptions::sample_times`] up to the stop (empty,
    /// not allocated, when none were asked for).
    pub samples: Vec<SlideState>,
    /// Every pivot phase, in order (empty when none).
    pub pivots: Vec<PivotPhase>,
    /// Accepted integrator steps.
    pub steps: usize,
    /// Rejected integrator steps.
    pub rejected: usize,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
}

/// What the slide says about the run of a model that continued into it
/// ([`crate::Trajectory::slide`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SlideReport {
    /// When the pusher let go (s).
    pub t_release: f64,
    /// When the plate stopped (s); None: not within `max_duration`.
    pub t_stop: Option<f64>,
    /// The pivot phases of the slide.
    pub pivots: Vec<PivotPhase>,
}

/// Distance in σ = −ln s, as a multiple of √tol, below which a support
/// about to stick is stuck by one explicit (Euler) step: its error, about
/// ½ δ² |y''| with |y''| of the order of the state's own size, is then
/// below a hundredth of the tolerance.
const SNAP: f64 = 0.1;

/// Share of the predicted distance to a pivot that an aimed step covers.
const AIM: f64 = 0.8;

/// Relative slip `|uᵢ|/s` given to a support leaving a pivot, in the
/// direction friction already pulls it (no state has a direction at zero).
/// The slip then grows from this size through a stiff regime (its
/// direction relaxes on a time proportional to |uᵢ|), which the explicit
/// steps follow slowly: a pivot that ends in a slip costs thousands of
/// steps.
const NUDGE: f64 = 1e-12;

/// A support that has just left a pivot.
#[derive(Debug, Clone, Copy)]
struct Escape {
    support: usize,
}

/// Accepted steps before a slide is declared stuck in the integrator.
const MAX_STEPS: usize = 100_000;

/// Pivot phases before a slide is declared chattering.
const MAX_PIVOTS: usize = 1_000;

const M: usize = 9;
type Y = [f64; M];
const VX: usize = 0;
const VY: usize = 1;
const W: usize = 2;
const T: usize = 3;
const TH: usize = 4;
const PX: usize = 5;
const PY: usize = 6;
const EX: usize = 7;
const EY: usize = 8;

/// The body as the slide reads it (borrowed; nothing allocated).
struct Plate<'b> {
    sx: &'b [f64],
    sy: &'b [f64],
    f: &'b [f64],
    mass: f64,
    inertia: f64,
    rho: f64,
    /// 1/m, 1/ρ and ρ/I: the right-hand side multiplies (a division would
    /// sit on the stages' serial chain).
    inv_mass: f64,
    inv_rho: f64,
    rho_over_inertia: f64,
}

/// A pivot about one support at one ω: its deceleration and reaction.
struct PivotDyn {
    /// |ω̇| (rad/s²).
    alpha: f64,
    /// The reaction's constant part `A` (object frame, N): `R = A + m ω² rᵢ`.
    a: Vec2,
    /// The support's friction limit (N), coincident supports included.
    cap: f64,
    /// `rᵢ` (m).
    r: Vec2,
}

impl PivotDyn {
    fn reaction(&self, mass: f64, omega: f64) -> Vec2 {
        self.a + self.r * (mass * omega * omega)
    }
}

impl<'b> Plate<'b> {
    fn new(body: &'b Body) -> Self {
        let (sx, sy, f) = body.arrays();
        let rho = (body.inertia_cm() / body.mass()).sqrt();
        Self {
            sx,
            sy,
            f,
            mass: body.mass(),
            inertia: body.inertia_cm(),
            rho,
            inv_mass: 1.0 / body.mass(),
            inv_rho: 1.0 / rho,
            rho_over_inertia: rho / body.inertia_cm(),
        }
    }

    /// d y / dσ.
    #[inline]
    fn rhs(&self, y: &Y) -> Y {
        let (vx, vy) = (y[VX], y[VY]);
        let w = y[W] * self.inv_rho;
        let (mut fx, mut fy, mut mz, mut p) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..self.f.len() {
            let (rx, ry) = (self.sx[i], self.sy[i]);
            let ux = vx - w * ry;
            let uy = vy + w * rx;
            // A support at rest (|u| clamped) contributes nothing: its
            // numerator is zero. Only a pivot has one, and it is not
            // integrated.
            let n = (ux * ux + uy * uy).max(crate::dynamic::U2_FLOOR).sqrt();
            let k = self.f[i] / n;
            fx += k * ux;
            fy += k * uy;
            mz += k * (rx * uy - ry * ux);
            p += self.f[i] * n;
        }
        let s2 = vx * vx + vy * vy + y[W] * y[W];
        // dt/dσ = m s² / (Σ fᵢ |uᵢ|): the time the remaining motion would
        // take with its direction frozen.
        let g = self.mass * s2 / p;
        let (ex, ey) = (y[EX], y[EY]);
        [
            g * (w * vy - fx * self.inv_mass),
            g * (-fy * self.inv_mass - w * vx),
            -g * self.rho_over_inertia * mz,
            g,
            g * w,
            g * (ex * vx - ey * vy),
            g * (ey * vx + ex * vy),
            -g * w * ey,
            g * w * ex,
        ]
    }

    /// Sliding velocity of support i in the object frame (m/s) from a state
    /// or (from d y/dσ) its rate.
    #[inline]
    fn slip(&self, i: usize, y: &Y) -> Vec2 {
        let w = y[W] / self.rho;
        Vec2::new(y[VX] - w * self.sy[i], y[VY] + w * self.sx[i])
    }

    /// The pivot about support i turning at `omega` (≠ 0).
    fn pivot(&self, i: usize, omega: f64) -> PivotDyn {
        let r = Vec2::new(self.sx[i], self.sy[i]);
        let sgn = omega.signum();
        let (mut cap, mut moment, mut others) = (0.0, 0.0, Vec2::zeros());
        for j in 0..self.f.len() {
            let d = Vec2::new(self.sx[j] - r.x, self.sy[j] - r.y);
            let l = d.norm();
            if l == 0.0 {
                cap += self.f[j];
                continue;
            }
            moment += self.f[j] * l;
            // Support j slides along ω D d: friction −fⱼ sgn(ω) D d / |d|.
            others -= crate::perp(&d) * (self.f[j] * sgn / l);
        }
        let alpha = moment / (self.inertia + self.mass * r.norm_squared());
        // a_cm = −ω̇ D rᵢ + ω² rᵢ with ω̇ = −sgn α; R = m a_cm − Σ Fⱼ.
        let a = crate::perp(&r) * (self.mass * sgn * alpha) - others;
        PivotDyn { alpha, a, cap, r }
    }

    fn state_of(&self, y: &Y) -> SlideState {
        let n = (y[EX] * y[EX] + y[EY] * y[EY]).sqrt();
        let (c, s) = (y[EX] / n, y[EY] / n);
        SlideState {
            t: y[T],
            x: y[PX],
            y: y[PY],
            theta: y[TH],
            vx: c * y[VX] - s * y[VY],
            vy: s * y[VX] + c * y[VY],
            omega: y[W] / self.rho,
        }
    }

    fn y_of(&self, st: &SlideState) -> Y {
        let (s, c) = st.theta.sin_cos();
        [
            c * st.vx + s * st.vy,
            -s * st.vx + c * st.vy,
            self.rho * st.omega,
            st.t,
            st.theta,
            st.x,
            st.y,
            c,
            s,
        ]
    }
}

fn speed(y: &Y) -> f64 {
    (y[VX] * y[VX] + y[VY] * y[VY] + y[W] * y[W]).sqrt()
}

/// The state `dt` (s) into the frozen-direction remainder that starts at
/// `y` and lasts `t_rem` (s): every velocity falls linearly to zero.
fn remainder_at(plate: &Plate, y: &Y, t_rem: f64, dt: f64) -> SlideState {
    let mut st = plate.state_of(y);
    let tau = dt.clamp(0.0, t_rem);
    let travel = tau - tau * tau / (2.0 * t_rem);
    let left = 1.0 - tau / t_rem;
    st.t = y[T] + dt;
    st.x += st.vx * travel;
    st.y += st.vy * travel;
    st.theta += st.omega * travel;
    st.vx *= left;
    st.vy *= left;
    st.omega *= left;
    st
}

/// The sample sink: the caller's times and the states found for them.
struct Sampler<'a> {
    times: &'a [f64],
    next: usize,
    out: Vec<SlideState>,
}

impl Sampler<'_> {
    /// The next time to sample if it is at or before `t`.
    fn due(&self, t: f64) -> Option<f64> {
        self.times.get(self.next).copied().filter(|&ts| ts <= t)
    }
    fn push(&mut self, st: SlideState) {
        self.out.push(st);
        self.next += 1;
    }
}

/// Slides the plate `body` from `start` until it stops (or until
/// `opts.max_duration` has passed).
///
/// Errors: a parameter outside its domain (non-finite start, tolerance or
/// duration ≤ 0, sample times decreasing or before the start), or an
/// integration that cannot finish (step underflow, more than 100 000
/// steps or 1 000 pivot phases), with the time it happened.
pub fn slide_to_rest(
    body: &Body,
    start: &SlideState,
    opts: &SlideOptions,
) -> Result<Slide, ModelError> {
    check(start, opts)?;
    let plate = Plate::new(body);
    let mut run = Run {
        plate: &plate,
        tol: opts.tol,
        t_max: start.t + opts.max_duration,
        sampler: Sampler {
            times: opts.sample_times,
            next: 0,
            out: Vec::new(),
        },
        out: Slide::default(),
    };
    if !opts.sample_times.is_empty() {
        run.sampler.out.reserve_exact(opts.sample_times.len());
    }
    run.go(plate.y_of(start))?;
    let mut out = run.out;
    out.samples = run.sampler.out;
    Ok(out)
}

fn check(start: &SlideState, opts: &SlideOptions) -> Result<(), ModelError> {
    let fields = [
        ("slide start t", start.t),
        ("slide start x", start.x),
        ("slide start y", start.y),
        ("slide start theta", start.theta),
        ("slide start vx", start.vx),
        ("slide start vy", start.vy),
        ("slide start omega", start.omega),
    ];
    for (name, v) in fields {
        if !v.is_finite() {
            return Err(ModelError::Parameter {
                name,
                requirement: "finite",
                value: v,
            });
        }
    }
    ModelError::require_positive("slide tolerance", opts.tol)?;
    ModelError::require_positive("slide max_duration", opts.max_duration)?;
    let mut prev = start.t;
    for &ts in opts.sample_times {
        if !(ts >= prev) {
            return Err(ModelError::Parameter {
                name: "slide sample time",
                requirement: "finite, non-decreasing and not before the start",
                value: ts,
            });
        }
        prev = ts;
    }
    Ok(())
}

/// One slide in progress.
struct Run<'p, 'b, 'a> {
    plate: &'p Plate<'b>,
    tol: f64,
    t_max: f64,
    sampler: Sampler<'a>,
    out: Slide,
}

/// What the integration phase ended in.
enum Phase {
    /// At rest (the state).
    Rest(SlideState),
    /// Out of time (the state at `t_max`).
    Timeout(SlideState),
    /// Support `i` sticks from state `y`.
    Pivot(usize, Y),
}

impl Run<'_, '_, '_> {
    fn go(&mut self, mut y: Y) -> Result<(), ModelError> {
        // A support that is exactly at rest at the start: a pivot already,
        // or a support about to slip (given the direction it slips in).
        let mut left: Option<Escape> = None;
        loop {
            let s = speed(&y);
            if s == 0.0 {
                let st = self.plate.state_of(&y);
                return self.finish(st, Some(st.t));
            }
            let resting = (0..self.plate.f.len())
                .find(|&i| self.plate.f[i] > 0.0 && self.plate.slip(i, &y).norm() <= NUDGE * s);
            let phase = match resting {
                Some(i) if left.map(|e| e.support) != Some(i) => {
                    let omega = y[W] / self.plate.rho;
                    let pd = self.plate.pivot(i, omega);
                    if pd.reaction(self.plate.mass, omega).norm() <= pd.cap {
                        Phase::Pivot(i, y)
                    } else {
                        left = Some(nudge(self.plate, &mut y, i, &pd, omega));
                        self.integrate(y, left)?
                    }
                }
                _ => self.integrate(y, left)?,
            };
            match phase {
                Phase::Rest(st) => return self.finish(st, Some(st.t)),
                Phase::Timeout(st) => return self.finish(st, None),
                Phase::Pivot(i, yp) => {
                    if self.out.pivots.len() >= MAX_PIVOTS {
                        return Err(ModelError::Integration {
                            t: yp[T],
                            reason: format!(
                                "more than {MAX_PIVOTS} pivot phases (support {i} last): the slide chatters"
                            ),
                        });
                    }
                    match self.pivot(i, yp) {
                        (PivotEnd::Rest, st) => return self.finish(st, Some(st.t)),
                        (PivotEnd::MaxDuration, st) => return self.finish(st, None),
                        (PivotEnd::Slip, st) => {
                            y = self.plate.y_of(&st);
                            let omega = st.omega;
                            let pd = self.plate.pivot(i, omega);
                            left = Some(nudge(self.plate, &mut y, i, &pd, omega));
                        }
                    }
                }
            }
        }
    }

    fn finish(&mut self, end: SlideState, stop: Option<f64>) -> Result<(), ModelError> {
        let mut end = end;
        if stop.is_some() {
            (end.vx, end.vy, end.omega) = (0.0, 0.0, 0.0);
        }
        while let Some(ts) = self.sampler.due(end.t) {
            self.sampler.push(SlideState { t: ts, ..end });
        }
        self.out.end = end;
        self.out.stop = stop;
        Ok(())
    }

    /// Integrates in σ from `y` until the stop, the time limit or a pivot.
    /// `left`: a support that has just left a pivot (not stuck again until
    /// it has clearly slipped).
    fn integrate(&mut self, mut y: Y, mut left: Option<Escape>) -> Result<Phase, ModelError> {
        let plate = self.plate;
        let mut rhs = |y: &Y| plate.rhs(y);
        let mut k1 = rhs(&y);
        self.out.rhs_evals += 1;
        // The time scale of the whole slide: the remaining time with the
        // direction frozen, at the start. Time errors are held relative to it.
        let t_scale = k1[T];
        let tol = self.tol;
        let rho_len = plate.rho.min(1.0);
        let snap = SNAP * tol.sqrt();
        // |∇_q ln P| ≤ 1 + max |rᵢ|/ρ: how fast the friction power moves
        // with the direction.
        let lever = 1.0
            + (0..plate.f.len())
                .map(|i| plate.sx[i].hypot(plate.sy[i]))
                .fold(0.0, f64::max)
                / plate.rho;
        // First step: a tenth of the σ over which the direction turns by a
        // radian (the body frame turns at ω dt/dσ, which is large for a
        // plate that spins many times before it stops).
        let turn = (k1[VX].hypot(k1[VY]).hypot(k1[W]) / speed(&y)).max(1.0);
        let mut h: f64 = 0.1 / turn;
        for step in 0.. {
            if step > MAX_STEPS {
                return Err(ModelError::Integration {
                    t: y[T],
                    reason: format!("more than {MAX_STEPS} steps in the slide"),
                });
            }
            // The velocities' error weight (m/s). An error δV with t_rem
            // left moves the rest pose by about δV t_rem and the stop time
            // by t_rem δV/s; with the deceleration a = s/t_rem, holding
            // both to the tolerance asks δV ≤ tol a min(t_scale, ρ/s) (ρ
            // capped at 1 m: angles in rad are held like metres). Late in
            // the slide this is far looser than the velocities' own size:
            // the direction's slow drift there moves nothing that is
            // reported, and is not resolved.
            let s_ref = speed(&y);
            let w_vel = tol * (s_ref / k1[T]) * t_scale.min(rho_len / s_ref);
            let a = dop853::attempt_with(&mut rhs, &y, &k1, h, |i, _, _| match i {
                VX | VY | W => w_vel,
                T => tol * t_scale,
                _ => tol,
            });
            self.out.rhs_evals += 12;
            // A non-finite stage can make the error norm vanish: refuse the
            // step on its result instead.
            if !(a.err <= 1.0 && a.y1.iter().all(|c| c.is_finite())) {
                self.out.rejected += 1;
                h = next_step8(h, a.err).min(0.9 * h);
                if h < 1e-12 {
                    return Err(ModelError::Integration {
                        t: y[T],
                        reason: "step size underflow in the slide".into(),
                    });
                }
                continue;
            }
            self.out.steps += 1;
            let (t0, t1) = (y[T], a.y1[T]);
            if self.sampler.due(t1.min(self.t_max)).is_some() || t1 >= self.t_max {
                let dense = a.dense(&mut rhs, 0.0, &y, h);
                self.out.rhs_evals += 3;
                let at = |ts: f64| {
                    // t(σ) increases: the σ where it equals ts, by
                    // regula falsi (Illinois) on the dense output.
                    let (mut lo, mut hi) = (0.0, h);
                    let (mut flo, mut fhi) = (t0 - ts, t1 - ts);
                    let mut yy = y;
                    for _ in 0..60 {
                        if flo >= 0.0 {
                            return y;
                        }
                        let sg = if fhi > flo {
                            lo - flo * (hi - lo) / (fhi - flo)
                        } else {
                            0.5 * (lo + hi)
                        };
                        yy = dense.eval(sg);
                        let fm = yy[T] - ts;
                        if fm.abs() <= 1e-15 * ts.abs().max(1.0) || hi - lo <= 1e-15 * h {
                            break;
                        }
                        if fm < 0.0 {
                            (lo, flo) = (sg, fm);
                            fhi *= 0.5;
                        } else {
                            (hi, fhi) = (sg, fm);
                            flo *= 0.5;
                        }
                    }
                    yy[T] = ts;
                    yy
                };
                while let Some(ts) = self.sampler.due(t1.min(self.t_max)) {
                    let st = plate.state_of(&at(ts));
                    self.sampler.push(st);
                }
                if t1 >= self.t_max {
                    return Ok(Phase::Timeout(plate.state_of(&at(self.t_max))));
                }
            }
            y = a.y1;
            k1 = a.k13;
            h = next_step8(h, a.err);
            // The stop: the rest of the motion with its direction frozen
            // lasts t_rem = dt/dσ and covers s t_rem / 2 (exact when the
            // direction q is constant). What freezing q misses is of the
            // order of its rate |dq/dσ| = |dY/dσ + Y|/s times the
            // sensitivity `lever` of P(q) to it: once that error is below
            // the tolerance in the pose and in the time, the remainder is
            // added in closed form.
            let s = speed(&y);
            let t_rem = k1[T];
            let dq = ((k1[VX] + y[VX]).powi(2) + (k1[VY] + y[VY]).powi(2) + (k1[W] + y[W]).powi(2))
                .sqrt()
                / s;
            let drift = (dq * lever).max(1e-3);
            if s * t_rem * drift <= tol && t_rem * drift <= 10.0 * tol * t_scale {
                if t1 + t_rem >= self.t_max {
                    return Ok(Phase::Timeout(remainder_at(
                        plate,
                        &y,
                        t_rem,
                        self.t_max - t1,
                    )));
                }
                while let Some(ts) = self.sampler.due(t1 + t_rem) {
                    let st = remainder_at(plate, &y, t_rem, ts - t1);
                    self.sampler.push(st);
                }
                return Ok(Phase::Rest(remainder_at(plate, &y, t_rem, t_rem)));
            }
            // Supports about to stop sliding.
            for i in 0..plate.f.len() {
                if plate.f[i] == 0.0 {
                    continue;
                }
                let u = plate.slip(i, &y);
                let rel = u.norm() / s;
                if rel >= 0.5 {
                    if left.map(|e| e.support) == Some(i) {
                        left = None;
                    }
                    continue;
                }
                if left.map(|e| e.support) == Some(i) {
                    if rel >= 1e-3 {
                        left = None;
                    } else {
                        continue;
                    }
                }
                let du = plate.slip(i, &k1);
                let dd = du.norm_squared();
                let delta = if dd > 0.0 { -u.dot(&du) / dd } else { 0.0 };
                // Where the support can stick, the true motion stops its
                // slip within τ ≈ |uᵢ| / (margin fᵢ/m) (margin = 1 − |R|/fᵢ,
                // the share of the cone left), moving the pose by about
                // |uᵢ| τ: once that is below a hundredth of the tolerance the
                // support is stuck at once, by the impulse that stops it
                // ([`Run::pivot`]). Near the cone's edge the approach is
                // slow and stiff (the slip's direction relaxes far faster
                // than it shrinks) and would otherwise hover at the
                // integration's resolution.
                let stick_now = |ratio: f64| {
                    let margin = 1.0 - ratio;
                    margin > 0.0
                        && u.norm_squared() * plate.mass <= 1e-2 * tol * margin * plate.f[i]
                };
                // Otherwise only a support heading for zero within the next
                // steps.
                let omega = y[W] / plate.rho;
                let heading =
                    delta > 0.0 && delta <= 3.0 * h && (u + du * delta).norm() <= 0.5 * u.norm();
                if !heading && rel > 1e-3 {
                    continue;
                }
                let pd = plate.pivot(i, omega);
                let ratio = pd.reaction(plate.mass, omega).norm() / pd.cap;
                if ratio > 1.0 {
                    continue;
                }
                if stick_now(ratio) {
                    return Ok(Phase::Pivot(i, y));
                }
                if !heading {
                    continue;
                }
                if delta <= snap {
                    let mut yp = y;
                    for (c, d) in yp.iter_mut().zip(&k1) {
                        *c += delta * d;
                    }
                    if yp[T] >= self.t_max {
                        // Cannot be: delta is far below any step; kept exact.
                        return Ok(Phase::Timeout(plate.state_of(&y)));
                    }
                    while let Some(ts) = self.sampler.due(yp[T]) {
                        let mut st = plate.state_of(&y);
                        st.t = ts;
                        self.sampler.push(st);
                    }
                    return Ok(Phase::Pivot(i, yp));
                }
                // Aimed a little short: a step ending on the pivot has
                // stages beyond it, where the support's friction has turned
                // round, and is rejected.
                h = h.min(AIM * delta);
            }
        }
        unreachable!("the step loop returns")
    }

    /// The pivot about support i from the state y: closed form until rest,
    /// a slip or the time limit. Returns how it ended and the state then.
    fn pivot(&mut self, i: usize, y: Y) -> (PivotEnd, SlideState) {
        let plate = self.plate;
        let st0 = plate.state_of(&y);
        // The support's residual slip u (object frame) is stopped by the
        // impulse J that stops it in the rigid body, J = −W⁻¹ u with the
        // support's mobility W = 1/m + (D r)(D r)ᵀ/I: ω changes by r × J / I
        // and the velocity follows from the pivot.
        let r = Vec2::new(plate.sx[i], plate.sy[i]);
        let u = plate.slip(i, &y);
        let dr = crate::perp(&r);
        let (im, ii) = (plate.inv_mass, 1.0 / plate.inertia);
        let (w11, w12, w22) = (
            im + dr.x * dr.x * ii,
            dr.x * dr.y * ii,
            im + dr.y * dr.y * ii,
        );
        let det = w11 * w22 - w12 * w12;
        let j = -Vec2::new(w22 * u.x - w12 * u.y, -w12 * u.x + w11 * u.y) / det;
        let w0 = st0.omega + crate::cross(&r, &j) * ii;
        let (t0, th0) = (st0.t, st0.theta);
        let pd = plate.pivot(i, w0);
        let sgn = w0.signum();
        // The pivot's world position: the centre of mass plus R(θ) rᵢ.
        let (sn, cs) = th0.sin_cos();
        let p = Vec2::new(st0.x, st0.y) + Vec2::new(cs * r.x - sn * r.y, sn * r.x + cs * r.y);
        let t_rest = if pd.alpha > 0.0 {
            w0.abs() / pd.alpha
        } else {
            f64::INFINITY
        };
        // Slip where |A + m ω² r|² = cap²: m²|r|² x² + 2m (A·r) x + |A|² − cap²
        // = 0 in x = ω². Positive at x = 0 iff |A| > cap; the phase starts
        // inside the cone, so the first crossing as ω² falls is the smaller
        // root.
        let m = plate.mass;
        let (qa, qb, qc) = (
            m * m * r.norm_squared(),
            2.0 * m * pd.a.dot(&r),
            pd.a.norm_squared() - pd.cap * pd.cap,
        );
        let t_slip = if qc > 0.0 && qa > 0.0 && pd.alpha > 0.0 {
            let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
            // Smaller root, in the form that does not cancel.
            let x = if qb < 0.0 {
                2.0 * qc / (-qb + disc)
            } else {
                (-qb - disc) / (2.0 * qa)
            };
            let x = x.clamp(0.0, w0 * w0);
            (w0.abs() - x.sqrt()) / pd.alpha
        } else {
            f64::INFINITY
        };
        let (mut dur, mut end) = if t_slip < t_rest {
            (t_slip, PivotEnd::Slip)
        } else {
            (t_rest, PivotEnd::Rest)
        };
        if t0 + dur >= self.t_max {
            (dur, end) = (self.t_max - t0, PivotEnd::MaxDuration);
        }
        let at = |tau: f64| {
            let tau = tau.min(dur);
            let w = w0 - sgn * pd.alpha * tau;
            let th = th0 + w0 * tau - sgn * pd.alpha * tau * tau / 2.0;
            let (sn, cs) = th.sin_cos();
            let rw = Vec2::new(cs * r.x - sn * r.y, sn * r.x + cs * r.y);
            let c = p - rw;
            // v = ω D (c − p) = −ω D R(θ) r.
            let v = -crate::perp(&rw) * w;
            SlideState {
                t: t0 + tau,
                x: c.x,
                y: c.y,
                theta: th,
                vx: v.x,
                vy: v.y,
                omega: w,
            }
        };
        let t_end = t0 + dur;
        while let Some(ts) = self.sampler.due(t_end) {
            let st = at(ts - t0);
            self.sampler.push(st);
        }
        let mut fin = at(dur);
        fin.t = t_end;
        if end == PivotEnd::Rest {
            fin.omega = 0.0;
            (fin.vx, fin.vy) = (0.0, 0.0);
        }
        // |R| is convex in ω² and ω² falls monotonically: its largest value
        // is at one end of the phase.
        let load = pd
            .reaction(m, w0)
            .norm()
            .max(pd.reaction(m, fin.omega).norm());
        self.out.pivots.push(PivotPhase {
            support: i,
            t_start: t0,
            t_end,
            max_load: if pd.cap > 0.0 {
                load / pd.cap
            } else {
                f64::INFINITY
            },
            end,
        });
        (end, fin)
    }
}

/// Gives support i, at rest in `y`, the slip `NUDGE s` in the direction it
/// starts to slip: against the reaction that would have held it, so that
/// its friction `−fᵢ û` continues that reaction.
fn nudge(plate: &Plate, y: &mut Y, i: usize, pd: &PivotDyn, omega: f64) -> Escape {
    let s = speed(y);
    let rr = pd.reaction(plate.mass, omega);
    let dir = if rr.norm() > 0.0 {
        -rr / rr.norm()
    } else {
        Vec2::new(1.0, 0.0)
    };
    let u = plate.slip(i, y);
    let want = dir * (NUDGE * s);
    y[VX] += want.x - u.x;
    y[VY] += want.y - u.y;
    Escape { support: i }
}

/// The state at the release from the pushing model's end: contact point
/// `c` (m, world), `theta`, `omega`, and the last push's contact velocity
/// `contact_velocity` (object frame; None without pushes: the problem's
/// initial state is the start). The pusher withdraws without an impulse.
pub(crate) fn release_state(
    problem: &Problem,
    c: Vec2,
    theta: f64,
    omega: f64,
    contact_velocity: Option<Vec2>,
) -> SlideState {
    let init = &problem.initial;
    let Some(vc) = contact_velocity.filter(|_| !problem.pushes.is_empty()) else {
        return SlideState {
            t: 0.0,
            x: init.position.x,
            y: init.position.y,
            theta: init.theta,
            vx: init.velocity.x,
            vy: init.velocity.y,
            omega: init.omega,
        };
    };
    let pc = problem.body.contact();
    // v_cm = R(θ) (v_c − ω D p_c), the centre of mass p = c − R(θ) p_c.
    let v = rotate(theta, &(vc - perp(&pc) * omega));
    let p = c - rotate(theta, &pc);
    SlideState {
        t: problem.duration(),
        x: p.x,
        y: p.y,
        theta,
        vx: v.x,
        vy: v.y,
        omega,
    }
}

/// Continues a model's trajectory through the slide from `start`: samples
/// on the problem's grid after the release, the last row the rest state (or
/// the state at `max_duration` when the plate has not stopped), and
/// [`Trajectory::slide`].
pub(crate) fn continue_run(
    problem: &Problem,
    release: &Release,
    start: SlideState,
    out: &mut Trajectory,
) -> Result<(), ModelError> {
    let eps = 1e-9 * problem.sample_dt;
    let t_end = start.t + release.max_duration;
    let times: Vec<f64> = problem
        .sample_times_through(t_end)
        .into_iter()
        .filter(|&ts| ts > start.t + eps)
        .collect();
    let row = |s: &SlideState| Sample {
        t: s.t,
        x: s.x,
        y: s.y,
        theta: s.theta,
        omega: s.omega,
    };
    if out.samples.last().is_none_or(|l| l.t < start.t - eps) {
        out.samples.push(row(&start));
    }
    let slide = slide_to_rest(
        &problem.body,
        &start,
        &SlideOptions {
            max_duration: release.max_duration,
            sample_times: &times,
            ..Default::default()
        },
    )?;
    out.samples.extend(slide.samples.iter().map(row));
    match out.samples.last_mut() {
        Some(l) if l.t >= slide.end.t - eps => *l = row(&slide.end),
        _ => out.samples.push(row(&slide.end)),
    }
    out.stats.steps += slide.steps;
    out.stats.rejected += slide.rejected;
    out.stats.rhs_evals += slide.rhs_evals;
    out.slide = Some(SlideReport {
        t_release: start.t,
        t_stop: slide.stop,
        pivots: slide.pivots,
    });
    Ok(())
}
