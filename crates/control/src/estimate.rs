//! The plate's friction estimated while the loop runs: the extended Kalman
//! filter of `pushval track` ([`pushval_model::track::Ekf`]) made to follow
//! pushes decided online. Its model is built from the pushes applied so far
//! ([`OnlineEstimator::applied`] appends each as the plant receives it), so
//! a reading is explained by exactly the pushes that produced it.
//!
//! It estimates `mu_scale` (a factor on every support's friction), the
//! centre of friction (where the supports' friction acts, relative to the
//! centre of mass) and `I_cm`, and gives the scene they describe
//! ([`OnlineEstimator::body`]): the supports' friction moved by the least
//! change that puts their centre at the estimate, scaled by `mu_scale`.
//!
//! # What the pushes identify
//!
//! A parameter is called identified when the readings so far have cut its
//! standard deviation to a quarter of the prior's (they carry at least 15
//! times the prior's information about it); the others stay near the file's
//! values, weighed by the prior, and [`Identified`] says so.
//!
//! What no pushed motion reveals: the friction of a support under the
//! contact (it has no moment about the contact, so the plate turns alike
//! whatever it is; only the pusher's force, which the loop does not read,
//! depends on it), and, with more supports than the estimate has
//! parameters, how the friction is split among them beyond its total,
//! centre and moment. The slide after the release depends on both, so a
//! rest pose predicted on the estimate carries an error the estimator
//! cannot see before it lets go. The scene it gives keeps the file's value
//! for a support under the contact rather than the value the estimate's
//! affine family would extrapolate there: on the seed's plate with a
//! slippery foot (four corners whose friction is not affine in position)
//! the extrapolation moved the slippery foot's deficit onto the pushed
//! corner, and in rapier2d at 1 m/s the loops judged at rest reached none
//! of the 20 goals, against 20 with the file's value.

use pushval_engine::EngineState;
use pushval_model::track::{
    Ekf, EkfSettings, Estimate, Estimator, Free, Measurement, TrackModel, CX, CY, INERTIA, MU,
};
use pushval_model::{Body, Problem, Push, Support};

use crate::sensor::SensorSpec;
use crate::ControlError;

/// The weights' floors for an exact sensor: position (m), θ (rad), ω
/// (rad/s). A plant is never exactly the model (an engine's step, its
/// contact model); weighing its readings as exact would make the filter
/// take those differences for friction.
pub const FLOOR: [f64; 3] = [2e-4, 2e-3, 5e-2];

/// The prior's std relative to each parameter's scale: `mu_scale`, the
/// centre of friction (in units of the plate's size) and `I_cm`. Wider than
/// `pushval track`'s default: a plate whose loads sit on one side moves its
/// centre of friction by a fifth of its size or more.
pub const PRIOR: [f64; 3] = [0.3, 0.25, 0.3];

/// A parameter counts as identified when its std is at most this fraction
/// of the prior's.
pub const IDENTIFIED: f64 = 0.25;

/// Which parameters the readings so far identify.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct Identified {
    /// `mu_scale`.
    pub mu_scale: bool,
    /// Both components of the centre of friction.
    pub center_of_friction: bool,
    /// `I_cm`.
    pub inertia_cm: bool,
}

/// One estimate of the loop, at the time of the reading it used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimateRow {
    /// Time of the reading (s).
    pub t: f64,
    /// `[mu_scale, c_x (m), c_y (m), I_cm (kg m²)]`, the centre of friction
    /// relative to the centre of mass.
    pub value: [f64; 4],
    /// Their standard deviations.
    pub std: [f64; 4],
}

/// The online estimator of the loop.
#[derive(Debug, Clone)]
pub struct OnlineEstimator {
    ekf: Ekf,
    scene: Problem,
    prior_std: [f64; 4],
    last_t: f64,
    lack_of_fit: usize,
}

impl OnlineEstimator {
    /// An estimator on `scene` (the file's body and start; its schedule is
    /// not used), weighed for `sensor`'s declared noise (with the floors of
    /// [`FLOOR`]).
    pub fn new(scene: &Problem, sensor: &SensorSpec) -> Result<Self, ControlError> {
        let mut p = scene.clone();
        if p.pushes.is_empty() {
            p.pushes.push(Push {
                duration: 1.0,
                speed: 0.1,
                phi: 0.0,
            });
        }
        let model = TrackModel::online(&p, &[])?;
        let settings = EkfSettings {
            sigma_position: sensor.sigma_position.max(FLOOR[0]),
            sigma_theta: sensor.sigma_theta.max(FLOOR[1]),
            sigma_omega: Some(sensor.sigma_omega.max(FLOOR[2])),
            sigma_force: None,
            prior: PRIOR,
            ..EkfSettings::default()
        };
        let size = model.size();
        let nominal = model.nominal();
        let prior_std = [
            PRIOR[0],
            PRIOR[1] * size,
            PRIOR[1] * size,
            PRIOR[2] * nominal[INERTIA],
        ];
        Ok(Self {
            ekf: Ekf::new(model, Free::default(), settings, None),
            scene: scene.clone(),
            prior_std,
            last_t: 0.0,
            lack_of_fit: 0,
        })
    }

    /// A push the plant received (in order, each right after the last).
    pub fn applied(&mut self, push: &Push) {
        self.ekf.extend(push.velocity(), push.duration);
    }

    /// Takes a reading (pose and ω; the velocity is not used: the pusher
    /// fixes it). Readings not later than the last one are ignored.
    pub fn measure(&mut self, st: &EngineState) -> Result<(), ControlError> {
        if !(st.t > self.last_t) {
            return Ok(());
        }
        let report = self.ekf.update(&Measurement {
            t: st.t,
            x: st.x,
            y: st.y,
            theta: st.theta,
            omega: Some(st.omega),
            force: None,
        })?;
        self.last_t = st.t;
        self.lack_of_fit += report.lack_of_fit as usize;
        Ok(())
    }

    /// The current estimate.
    pub fn estimate(&self) -> Estimate {
        self.ekf.estimate()
    }

    /// The current estimate as a row at the last reading's time.
    pub fn row(&self) -> EstimateRow {
        let e = self.estimate();
        EstimateRow {
            t: self.last_t,
            value: e.value,
            std: e.std(),
        }
    }

    /// Times the readings rejected the model (the filter then re-opened the
    /// parameters to their prior).
    pub fn lack_of_fit(&self) -> usize {
        self.lack_of_fit
    }

    /// Which parameters the readings so far identify.
    pub fn identified(&self) -> Identified {
        let std = self.estimate().std();
        let ok = |j: usize| std[j] <= IDENTIFIED * self.prior_std[j];
        let cof = self.ekf.model().center_of_friction_free();
        Identified {
            mu_scale: ok(MU),
            center_of_friction: cof && ok(CX) && ok(CY),
            inertia_cm: ok(INERTIA),
        }
    }

    /// The scene the estimate describes: the file's supports with the
    /// estimated friction at each (never below 0; a support under the
    /// contact keeps the file's, which no pushed motion reveals) and the
    /// estimated `I_cm`.
    pub fn body(&self) -> Result<Body, ControlError> {
        let p = self.estimate().value;
        let md = self.ekf.model();
        let b = &self.scene.body;
        let contact = b.contact();
        let supports: Vec<Support> = (0..md.supports())
            .zip(b.supports())
            .map(|(i, file)| {
                // A support under the contact has no moment about it: the
                // pushed motion does not depend on its friction, so the
                // readings say nothing of it and the file's value stays (the
                // estimate's family would extrapolate it from the others).
                let blind = (md.support_position(i) - contact).norm() <= 1e-9 * md.size();
                Support {
                    position: md.support_position(i),
                    friction: if blind {
                        file.friction
                    } else {
                        md.support_friction(i, &p).max(0.0)
                    },
                }
            })
            .collect();
        Ok(Body::new(b.mass(), p[INERTIA], b.contact(), &supports)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pushval_model::Vec2;

    #[test]
    fn the_file_values_give_the_file_scene() {
        let body = Body::new(
            1.0,
            0.01,
            Vec2::new(-0.1, -0.1),
            &[
                Support {
                    position: Vec2::new(-0.1, -0.1),
                    friction: 1.0,
                },
                Support {
                    position: Vec2::new(0.1, -0.1),
                    friction: 2.0,
                },
                Support {
                    position: Vec2::new(0.1, 0.1),
                    friction: 1.5,
                },
                Support {
                    position: Vec2::new(-0.1, 0.1),
                    friction: 0.5,
                },
            ],
        )
        .unwrap();
        let problem = Problem {
            body: body.clone(),
            limits: Default::default(),
            pushes: Vec::new(),
            initial: Default::default(),
            switching: Default::default(),
            sample_dt: 0.01,
            release: None,
        };
        let e = OnlineEstimator::new(&problem, &SensorSpec::default()).unwrap();
        let b = e.body().unwrap();
        for (s, t) in b.supports().zip(body.supports()) {
            assert!((s.friction - t.friction).abs() < 1e-12);
            assert_eq!(s.position, t.position);
        }
        assert!((b.inertia_cm() - 0.01).abs() < 1e-15);
        // Before any reading nothing is identified.
        assert_eq!(e.identified(), Identified::default());
    }
}
