//! Model errors injected into the dynamic model: the perturbed trajectory a
//! wrong model would give (I_cm or a μ scaled, the centre of friction moved,
//! the switching rule or the friction law changed, the time shifted). The
//! gate's sensitivity estimate (`harness::catchable`) and `pushval power`'s
//! bisection both perturb through here.

use pushval_model::{DynamicModel, Integrator, Simulator, Switching, Trajectory, Vec2};
use pushval_scenario::Scenario;

pub mod law;

/// The dynamic model's default tolerance, as the gate runs it (the default
/// of `harness::RunOptions::model_tol`, dimensionless per-step error).
pub const MODEL_TOL: f64 = 1e-10;

/// A kind of model error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// I_cm scaled by 1 + m.
    InertiaCm,
    /// Every support's μ scaled by 1 + m.
    MuAll,
    /// μ of the support farthest from the contact scaled by 1 + m (a
    /// support under the contact point has no moment about it and changes
    /// nothing but the pusher force).
    MuOne,
    /// The normal loads redistributed (least change) to move the centre of
    /// friction by m (m) along the object's x axis.
    CenterOfFriction,
    /// The contact point moved by m (m) along the polygon edge it lies on.
    ContactOffset,
    /// The centre of mass moved by m (m) along the object's x axis.
    CmOffset,
    /// Every push direction φ biased by m (rad).
    PhiBias,
    /// Continuous instead of impulsive switching (binary).
    Switching,
    /// The support friction direction blended towards −K⁻¹u with weight m
    /// ([`law`]; m = 1 is the game-engine law).
    KinvLaw,
    /// The trajectory's clock shifted by m (s).
    TimeShift,
}

impl ErrorKind {
    /// Every kind, in output order.
    pub const ALL: [ErrorKind; 10] = [
        ErrorKind::InertiaCm,
        ErrorKind::MuAll,
        ErrorKind::MuOne,
        ErrorKind::CenterOfFriction,
        ErrorKind::ContactOffset,
        ErrorKind::CmOffset,
        ErrorKind::PhiBias,
        ErrorKind::Switching,
        ErrorKind::KinvLaw,
        ErrorKind::TimeShift,
    ];
    /// The name in the CSV.
    pub fn name(self) -> &'static str {
        match self {
            ErrorKind::InertiaCm => "inertia_cm",
            ErrorKind::MuAll => "mu_all",
            ErrorKind::MuOne => "mu_one_support",
            ErrorKind::CenterOfFriction => "center_of_friction",
            ErrorKind::ContactOffset => "contact_offset",
            ErrorKind::CmOffset => "cm_offset",
            ErrorKind::PhiBias => "phi_bias",
            ErrorKind::Switching => "continuous_switching",
            ErrorKind::KinvLaw => "kinv_friction_law",
            ErrorKind::TimeShift => "time_shift",
        }
    }
    /// The magnitude's unit.
    pub fn unit(self) -> &'static str {
        match self {
            ErrorKind::InertiaCm | ErrorKind::MuAll | ErrorKind::MuOne => "relative",
            ErrorKind::CenterOfFriction | ErrorKind::ContactOffset | ErrorKind::CmOffset => "m",
            ErrorKind::PhiBias => "rad",
            ErrorKind::Switching => "binary",
            ErrorKind::KinvLaw => "blend weight",
            ErrorKind::TimeShift => "s",
        }
    }
    /// The magnitudes searched, smallest and largest.
    pub fn range(self) -> (f64, f64) {
        match self {
            ErrorKind::InertiaCm | ErrorKind::MuAll | ErrorKind::MuOne => (1e-6, 0.5),
            ErrorKind::CenterOfFriction | ErrorKind::ContactOffset | ErrorKind::CmOffset => {
                (1e-7, 0.02)
            }
            ErrorKind::PhiBias => (1e-7, 0.2),
            ErrorKind::Switching => (1.0, 1.0),
            ErrorKind::KinvLaw => (1e-6, 1.0),
            ErrorKind::TimeShift => (1e-6, 0.5),
        }
    }
    /// The target: the default gate must catch this magnitude.
    pub fn target(self) -> Option<f64> {
        match self {
            ErrorKind::InertiaCm | ErrorKind::MuAll => Some(0.005),
            ErrorKind::ContactOffset | ErrorKind::CenterOfFriction => Some(5e-4),
            _ => None,
        }
    }
    /// Whether the kind has a sign (binary and blend kinds have one side).
    pub fn signed(self) -> bool {
        !matches!(self, ErrorKind::Switching | ErrorKind::KinvLaw)
    }
}

/// The model the harness runs (the gate's reference), for perturbed problems.
fn model() -> DynamicModel {
    DynamicModel {
        integrator: Integrator::Dop853 { tol: MODEL_TOL },
        ..Default::default()
    }
}

/// Least-change redistribution of the support friction magnitudes
/// `F_i = μ_i N_i` that moves their centre by `shift` (object frame, m) and
/// keeps their sum: `ΔF = Aᵀ (A Aᵀ)⁺ b` with rows `1`, `x_i`, `y_i`.
fn shift_center_of_friction(sc: &mut Scenario, shift: Vec2) -> Option<()> {
    let n = sc.supports.len();
    let f: Vec<f64> = sc.supports.iter().map(|s| s.mu * s.load).collect();
    let total: f64 = f.iter().sum();
    let a = nalgebra::DMatrix::from_fn(3, n, |r, c| match r {
        0 => 1.0,
        1 => sc.supports[c].position.x,
        _ => sc.supports[c].position.y,
    });
    let b = nalgebra::DVector::from_vec(vec![0.0, total * shift.x, total * shift.y]);
    let aat = &a * a.transpose();
    let y = aat.pseudo_inverse(1e-14).ok()? * b;
    let df = a.transpose() * y;
    for (s, (fi, d)) in sc.supports.iter_mut().zip(f.iter().zip(df.iter())) {
        let fnew = fi + d;
        if !(fnew > 0.0) {
            return None;
        }
        s.load = fnew / s.mu;
    }
    Some(())
}

/// Unit tangent of the polygon edge nearest the contact point.
fn contact_tangent(sc: &Scenario) -> Vec2 {
    let p = sc.contact;
    let n = sc.polygon.len();
    let mut best = (f64::INFINITY, Vec2::new(1.0, 0.0));
    for k in 0..n {
        let (a, b) = (sc.polygon[k], sc.polygon[(k + 1) % n]);
        let e = b - a;
        let s = ((p - a).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
        let d = (a + s * e - p).norm();
        if d < best.0 - 1e-12 {
            best = (d, e / e.norm());
        }
    }
    best.1
}

/// The model's trajectory with error `kind` of magnitude `m` (signed) injected;
/// None where the error cannot be made (e.g. a load would turn negative).
pub fn inject(sc: &Scenario, kind: ErrorKind, m: f64) -> Option<Trajectory> {
    let mut s = sc.clone();
    match kind {
        ErrorKind::InertiaCm => s.inertia_cm *= 1.0 + m,
        ErrorKind::MuAll => s.supports.iter_mut().for_each(|p| p.mu *= 1.0 + m),
        ErrorKind::MuOne => {
            let far = (0..s.supports.len())
                .max_by(|&a, &b| {
                    let d = |i: usize| (s.supports[i].position - s.contact).norm();
                    d(a).total_cmp(&d(b))
                })
                .expect("a scenario has supports");
            s.supports[far].mu *= 1.0 + m;
        }
        ErrorKind::CenterOfFriction => shift_center_of_friction(&mut s, Vec2::new(m, 0.0))?,
        ErrorKind::ContactOffset => s.contact += m * contact_tangent(sc),
        ErrorKind::CmOffset => s.center_of_mass += Vec2::new(m, 0.0),
        ErrorKind::PhiBias => s.pushes.iter_mut().for_each(|p| p.phi += m),
        ErrorKind::Switching => {
            s.switching = match sc.switching {
                Switching::Impulsive => Switching::Continuous,
                Switching::Continuous => Switching::Impulsive,
            }
        }
        ErrorKind::KinvLaw => return Some(law::simulate(&sc.problem(), m)),
        ErrorKind::TimeShift => return Some(time_shifted(sc, m)),
    }
    if !(s.inertia_cm > 0.0) || s.supports.iter().any(|p| !(p.mu > 0.0)) {
        return None;
    }
    model().simulate(&s.problem()).ok()
}

/// The model's trajectory seen through a clock shifted by `delay` (s):
/// `X(t − delay)`, the state at t = 0 held before it. Sampled from a run 20
/// times finer than the scenario's samples (linear interpolation error below
/// 1e-7 m on the shipped scenes).
fn time_shifted(sc: &Scenario, delay: f64) -> Trajectory {
    let mut problem = sc.problem();
    let times = problem.sample_times();
    if let Some(last) = problem.pushes.last_mut() {
        last.duration += delay.abs();
    }
    problem.sample_dt = sc.sample_dt / 20.0;
    let fine = model().simulate(&problem).expect("the model runs");
    let at = |t: f64| {
        let t = t.max(0.0);
        let k = fine
            .samples
            .partition_point(|s| s.t <= t)
            .clamp(1, fine.samples.len() - 1);
        let (a, b) = (&fine.samples[k - 1], &fine.samples[k]);
        let u = if b.t > a.t {
            (t - a.t) / (b.t - a.t)
        } else {
            0.0
        };
        let l = |p: f64, q: f64| p + u * (q - p);
        pushval_model::Sample {
            t,
            x: l(a.x, b.x),
            y: l(a.y, b.y),
            theta: l(a.theta, b.theta),
            omega: l(a.omega, b.omega),
        }
    };
    let samples = times
        .iter()
        .map(|&t| pushval_model::Sample { t, ..at(t - delay) })
        .collect();
    let mut reference = model().simulate(&sc.problem()).expect("the model runs");
    reference.samples = samples;
    reference.model = format!("time_shift[{delay}]");
    reference
}
