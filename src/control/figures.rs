//! The control study's figures: `success.svg` (goals reached per engine,
//! mode and plant) and `paths.svg` (the paths of a plan in every engine).

use std::collections::BTreeMap;

use anyhow::Context;
use pushval_control::plan::{straight_time, PlanSpec, Planner};
use pushval_control::predict::Start;
use pushval_control::{Goal, ModelKind, Reach};
use pushval_model::Problem;

/// One success.csv row's key: engine, speed (bits), rule (`release` or
/// `rest`), plan predictor, mode, plant.
pub(crate) type Group = (
    String,
    u64,
    &'static str,
    &'static str,
    &'static str,
    &'static str,
);

use crate::plot::{self, Axis, Figure, Legend, MapCell, Panel, Scale, Series, Stroke};

/// The columns of the tables and of `success.svg`: plan predictor, mode,
/// plant.
pub(crate) const COLUMNS: [(&str, &str, &str); 8] = [
    ("dynamic", "open", "nominal"),
    ("dynamic", "mpc", "nominal"),
    ("dynamic", "open", "perturbed"),
    ("dynamic", "mpc", "perturbed"),
    ("kinematic", "open", "nominal"),
    ("kinematic", "mpc", "nominal"),
    ("kinematic", "open", "perturbed"),
    ("kinematic", "mpc", "perturbed"),
];

/// A column's short label, e.g. `dyn·open·nom`.
pub(crate) fn short(c: &(&str, &str, &str)) -> String {
    format!(
        "{}·{}·{}",
        if c.0 == "dynamic" { "dyn" } else { "kin" },
        c.1,
        if c.2 == "nominal" { "nom" } else { "pert" }
    )
}

pub(crate) fn success_figure(
    names: &[String],
    speeds: &[f64],
    summary: &BTreeMap<Group, (usize, usize, f64, f64)>,
    failed: &BTreeMap<Group, usize>,
) -> Figure {
    // A sequential ramp, worst to best, so the colours read in order.
    let colors = vec![
        plotters::style::RGBColor(178, 24, 43),
        plotters::style::RGBColor(239, 138, 98),
        plotters::style::RGBColor(253, 219, 199),
        plotters::style::RGBColor(166, 219, 160),
        plotters::style::RGBColor(27, 120, 55),
    ];
    let scale = Scale::Classes(colors);
    let mut panels = Vec::new();
    for (v, at) in speeds
        .iter()
        .flat_map(|&v| pushval_control::At::ALL.map(|at| (v, at.as_str())))
    {
        let mut cells = Vec::new();
        let n = names.len();
        for (row, name) in names.iter().enumerate() {
            let y = (n - 1 - row) as f64;
            for (col, c) in COLUMNS.iter().enumerate() {
                let k: Group = (name.clone(), v.to_bits(), at, c.0, c.1, c.2);
                let (value, mark) = match summary.get(&k) {
                    Some(&(ok, total, _, _)) if total > 0 => {
                        let share = ok as f64 / total as f64;
                        let class = if share >= 0.95 {
                            4.0
                        } else if share >= 0.75 {
                            3.0
                        } else if share >= 0.5 {
                            2.0
                        } else if share >= 0.25 {
                            1.0
                        } else {
                            0.0
                        };
                        // Runs that ended with an engine error count as
                        // misses and are marked in the cell.
                        let mark = match failed.get(&k).copied().unwrap_or(0) {
                            0 => format!("{ok}/{total}"),
                            f => format!("{ok}/{total} ({f} failed)"),
                        };
                        (class, mark)
                    }
                    _ => (f64::NAN, String::new()),
                };
                cells.push(MapCell {
                    x: (col as f64 + 3.0, col as f64 + 4.0),
                    y: (y, y + 1.0),
                    value,
                    mark,
                });
            }
            // The engine's name in a white column on the left.
            cells.push(MapCell {
                x: (0.0, 3.0),
                y: (y, y + 1.0),
                value: 5.0,
                mark: name.clone(),
            });
        }
        for (col, c) in COLUMNS.iter().enumerate() {
            cells.push(MapCell {
                x: (col as f64 + 3.0, col as f64 + 4.0),
                y: (n as f64, n as f64 + 1.0),
                value: 5.0,
                mark: short(c),
            });
        }
        let mut with_white = scale.clone();
        if let Scale::Classes(c) = &mut with_white {
            c.push(plotters::style::RGBColor(255, 255, 255));
        }
        let panel = plot::heat_map(
            format!(
                "goals reached at {v} m/s, judged {}",
                if at == "rest" {
                    "at rest"
                } else {
                    "at the release"
                }
            ),
            Axis::lin("plan predictor · open loop or MPC · plant")
                .range(0.0, 11.0)
                .without_ticks(),
            Axis::lin("engine")
                .range(0.0, n as f64 + 1.0)
                .without_ticks(),
            &cells,
            &with_white,
        )
        .legend(Legend::None);
        panels.push(panel);
    }
    let labels = ["< 25 %", "25–50 %", "50–75 %", "75–95 %", "≥ 95 %"];
    let notes = vec![
        "goals reached (20 mm, 5°) judged".to_string(),
        "at the release or at rest (an".to_string(),
        "engine that cannot release: at".to_string(),
        "the release, runs.csv judged_at)".to_string(),
        "dyn/kin: plan made on the".to_string(),
        "dynamic / kinematic model;".to_string(),
        "pert: plant μ × 0.8, I_cm × 1.2".to_string(),
    ];
    let key = scale.key("success", &labels, &notes);
    let rows = names.len().max(4) as u32;
    Figure {
        size: (
            1500,
            120 + 34 * (rows + 1) * (speeds.len() * pushval_control::At::ALL.len()) as u32,
        ),
        cols: 1,
        panels,
        key: Some(key),
    }
}

/// The first goal's paths (the dynamic plan aimed at rest, open loop,
/// nominal plant, at the grid's fastest speed) in every engine through the
/// slide to rest, drawn over the goal and the dynamic model's prediction;
/// an engine that cannot release is drawn to the release and says so.
pub(crate) fn paths_figure(
    problem: &Problem,
    segments: usize,
    names: &[String],
    goals: &[Goal],
    speeds: &[f64],
) -> anyhow::Result<Figure> {
    let v = speeds.iter().copied().fold(f64::MIN, f64::max);
    let goal = goals[0];
    let start = Start::of_problem(problem);
    let spec = PlanSpec {
        segments,
        speed: v,
        predictor: ModelKind::Dynamic,
        at: pushval_control::At::Rest,
    };
    let mut planner = Planner::new(
        problem,
        goal,
        spec,
        straight_time(&start, &goal, v),
        Reach::default(),
    );
    let plan = planner.plan(&start).context("the first goal's plan")?;
    let mut p = problem.clone();
    p.pushes = plan.pushes.clone();
    p.release = Some(p.release.unwrap_or_default());
    p.sample_dt = p.duration() / 200.0;
    let mut held = p.clone();
    held.release = None;
    let model = pushval_model::DynamicModel::default();
    let traj = pushval_model::Simulator::simulate(&model, &p)?;
    // The plate's outline: the hull of its support points in the body frame
    // (about the centre of mass); the study's plate has one at each corner.
    let hull = hull(
        &problem
            .body
            .supports()
            .map(|s| (s.position.x, s.position.y))
            .collect::<Vec<_>>(),
    );
    let outline = |x: f64, y: f64, theta: f64| -> Vec<(f64, f64)> {
        let (sn, cs) = theta.sin_cos();
        hull.iter()
            .chain(hull.first())
            .map(|&(px, py)| (x + cs * px - sn * py, y + sn * px + cs * py))
            .collect()
    };
    // Small multiples: one panel per engine family (the name before its
    // first `_`), each with the model's path and the goal drawn as the
    // plate's outline at the goal pose; every engine's final pose marked.
    let family = |n: &str| n.split(['_', '[']).next().unwrap_or(n).to_string();
    let mut families: Vec<(String, Vec<&String>)> = Vec::new();
    for n in names {
        let f = family(n);
        match families.iter_mut().find(|(g, _)| *g == f) {
            Some((_, v)) => v.push(n),
            None => families.push((f, vec![n])),
        }
    }
    let mut panels = Vec::new();
    for (fam, members) in &families {
        let labels: Vec<&str> = members.iter().map(|s| s.as_str()).collect();
        let styles = plot::family_styles(&labels);
        let mut panel = Panel::new(
            format!("{fam}: goal 0 at {v} m/s, the dynamic plan open loop, to rest"),
            Axis::lin("x (m)"),
            Axis::lin("y (m)"),
        )
        .legend(Legend::Outside)
        .equal_aspect()
        .series(
            Series::new("dynamic model", plot::DARK, Stroke::Solid)
                .width(3)
                .points(traj.samples.iter().map(|s| (s.x, s.y)).collect()),
        )
        .series(
            Series::new("goal pose", plot::RED_, Stroke::Solid)
                .width(3)
                .points(outline(goal.x, goal.y, goal.theta)),
        );
        for (name, (color, stroke)) in members.iter().zip(styles) {
            let e = crate::registry::entry(name)
                .expect("listed")
                .default_engine();
            let (run, label) = match e.run(&p, e.default_dt()) {
                Err(pushval_model::ModelError::NoRelease { .. }) => (
                    e.run(&held, e.default_dt()),
                    format!("{name} (to the release: it cannot release)"),
                ),
                r => (r, (*name).clone()),
            };
            match run {
                Ok(run) => {
                    let pts: Vec<(f64, f64)> =
                        run.trajectory.samples.iter().map(|s| (s.x, s.y)).collect();
                    panel = panel.series(Series::new(label, color, stroke).points(pts));
                    if let Some(l) = run.trajectory.samples.last() {
                        panel = panel.series(
                            Series::new(format!("{name}: final pose"), color, Stroke::Dotted)
                                .points(outline(l.x, l.y, l.theta)),
                        );
                    }
                }
                Err(err) => eprintln!("control-study: paths: {name}: {err}"),
            }
        }
        panels.push(panel);
    }
    let cols = 2u32;
    let rows = (panels.len() as u32).div_ceil(cols).max(1);
    Ok(Figure {
        size: (1600, 520 * rows),
        cols: cols as usize,
        panels,
        key: None,
    })
}

/// The convex hull of `points` (counter-clockwise; Andrew's monotone chain:
/// a handful of support points, so no geometry crate is worth it here).
fn hull(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut lower: Vec<(f64, f64)> = Vec::new();
    for &q in &p {
        while lower.len() >= 2 && cross(lower[lower.len() - 2], lower[lower.len() - 1], q) <= 0.0 {
            lower.pop();
        }
        lower.push(q);
    }
    let mut upper: Vec<(f64, f64)> = Vec::new();
    for &q in p.iter().rev() {
        while upper.len() >= 2 && cross(upper[upper.len() - 2], upper[upper.len() - 1], q) <= 0.0 {
            upper.pop();
        }
        upper.push(q);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

#[cfg(test)]
mod tests {
    use super::hull;

    /// The hull of a square's corners and its centre is the four corners,
    /// counter-clockwise (positive signed area: the square's).
    #[test]
    fn the_hull_of_a_square_and_its_centre_is_the_square() {
        let h = hull(&[
            (1.0, 1.0),
            (-1.0, -1.0),
            (0.0, 0.0),
            (1.0, -1.0),
            (-1.0, 1.0),
        ]);
        assert_eq!(h.len(), 4, "{h:?}");
        let area: f64 = (0..h.len())
            .map(|i| {
                let (a, b) = (h[i], h[(i + 1) % h.len()]);
                a.0 * b.1 - b.0 * a.1
            })
            .sum::<f64>()
            / 2.0;
        assert_eq!(area, 4.0);
    }
}
