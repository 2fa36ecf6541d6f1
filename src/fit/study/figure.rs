//! `identifiability.svg`: the Fisher std of every parameter along each
//! sweep, from the study's rows.

use super::analysis::*;

pub(super) fn sweep_x(sweep: &str, p: &Point) -> f64 {
    match sweep {
        "speed" => p.speed,
        "duration" => p.duration,
        _ => p.segments as f64,
    }
}

/// Whether `p` (a check point) lies on `sweep`'s line through the base push.
pub(super) fn on_sweep(sweep: &str, p: &Point) -> bool {
    match sweep {
        "speed" => p.duration == 2.0 && p.segments == 1,
        "duration" => p.speed == 1.0 && p.segments == 1,
        _ => p.speed == 1.0 && p.duration == 2.0,
    }
}

pub(super) fn figure(o: &Outcome) -> Figure {
    let sweeps = [
        ("speed", Axis::lin("push speed v_c (m/s); 2 s, one segment")),
        (
            "duration",
            Axis::log("push duration (s); 1 m/s, one segment"),
        ),
        ("segments", Axis::lin("segments in 2 s at 1 m/s")),
    ];
    let color = |p: Param, k: usize| match (p, k) {
        (Param::MuScale, _) => plot::BLUE_,
        (Param::InertiaCm, _) => plot::RED_,
        (_, 0) => plot::GREEN_,
        _ => plot::PURPLE,
    };
    let mut top = Vec::new();
    let mut bottom = Vec::new();
    for (sweep, axis) in &sweeps {
        let on: Vec<&Row> = o.rows.iter().filter(|r| r.point.sweep == *sweep).collect();
        let (xlo, xhi) = on
            .iter()
            .map(|r| sweep_x(sweep, &r.point))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        // The segment panels' curves are flat: room above them for the legend.
        let (rel_axis, pos_axis) = if *sweep == "segments" {
            (
                Axis::log("Fisher std / value").range(1e-4, 1.0),
                Axis::log("Fisher std (mm)").range(0.05, 10.0),
            )
        } else {
            (
                Axis::log("Fisher std / value"),
                Axis::log("Fisher std (mm)"),
            )
        };
        let mut rel = Panel::new(
            format!("μ and I_cm: relative 1σ against {sweep}"),
            axis.clone(),
            rel_axis,
        )
        .legend(Legend::UpperRight);
        let mut pos = Panel::new(
            format!("contact / centre of friction: 1σ against {sweep}"),
            axis.clone(),
            pos_axis,
        )
        .legend(Legend::UpperRight);
        // Curves: μ and I of the sets without and with the contact; the
        // contact's and the centre of friction's components.
        for (set, stroke, label) in [
            (0usize, Stroke::Solid, "μ, I"),
            (1, Stroke::Dashed, "μ, I, contact"),
            (2, Stroke::Dashed, "μ, I, c.o.f."),
        ] {
            for (param, k) in Parametrised::slots_of(&sets()[set]) {
                let vector = param.dim() == 2;
                if !vector && set == 2 {
                    continue;
                }
                let pts: Vec<(f64, f64)> = on
                    .iter()
                    .filter(|r| r.set == set && r.param == param && r.component == k)
                    .filter(|r| r.set_identifiable)
                    .map(|r| {
                        let y = if vector {
                            r.fisher_std * 1e3
                        } else {
                            r.relative_std()
                        };
                        (sweep_x(sweep, &r.point), y)
                    })
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                let stroke = if vector && set == 1 {
                    Stroke::Solid
                } else {
                    stroke
                };
                let s = Series::new(
                    format!("{} ({label})", component_name(param, k)),
                    color(param, k),
                    stroke,
                )
                .points(pts);
                if vector {
                    pos = pos.series(s);
                } else {
                    rel = rel.series(s);
                }
            }
        }
        rel = rel
            .series(
                Series::new("μ target: 2σ ≤ 1 %", plot::BLUE_, Stroke::Dashed)
                    .width(1)
                    .points(vec![(xlo, MU_TARGET / SIGMAS), (xhi, MU_TARGET / SIGMAS)]),
            )
            .series(
                Series::new("I target: 2σ ≤ 2 %", plot::RED_, Stroke::Dashed)
                    .width(1)
                    .points(vec![
                        (xlo, INERTIA_TARGET / SIGMAS),
                        (xhi, INERTIA_TARGET / SIGMAS),
                    ]),
            );
        let checks: Vec<&Row> = o
            .rows
            .iter()
            .filter(|r| r.point.sweep == "check" && on_sweep(sweep, &r.point))
            .collect();
        let emp = |vector: bool| -> Vec<(f64, f64)> {
            checks
                .iter()
                .filter(|r| (r.param.dim() == 2) == vector)
                .filter_map(|r| {
                    let (e, _) = r.empirical?;
                    let y = if vector { e * 1e3 } else { e / r.scale };
                    Some((sweep_x(sweep, &r.point), y))
                })
                .collect()
        };
        for (vector, panel) in [(false, &mut rel), (true, &mut pos)] {
            let pts = emp(vector);
            if !pts.is_empty() {
                *panel = panel.clone().series(
                    Series::new(
                        format!("std of {FITS} noisy fits"),
                        plot::DARK,
                        Stroke::Dots,
                    )
                    .points(pts),
                );
            }
        }
        top.push(rel);
        bottom.push(pos);
    }
    let mut panels = top;
    panels.extend(bottom);
    Figure {
        size: (1650, 1000),
        cols: 3,
        panels,
        key: None,
    }
}
