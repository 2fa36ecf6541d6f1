//! `pushval fit-study`: how well a push determines μ, I_cm, the contact
//! point and the centre of friction, from the Fisher information at the
//! truth with the stated noise (1 mm on x and y, 1 mrad on θ, every 0.01 s
//! sample), checked against repeated noisy fits. Writes
//! `OUT/identifiability.csv`, `OUT/identifiability.svg` and `OUT/fit.md`.
//!
//! The object is the seed paper's plate (`scenarios/paper-square-v1.0.toml`:
//! 0.25 m, 1 kg, four corner supports, μ 0.5, pushed at a corner), started
//! as the paper does (moving with the pusher, ω = 0). Three sweeps, each
//! from one base push of 1 m/s for 2 s at φ = π/4 + 0.3 (the file's first
//! segment):
//!
//! * speed: 0.1–2 m/s, 2 s;
//! * duration: 0.1–10 s at 1 m/s;
//! * segments: 2 s at 1 m/s cut into k = 1…5 equal segments whose φ run
//!   through the file's five angles in order.
//!
//! Three parameter sets ([`sets`]): `mu_scale, inertia_cm`; the same with
//! `contact`; the same with `center_of_friction` (what a third unknown
//! costs, and where it cannot be had at all).
//!
//! The answer to "what is the shortest push that gives μ within 1 % and
//! I_cm within 2 %": at 2σ (95 %) of the Fisher std, fitting `mu_scale` and
//! `inertia_cm` together, one segment from the paper's start, over the
//! speeds 0.2–2 m/s and the file's φ other than π/4 (through the centre of
//! mass: no turn). The information only grows with the duration (one more
//! sample adds a positive semi-definite term), so bisection over whole
//! sample steps finds the shortest duration exactly.
//!
//! This module holds the grid, the Fisher analysis per point and the
//! repeated noisy fits that check it (one row type, one check list);
//! [`figure`] draws `identifiability.svg` and [`text`] writes `fit.md`, both
//! from the rows alone.

use std::path::Path;

mod analysis;
mod figure;
mod text;

use anyhow::Context;

use crate::atomic::write_atomic;
use crate::outdir::Csv;
use crate::plot;
pub use analysis::*;
use figure::figure;
use text::text;

/// Runs the study and writes its files into `out` (`quick`: reduced grids,
/// one check point, the shortest push at 1 m/s only).
pub fn run(scenarios: &Path, out: &Path, quick: bool) -> anyhow::Result<Outcome> {
    let study = Study::new(scenarios)?;
    let mut rows = Vec::new();
    for p in grid(&study, quick) {
        for set in 0..sets().len() {
            rows.extend(study.rows(&p, set, None)?);
        }
    }
    let mut checks = Vec::new();
    let mut cps = check_points(&study);
    if quick {
        cps.truncate(1);
    }
    for (i, (p, set_ids)) in cps.iter().enumerate() {
        for &set in set_ids {
            let seed0 = 10_000 * (i as u64 + 1) + 1000 * set as u64;
            let c = study.check(p, &sets()[set], FITS, seed0)?;
            let at = Point {
                sweep: "check",
                ..p.clone()
            };
            rows.extend(study.rows(&at, set, Some(&c))?);
            checks.push(c);
        }
    }
    let mut shortest = Vec::new();
    let candidates: Vec<(f64, f64)> = shortest_candidates(&study)
        .into_iter()
        .filter(|c| !quick || c.0 == 1.0)
        .collect();
    let max_duration = if quick { 4.0 } else { 10.0 };
    for (v, phi) in candidates {
        let d = study.shortest(v, phi, max_duration)?;
        let mut violated = Vec::new();
        if let Some(d) = d {
            let p = Point {
                sweep: "shortest",
                speed: v,
                duration: d,
                segments: 1,
                phi,
            };
            let r = study.rows(&p, 0, None)?;
            violated = r[0].violated.clone();
            rows.extend(r);
        }
        shortest.push(Shortest {
            speed: v,
            phi,
            duration: d,
            violated,
        });
    }
    let mut o = Outcome {
        rows,
        checks,
        shortest,
        files: Vec::new(),
    };
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut csv = Csv::new(&HEADER);
    o.rows.iter().for_each(|r| csv.row(&r.csv()));
    let svg = plot::render(&figure(&o)).context("drawing identifiability.svg")?;
    for (name, bytes) in [
        ("identifiability.csv", csv.as_bytes().to_vec()),
        ("identifiability.svg", svg.into_bytes()),
        ("fit.md", text(&study, &o, quick).into_bytes()),
    ] {
        let path = out.join(name);
        write_atomic(&path, &bytes)?;
        o.files.push(path);
    }
    Ok(o)
}

/// `pushval fit-study`: runs the study on the shipped scenarios, prints the
/// answer; exit 0 when every empirical check agrees with the Fisher std, 1
/// when one does not.
pub fn cli(out: &Path, quick: bool) -> anyhow::Result<std::process::ExitCode> {
    let start = std::time::Instant::now();
    let o = run(&crate::scenario_dir::default_scenario_dir(), out, quick)?;
    match o.best(true) {
        Some((v, phi, d)) => println!(
            "shortest push (model assumptions holding) for μ within {} % and I_cm within {} % at {}σ: {d:.2} s at {v} m/s, φ = {phi:.4} rad",
            MU_TARGET * 100.0,
            INERTIA_TARGET * 100.0,
            SIGMAS
        ),
        None => println!("no candidate push reaches both targets"),
    }
    for c in &o.checks {
        let r: Vec<String> = c.ratios().iter().map(|r| format!("{r:.2}")).collect();
        println!(
            "check {} m/s, {} s, {} segment(s), {}: empirical/Fisher std {} ({})",
            c.point.speed,
            c.point.duration,
            c.point.segments,
            set_name(&c.set),
            r.join(", "),
            if c.pass() { "ok" } else { "FAIL" }
        );
    }
    let files: Vec<String> = o.files.iter().map(|f| f.display().to_string()).collect();
    println!(
        "{} rows in {:.1} s; wrote {}",
        o.rows.len(),
        start.elapsed().as_secs_f64(),
        files.join(", ")
    );
    Ok(if o.checks.iter().all(Check::pass) {
        std::process::ExitCode::SUCCESS
    } else {
        for c in o.checks.iter().filter(|c| !c.pass()) {
            eprintln!(
                "FAIL check {} m/s, {} s, {}: empirical/Fisher std outside a factor {AGREEMENT}",
                c.point.speed,
                c.point.duration,
                set_name(&c.set)
            );
        }
        std::process::ExitCode::from(1)
    })
}
