//! The seed paper's figures, with rapier2d drawn over the models, and the two
//! questions the paper leaves open: which inertia, and what ω does at a switch.

use std::f64::consts::FRAC_PI_4;
use std::path::Path;

use anyhow::Context;
use pushval_model::{
    DynamicModel, KinematicModel, Problem, SegmentDynamics, Simulator, Switching, Trajectory,
};
use pushval_scenario::Scenario;
use rayon::prelude::*;

use super::readme::{Entry, KEY_FIGURES};
use crate::harness::reference_engine;
use crate::outdir::{num, num10, Csv, Writer};
use crate::plot::{Axis, Figure, Legend, Panel, Series, Stroke, BLUE_, DARK, GREEN_, ORANGE, RED_};

/// The pusher speeds of the paper's ω(t) figure (m/s).
pub const SPEEDS: [f64; 5] = [0.2, 0.4, 0.6, 0.8, 1.0];

/// The dynamic, kinematic and engine runs of one problem.
#[derive(Debug, Clone)]
pub struct Runs {
    pub dynamic: Trajectory,
    pub kinematic: Trajectory,
    pub engine: Trajectory,
}

fn load(dir: &Path, name: &str) -> anyhow::Result<Scenario> {
    Scenario::from_path(dir.join(name)).map_err(anyhow::Error::from)
}

/// The scenario with every push's speed set to `speed`.
pub fn at_speed(sc: &Scenario, speed: f64) -> Scenario {
    let mut s = sc.clone();
    for p in &mut s.pushes {
        p.speed = speed;
    }
    s.name = format!("{}@{speed}", sc.name);
    s
}

fn run_problem(sc: &Scenario, problem: &Problem) -> anyhow::Result<Runs> {
    let dynamic = DynamicModel::default()
        .simulate(problem)
        .with_context(|| format!("{}: dynamic model", sc.name))?;
    let kinematic = KinematicModel
        .simulate(problem)
        .with_context(|| format!("{}: kinematic model", sc.name))?;
    let e = reference_engine(sc);
    let engine = e
        .run(problem, e.default_dt())
        .with_context(|| format!("{}: {}", sc.name, e.name()))?
        .trajectory;
    Ok(Runs {
        dynamic,
        kinematic,
        engine,
    })
}

/// Runs the scenario's problem in the three models.
pub fn run(sc: &Scenario) -> anyhow::Result<Runs> {
    run_problem(sc, &sc.problem())
}

/// Largest |ω_a − ω_b| over common samples (rad/s), optionally inside a time window.
pub fn max_omega_diff(a: &Trajectory, b: &Trajectory, window: Option<(f64, f64)>) -> f64 {
    a.samples
        .iter()
        .zip(&b.samples)
        .filter(|(s, _)| window.is_none_or(|(t0, t1)| s.t >= t0 - 1e-12 && s.t <= t1 + 1e-12))
        .map(|(s, r)| (s.omega - r.omega).abs())
        .fold(0.0, f64::max)
}

/// Largest centre-of-mass distance over common samples (m).
pub fn max_position_diff(a: &Trajectory, b: &Trajectory) -> f64 {
    a.samples
        .iter()
        .zip(&b.samples)
        .map(|(s, r)| (s.x - r.x).hypot(s.y - r.y))
        .fold(0.0, f64::max)
}

/// Per segment: kinematic ω = v ψ, the dynamic model's steady ω* (the state
/// a segment starting at ω = 0 converges to) and τ.
pub fn segment_steady(problem: &Problem) -> Vec<(f64, Option<f64>, Option<f64>)> {
    problem
        .pushes
        .iter()
        .map(|p| {
            let seg = SegmentDynamics::new(&problem.body, p);
            let roots = seg.steady_states();
            let st = seg.attractor(&roots, 0.0);
            let kin = pushval_model::kinematic::omega(&problem.body, p).unwrap_or(f64::NAN);
            (kin, st.map(|s| s.omega), st.and_then(|s| s.tau))
        })
        .collect()
}

/// Largest |ω* − v ψ| / |v ψ| over the segments that turn (|ψ| L > 1e-6).
fn steady_gap(problem: &Problem, length: f64) -> f64 {
    segment_steady(problem)
        .iter()
        .zip(&problem.pushes)
        .filter_map(|((kin, st, _), p)| {
            let st = (*st)?;
            (kin.abs() * length > 1e-6 * p.speed).then(|| ((st - kin) / kin).abs())
        })
        .fold(0.0, f64::max)
}

fn omega_pts(tr: &Trajectory, every: usize, window: Option<(f64, f64)>) -> Vec<(f64, f64)> {
    tr.samples
        .iter()
        .filter(|s| window.is_none_or(|(a, b)| s.t >= a - 1e-12 && s.t <= b + 1e-12))
        .step_by(every.max(1))
        .map(|s| (s.t, s.omega))
        .collect()
}

fn pts(
    tr: &Trajectory,
    every: usize,
    f: impl Fn(&pushval_model::Sample) -> (f64, f64),
) -> Vec<(f64, f64)> {
    tr.samples.iter().step_by(every.max(1)).map(f).collect()
}

fn traj_rows(csv: &mut Csv, label: &[String], tr: &Trajectory) {
    for s in &tr.samples {
        let mut row = label.to_vec();
        row.extend([
            num10(s.t),
            num10(s.x),
            num10(s.y),
            num10(s.theta),
            num10(s.omega),
        ]);
        csv.row(&row);
    }
}

const TRAJ_COLS: [&str; 5] = ["t", "x", "y", "theta", "omega"];

fn header(first: &[&'static str]) -> Vec<&'static str> {
    first.iter().copied().chain(TRAJ_COLS).collect()
}

/// Every paper figure; returns their README entries.
pub fn figures(dir: &Path, w: &mut Writer) -> anyhow::Result<Vec<Entry>> {
    let base = load(dir, "paper-square-v1.0.toml")?;
    let slippery = [
        load(dir, "slippery-square-v0.2.toml")?,
        load(dir, "slippery-square-v1.0.toml")?,
    ];
    let heavy = load(dir, "heavy-square-v1.0.toml")?;
    let printed = load(dir, "printed-inertia-v1.0.toml")?;

    // Every run is independent: run them in parallel, in a fixed order.
    let mut scenes: Vec<Scenario> = SPEEDS.iter().map(|&v| at_speed(&base, v)).collect();
    scenes.extend(slippery.iter().cloned());
    scenes.push(heavy.clone());
    scenes.push(printed.clone());
    let runs: Vec<Runs> = scenes
        .par_iter()
        .map(run)
        .collect::<anyhow::Result<Vec<_>>>()?;
    let paper_runs = &runs[..SPEEDS.len()];
    let slippery_runs = &runs[SPEEDS.len()..SPEEDS.len() + 2];
    let heavy_run = &runs[SPEEDS.len() + 2];
    let printed_run = &runs[SPEEDS.len() + 3];

    let mut entries = vec![phi_input(&base, w)?];
    entries.push(omega_figure(&base, paper_runs, w)?);
    for (i, v) in [(0usize, 0.2), (4, 1.0)] {
        entries.push(path_figure(
            &scenes[i],
            &paper_runs[i],
            &format!("path_v{v:.1}"),
            &format!("Paper plate (μ 0.5) at v_c = {v} m/s"),
            w,
        )?);
    }
    entries.push(slippery_omega(&slippery, slippery_runs, w)?);
    for (sc, r) in slippery.iter().zip(slippery_runs) {
        let v = sc.pushes[0].speed;
        entries.push(path_figure(
            sc,
            r,
            &format!("slippery_path_v{v:.1}"),
            &format!("Slippery floor (μ 0.1) at v_c = {v} m/s"),
            w,
        )?);
    }
    entries.push(mass_figure(&paper_runs[4], heavy_run, w)?);
    entries.push(inertia_figure(
        &base,
        &printed,
        &paper_runs[4],
        printed_run,
        w,
    )?);
    entries.push(switching_figure(&base, w)?);
    Ok(entries)
}

fn phi_input(sc: &Scenario, w: &mut Writer) -> anyhow::Result<Entry> {
    let problem = sc.problem();
    let mut csv = Csv::new(&["segment", "t_start", "t_end", "phi", "phi_minus_pi_4"]);
    let mut line = Vec::new();
    for (j, ((t0, t1), p)) in problem
        .segment_times()
        .iter()
        .zip(&problem.pushes)
        .enumerate()
    {
        csv.row(&[
            j.to_string(),
            num(*t0),
            num(*t1),
            num(p.phi),
            num(p.phi - FRAC_PI_4),
        ]);
        line.push((*t0, p.phi));
        line.push((*t1, p.phi));
    }
    let fig = Figure {
        size: (900, 420),
        cols: 1,
        panels: vec![Panel::new(
            "Pusher direction φ(t): the paper's input (object frame)",
            Axis::lin("time t (s)"),
            Axis::lin("push direction φ (rad)"),
        )
        .series(
            Series::new("φ(t)", BLUE_, Stroke::Solid)
                .width(3)
                .points(line),
        )
        .series(
            Series::new("π/4 (through the centre of mass)", DARK, Stroke::Dashed)
                .width(1)
                .points(vec![(0.0, FRAC_PI_4), (problem.duration(), FRAC_PI_4)]),
        )
        .legend(Legend::LowerLeft)],
        key: None,
    };
    w.file("phi_input.csv", csv.as_bytes())?;
    w.figure("phi_input.svg", &fig)?;
    let list: Vec<String> = problem
        .pushes
        .iter()
        .map(|p| {
            let d = p.phi - FRAC_PI_4;
            if d.abs() < 1e-12 {
                "π/4".to_string()
            } else {
                format!("π/4{}{:.2}", if d > 0.0 { "+" } else { "−" }, d.abs())
            }
        })
        .collect();
    Ok(Entry {
        figure: "phi_input.svg".into(),
        data: vec!["phi_input.csv".into()],
        text: format!(
            "The input of every paper figure: {} segments of {} s with φ = {} rad \
             (object frame; φ = π/4 pushes through the centre of mass).",
            problem.pushes.len(),
            problem.pushes[0].duration,
            list.join(", ")
        ),
    })
}

fn omega_figure(base: &Scenario, runs: &[Runs], w: &mut Writer) -> anyhow::Result<Entry> {
    let mut csv = Csv::new(&header(&["speed", "model"]));
    let mut panels = Vec::new();
    let mut lines = Vec::new();
    for (&v, r) in SPEEDS.iter().zip(runs) {
        let sc = at_speed(base, v);
        let problem = sc.problem();
        for tr in [&r.dynamic, &r.kinematic, &r.engine] {
            traj_rows(&mut csv, &[num(v), tr.model.clone()], tr);
        }
        let gap = steady_gap(&problem, sc.froude_length());
        let eng = max_omega_diff(&r.dynamic, &r.engine, None);
        lines.push(format!(
            "| {v} | {:.3} | {:.1} % | {:.1e} |",
            sc.froude(v),
            100.0 * gap,
            eng
        ));
        panels.push(
            Panel::new(
                format!("v_c = {v} m/s  (Fr = {:.3})", sc.froude(v)),
                Axis::lin("time t (s)"),
                Axis::lin("angular velocity ω (rad/s)"),
            )
            .series(
                Series::new("kinematic  v_c ψ(φ)", DARK, Stroke::Dashed)
                    .width(2)
                    .points(omega_pts(&r.kinematic, 1, None)),
            )
            .series(
                Series::new("dynamic model", BLUE_, Stroke::Solid)
                    .width(2)
                    .points(omega_pts(&r.dynamic, 1, None)),
            )
            .series(
                Series::new("rapier2d", ORANGE, Stroke::Dots)
                    .width(2)
                    .points(omega_pts(&r.engine, 8, None)),
            )
            .legend(Legend::LowerLeft),
        );
    }
    w.file("omega_paper.csv", csv.as_bytes())?;
    w.figure(
        "omega_paper.svg",
        &Figure {
            size: (1300, 1250),
            cols: 2,
            panels,
            key: None,
        },
    )?;
    Ok(Entry {
        figure: "omega_paper.svg".into(),
        data: vec!["omega_paper.csv".into()],
        text: format!(
            "ω(t) of the paper plate for the schedule of `phi_input.svg` at five pusher speeds: \
             the kinematic model (dashed) jumps to v_c ψ(φ); the dynamic model relaxes \
             towards a steady ω* that departs from v_c ψ as the speed grows; rapier2d (dots, every \
             8th sample) lies on the dynamic model.\n\n\
             | v_c (m/s) | Fr | max \\|ω* − v_c ψ\\| / \\|v_c ψ\\| (segments with φ ≠ π/4) | max \\|ω_dynamic − ω_rapier2d\\| (rad/s) |\n\
             |---|---|---|---|\n{}",
            lines.join("\n")
        ),
    })
}

fn path_figure(
    sc: &Scenario,
    r: &Runs,
    stem: &str,
    title: &str,
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let mut csv = Csv::new(&header(&["model"]));
    for tr in [&r.dynamic, &r.kinematic, &r.engine] {
        traj_rows(&mut csv, std::slice::from_ref(&tr.model), tr);
    }
    type Getter = fn(&pushval_model::Sample) -> (f64, f64);
    let make = |name: &str, x: Axis, y: Axis, get: Getter, legend: Legend| {
        Panel::new(name, x, y)
            .series(
                Series::new("kinematic", DARK, Stroke::Dashed)
                    .width(2)
                    .points(pts(&r.kinematic, 1, get)),
            )
            .series(
                Series::new("dynamic", BLUE_, Stroke::Solid)
                    .width(2)
                    .points(pts(&r.dynamic, 1, get)),
            )
            .series(
                Series::new("rapier2d", ORANGE, Stroke::Dots)
                    .width(2)
                    .points(pts(&r.engine, 8, get)),
            )
            .legend(legend)
    };
    let fig = Figure {
        size: (1500, 520),
        cols: 3,
        panels: vec![
            make(
                &format!("{title}: x(t)"),
                Axis::lin("time t (s)"),
                Axis::lin("centre of mass x (m)"),
                |s| (s.t, s.x),
                Legend::UpperLeft,
            ),
            make(
                "y(t)",
                Axis::lin("time t (s)"),
                Axis::lin("centre of mass y (m)"),
                |s| (s.t, s.y),
                Legend::UpperLeft,
            ),
            make(
                "path (equal scales)",
                Axis::lin("x (m)"),
                Axis::lin("y (m)"),
                |s| (s.x, s.y),
                Legend::LowerRight,
            )
            .equal_aspect(),
        ],
        key: None,
    };
    let csv_name = format!("{stem}.csv");
    let svg_name = format!("{stem}.svg");
    w.file(&csv_name, csv.as_bytes())?;
    w.figure(&svg_name, &fig)?;
    let last = |t: &Trajectory| t.samples.last().map(|s| (s.x, s.y)).unwrap_or_default();
    let (d, k, e) = (last(&r.dynamic), last(&r.kinematic), last(&r.engine));
    let v = sc.pushes[0].speed;
    let duration = sc.problem().duration();
    let kinematic_end = w.key(
        &svg_name,
        "kinematic_end_distance_m",
        (d.0 - k.0).hypot(d.1 - k.1),
    );
    let path_length = w.key(&svg_name, "path_length_m", v * duration);
    let engine_max = w.key(
        &svg_name,
        "rapier2d_max_distance_m",
        max_position_diff(&r.dynamic, &r.engine),
    );
    let engine_end = w.key(
        &svg_name,
        "rapier2d_end_distance_m",
        (d.0 - e.0).hypot(d.1 - e.1),
    );
    Ok(Entry {
        figure: svg_name,
        data: vec![csv_name, KEY_FIGURES.to_string()],
        text: format!(
            "{title} (Fr = {:.3}): x(t), y(t) and the path of the centre of mass. After {} s the \
             kinematic model ends {:.3} m from the dynamic model (path length {:.1} m); \
             rapier2d stays within {:.1e} m of the dynamic model throughout (end point {:.1e} m).",
            sc.froude(v),
            duration,
            kinematic_end,
            path_length,
            engine_max,
            engine_end,
        ),
    })
}

fn slippery_omega(scs: &[Scenario], runs: &[Runs], w: &mut Writer) -> anyhow::Result<Entry> {
    let mut csv = Csv::new(&header(&["speed", "model"]));
    let mut panels = Vec::new();
    let mut lines = Vec::new();
    for (sc, r) in scs.iter().zip(runs) {
        let v = sc.pushes[0].speed;
        for tr in [&r.dynamic, &r.kinematic, &r.engine] {
            traj_rows(&mut csv, &[num(v), tr.model.clone()], tr);
        }
        let gap = steady_gap(&sc.problem(), sc.froude_length());
        lines.push(format!(
            "v_c = {v} m/s: Fr = {:.3}, max |ω* − v_c ψ|/|v_c ψ| = {:.1} %, \
             max |ω_dynamic − ω_rapier2d| = {:.1e} rad/s",
            sc.froude(v),
            100.0 * gap,
            max_omega_diff(&r.dynamic, &r.engine, None)
        ));
        panels.push(
            Panel::new(
                format!(
                    "Slippery floor (μ 0.1), v_c = {v} m/s (Fr = {:.2})",
                    sc.froude(v)
                ),
                Axis::lin("time t (s)"),
                Axis::lin("angular velocity ω (rad/s)"),
            )
            .series(
                Series::new("kinematic  v_c ψ(φ)", DARK, Stroke::Dashed).points(omega_pts(
                    &r.kinematic,
                    1,
                    None,
                )),
            )
            .series(
                Series::new("dynamic model", BLUE_, Stroke::Solid)
                    .points(omega_pts(&r.dynamic, 1, None)),
            )
            .series(
                Series::new("rapier2d", ORANGE, Stroke::Dots).points(omega_pts(&r.engine, 8, None)),
            )
            .legend(Legend::LowerLeft),
        );
    }
    w.file("omega_slippery.csv", csv.as_bytes())?;
    w.figure(
        "omega_slippery.svg",
        &Figure {
            size: (1400, 520),
            cols: 2,
            panels,
            key: None,
        },
    )?;
    Ok(Entry {
        figure: "omega_slippery.svg".into(),
        data: vec!["omega_slippery.csv".into()],
        text: format!(
            "ω(t) on a slippery floor (μ 0.1): the same speed is five times the Froude number, so at low speed \
             the transients last about five times longer, and ω* departs further from v_c ψ. {}.",
            lines.join("; ")
        ),
    })
}

fn mass_figure(light: &Runs, heavy: &Runs, w: &mut Writer) -> anyhow::Result<Entry> {
    let mut csv = Csv::new(&header(&["mass", "model"]));
    for (m, r) in [(1.0, light), (10.0, heavy)] {
        for tr in [&r.dynamic, &r.engine] {
            traj_rows(&mut csv, &[num(m), tr.model.clone()], tr);
        }
    }
    let dw_model = max_omega_diff(&light.dynamic, &heavy.dynamic, None);
    let dp_model = max_position_diff(&light.dynamic, &heavy.dynamic);
    let dw_engine = max_omega_diff(&light.engine, &heavy.engine, None);
    let dp_engine = max_position_diff(&light.engine, &heavy.engine);
    type Getter = fn(&pushval_model::Sample) -> (f64, f64);
    let make = |title: String, x: Axis, y: Axis, get: Getter, legend: Legend| {
        Panel::new(title, x, y)
            .series(
                Series::new("dynamic, 1 kg", BLUE_, Stroke::Solid)
                    .width(3)
                    .points(pts(&light.dynamic, 1, get)),
            )
            .series(
                Series::new("dynamic, 10 kg", RED_, Stroke::Dashed)
                    .width(2)
                    .points(pts(&heavy.dynamic, 1, get)),
            )
            .series(
                Series::new("rapier2d, 1 kg", ORANGE, Stroke::Dots)
                    .width(3)
                    .points(pts(&light.engine, 10, get)),
            )
            .series(
                Series::new("rapier2d, 10 kg", GREEN_, Stroke::Dots)
                    .width(2)
                    .points(pts(&heavy.engine, 10, get)),
            )
            .legend(legend)
    };
    let fig = Figure {
        size: (1400, 560),
        cols: 2,
        panels: vec![
            make(
                format!("Mass independence at v_c = 1 m/s: ω(t), max |Δω| = {dw_model:.1e} rad/s"),
                Axis::lin("time t (s)"),
                Axis::lin("angular velocity ω (rad/s)"),
                |s| (s.t, s.omega),
                Legend::LowerLeft,
            ),
            make(
                format!("path, max |Δ position| = {dp_model:.1e} m"),
                Axis::lin("x (m)"),
                Axis::lin("y (m)"),
                |s| (s.x, s.y),
                Legend::LowerRight,
            )
            .equal_aspect(),
        ],
        key: None,
    };
    w.file("mass.csv", csv.as_bytes())?;
    w.figure("mass.svg", &fig)?;
    // Differences of two runs: no column of mass.csv holds them.
    for (q, v) in [
        ("max_domega_dynamic_rad_s", dw_model),
        ("max_dposition_dynamic_m", dp_model),
        ("max_domega_rapier2d_rad_s", dw_engine),
        ("max_dposition_rapier2d_m", dp_engine),
    ] {
        w.key("mass.svg", q, v);
    }
    Ok(Entry {
        figure: "mass.svg".into(),
        data: vec!["mass.csv".into(), KEY_FIGURES.into()],
        text: format!(
            "The paper plate at 1 kg and at 10 kg (inertia and loads scale with the mass), \
             v_c = 1 m/s. Dynamic model: max |Δω| = {dw_model:.1e} rad/s, max |Δposition| = \
             {dp_model:.1e} m (integrator tolerance). rapier2d: max |Δω| = {dw_engine:.1e} rad/s, \
             max |Δposition| = {dp_engine:.1e} m. The motion does not depend on the mass."
        ),
    })
}

fn inertia_figure(
    base: &Scenario,
    printed: &Scenario,
    geometric: &Runs,
    printed_run: &Runs,
    w: &mut Writer,
) -> anyhow::Result<Entry> {
    let mut csv = Csv::new(&header(&["inertia", "model"]));
    traj_rows(
        &mut csv,
        &["geometric".into(), "dynamic".into()],
        &geometric.dynamic,
    );
    traj_rows(
        &mut csv,
        &["printed".into(), "dynamic".into()],
        &printed_run.dynamic,
    );
    traj_rows(
        &mut csv,
        &["geometric".into(), "rapier2d".into()],
        &geometric.engine,
    );
    let ip_geo = base.problem().body.inertia_contact();
    let ip_pr = printed.problem().body.inertia_contact();
    let d_geo = max_omega_diff(&geometric.dynamic, &geometric.engine, None);
    let d_pr = max_omega_diff(&printed_run.dynamic, &geometric.engine, None);
    let tau = |sc: &Scenario| segment_steady(&sc.problem())[0].2.unwrap_or(f64::NAN);
    let (tau_geo, tau_pr) = (tau(base), tau(printed));
    let make = |title: String, window: Option<(f64, f64)>, every: usize| {
        Panel::new(
            title,
            Axis::lin("time t (s)"),
            Axis::lin("angular velocity ω (rad/s)"),
        )
        .series(
            Series::new(
                format!("dynamic, printed I_P = {ip_pr:.4} kg m²"),
                RED_,
                Stroke::Dashed,
            )
            .points(omega_pts(&printed_run.dynamic, 1, window)),
        )
        .series(
            Series::new(
                format!("dynamic, geometric I_P = {ip_geo:.4} kg m²"),
                BLUE_,
                Stroke::Solid,
            )
            .points(omega_pts(&geometric.dynamic, 1, window)),
        )
        .series(
            Series::new("rapier2d (the 0.25 m plate)", ORANGE, Stroke::Dots)
                .width(3)
                .points(omega_pts(&geometric.engine, every, window)),
        )
        .legend(Legend::UpperRight)
    };
    let fig = Figure {
        size: (1400, 560),
        cols: 2,
        panels: vec![
            make("Which inertia? ω(t) at v_c = 1 m/s".into(), None, 8),
            make("first segment, t ≤ 1 s".into(), Some((0.0, 1.0)), 2),
        ],
        key: None,
    };
    w.file("inertia.csv", csv.as_bytes())?;
    w.figure("inertia.svg", &fig)?;
    Ok(Entry {
        figure: "inertia.svg".into(),
        data: vec!["inertia.csv".into()],
        text: format!(
            "The paper's printed inertia (I_P = {ip_pr:.4} kg m² about the contact, a 0.5 m \
             plate's value) against the geometric one of the 0.25 m plate (I_P = {ip_geo:.4} \
             kg m²), with rapier2d simulating the 0.25 m plate, v_c = 1 m/s. τ in the first \
             segment: {tau_geo:.3} s (geometric) vs {tau_pr:.3} s (printed). Max |ω − ω_rapier2d|: \
             {d_geo:.1e} rad/s with the geometric inertia, {d_pr:.2} rad/s with the printed one: \
             the engine settles it for the geometric reading."
        ),
    })
}

fn switching_figure(base: &Scenario, w: &mut Writer) -> anyhow::Result<Entry> {
    let sc = at_speed(base, 1.0);
    let mut impulsive = sc.problem();
    impulsive.sample_dt = 1e-3;
    let mut continuous = impulsive.clone();
    continuous.switching = Switching::Continuous;
    let model = DynamicModel::default();
    let (r_imp, r_con, r_eng) = (
        model.simulate(&impulsive).context("dynamic, impulsive")?,
        model.simulate(&continuous).context("dynamic, continuous")?,
        {
            let e = reference_engine(&sc);
            e.run(&impulsive, e.default_dt())
                .with_context(|| e.name().to_string())?
                .trajectory
        },
    );
    let windows = [(1.95, 2.25), (5.95, 6.25)];
    let mut csv = Csv::new(&header(&["switching", "model"]));
    for (name, tr) in [
        ("impulsive", &r_imp),
        ("continuous", &r_con),
        ("engine", &r_eng),
    ] {
        let mut clipped = tr.clone();
        clipped.samples.retain(|s| {
            windows
                .iter()
                .any(|&(a, b)| s.t >= a - 1e-12 && s.t <= b + 1e-12)
        });
        traj_rows(&mut csv, &[name.into(), tr.model.clone()], &clipped);
    }
    let at = |tr: &Trajectory, t: f64| {
        tr.samples
            .iter()
            .min_by(|a, b| (a.t - t).abs().total_cmp(&(b.t - t).abs()))
            .map(|s| s.omega)
            .unwrap_or(f64::NAN)
    };
    let mut panels = Vec::new();
    let mut notes = Vec::new();
    for (i, &(a, b)) in windows.iter().enumerate() {
        let ts = (a + b) / 2.0 - 0.05;
        let ts = ts.round();
        let jump_model = at(&r_imp, ts) - at(&r_imp, ts - 1e-3);
        let jump_engine = at(&r_eng, ts) - at(&r_eng, ts - 1e-3);
        let e_imp = max_omega_diff(&r_imp, &r_eng, Some((a, b)));
        let e_con = max_omega_diff(&r_con, &r_eng, Some((a, b)));
        notes.push(format!(
            "switch {} at t = {ts} s: ω jumps by {jump_model:.3} rad/s (impulsive model) and \
             {jump_engine:.3} rad/s (rapier2d over one 1 ms step); max |ω − ω_rapier2d| in the \
             window: {e_imp:.1e} rad/s impulsive, {e_con:.2} rad/s continuous",
            if i == 0 { 1 } else { 3 }
        ));
        panels.push(
            Panel::new(
                format!("ω around the switch at t = {ts} s (v_c = 1 m/s)"),
                Axis::lin("time t (s)"),
                Axis::lin("angular velocity ω (rad/s)"),
            )
            .series(
                Series::new("dynamic, continuous ω (paper)", RED_, Stroke::Dashed)
                    .points(omega_pts(&r_con, 1, Some((a, b)))),
            )
            .series(
                Series::new("dynamic, impulsive (H_c conserved)", BLUE_, Stroke::Solid)
                    .points(omega_pts(&r_imp, 1, Some((a, b)))),
            )
            .series(
                Series::new("rapier2d", ORANGE, Stroke::Dots)
                    .width(3)
                    .points(omega_pts(&r_eng, 4, Some((a, b)))),
            )
            .legend(Legend::LowerRight),
        );
    }
    w.file("switching.csv", csv.as_bytes())?;
    w.figure(
        "switching.svg",
        &Figure {
            size: (1400, 560),
            cols: 2,
            panels,
            key: None,
        },
    )?;
    Ok(Entry {
        figure: "switching.svg".into(),
        data: vec!["switching.csv".into()],
        text: format!(
            "Impulsive switching (angular momentum about the contact conserved, ω jumps) against \
             the paper's continuous ω, with rapier2d, at 1 ms sampling around two switches of the \
             paper schedule at v_c = 1 m/s: {}. The rigid body in the engine jumps.",
            notes.join("; ")
        ),
    })
}
