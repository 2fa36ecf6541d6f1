//! What an engine's rows must satisfy beyond their format: in time order
//! and continuous.
//!
//! The CSV reader already refuses a number that is not finite. A row that
//! is finite but far from its neighbour (a position of 1e300 m between two
//! sample times, an angle wrapped to (−π, π]) is refused here, naming its
//! line: between two consecutive rows `Δt` apart, the centre of mass can
//! move at most `(v + ω_max R) Δt` and the angle at most `ω_max Δt`, where
//! `v` is the fastest push, `R` the object's reach (the farthest support or
//! contact from the centre of mass) and `ω_max = |ω₀| + v / r_g` (r_g =
//! √(I_cm / m), the radius of gyration: an impulsive start turns the object
//! at most at `v / (2 r_g)`, and friction only slows it). The check allows
//! [`MARGIN`] times that, plus [`SLACK`] of the reach (m) and of a radian
//! per row (an engine's contact jitter at rest).

use pushval_model::Problem;

use crate::csv::Record;

/// How many times the largest motion the push allows a jump may be.
pub const MARGIN: f64 = 10.0;
/// Allowed on top of the bound at every row: this fraction of the object's
/// reach (m), and this many radians.
pub const SLACK: f64 = 1e-3;

/// The largest motion a problem allows between two rows.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bound {
    /// The fastest push (m/s).
    speed: f64,
    /// The object's reach from its centre of mass (m).
    reach: f64,
    /// The fastest turn (rad/s).
    omega: f64,
    /// |ω₀| (rad/s): 0 from rest.
    omega0: f64,
    /// The radius of gyration √(I_cm / m) (m).
    gyration: f64,
}

impl Bound {
    /// The bound of `problem` (its whole schedule).
    pub(crate) fn of(problem: &Problem) -> Self {
        let body = &problem.body;
        let speed = problem
            .pushes
            .iter()
            .map(|p| p.speed.abs())
            .fold(0.0, f64::max);
        let reach = body
            .supports()
            .map(|s| s.position.norm())
            .fold(body.contact().norm(), f64::max);
        let gyration = (body.inertia_cm() / body.mass()).sqrt();
        let omega0 = if problem.initial.from_rest {
            0.0
        } else {
            problem.initial.omega.abs()
        };
        Self {
            speed,
            reach,
            omega: omega0 + speed / gyration,
            omega0,
            gyration,
        }
    }

    /// The bound once `speed` (m/s) is pushed too: as [`Bound::of`] the
    /// problem with that push added to its schedule.
    pub(crate) fn widen(&mut self, speed: f64) {
        self.speed = self.speed.max(speed.abs());
        self.omega = self.omega0 + self.speed / self.gyration;
    }

    /// The bound once the plate slides freely from a centre-of-mass speed
    /// `speed` (m/s) and spin `omega` (rad/s): friction only slows it.
    pub(crate) fn widen_slide(&mut self, speed: f64, omega: f64) {
        self.speed = self.speed.max(speed.abs());
        self.omega0 = self.omega0.max(omega.abs());
        self.omega = self.omega.max(self.omega0 + self.speed / self.gyration);
    }

    /// Whether the step from row `a` to row `b` is within the bound; else
    /// the sentence saying which jump is not (naming `b`'s line as `where_`
    /// tells).
    pub(crate) fn step(
        &self,
        a: &Record,
        b: &Record,
        where_: impl Fn() -> String,
    ) -> Result<(), String> {
        let dt = b.numbers[0] - a.numbers[0];
        let moved = (b.numbers[1] - a.numbers[1]).hypot(b.numbers[2] - a.numbers[2]);
        let allowed = MARGIN * (self.speed + self.omega * self.reach) * dt + SLACK * self.reach;
        if !(moved <= allowed) {
            return Err(format!(
                "{}: the centre of mass jumps {moved:.6e} m from the row before ({} s to {} s), more than the push allows ({allowed:.3e} m: {MARGIN} × (push speed {} m/s + {:.4} rad/s × reach {:.4} m) × {dt:.3e} s, + {SLACK} × reach)",
                where_(),
                a.numbers[0],
                b.numbers[0],
                self.speed,
                self.omega,
                self.reach
            ));
        }
        let turned = (b.numbers[3] - a.numbers[3]).abs();
        let allowed = MARGIN * self.omega * dt + SLACK;
        if !(turned <= allowed) {
            return Err(format!(
                "{}: theta jumps {turned:.6e} rad from the row before ({} s to {} s), more than the push allows ({allowed:.3e} rad: {MARGIN} × {:.4} rad/s × {dt:.3e} s, + {SLACK} rad; theta must be unwrapped)",
                where_(),
                a.numbers[0],
                b.numbers[0],
                self.omega
            ));
        }
        Ok(())
    }
}

/// Checks `rows` (after `before`, the last row already checked, if any):
/// times strictly increasing and every step within `bound`. `line` names a
/// row's line for messages.
pub(crate) fn rows(
    bound: &Bound,
    before: Option<&Record>,
    rows: &[Record],
    line: impl Fn(&Record) -> String,
) -> Result<(), String> {
    let mut prev = before;
    for r in rows {
        if let Some(a) = prev {
            if !(r.numbers[0] > a.numbers[0]) {
                return Err(format!(
                    "{}: column `t`: {} s does not increase (the row before is at {} s)",
                    line(r),
                    r.numbers[0],
                    a.numbers[0]
                ));
            }
            bound.step(a, r, || line(r))?;
        }
        prev = Some(r);
    }
    Ok(())
}
