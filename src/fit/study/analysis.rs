//! The study's grid, the Fisher analysis per point and the repeated noisy
//! fits that check it: one row type and one check list, which the figure
//! and `fit.md` read.

pub(super) use std::f64::consts::FRAC_PI_4;
pub(super) use std::path::{Path, PathBuf};

pub(super) use anyhow::Context;
pub(super) use pushval_model::{Push, Simulator};
pub(super) use pushval_scenario::Scenario;

pub(super) use crate::fit::{fisher_at, fit, noise, Param, Parametrised, Settings};
pub(super) use crate::plot::{self, Axis, Figure, Legend, Panel, Series, Stroke};

/// The stated noise of the study on x and y (m).
pub const SIGMA_POSITION: f64 = 1e-3;
/// The stated noise of the study on θ (rad).
pub const SIGMA_THETA: f64 = 1e-3;
/// Noisy fits per check point.
pub const FITS: usize = 40;
/// The empirical std must lie within this factor of the Fisher std (either
/// way). With 40 fits the sample std of a normal estimate lies within
/// [0.78, 1.22] of the true std 95 % of the time and within [0.66, 1.36]
/// 99.8 % of the time (χ² with 39 degrees of freedom); outside a factor 1.5
/// about 0.1 % of the time per component. (With 20 fits that chance is 2 %.)
pub const AGREEMENT: f64 = 1.5;
/// The shortest-push question's target on μ (relative, at [`SIGMAS`] σ).
pub const MU_TARGET: f64 = 0.01;
/// The shortest-push question's target on I_cm (relative, at [`SIGMAS`] σ).
pub const INERTIA_TARGET: f64 = 0.02;
/// How many Fisher std the targets must hold at (2: about 95 %).
pub const SIGMAS: f64 = 2.0;

/// One push schedule of the study.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// "speed", "duration", "segments" or "shortest".
    pub sweep: &'static str,
    /// Pusher speed (m/s), every segment.
    pub speed: f64,
    /// Total duration (s).
    pub duration: f64,
    /// Number of equal segments.
    pub segments: usize,
    /// φ of the first segment (rad).
    pub phi: f64,
}

impl Point {
    /// The pushes: `segments` equal pieces of `duration`, φ from `phis`
    /// in turn starting with `phi` (its index in `phis`).
    pub(super) fn pushes(&self, phis: &[f64]) -> Vec<Push> {
        let start = phis
            .iter()
            .position(|p| (p - self.phi).abs() < 1e-12)
            .unwrap_or(0);
        (0..self.segments)
            .map(|i| Push {
                duration: self.duration / self.segments as f64,
                speed: self.speed,
                phi: if self.segments == 1 {
                    self.phi
                } else {
                    phis[(start + i) % phis.len()]
                },
            })
            .collect()
    }
}

/// The parameter sets: μ and I; with the contact offset; with the centre
/// of friction.
pub fn sets() -> [Vec<Param>; 3] {
    [
        vec![Param::InertiaCm, Param::MuScale],
        vec![Param::Contact, Param::InertiaCm, Param::MuScale],
        vec![Param::CenterOfFriction, Param::InertiaCm, Param::MuScale],
    ]
}

pub(super) fn set_name(set: &[Param]) -> String {
    set.iter().map(|p| p.name()).collect::<Vec<_>>().join("+")
}

/// The study's scene: the base scenario with `point`'s pushes.
pub struct Study {
    /// The scenario every push is put into.
    pub base: Scenario,
    /// The file's push angles.
    pub phis: Vec<f64>,
    /// The fit's settings with the study's noise levels.
    pub settings: Settings,
}

impl Study {
    /// The study on `scenarios/paper-square-v1.0.toml` in `scenarios`.
    pub fn new(scenarios: &Path) -> anyhow::Result<Self> {
        let base = crate::registry::load(scenarios.join("paper-square-v1.0.toml"))?;
        let phis = base.pushes.iter().map(|p| p.phi).collect();
        Ok(Self {
            base,
            phis,
            settings: Settings {
                sigma_position: SIGMA_POSITION,
                sigma_theta: SIGMA_THETA,
                ..Settings::default()
            },
        })
    }

    /// The scenario for `point`.
    pub fn scenario(&self, point: &Point) -> Scenario {
        let mut sc = self.base.clone();
        sc.pushes = point.pushes(&self.phis);
        sc
    }

    /// The base push: 1 m/s for 2 s at the file's first φ, one segment.
    pub fn base_point(&self, sweep: &'static str) -> Point {
        Point {
            sweep,
            speed: 1.0,
            duration: 2.0,
            segments: 1,
            phi: self.phis[0],
        }
    }

    /// Fisher std of each component of `set` at the truth (the file's values)
    /// for `point`, with the component scales; NaN where unidentifiable.
    pub fn fisher_std(&self, point: &Point, set: &[Param]) -> anyhow::Result<(Vec<f64>, Vec<f64>)> {
        let sc = self.scenario(point);
        let model = Parametrised::new(&sc, set).map_err(anyhow::Error::msg)?;
        let f = fisher_at(&model, &model.file_values(), &self.settings)
            .map_err(anyhow::Error::msg)
            .with_context(|| format!("Fisher information at {point:?}"))?;
        Ok((f.std(), model.file_values()))
    }

    /// `fits` fits of `set` to the exact trajectory plus noise (seeds
    /// `seed0 + i`), each started off the truth (μ × 0.9, I × 1.15, the
    /// centre of friction 5 mm off in x and y). Returns the estimates, one
    /// vector per fit, and how many did not converge.
    pub fn noisy_fits(
        &self,
        point: &Point,
        set: &[Param],
        fits: usize,
        seed0: u64,
    ) -> anyhow::Result<(Vec<Vec<f64>>, usize)> {
        let sc = self.scenario(point);
        let model = Parametrised::new(&sc, set).map_err(anyhow::Error::msg)?;
        let truth = model.file_values();
        let exact = pushval_model::DynamicModel::default()
            .simulate(&sc.problem())
            .context("the exact trajectory")?
            .samples;
        let start: Vec<f64> = model
            .slots()
            .iter()
            .zip(&truth)
            .map(|((p, _), v)| match p {
                Param::MuScale => v * 0.9,
                Param::InertiaCm => v * 1.15,
                Param::CenterOfFriction | Param::Contact => v + 0.005,
            })
            .collect();
        let mut out = Vec::with_capacity(fits);
        let mut failed = 0;
        for i in 0..fits {
            let data = noise::add_noise(
                &exact,
                self.settings.sigma_position,
                self.settings.sigma_theta,
                seed0 + i as u64,
            );
            let f = fit(&model, &data, &start, &self.settings).map_err(anyhow::Error::msg)?;
            if !f.converged {
                failed += 1;
            }
            out.push(f.value);
        }
        Ok((out, failed))
    }

    /// The empirical std of [`Self::noisy_fits`]' estimates per component
    /// (about their mean, n − 1 in the denominator) and the Fisher std.
    pub fn check(
        &self,
        point: &Point,
        set: &[Param],
        fits: usize,
        seed0: u64,
    ) -> anyhow::Result<Check> {
        let (est, failed) = self.noisy_fits(point, set, fits, seed0)?;
        let (fisher, truth) = self.fisher_std(point, set)?;
        let n = truth.len();
        let empirical: Vec<f64> = (0..n)
            .map(|j| {
                let mean = est.iter().map(|e| e[j]).sum::<f64>() / fits as f64;
                (est.iter().map(|e| (e[j] - mean).powi(2)).sum::<f64>() / (fits - 1) as f64).sqrt()
            })
            .collect();
        Ok(Check {
            point: point.clone(),
            set: set.to_vec(),
            truth,
            fisher,
            empirical,
            fits,
            failed,
        })
    }

    /// The shortest one-segment push at `speed` and `phi` whose 2σ Fisher
    /// error is within 1 % on μ and 2 % on I_cm (fitting both), in whole
    /// sample steps up to `max_duration`; None if not even that is enough.
    pub fn shortest(&self, speed: f64, phi: f64, max_duration: f64) -> anyhow::Result<Option<f64>> {
        let set = &sets()[0];
        let dt = self.base.sample_dt;
        let ok = |steps: usize| -> anyhow::Result<bool> {
            let p = Point {
                sweep: "shortest",
                speed,
                duration: steps as f64 * dt,
                segments: 1,
                phi,
            };
            let (std, truth) = self.fisher_std(&p, set)?;
            // Components in Param::ALL order: inertia_cm, mu_scale.
            Ok(SIGMAS * std[0] / truth[0] <= INERTIA_TARGET
                && SIGMAS * std[1] / truth[1] <= MU_TARGET)
        };
        let (mut lo, mut hi) = (1usize, (max_duration / dt).round() as usize);
        if !ok(hi)? {
            return Ok(None);
        }
        // Invariant: ok(hi), and lo - 1 is not known to be ok.
        while lo < hi {
            let mid = (lo + hi) / 2;
            if ok(mid)? {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        Ok(Some(hi as f64 * dt))
    }
}

/// An empirical check: Fisher std against the spread of repeated fits.
#[derive(Debug, Clone)]
pub struct Check {
    /// Where.
    pub point: Point,
    /// The parameters fitted.
    pub set: Vec<Param>,
    /// The truth, per component.
    pub truth: Vec<f64>,
    /// Fisher std at the truth, per component.
    pub fisher: Vec<f64>,
    /// Std of the noisy fits' estimates about their mean, per component.
    pub empirical: Vec<f64>,
    /// Number of noisy fits.
    pub fits: usize,
    /// Fits that did not converge.
    pub failed: usize,
}

impl Check {
    /// Empirical over Fisher std per component.
    pub fn ratios(&self) -> Vec<f64> {
        self.empirical
            .iter()
            .zip(&self.fisher)
            .map(|(e, f)| e / f)
            .collect()
    }
    /// Every ratio within [1/AGREEMENT, AGREEMENT] and every fit converged.
    pub fn pass(&self) -> bool {
        self.failed == 0
            && self
                .ratios()
                .iter()
                .all(|r| *r >= 1.0 / AGREEMENT && *r <= AGREEMENT)
    }
}

/// The grids of the three sweeps (`quick`: a few points each).
pub fn grid(study: &Study, quick: bool) -> Vec<Point> {
    let speeds: &[f64] = if quick {
        &[0.2, 1.0]
    } else {
        &[0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0]
    };
    let durations: &[f64] = if quick {
        &[0.5, 2.0]
    } else {
        &[0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0]
    };
    let segments: &[usize] = if quick { &[1, 3] } else { &[1, 2, 3, 4, 5] };
    let mut out = Vec::new();
    for &v in speeds {
        out.push(Point {
            speed: v,
            ..study.base_point("speed")
        });
    }
    for &d in durations {
        out.push(Point {
            duration: d,
            ..study.base_point("duration")
        });
    }
    for &k in segments {
        out.push(Point {
            segments: k,
            ..study.base_point("segments")
        });
    }
    out
}

/// The check points and the sets checked there (indices into [`sets`]):
/// the base push, a slow push and a short one with μ, I and μ, I, contact;
/// five segments with every set (the centre of friction needs more than one
/// push direction).
pub fn check_points(study: &Study) -> Vec<(Point, Vec<usize>)> {
    vec![
        (study.base_point("duration"), vec![0, 1]),
        (
            Point {
                speed: 0.3,
                ..study.base_point("speed")
            },
            vec![0, 1],
        ),
        (
            Point {
                duration: 0.5,
                ..study.base_point("duration")
            },
            vec![0, 1],
        ),
        (
            Point {
                segments: 5,
                ..study.base_point("segments")
            },
            vec![0, 1, 2],
        ),
    ]
}

/// The speeds and angles the shortest-push search covers: 0.2–2 m/s and the
/// file's φ other than π/4.
pub fn shortest_candidates(study: &Study) -> Vec<(f64, f64)> {
    let mut phis: Vec<f64> = study
        .phis
        .iter()
        .cloned()
        .filter(|p| (p - FRAC_PI_4).abs() > 1e-9)
        .collect();
    phis.sort_by(f64::total_cmp);
    phis.dedup();
    let mut out = Vec::new();
    for v in [0.2, 0.5, 1.0, 1.5, 2.0] {
        for &phi in &phis {
            out.push((v, phi));
        }
    }
    out
}

/// One row of `identifiability.csv`: one component of one parameter set at
/// one push.
#[derive(Debug, Clone)]
pub struct Row {
    /// The push.
    pub point: Point,
    /// Index into [`sets`].
    pub set: usize,
    /// The parameter.
    pub param: Param,
    /// 0 for a scalar or x, 1 for y.
    pub component: usize,
    /// The true value (the file's).
    pub truth: f64,
    /// The component's scale ([`Parametrised::scales`]): relative std is
    /// std / scale.
    pub scale: f64,
    /// Fisher std at the stated noise; NaN where unidentifiable.
    pub fisher_std: f64,
    /// Every component of the set is identifiable here. Where one is not,
    /// the others' std is conditional on it being known: kept in the CSV,
    /// not drawn.
    pub set_identifiable: bool,
    /// Empirical std of the noisy fits and their number (check rows only).
    pub empirical: Option<(f64, usize)>,
    /// The model's assumption checks that fail on this push (empty: all hold).
    pub violated: Vec<&'static str>,
}

impl Row {
    /// Fisher std over the component's scale.
    pub fn relative_std(&self) -> f64 {
        self.fisher_std / self.scale
    }
    /// Within the shortest-push target at [`SIGMAS`] σ (μ and I only).
    pub fn within_target(&self) -> Option<bool> {
        let target = match self.param {
            Param::MuScale => MU_TARGET,
            Param::InertiaCm => INERTIA_TARGET,
            _ => return None,
        };
        Some(SIGMAS * self.relative_std() <= target)
    }
    /// The fields of its `identifiability.csv` record ([`HEADER`]).
    pub(super) fn csv(&self) -> [String; 19] {
        let p = &self.point;
        let opt = |v: f64| {
            if v.is_finite() {
                format!("{v}")
            } else {
                String::new()
            }
        };
        let (emp, fits, ratio) = match self.empirical {
            Some((e, n)) => (format!("{e}"), format!("{n}"), opt(e / self.fisher_std)),
            None => (String::new(), String::new(), String::new()),
        };
        [
            p.sweep.to_string(),
            p.speed.to_string(),
            p.duration.to_string(),
            p.segments.to_string(),
            p.phi.to_string(),
            set_name(&sets()[self.set]),
            self.param.name().to_string(),
            if self.param.dim() == 2 {
                ["x", "y"][self.component]
            } else {
                ""
            }
            .to_string(),
            self.truth.to_string(),
            self.scale.to_string(),
            opt(self.fisher_std),
            opt(self.relative_std()),
            self.fisher_std.is_finite().to_string(),
            self.set_identifiable.to_string(),
            emp,
            fits,
            ratio,
            self.within_target()
                .map_or(String::new(), |b| b.to_string()),
            if self.violated.is_empty() {
                "hold".to_string()
            } else {
                self.violated.join(";")
            },
        ]
    }
}

/// The columns of `identifiability.csv`.
pub(super) const HEADER: [&str; 19] = [
    "sweep",
    "speed_m_s",
    "duration_s",
    "segments",
    "phi_rad",
    "set",
    "parameter",
    "component",
    "truth",
    "scale",
    "fisher_std",
    "relative_std",
    "identifiable",
    "set_identifiable",
    "empirical_std",
    "fits",
    "ratio",
    "within_target",
    "assumptions",
];

impl Study {
    /// The names of the model's assumption checks that fail on `point`'s
    /// push (the pusher pulls, the contact slips, a support sticks, …).
    pub fn violated(&self, point: &Point) -> anyhow::Result<Vec<&'static str>> {
        let a = pushval_model::DynamicModel::default()
            .simulate(&self.scenario(point).problem())
            .context("the assumption checks")?
            .assumptions;
        Ok([
            ("pulling", a.pulling.is_some()),
            ("contact_slip", a.contact_slip.is_some()),
            ("force_limit", a.force_limit.is_some()),
            ("sticking", a.sticking.is_some()),
            ("pulling_impulse", a.pulling_impulse.is_some()),
            ("runaway", a.runaway.is_some()),
        ]
        .into_iter()
        .filter_map(|(n, v)| v.then_some(n))
        .collect())
    }

    /// The rows of set `set` (index into [`sets`]) at `point`, with the
    /// empirical std where a check gives it.
    pub fn rows(
        &self,
        point: &Point,
        set: usize,
        check: Option<&Check>,
    ) -> anyhow::Result<Vec<Row>> {
        let params = &sets()[set];
        let model = Parametrised::new(&self.scenario(point), params).map_err(anyhow::Error::msg)?;
        let (std, truth) = match check {
            Some(c) => (c.fisher.clone(), c.truth.clone()),
            None => self.fisher_std(point, params)?,
        };
        let scales = model.scales();
        let violated = self.violated(point)?;
        let set_identifiable = std.iter().all(|v| v.is_finite());
        Ok(model
            .slots()
            .into_iter()
            .enumerate()
            .map(|(j, (param, component))| Row {
                point: point.clone(),
                set,
                param,
                component,
                truth: truth[j],
                scale: scales[j],
                fisher_std: std[j],
                set_identifiable,
                empirical: check.map(|c| (c.empirical[j], c.fits)),
                violated: violated.clone(),
            })
            .collect())
    }
}

/// What the study found.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Every row of `identifiability.csv`.
    pub rows: Vec<Row>,
    /// The empirical checks.
    pub checks: Vec<Check>,
    /// The shortest push per candidate speed and φ.
    pub shortest: Vec<Shortest>,
    /// The files written.
    pub files: Vec<PathBuf>,
}

/// The shortest push at one speed and φ.
#[derive(Debug, Clone, PartialEq)]
pub struct Shortest {
    /// m/s
    pub speed: f64,
    /// rad
    pub phi: f64,
    /// s; None: longer than the longest searched.
    pub duration: Option<f64>,
    /// The model's assumption checks that fail on that push.
    pub violated: Vec<&'static str>,
}

impl Outcome {
    /// The shortest push over every candidate on which the model's
    /// assumptions hold (`valid`), or over all of them: (speed, φ, duration).
    pub fn best(&self, valid: bool) -> Option<(f64, f64, f64)> {
        self.shortest
            .iter()
            .filter(|c| !valid || c.violated.is_empty())
            .filter_map(|c| c.duration.map(|d| (c.speed, c.phi, d)))
            .min_by(|a, b| a.2.total_cmp(&b.2).then(a.0.total_cmp(&b.0)))
    }
}

pub(super) fn component_name(p: Param, k: usize) -> String {
    if p.dim() == 1 {
        p.name().into()
    } else {
        format!("{}[{}]", p.name(), ["x", "y"][k])
    }
}
