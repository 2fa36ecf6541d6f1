//! Jolt's friction against its closed form and Coulomb's on the paper plate,
//! with what `pushval study jolt_box|jolt_feet` does not write: per map cell
//! the friction slip angle, the loads and the law's band
//! (`diagnostics.csv`), and the rest loads against the step and the
//! iterations (`loads.csv`), beside its own `paper_plate.csv`, `map.csv` and
//! `README.md`, one folder per model (`jolt_box/`, `jolt_feet/`).
//!
//! Writes into `target/jolt-study/` of the workspace (or `--out DIR`), never
//! into `results/`: the studies there are `pushval study`'s
//! (`results/MANIFEST.csv`).
//!
//! ```sh
//! cargo run --release -p pushval-jolt --features jolt --example study [-- --quick] [-- --out DIR]
//! ```
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use pushval_jolt::predict::{self, at_rest, Direction, Law};
use pushval_jolt::{DetailedEngine, JoltRun, JoltSettings, JoltSimulator, Scene};
use pushval_model::{Body, Initial, Problem, Push, SegmentDynamics, Support, Switching, Vec2};

const MU: f64 = 0.5;
const G: f64 = 9.81;
const MASS: f64 = 1.0;
const HALF: f64 = 0.125;
const PHI_TABLE: f64 = std::f64::consts::FRAC_PI_4 + 0.3;
const TABLE_SPEEDS: [f64; 3] = [0.2, 0.5, 1.0];
const FRS: [f64; 20] = [
    0.02, 0.0255, 0.0325, 0.0414, 0.0527, 0.0672, 0.0856, 0.109, 0.139, 0.177, 0.226, 0.288, 0.367,
    0.467, 0.595, 0.759, 0.967, 1.23, 1.57, 2.0,
];
const FRS_QUICK: [f64; 5] = [0.02, 0.1, 0.3, 1.0, 2.0];
const PHI_RANGE: (f64, f64) = (0.15, 1.42);
/// Table runs (s) and map runs (s); ω is averaged over the last fifth.
const T_RUN: f64 = 4.0;
const T_MAP: f64 = 2.5;
/// "Within" for the shares.
const TOL: f64 = 1e-2;
/// Step of the law's reduced dynamics (s).
const LAW_H: f64 = 1e-4;

fn plate() -> Body {
    let h = HALF;
    let s: Vec<Support> = [[-h, -h], [h, -h], [h, h], [-h, h]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: MU * MASS * G / 4.0,
        })
        .collect();
    let side = 2.0 * h;
    Body::new(MASS, MASS * side * side / 6.0, Vec2::new(-h, -h), &s).expect("valid plate")
}

fn problem(speed: f64, phi: f64, duration: f64) -> Problem {
    Problem {
        body: plate(),
        limits: Default::default(),
        pushes: vec![Push {
            duration,
            speed,
            phi,
        }],
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.01,
        release: None,
    }
}

fn length() -> f64 {
    plate().contact().norm()
}

fn speed_of(fr: f64) -> f64 {
    (fr * MU * G * length()).sqrt()
}

fn coulomb_star(body: &Body, push: &Push) -> f64 {
    let seg = SegmentDynamics::new(body, push);
    let roots = seg.steady_states();
    seg.attractor(&roots, 0.0).map_or(f64::NAN, |s| s.omega)
}

/// The law of `scene` with the engine's rest loads (`μ̄ N_i`).
fn law(scene: Scene, body: &Body, run: &JoltRun) -> Law {
    let caps: Vec<f64> = run.rest_loads.iter().map(|n| run.mu * n).collect();
    match scene {
        Scene::Box => Law::jolt_box(body, Some(&caps), Direction::EffectiveMass),
        Scene::Feet => Law::jolt_feet(body, Some(&caps), Direction::EffectiveMass),
    }
}

/// `(ω_law, class)`: the law's tail mean over the run and the class of
/// ω = 0 (box: locked/turns; feet: no twist rows, so never locked).
fn predict_cell(scene: Scene, p: &Problem, run: &JoltRun, t: f64) -> (f64, &'static str) {
    let l = law(scene, &p.body, run);
    let push = p.pushes[0];
    let w = predict::tail_omega(&l, &p.body, &push, t, (0.0, 0.0), LAW_H);
    (w, at_rest(&l, &p.body, &push, 0.0).as_str())
}

/// Agreement within TOL: relative, with the floor of `pushval_engine::rel_err`.
fn within(a: f64, b: f64, speed: f64) -> bool {
    pushval_engine::rel_err(a, b, speed, length()) <= TOL
}

fn run(scene: Scene, p: &Problem, dt: f64, vsteps: u32) -> JoltRun {
    JoltSimulator::new(JoltSettings {
        scene,
        dt,
        velocity_steps: vsteps,
        ..Default::default()
    })
    .run(p)
    .unwrap_or_else(|e| panic!("Jolt run failed: {e}"))
}

fn write(path: &Path, text: &str) {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, text).unwrap_or_else(|e| panic!("{}: {e}", tmp.display()));
    std::fs::rename(&tmp, path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

fn f(x: f64) -> String {
    format!("{x:.6}")
}

struct Cell {
    fr: f64,
    phi: f64,
    speed: f64,
    engine: f64,
    coulomb: f64,
    law: f64,
    class: &'static str,
    angle: f64,
    angle_vs_law: f64,
    load_min: f64,
    load_max: f64,
    band: (f64, f64),
}

/// The law's ω over the loads four rigid feet (or corners) allow with the
/// centre of mass at the centre: `N₀ = N₂ = a`, `N₁ = N₃ = W/2 − a`, for
/// a in 0, W/16, …, W/2: `(min, max)` of the tail means.
fn band(scene: Scene, p: &Problem, mu: f64, t: f64) -> (f64, f64) {
    let w = MASS * G;
    let push = p.pushes[0];
    (0..=8)
        .map(|k| {
            let a = 0.5 * w * k as f64 / 8.0;
            let caps = [mu * a, mu * (0.5 * w - a), mu * a, mu * (0.5 * w - a)];
            let l = match scene {
                Scene::Box => Law::jolt_box(&p.body, Some(&caps), Direction::EffectiveMass),
                Scene::Feet => Law::jolt_feet(&p.body, Some(&caps), Direction::EffectiveMass),
            };
            predict::tail_omega(&l, &p.body, &push, t, (0.0, 0.0), LAW_H)
        })
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        })
}

/// The workspace's `target/jolt-study/`.
fn default_out() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../target/jolt-study")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .map_or_else(default_out, PathBuf::from);
    let frs: &[f64] = if quick { &FRS_QUICK } else { &FRS };
    let nphi = if quick { 5 } else { 20 };
    let phis: Vec<f64> = (0..nphi)
        .map(|k| PHI_RANGE.0 + k as f64 * (PHI_RANGE.1 - PHI_RANGE.0) / (nphi - 1) as f64)
        .collect();
    for scene in Scene::ALL {
        let dir = out.join(scene.model_name());
        std::fs::create_dir_all(&dir).expect("output folder");
        // Paper table.
        let mut table = String::from("speed,omega_engine,omega_coulomb,omega_law\n");
        let mut table_rows = Vec::new();
        for v in TABLE_SPEEDS {
            let p = problem(v, PHI_TABLE, T_RUN);
            let r = run(scene, &p, 1e-3, 10);
            let (wl, _) = predict_cell(scene, &p, &r, T_RUN);
            let wc = coulomb_star(&p.body, &p.pushes[0]);
            writeln!(
                table,
                "{v},{},{},{}",
                f(r.segment_tail_omega[0]),
                f(wc),
                f(wl)
            )
            .unwrap();
            table_rows.push((v, r.segment_tail_omega[0], wc, wl, r));
        }
        write(&dir.join("paper_plate.csv"), &table);
        // Map.
        let mut cells = Vec::new();
        for &fr in frs {
            for &phi in &phis {
                let v = speed_of(fr);
                let p = problem(v, phi, T_MAP);
                let r = run(scene, &p, 1e-3, 10);
                let (wl, class) = predict_cell(scene, &p, &r, T_MAP);
                let range = &r.segment_tail_load_range[0];
                cells.push(Cell {
                    fr,
                    phi,
                    speed: v,
                    engine: r.segment_tail_omega[0],
                    coulomb: coulomb_star(&p.body, &p.pushes[0]),
                    law: wl,
                    class,
                    angle: r.segment_tail_max_angle[0],
                    angle_vs_law: r.segment_tail_max_angle_vs_law[0],
                    load_min: range.iter().map(|x| x[0]).fold(f64::INFINITY, f64::min),
                    load_max: range.iter().map(|x| x[1]).fold(0.0, f64::max),
                    band: band(scene, &p, r.mu, T_MAP),
                });
            }
        }
        let mut map = String::from("froude,phi,omega_engine,omega_coulomb,omega_law,class\n");
        let mut diag = String::from(
            "froude,phi,speed,omega_engine,omega_law,max_friction_slip_angle,max_angle_vs_law,min_load,max_load,omega_law_band_min,omega_law_band_max\n",
        );
        for c in &cells {
            writeln!(
                map,
                "{},{},{},{},{},{}",
                c.fr,
                f(c.phi),
                f(c.engine),
                f(c.coulomb),
                f(c.law),
                c.class
            )
            .unwrap();
            writeln!(
                diag,
                "{},{},{},{},{},{},{},{},{},{},{}",
                c.fr,
                f(c.phi),
                f(c.speed),
                f(c.engine),
                f(c.law),
                f(c.angle),
                f(c.angle_vs_law),
                f(c.load_min),
                f(c.load_max),
                f(c.band.0),
                f(c.band.1)
            )
            .unwrap();
        }
        write(&dir.join("map.csv"), &map);
        write(&dir.join("diagnostics.csv"), &diag);
        // Loads vs dt and iterations (rest), and their drift while sliding.
        let mut loads = String::from(
            "dt,velocity_steps,rest_load_0,rest_load_1,rest_load_2,rest_load_3,manifold_sizes,tail_min_load,tail_max_load,omega_engine\n",
        );
        for (dt, vs) in [(2e-3, 10), (1e-3, 10), (5e-4, 10), (1e-3, 30), (1e-3, 100)] {
            let p = problem(0.5, PHI_TABLE, T_RUN);
            let r = run(scene, &p, dt, vs);
            let range = &r.segment_tail_load_range[0];
            writeln!(
                loads,
                "{dt},{vs},{},{},{},{},{},{},{},{}",
                f(r.rest_loads[0]),
                f(r.rest_loads[1]),
                f(r.rest_loads[2]),
                f(r.rest_loads[3]),
                r.manifold_sizes
                    .iter()
                    .map(|s| s.to_string())
                    .collect::<Vec<_>>()
                    .join(" "),
                f(range.iter().map(|x| x[0]).fold(f64::INFINITY, f64::min)),
                f(range.iter().map(|x| x[1]).fold(0.0, f64::max)),
                f(r.segment_tail_omega[0])
            )
            .unwrap();
        }
        write(&dir.join("loads.csv"), &loads);
        write(&dir.join("README.md"), &readme(scene, &dir));
        eprintln!("{}: written {}", scene.model_name(), dir.display());
    }
}

/// The README, computed from the files just written.
fn readme(scene: Scene, dir: &Path) -> String {
    let read = |name: &str| -> Vec<Vec<String>> {
        std::fs::read_to_string(dir.join(name))
            .expect("just written")
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect()
    };
    let num = |s: &str| s.parse::<f64>().unwrap_or(f64::NAN);
    let table = read("paper_plate.csv");
    let map = read("map.csv");
    let diag = read("diagnostics.csv");
    let loads = read("loads.csv");
    let n = map.len();
    let (mut law_ok, mut coul_ok, mut locked, mut turns, mut still) = (0, 0, 0, 0, 0);
    let mut in_band = 0;
    for (row, d) in map.iter().zip(&diag) {
        let (we, wc, wl) = (num(&row[2]), num(&row[3]), num(&row[4]));
        let v = num(&d[2]);
        law_ok += within(we, wl, v) as usize;
        let (lo, hi) = (num(&d[9]), num(&d[10]));
        let slack = TOL * we.abs().max(1e-3 * v / length());
        in_band += (we >= lo - slack && we <= hi + slack) as usize;
        coul_ok += within(we, wc, v) as usize;
        locked += (row[5] == "locked") as usize;
        turns += (row[5] == "turns") as usize;
        still += (we.abs() < 1e-3 * wc.abs().max(1e-9)) as usize;
    }
    let max_col = |col: usize| diag.iter().map(|d| num(&d[col])).fold(0.0, f64::max);
    let min_col = |col: usize| {
        diag.iter()
            .map(|d| num(&d[col]))
            .fold(f64::INFINITY, f64::min)
    };
    let mut s = String::new();
    let name = scene.model_name();
    writeln!(s, "# {name}: Jolt 5.6 friction against its closed form\n").unwrap();
    writeln!(
        s,
        "Generated by `cargo run --release -p pushval-jolt --features jolt --example study` \
         from `paper_plate.csv`, `map.csv`, `diagnostics.csv` and `loads.csv` in this folder. \
         The law is `pushval_jolt::predict` (one friction disc per manifold at the unweighted \
         mean of its points, along `−D u` with `D` the two world-axis rows' effective masses, \
         plus a twist row clamped to `μ Σ dᵢλᵢ` on manifolds of more than one point), given the \
         loads Jolt chose at rest; `omega_law` is its reduced dynamics' mean ω over the last \
         fifth of the run, as the engine's.\n"
    )
    .unwrap();
    writeln!(s, "## Paper plate (φ = π/4 + 0.3, {T_RUN} s, dt = 1 ms)\n").unwrap();
    writeln!(
        s,
        "| v_c (m/s) | engine ω | Coulomb ω* | law ω |\n|---|---|---|---|"
    )
    .unwrap();
    for r in &table {
        writeln!(s, "| {} | {} | {} | {} |", r[0], r[1], r[2], r[3]).unwrap();
    }
    writeln!(s, "\n## (Fr, φ) map ({n} cells, {T_MAP} s, dt = 1 ms)\n").unwrap();
    writeln!(
        s,
        "* cells within {TOL} (relative, floor 1e-3 v_c/L) of the law: {law_ok} of {n} ({:.1} %)",
        100.0 * law_ok as f64 / n as f64
    )
    .unwrap();
    writeln!(
        s,
        "* cells within {TOL} of Coulomb: {coul_ok} of {n} ({:.1} %)",
        100.0 * coul_ok as f64 / n as f64
    )
    .unwrap();
    writeln!(
        s,
        "* cells whose engine ω lies within the law's band over the load splits four rigid \
         supports allow (N₀ = N₂ = a, N₁ = N₃ = W/2 − a, a in 0 … W/2, slack {TOL}): {in_band} of {n} ({:.1} %)",
        100.0 * in_band as f64 / n as f64
    )
    .unwrap();
    writeln!(
        s,
        "* law's class of ω = 0: locked {locked}, turns {turns}, semi-stable 0 (one twist row \
         per manifold: holding at rest and Filippov's condition coincide); engine |ω| below \
         1e-3 of Coulomb's: {still} cells"
    )
    .unwrap();
    writeln!(
        s,
        "* largest angle between a manifold's friction force and its slip's opposite: {:.4} rad; \
         largest difference from the law's angle for the same slip: {:.2e} rad",
        max_col(5),
        max_col(6)
    )
    .unwrap();
    writeln!(
        s,
        "* support loads over the runs' tails: {:.4} N to {:.4} N (weight {:.4} N)\n",
        min_col(7),
        max_col(8),
        MASS * G
    )
    .unwrap();
    writeln!(s, "## Loads (v_c = 0.5 m/s, φ = π/4 + 0.3)\n").unwrap();
    writeln!(
        s,
        "| dt (s) | velocity steps | rest loads (N) | manifold sizes | tail min / max load (N) | engine ω |\n|---|---|---|---|---|---|"
    )
    .unwrap();
    for r in &loads {
        writeln!(
            s,
            "| {} | {} | {} {} {} {} | {} | {} / {} | {} |",
            r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8], r[9]
        )
        .unwrap();
    }
    s
}
