//! The parameters `pushval fit` can estimate, and how a value of each turns
//! the scenario into the problem the model runs.

use pushval_model::{Body, Problem, Support, Vec2};
use pushval_scenario::Scenario;

/// One estimable parameter of a scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Param {
    /// `[x, y]` (m, the file's object frame): the centre of friction
    /// `Σ μ_i N_i p_i / Σ μ_i N_i`. Moving it changes the normal loads to the
    /// least-change loads (least squares in N) that keep `Σ N_i` and put the
    /// centre of friction there; loads that would turn negative are refused.
    CenterOfFriction,
    /// `[dx, dy]` (m, object frame): offset of the contact point from the
    /// file's `contact.point` (`[0, 0]` = as in the file).
    Contact,
    /// Inertia about the centre of mass (kg m²).
    InertiaCm,
    /// A factor on every support's μ (1 = as in the file).
    MuScale,
}

impl Param {
    /// Every parameter, in the order outputs list them (alphabetical by name).
    pub const ALL: [Param; 4] = [
        Param::CenterOfFriction,
        Param::Contact,
        Param::InertiaCm,
        Param::MuScale,
    ];

    /// The name on the command line and in `fit.json`.
    pub fn name(self) -> &'static str {
        match self {
            Param::CenterOfFriction => "center_of_friction",
            Param::Contact => "contact",
            Param::InertiaCm => "inertia_cm",
            Param::MuScale => "mu_scale",
        }
    }

    /// The parameter called `name`, if any.
    pub fn from_name(name: &str) -> Option<Param> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// Number of scalar components (2 for the vector parameters).
    pub fn dim(self) -> usize {
        match self {
            Param::CenterOfFriction | Param::Contact => 2,
            Param::InertiaCm | Param::MuScale => 1,
        }
    }

    /// Unit of each component, for messages and tables.
    pub fn unit(self) -> &'static str {
        match self {
            Param::CenterOfFriction | Param::Contact => "m",
            Param::InertiaCm => "kg m^2",
            Param::MuScale => "1",
        }
    }
}

/// Parses `NAME[,NAME...]`: known names, no repeats; returned in
/// [`Param::ALL`] order (the order of `fit.json` and its covariance).
pub fn parse_list(list: &str) -> Result<Vec<Param>, String> {
    let mut out = Vec::new();
    for name in list.split(',').map(str::trim) {
        let Some(p) = Param::from_name(name) else {
            let known: Vec<&str> = Param::ALL.iter().map(|p| p.name()).collect();
            return Err(format!(
                "unknown parameter `{name}` (known: {})",
                known.join(", ")
            ));
        };
        if out.contains(&p) {
            return Err(format!("parameter `{name}` is named twice"));
        }
        out.push(p);
    }
    out.sort();
    Ok(out)
}

/// The scenario as the fit sees it: everything fixed except the chosen
/// parameters, whose values live in one flat vector (each parameter's
/// components in turn, parameters in [`Param::ALL`] order).
#[derive(Debug, Clone)]
pub struct Parametrised {
    params: Vec<Param>,
    base: Problem,
    /// Support positions relative to the centre of mass (m).
    positions: Vec<Vec2>,
    mu: Vec<f64>,
    /// Normal loads as in the file (N).
    loads: Vec<f64>,
    /// The file's contact point relative to the centre of mass (m).
    contact: Vec2,
    center_of_mass: Vec2,
    mass: f64,
    inertia_cm: f64,
    /// Size of the body (m): the scale of the vector parameters.
    size: f64,
}

/// Why a parameter value gives no problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Invalid(pub String);

impl std::fmt::Display for Invalid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl Parametrised {
    /// The scenario with `params` free. Refuses `center_of_friction` when the
    /// supports cannot move it (fewer than three, or all on one line).
    pub fn new(sc: &Scenario, params: &[Param]) -> Result<Self, String> {
        let mut params = params.to_vec();
        params.sort();
        params.dedup();
        let positions: Vec<Vec2> = sc
            .supports
            .iter()
            .map(|s| s.position - sc.center_of_mass)
            .collect();
        let size = positions
            .iter()
            .map(|p| p.norm())
            .chain(std::iter::once((sc.contact - sc.center_of_mass).norm()))
            .fold(0.0f64, f64::max)
            .max(1e-3);
        let me = Self {
            params,
            base: sc.problem(),
            positions,
            mu: sc.supports.iter().map(|s| s.mu).collect(),
            loads: sc.supports.iter().map(|s| s.load).collect(),
            contact: sc.contact - sc.center_of_mass,
            center_of_mass: sc.center_of_mass,
            mass: sc.mass,
            inertia_cm: sc.inertia_cm,
            size,
        };
        if me.params.contains(&Param::CenterOfFriction) {
            let c = me.file_center_of_friction();
            if shift_matrix(&me.positions, &me.mu, c).is_none() {
                return Err(
                    "center_of_friction needs at least three supports with friction, not all on one line"
                        .into(),
                );
            }
        }
        Ok(me)
    }

    /// The free parameters, in [`Param::ALL`] order.
    pub fn params(&self) -> &[Param] {
        &self.params
    }

    /// Number of scalar components.
    pub fn dim(&self) -> usize {
        self.params.iter().map(|p| p.dim()).sum()
    }

    /// `(parameter, component)` of every scalar slot.
    pub fn slots(&self) -> Vec<(Param, usize)> {
        Self::slots_of(&self.params)
    }

    /// The slots of `params` (in the order given; a fit sorts them first).
    pub fn slots_of(params: &[Param]) -> Vec<(Param, usize)> {
        params
            .iter()
            .flat_map(|&p| (0..p.dim()).map(move |k| (p, k)))
            .collect()
    }

    /// The values the file gives (the start of a fit).
    pub fn file_values(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(self.dim());
        for p in &self.params {
            match p {
                Param::CenterOfFriction => {
                    let c = self.file_center_of_friction() + self.center_of_mass;
                    v.extend([c.x, c.y]);
                }
                Param::Contact => v.extend([0.0, 0.0]),
                Param::InertiaCm => v.push(self.inertia_cm),
                Param::MuScale => v.push(1.0),
            }
        }
        v
    }

    /// A typical magnitude of each slot: the finite-difference step and the
    /// identifiability test are relative to it. μ scale: 1; inertia: the
    /// file's; positions: the distance of the farthest support or contact
    /// from the centre of mass.
    pub fn scales(&self) -> Vec<f64> {
        self.slots()
            .iter()
            .map(|(p, _)| match p {
                Param::CenterOfFriction | Param::Contact => self.size,
                Param::InertiaCm => self.inertia_cm,
                Param::MuScale => 1.0,
            })
            .collect()
    }

    /// Centre of friction of the file's loads, relative to the centre of mass.
    fn file_center_of_friction(&self) -> Vec2 {
        let mut f = 0.0;
        let mut m = Vec2::zeros();
        for ((p, mu), n) in self.positions.iter().zip(&self.mu).zip(&self.loads) {
            f += mu * n;
            m += p * (mu * n);
        }
        m / f
    }

    /// The problem for the parameter values `values` (one per slot).
    pub fn problem(&self, values: &[f64]) -> Result<Problem, Invalid> {
        assert_eq!(values.len(), self.dim(), "one value per parameter slot");
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(Invalid(format!("parameter value {v} is not finite")));
        }
        let mut mu_scale = 1.0;
        let mut inertia = self.inertia_cm;
        let mut contact = self.contact;
        let mut loads = std::borrow::Cow::Borrowed(&self.loads);
        let mut i = 0;
        for p in &self.params {
            match p {
                Param::CenterOfFriction => {
                    let c = Vec2::new(values[i], values[i + 1]) - self.center_of_mass;
                    loads = std::borrow::Cow::Owned(shifted_loads(
                        &self.positions,
                        &self.mu,
                        &self.loads,
                        c,
                    )?);
                }
                Param::Contact => contact += Vec2::new(values[i], values[i + 1]),
                Param::InertiaCm => inertia = values[i],
                Param::MuScale => mu_scale = values[i],
            }
            i += p.dim();
        }
        if !(mu_scale > 0.0) {
            return Err(Invalid(format!("mu_scale {mu_scale} is not > 0")));
        }
        if !(inertia > 0.0) {
            return Err(Invalid(format!("inertia_cm {inertia} is not > 0")));
        }
        let supports: Vec<Support> = self
            .positions
            .iter()
            .zip(&self.mu)
            .zip(loads.iter())
            .map(|((&position, mu), n)| Support {
                position,
                friction: mu_scale * mu * n,
            })
            .collect();
        let body = Body::new(self.mass, inertia, contact, &supports)
            .map_err(|e| Invalid(e.to_string()))?;
        Ok(Problem {
            body,
            ..self.base.clone()
        })
    }
}

/// The 3×3 matrix `A Aᵀ` of the load-shift constraints for centre `c`
/// (relative to the centre of mass) and its inverse; None when singular.
fn shift_matrix(positions: &[Vec2], mu: &[f64], c: Vec2) -> Option<[[f64; 3]; 3]> {
    let rows = constraint_rows(positions, mu, c);
    let mut m = [[0.0; 3]; 3];
    for r in &rows {
        for a in 0..3 {
            for b in 0..3 {
                m[a][b] += r[a] * r[b];
            }
        }
    }
    invert3(&m)
}

/// Column `i` of the constraint matrix `A` (3 × n): `Σ N_i` kept, and the
/// friction moment about `c` zero, `Σ μ_i N_i (p_i − c) = 0`.
fn constraint_rows(positions: &[Vec2], mu: &[f64], c: Vec2) -> Vec<[f64; 3]> {
    positions
        .iter()
        .zip(mu)
        .map(|(p, mu)| [1.0, mu * (p.x - c.x), mu * (p.y - c.y)])
        .collect()
}

/// The least-change normal loads with the same total and their centre of
/// friction at `c` (relative to the centre of mass):
/// `N' = N + Aᵀ (A Aᵀ)⁻¹ (b − A N)`, the minimum of `Σ (N'_i − N_i)²` under
/// `A N' = b`. With one μ for every support this is the statics-like
/// least-norm shift of the centre of pressure. Err when a load would be
/// negative or the constraints are singular.
pub fn shifted_loads(
    positions: &[Vec2],
    mu: &[f64],
    loads: &[f64],
    c: Vec2,
) -> Result<Vec<f64>, Invalid> {
    let rows = constraint_rows(positions, mu, c);
    let inv = shift_matrix(positions, mu, c).ok_or_else(|| {
        Invalid("the supports cannot carry a centre of friction (singular)".into())
    })?;
    let total: f64 = loads.iter().sum();
    let mut resid = [total, 0.0, 0.0];
    for (r, n) in rows.iter().zip(loads) {
        for a in 0..3 {
            resid[a] -= r[a] * n;
        }
    }
    let mut y = [0.0; 3];
    for a in 0..3 {
        for b in 0..3 {
            y[a] += inv[a][b] * resid[b];
        }
    }
    let out: Vec<f64> = rows
        .iter()
        .zip(loads)
        .map(|(r, n)| n + r[0] * y[0] + r[1] * y[1] + r[2] * y[2])
        .collect();
    if let Some((i, n)) = out.iter().enumerate().find(|(_, n)| !(**n >= 0.0)) {
        return Err(Invalid(format!(
            "centre of friction ({:.4}, {:.4}) m (from the centre of mass) would need load {n:.4} N on support {}",
            c.x,
            c.y,
            i + 1
        )));
    }
    Ok(out)
}

fn invert3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c = |r: usize, s: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (s1, s2) = ((s + 1) % 3, (s + 2) % 3);
        m[r1][s1] * m[r2][s2] - m[r1][s2] * m[r2][s1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let scale = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    if !(det.abs() > 1e-12 * scale.powi(3)) {
        return None;
    }
    let mut inv = [[0.0; 3]; 3];
    for (r, row) in inv.iter_mut().enumerate() {
        for (s, v) in row.iter_mut().enumerate() {
            // Inverse = adjugate / det, adjugate = transposed cofactors.
            *v = c(s, r) / det;
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifted_loads_meet_the_constraints_and_leave_a_met_centre_alone() {
        let a = 0.125;
        let p = [
            Vec2::new(-a, -a),
            Vec2::new(a, -a),
            Vec2::new(a, a),
            Vec2::new(-a, a),
        ];
        let mu = [0.5, 0.4, 0.5, 0.6];
        let n = [2.0, 2.5, 3.0, 2.31];
        let c = Vec2::new(0.02, -0.01);
        let s = shifted_loads(&p, &mu, &n, c).unwrap();
        let total: f64 = s.iter().sum();
        assert!((total - n.iter().sum::<f64>()).abs() < 1e-12);
        let f: f64 = s.iter().zip(&mu).map(|(n, m)| n * m).sum();
        let mx: f64 = (0..4).map(|i| s[i] * mu[i] * p[i].x).sum::<f64>() / f;
        let my: f64 = (0..4).map(|i| s[i] * mu[i] * p[i].y).sum::<f64>() / f;
        assert!((mx - c.x).abs() < 1e-12 && (my - c.y).abs() < 1e-12);
        // Shifting to where it already is changes nothing.
        let again = shifted_loads(&p, &mu, &s, c).unwrap();
        for (x, y) in again.iter().zip(&s) {
            assert!((x - y).abs() < 1e-12);
        }
        // Outside the support polygon: refused.
        assert!(shifted_loads(&p, &mu, &n, Vec2::new(0.2, 0.0)).is_err());
    }
}
