//! MuJoCo 3.17 (compiled in: `pushval-mujoco` on mujoco-rs, feature
//! `mujoco`) against MuJoCo 4.0 (the outside engines `mujoco4_*` of
//! `pushval.toml`: `adapters/python/mujoco_push.py` on the PyPI wheel), on
//! the same scene and the same problems, per friction cone.
//!
//! Run from the repository root after `scripts/setup-adapters.sh`:
//!
//! ```text
//! eval "$(scripts/setup-mujoco.sh)"
//! cargo run --release --features mujoco --example mujoco_versions
//! ```
//!
//! Writes `results/friction_models/mujoco_versions.csv` (through a temporary
//! and a rename): the paper plate pushed at v_c = 0.2, 0.5, 1.0 m/s in the
//! direction φ = π/4 + 0.3 for 6 s from θ = 0 (moving with the pusher,
//! ω = 0) at dt = 1 ms, one row per (cone, speed): Coulomb's steady ω, each
//! version's ω over the last 20 % of the push (mean and standard deviation)
//! and its angle at the end, the change 4.0 − 3.17, and each version's
//! relative error against Coulomb; plus the largest |Δθ| and |Δω| between
//! the two versions' samples over the whole push.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;
use pushval::registry;
use pushval::study::plate::{self, PHI_TABLE, TABLE_SPEEDS};
use pushval_engine::EngineOptions;

const DT: f64 = 1e-3;
const DURATION: f64 = 6.0;

/// Mean and standard deviation of ω over the last 20 % of the samples.
fn tail(samples: &[pushval_model::Sample]) -> (f64, f64) {
    let from = samples.len() - samples.len() / 5;
    let w: Vec<f64> = samples[from..].iter().map(|s| s.omega).collect();
    let n = w.len() as f64;
    let mean = w.iter().sum::<f64>() / n;
    let var = w.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}

fn main() -> anyhow::Result<()> {
    registry::use_engines_file(Some(Path::new("pushval.toml")))?;
    let build = |name: &str| -> anyhow::Result<Box<dyn pushval_engine::Engine>> {
        let e = registry::entry(name)
            .with_context(|| format!("no engine `{name}` (pushval.toml, this build)"))?
            .build(&EngineOptions::default())
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        e.availability()
            .map_err(|why| anyhow::anyhow!("{name}: {why}"))?;
        Ok(e)
    };
    let mut csv = String::from(
        "cone,speed,omega_coulomb,version_old,version_new,omega_old,omega_old_std,omega_new,omega_new_std,change,rel_change,rel_err_old,rel_err_new,theta_end_old,theta_end_new,max_abs_theta_diff,max_abs_omega_diff\n",
    );
    for cone in ["pyramidal", "elliptic"] {
        let old = build(&format!("mujoco_{cone}"))?;
        let new = build(&format!("mujoco4_{cone}"))?;
        for &speed in &TABLE_SPEEDS {
            let problem = plate::paper_plate(speed, PHI_TABLE, DURATION, None);
            let coulomb = pushval_engine::coulomb_steady(&problem, 0).unwrap_or(f64::NAN);
            eprintln!("mujoco_versions: {cone}, v_c = {speed} m/s");
            let a = old
                .run(&problem, DT)
                .map_err(|e| anyhow::anyhow!("{}: {e}", old.name()))?;
            let b = new
                .run(&problem, DT)
                .map_err(|e| anyhow::anyhow!("{}: {e}", new.name()))?;
            let (sa, sb) = (&a.trajectory.samples, &b.trajectory.samples);
            anyhow::ensure!(sa.len() == sb.len(), "sample counts differ");
            let (wa, da) = tail(sa);
            let (wb, db) = tail(sb);
            let (mut dth, mut dw) = (0.0f64, 0.0f64);
            for (p, q) in sa.iter().zip(sb) {
                dth = dth.max((p.theta - q.theta).abs());
                dw = dw.max((p.omega - q.omega).abs());
            }
            writeln!(
                csv,
                "{cone},{speed},{coulomb},\"{}\",\"{}\",{wa},{da},{wb},{db},{:.3e},{:.3e},{},{},{},{},{dth:.3e},{dw:.3e}",
                old.version(),
                new.version(),
                wb - wa,
                (wb - wa) / wa.abs().max(1e-3 * speed / plate::length()),
                rel(wa, coulomb),
                rel(wb, coulomb),
                sa.last().unwrap().theta,
                sb.last().unwrap().theta,
            )?;
        }
    }
    let out = Path::new("results/friction_models/mujoco_versions.csv");
    pushval::atomic::write_atomic(out, csv.as_bytes())?;
    eprintln!("{csv}");
    Ok(())
}

/// `|a − b| / |b|`.
fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}
