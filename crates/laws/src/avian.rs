//! What `avian3d`'s own contact friction does, in closed form, and the
//! steady ω it predicts.
//!
//! ## Avian's contact friction law
//!
//! Avian 0.7 solves each contact point's friction as one 2-D tangential
//! impulse (`dynamics/solver/contact/tangent_part.rs`, `solve_impulse`).
//! With `s` the point's relative tangential velocity as the solver has it at
//! that moment and `K` the 2×2 inverse effective mass of the two tangent
//! directions, one iteration does
//!
//! ```text
//! λ ← clamp_disk( λ − (|s|² / sᵀK s) s ,  μ λ_n )
//! ```
//!
//! (the increment is along the slip `s` itself, scaled by the Rayleigh
//! quotient of K, not `K⁻¹ s`), in every substep, once in the biased solve
//! and once in the relaxation, warm-started with the previous substep's
//! impulse. While the point slides the disk clamp is active, and a fixed
//! point of the update needs the increment parallel to λ: `λ = −μ λ_n s/|s|`.
//! So the friction of every contact point is **Coulomb's, along −u_i** (the
//! slip velocity the solver leaves: implicit, converging to the body's slip
//! velocity as the substep shrinks), with magnitude μ_i times the point's
//! normal load. This differs from rapier3d's `FrictionModel::Coulomb`, whose
//! update `λ ← clamp(λ − K⁻¹ s)` fixes λ along `−K⁻¹ u` (the stopping
//! impulse of the free body, an idiom of 2-D engines), and from its
//! `Simplified` model. (The increment's size only sets how fast the
//! iteration reaches its fixed point: one increment `m|s|` is hundreds of
//! times the cap `μ λ_n` per substep here, so it is reached at once.)
//!
//! What is left is where the loads `N_i` come from. The floor's contacts are
//! soft: a point's normal impulse per substep is the effective normal mass
//! `m_i = 1/(1/m + (r_i × ẑ)ᵀ I⁻¹ (r_i × ẑ))` times a bias proportional to
//! its penetration (Avian's soft-constraint coefficients are the same for
//! every contact), i.e. the feet are springs of stiffness ∝ `m_i` under a
//! rigid plate, and `N_i = m_i (α + β · r_i)` ([`PlateScene::loads`]). With
//! the pinned point at the centre of mass's height, the moment balance about
//! the centre of mass in the horizontal axes gives the first moment of the
//! loads
//!
//! ```text
//! Σ N_i r_i = −h_cm Σ f_i
//! ```
//!
//! (the pusher's force and the friction, `h_cm` apart, form a couple; the
//! centre of mass's acceleration drops out). So at `h_cm = 0` (the default)
//! the loads are the rest loads, μ_i N_i = F_i, and the steady ω is the
//! Coulomb root ω* of the analytic model; above 0 the steady ω is the root of
//! the moment balance with `F_i = μ_i N_i(ω)`, a fixed point
//! ([`PlateScene::steady`]).
//!
//! ## References
//!
//! avian3d 0.7.0, `src/dynamics/solver/contact/{tangent_part,normal_part,mod}.rs`
//! and `src/dynamics/solver/plugin.rs` (substep loop, warm start, relax).

use pushval_model::{Body, ModelError, Problem, Push, SegmentDynamics, Support, Vec2};

use crate::{FrictionLaw, LawClass, LawSteady};

/// The plain parameters of the `avian3d` scene the closed forms need (the
/// adapter's `Avian3dSettings` convert into them). Defaults are the
/// adapter's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlateParams {
    /// Plate thickness (m) for the tilt inertia; default `0.005`.
    pub plate_thickness: f64,
    /// Gravity (m/s²); default 9.81.
    pub gravity: f64,
    /// Height of the centre of mass (and of the pinned point) above the
    /// floor (m, ≥ 0); default 0.
    pub cm_height: f64,
}

impl Default for PlateParams {
    fn default() -> Self {
        Self {
            plate_thickness: 0.005,
            gravity: 9.81,
            cm_height: 0.0,
        }
    }
}

/// Tilt inertia of a thin plate (kg m²): `I_cm/2 + m t²/12`, each horizontal
/// axis (perpendicular-axis theorem for the plate's area, plus its
/// thickness `t`).
pub fn tilt_inertia(inertia_cm: f64, mass: f64, thickness: f64) -> f64 {
    inertia_cm / 2.0 + mass * thickness * thickness / 12.0
}

/// The plate of the `avian3d` scene as the closed forms see it.
#[derive(Debug, Clone, PartialEq)]
pub struct PlateScene {
    /// Mass (kg).
    pub mass: f64,
    /// Vertical-axis inertia about the centre of mass (kg m²).
    pub inertia_cm: f64,
    /// Tilt inertia, each horizontal axis (kg m²).
    pub tilt_inertia: f64,
    /// Contact point in the object frame (m).
    pub contact: [f64; 2],
    /// Support positions in the object frame, relative to the centre of
    /// mass (m).
    pub points: Vec<[f64; 2]>,
    /// Each foot's friction coefficient, `F_i / N_i` at rest.
    pub mu: Vec<f64>,
    /// Weight `m g` (N).
    pub weight: f64,
    /// Height of the centre of mass (and of the pinned point) above the
    /// floor (m).
    pub cm_height: f64,
}

impl PlateScene {
    /// The scene the adapter builds for `problem` under `settings` (the
    /// adapter's settings or [`PlateParams`]), with the μ_i it would
    /// calibrate if the rest loads are [`Self::rest_loads`]. Errors when a
    /// support with friction would carry no load at rest.
    pub fn new(problem: &Problem, settings: impl Into<PlateParams>) -> Result<Self, ModelError> {
        let settings: PlateParams = settings.into();
        let body = &problem.body;
        let mut scene = Self {
            mass: body.mass(),
            inertia_cm: body.inertia_cm(),
            tilt_inertia: tilt_inertia(body.inertia_cm(), body.mass(), settings.plate_thickness),
            contact: [body.contact().x, body.contact().y],
            points: body
                .supports()
                .map(|s| [s.position.x, s.position.y])
                .collect(),
            mu: Vec::new(),
            weight: body.mass() * settings.gravity,
            cm_height: settings.cm_height,
        };
        let rest = scene.rest_loads().ok_or(ModelError::Parameter {
            name: "avian3d supports (rest loads of a plate on them)",
            requirement: "not all on one line",
            value: scene.points.len() as f64,
        })?;
        for (s, n) in body.supports().zip(rest) {
            if s.friction > 0.0 && !(n > 0.0) {
                return Err(ModelError::Parameter {
                    name: "avian3d rest load of a support with friction",
                    requirement: "> 0",
                    value: n,
                });
            }
            scene.mu.push(if n > 0.0 { s.friction / n } else { 0.0 });
        }
        Ok(scene)
    }

    /// Each foot's effective normal mass `1/(1/m + y_i²/I_t + x_i²/I_t)`
    /// (kg): the stiffness of its soft contact, up to a factor common to all.
    pub fn stiffness(&self) -> Vec<f64> {
        self.points
            .iter()
            .map(|p| 1.0 / (1.0 / self.mass + (p[0] * p[0] + p[1] * p[1]) / self.tilt_inertia))
            .collect()
    }

    /// The normal loads (N) of the rigid plate on springs of
    /// [`Self::stiffness`] with `Σ N_i = m g` and first moment
    /// `Σ N_i r_i = moment` (N m, object frame): `N_i = k_i (α + β · r_i)`.
    /// None when the supports lie on one line (the system is singular).
    pub fn loads(&self, moment: [f64; 2]) -> Option<Vec<f64>> {
        let k = self.stiffness();
        // Normal equations of N_i = k_i (α + β_x x_i + β_y y_i).
        let mut a = [[0.0; 3]; 3];
        for (p, &ki) in self.points.iter().zip(&k) {
            let v = [1.0, p[0], p[1]];
            for r in 0..3 {
                for c in 0..3 {
                    a[r][c] += ki * v[r] * v[c];
                }
            }
        }
        let x = solve3(a, [self.weight, moment[0], moment[1]])?;
        Some(
            self.points
                .iter()
                .zip(&k)
                .map(|(p, ki)| ki * (x[0] + x[1] * p[0] + x[2] * p[1]))
                .collect(),
        )
    }

    /// The loads at rest (no horizontal force): [`Self::loads`] of a zero
    /// moment.
    pub fn rest_loads(&self) -> Option<Vec<f64>> {
        self.loads([0.0, 0.0])
    }

    /// The planar body whose support friction is `μ_i N_i` for the given
    /// loads.
    pub fn body(&self, loads: &[f64]) -> Result<Body, ModelError> {
        let supports: Vec<Support> = self
            .points
            .iter()
            .zip(&self.mu)
            .zip(loads)
            .map(|((p, mu), n)| Support {
                position: Vec2::new(p[0], p[1]),
                friction: mu * n.max(0.0),
            })
            .collect();
        Body::new(
            self.mass,
            self.inertia_cm,
            Vec2::new(self.contact[0], self.contact[1]),
            &supports,
        )
    }

    /// The steady ω (rad/s) a push settles on, starting from ω = `from`, and
    /// the loads there: the fixed point of "loads from the couple of the
    /// friction at ω" and "ω the stable root the loads give" (the Coulomb
    /// root ω* when `cm_height` is 0). None when the iteration finds no
    /// stable root or does not settle within 200 rounds.
    pub fn steady(&self, push: &Push, from: f64) -> Option<(f64, Vec<f64>)> {
        let mut loads = self.rest_loads()?;
        let mut omega = from;
        for _ in 0..200 {
            let body = self.body(&loads).ok()?;
            let dynamics = SegmentDynamics::new(&body, push);
            let root = dynamics.attractor_from(omega)?;
            if !root.is_stable() {
                return None;
            }
            let f = dynamics.friction_force(root.omega);
            let h = self.cm_height;
            let next = self.loads([-h * f.x, -h * f.y])?;
            let settled = (root.omega - omega).abs() <= 1e-13 * (1.0 + omega.abs())
                && next
                    .iter()
                    .zip(&loads)
                    .all(|(a, b)| (a - b).abs() <= 1e-12 * self.weight);
            omega = root.omega;
            loads = next;
            if settled {
                return Some((omega, loads));
            }
        }
        None
    }
}

/// Solves the 3×3 system `a x = b` by Gaussian elimination with partial
/// pivoting; None when it is singular (relative to its largest entry).
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    let scale = a
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    for col in 0..3 {
        let piv = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() <= 1e-12 * scale {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        let pivot = a[col];
        for r in col + 1..3 {
            let f = a[r][col] / pivot[col];
            for (x, p) in a[r][col..].iter_mut().zip(&pivot[col..]) {
                *x -= f * p;
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for r in (0..3).rev() {
        let s: f64 = (r + 1..3).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

/// avian3d's contact friction in closed form: Coulomb along −u at every
/// foot with the loads of its soft contacts, coupled to the forces when the
/// centre of mass is above the floor ([`PlateScene::steady`] from ω = 0).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Avian3dTilt {
    /// The scene's parameters.
    pub plate: PlateParams,
}

impl FrictionLaw for Avian3dTilt {
    fn law_name(&self) -> &'static str {
        "Coulomb along −u at every foot with the soft contacts' loads, load transfer above the floor (pushval_avian::predict)"
    }
    fn steady(&self, problem: &Problem, segment: usize, _dt: f64) -> Option<LawSteady> {
        let push = problem.pushes.get(segment)?;
        let scene = PlateScene::new(problem, self.plate).ok()?;
        let (omega, _) = scene.steady(push, 0.0)?;
        Some(LawSteady {
            omega,
            class: LawClass::Turns,
        })
    }
    /// The feet's loads (N) at the steady state: the rest loads of the soft
    /// contacts (`m g` shared as springs ∝ effective mass: statics for three
    /// feet) moved by the couple `−h_cm Σ f_i` of the friction
    /// ([`PlateScene::steady`]).
    fn loads(&self, problem: &Problem, segment: usize, _dt: f64) -> Option<Vec<f64>> {
        let push = problem.pushes.get(segment)?;
        let scene = PlateScene::new(problem, self.plate).ok()?;
        scene.steady(push, 0.0).map(|(_, loads)| loads)
    }
    /// Coulomb along −u at every foot with the given loads.
    fn coulomb_on_run_loads(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(h: f64) -> PlateScene {
        let a = 0.125;
        PlateScene {
            mass: 1.0,
            inertia_cm: 0.25 * 0.25 / 6.0,
            tilt_inertia: tilt_inertia(0.25 * 0.25 / 6.0, 1.0, 0.005),
            contact: [-a, -a],
            points: vec![[-a, -a], [a, -a], [a, a], [-a, a]],
            mu: vec![0.5; 4],
            weight: 9.81,
            cm_height: h,
        }
    }

    /// Four symmetric feet: equal loads at rest; a first moment `Σ N x = M`
    /// adds `±M/(4 a)` to the feet at x = ±a (`N_i = W/4 + β x_i`,
    /// `β Σ x_i² = 4 a² β = M`).
    #[test]
    fn square_loads_are_statics() {
        let s = square(0.0);
        let rest = s.rest_loads().unwrap();
        for n in &rest {
            assert!((n - 9.81 / 4.0).abs() < 1e-12);
        }
        let m = 0.04;
        let l = s.loads([m, 0.0]).unwrap();
        let a = 0.125;
        let dn = m / (4.0 * a);
        let expected = [
            9.81 / 4.0 - dn,
            9.81 / 4.0 + dn,
            9.81 / 4.0 + dn,
            9.81 / 4.0 - dn,
        ];
        for (n, e) in l.iter().zip(expected) {
            assert!((n - e).abs() < 1e-12, "{n} {e}");
        }
        let first: f64 = l.iter().zip(&s.points).map(|(n, p)| n * p[0]).sum();
        assert!((first - m).abs() < 1e-12);
    }

    /// At h_cm = 0 the prediction is the Coulomb root of the analytic model.
    #[test]
    fn flat_plate_predicts_the_coulomb_root() {
        let s = square(0.0);
        let push = Push {
            duration: 1.0,
            speed: 0.5,
            phi: std::f64::consts::FRAC_PI_4 + 0.3,
        };
        let (w, _) = s.steady(&push, 0.0).unwrap();
        let body = s.body(&s.rest_loads().unwrap()).unwrap();
        let star = SegmentDynamics::new(&body, &push)
            .attractor_from(0.0)
            .unwrap();
        assert!((w - star.omega).abs() < 1e-12, "{w} {}", star.omega);
    }

    /// Collinear supports: no plate stands on them.
    #[test]
    fn collinear_supports_have_no_loads() {
        let mut s = square(0.0);
        s.points = vec![[-0.1, 0.0], [0.0, 0.0], [0.1, 0.0]];
        s.mu = vec![0.5; 3];
        assert!(s.loads([0.0, 0.0]).is_none());
    }
}
