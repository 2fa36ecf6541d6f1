//! The pushing model with a different support-friction law, for injecting a
//! friction-law error into the model: each support's force is
//! `−F_i w_i/|w_i|` with `w_i = (1 − ε) u_i + ε K_i⁻¹ u_i / m`, where
//! `K_i = 1/m + (D p_i)(D p_i)ᵀ / I_cm` maps an impulse at support i (p_i from
//! the centre of mass) to the velocity change it causes. ε = 0 is Coulomb
//! (the dynamic model); ε = 1 is the direction law of a game engine's capped
//! per-support friction impulse (`−K⁻¹u`, rapier2d_impulse_disk).
//!
//! The equations are the model's (DESIGN.md): `I_P ω̇ = Σ r_i × f_i + m v_c ω
//! (p_c · n_φ)`, `ṗ_cm = R(θ)(v_c n_φ − ω D p_c)`, with the angular momentum
//! about the contact conserved at switches (`Switching::Impulsive`) or ω kept
//! (`Continuous`). Integrated here with classical RK4 at a fixed step of at
//! most `sample_dt / 32`, because the model crate's integrators are built
//! around the Coulomb friction sum; at ε = 0 this agrees with
//! `DynamicModel` to 1e-9 m (tests/suite/power.rs), which checks both.

use pushval_model::{
    cross, perp, rotate, Problem, Sample, SegmentReport, Switching, Trajectory, Vec2,
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
    inertia_cm: f64,
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
            inertia_cm: i,
            inertia_p: b.inertia_contact(),
            contact: b.contact(),
            supports,
            eps,
        }
    }

    fn rhs(&self, s: &State, speed: f64, n: Vec2) -> State {
        let pc = self.contact;
        let mut moment = 0.0;
        for (p, f, k) in &self.supports {
            let r = p - pc;
            let u = speed * n + s.omega * perp(&r);
            let ku = Vec2::new(k[0] * u.x + k[1] * u.y, k[1] * u.x + k[2] * u.y);
            let w = (1.0 - self.eps) * u + self.eps * ku;
            let len = w.norm();
            if len > 1e-15 {
                moment += cross(&r, &(-*f / len * w));
            }
        }
        let wdot = (moment + self.mass * speed * s.omega * pc.dot(&n)) / self.inertia_p;
        let v = rotate(s.theta, &(speed * n - s.omega * perp(&pc)));
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
    let _ = law.inertia_cm;
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
                let k1 = law.rhs(s, push.speed, n);
                let k2 = law.rhs(&s.add(&k1, h / 2.0), push.speed, n);
                let k3 = law.rhs(&s.add(&k2, h / 2.0), push.speed, n);
                let k4 = law.rhs(&s.add(&k3, h), push.speed, n);
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
