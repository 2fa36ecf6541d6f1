//! Bullet's contact friction (the outside engine `pybullet_contact` of
//! `pushval.toml`) against Coulomb's law and against the closed form
//! `FrictionModel::ImpulseRowsDisk` (`pushval_rapier2d::idioms`): the per-axis
//! friction rows of Bullet's multibody solver, their pair scaled back onto
//! the friction disk.
//!
//! Run from the repository root after `scripts/setup-adapters.sh`:
//! `cargo run --release --example bullet_law`. Writes, in
//! `results/friction_models/` (each file through a temporary and a rename):
//!
//! * `bullet_contact.csv`: the paper plate pushed at v_c = 0.2, 0.5, 1.0 m/s
//!   in the direction φ = π/4 + 0.3 for 6 s from θ = 0 (moving with the
//!   pusher, ω = 0): per sample `speed,t,theta_engine,omega_engine,
//!   theta_law,omega_law,omega_law_frozen,omega_coulomb` (the law's reduced
//!   model integrated from the same start; the law's steady ω frozen at the
//!   engine's own angle; Coulomb's steady ω);
//! * `bullet_law_theta.csv`: the law's frozen steady ω over one quarter turn
//!   of θ (the law's period for the square plate), per speed;
//! * `bullet_contact_summary.csv`: per speed, Coulomb's ω*; the means of the
//!   engine's ω and of the law's over the second half (t ≥ 3 s) and their
//!   relative differences; the largest differences between the engine and
//!   the law over the second half; the range of the engine's ω there and of
//!   the law's frozen ω*(θ) over θ; the law's quasi-steady mean over a turn,
//!   `1/⟨1/ω*(θ)⟩`;
//! * `bullet_contact_dt.csv`: the second-half means of the engine and of the
//!   law at dt = 1, 0.5 and 0.25 ms, per speed (how much of the engine–law
//!   gap is the engine's time step).

use std::f64::consts::FRAC_PI_2;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;
use pushval::registry;
use pushval::study::plate::{self, PHI_TABLE, TABLE_SPEEDS};
use pushval_engine::EngineOptions;
use pushval_rapier2d::idioms::{self, FrictionModel};

/// The engine's step (s).
const DT: f64 = 1e-3;
/// Length of each push (s).
const DURATION: f64 = 6.0;
/// The law.
const LAW: FrictionModel = FrictionModel::ImpulseRowsDisk;

fn write(path: &Path, text: &str) -> anyhow::Result<()> {
    pushval::atomic::write_atomic(path, text.as_bytes())
}

fn main() -> anyhow::Result<()> {
    registry::use_engines_file(Some(Path::new("pushval.toml")))?;
    let engine = registry::entry("pybullet_contact")
        .context("pushval.toml declares no engine `pybullet_contact`")?
        .build(&EngineOptions::default())
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let out = Path::new("results/friction_models");
    std::fs::create_dir_all(out)?;
    let mut series = String::from(
        "speed,t,theta_engine,omega_engine,theta_law,omega_law,omega_law_frozen,omega_coulomb\n",
    );
    let mut summary = String::from(
        "speed,omega_coulomb,omega_engine_mean,omega_law_mean,rel_engine_vs_coulomb,rel_engine_vs_law,max_abs_omega_engine_minus_law,max_abs_theta_engine_minus_law,omega_engine_min,omega_engine_max,omega_law_frozen_min,omega_law_frozen_max,omega_law_quasi_steady_mean\n",
    );
    let mut theta_table = String::from("speed,theta,omega_law_frozen,omega_coulomb\n");
    for &speed in &TABLE_SPEEDS {
        let problem = plate::paper_plate(speed, PHI_TABLE, DURATION, None);
        let body = &problem.body;
        let push = &problem.pushes[0];
        let coulomb = pushval_engine::coulomb_steady(&problem, 0).unwrap_or(f64::NAN);
        eprintln!("bullet_law: pybullet_contact at v_c = {speed} m/s");
        let run = engine
            .run(&problem, DT)
            .map_err(|e| anyhow::anyhow!("pybullet_contact at v_c = {speed}: {e}"))?;
        let law = idioms::predicted_angle_history(
            LAW,
            body,
            push,
            DT,
            (0.0, 0.0),
            DURATION,
            problem.sample_dt,
        );
        let samples = &run.trajectory.samples;
        anyhow::ensure!(
            samples.len() == law.len(),
            "{} engine samples, {} law samples",
            samples.len(),
            law.len()
        );
        let (mut sum_w, mut sum_law, mut n_half) = (0.0, 0.0, 0usize);
        let (mut d_w, mut d_th) = (0.0f64, 0.0f64);
        let (mut w_min, mut w_max) = (f64::INFINITY, f64::NEG_INFINITY);
        for (s, &(t, th_law, w_law)) in samples.iter().zip(&law) {
            let frozen = idioms::predicted_steady_omega(LAW, body, push, DT, s.theta, s.omega)
                .unwrap_or(f64::NAN);
            writeln!(
                series,
                "{speed},{t:.2},{},{},{th_law},{w_law},{frozen},{coulomb}",
                s.theta, s.omega
            )?;
            if t >= 0.5 * DURATION - 1e-9 {
                sum_w += s.omega;
                sum_law += w_law;
                n_half += 1;
                d_w = d_w.max((s.omega - w_law).abs());
                d_th = d_th.max((s.theta - th_law).abs());
                w_min = w_min.min(s.omega);
                w_max = w_max.max(s.omega);
            }
        }
        let mean = sum_w / n_half as f64;
        let law_mean = sum_law / n_half as f64;
        let quasi = idioms::predicted_mean_omega(LAW, body, push, DT, 720).unwrap_or(f64::NAN);
        let (mut f_min, mut f_max) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..=90 {
            let th = FRAC_PI_2 * k as f64 / 90.0;
            let w =
                idioms::predicted_steady_omega(LAW, body, push, DT, th, 0.0).unwrap_or(f64::NAN);
            f_min = f_min.min(w);
            f_max = f_max.max(w);
            writeln!(theta_table, "{speed},{th},{w},{coulomb}")?;
        }
        writeln!(
            summary,
            "{speed},{coulomb},{mean},{law_mean},{},{},{d_w},{d_th},{w_min},{w_max},{f_min},{f_max},{quasi}",
            rel(mean, coulomb),
            rel(mean, law_mean)
        )?;
    }
    // The engine's time step: the second-half means at dt, dt/2, dt/4.
    let mut by_dt = String::from("speed,dt,omega_engine_mean,omega_law_mean,rel_engine_vs_law\n");
    for &speed in &TABLE_SPEEDS {
        let problem = plate::paper_plate(speed, PHI_TABLE, DURATION, None);
        for dt in [DT, DT / 2.0, DT / 4.0] {
            eprintln!("bullet_law: pybullet_contact at v_c = {speed} m/s, dt = {dt} s");
            let run = engine
                .run(&problem, dt)
                .map_err(|e| anyhow::anyhow!("pybullet_contact at v_c = {speed}, dt {dt}: {e}"))?;
            let law = idioms::predicted_angle_history(
                LAW,
                &problem.body,
                &problem.pushes[0],
                dt,
                (0.0, 0.0),
                DURATION,
                problem.sample_dt,
            );
            let (mut se, mut sl, mut n) = (0.0, 0.0, 0usize);
            for (s, &(t, _, wl)) in run.trajectory.samples.iter().zip(&law) {
                if t >= 0.5 * DURATION - 1e-9 {
                    se += s.omega;
                    sl += wl;
                    n += 1;
                }
            }
            let (me, ml) = (se / n as f64, sl / n as f64);
            writeln!(by_dt, "{speed},{dt},{me},{ml},{}", rel(me, ml))?;
        }
    }
    write(&out.join("bullet_contact_dt.csv"), &by_dt)?;
    write(&out.join("bullet_contact.csv"), &series)?;
    write(&out.join("bullet_law_theta.csv"), &theta_table)?;
    write(&out.join("bullet_contact_summary.csv"), &summary)?;
    eprintln!("{summary}");
    Ok(())
}

/// `|a − b| / |b|`.
fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}
