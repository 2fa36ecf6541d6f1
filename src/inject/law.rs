//! The pushing model with a different support-friction law, for injecting a
//! friction-law error into the model: each support's force is
//! `−F_i w_i/|w_i|` with `w_i = (1 − ε) u_i + ε K_i⁻¹ u_i / m`, where
//! `K_i = 1/m + (D p_i)(D p_i)ᵀ / I_cm` maps an impulse at support i (p_i from
//! the centre of mass) to the velocity change it causes. ε = 0 is Coulomb
//! (the dynamic model); ε = 1 is the direction law of a game engine's capped
//! per-support friction impulse (`−K⁻¹u`, rapier2d_impulse_disk).
//!
//! The equations are the model's (docs/architecture.md, "The model"): `I_P ω̇ = Σ r_i × f_i + m v_c ω
//! (p_c · n_φ)`, `ṗ_cm = R(θ)(v_c n_φ − ω D p_c)`, with the angular momentum
//! about the contact conserved at switches (`Switching::Impulsive`) or ω kept
//! (`Continuous`). The right-hand side is the model crate's
//! ([`SegmentDynamics`]): at ε = 0 its `omega_dot` itself; at ε > 0 its
//! inertial term and `I_P` with the blended friction moment in place of the
//! Coulomb one. That moment is the one sum written here (the model crate has
//! only the Coulomb law); the test below holds it at ε = 0 to
//! `SegmentDynamics::friction_moment_at` (random states, 1e-12 relative).
//! Integrated with classical RK4 at a fixed step of at most
//! `sample_dt / 32`, because the model crate's integrators are built around
//! the Coulomb friction sum; at ε = 0 this agrees with `DynamicModel` to
//! 1e-9 m (tests/suite/power.rs), which checks both.

use pushval_model::{
    cross, perp, rotate, Problem, Sample, SegmentDynamics, SegmentReport, Switching, Trajectory,
    Vec2,
};

/// State: θ (rad), ω (rad/s), CM position (m).
#[derive(Debug, Clone, Copy)]
struct State {
    theta: f64,
    omega: f64,
    x: f64,
    y: f64,
}

impl State {
    fn add(&self, k: &State, h: f64) -> State {
        State {
            theta: self.theta + h * k.theta,
            omega: self.omega + h * k.omega,
            x: self.x + h * k.x,
            y: self.y + h * k.y,
        }
    }
}

/// The problem's body in the terms the law needs.
struct Law {
    mass: f64,
    inertia_p: f64,
    contact: Vec2,
    /// (position from the CM, F_i = μ_i N_i, K_i⁻¹ / m as [a, b, c] of a
    /// symmetric 2×2).
    supports: Vec<(Vec2, f64, [f64; 3])>,
    eps: f64,
}

impl Law {
    fn new(problem: &Problem, eps: f64) -> Self {
        let b = &problem.body;
        let (m, i) = (b.mass(), b.inertia_cm());
        let supports = b
            .supports()
            .map(|s| {
                // K = I/m + (D p)(D p)ᵀ / I; its inverse in closed form.
                let d = perp(&s.position);
                let (k11, k12, k22) = (
                    1.0 / m + d.x * d.x / i,
                    d.x * d.y / i,
                    1.0 / m + d.y * d.y / i,
                );
                let det = k11 * k22 - k12 * k12;
                let inv = [k22 / det / m, -k12 / det / m, k11 / det / m];
                (s.position, s.friction, inv)
            })
            .collect();
        Self {
            mass: m,
            inertia_p: b.inertia_contact(),
            contact: b.contact(),
            supports,
            eps,
        }
    }

    /// The blended law's friction moment about the contact (N m) at ω for
    /// pusher velocity `speed · n` (object frame).
    fn friction_moment(&self, omega: f64, speed: f64, n: Vec2) -> f64 {
        let pc = self.contact;
        let mut moment = 0.0;
        for (p, f, k) in &self.supports {
            let r = p - pc;
            let u = speed * n + omega * perp(&r);
            let ku = Vec2::new(k[0] * u.x + k[1] * u.y, k[1] * u.x + k[2] * u.y);
            let w = (1.0 - self.eps) * u + self.eps * ku;
            let len = w.norm();
            if len > 1e-15 {
                moment += cross(&r, &(-*f / len * w));
            }
        }
        moment
    }

    /// The state's rate in the segment `seg` (pusher velocity `speed · n`).
    fn rhs(&self, s: &State, seg: &SegmentDynamics, speed: f64, n: Vec2) -> State {
        let wdot = if self.eps == 0.0 {
            seg.omega_dot(s.omega)
        } else {
            (self.friction_moment(s.omega, speed, n) + seg.inertial_slope() * s.omega)
                / seg.inertia_contact()
        };
        let v = rotate(s.theta, &(speed * n - s.omega * perp(&self.contact)));
        State {
            theta: s.omega,
            omega: wdot,
            x: v.x,
            y: v.y,
        }
    }

    /// ω just after a switch from (v0, n0) to (v1, n1) at ω0.
    fn jump(&self, omega: f64, v0: f64, n0: Vec2, v1: f64, n1: Vec2) -> f64 {
        let pc = self.contact;
        let h = self.inertia_p * omega - self.mass * v0 * cross(&pc, &n0);
        (h + self.mass * v1 * cross(&pc, &n1)) / self.inertia_p
    }
}

/// The problem's trajectory under the blended law with weight `eps` ∈ [0, 1].
pub fn simulate(problem: &Problem, eps: f64) -> Trajectory {
    let law = Law::new(problem, eps);
    let init = problem.initial;
    let mut s = State {
        theta: init.theta,
        omega: init.omega,
        x: init.position.x,
        y: init.position.y,
    };
    let dir = |phi: f64| Vec2::new(phi.cos(), phi.sin());
    // Before the first push: at rest, or moving with the first push at ω0.
    let (mut v_prev, mut n_prev) = if init.from_rest {
        s.omega = 0.0;
        (0.0, dir(problem.pushes[0].phi))
    } else {
        (problem.pushes[0].speed, dir(problem.pushes[0].phi))
    };
    let times = problem.sample_times();
    let mut samples = Vec::with_capacity(times.len());
    let mut segments = Vec::new();
    let mut t = 0.0;
    let mut k = 0;
    let last = problem.pushes.len() - 1;
    for (j, (push, (t0, t1))) in problem
        .pushes
        .iter()
        .zip(problem.segment_times())
        .enumerate()
    {
        let n = dir(push.phi);
        let seg = SegmentDynamics::new(&problem.body, push);
        if problem.switching == Switching::Impulsive {
            s.omega = law.jump(s.omega, v_prev, n_prev, push.speed, n);
        }
        let omega_start = s.omega;
        (v_prev, n_prev) = (push.speed, n);
        let tol = 1e-9 * t1.max(1.0);
        // Samples in [t0, t1) (and t1 itself for the last segment).
        let advance = |to: f64, s: &mut State, t: &mut f64| {
            let span = to - *t;
            if span <= 0.0 {
                return;
            }
            let steps = (span / (problem.sample_dt / 32.0)).ceil().max(1.0) as usize;
            let h = span / steps as f64;
            for _ in 0..steps {
                let k1 = law.rhs(s, &seg, push.speed, n);
                let k2 = law.rhs(&s.add(&k1, h / 2.0), &seg, push.speed, n);
                let k3 = law.rhs(&s.add(&k2, h / 2.0), &seg, push.speed, n);
                let k4 = law.rhs(&s.add(&k3, h), &seg, push.speed, n);
                s.theta += h / 6.0 * (k1.theta + 2.0 * k2.theta + 2.0 * k3.theta + k4.theta);
                s.omega += h / 6.0 * (k1.omega + 2.0 * k2.omega + 2.0 * k3.omega + k4.omega);
                s.x += h / 6.0 * (k1.x + 2.0 * k2.x + 2.0 * k3.x + k4.x);
                s.y += h / 6.0 * (k1.y + 2.0 * k2.y + 2.0 * k3.y + k4.y);
            }
            *t = to;
        };
        while k < times.len() && (times[k] < t1 - tol || (j == last && times[k] <= t1 + tol)) {
            advance(times[k].max(t0), &mut s, &mut t);
            samples.push(Sample {
                t: times[k],
                x: s.x,
                y: s.y,
                theta: s.theta,
                omega: s.omega,
            });
            k += 1;
        }
        advance(t1, &mut s, &mut t);
        segments.push(SegmentReport {
            index: j,
            t_start: t0,
            t_end: t1,
            omega_start,
            omega_end: s.omega,
            settled_at: None,
        });
    }
    Trajectory {
        model: format!("blended_law[eps={eps}]"),
        samples,
        segments,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushval_model::{Body, Push, Support};

    /// At ε = 0 the blended law is Coulomb's: its friction moment is the
    /// model's, and the right-hand side is `SegmentDynamics::omega_dot`
    /// itself; at ε > 0 the inertial term and I_P are still the model's.
    #[test]
    fn the_blended_law_at_zero_is_the_models_right_hand_side() {
        let supports: Vec<Support> = [
            (-0.1, -0.12, 1.1),
            (0.13, -0.1, 0.7),
            (0.1, 0.12, 1.9),
            (-0.12, 0.09, 0.4),
        ]
        .iter()
        .map(|&(x, y, f)| Support {
            position: Vec2::new(x, y),
            friction: f,
        })
        .collect();
        let body = Body::new(1.3, 0.011, Vec2::new(-0.125, -0.03), &supports).unwrap();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let push0 = Push {
            duration: 1.0,
            speed: 0.5,
            phi: 0.3,
        };
        let problem = Problem {
            body: body.clone(),
            limits: Default::default(),
            pushes: vec![push0],
            initial: Default::default(),
            switching: Switching::Impulsive,
            sample_dt: 0.01,
            release: None,
        };
        for _ in 0..500 {
            let push = Push {
                duration: 1.0,
                speed: 2.0 * uniform(),
                phi: 6.3 * uniform(),
            };
            let seg = SegmentDynamics::new(&body, &push);
            let n = push.direction();
            let s = State {
                theta: 6.0 * uniform(),
                omega: 30.0 * (uniform() - 0.5),
                x: 0.0,
                y: 0.0,
            };
            let scale = seg.max_moment();
            let coulomb = Law::new(&problem, 0.0);
            let got = coulomb.friction_moment(s.omega, push.speed, n);
            let want = seg.friction_moment_at(push.speed, s.omega);
            assert!((got - want).abs() <= 1e-12 * scale, "{got} vs {want}");
            let r = coulomb.rhs(&s, &seg, push.speed, n);
            assert_eq!(r.omega, seg.omega_dot(s.omega));
            let blended = Law::new(&problem, 0.5);
            let m = blended.friction_moment(s.omega, push.speed, n);
            let r = blended.rhs(&s, &seg, push.speed, n);
            let want = (m + seg.inertial_slope() * s.omega) / body.inertia_contact();
            assert!(
                (r.omega - want).abs() <= 1e-12 * want.abs().max(scale / body.inertia_contact())
            );
        }
    }
}
