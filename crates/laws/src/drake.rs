//! Drake's convex contact approximations, SAP and Similar, in closed form:
//! the lift of a sliding contact (no Drake needed; only `pushval-model`).
//!
//! The scene is the plate of `adapters/python/drake_push.py`: sphere feet
//! on a ground half-space, point contact, each foot's stiffness
//! `k_i = N_i / δ` (`δ` the rest penetration), the centre of mass at the
//! feet's height.
//!
//! **The normal law while sliding.** SAP's friction cone constraint
//! (`SapFrictionConeConstraint`, Castro et al.) projects `y = R⁻¹(v̂ − v_c)`
//! onto the cone in the `R` norm, `R = diag(R_t, R_t, R_n)`,
//! `v̂_n = x₀/(δt + τ_d)` (`x₀` the penetration at the step's start),
//! `R_n = 1/(δt k (δt + τ_d))` in the compliant range. In the sliding mode the
//! residual `R(y − γ)` is normal to the cone at `γ`, along `(t̂, −μ)`; its
//! tangential part is the slip beyond `μ R_t γ_n`, and the normal part gives
//!
//! ```text
//!   γ_n (R_n + μ² R_t) = v̂_n − v_n + μ |v_t|
//!   N = γ_n/δt = k (x₀ + (δt + τ_d)(μ |v_t| − v_n)) / (1 + μ² R_t/R_n)
//! ```
//!
//! the compliant law with `v_n` replaced by `v_n − μ|v_t|`: the ground seems
//! to rise at `μ |v_t|` under the damper (`μ² R_t/R_n ≈ σ w_t δt k (δt+τ_d)`
//! is below 1e-3 here and dropped). Similar (`SapHuntCrossleyConstraint`)
//! evaluates its Hunt–Crossley impulse at `z = v_n − μ |v_t|` by
//! construction: `N = k (x₀ − δt z)(1 − d z)`. Friction is `μ N` along
//! `−v_t` in both: the friction law is Coulomb's with these loads.
//!
//! **Glide.** At a steady height (`v_n = 0`) a foot that has risen `z` above
//! its rest height (penetration `x₀ = δ − z`) carries
//!
//! ```text
//!   SAP:      N = k (δ + (δt + τ_d) μ |v_t| − z)
//!   Similar:  N = k (1 + d μ |v_t|) (δ + δt μ |v_t| − z)
//! ```
//!
//! so a lone foot rises by `ℓ = (δt + τ_d) μ |v_t|` (SAP) or
//! `δ d μ|v_t|/(1 + d μ|v_t|) + δt μ |v_t|` (Similar). The rigid plate's
//! feet lie on a plane `z_i = z₀ + b·p_i` fixed by `Σ N_i = m g` and
//! `Σ p_i N_i = 0` (no tipping moment): the loads are the feet's lifts
//! minus that plane, i.e. the plate's mean rise is the lifts' (weighted)
//! mean and the rest moves load between the feet (on four feet, the twist
//! `ΔN ∝ ±(ℓ₀ − ℓ₁ + ℓ₂ − ℓ₃)` no plane can absorb). ω is Coulomb's with
//! those loads ([`DrakeConvex::lift`]). This holds while every foot still
//! penetrates, `z_i < δ`.
//!
//! **Hop.** Where a foot's lift reaches `δ` it leaves the ground: the
//! contact force at zero penetration, `k (δt + τ_d) μ |v_t|`, exceeds its
//! load. Each touchdown launches the foot at the speed one step's impulse
//! gives its share of the mass `m_i = N_i/g` ([`DrakeConvex::launch_speed`];
//! `μ |v_t|` in the rigid limit, the Anitescu relaxation's), and the plate
//! hovers at zero penetration: its mean rise is `δ + ⟨u_i²⟩/(3g)` (the mean
//! height of ballistic arcs). The time-averaged normal force still carries
//! the weight with no tipping moment, and friction is `μ N` along `−v_t` at
//! every touchdown, so the mean friction is Coulomb's with the statics'
//! loads: the law's ω is Coulomb's. On four feet the statics leave one
//! load pattern free (the twist); the hops set it at random, which the law
//! cannot predict (results/friction_models/drake/README.md: ±2 % in ω at
//! dt ≤ 1e-3 s on the paper plate, up to 15 % at dt = 4e-3 s).

use pushval_model::{Body, Problem, Push, Vec2};

use crate::mujoco::{rest_loads, steady_omega, Coulomb as CoulombForce};
use crate::{coulomb_steady, LawClass, LawSteady};

/// Which convex approximation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Approximation {
    /// SAP (`DiscreteContactApproximation::kSap`): the friction-cone
    /// constraint with relaxation time `τ_d`.
    Sap,
    /// Similar (`kSimilar`): Hunt–Crossley at `z = v_n − μ |v_t|`.
    Similar,
}

/// Whether every foot keeps penetrating while it slides.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regime {
    /// Every foot penetrates at a steady height: loads from the glide plane.
    Glide,
    /// A foot's lift reaches the rest penetration: the plate hops.
    Hop,
}

impl Regime {
    /// `"glide"` or `"hop"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Regime::Glide => "glide",
            Regime::Hop => "hop",
        }
    }
}

/// The lift's steady state for one push segment.
#[derive(Debug, Clone, PartialEq)]
pub struct Lift {
    /// Glide or hop.
    pub regime: Regime,
    /// Mean rise of the centre of mass above its rest height (m).
    pub rise: f64,
    /// Each support's (mean) normal load (N), in the problem's order.
    pub loads: Vec<f64>,
    /// Steady ω (rad/s): Coulomb's with `loads`.
    pub omega: f64,
}

/// The law of SAP or Similar on drake_push.py's plate: Coulomb at every
/// foot with the loads of the lift (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrakeConvex {
    /// Which approximation.
    pub approximation: Approximation,
    /// Rest penetration δ (m, > 0): each foot's stiffness is `N_i / δ`.
    pub penetration: f64,
    /// SAP's relaxation time τ_d (s, ≥ 0); unused by Similar.
    pub relaxation_time: f64,
    /// Similar's Hunt–Crossley dissipation d (s/m, ≥ 0); unused by SAP.
    pub dissipation: f64,
    /// Gravity (m/s²): the weight the feet share, `N_i = m_i g`.
    pub gravity: f64,
}

/// drake_push.py's rest penetration (m).
pub const DEFAULT_PENETRATION: f64 = 1e-4;
/// The default gravity (m/s²).
pub const DEFAULT_GRAVITY: f64 = 9.81;

impl DrakeConvex {
    /// drake_push.py's defaults: δ = 1e-4 m and critical damping of the
    /// plate's bounce on its feet, `ω_n = sqrt(Σk_i/m) = sqrt(g/δ)`:
    /// `τ_d = 2/ω_n`, `d = 2 ω_n / g`.
    pub fn new(approximation: Approximation) -> Self {
        let (delta, g) = (DEFAULT_PENETRATION, DEFAULT_GRAVITY);
        let wn = (g / delta).sqrt();
        Self {
            approximation,
            penetration: delta,
            relaxation_time: 2.0 / wn,
            dissipation: 2.0 * wn / g,
            gravity: g,
        }
    }

    /// A sliding foot's steady normal law `N = K (a − z)` (z its rise, m):
    /// `(K, a)` for stiffness `k` (N/m), friction μ, slip speed `v` (m/s)
    /// and step `dt` (s).
    pub fn contact_line(&self, k: f64, mu: f64, v: f64, dt: f64) -> (f64, f64) {
        match self.approximation {
            Approximation::Sap => (k, self.penetration + (dt + self.relaxation_time) * mu * v),
            Approximation::Similar => (
                k * (1.0 + self.dissipation * mu * v),
                self.penetration + dt * mu * v,
            ),
        }
    }

    /// The normal velocity (m/s) one step's impulse gives a foot of mass
    /// `mass` (kg) and stiffness `k` (N/m) touching at zero penetration and
    /// zero normal velocity while it slides at `v` (m/s), friction μ:
    /// SAP `u = c μ v / (1 + c)`, `c = δt k (δt + τ_d) / m`; Similar
    /// `u = μ v − w` with `c' w (1 + d w) = μ v − w`, `c' = δt² k / m`.
    /// Both tend to `μ v` as the contact stiffens (the rigid relaxation's
    /// `v_n = μ |v_t|`) and to 0 with `dt`.
    pub fn launch_speed(&self, k: f64, mass: f64, mu: f64, v: f64, dt: f64) -> f64 {
        let s = mu * v;
        match self.approximation {
            Approximation::Sap => {
                let c = dt * k * (dt + self.relaxation_time) / mass;
                c * s / (1.0 + c)
            }
            Approximation::Similar => {
                let c = dt * dt * k / mass;
                let dc = self.dissipation * c;
                if dc * s < 1e-12 {
                    return c * s / (1.0 + c);
                }
                let w = (-(1.0 + c) + ((1.0 + c) * (1.0 + c) + 4.0 * dc * s).sqrt()) / (2.0 * dc);
                s - w
            }
        }
    }

    /// The lift's steady state of segment `segment` at time step `dt` (s):
    /// the rest loads are the least-norm share of `m g` (statics up to
    /// three supports), `μ_i = F_i / N_i`; the glide's loads and ω are
    /// iterated to a fixed point from Coulomb's steady state. None where
    /// Coulomb's has none, or a support with friction carries no load.
    pub fn lift(&self, problem: &Problem, segment: usize, dt: f64) -> Option<Lift> {
        let push = problem.pushes.get(segment)?;
        let body = &problem.body;
        let rest = rest_loads(body, body.mass() * self.gravity)?;
        let mut mu = Vec::with_capacity(rest.len());
        for (s, &n) in body.supports().zip(&rest) {
            if s.friction == 0.0 {
                mu.push(0.0);
            } else if n > 0.0 {
                mu.push(s.friction / n);
            } else {
                return None;
            }
        }
        let stiff: Vec<f64> = rest.iter().map(|n| n.max(0.0) / self.penetration).collect();
        let omega0 = coulomb_steady(problem, segment)?;
        let mut omega = omega0;
        let mut glide = None;
        for _ in 0..100 {
            let v = slip_speeds(body, push, omega);
            let Some((loads, rise)) = self.glide_plane(body, &stiff, &mu, &v, dt) else {
                glide = None;
                break;
            };
            let forces: Vec<f64> = loads.iter().zip(&mu).map(|(n, m)| n * m).collect();
            let next = steady_omega(body, push, &CoulombForce, &forces, omega)?;
            let done = (next - omega).abs() <= 1e-13 * omega.abs().max(1.0);
            omega = next;
            glide = Some((loads, rise));
            if done {
                break;
            }
        }
        Some(match glide {
            Some((loads, rise)) => Lift {
                regime: Regime::Glide,
                rise,
                loads,
                omega,
            },
            None => {
                let v = slip_speeds(body, push, omega0);
                let n = rest.len() as f64;
                let u2: f64 = rest
                    .iter()
                    .zip(&stiff)
                    .zip(mu.iter().zip(&v))
                    .map(|((&load, &k), (&m, &vi))| {
                        if load > 0.0 {
                            self.launch_speed(k, load / self.gravity, m, vi, dt).powi(2)
                        } else {
                            0.0
                        }
                    })
                    .sum();
                Lift {
                    regime: Regime::Hop,
                    rise: self.penetration + u2 / n / (3.0 * self.gravity),
                    loads: rest,
                    omega: omega0,
                }
            }
        })
    }

    /// The glide's loads and the centre of mass's rise for slip speeds `v`,
    /// or None where a loaded foot would rise to δ (it leaves: hop).
    fn glide_plane(
        &self,
        body: &Body,
        stiff: &[f64],
        mu: &[f64],
        v: &[f64],
        dt: f64,
    ) -> Option<(Vec<f64>, f64)> {
        let weight = body.mass() * self.gravity;
        let lines: Vec<(f64, f64)> = stiff
            .iter()
            .zip(mu.iter().zip(v))
            .map(|(&k, (&m, &vi))| self.contact_line(k, m, vi, dt))
            .collect();
        let pts: Vec<Vec2> = body.supports().map(|s| s.position).collect();
        // Σ K_i (a_i − z₀ − b·p_i) (1, p_i) = (m g, 0, 0).
        let mut m = nalgebra::Matrix3::<f64>::zeros();
        let mut rhs = nalgebra::Vector3::<f64>::zeros();
        for (&(kk, a), p) in lines.iter().zip(&pts) {
            let e = nalgebra::Vector3::new(1.0, p.x, p.y);
            m += kk * e * e.transpose();
            rhs += kk * a * e;
        }
        rhs[0] -= weight;
        let z = m.lu().solve(&rhs)?;
        let mut loads = Vec::with_capacity(pts.len());
        for (&(kk, a), p) in lines.iter().zip(&pts) {
            let zi = z[0] + z[1] * p.x + z[2] * p.y;
            if kk > 0.0 && zi >= self.penetration {
                return None;
            }
            loads.push(kk * (a - zi));
        }
        Some((loads, z[0]))
    }
}

/// |slip| (m/s) of every support at ω, the pusher at the contact point.
fn slip_speeds(body: &Body, push: &Push, omega: f64) -> Vec<f64> {
    let pc = body.contact();
    body.supports()
        .map(|s| {
            let r = s.position - pc;
            (push.velocity() + Vec2::new(-r.y, r.x) * omega).norm()
        })
        .collect()
}

impl crate::FrictionLaw for DrakeConvex {
    fn law_name(&self) -> &'static str {
        match self.approximation {
            Approximation::Sap => {
                "Drake SAP: Coulomb at every foot with the loads of the convex relaxation's lift, glide or hop (pushval_laws::drake)"
            }
            Approximation::Similar => {
                "Drake Similar: Coulomb at every foot with the loads of Hunt-Crossley at v_n - mu|v_t|, glide or hop (pushval_laws::drake)"
            }
        }
    }
    fn steady(&self, problem: &Problem, segment: usize, dt: f64) -> Option<LawSteady> {
        let lift = self.lift(problem, segment, dt)?;
        Some(LawSteady {
            omega: lift.omega,
            class: if lift.omega == 0.0 {
                LawClass::Locked
            } else {
                LawClass::Turns
            },
        })
    }
    /// The glide's loads, or the statics' (the hops' time average).
    fn loads(&self, problem: &Problem, segment: usize, dt: f64) -> Option<Vec<f64>> {
        self.lift(problem, segment, dt).map(|l| l.loads)
    }
    /// The friction stays Coulomb's (μN along −slip, measured to 1e-4 of
    /// the ratio): with the run's loads the law is Coulomb on them.
    fn coulomb_on_run_loads(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FrictionLaw;
    use pushval_model::{Support, Switching};

    /// The paper plate (1 kg, side 0.25 m, μ = 0.5, equal loads) pushed at
    /// its corner at `speed`, φ = π/4 + 0.3.
    fn plate(speed: f64) -> Problem {
        let h = 0.125;
        let supports: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
            .iter()
            .map(|c| Support {
                position: Vec2::new(c[0], c[1]),
                friction: 0.5 * 9.81 / 4.0,
            })
            .collect();
        Problem {
            body: Body::new(1.0, 0.0625 * 2.0 / 12.0, Vec2::new(-h, -h), &supports).unwrap(),
            limits: Default::default(),
            pushes: vec![Push {
                duration: 2.0,
                speed,
                phi: std::f64::consts::FRAC_PI_4 + 0.3,
            }],
            initial: Default::default(),
            switching: Switching::Impulsive,
            sample_dt: 0.01,
            release: None,
        }
    }

    fn soft(approximation: Approximation, tau: f64, d: f64) -> DrakeConvex {
        DrakeConvex {
            approximation,
            penetration: 1e-3,
            relaxation_time: tau,
            dissipation: d,
            gravity: 9.81,
        }
    }

    /// The defaults are critical damping of the bounce at δ = 1e-4 m:
    /// ω_n = sqrt(9.81 / 1e-4) = 313.2 rad/s, τ_d = 6.386 ms, d = 63.86 s/m.
    #[test]
    fn defaults_are_critical() {
        let l = DrakeConvex::new(Approximation::Sap);
        assert!((l.relaxation_time - 6.3855e-3).abs() < 1e-6);
        assert!((l.dissipation - 63.855).abs() < 1e-2);
    }

    /// No lift (τ_d = 0, d = 0, dt → 0): the loads are the rest loads and
    /// ω is Coulomb's.
    #[test]
    fn no_lift_is_coulomb() {
        let p = plate(0.5);
        let star = coulomb_steady(&p, 0).unwrap();
        for a in [Approximation::Sap, Approximation::Similar] {
            let lift = soft(a, 0.0, 0.0).lift(&p, 0, 1e-12).unwrap();
            assert_eq!(lift.regime, Regime::Glide);
            assert!((lift.omega - star).abs() < 1e-9 * star.abs(), "{lift:?}");
            for n in &lift.loads {
                assert!((n - 9.81 / 4.0).abs() < 1e-9, "{lift:?}");
            }
            assert!(lift.rise.abs() < 1e-12, "{lift:?}");
        }
    }

    /// The glide's loads keep the statics (Σ N = m g, no moment about the
    /// centre of mass), move load only in the square's twist pattern
    /// (+, −, +, −), and the plate's rise is the feet's mean lift
    /// ℓ_i = (δt + τ_d) μ |u_i| with |u_i| the slips at the law's ω.
    #[test]
    fn glide_keeps_statics_and_twists() {
        let p = plate(0.5);
        let (dt, tau) = (1e-3, 2e-3);
        let law = soft(Approximation::Sap, tau, 0.0);
        let lift = law.lift(&p, 0, dt).unwrap();
        assert_eq!(lift.regime, Regime::Glide);
        let n = &lift.loads;
        let sum: f64 = n.iter().sum();
        assert!((sum - 9.81).abs() < 1e-9, "{n:?}");
        let (mx, my) = p.body.supports().zip(n).fold((0.0, 0.0), |(x, y), (s, l)| {
            (x + l * s.position.x, y + l * s.position.y)
        });
        assert!(mx.abs() < 1e-9 && my.abs() < 1e-9, "{mx} {my}");
        let dn: Vec<f64> = n.iter().map(|l| l - 9.81 / 4.0).collect();
        assert!((dn[0] + dn[1]).abs() < 1e-9 && (dn[0] - dn[2]).abs() < 1e-9);
        assert!((dn[1] - dn[3]).abs() < 1e-9);
        let v = slip_speeds(&p.body, &p.pushes[0], lift.omega);
        let lifts: Vec<f64> = v.iter().map(|vi| (dt + tau) * 0.5 * vi).collect();
        let k = 9.81 / 4.0 / 1e-3;
        let twist = (lifts[0] - lifts[1] + lifts[2] - lifts[3]) / 4.0;
        assert!(
            (dn[0] - k * twist).abs() < 1e-9,
            "{} vs {}",
            dn[0],
            k * twist
        );
        let mean = lifts.iter().sum::<f64>() / 4.0;
        assert!((lift.rise - mean).abs() < 1e-12, "{} vs {mean}", lift.rise);
    }

    /// The lift grows with the step: the rise is monotonic in dt, and ω
    /// departs further from Coulomb's; past the rest penetration the plate
    /// hops and the law returns Coulomb's ω with the rest loads.
    #[test]
    fn monotonic_in_dt_then_hop() {
        let p = plate(0.5);
        let star = coulomb_steady(&p, 0).unwrap();
        let law = soft(Approximation::Sap, 0.0, 0.0);
        let mut last: Option<Lift> = None;
        for dt in [1e-4, 2.5e-4, 5e-4, 1e-3] {
            let l = law.lift(&p, 0, dt).unwrap();
            assert_eq!(l.regime, Regime::Glide, "dt {dt}");
            if let Some(prev) = &last {
                assert!(l.rise > prev.rise, "dt {dt}");
                assert!(
                    (l.omega - star).abs() > (prev.omega - star).abs(),
                    "dt {dt}"
                );
            }
            last = Some(l);
        }
        // dt = 1e-2 s: the feet's mean lift (δt μ ⟨|u|⟩, ⟨|u|⟩ ≈ 0.45 m/s)
        // is ≈ 2e-3 m > δ = 1e-3 m, so a foot of the plane rises past δ.
        let l = law.lift(&p, 0, 1e-2).unwrap();
        assert_eq!(l.regime, Regime::Hop);
        assert_eq!(l.omega, star);
        assert!(l.rise > 1e-3);
    }

    /// Similar without dissipation lifts as SAP without relaxation (both
    /// δt μ |v_t|): the same law.
    #[test]
    fn similar_without_dissipation_is_sap_without_relaxation() {
        let p = plate(1.0);
        let a = soft(Approximation::Sap, 0.0, 5.0)
            .lift(&p, 0, 5e-4)
            .unwrap();
        let b = soft(Approximation::Similar, 1.0, 0.0)
            .lift(&p, 0, 5e-4)
            .unwrap();
        assert_eq!(a, b);
    }

    /// The launch speed tends to the rigid relaxation's μ v as the contact
    /// stiffens and to 0 with the step (linearly for SAP with τ_d > 0:
    /// c ∝ δt (δt + τ_d)).
    #[test]
    fn launch_speed_limits() {
        for a in [Approximation::Sap, Approximation::Similar] {
            let law = DrakeConvex::new(a);
            let rigid = law.launch_speed(1e12, 0.25, 0.5, 1.0, 1e-3);
            assert!((rigid - 0.5).abs() < 1e-3, "{a:?} {rigid}");
            let small = law.launch_speed(24525.0, 0.25, 0.5, 1.0, 1e-9);
            assert!(small < 1e-5, "{a:?} {small}");
        }
    }

    /// At drake_push.py's defaults on the paper plate the lift
    /// ((δt + τ_d) μ |v_t| ≈ 7e-3 s × 0.2 m/s) is far above δ = 1e-4 m:
    /// the plate hops and the law is Coulomb's.
    #[test]
    fn defaults_hop_on_the_paper_plate() {
        for speed in [0.2, 0.5, 1.0] {
            let p = plate(speed);
            let star = coulomb_steady(&p, 0).unwrap();
            for a in [Approximation::Sap, Approximation::Similar] {
                let law = DrakeConvex::new(a);
                let l = law.lift(&p, 0, 1e-3).unwrap();
                assert_eq!(l.regime, Regime::Hop, "{a:?} {speed}");
                assert_eq!(law.steady(&p, 0, 1e-3).unwrap().omega, star);
            }
        }
    }
}
