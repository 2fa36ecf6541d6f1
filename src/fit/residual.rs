//! The residual function (the model's fast trajectory against the data) and
//! its finite-difference Jacobian, as the `levenberg-marquardt` crate wants
//! them.

use levenberg_marquardt::LeastSquaresProblem;
use nalgebra034::{DMatrix, DVector, Dyn, Owned};
use pushval_model::{DynamicModel, Integrator, Sample, Simulator};

use super::params::Parametrised;
use super::settings::Settings;

/// Whitened residuals: per sample `(x_m − x_d)/σ_p, (y_m − y_d)/σ_p,
/// (θ_m − θ_d)/σ_θ`, samples in time order.
pub(crate) struct Residuals<'a> {
    pub model: &'a Parametrised,
    pub data: &'a [Sample],
    pub settings: &'a Settings,
    sim: DynamicModel,
    scales: Vec<f64>,
}

impl<'a> Residuals<'a> {
    pub fn new(model: &'a Parametrised, data: &'a [Sample], settings: &'a Settings) -> Self {
        Self {
            model,
            data,
            settings,
            sim: DynamicModel {
                integrator: Integrator::Dop853 {
                    tol: settings.tolerance,
                },
                skip_settled: true,
                // The fit needs the pose only.
                check_assumptions: false,
                ..DynamicModel::default()
            },
            scales: model.scales(),
        }
    }

    /// Number of residuals.
    pub fn len(&self) -> usize {
        3 * self.data.len()
    }

    /// The model's samples for `values`; None when the values give no
    /// problem or the model fails on it.
    pub fn trajectory(&self, values: &[f64]) -> Option<Vec<Sample>> {
        let problem = self.model.problem(values).ok()?;
        let tr = self.sim.simulate(&problem).ok()?;
        (tr.samples.len() == self.data.len()).then_some(tr.samples)
    }

    /// The whitened residual vector, None as for [`Self::trajectory`].
    pub fn eval(&self, values: &[f64]) -> Option<DVector<f64>> {
        let samples = self.trajectory(values)?;
        let (sp, st) = (self.settings.sigma_position, self.settings.sigma_theta);
        let mut r = DVector::zeros(self.len());
        for (k, (m, d)) in samples.iter().zip(self.data).enumerate() {
            r[3 * k] = (m.x - d.x) / sp;
            r[3 * k + 1] = (m.y - d.y) / sp;
            r[3 * k + 2] = (m.theta - d.theta) / st;
        }
        Some(r)
    }

    /// Jacobian of [`Self::eval`] by central differences with step
    /// `h_j = fd_step × scale_j`; one-sided where one side leaves the
    /// parameters' domain; None when both do.
    pub fn jacobian(&self, values: &[f64]) -> Option<DMatrix<f64>> {
        let n = values.len();
        let mut jac = DMatrix::zeros(self.len(), n);
        let mut centre: Option<Option<DVector<f64>>> = None;
        for j in 0..n {
            let h = self.settings.fd_step * self.scales[j];
            let at = |delta: f64| {
                let mut v = values.to_vec();
                v[j] += delta;
                self.eval(&v)
            };
            let col = match (at(h), at(-h)) {
                (Some(a), Some(b)) => (a - b) / (2.0 * h),
                (Some(a), None) => {
                    let c = centre.get_or_insert_with(|| self.eval(values)).as_ref()?;
                    (a - c) / h
                }
                (None, Some(b)) => {
                    let c = centre.get_or_insert_with(|| self.eval(values)).as_ref()?;
                    (c - b) / h
                }
                (None, None) => return None,
            };
            jac.set_column(j, &col);
        }
        Some(jac)
    }
}

/// The least-squares problem handed to the solver: the residuals at the
/// current parameter vector.
pub(crate) struct Problem<'a> {
    pub residuals: Residuals<'a>,
    pub x: DVector<f64>,
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    /// Outside the parameters' domain (a negative inertia, a load that
    /// would turn negative) the residuals are NaN: the solver then rejects
    /// the step and shrinks its trust region instead of stopping.
    fn residuals(&self) -> Option<DVector<f64>> {
        Some(
            self.residuals
                .eval(self.x.as_slice())
                .unwrap_or_else(|| DVector::from_element(self.residuals.len(), f64::NAN)),
        )
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        self.residuals.jacobian(self.x.as_slice())
    }
}
