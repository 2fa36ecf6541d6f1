//! Where game-engine friction idioms disagree with Coulomb support friction.
//!
//! `cargo run --release -p pushval-rapier --example friction_models [OUT]`
//! writes `OUT` (default `results/friction_models/`): one CSV per idiom over
//! a (Fr, φ) grid on the paper plate at two engine steps, the table at
//! φ = π/4 + 0.3, the Δt and v_s sweeps, the box's angle dependence, an SVG
//! map and a README with the numbers.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::prelude::*;
use pushval_model::{
    Body, DynamicModel, Initial, Problem, Push, SegmentDynamics, Simulator, Support, Switching,
    Vec2,
};
use pushval_rapier2d::idioms::{
    lock_angles, predicted_angle_history, predicted_mean_omega, stop_gain,
};
use pushval_rapier2d::{EngineSettings, FrictionModel, RapierRun, RapierSimulator};

const MU: f64 = 0.5;
const G: f64 = 9.81;
const SLIP: f64 = 0.01;
const T_RUN: f64 = 6.0;
const GAME_DT: f64 = 1.0 / 60.0;
const FINE_DT: f64 = 1e-3;
/// Starting angle of the grid runs: generic (θ = 0 is an unstable balance of the box law).
const THETA0: f64 = 0.1;

fn plate() -> Body {
    let h = 0.125;
    let supports: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: MU * G / 4.0,
        })
        .collect();
    Body::new(1.0, 0.0625 * 2.0 / 12.0, Vec2::new(-h, -h), &supports).unwrap()
}

fn idioms() -> Vec<FrictionModel> {
    vec![
        FrictionModel::Coulomb,
        FrictionModel::ImpulseDisk,
        FrictionModel::ImpulseBox,
        FrictionModel::RegularisedLinear { slip_speed: SLIP },
        FrictionModel::RegularisedTanh { slip_speed: SLIP },
    ]
}

fn problem(body: &Body, push: Push, theta0: f64) -> Problem {
    Problem {
        body: body.clone(),
        limits: Default::default(),
        pushes: vec![push],
        initial: Initial {
            theta: theta0,
            ..Default::default()
        },
        switching: Switching::Impulsive,
        sample_dt: 0.01,
    }
}

fn engine(p: &Problem, model: FrictionModel, dt: f64) -> RapierRun {
    RapierSimulator::new(EngineSettings {
        dt,
        friction_model: model,
        ..Default::default()
    })
    .run(p)
    .unwrap()
}

/// What one engine run gives.
struct Measured {
    /// Mean ω over the second half (whole quarter turns when the body turns
    /// that far: the box law repeats every π/2 for the square).
    omega: f64,
    /// Largest minus smallest step ω over the second half.
    range: f64,
    /// rms step-to-step change of ω over the second half.
    jitter: f64,
}

fn measure(run: &RapierRun) -> Measured {
    let steps: Vec<_> = run.history.iter().filter(|r| r.t1 > r.t0).collect();
    let t_end = steps.last().unwrap().t1;
    let half: Vec<_> = steps.iter().filter(|r| r.t0 >= 0.5 * t_end).collect();
    let th_end = steps.last().unwrap().theta;
    let th_half = half[0].theta;
    let quarters = ((th_end - th_half).abs() / FRAC_PI_2).floor();
    let omega = if quarters >= 1.0 {
        // The last time θ was a whole number of quarter turns before the end.
        let target = th_end - (th_end - th_half).signum() * quarters * FRAC_PI_2;
        let mut t_a = half[0].t1;
        for w in steps.windows(2) {
            let (a, b) = (w[0], w[1]);
            if (a.theta - target) * (b.theta - target) <= 0.0 && b.theta != a.theta {
                t_a = a.t1 + (target - a.theta) / (b.theta - a.theta) * (b.t1 - a.t1);
            }
        }
        (th_end - target) / (t_end - t_a)
    } else {
        half.iter().map(|r| r.omega * (r.t1 - r.t0)).sum::<f64>()
            / half.iter().map(|r| r.t1 - r.t0).sum::<f64>()
    };
    let (lo, hi) = half
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), r| {
            (l.min(r.omega), h.max(r.omega))
        });
    let d: Vec<f64> = half.windows(2).map(|w| w[1].omega - w[0].omega).collect();
    let jitter = (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt();
    Measured {
        omega,
        range: hi - lo,
        jitter,
    }
}

fn status(m: &Measured, omega_star: f64) -> &'static str {
    if m.omega.abs() < 0.05 * omega_star.abs() {
        "stops"
    } else if m.jitter > 0.05 * omega_star.abs() {
        "chatters"
    } else if m.range > 0.2 * omega_star.abs() {
        "oscillates"
    } else {
        "ok"
    }
}

fn coulomb_star(body: &Body, push: &Push) -> f64 {
    SegmentDynamics::new(body, push)
        .steady_states()
        .into_iter()
        .find(|s| s.is_stable())
        .map(|s| s.omega)
        .unwrap()
}

fn write(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

/// One grid cell of one idiom.
struct Cell {
    /// Box: the final angle mod π/2 and its distance to the nearest
    /// predicted stable lock angle.
    lock: Option<(f64, f64)>,
    dt: f64,
    fr: f64,
    speed: f64,
    phi: f64,
    omega_star: f64,
    engine: Measured,
    predicted: Option<f64>,
    pos_err: f64,
    theta_err: f64,
    theta_err_pred: f64,
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn main() {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "results/friction_models".into()),
    );
    std::fs::create_dir_all(&out).unwrap();
    let body = plate();
    let l = body.contact().norm();
    let fr_of = |v: f64| v * v / (MU * G * l);
    let mut readme = String::new();

    // 1. The table at φ = π/4 + 0.3.
    let phi_t = FRAC_PI_4 + 0.3;
    let mut table = String::from(
        "dt,speed,idiom,omega_star,omega_engine,omega_predicted,rel_err_vs_star,rel_err_vs_predicted,jitter,status\n",
    );
    let mut md_table = String::from(
        "| v_c (m/s) | ω* Coulomb | Δt | impulse_disk | impulse_box | regularised_linear | regularised_tanh |\n|---:|---:|---|---:|---:|---:|---:|\n",
    );
    for &dt in &[GAME_DT, FINE_DT] {
        for &v in &[0.2, 0.5, 1.0] {
            let push = Push {
                duration: T_RUN,
                speed: v,
                phi: phi_t,
            };
            let star = coulomb_star(&body, &push);
            let mut row = format!(
                "| {v} | {star:.4} | {} |",
                if dt == GAME_DT { "1/60" } else { "1e-3" }
            );
            for m in idioms() {
                let run = engine(&problem(&body, push, 0.0), m, dt);
                let e = measure(&run);
                let pred = predicted_mean_omega(m, &body, &push, dt, 720);
                writeln!(
                    table,
                    "{dt},{v},{},{star},{},{},{},{},{},{}",
                    m.as_str(),
                    e.omega,
                    pred.map_or(String::new(), |p| p.to_string()),
                    rel(e.omega, star),
                    pred.map_or(String::new(), |p| rel(e.omega, p).to_string()),
                    e.jitter,
                    status(&e, star)
                )
                .unwrap();
                if m != FrictionModel::Coulomb {
                    write!(
                        row,
                        " {:.4} ({:+.1} %; pred. {}) |",
                        e.omega,
                        100.0 * (e.omega - star) / star,
                        pred.map_or("—".into(), |p| format!("{p:.4}"))
                    )
                    .unwrap();
                }
            }
            md_table.push_str(&row);
            md_table.push('\n');
        }
    }
    write(&out.join("table_phi_pi4+0.3.csv"), &table);

    // 2. The (Fr, φ) grid, per idiom.
    let frs = [0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0];
    let phis: Vec<f64> = (0..9)
        .map(|k| 0.15 + k as f64 * (1.42 - 0.15) / 8.0)
        .collect();
    let mut grid: Vec<(FrictionModel, Vec<Cell>)> =
        idioms().into_iter().map(|m| (m, vec![])).collect();
    for &dt in &[GAME_DT, FINE_DT] {
        for &fr in &frs {
            let v = (fr * MU * G * l).sqrt();
            for &phi in &phis {
                let push = Push {
                    duration: T_RUN,
                    speed: v,
                    phi,
                };
                let star = coulomb_star(&body, &push);
                let p = problem(&body, push, THETA0);
                let reference = DynamicModel::default().simulate(&p).unwrap();
                for (m, cells) in grid.iter_mut() {
                    let run = engine(&p, *m, dt);
                    let e = measure(&run);
                    let pred = predicted_mean_omega(*m, &body, &push, dt, 360);
                    let hist =
                        predicted_angle_history(*m, &body, &push, dt, (THETA0, 0.0), T_RUN, 0.01);
                    let (mut pe, mut te, mut tp) = (0.0f64, 0.0f64, 0.0f64);
                    for (k, (s, r)) in run
                        .trajectory
                        .samples
                        .iter()
                        .zip(&reference.samples)
                        .enumerate()
                    {
                        pe = pe.max(((s.x - r.x).powi(2) + (s.y - r.y).powi(2)).sqrt());
                        te = te.max((s.theta - r.theta).abs());
                        if let Some(h) = hist.get(k) {
                            tp = tp.max((s.theta - h.1).abs());
                        }
                    }
                    let lock = if m.is_isotropic() {
                        None
                    } else {
                        let th = run.history.last().unwrap().theta.rem_euclid(FRAC_PI_2);
                        let locks = lock_angles(*m, &body, &push, dt, 720);
                        let best = locks
                            .iter()
                            .filter(|l| l.1)
                            .map(|l| {
                                let d = (l.0 - th).rem_euclid(FRAC_PI_2);
                                d.min(FRAC_PI_2 - d)
                            })
                            .fold(f64::INFINITY, f64::min);
                        Some((th, best))
                    };
                    cells.push(Cell {
                        lock,
                        dt,
                        fr: fr_of(v),
                        speed: v,
                        phi,
                        omega_star: star,
                        engine: e,
                        predicted: pred,
                        pos_err: pe,
                        theta_err: te,
                        theta_err_pred: tp,
                    });
                }
            }
        }
    }
    let mut summary = String::from(
        "| idiom | Δt | median ‖ω−ω*‖/ω* | max | median ‖ω−ω_pred‖/ω | max | max position error vs Coulomb (m) | max θ error vs Coulomb (rad) | max θ error vs predicted (rad) | cells not ok |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for (m, cells) in &grid {
        let mut csv = String::from("dt,froude,speed,phi,omega_star,omega_engine,omega_predicted,rel_err_vs_star,rel_err_vs_predicted,omega_range,jitter,position_err_max,theta_err_max,theta_err_vs_predicted_max,status,final_theta_mod_quarter,dist_to_predicted_lock\n");
        for c in cells {
            writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                c.dt,
                c.fr,
                c.speed,
                c.phi,
                c.omega_star,
                c.engine.omega,
                c.predicted.map_or(String::new(), |p| p.to_string()),
                rel(c.engine.omega, c.omega_star),
                c.predicted
                    .map_or(String::new(), |p| rel(c.engine.omega, p).to_string()),
                c.engine.range,
                c.engine.jitter,
                c.pos_err,
                c.theta_err,
                c.theta_err_pred,
                status(&c.engine, c.omega_star),
                c.lock.map_or(String::new(), |l| l.0.to_string()),
                c.lock.map_or(String::new(), |l| l.1.to_string())
            )
            .unwrap();
        }
        write(&out.join(format!("{}.csv", m.as_str())), &csv);
        for &dt in &[GAME_DT, FINE_DT] {
            let cs: Vec<&Cell> = cells.iter().filter(|c| c.dt == dt).collect();
            let mut es: Vec<f64> = cs
                .iter()
                .map(|c| rel(c.engine.omega, c.omega_star))
                .collect();
            let mut ps: Vec<f64> = cs
                .iter()
                .filter_map(|c| c.predicted.map(|p| rel(c.engine.omega, p)))
                .collect();
            es.sort_by(f64::total_cmp);
            ps.sort_by(f64::total_cmp);
            let bad: Vec<String> = cs
                .iter()
                .filter(|c| status(&c.engine, c.omega_star) != "ok")
                .map(|c| {
                    format!(
                        "{} (Fr {:.2}, φ {:.2})",
                        status(&c.engine, c.omega_star),
                        c.fr,
                        c.phi
                    )
                })
                .collect();
            let np = cs.len() - ps.len();
            writeln!(
                summary,
                "| {} | {} | {:.2e} | {:.2e} | {} | {} | {:.3} | {:.3} | {:.2e} | {} |",
                m.as_str(),
                if dt == GAME_DT { "1/60" } else { "1e-3" },
                es[es.len() / 2],
                es[es.len() - 1],
                ps.get(ps.len() / 2)
                    .map_or("—".into(), |x| format!("{x:.2e}")),
                ps.last().map_or("—".into(), |x| format!(
                    "{x:.2e}{}",
                    if np > 0 {
                        format!(" ({np} none)")
                    } else {
                        String::new()
                    }
                )),
                cs.iter().map(|c| c.pos_err).fold(0.0, f64::max),
                cs.iter().map(|c| c.theta_err).fold(0.0, f64::max),
                cs.iter().map(|c| c.theta_err_pred).fold(0.0, f64::max),
                if bad.is_empty() {
                    "—".to_string()
                } else {
                    format!(
                        "{}: {}",
                        bad.len(),
                        bad.iter().take(3).cloned().collect::<Vec<_>>().join("; ")
                    )
                }
            )
            .unwrap();
        }
    }
    draw_map(&out.join("map.svg"), &grid, &frs, &phis).unwrap();

    // 3. Δt sweep (impulse idioms) and v_s sweep (regularised), at v = 0.5.
    let push = Push {
        duration: T_RUN,
        speed: 0.5,
        phi: phi_t,
    };
    let star = coulomb_star(&body, &push);
    let mut sweep = String::from("idiom,dt,slip_speed,omega_star,omega_engine,omega_predicted,rel_err_vs_star,jitter,status\n");
    let mut md_sweep = String::from("| idiom | Δt (s) | v_s (m/s) | ω engine | (ω−ω*)/ω* | predicted | status |\n|---|---:|---:|---:|---:|---:|---|\n");
    let mut cases: Vec<(FrictionModel, f64)> = Vec::new();
    for dt in [1.0 / 30.0, GAME_DT, 1.0 / 120.0, 1.0 / 240.0, 1e-3, 2.5e-4] {
        cases.push((FrictionModel::ImpulseDisk, dt));
        cases.push((FrictionModel::ImpulseBox, dt));
    }
    for vs in [1.0, 0.3, 0.1, 0.03, 0.01, 0.001] {
        for dt in [GAME_DT, FINE_DT] {
            cases.push((FrictionModel::RegularisedLinear { slip_speed: vs }, dt));
            cases.push((FrictionModel::RegularisedTanh { slip_speed: vs }, dt));
        }
    }
    for (m, dt) in cases {
        let e = measure(&engine(&problem(&body, push, 0.0), m, dt));
        let pred = predicted_mean_omega(m, &body, &push, dt, 720);
        let vs = match m {
            FrictionModel::RegularisedLinear { slip_speed }
            | FrictionModel::RegularisedTanh { slip_speed } => slip_speed.to_string(),
            _ => String::new(),
        };
        writeln!(
            sweep,
            "{},{dt},{vs},{star},{},{},{},{},{}",
            m.as_str(),
            e.omega,
            pred.map_or(String::new(), |p| p.to_string()),
            rel(e.omega, star),
            e.jitter,
            status(&e, star)
        )
        .unwrap();
        writeln!(
            md_sweep,
            "| {} | {:.3e} | {} | {:.4} | {:+.2e} | {} | {} |",
            m.as_str(),
            dt,
            if vs.is_empty() { "—".into() } else { vs },
            e.omega,
            (e.omega - star) / star,
            pred.map_or("—".into(), |p| format!("{p:.4}")),
            status(&e, star)
        )
        .unwrap();
    }
    write(&out.join("sweeps.csv"), &sweep);

    // 4. Angle dependence: the box's frozen ω*(θ) against the engine's ω(θ),
    // and every idiom's mean ω for several starting angles.
    let mut theta_csv = String::from("theta,omega_box_frozen_game_dt,omega_disk_frozen_game_dt\n");
    for j in 0..=90 {
        let th = FRAC_PI_2 * j as f64 / 90.0;
        let b = pushval_rapier2d::idioms::predicted_steady_omega(
            FrictionModel::ImpulseBox,
            &body,
            &push,
            GAME_DT,
            th,
            0.0,
        );
        let d = pushval_rapier2d::idioms::predicted_steady_omega(
            FrictionModel::ImpulseDisk,
            &body,
            &push,
            GAME_DT,
            th,
            0.0,
        );
        writeln!(
            theta_csv,
            "{th},{},{}",
            b.unwrap_or(f64::NAN),
            d.unwrap_or(f64::NAN)
        )
        .unwrap();
    }
    write(&out.join("box_frozen_omega_vs_theta.csv"), &theta_csv);
    let run = engine(
        &problem(&body, push, 0.0),
        FrictionModel::ImpulseBox,
        GAME_DT,
    );
    let mut eng_theta = String::from("t,theta,omega\n");
    for r in run.history.iter().filter(|r| r.t1 > r.t0) {
        writeln!(eng_theta, "{},{},{}", r.t1, r.theta, r.omega).unwrap();
    }
    write(&out.join("box_engine_history_game_dt.csv"), &eng_theta);
    let frozen: Vec<f64> = (0..360)
        .filter_map(|j| {
            pushval_rapier2d::idioms::predicted_steady_omega(
                FrictionModel::ImpulseBox,
                &body,
                &push,
                GAME_DT,
                FRAC_PI_2 * j as f64 / 360.0,
                0.0,
            )
        })
        .collect();
    let (fmin, fmax) = frozen
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
            (a.min(w), b.max(w))
        });
    let mut md_theta = String::from("| idiom (Δt = 1/60) | θ₀ = 0 | θ₀ = 0.2 | θ₀ = 0.4 | θ₀ = 0.6 |\n|---|---:|---:|---:|---:|\n");
    let short = Push {
        duration: 0.5,
        ..push
    };
    let mut theta_dep = String::from("idiom,theta0,omega_at_0.5s\n");
    for m in idioms() {
        let mut row = format!("| {} |", m.as_str());
        for th0 in [0.0, 0.2, 0.4, 0.6] {
            let r = engine(&problem(&body, short, th0), m, GAME_DT);
            let w = r.history.last().unwrap().omega;
            writeln!(theta_dep, "{},{th0},{w}", m.as_str()).unwrap();
            write!(row, " {w:.4} |").unwrap();
        }
        md_theta.push_str(&row);
        md_theta.push('\n');
    }
    write(&out.join("theta_dependence.csv"), &theta_dep);

    // 5. Box locks: final angle against the predicted stable lock angles.
    let mut md_lock = String::new();
    for (m, cells) in grid.iter().filter(|(m, _)| !m.is_isotropic()) {
        for &dt in &[GAME_DT, FINE_DT] {
            let ds: Vec<f64> = cells
                .iter()
                .filter(|c| c.dt == dt)
                .filter_map(|c| c.lock.map(|l| l.1))
                .collect();
            writeln!(
                md_lock,
                "* {} at Δt = {}: largest distance (mod π/2) between the engine's final angle and the nearest predicted stable lock angle over the grid: {:.2e} rad.",
                m.as_str(),
                if dt == GAME_DT { "1/60" } else { "1e-3" },
                ds.iter().copied().fold(0.0, f64::max)
            )
            .unwrap();
        }
    }
    let locks = lock_angles(FrictionModel::ImpulseBox, &body, &push, FINE_DT, 720);
    let stable: Vec<String> = locks
        .iter()
        .filter(|l| l.1 && l.0 < FRAC_PI_2)
        .map(|l| format!("{:.4}", l.0))
        .collect();
    let unstable: Vec<String> = locks
        .iter()
        .filter(|l| !l.1 && l.0 < FRAC_PI_2)
        .map(|l| format!("{:.4}", l.0))
        .collect();
    writeln!(md_lock, "* At v_c = 0.5, φ = π/4 + 0.3, Δt = 1e-3 the box law's lock angles in [0, π/2): stable {stable:?}, unstable {unstable:?} rad.").unwrap();

    // 6. Stopping: 1 s at 0.5 m/s, then the pusher stops for 1 s.
    let mut md_stop = String::from("| idiom | Δt | predicted step gain γ | mean |ω| over the last 0.5 s (rad/s) | rms step-to-step Δω | angle turned after the stop (rad) |\n|---|---|---:|---:|---:|---:|\n");
    let mut stop_csv =
        String::from("idiom,dt,gain,mean_abs_omega_tail,jitter_tail,angle_after_stop\n");
    let stop_problem = Problem {
        pushes: vec![
            Push {
                duration: 1.0,
                speed: 0.5,
                phi: phi_t,
            },
            Push {
                duration: 1.0,
                speed: 0.0,
                phi: phi_t,
            },
        ],
        ..problem(&body, push, THETA0)
    };
    for m in idioms() {
        for &dt in &[GAME_DT, FINE_DT] {
            let run = engine(&stop_problem, m, dt);
            let steps: Vec<_> = run.history.iter().filter(|r| r.t1 > r.t0).collect();
            let tail: Vec<_> = steps.iter().filter(|r| r.t0 >= 1.5).collect();
            let mean_abs = tail.iter().map(|r| r.omega.abs()).sum::<f64>() / tail.len() as f64;
            let d: Vec<f64> = tail.windows(2).map(|w| w[1].omega - w[0].omega).collect();
            let jit = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
            let th_stop = steps
                .iter()
                .rev()
                .find(|r| r.t1 <= 1.0 + 1e-12)
                .unwrap()
                .theta;
            let turned = steps.last().unwrap().theta - th_stop;
            let gain = stop_gain(m, &body, dt, THETA0);
            writeln!(
                stop_csv,
                "{},{dt},{},{mean_abs},{jit},{turned}",
                m.as_str(),
                gain.map_or(String::new(), |g| g.to_string())
            )
            .unwrap();
            writeln!(
                md_stop,
                "| {} | {} | {} | {mean_abs:.2e} | {jit:.2e} | {turned:+.4} |",
                m.as_str(),
                if dt == GAME_DT { "1/60" } else { "1e-3" },
                gain.map_or("—".into(), |g| format!("{g:.3}"))
            )
            .unwrap();
        }
    }
    write(&out.join("stop.csv"), &stop_csv);
    let seg = SegmentDynamics::new(&body, &push);
    let umin = seg.min_support_speed(star).0;

    // README.
    writeln!(
        readme,
        "# Game-engine friction idioms against Coulomb support friction\n"
    )
    .unwrap();
    writeln!(readme, "Generated by `cargo run --release -p pushval-rapier --example friction_models`. Paper plate: 0.25 m square, 1 kg, four corner supports with μ = 0.5 and equal loads (F = μ m g / 4 = {:.4} N each), pushed at the corner (−0.125, −0.125); rapier2d-f64, leapfrog mode, the idiom's force applied at every support each step (see `crates/engine/src/idioms.rs`). Fr = v_c²/(μ g L), L = |p_c| = {:.4} m. Slip speed of the regularised laws v_s = {SLIP} m/s unless stated. Each run: {T_RUN} s from ω = 0 moving with the pusher; the engine's ω is the mean over the second half (over whole quarter turns where the body turns that far).\n", MU * G / 4.0, l).unwrap();
    readme.push_str(FINDINGS);
    writeln!(readme, "## Steady ω at φ = π/4 + 0.3 (rad/s; in brackets the error against the Coulomb ω*, then the closed-form prediction)\n\n{md_table}").unwrap();
    writeln!(readme, "Data: `table_phi_pi4+0.3.csv`.\n").unwrap();
    writeln!(readme, "## Over the (Fr, φ) grid\n\nFr ∈ {frs:?}, φ ∈ 9 values in [0.15, 1.42] rad; per idiom `IDIOM.csv`, map of the steady-ω error in `map.svg`. 'not ok': `stops` (|ω| < 5 % of ω*), `chatters` (rms step-to-step change of ω > 5 % of ω*), `oscillates` (ω range over the second half > 20 % of ω*).\n\n{summary}").unwrap();
    writeln!(readme, "## Δt and slip-speed sweeps (v_c = 0.5 m/s, φ = π/4 + 0.3, ω* = {star:.5})\n\n{md_sweep}\nData: `sweeps.csv`.\n").unwrap();
    writeln!(
        readme,
        "At ω* the slowest support slides at {umin:.4} m/s.\n"
    )
    .unwrap();
    writeln!(readme, "## Box locks\n\n{md_lock}").unwrap();
    writeln!(readme, "## Stopping (1 s at 0.5 m/s, then the pusher at rest for 1 s)\n\n{md_stop}\nData: `stop.csv`.\n").unwrap();
    writeln!(readme, "## Angle dependence\n\nω after 0.5 s for several starting angles θ₀ (v_c = 0.5 m/s, φ = π/4 + 0.3):\n\n{md_theta}\nThe box law's frozen steady ω*(θ) at Δt = 1/60 ranges over [{fmin:.4}, {fmax:.4}] rad/s (period π/2; `box_frozen_omega_vs_theta.csv`); the engine's ω along a run is in `box_engine_history_game_dt.csv`.\n").unwrap();
    readme.push_str(&other_engines(&out));
    write(&out.join("README.md"), &readme);
    println!("{readme}");
}

/// Rows of a CSV file as header → value maps (None when the file is missing).
fn read_csv(path: &Path) -> Option<Vec<std::collections::HashMap<String, String>>> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next()?.split(',').collect();
    Some(
        lines
            .map(|l| {
                head.iter()
                    .zip(l.split(','))
                    .map(|(h, v)| (h.to_string(), v.to_string()))
                    .collect()
            })
            .collect(),
    )
}

/// The summary over every engine at φ = π/4 + 0.3 (from this run's table and
/// the CSVs of the rapier3d and MuJoCo studies, which
/// scripts/friction-models.sh regenerates first), followed by those studies'
/// own READMEs.
fn other_engines(out: &Path) -> String {
    let mut md = String::new();
    // Per row label: (v_c, ω engine, ω*) for each speed.
    type Cells = Vec<(f64, f64, f64)>;
    let mut rows: Vec<(String, Cells)> = Vec::new();
    let mut push_rows =
        |file: &str,
         label: &dyn Fn(&std::collections::HashMap<String, String>) -> Option<String>,
         speed: &str,
         engine: &str,
         star: &str| {
            let Some(table) = read_csv(&out.join(file)) else {
                return;
            };
            for r in &table {
                let Some(name) = label(r) else { continue };
                let num = |k: &str| {
                    r.get(k)
                        .and_then(|v| v.parse::<f64>().ok())
                        .unwrap_or(f64::NAN)
                };
                let entry = (num(speed), num(engine), num(star));
                match rows.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, v)) => v.push(entry),
                    None => rows.push((name, vec![entry])),
                }
            }
        };
    let at_1e3 = |r: &std::collections::HashMap<String, String>| {
        r.get("dt").and_then(|v| v.parse::<f64>().ok()) == Some(1e-3)
    };
    push_rows(
        "table_phi_pi4+0.3.csv",
        &|r| at_1e3(r).then(|| format!("rapier2d, {}", r["idiom"])),
        "speed",
        "omega_engine",
        "omega_star",
    );
    push_rows(
        "rapier3d/paper_table.csv",
        &|r| at_1e3(r).then(|| format!("rapier3d, {}", r["friction"])),
        "speed",
        "omega_engine",
        "omega_star",
    );
    push_rows(
        "mujoco/paper_plate.csv",
        &|r| (r["variant"] == "default").then(|| format!("MuJoCo, {} cone", r["cone"])),
        "v_c",
        "omega_mujoco",
        "omega_star",
    );
    md.push_str(
        "## Every engine on the paper plate at φ = π/4 + 0.3

",
    );
    md.push_str("Steady ω in rad/s (relative error against the Coulomb model's ω*); rapier at Δt = 1e-3, MuJoCo at its defaults (Δt = 1e-3). Sources: `table_phi_pi4+0.3.csv`, `rapier3d/paper_table.csv`, `mujoco/paper_plate.csv` (regenerate all with `scripts/friction-models.sh`).\n\n");
    md.push_str("| engine, friction | v_c = 0.2 m/s | 0.5 m/s | 1.0 m/s |\n|---|---:|---:|---:|\n");
    if let Some((_, v)) = rows.first() {
        let stars: Vec<String> = [0.2, 0.5, 1.0]
            .iter()
            .map(|s| {
                v.iter()
                    .find(|e| (e.0 - s).abs() < 1e-9)
                    .map_or("—".into(), |e| format!("{:.4}", e.2))
            })
            .collect();
        md.push_str(&format!("| Coulomb model ω* | {} |\n", stars.join(" | ")));
    }
    for (name, v) in &rows {
        let cells: Vec<String> = [0.2, 0.5, 1.0]
            .iter()
            .map(|s| {
                v.iter()
                    .find(|e| (e.0 - s).abs() < 1e-9)
                    .map_or("—".into(), |e| {
                        format!("{:.4} ({:+.1} %)", e.1, 100.0 * (e.1 - e.2) / e.2)
                    })
            })
            .collect();
        md.push_str(&format!("| {name} | {} |\n", cells.join(" | ")));
    }
    md.push('\n');
    for (dir, title) in [("rapier3d", "rapier3d"), ("mujoco", "MuJoCo")] {
        match std::fs::read_to_string(out.join(dir).join("README.md")) {
            Ok(text) => {
                md.push_str(&format!("---\n\n(From `{dir}/README.md`: {title}.)\n\n"));
                for line in text.lines() {
                    if line.starts_with('#') {
                        md.push('#');
                    }
                    md.push_str(line);
                    md.push('\n');
                }
                md.push('\n');
            }
            Err(_) => md.push_str(&format!(
                "({title}: `{dir}/README.md` not generated yet.)\n\n"
            )),
        }
    }
    md
}

fn draw_map(
    path: &Path,
    grid: &[(FrictionModel, Vec<Cell>)],
    frs: &[f64],
    phis: &[f64],
) -> Result<(), Box<dyn std::error::Error>> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (1500, 760)).into_drawing_area();
        root.fill(&WHITE)?;
        let rows = root.split_evenly((2, 4));
        let dts = [GAME_DT, FINE_DT];
        let models: Vec<&(FrictionModel, Vec<Cell>)> = grid
            .iter()
            .filter(|(m, _)| *m != FrictionModel::Coulomb)
            .collect();
        for (k, area) in rows.iter().enumerate() {
            let (dt, (m, cells)) = (dts[k / 4], models[k % 4]);
            let dphi = phis[1] - phis[0];
            let mut chart = ChartBuilder::on(area)
                .caption(
                    format!(
                        "{} Δt={}",
                        m.as_str(),
                        if dt == GAME_DT { "1/60" } else { "1e-3" }
                    ),
                    ("sans-serif", 16),
                )
                .margin(6)
                .x_label_area_size(32)
                .y_label_area_size(40)
                .build_cartesian_2d(
                    (phis[0] - 0.5 * dphi)..(phis[phis.len() - 1] + 0.5 * dphi),
                    -0.5..(frs.len() as f64 - 0.5),
                )?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc("φ (rad)")
                .y_desc("Fr")
                .y_labels(frs.len())
                .y_label_formatter(&|y| {
                    let i = y.round() as usize;
                    frs.get(i).map_or(String::new(), |f| f.to_string())
                })
                .draw()?;
            for c in cells.iter().filter(|c| c.dt == dt) {
                let i = frs
                    .iter()
                    .position(|f| ((f - c.fr) / f).abs() < 1e-6)
                    .unwrap_or(0) as f64;
                let e = rel(c.engine.omega, c.omega_star).max(1e-9);
                // log10 error from −6 (white-ish blue) to 0 (red).
                let s = ((e.log10() + 6.0) / 6.0).clamp(0.0, 1.0);
                let color = RGBColor(
                    (40.0 + 215.0 * s) as u8,
                    (80.0 + 120.0 * (1.0 - (2.0 * s - 1.0).abs())) as u8,
                    (255.0 * (1.0 - s)) as u8,
                );
                chart.draw_series(std::iter::once(Rectangle::new(
                    [(c.phi - 0.5 * dphi, i - 0.5), (c.phi + 0.5 * dphi, i + 0.5)],
                    color.filled(),
                )))?;
                let mark = match status(&c.engine, c.omega_star) {
                    "ok" => "",
                    "stops" => "S",
                    "chatters" => "C",
                    _ => "O",
                };
                chart.draw_series(std::iter::once(Text::new(
                    format!("{:.0}{mark}", e.log10()),
                    (c.phi - 0.3 * dphi, i + 0.2),
                    ("sans-serif", 11),
                )))?;
            }
        }
        root.present()?;
    }
    let mut text = buf;
    text.insert_str(
        text.find("</svg>").unwrap_or(text.len()),
        "<text x=\"10\" y=\"755\" font-family=\"sans-serif\" font-size=\"12\">cell: log10 |ω_engine − ω*|/ω* (blue −6 … red 0); S stops, C chatters, O oscillates</text>",
    );
    std::fs::write(path, text)?;
    Ok(())
}

/// The explanations, asserted by `crates/engine/tests/idioms.rs`.
const FINDINGS: &str = "## What explains each disagreement\n\n\
* **impulse_disk** (Box2D friction joint / Chipmunk pivot joint with max force, one per support): the force is \
`f = −clamp_len(K⁻¹u/Δt, F)` with `K = I/m + (D r)(D r)ᵀ/I` (r from the centre of mass). Below the cap it sticks \
(force `m_eff |u|/Δt` along an eigen-direction of K), but at these speeds the supports slide far above the sticking \
zone (`|K⁻¹u| < F Δt`, i.e. |u| below about 1–5 mm/s at Δt = 1e-3, 0.02–0.08 m/s at 1/60), so the error is not sticking: \
it is the **direction** of the capped impulse, `−K⁻¹u/|K⁻¹u|` instead of `−u/|u|`. K⁻¹ weights the part of u along r \
(eigenvalue m) four times more than the part across it (eigenvalue 1/(1/m + |r|²/I) = m/4 here), so the friction \
moment about the contact changes and ω* is 43–56 % too large at φ = π/4 + 0.3, **independent of Δt** (the Δt → 0 law \
is the pure direction bias). The root of the moment balance with this law predicts the engine to ≤ 6.5e-7 at Δt = 1e-3 \
over the whole grid. At Δt = 1/60 and small Fr it chatters (stop gain γ > 2, below).\n\
* **impulse_box** (per world axis, each component capped at F Δt; rapier's joint-motor idiom): at large speeds every \
support's force is `−F (sgn u_x, sgn u_y)` in world axes, so the law depends on the angle θ. The moment `G(θ, 0)` at \
ω = 0 has stable zeros: the body **locks its orientation** and then translates with the pusher (mean ω over the \
second half ≈ 0 in every grid cell; many cells still swing about the lock, flagged `oscillates`/`chatters`). The stable lock is near `θ = π/2 − φ (mod π/2)`, where the pusher runs along a world axis; \
`idioms::lock_angles` predicts it: at v_c = 0.5 the engine's final angle is within 0.02 rad of it (asserted); over \
the grid within 0.09 rad at Δt = 1e-3, while at Δt = 1/60 some cells chatter and the frozen law has no stable lock \
(`inf` below). `θ = 0` is an unstable \
balance (the runs start at θ = 0.1).\n\
* **regularised_linear / regularised_tanh**: the steady state only feels the law at supports slower than v_s. The \
linear law is exactly Coulomb whenever the slowest support at ω* slides faster than v_s (0.399 m/s at v_c = 0.5), so \
v_s = 0.01 m/s changes nothing anywhere on the grid; tanh converges exponentially (error 30 % at v_s = 1, 8 % at 0.3, \
6e-4 at 0.1). Their failure is stopping: with the pusher at rest the explicit step maps ω to (1 − γ) ω with \
`γ = Δt Σ F_i |p_i − p_c|² / (v_s I_P)`; γ > 2 (Δt > 2 v_s I_P / Σ F|d|², i.e. v_s < 0.061 m/s at Δt = 1/60) chatters \
like explicit Coulomb, γ < 2 stops cleanly (exponentially, no true sticking).\n\
* **Stopping, impulse idioms**: inside the sticking zone the one-pass Jacobi impulses give \
`γ = Σ_i (d_i × K_i⁻¹ D d_i)/I_P` (d_i = p_i − p_c), independent of Δt: 2.63 (disk), 2.41 (box) > 2, so the stop chatters \
at every Δt with an amplitude of one capped impulse (a Gauss–Seidel solver iterating the four supports would damp this; \
not done).\n\n";
