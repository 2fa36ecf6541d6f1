//! `pushval study` (issue "The studies in one place"): the quick 2-D idioms
//! study writes data whose physics holds, a README whose numbers are the
//! data's, and a sharded run merges into the same bytes as a single run.
//!
//! Known answers, each from a closed form or an identity (not from the
//! study's own summary): the impulse_disk engine follows the root of the
//! moment balance with the capped-impulse direction
//! (`idioms::predicted_mean_omega`) and is 40–60 % off Coulomb where ω* is
//! not ≈ 0; regularised_linear is Coulomb wherever every support slides
//! faster than its slip speed at the Coulomb steady state (checked per cell
//! with the model's slowest support speed).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use pushval_model::{Push, SegmentDynamics};

use crate::common::{paper_plate, root};

/// Slip speed of the regularised idioms in the study (m/s).
const SLIP: f64 = 0.01;

fn study(args: &[&str], out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pushval"))
        .current_dir(root())
        .arg("study")
        .args(args)
        .arg("--out")
        .arg(out)
        .env("CI", "1")
        .output()
        .unwrap()
}

fn ok(out: Output) {
    assert!(
        out.status.success(),
        "pushval study failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// One quick idioms study, shared by the tests that read it.
fn quick_dir() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        ok(study(&["idioms", "--quick"], dir.path()));
        dir
    })
    .path()
}

/// A CSV file as rows of named fields.
fn read_csv(path: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), header.len(), "{}: {l}", path.display());
            header
                .iter()
                .zip(f)
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

fn val(row: &BTreeMap<String, String>, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key} = '{}' is not a number", row[key]))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn impulse_disk_follows_its_closed_form_not_coulomb() {
    let rows = read_csv(&quick_dir().join("impulse_disk.csv"));
    assert!(rows.len() >= 12, "{} cells", rows.len());
    let mut off_coulomb = 0;
    for r in &rows {
        let (w, pred, star) = (
            val(r, "omega_engine"),
            val(r, "omega_predicted"),
            val(r, "omega_star"),
        );
        if val(r, "dt") == 1e-3 {
            assert!(
                rel(w, pred) <= 1e-4,
                "Fr {} φ {}: engine {w} vs closed form {pred}",
                r["froude"],
                r["phi"]
            );
        }
        if star.abs() > 0.05 {
            let e = rel(w, star);
            assert!(e > 0.2 && e < 0.8, "Fr {} φ {}: {e}", r["froude"], r["phi"]);
            off_coulomb += 1;
        }
    }
    assert!(off_coulomb >= 4);
}

#[test]
fn regularised_linear_is_coulomb_on_the_grid() {
    let dir = quick_dir();
    let coulomb = read_csv(&dir.join("coulomb.csv"));
    let linear = read_csv(&dir.join("regularised_linear.csv"));
    assert_eq!(coulomb.len(), linear.len());
    let mut checked = 0;
    for (c, l) in coulomb.iter().zip(&linear) {
        for k in ["dt", "froude", "phi"] {
            assert_eq!(c[k], l[k]);
        }
        let push = Push {
            duration: 1.0,
            speed: val(c, "speed"),
            phi: val(c, "phi"),
        };
        let slowest = SegmentDynamics::new(&paper_plate(), &push)
            .min_support_speed(val(c, "omega_star"))
            .0;
        if slowest <= SLIP {
            continue;
        }
        checked += 1;
        let (wc, wl) = (val(c, "omega_engine"), val(l, "omega_engine"));
        let scale = val(c, "omega_star").abs().max(1e-3);
        assert!(
            (wl - wc).abs() <= 1e-6 * scale,
            "Fr {} φ {}: linear {wl} vs Coulomb {wc}",
            c["froude"],
            c["phi"]
        );
        // And Coulomb itself is the model's ω* at Δt = 1e-3.
        if val(c, "dt") == 1e-3 {
            assert!((wc - val(c, "omega_star")).abs() <= 1e-5 * scale);
        }
    }
    assert!(checked >= coulomb.len() / 2, "{checked} cells checked");
}

#[test]
fn readme_numbers_are_the_data() {
    let dir = quick_dir();
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    // The disk's bias at φ = π/4 + 0.3, recomputed from the table.
    let table = read_csv(&dir.join("table_phi_pi4+0.3.csv"));
    let bias: Vec<f64> = table
        .iter()
        .filter(|r| r["idiom"] == "impulse_disk")
        .map(|r| 100.0 * (val(r, "omega_engine") - val(r, "omega_star")) / val(r, "omega_star"))
        .collect();
    assert_eq!(bias.len(), 6);
    let lo = bias.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = bias.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let text = format!("ω* is {lo:.0}–{hi:.0} % too large");
    assert!(readme.contains(&text), "README lacks '{text}'");
    // The stop gains, from stop.csv.
    let stop = read_csv(&dir.join("stop.csv"));
    let gain = |idiom: &str| {
        stop.iter()
            .find(|r| r["idiom"] == idiom)
            .map(|r| val(r, "gain"))
            .unwrap()
    };
    let text = format!(
        "{:.2} (disk), {:.2} (box)",
        gain("impulse_disk"),
        gain("impulse_box")
    );
    assert!(readme.contains(&text), "README lacks '{text}'");
    assert!(gain("impulse_disk") > 2.0 && gain("impulse_box") > 2.0);
    for bad in ["NaN", "inf %"] {
        assert!(!readme.contains(bad), "README holds '{bad}'");
    }
    let svg = std::fs::read_to_string(dir.join("map.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.matches("<rect").count() >= 4 * 2 * 6);
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    v.sort();
    v
}

#[test]
fn shards_merged_equal_a_single_run_byte_for_byte() {
    let single = quick_dir();
    let sharded = tempfile::tempdir().unwrap();
    for k in ["1/2", "2/2"] {
        ok(study(&["idioms", "--quick", "--shard", k], sharded.path()));
    }
    assert!(files(sharded.path()).is_empty(), "a shard wrote outputs");
    // A merge with a part missing is refused (exit 2).
    let part = sharded.path().join("parts/idioms-2-of-2.csv");
    let saved = std::fs::read(&part).unwrap();
    std::fs::remove_file(&part).unwrap();
    let out = study(&["idioms", "--quick", "--merge"], sharded.path());
    assert_eq!(out.status.code(), Some(2));
    std::fs::write(&part, saved).unwrap();
    ok(study(&["idioms", "--quick", "--merge"], sharded.path()));
    let (a, b) = (files(single), files(sharded.path()));
    let names = |v: &[PathBuf]| -> Vec<String> {
        v.iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect()
    };
    assert_eq!(names(&a), names(&b));
    for (x, y) in a.iter().zip(&b) {
        assert!(
            std::fs::read(x).unwrap() == std::fs::read(y).unwrap(),
            "{} differs between the single and the merged run",
            x.display()
        );
    }
}

#[test]
fn unknown_and_missing_studies_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = study(&["nonsense"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("idioms"));
    #[cfg(not(feature = "mujoco"))]
    {
        let out = study(&["mujoco", "--quick"], dir.path());
        assert_eq!(out.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&out.stderr).contains("--features mujoco"));
    }
}
