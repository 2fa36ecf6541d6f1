//! `pushval fit`: estimates parameters of a scenario from a measured (or
//! computed) trajectory, and `pushval fit-study`: how well a push of a given
//! speed, duration and number of segments determines them.
//!
//! # Method
//!
//! Levenberg–Marquardt (the `levenberg-marquardt` crate, a port of MINPACK's
//! `lmder`) on whitened residuals: per sample, `(x_m − x_d)/σ_p`,
//! `(y_m − y_d)/σ_p` and `(θ_m − θ_d)/σ_θ`, with the stated noise levels
//! `σ_p` (default 1 mm) and `σ_θ` (default 1 mrad) — θ weighs as a length of
//! `σ_p/σ_θ` (1 m by default). The model is the dynamic model's fast
//! trajectory (DOP853, tolerance [`Settings::tolerance`], the settled-segment
//! series on). The Jacobian is by central differences with step
//! `h_j = 1e-5 × scale_j` ([`Parametrised::scales`]). The fit starts from
//! the file's values ([`Parametrised::file_values`]) and stops on MINPACK's
//! tests with `ftol = 1e-10` (relative reduction of the sum of squares),
//! `xtol = 1e-8` (relative step) and `gtol = 1e-12`; a stop because no step
//! can improve in floating point also counts as converged. Parameter values
//! outside their domain (μ scale or inertia ≤ 0, a load shift that needs a
//! negative load) give NaN residuals, which the solver rejects as a step.
//!
//! Uncertainty: `cov = s² (JᵀJ)⁻¹` with `J` the whitened Jacobian at the
//! estimate and `s² = |r|² / (3K − n)` from the residual (K samples, n
//! parameter components), so the reported std does not trust the stated
//! noise levels, only their ratio.
//!
//! # Identifiability
//!
//! From the Fisher information `F = JᵀJ` (whitened, so at the stated noise)
//! in units of each component's scale, `F̃ = S F S`, `S = diag(scale_j)`,
//! a component is unidentifiable when
//!
//! 1. its information is below [`NO_INFORMATION`] (1e-10) of the largest
//!    diagonal entry of `F̃` (the trajectory does not depend on it), or
//! 2. the correlation matrix `D F̃ D` (`D = diag(F̃)^{-1/2}`) of the rest has
//!    an eigenvalue below `λ_max / ` [`CONDITION_LIMIT`] (1e10) and the
//!    component carries at least [`DIRECTION_SHARE`] (10 %) of that
//!    eigenvector's squared norm (a combination of parameters the trajectory
//!    cannot tell apart), or
//! 3. its Fisher std at the stated noise exceeds [`RELATIVE_STD_LIMIT`]
//!    (1e3) times its scale.
//!
//! A parameter is unidentifiable when one of its components is. Its std and
//! covariance entries are null; the others' come from the information of the
//! identifiable components alone (as if the unidentifiable ones were known).
//!
//! # Format
//!
//! `DIR/fit.json`:
//!
//! ```json
//! {"parameters": {"inertia_cm": {"value": 0.0125, "std": 1.2e-5},
//!                 "contact": {"value": [0.001, -0.002], "std": [1e-4, 1e-4]}, ...},
//!  "covariance": [[...], ...],
//!  "residual": {"position_rms": 0.001, "theta_rms": 0.001},
//!  "converged": true,
//!  "unidentifiable": ["inertia_cm", ...],
//!  "lack_of_fit": {"test": "...", "statistic": 2987.1, "dof": 3003,
//!                  "p_value": 0.58, "alpha": 0.001, "verdict": "fits"}}
//! ```
//!
//! Units: `mu_scale` 1, `inertia_cm` kg m², `center_of_friction` m (the
//! file's object frame), `contact` m (offset from the file's contact point);
//! `position_rms` m (RMS over the samples of the distance between the model's
//! and the data's centre of mass), `theta_rms` rad. The covariance rows and
//! columns follow the parameters in alphabetical order of their names (the
//! order `parameters` is written in), vector parameters as two consecutive
//! components x, y.

pub mod engine;
pub mod noise;
pub mod params;
mod residual;
mod settings;
pub mod study;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use levenberg_marquardt::{LevenbergMarquardt, TerminationReason};
use nalgebra034::{DMatrix, DVector, SymmetricEigen};
use pushval_model::Sample;
use pushval_scenario::Scenario;
use serde_json::{json, Value};

pub use params::{parse_list, shifted_loads, Invalid, Param, Parametrised};
pub use settings::Settings;

/// Rule 1: a component whose information is below this share of the largest
/// (in units of the components' scales) is unidentifiable.
pub const NO_INFORMATION: f64 = 1e-10;
/// Rule 2: a direction of the correlation matrix whose eigenvalue is below
/// `λ_max / CONDITION_LIMIT` is not determined by the data.
pub const CONDITION_LIMIT: f64 = 1e10;
/// Rule 2: a component with at least this share of such a direction's
/// squared norm is unidentifiable.
pub const DIRECTION_SHARE: f64 = 0.1;
/// Rule 3: a component whose Fisher std at the stated noise exceeds this
/// many times its scale is unidentifiable.
pub const RELATIVE_STD_LIMIT: f64 = 1e3;

/// The Fisher information of a set of components and what follows from it.
#[derive(Debug, Clone)]
pub struct Fisher {
    /// `JᵀJ` of the whitened residuals (per unit of each component).
    pub information: DMatrix<f64>,
    /// Per component: unidentifiable by the rules in the module doc.
    pub unidentifiable: Vec<bool>,
    /// `(JᵀJ)⁻¹` over the identifiable components: the covariance at the
    /// stated noise; NaN in the rows and columns of unidentifiable ones.
    pub covariance: DMatrix<f64>,
}

impl Fisher {
    /// Analyses the whitened Jacobian `jac` (residuals × components) with the
    /// components' `scales`.
    pub fn new(jac: &DMatrix<f64>, scales: &[f64]) -> Self {
        let n = jac.ncols();
        let information = jac.transpose() * jac;
        let scaled = DMatrix::from_fn(n, n, |a, b| information[(a, b)] * scales[a] * scales[b]);
        let dmax = (0..n).map(|j| scaled[(j, j)]).fold(0.0f64, f64::max);
        let mut unident: Vec<bool> = (0..n)
            .map(|j| !(scaled[(j, j)] > NO_INFORMATION * dmax) || !(dmax > 0.0))
            .collect();
        // Rule 2 on the components that carry information.
        let keep: Vec<usize> = (0..n).filter(|&j| !unident[j]).collect();
        if keep.len() > 1 {
            let m = keep.len();
            let corr = DMatrix::from_fn(m, m, |a, b| {
                let (i, j) = (keep[a], keep[b]);
                scaled[(i, j)] / (scaled[(i, i)] * scaled[(j, j)]).sqrt()
            });
            let eig = SymmetricEigen::new(corr);
            let lmax = eig.eigenvalues.iter().cloned().fold(0.0f64, f64::max);
            for (k, &l) in eig.eigenvalues.iter().enumerate() {
                if l < lmax / CONDITION_LIMIT {
                    for a in 0..m {
                        if eig.eigenvectors[(a, k)].powi(2) >= DIRECTION_SHARE {
                            unident[keep[a]] = true;
                        }
                    }
                }
            }
        }
        let mut covariance = inverse_on(&information, &unident);
        // Rule 3, then the inverse again without what it removed.
        let mut changed = false;
        for j in 0..n {
            if !unident[j] && !(covariance[(j, j)].sqrt() <= RELATIVE_STD_LIMIT * scales[j]) {
                unident[j] = true;
                changed = true;
            }
        }
        if changed {
            covariance = inverse_on(&information, &unident);
        }
        Self {
            information,
            unidentifiable: unident,
            covariance,
        }
    }

    /// Fisher std of each component at the stated noise (NaN where
    /// unidentifiable).
    pub fn std(&self) -> Vec<f64> {
        (0..self.covariance.nrows())
            .map(|j| self.covariance[(j, j)].sqrt())
            .collect()
    }
}

/// The inverse of `m` restricted to the components not `drop`ped, NaN in
/// the dropped rows and columns (and everywhere if the rest is singular).
fn inverse_on(m: &DMatrix<f64>, drop: &[bool]) -> DMatrix<f64> {
    let n = m.nrows();
    let keep: Vec<usize> = (0..n).filter(|&j| !drop[j]).collect();
    let mut out = DMatrix::from_element(n, n, f64::NAN);
    let sub = DMatrix::from_fn(keep.len(), keep.len(), |a, b| m[(keep[a], keep[b])]);
    // Scale to unit diagonal before inverting: the components differ by
    // many orders of magnitude (kg m² against a factor of 1).
    let d: Vec<f64> = (0..keep.len()).map(|a| sub[(a, a)].sqrt()).collect();
    let unit = DMatrix::from_fn(keep.len(), keep.len(), |a, b| sub[(a, b)] / (d[a] * d[b]));
    if let Some(inv) = unit.cholesky().map(|c| c.inverse()) {
        for (a, &i) in keep.iter().enumerate() {
            for (b, &j) in keep.iter().enumerate() {
                out[(i, j)] = inv[(a, b)] / (d[a] * d[b]);
            }
        }
    }
    out
}

/// The result of a fit.
#[derive(Debug, Clone)]
pub struct Fit {
    /// The parameters, in [`Param::ALL`] order.
    pub params: Vec<Param>,
    /// The estimate, one value per component.
    pub value: Vec<f64>,
    /// `s² (JᵀJ)⁻¹` at the estimate (NaN where unidentifiable).
    pub covariance: DMatrix<f64>,
    /// `s² = |r|² / (3K − n)`: the residual variance in units of the stated
    /// noise (≈ 1 when the noise is as stated).
    pub residual_variance: f64,
    /// RMS over the samples of the centre of mass's distance, model to data (m).
    pub position_rms: f64,
    /// RMS over the samples of the angle difference (rad).
    pub theta_rms: f64,
    /// The solver stopped at a minimum (MINPACK's convergence tests, or no
    /// further improvement possible in floating point).
    pub converged: bool,
    /// Why the solver stopped.
    pub termination: String,
    /// Residual evaluations (model trajectories) the solver used, without
    /// the Jacobian's.
    pub evaluations: usize,
    /// The Fisher analysis at the estimate.
    pub fisher: Fisher,
    /// Parameters with an unidentifiable component.
    pub unidentifiable: Vec<Param>,
    /// The χ² test of the residuals against the stated noise.
    pub lack_of_fit: LackOfFit,
    /// Why the fit is degenerate ([`degenerate_reasons`]); empty when not.
    pub degenerate: Vec<String>,
}

/// Significance below which the residuals reject the model: 1e-3, so a
/// right model with the stated noise is called wrong once in a thousand
/// fits (a CI gate must rarely cry wolf), while a model off by more than
/// the noise (s² a few per cent above 1 on a few thousand residuals) is
/// still caught.
pub const LACK_OF_FIT_ALPHA: f64 = 1e-3;

/// Whether the model explains the data: the whitened residual sum of
/// squares `χ² = |r|²` (residuals divided by the stated σ) against the χ²
/// distribution with `3K − n` degrees of freedom it follows when the model
/// is right and the noise is Gaussian at the stated σ. Only the upper tail
/// rejects: a fit better than the noise (a noiseless trajectory) is not a
/// lack of fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LackOfFit {
    /// χ² = |r|² (whitened).
    pub statistic: f64,
    /// Degrees of freedom, 3K − n.
    pub dof: usize,
    /// P(χ²_dof ≥ statistic).
    pub p_value: f64,
    /// True when `p_value < LACK_OF_FIT_ALPHA`.
    pub rejected: bool,
}

impl LackOfFit {
    /// The test for a whitened residual sum of squares with `dof` degrees
    /// of freedom.
    pub fn new(statistic: f64, dof: usize) -> Self {
        use statrs::distribution::{ChiSquared, ContinuousCDF};
        let p_value = ChiSquared::new(dof.max(1) as f64)
            .map(|d| d.sf(statistic))
            .unwrap_or(f64::NAN);
        Self {
            statistic,
            dof,
            p_value,
            rejected: !(p_value >= LACK_OF_FIT_ALPHA),
        }
    }

    /// `"fits"` or `"lack of fit"`.
    pub fn verdict(&self) -> &'static str {
        if self.rejected {
            "lack of fit"
        } else {
            "fits"
        }
    }
}

impl Fit {
    /// Std of each component (NaN where unidentifiable).
    pub fn std(&self) -> Vec<f64> {
        (0..self.covariance.nrows())
            .map(|j| self.covariance[(j, j)].sqrt())
            .collect()
    }

    /// Value and std of `p`'s components.
    pub fn get(&self, p: Param) -> Option<(Vec<f64>, Vec<f64>)> {
        let mut i = 0;
        let std = self.std();
        for &q in &self.params {
            if q == p {
                return Some((
                    self.value[i..i + p.dim()].to_vec(),
                    std[i..i + p.dim()].to_vec(),
                ));
            }
            i += q.dim();
        }
        None
    }

    /// `fit.json` (see the module doc's "Format").
    pub fn to_json(&self) -> Value {
        let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
        let mut parameters = serde_json::Map::new();
        for &p in &self.params {
            let (v, s) = self.get(p).expect("own parameter");
            let (value, std) = if p.dim() == 1 {
                (num(v[0]), num(s[0]))
            } else {
                (
                    Value::Array(v.iter().map(|x| num(*x)).collect()),
                    Value::Array(s.iter().map(|x| num(*x)).collect()),
                )
            };
            parameters.insert(p.name().into(), json!({"value": value, "std": std}));
        }
        let n = self.covariance.nrows();
        let covariance: Vec<Value> = (0..n)
            .map(|a| Value::Array((0..n).map(|b| num(self.covariance[(a, b)])).collect()))
            .collect();
        json!({
            "parameters": parameters,
            "covariance": covariance,
            "residual": {"position_rms": num(self.position_rms), "theta_rms": num(self.theta_rms)},
            "converged": self.converged,
            "unidentifiable": self.unidentifiable.iter().map(|p| p.name()).collect::<Vec<_>>(),
            "degenerate": self.degenerate,
            "lack_of_fit": {
                "test": "chi-squared: whitened residual sum of squares against chi2(3K - n)",
                "statistic": num(self.lack_of_fit.statistic),
                "dof": self.lack_of_fit.dof,
                "p_value": num(self.lack_of_fit.p_value),
                "alpha": LACK_OF_FIT_ALPHA,
                "verdict": self.lack_of_fit.verdict(),
            },
        })
    }
}

/// Fits `model`'s free parameters to `data` (on the scenario's sample grid)
/// from `start`. Err when `start` itself gives no problem the model can run.
pub fn fit(
    model: &Parametrised,
    data: &[Sample],
    start: &[f64],
    settings: &Settings,
) -> Result<Fit, String> {
    let res = residual::Residuals::new(model, data, settings);
    if let Err(e) = model.problem(start) {
        return Err(format!("the start values give no problem: {e}"));
    }
    if res.eval(start).is_none() {
        return Err("the model fails at the start values".into());
    }
    let problem = residual::Problem {
        residuals: res,
        x: DVector::from_column_slice(start),
    };
    let (problem, report) = LevenbergMarquardt::new()
        .with_ftol(1e-10)
        .with_xtol(1e-8)
        .with_gtol(1e-12)
        .with_patience(settings.patience)
        .minimize(problem);
    let converged = matches!(
        report.termination,
        TerminationReason::Converged { .. }
            | TerminationReason::ResidualsZero
            | TerminationReason::Orthogonal
            | TerminationReason::NoImprovementPossible(_)
    );
    let value: Vec<f64> = problem.x.iter().cloned().collect();
    summarise(
        &problem.residuals,
        value,
        converged,
        format!("{:?}", report.termination),
        report.number_of_evaluations,
    )
}

/// The Fisher analysis of `model` at `values` against its own exact
/// trajectory there (the residual's Jacobian does not depend on the data).
pub fn fisher_at(
    model: &Parametrised,
    values: &[f64],
    settings: &Settings,
) -> Result<Fisher, String> {
    let problem = model.problem(values).map_err(|e| e.to_string())?;
    let sim = pushval_model::DynamicModel {
        integrator: pushval_model::Integrator::Dop853 {
            tol: settings.tolerance,
        },
        check_assumptions: false,
        ..Default::default()
    };
    let data = pushval_model::Simulator::simulate(&sim, &problem)
        .map_err(|e| e.to_string())?
        .samples;
    let res = residual::Residuals::new(model, &data, settings);
    let jac = res
        .jacobian(values)
        .ok_or("the model fails next to these values")?;
    Ok(Fisher::new(&jac, &model.scales()))
}

fn summarise(
    res: &residual::Residuals,
    value: Vec<f64>,
    converged: bool,
    termination: String,
    evaluations: usize,
) -> Result<Fit, String> {
    let model = res.model;
    let r = res.eval(&value).ok_or("the model fails at the estimate")?;
    let jac = res
        .jacobian(&value)
        .ok_or("the model fails next to the estimate")?;
    let k = res.data.len();
    let n = value.len();
    let dof = (3 * k).saturating_sub(n).max(1);
    let s2 = r.norm_squared() / dof as f64;
    let fisher = Fisher::new(&jac, &model.scales());
    let covariance = &fisher.covariance * s2;
    let (sp, st) = (res.settings.sigma_position, res.settings.sigma_theta);
    let mut pos = 0.0;
    let mut th = 0.0;
    for i in 0..k {
        pos += (r[3 * i].powi(2) + r[3 * i + 1].powi(2)) * sp * sp;
        th += (r[3 * i + 2] * st).powi(2);
    }
    let slots = model.slots();
    let mut unidentifiable: Vec<Param> = slots
        .iter()
        .zip(&fisher.unidentifiable)
        .filter(|(_, u)| **u)
        .map(|((p, _), _)| *p)
        .collect();
    unidentifiable.dedup();
    let degenerate = degenerate_reasons(&slots, &value, &model.file_values());
    Ok(Fit {
        params: model.params().to_vec(),
        value,
        covariance,
        residual_variance: s2,
        position_rms: (pos / k as f64).sqrt(),
        theta_rms: (th / k as f64).sqrt(),
        converged,
        termination,
        evaluations,
        fisher,
        unidentifiable,
        lack_of_fit: LackOfFit::new(r.norm_squared(), dof),
        degenerate,
    })
}

/// A positive parameter (μ scale, I_cm) at or below this fraction of the
/// file's value is "near zero": a frictionless or massless explanation, one
/// no physical plate has.
pub const NEAR_ZERO: f64 = 0.05;

/// Why a fit explains nothing even where its residuals are small: a
/// positive parameter (μ scale, I_cm) at or below [`NEAR_ZERO`] of the
/// file's value or not positive at all (outside its physical bounds).
/// Empty when the fit is not degenerate. An ill-conditioned Fisher
/// information is reported on its own, as unidentifiable components
/// ([`Fit::unidentifiable`], the rules of the module doc).
pub fn degenerate_reasons(slots: &[(Param, usize)], value: &[f64], file: &[f64]) -> Vec<String> {
    let mut out = Vec::new();
    for (((p, _), v), f) in slots.iter().zip(value).zip(file) {
        if matches!(p, Param::MuScale | Param::InertiaCm) && !(*v > NEAR_ZERO * f.abs()) {
            out.push(format!(
                "{} = {v:.3e} is at or below {NEAR_ZERO} x its file value {f:.3e} (a {} plate explains the run; that explains nothing)",
                p.name(),
                if *p == Param::MuScale { "frictionless" } else { "massless" }
            ));
        }
    }
    out
}

/// Checks that `samples` lie on the scenario's sample grid
/// ([`pushval_model::Problem::sample_times`]) to within 1e-6 of a step.
pub fn check_grid(sc: &Scenario, samples: &[Sample]) -> Result<(), String> {
    let times = sc.problem().sample_times();
    if samples.len() != times.len() {
        return Err(format!(
            "{} samples, the scenario's grid has {} (t from 0 to {} s in steps of {} s)",
            samples.len(),
            times.len(),
            sc.problem().duration(),
            sc.sample_dt
        ));
    }
    for (i, (s, t)) in samples.iter().zip(&times).enumerate() {
        if (s.t - t).abs() > 1e-6 * sc.sample_dt {
            return Err(format!(
                "sample {} has t = {} s, the scenario's grid has {} s there (steps of {} s from 0)",
                i + 1,
                s.t,
                t,
                sc.sample_dt
            ));
        }
    }
    Ok(())
}

/// What `pushval fit` was asked.
#[derive(Debug, Clone)]
pub struct Request {
    /// The scenario file.
    pub scenario: PathBuf,
    /// The trajectory CSV ([`pushval_model::format`]).
    pub trajectory: PathBuf,
    /// `NAME[,NAME...]` as given.
    pub params: String,
    /// Output folder for `fit.json` (created if missing).
    pub out: PathBuf,
    /// Which run of the CSV (its `model` column); None: the only one.
    pub model: Option<String>,
    /// Noise levels and numerics.
    pub settings: Settings,
}

/// `pushval fit`: exit 0 converged and every parameter identifiable, 1 not
/// converged, a parameter unidentifiable or a lack of fit (named on stderr), Err (exit 2)
/// on bad input, with nothing written.
pub fn cli(req: &Request) -> anyhow::Result<ExitCode> {
    let sc = crate::registry::load(&req.scenario)?;
    let params = parse_list(&req.params).map_err(|e| anyhow::anyhow!("--params: {e}"))?;
    for (what, v) in [
        ("--sigma-position", req.settings.sigma_position),
        ("--sigma-theta", req.settings.sigma_theta),
    ] {
        if !(v.is_finite() && v > 0.0) {
            bail!("{what}: must be a finite number > 0, got {v}");
        }
    }
    let csv = &req.trajectory;
    let outside = crate::compare::read_trajectory(csv, req.model.as_deref())?;
    if let Some(note) = outside.omega_note() {
        println!("{note}");
    }
    let samples = &outside.samples;
    check_grid(&sc, samples).map_err(|e| anyhow::anyhow!("{}: {e}", csv.display()))?;
    let model = Parametrised::new(&sc, &params)
        .map_err(|e| anyhow::anyhow!("{}: {e}", req.scenario.display()))?;
    let start = model.file_values();
    let fit = fit(&model, samples, &start, &req.settings)
        .map_err(|e| anyhow::anyhow!("{}: {e}", req.scenario.display()))?;
    let path = write(&fit, &req.out)?;
    print!("{}", table(&fit));
    println!("wrote {}", path.display());
    let mut code = ExitCode::SUCCESS;
    if !fit.converged {
        eprintln!(
            "FAIL {}: the fit did not converge ({}); parameters {}",
            sc.name,
            fit.termination,
            names_of(&fit.params)
        );
        code = ExitCode::from(1);
    }
    if !fit.unidentifiable.is_empty() {
        eprintln!(
            "FAIL {}: unidentifiable from this trajectory: {}",
            sc.name,
            names_of(&fit.unidentifiable)
        );
        code = ExitCode::from(1);
    }
    for why in &fit.degenerate {
        eprintln!("FAIL {}: degenerate fit: {why}", req.scenario.display());
        code = ExitCode::from(1);
    }
    let l = &fit.lack_of_fit;
    if l.rejected {
        eprintln!(
            "FAIL {}: lack of fit: the model cannot explain this trajectory: residual RMS {:.3e} m, {:.3e} rad against the stated sigma {:.1e} m, {:.1e} rad (s^2 = {:.3e}); chi-squared {:.4e} on {} degrees of freedom, p = {:.2e} < {LACK_OF_FIT_ALPHA:e}",
            sc.name,
            fit.position_rms,
            fit.theta_rms,
            req.settings.sigma_position,
            req.settings.sigma_theta,
            fit.residual_variance,
            l.statistic,
            l.dof,
            l.p_value
        );
        code = ExitCode::from(1);
    }
    Ok(code)
}

fn names_of(p: &[Param]) -> String {
    p.iter().map(|p| p.name()).collect::<Vec<_>>().join(", ")
}

/// A short table of the estimate for the terminal.
pub fn table(fit: &Fit) -> String {
    let mut s = format!(
        "{:<20} {:>14} {:>12} {}\n",
        "parameter", "value", "std", "unit"
    );
    let std = fit.std();
    let mut i = 0;
    for &p in &fit.params {
        for k in 0..p.dim() {
            let name = if p.dim() == 1 {
                p.name().to_string()
            } else {
                format!("{}[{}]", p.name(), ["x", "y"][k])
            };
            let sd = if std[i].is_finite() {
                format!("{:.3e}", std[i])
            } else {
                "unidentif.".into()
            };
            s += &format!("{name:<20} {:>14.7e} {sd:>12} {}\n", fit.value[i], p.unit());
            i += 1;
        }
    }
    s += &format!(
        "residual: position {:.3e} m, theta {:.3e} rad (RMS); s^2 = {:.3e}; {} ({} evaluations)\n",
        fit.position_rms, fit.theta_rms, fit.residual_variance, fit.termination, fit.evaluations
    );
    s
}

/// Writes `fit.json` for an already computed fit into `dir` (atomically).
pub fn write(fit: &Fit, dir: &Path) -> anyhow::Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let path = dir.join("fit.json");
    crate::atomic::write_atomic(
        &path,
        serde_json::to_string_pretty(&fit.to_json())?.as_bytes(),
    )?;
    Ok(path)
}

#[cfg(test)]
mod degenerate_tests {
    use super::*;

    /// The locked-plate case: a fit that drives the friction scale and the
    /// inertia to ~0 explains a plate that does not turn by a plate without
    /// friction or mass; both are named. A fit at physical values (μ scale
    /// 0.84, I_cm at 90 % of the file's) is not degenerate, nor is one just
    /// above the threshold.
    #[test]
    fn parameters_near_zero_are_degenerate() {
        let slots = [(Param::InertiaCm, 0), (Param::MuScale, 0)];
        let file = [0.0104, 1.0];
        let why = degenerate_reasons(&slots, &[2.1e-9, 2.5e-9], &file);
        assert_eq!(why.len(), 2, "{why:?}");
        assert!(why[0].contains("inertia_cm") && why[0].contains("massless"));
        assert!(why[1].contains("mu_scale") && why[1].contains("frictionless"));
        assert!(degenerate_reasons(&slots, &[0.9 * 0.0104, 0.84], &file).is_empty());
        assert!(degenerate_reasons(&slots, &[0.0104, 1.01 * NEAR_ZERO], &file).is_empty());
        // Negative (outside the physical bounds) and NaN are degenerate too.
        assert_eq!(
            degenerate_reasons(&slots, &[-1e-3, f64::NAN], &file).len(),
            2
        );
    }
}
