use crate::{ModelError, Vec2};

/// One support point: where it is and how hard its friction pulls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Support {
    /// Position in the object frame, relative to the centre of mass (m).
    pub position: Vec2,
    /// Magnitude of the sliding friction force, `μ_i N_i` (N).
    pub friction: f64,
}

/// The pushed object as the models see it: mass, inertia, supports and the
/// contact point, all in the object frame with its origin at the centre of mass.
///
/// Supports are stored as a structure of arrays so the friction loop over
/// thousands of supports vectorises.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    mass: f64,
    inertia_cm: f64,
    contact: Vec2,
    sx: Vec<f64>,
    sy: Vec<f64>,
    friction: Vec<f64>,
}

fn positive(name: &'static str, value: f64) -> Result<f64, ModelError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ModelError::Parameter {
            name,
            requirement: "finite and > 0",
            value,
        })
    }
}

impl Body {
    /// Builds a body. `mass` in kg, `inertia_cm` in kg m² about the centre of
    /// mass, `contact` and support positions in m relative to the centre of mass.
    pub fn new(
        mass: f64,
        inertia_cm: f64,
        contact: Vec2,
        supports: &[Support],
    ) -> Result<Self, ModelError> {
        positive("mass", mass)?;
        positive("inertia_cm", inertia_cm)?;
        if supports.is_empty() {
            return Err(ModelError::NoSupports);
        }
        for c in [contact.x, contact.y] {
            if !c.is_finite() {
                return Err(ModelError::Parameter {
                    name: "contact",
                    requirement: "finite",
                    value: c,
                });
            }
        }
        for s in supports {
            if !(s.position.x.is_finite() && s.position.y.is_finite()) {
                return Err(ModelError::Parameter {
                    name: "support position",
                    requirement: "finite",
                    value: if s.position.x.is_finite() {
                        s.position.y
                    } else {
                        s.position.x
                    },
                });
            }
            if !(s.friction.is_finite() && s.friction >= 0.0) {
                return Err(ModelError::Parameter {
                    name: "support friction",
                    requirement: "finite and >= 0",
                    value: s.friction,
                });
            }
        }
        if supports.iter().all(|s| s.friction == 0.0) {
            return Err(ModelError::Parameter {
                name: "total support friction",
                requirement: "> 0",
                value: 0.0,
            });
        }
        Ok(Self {
            mass,
            inertia_cm,
            contact,
            sx: supports.iter().map(|s| s.position.x).collect(),
            sy: supports.iter().map(|s| s.position.y).collect(),
            friction: supports.iter().map(|s| s.friction).collect(),
        })
    }

    /// Mass (kg).
    pub fn mass(&self) -> f64 {
        self.mass
    }
    /// Moment of inertia about the centre of mass (kg m²).
    pub fn inertia_cm(&self) -> f64 {
        self.inertia_cm
    }
    /// Moment of inertia about the contact point, `I_cm + m |p_c|²` (kg m²).
    pub fn inertia_contact(&self) -> f64 {
        self.inertia_cm + self.mass * self.contact.norm_squared()
    }
    /// Contact point relative to the centre of mass (m).
    pub fn contact(&self) -> Vec2 {
        self.contact
    }
    /// Number of support points.
    pub fn len(&self) -> usize {
        self.sx.len()
    }
    /// Always false: a body has at least one support.
    pub fn is_empty(&self) -> bool {
        self.sx.is_empty()
    }
    /// Support `i`.
    pub fn support(&self, i: usize) -> Support {
        Support {
            position: Vec2::new(self.sx[i], self.sy[i]),
            friction: self.friction[i],
        }
    }
    /// All supports.
    pub fn supports(&self) -> impl Iterator<Item = Support> + '_ {
        (0..self.len()).map(|i| self.support(i))
    }
    /// Sum of the friction magnitudes `Σ μ_i N_i` (N).
    pub fn total_friction(&self) -> f64 {
        self.friction.iter().sum()
    }
    /// Centre of friction `Σ F_i p_i / Σ F_i` relative to the centre of mass (m).
    pub fn center_of_friction(&self) -> Vec2 {
        let f = self.total_friction();
        let x: f64 = self.sx.iter().zip(&self.friction).map(|(x, f)| x * f).sum();
        let y: f64 = self.sy.iter().zip(&self.friction).map(|(y, f)| y * f).sum();
        Vec2::new(x / f, y / f)
    }
    /// The same body with its mass and inertia replaced (support friction unchanged).
    pub fn with_inertia(&self, mass: f64, inertia_cm: f64) -> Result<Self, ModelError> {
        let supports: Vec<Support> = self.supports().collect();
        Self::new(mass, inertia_cm, self.contact, &supports)
    }
    pub(crate) fn arrays(&self) -> (&[f64], &[f64], &[f64]) {
        (&self.sx, &self.sy, &self.friction)
    }
}

/// One piece of the piecewise-constant pusher input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Push {
    /// How long the piece lasts (s), > 0.
    pub duration: f64,
    /// Pusher speed `v_c` (m/s), ≥ 0.
    pub speed: f64,
    /// Push direction φ in the object frame (rad).
    pub phi: f64,
}

impl Push {
    /// Unit push direction `n_φ = (cos φ, sin φ)` in the object frame.
    pub fn direction(&self) -> Vec2 {
        let (s, c) = self.phi.sin_cos();
        Vec2::new(c, s)
    }
    /// Pusher velocity in the object frame, `v_c n_φ` (m/s).
    pub fn velocity(&self) -> Vec2 {
        self.direction() * self.speed
    }
}
