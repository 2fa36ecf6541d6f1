//! The sweep figures of `pushval report`: κ against the Froude number, τ
//! and the relaxation length, the kinematic model's validity map and the
//! assumptions map, each an SVG with its CSV and a README entry, built from
//! the rows of the sweep cells ([`super::cells`]).

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use plotters::style::RGBColor;

use super::cells::{
    assume_cell, assume_geometry, segment, steady, Geometry, Grids, Task, ASSUME_PHI_LO,
    CONTACT_MU, FORCE_SAMPLES, SCHEDULE_PHIS, SEGMENT_LENGTH,
};
use super::readme::Entry;
use crate::outdir::{num, Csv, Writer};
use crate::plot::{
    heat_map, Axis, Figure, Legend, MapCell, Panel, Scale, Series, Stroke, BLUE_, DARK, PALETTE,
    PURPLE,
};
use pushval_model::{kappa, kappa_series, KappaSeries};

/// `(min, max)` of the finite values (`(NaN, NaN)` when there are none).
fn min_max(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        (f64::NAN, f64::NAN)
    } else {
        (lo, hi)
    }
}

/// Value of `y` at `x` by linear interpolation in log x (points sorted by x).
fn interp_log(points: &[(f64, f64)], x: f64) -> f64 {
    for w in points.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x >= x0 && x <= x1 {
            let s = (x.ln() - x0.ln()) / (x1.ln() - x0.ln());
            return y0 + s * (y1 - y0);
        }
    }
    f64::NAN
}

/// Smallest x at which y first reaches `level` (log-linear interpolation), if any.
pub fn first_crossing(points: &[(f64, f64)], level: f64) -> Option<f64> {
    if points.first().is_some_and(|p| p.1 >= level) {
        return points.first().map(|p| p.0);
    }
    points.windows(2).find_map(|w| {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        (y0 < level && y1 >= level).then(|| {
            let s = (level - y0) / (y1 - y0);
            (x0.ln() + s * (x1.ln() - x0.ln())).exp()
        })
    })
}

/// Every sweep figure; returns their README entries.
pub fn figures(
    geoms: &[Geometry],
    tasks: &[Task],
    rows: &[Vec<f64>],
    quick: bool,
    w: &mut Writer,
) -> anyhow::Result<Vec<Entry>> {
    let grids = Grids::new(quick);
    Ok(vec![
        kappa_figure(geoms, &grids, tasks, rows, w)?,
        tau_figure(geoms, &grids, tasks, rows, w)?,
        validity_figure(geoms, &grids, tasks, rows, w)?,
        assumptions_figure(geoms, &grids, tasks, rows, w)?,
    ])
}

/// The relative error a closed form of κ may have below its Froude limit.
pub const KAPPA_LIMIT_TOLERANCE: f64 = 0.01;

/// One κ curve: a geometry and push direction, its closed-form series and
/// the Froude numbers below which each closed form stays within
/// [`KAPPA_LIMIT_TOLERANCE`] of the exact κ.
struct KappaCurve {
    geom: usize,
    phi: usize,
    series: Option<KappaSeries>,
    /// `[first order, second order]` (`first_order_froude_limit`,
    /// `second_order_froude_limit`); NaN where no series exists.
    limits: [f64; 2],
    /// `(Fr, κ exact)` on the grid.
    exact: Vec<(f64, f64)>,
}

impl KappaCurve {
    /// `[1 + κ₁ Fr, 1 + κ₁ Fr + κ₂ Fr²]` (NaN without a series).
    fn closed(&self, fr: f64) -> [f64; 2] {
        self.series
            .map_or([f64::NAN; 2], |s| [s.first_order(fr), s.second_order(fr)])
    }
}

/// `(x, y)` points up to the first one outside `[lo, hi]` in y (a closed
/// form leaves the panel and is not drawn beyond).
fn within(points: impl IntoIterator<Item = (f64, f64)>, lo: f64, hi: f64) -> Vec<(f64, f64)> {
    points
        .into_iter()
        .take_while(|p| p.1 >= lo && p.1 <= hi)
        .collect()
}

fn kappa_figure(
    geoms: &[Geometry],
    grids: &Grids,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let mut curves: Vec<KappaCurve> = Vec::new();
    for (gi, g) in geoms.iter().enumerate() {
        for (pi, &phi) in g.phis.iter().enumerate() {
            let series = kappa_series(&g.body, phi);
            let limit = |f: fn(&pushval_model::Body, f64, f64) -> Option<f64>| {
                f(&g.body, phi, KAPPA_LIMIT_TOLERANCE).unwrap_or(f64::NAN)
            };
            curves.push(KappaCurve {
                geom: gi,
                phi: pi,
                series,
                limits: [
                    limit(kappa::first_order_froude_limit),
                    limit(kappa::second_order_froude_limit),
                ],
                exact: Vec::new(),
            });
        }
    }
    let mut csv = Csv::new(&[
        "geometry",
        "phi",
        "froude",
        "speed",
        "psi",
        "omega_steady",
        "kappa",
        "tau",
        "kappa1",
        "kappa2",
        "kappa_first_order",
        "kappa_second_order",
        "froude_limit_first_order",
        "froude_limit_second_order",
    ]);
    for (t, r) in tasks.iter().zip(rows) {
        if let Task::Kappa { geom, phi, i } = *t {
            let g = &geoms[geom];
            let fr = grids.fr[i];
            let c = curves
                .iter_mut()
                .find(|c| c.geom == geom && c.phi == phi)
                .expect("a curve per geometry and direction");
            let [k1, k2] = c.series.map_or([f64::NAN; 2], |s| [s.kappa1, s.kappa2]);
            let [first, second] = c.closed(fr);
            csv.row(&[
                g.name.to_string(),
                num(g.phis[phi]),
                num(fr),
                num(r[0]),
                num(r[1]),
                num(r[2]),
                num(r[3]),
                num(r[4]),
                num(k1),
                num(k2),
                num(first),
                num(second),
                num(c.limits[0]),
                num(c.limits[1]),
            ]);
            c.exact.push((fr, r[3]));
        }
    }
    // One panel per geometry: exact (solid), first order (dashed), second
    // order (dotted), one colour per push direction; then the closed forms'
    // relative errors, one colour per geometry, with the 1 % line.
    let (k_lo, k_hi) = min_max(curves.iter().flat_map(|c| c.exact.iter().map(|p| p.1)));
    let (y_lo, y_hi) = (k_lo.min(1.0) - 0.05, k_hi.max(1.0) + 0.05);
    let fr_axis = || Axis::log("Froude number Fr = v_c² / (μ̄ g L)");
    let mut panels = Vec::new();
    for (gi, g) in geoms.iter().enumerate().filter(|(_, g)| !g.phis.is_empty()) {
        let mut p = Panel::new(
            format!("κ = ω*/(v_c ψ): {}", g.name),
            fr_axis(),
            Axis::lin("κ").range(y_lo, y_hi),
        )
        .legend(Legend::LowerLeft);
        let mine: Vec<&KappaCurve> = curves.iter().filter(|c| c.geom == gi).collect();
        for c in &mine {
            p = p.series(
                Series::new(
                    format!("φ = {:.3}", g.phis[c.phi]),
                    PALETTE[c.phi % PALETTE.len()],
                    Stroke::Solid,
                )
                .points(c.exact.clone()),
            );
        }
        for (k, stroke, label) in [
            (0, Stroke::Dashed, "1 + κ₁ Fr (dashed)"),
            (1, Stroke::Dotted, "1 + κ₁ Fr + κ₂ Fr² (dotted)"),
        ] {
            for c in &mine {
                let pts = within(
                    c.exact.iter().map(|&(fr, _)| (fr, c.closed(fr)[k])),
                    y_lo,
                    y_hi,
                );
                let label = if c.phi == 0 { label } else { "" };
                p = p
                    .series(Series::new(label, PALETTE[c.phi % PALETTE.len()], stroke).points(pts));
            }
        }
        panels.push(p);
    }
    for (k, order) in [
        (0, "first order 1 + κ₁ Fr"),
        (1, "second order 1 + κ₁ Fr + κ₂ Fr²"),
    ] {
        let mut p = Panel::new(
            format!("relative error of the {order}"),
            fr_axis(),
            Axis::log("|κ_closed − κ| / κ"),
        )
        .legend(if k == 0 {
            Legend::UpperLeft
        } else {
            Legend::None
        });
        for c in &curves {
            let label = if c.phi == 0 { geoms[c.geom].name } else { "" };
            let pts: Vec<(f64, f64)> = c
                .exact
                .iter()
                .map(|&(fr, kappa)| (fr, ((c.closed(fr)[k] - kappa) / kappa).abs()))
                .filter(|q| q.1 > 0.0 && q.1.is_finite())
                .collect();
            p = p.series(
                Series::new(label, PALETTE[c.geom % PALETTE.len()], Stroke::Solid).points(pts),
            );
        }
        p = p.series(
            Series::new(
                if k == 0 {
                    "1 % (the Froude limits)"
                } else {
                    ""
                },
                DARK,
                Stroke::Dashed,
            )
            .width(1)
            .points(vec![
                (grids.fr[0], KAPPA_LIMIT_TOLERANCE),
                (*grids.fr.last().unwrap_or(&10.0), KAPPA_LIMIT_TOLERANCE),
            ]),
        );
        panels.push(p);
    }
    w.file("kappa.csv", csv.as_bytes())?;
    w.figure(
        "kappa.svg",
        &Figure {
            size: (1800, 1040),
            cols: 3,
            panels,
            key: None,
        },
    )?;
    let all: Vec<&Vec<(f64, f64)>> = curves.iter().map(|c| &c.exact).collect();
    let spread_at = |fr: f64| {
        let ks: Vec<f64> = all.iter().map(|c| interp_log(c, fr)).collect();
        let lo = ks.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = ks.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    };
    let fr_lo = grids.fr[0];
    let levels = [fr_lo, 0.01, 0.1, 1.0, 10.0];
    let table: Vec<String> = levels
        .iter()
        .map(|&fr| {
            let (lo, hi) = spread_at(fr);
            format!("| {fr} | {lo:.4} | {hi:.4} | {:.4} |", hi - lo)
        })
        .collect();
    // Observed orders of the closed forms' errors at the two smallest Fr.
    let order_of = |k: usize| {
        min_max(curves.iter().filter(|c| c.exact.len() >= 2).map(|c| {
            let e = |p: (f64, f64)| ((c.closed(p.0)[k] - p.1) / p.1).abs();
            let (a, b) = (c.exact[0], c.exact[1]);
            (e(b).ln() - e(a).ln()) / (b.0.ln() - a.0.ln())
        }))
    };
    let (o1, o2) = (order_of(0), order_of(1));
    let (c_lo, c_hi) = min_max(curves.iter().filter_map(|c| c.series.map(|s| s.kappa1)));
    let limits: Vec<String> = curves
        .iter()
        .map(|c| {
            let g = &geoms[c.geom];
            let (k1, k2) = c
                .series
                .map_or((f64::NAN, f64::NAN), |s| (s.kappa1, s.kappa2));
            let speed = |fr: f64| g.speed(fr);
            format!(
                "| {} | {:.3} | {k1:.4} | {k2:.4} | {} | {} |",
                g.name,
                g.phis[c.phi],
                limit_text(c.limits[0], speed(c.limits[0])),
                limit_text(c.limits[1], speed(c.limits[1])),
            )
        })
        .collect();
    let (l1_lo, l1_hi) = min_max(curves.iter().map(|c| c.limits[0]));
    let (l2_lo, l2_hi) = min_max(curves.iter().map(|c| c.limits[1]));
    Ok(Entry {
        figure: "kappa.svg".into(),
        data: vec!["kappa.csv".into()],
        text: format!(
            "κ = ω*/(v_c ψ), the paper's missing scaling factor between the dynamic and the \
             quasi-static model, against Fr (log x) for {n} curves: four geometries (one panel \
             each: the paper plate pushed at a corner on four supports, a triangle pushed on an \
             edge, the same square on a uniform pressure, a 3:1 rectangle pushed at a corner) and \
             three push directions each (colours). Solid: the exact κ (the steady root of the \
             dynamic model reached from ω = 0); dashed: the first-order closed form 1 + κ₁ Fr; \
             dotted: the second-order one 1 + κ₁ Fr + κ₂ Fr² (`pushval_model::kappa`: \
             κ₁ = −L (p_c · n_φ)/h'(ψ), κ₂ = κ₁² (1 − ψ h''(ψ)/(2 h'(ψ))), h the friction moment \
             about the contact per unit total friction; a closed form is drawn until it leaves \
             the panel). The bottom panels give their relative errors: at the two smallest Fr \
             they grow with Fr with the observed order {o1a:.2}–{o1b:.2} (first order) and \
             {o2a:.2}–{o2b:.2} (second order): the first-order formula is off by O(Fr²), the \
             second-order one by O(Fr³). Every curve starts at κ = 1; the slope κ₁ ranges over {c_lo:.3} to \
             {c_hi:.3}, so the curves do not collapse on Fr alone (a factor {ratio:.1} between \
             the slopes), and the spread (max − min κ) peaks near Fr ≈ 1.\n\n\
             The Froude number below which each closed form stays within \
             {tol} % of the exact κ (`first_order_froude_limit` / `second_order_froude_limit` \
             with tolerance {tolf}: the first Fr, on a scan of 8 points a decade bisected to \
             1e-10, where the relative error exceeds it; in brackets the pusher speed there): \
             the first order holds up to Fr = {l1_lo:.3}–{l1_hi:.3}, the second order up to \
             Fr = {l2_lo:.3}–{l2_hi:.3}.\n\n\
             | geometry | φ (rad) | κ₁ | κ₂ | Fr limit, first order (v_c) | Fr limit, second order (v_c) |\n\
             |---|---|---|---|---|---|\n{limits}\n\n\
             | Fr | min κ | max κ | spread |\n|---|---|---|---|\n{table}",
            n = curves.len(),
            o1a = o1.0,
            o1b = o1.1,
            o2a = o2.0,
            o2b = o2.1,
            ratio = c_lo.abs().max(c_hi.abs()) / c_lo.abs().min(c_hi.abs()),
            tol = 100.0 * KAPPA_LIMIT_TOLERANCE,
            tolf = KAPPA_LIMIT_TOLERANCE,
            limits = limits.join("\n"),
            table = table.join("\n"),
        ),
    })
}

/// A Froude limit and the pusher speed there, for the README.
fn limit_text(fr: f64, speed: f64) -> String {
    if fr.is_nan() {
        "no series".into()
    } else if fr.is_infinite() {
        "none up to 1e6".into()
    } else {
        format!("{fr:.4} ({speed:.3} m/s)")
    }
}

fn tau_figure(
    geoms: &[Geometry],
    grids: &Grids,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let mut csv = Csv::new(&[
        "phi",
        "speed",
        "froude",
        "omega_steady",
        "tau",
        "relaxation_length",
    ]);
    let mut tau_c: Vec<Vec<(f64, f64)>> = vec![Vec::new(); SCHEDULE_PHIS.len()];
    let mut len_c: Vec<Vec<(f64, f64)>> = vec![Vec::new(); SCHEDULE_PHIS.len()];
    for (t, r) in tasks.iter().zip(rows) {
        if let Task::Tau { phi, i } = *t {
            let v = grids.tau_v[i];
            csv.row(&[
                num(SCHEDULE_PHIS[phi]),
                num(v),
                num(r[3]),
                num(r[0]),
                num(r[1]),
                num(r[2]),
            ]);
            tau_c[phi].push((v, r[1]));
            len_c[phi].push((v, r[2]));
        }
    }
    let label = |phi: f64| {
        let d = phi - FRAC_PI_4;
        if d.abs() < 1e-12 {
            "φ = π/4".to_string()
        } else {
            format!("φ = π/4 {} {:.2}", if d > 0.0 { "+" } else { "−" }, d.abs())
        }
    };
    let mut p1 = Panel::new(
        "Relaxation time τ of the paper plate",
        Axis::log("pusher speed v_c (m/s)"),
        Axis::log("relaxation time τ (s)"),
    )
    .legend(Legend::UpperLeft);
    let mut p2 = Panel::new(
        "Relaxation length v_c τ",
        Axis::log("pusher speed v_c (m/s)"),
        Axis::log("relaxation length v_c τ (m)"),
    )
    .legend(Legend::UpperLeft);
    for (k, &phi) in SCHEDULE_PHIS.iter().enumerate() {
        p1 = p1.series(Series::new(label(phi), PALETTE[k], Stroke::Solid).points(tau_c[k].clone()));
        p2 = p2.series(Series::new(label(phi), PALETTE[k], Stroke::Solid).points(len_c[k].clone()));
    }
    let sq = &geoms[0];
    let l = sq.length;
    p2 = p2.series(
        Series::new(format!("L = |p_c − p_cm| = {l:.3} m"), DARK, Stroke::Dashed)
            .width(1)
            .points(vec![
                (grids.tau_v[0], l),
                (*grids.tau_v.last().unwrap_or(&2.0), l),
            ]),
    );
    w.file("tau.csv", csv.as_bytes())?;
    w.figure(
        "tau.svg",
        &Figure {
            size: (1500, 620),
            cols: 2,
            panels: vec![p1, p2],
            key: None,
        },
    )?;
    let slope = |c: &[(f64, f64)]| {
        let (a, b) = (c[0], c[1]);
        (b.1.ln() - a.1.ln()) / (b.0.ln() - a.0.ln())
    };
    let mut facts = Vec::new();
    for v in [0.2, 1.0] {
        let seg = segment(&sq.body, v, SCHEDULE_PHIS[0]);
        let (_, tau) = steady(&seg);
        facts.push(format!(
            "at v_c = {v} m/s τ = {tau:.3} s and v_c τ = {:.3} m ({:.2} L)",
            v * tau,
            v * tau / l
        ));
    }
    Ok(Entry {
        figure: "tau.svg".into(),
        data: vec!["tau.csv".into()],
        text: format!(
            "τ = −I_P/G'(ω*) and the relaxation length v_c τ (the push distance over which a \
             transient decays by 1/e) against v_c, for the five directions of the paper \
             schedule. At low speed τ ∝ v_c^{:.2} and v_c τ ∝ v_c^{:.2} (log–log slopes at the \
             slowest grid points, φ = π/4 + 0.3): the quasi-static limit is approached \
             quadratically in distance. For φ = π/4 + 0.3, {}.",
            slope(&tau_c[0]),
            slope(&len_c[0]),
            facts.join("; ")
        ),
    })
}

const CLASS_COLORS: [RGBColor; 5] = [
    RGBColor(199, 233, 192),
    RGBColor(255, 237, 160),
    RGBColor(253, 174, 97),
    RGBColor(215, 48, 39),
    RGBColor(120, 0, 30),
];

fn log_cell(x: f64, half: f64) -> (f64, f64) {
    (x * 10f64.powf(-half), x * 10f64.powf(half))
}

fn validity_figure(
    geoms: &[Geometry],
    grids: &Grids,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let sq = &geoms[0];
    let levels = [0.01, 0.05, 0.10];
    let mut csv = Csv::new(&[
        "froude",
        "phi",
        "speed",
        "psi",
        "omega_steady",
        "tau",
        "duration",
        "theta_dynamic",
        "theta_kinematic",
        "error",
    ]);
    let dphi = FRAC_PI_2 / grids.val_phi.len() as f64;
    let mut cells = Vec::new();
    let mut by_phi: Vec<Vec<(f64, f64)>> = vec![Vec::new(); grids.val_phi.len()];
    for (t, r) in tasks.iter().zip(rows) {
        if let Task::Validity { i, j } = *t {
            let (fr, phi) = (grids.fr[i], grids.val_phi[j]);
            let mut row = vec![num(fr), num(phi)];
            row.extend(r.iter().map(|v| num(*v)));
            csv.row(&row);
            let eps = r[7];
            let class = levels.iter().filter(|&&l| eps >= l).count();
            cells.push(MapCell {
                x: log_cell(fr, grids.fr_step / 2.0),
                y: (phi - dphi / 2.0, phi + dphi / 2.0),
                value: class as f64,
                mark: String::new(),
            });
            by_phi[j].push((fr, eps));
        }
    }
    let fr_hi = *grids.fr.last().unwrap_or(&10.0);
    let (xlo, xhi) = (
        log_cell(grids.fr[0], grids.fr_step / 2.0).0,
        log_cell(fr_hi, grids.fr_step / 2.0).1,
    );
    let scale = Scale::Classes(CLASS_COLORS[..4].to_vec());
    let mut panel = heat_map(
        format!(
            "Kinematic model's angle error over a {SEGMENT_LENGTH} L push from ω = 0 (paper plate)"
        ),
        Axis::log("Froude number Fr = v_c² / (μ̄ g L)").range(xlo, xhi),
        Axis::lin("push direction φ (rad)").range(0.0, FRAC_PI_2),
        &cells,
        &scale,
    )
    .legend(Legend::UpperLeft);
    let line_colors = [BLUE_, PURPLE, DARK];
    let mut crossings = Vec::new();
    for (k, &lvl) in levels.iter().enumerate() {
        let pts: Vec<(f64, f64)> = by_phi
            .iter()
            .zip(&grids.val_phi)
            .filter_map(|(c, &phi)| first_crossing(c, lvl).map(|x| (x, phi)))
            .collect();
        crossings.push(pts.clone());
        panel = panel.series(
            Series::new(
                format!("ε = {:.0} %", lvl * 100.0),
                line_colors[k],
                Stroke::Solid,
            )
            .width(3)
            .points(pts),
        );
    }
    panel = panel.series(
        Series::new("φ = π/4 (ψ = 0)", DARK, Stroke::Dashed)
            .width(1)
            .points(vec![(xlo, FRAC_PI_4), (xhi, FRAC_PI_4)]),
    );
    w.file("validity.csv", csv.as_bytes())?;
    w.figure(
        "validity.svg",
        &Figure {
            size: (1250, 750),
            cols: 1,
            panels: vec![panel],
            key: Some(scale.key(
                "error ε",
                &["ε < 1 %", "1 % ≤ ε < 5 %", "5 % ≤ ε < 10 %", "ε ≥ 10 %"],
                &[],
            )),
        },
    )?;
    let mut lines = Vec::new();
    for (k, &lvl) in levels.iter().enumerate() {
        let pts = &crossings[k];
        let worst = pts.iter().copied().min_by(|a, b| a.0.total_cmp(&b.0));
        let best = pts.iter().copied().max_by(|a, b| a.0.total_cmp(&b.0));
        match (worst, best) {
            (Some(wst), Some(bst)) => lines.push(format!(
                "| {:.0} % | {:.3} (v_c = {:.2} m/s, φ = {:.2}) | {:.3} (φ = {:.2}) | {}/{} |",
                lvl * 100.0,
                wst.0,
                sq.speed(wst.0),
                wst.1,
                bst.0,
                bst.1,
                pts.len(),
                grids.val_phi.len()
            )),
            _ => lines.push(format!("| {:.0} % | not reached | – | 0 |", lvl * 100.0)),
        }
    }
    Ok(Entry {
        figure: "validity.svg".into(),
        data: vec!["validity.csv".into()],
        text: format!(
            "Where the kinematic model is good enough, over (Fr, φ) for the paper plate. Error \
             definition: the object moves straight with the pusher (ω = 0) when a push of length \
             d = {SEGMENT_LENGTH} L = {:.2} m starts (duration d/v_c); ε = |Δθ_dynamic − \
             Δθ_kinematic| / |Δθ_kinematic| is the relative error of the angle the kinematic model \
             says the object turns over it (Δθ_dynamic by RK4 on the scalar ODE, steps τ/40). It \
             combines the steady mismatch (κ − 1) and the transient lag (≈ τ/duration ∝ Fr). \
             Colours: the classes; lines: the smallest Fr at which ε reaches 1 %, 5 %, 10 % for \
             each φ. Boundary Fr:\n\n\
             | ε | smallest Fr over φ (worst direction) | largest Fr over φ | directions that reach it |\n\
             |---|---|---|---|\n{}",
            SEGMENT_LENGTH * sq.length,
            lines.join("\n")
        ),
    })
}

fn assumptions_figure(
    geoms: &[Geometry],
    grids: &Grids,
    tasks: &[Task],
    rows: &[Vec<f64>],
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let bounds = [0.2, 0.5, CONTACT_MU];
    let mut csv = Csv::new(&[
        "contact",
        "speed",
        "phi",
        "froude",
        "omega_steady",
        "cone_angle_max",
        "mu_required",
        "force_max",
    ]);
    let names = ["corner", "edge_middle"];
    let scale = Scale::Classes(CLASS_COLORS.to_vec());
    let dv = 2.0 / grids.as_v.len() as f64;
    let mut panels = Vec::new();
    let mut texts = Vec::new();
    for k in 0..2 {
        let g = assume_geometry(geoms, k);
        let dphi = PI / grids.as_phi[k].len() as f64;
        let mut cells = Vec::new();
        let mut counts = [0usize; 5];
        let mut pulling: Vec<f64> = Vec::new();
        // Directions that do not slip at the slowest and at the fastest speed.
        let mut hold_slow: Vec<f64> = Vec::new();
        let mut hold_fast: Vec<f64> = Vec::new();
        for (t, r) in tasks.iter().zip(rows) {
            let Task::Assume { k: kk, i, j } = *t else {
                continue;
            };
            if kk != k {
                continue;
            }
            let (v, phi) = (grids.as_v[i], grids.as_phi[k][j]);
            csv.row(&[
                names[k].to_string(),
                num(v),
                num(phi),
                num(g.froude(v)),
                num(r[0]),
                num(r[1]),
                num(r[2]),
                num(r[3]),
            ]);
            let class = if r[1] > FRAC_PI_2 {
                4
            } else {
                bounds.iter().filter(|&&b| r[2] > b).count()
            };
            counts[class] += 1;
            if class == 4 {
                pulling.push(phi);
            }
            if class < 3 && i == 0 {
                hold_slow.push(phi);
            }
            if class < 3 && i + 1 == grids.as_v.len() {
                hold_fast.push(phi);
            }
            cells.push(MapCell {
                x: (v - dv / 2.0, v + dv / 2.0),
                y: (phi - dphi / 2.0, phi + dphi / 2.0),
                value: class as f64,
                mark: String::new(),
            });
        }
        let lo = ASSUME_PHI_LO[k];
        let title = if k == 0 {
            "Pushed at the corner (−0.125, −0.125) m"
        } else {
            "Pushed at the middle of the bottom edge (0, −0.125) m"
        };
        let mut panel = heat_map(
            title,
            Axis::lin("pusher speed v_c (m/s)").range(0.0, 2.0),
            Axis::lin("push direction φ (rad)").range(lo, lo + PI),
            &cells,
            &scale,
        )
        .legend(Legend::LowerRight);
        if k == 0 {
            for (n, &phi) in SCHEDULE_PHIS.iter().enumerate() {
                let label = if n == 0 { "paper schedule φ" } else { "" };
                panel = panel.series(
                    Series::new(label, DARK, Stroke::Dashed)
                        .width(1)
                        .points(vec![(0.0, phi), (2.0, phi)]),
                );
            }
        }
        panels.push(panel);
        let total: usize = counts.iter().sum();
        let pct = |c: usize| 100.0 * c as f64 / total.max(1) as f64;
        let range = |v: &[f64]| match (v.first(), v.last()) {
            (Some(a), Some(b)) => format!("{a:.2} to {b:.2} rad"),
            _ => "none".to_string(),
        };
        texts.push(format!(
            "{} contact: {:.0} % of the cells need μ ≤ 0.2, {:.0} % 0.2–0.5, {:.0} % 0.5–0.8, \
             {:.0} % slip at μ_c = {CONTACT_MU}, {:.0} % pull (pulling directions: {}); the \
             contact holds at μ_c = {CONTACT_MU} for φ in {} at {} m/s and in {} at {} m/s (cell \
             centres)",
            if k == 0 { "Corner" } else { "Edge-middle" },
            pct(counts[0]),
            pct(counts[1]),
            pct(counts[2]),
            pct(counts[3]),
            pct(counts[4]),
            range(&pulling),
            range(&hold_slow),
            grids.as_v[0],
            range(&hold_fast),
            grids.as_v[grids.as_v.len() - 1],
        ));
    }
    w.file("assumptions.csv", csv.as_bytes())?;
    w.figure(
        "assumptions.svg",
        &Figure {
            size: (1700, 720),
            cols: 2,
            panels,
            key: Some(scale.key(
                "needed contact μ",
                &[
                    "μ_req ≤ 0.2",
                    "0.2 < μ_req ≤ 0.5",
                    "0.5 < μ_req ≤ 0.8",
                    "μ_req > 0.8: slips",
                    "pusher would pull",
                ],
                &[],
            )),
        },
    )?;
    let sq = &geoms[0];
    let sched: Vec<String> = SCHEDULE_PHIS
        .iter()
        .map(|&phi| format!("{:.2}", assume_cell(sq, phi, 1.0)[2]))
        .collect();
    Ok(Entry {
        figure: "assumptions.svg".into(),
        data: vec!["assumptions.csv".into()],
        text: format!(
            "Where the model's contact assumptions fail, over (v_c, φ) for the paper plate pushed \
             at its corner (left, the paper's contact) and at the middle of an edge (right). For \
             each cell the dynamic model's pusher force f_c(ω) is evaluated along the segment's \
             transient from ω = 0 to ω* ({FORCE_SAMPLES} steps; ω relaxes monotonically and f_c \
             depends on ω alone); α is its largest angle from the cone of inward normals at the \
             contact (at a corner, the quadrant between the two edges' normals), μ_req = tan α \
             the contact friction needed not to slip, and α > 90° means the pusher would have to \
             pull. {}. Along the paper schedule at 1 m/s the corner needs μ_req = {}: the paper's \
             inputs never slip or pull.",
            texts.join(". "),
            sched.join(", ")
        ),
    })
}
