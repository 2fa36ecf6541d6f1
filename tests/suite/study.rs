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

/// A quick study run once per test binary: its temporary output and the
/// study's folder in it.
type QuickStudy = OnceLock<(tempfile::TempDir, PathBuf)>;

/// `pushval study NAME --quick` into a temporary folder, run on first use
/// and shared by the tests that read it; returns `OUT/NAME/`.
fn quick_study(cell: &'static QuickStudy, name: &str) -> &'static Path {
    let (_, path) = cell.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        ok(study(&[name, "--quick"], dir.path()));
        let path = dir.path().join(name);
        (dir, path)
    });
    path
}

// Issue "More engines": the Box2D study (`pushval study box2d`).

/// One quick Box2D study (its folder `OUT/box2d/`), shared by the tests
/// that read it.
fn box2d_dir() -> &'static Path {
    static DIR: QuickStudy = OnceLock::new();
    quick_study(&DIR, "box2d")
}

/// The plate of a `geometry` column: the paper plate, or the same plate on
/// supports moved in to (±0.05, ±0.05) m.
fn box2d_body(geometry: &str) -> pushval_model::Body {
    let b = paper_plate();
    match geometry {
        "paper" => b,
        "inner" => {
            let supports: Vec<pushval_model::Support> = b
                .supports()
                .map(|s| pushval_model::Support {
                    position: s.position * (0.05 / 0.125),
                    friction: s.friction,
                })
                .collect();
            pushval_model::Body::new(b.mass(), b.inertia_cm(), b.contact(), &supports).unwrap()
        }
        g => panic!("unknown geometry {g}"),
    }
}

/// `box2d_motor_joint` against its closed form (`pushval_box2d::predict`,
/// recomputed here from each row's push): on the paper plate the torque cap
/// locks the plate (ω = 0 exactly; the engine's |ω| checked absolutely, to
/// 1e-2 of 1e-3 v_c/L), on the inner supports it turns (relative, 1e-2),
/// and either way it is not Coulomb.
#[test]
fn box2d_motor_joint_follows_its_closed_form() {
    use pushval_box2d::predict::motor_joint_steady;
    let length = 0.125 * 2f64.sqrt();
    let rows = read_csv(&box2d_dir().join("steady.csv"));
    let mut checked = [0, 0];
    for r in rows
        .iter()
        .filter(|r| r["model"] == "box2d_motor_joint" && val(r, "dt") == 1e-3)
    {
        let body = box2d_body(&r["geometry"]);
        let push = Push {
            duration: 6.0,
            speed: val(r, "speed"),
            phi: val(r, "phi"),
        };
        let closed = motor_joint_steady(&body, &push, 0.0).unwrap();
        let (w, star) = (val(r, "omega_engine"), val(r, "omega_star"));
        assert!((val(r, "omega_closed_form") - closed.omega).abs() <= 1e-12);
        if r["geometry"] == "paper" {
            assert!(closed.locked && closed.omega == 0.0);
            assert!(
                w.abs() <= 1e-2 * 1e-3 * push.speed / length,
                "v_c {}: locked plate turns at {w}",
                push.speed
            );
            checked[0] += 1;
        } else {
            assert!(!closed.locked);
            assert!(
                rel(w, closed.omega) <= 1e-2,
                "v_c {}: engine {w} vs closed form {}",
                push.speed,
                closed.omega
            );
            checked[1] += 1;
        }
        assert!(
            rel(w, star) > 0.2,
            "the motor joint is not Coulomb: {w} vs {star}"
        );
    }
    assert_eq!(checked, [3, 3]);
    // Every map cell, in the map's own measure (relative, absolute at ω = 0).
    let mut turning = 0;
    for geometry in ["paper", "inner"] {
        let map = read_csv(&box2d_dir().join(format!("map_box2d_motor_joint_{geometry}_1e-3.csv")));
        assert!(!map.is_empty());
        for c in &map {
            assert!(
                val(c, "err_vs_closed_form") <= 1e-2,
                "{geometry} Fr {} φ {}: {}",
                c["froude"],
                c["phi"],
                c["err_vs_closed_form"]
            );
            turning += usize::from(val(c, "locked") == 0.0);
        }
    }
    assert!(turning >= 1, "no map cell turns");
}

/// `box2d` is Coulomb support friction to first order in Δt: on the quick
/// ladder (4, 2, 1 ms) the steady-ω error against the dynamic model halves
/// with the step (observed order 1 ± 0.1), and the README's order range is
/// the data's.
#[test]
fn box2d_coulomb_is_first_order_and_the_readme_says_so() {
    let dir = box2d_dir();
    let ladder = read_csv(&dir.join("dt_ladder.csv"));
    let orders: Vec<f64> = ladder
        .iter()
        .filter(|r| !r["observed_order"].is_empty())
        .map(|r| val(r, "observed_order"))
        .collect();
    assert_eq!(orders.len(), 6, "two steps × three speeds");
    for p in &orders {
        assert!((p - 1.0).abs() <= 0.1, "order {p}");
    }
    for r in ladder.iter().filter(|r| val(r, "dt") == 1e-3) {
        assert!(val(r, "err_vs_model") <= 5e-3, "{}", r["err_vs_model"]);
    }
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let lo = orders.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = orders.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (a, b) = (format!("{lo:.2}"), format!("{hi:.2}"));
    let text = if a == b {
        format!("observed order {a} ")
    } else {
        format!("observed order {a}–{b} ")
    };
    assert!(readme.contains(&text), "README lacks '{text}'");
    // The paper-plate table: ω* and box2d's ω from paper_plate.csv.
    for r in read_csv(&dir.join("paper_plate.csv")) {
        let text = format!(
            "| {:.4} | {:.4} (",
            val(&r, "omega_star"),
            val(&r, "omega_box2d")
        );
        assert!(readme.contains(&text), "README lacks '{text}'");
    }
    for bad in ["NaN", " inf"] {
        assert!(!readme.contains(bad), "README holds '{bad}'");
    }
}

#[test]
fn box2d_shards_merged_equal_a_single_run_byte_for_byte() {
    let single = box2d_dir();
    let sharded = tempfile::tempdir().unwrap();
    for k in ["1/3", "2/3", "3/3"] {
        ok(study(&["box2d", "--quick", "--shard", k], sharded.path()));
    }
    assert!(
        !sharded.path().join("box2d").exists(),
        "a shard wrote outputs"
    );
    ok(study(&["box2d", "--quick", "--merge"], sharded.path()));
    let (a, b) = (files(single), files(&sharded.path().join("box2d")));
    assert_eq!(a.len(), b.len());
    assert!(a.len() >= 9, "{} files", a.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.file_name(), y.file_name());
        assert!(
            std::fs::read(x).unwrap() == std::fs::read(y).unwrap(),
            "{} differs between the single and the merged run",
            x.display()
        );
    }
}

// ---------------------------------------------------------------------------
// `pushval study coulomb_fits` (issue "The seed paper's future work", item 4):
// the Coulomb model fitted to each engine's trajectory. Known answers: the
// Coulomb engine (rapier2d, a Coulomb force at every support) must be
// explained by the file's own parameters (μ scale 1, the file's centre of
// friction (0, 0) and I_cm); impulse_box, which locks the plate's
// orientation, must not be explained once the schedule switches direction.
// ---------------------------------------------------------------------------

/// One quick Coulomb-fit study (rapier2d and rapier2d_impulse_box, both
/// schedules), shared by the tests that read it.
fn fits_dir() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        ok(study(&["coulomb_fits", "--quick"], dir.path()));
        dir
    })
    .path()
}

fn fit_row(engine: &str, schedule: &str) -> BTreeMap<String, String> {
    read_csv(&fits_dir().join("coulomb_fits.csv"))
        .into_iter()
        .find(|r| r["engine"] == engine && r["schedule"] == schedule)
        .unwrap_or_else(|| panic!("no fit of {engine} on {schedule}"))
}

/// The threshold of the verdict, recomputed from the engine's own error.
fn threshold(r: &BTreeMap<String, String>, what: &str) -> f64 {
    (10.0 * val(r, &format!("engine_error_{what}"))).max(1e-6)
}

#[test]
fn coulomb_fit_recovers_the_coulomb_engine_s_own_parameters() {
    let r = fit_row("rapier2d", "paper-square-v1.0");
    // The five segments identify every parameter, so all are fitted.
    assert_eq!(r["fitted"], "mu_scale+center_of_friction+inertia_cm");
    assert_eq!(r["unidentifiable"], "");
    assert_eq!(r["converged"], "true");
    // Truth: the file (μ scale 1, equal loads on a centred square: centre
    // of friction at the centre of mass, I_cm = m a²/6 for a 0.25 m plate).
    let sc = crate::common::load(&root().join("scenarios/paper-square-v1.0.toml"));
    assert!((val(&r, "inertia_cm_file") - sc.inertia_cm).abs() < 1e-15);
    assert!((sc.inertia_cm - 0.25f64.powi(2) / 6.0).abs() < 1e-12);
    let within = |v: f64, truth: f64, std: f64, what: &str| {
        assert!(std > 0.0 && std.is_finite(), "{what}: std {std}");
        assert!(
            (v - truth).abs() <= 2.0 * std,
            "{what}: {v} vs the file's {truth}, std {std}"
        );
    };
    within(
        val(&r, "mu_scale"),
        1.0,
        val(&r, "mu_scale_std"),
        "mu_scale",
    );
    within(val(&r, "cof_x"), 0.0, val(&r, "cof_x_std"), "cof_x");
    within(val(&r, "cof_y"), 0.0, val(&r, "cof_y_std"), "cof_y");
    within(
        val(&r, "inertia_cm"),
        sc.inertia_cm,
        val(&r, "inertia_cm_std"),
        "inertia_cm",
    );
    // And to an absolute standard: 1e-5 in μ, 10 µm, 1e-5 relative in I.
    assert!((val(&r, "mu_scale") - 1.0).abs() < 1e-5);
    assert!(val(&r, "cof_x").hypot(val(&r, "cof_y")) < 1e-5);
    assert!((val(&r, "inertia_cm") / sc.inertia_cm - 1.0).abs() < 1e-5);
    // The residual is below the threshold, and the threshold is tight.
    for what in ["position", "theta"] {
        let t = threshold(&r, what);
        assert!((t - val(&r, &format!("threshold_{what}"))).abs() <= 1e-12 * t);
        assert!(t < 1e-4, "threshold {what} {t}");
        let rms = val(&r, &format!("{what}_rms"));
        assert!(rms <= t, "rapier2d residual {what} {rms} above {t}");
    }
    assert_eq!(r["verdict"], "explained");
    // Before the fit (at the file's values) the residual is the engine's own
    // error: the Coulomb engine needs no fitting.
    assert!(val(&r, "start_position_rms") <= threshold(&r, "position"));
}

#[test]
fn coulomb_fit_does_not_explain_the_orientation_lock() {
    let r = fit_row("rapier2d_impulse_box", "paper-square-v1.0");
    let (p, t) = (val(&r, "position_rms"), val(&r, "theta_rms"));
    assert!(
        p > threshold(&r, "position") || t > threshold(&r, "theta"),
        "impulse_box explained: residual {p} m, {t} rad"
    );
    // Not a marginal miss: centimetres and tens of mrad off.
    assert!(p > 0.01 && t > 0.01, "residual {p} m, {t} rad");
    assert_eq!(r["verdict"], "not_explained");
    // On one push from ω = 0 a frictionless plate (μ → 0) keeps its
    // orientation exactly as the lock does: explained, by a degenerate μ.
    let one = fit_row("rapier2d_impulse_box", "friction-engines");
    assert_eq!(one["verdict"], "explained");
    assert!(val(&one, "mu_scale") < 1e-3);
}

#[test]
fn one_push_does_not_identify_the_centre_of_friction() {
    // The Fisher information of a single constant push at the file's values
    // leaves the centre of friction unidentifiable (only ω* and one
    // relaxation show), so the fit there holds it at the file's value.
    let r = fit_row("rapier2d", "friction-engines");
    assert_eq!(r["fitted"], "mu_scale+inertia_cm");
    assert_eq!(val(&r, "cof_x"), 0.0);
    assert_eq!(r["cof_x_std"], "");
    assert_eq!(r["verdict"], "explained");
    assert!((val(&r, "mu_scale") - 1.0).abs() <= 2.0 * val(&r, "mu_scale_std"));
}

#[test]
fn coulomb_fit_verdicts_and_readme_follow_the_data() {
    let rows = read_csv(&fits_dir().join("coulomb_fits.csv"));
    assert!(rows.len() >= 4);
    for r in &rows {
        let (p, t) = (val(r, "position_rms"), val(r, "theta_rms"));
        let (tp, tt) = (threshold(r, "position"), threshold(r, "theta"));
        let verdict = if p > tp || t > tt {
            "not_explained"
        } else if p <= 1e-3 && t <= 1e-3 {
            "explained"
        } else {
            "undecided"
        };
        assert_eq!(
            r["verdict"], verdict,
            "{} on {}",
            r["engine"], r["schedule"]
        );
        let mu = val(r, "mu_file") * val(r, "mu_scale");
        assert!((val(r, "mu_effective") - mu).abs() <= 1e-12 * mu.abs().max(1e-300));
    }
    let md = pushval::study::fits::readme_section(fits_dir());
    let r = fit_row("rapier2d", "paper-square-v1.0");
    let mu = format!("{:.8}", val(&r, "mu_scale"));
    assert!(
        md.contains(&format!("μ scale {mu}")),
        "README lacks μ scale {mu}"
    );
    let box_row = fit_row("rapier2d_impulse_box", "paper-square-v1.0");
    let text = format!(
        "rapier2d_impulse_box ({:.3} m, {:.3} rad)",
        val(&box_row, "position_rms"),
        val(&box_row, "theta_rms")
    );
    assert!(md.contains(&text), "README lacks '{text}'");
    assert!(!md.contains("NaN"), "README section holds NaN");
    assert!(
        !md.split(|c: char| !c.is_alphanumeric()).any(|w| w == "inf"),
        "README section holds inf"
    );
}

#[test]
fn coulomb_fit_shards_merge_into_the_single_run() {
    let sharded = tempfile::tempdir().unwrap();
    for k in ["1/3", "2/3", "3/3"] {
        ok(study(
            &["coulomb_fits", "--quick", "--shard", k],
            sharded.path(),
        ));
    }
    ok(study(
        &["coulomb_fits", "--quick", "--merge"],
        sharded.path(),
    ));
    let name = "coulomb_fits.csv";
    assert!(
        std::fs::read(fits_dir().join(name)).unwrap()
            == std::fs::read(sharded.path().join(name)).unwrap(),
        "{name} differs between the single and the merged run"
    );
}

// ---------------------------------------------------------------------------
// `pushval study avian` (needs the root feature `avian`). Known answers, each
// recomputed here from a closed form, not read from the study's summary:
// avian2d applies Coulomb's law, so its steady ω is the Coulomb root ω* up to
// a first-order step error; avian3d's friction is Coulomb along −u per
// contact point with the loads of a rigid plate on soft contacts
// (`pushval_avian::predict::PlateScene::steady`), which is ω* itself when the
// centre of mass is on the floor's plane and moves off it when raised.
// ---------------------------------------------------------------------------

/// One quick Avian study (its folder `OUT/avian/`), shared by the tests
/// that read it.
#[cfg(feature = "avian")]
fn avian_dir() -> &'static Path {
    static DIR: QuickStudy = OnceLock::new();
    quick_study(&DIR, "avian")
}

/// avian3d against `PlateScene::steady`, recomputed from each row's push and
/// centre-of-mass height: within 1e-2 (relative) in the load-transfer table
/// and in every cell of both avian3d maps; at h_cm = 0 the closed form is ω*,
/// raised it is more than 1 % off ω* (load transfer matters).
#[cfg(feature = "avian")]
#[test]
fn avian3d_follows_its_closed_form() {
    use pushval_avian::predict::PlateScene;
    use pushval_avian::Avian3dSettings;
    let predicted = |speed: f64, phi: f64, cm_height: f64| {
        let p = crate::common::one_push(paper_plate(), 1.0, speed, phi);
        let s = Avian3dSettings {
            cm_height,
            ..Default::default()
        };
        PlateScene::new(&p, &s)
            .unwrap()
            .steady(&p.pushes[0], 0.0)
            .unwrap()
            .0
    };
    let star = |speed: f64, phi: f64| {
        let push = Push {
            duration: 1.0,
            speed,
            phi,
        };
        SegmentDynamics::new(&paper_plate(), &push)
            .attractor_from(0.0)
            .unwrap()
            .omega
    };
    let dir = avian_dir();
    let loads = read_csv(&dir.join("load_transfer.csv"));
    assert_eq!(loads.len(), 3);
    for r in &loads {
        let (v, phi, h) = (val(r, "speed"), val(r, "phi"), val(r, "cm_height"));
        let pred = predicted(v, phi, h);
        assert!((val(r, "omega_predicted") - pred).abs() <= 1e-12);
        assert!((val(r, "omega_star") - star(v, phi)).abs() <= 1e-12);
        let w = val(r, "omega_engine");
        assert!(rel(w, pred) <= 1e-2, "h {h} v {v}: engine {w} vs {pred}");
        assert!(
            rel(pred, star(v, phi)) > 1e-2,
            "h {h} v {v}: no load transfer"
        );
    }
    for (name, h) in [("map_avian3d_h0.csv", 0.0), ("map_avian3d_h0.02.csv", 0.02)] {
        let map = read_csv(&dir.join(name));
        assert_eq!(map.len(), 6, "{name}");
        for c in &map {
            let (v, phi) = (val(c, "speed"), val(c, "phi"));
            let pred = predicted(v, phi, h);
            if h == 0.0 {
                assert!(rel(pred, star(v, phi)) <= 1e-12);
            }
            let w = val(c, "omega_engine");
            assert!(rel(w, pred) <= 1e-2, "{name} v {v} φ {phi}: {w} vs {pred}");
        }
    }
}

/// avian2d is Coulomb to first order in Δt: on the quick ladder (2, 1 ms)
/// the steady-ω error against ω* halves with the step (order 1 ± 0.25), is
/// within 5e-4 of ω* at 1 ms on the paper plate, and the README's table and
/// order range are the data's.
#[cfg(feature = "avian")]
#[test]
fn avian2d_is_first_order_coulomb_and_the_readme_says_so() {
    let dir = avian_dir();
    let ladder = read_csv(&dir.join("dt_ladder.csv"));
    let orders = |model: &str| -> Vec<f64> {
        ladder
            .iter()
            .filter(|r| r["model"] == model && !r["observed_order"].is_empty())
            .map(|r| val(r, "observed_order"))
            .collect()
    };
    let o2 = orders("avian2d");
    assert_eq!(o2.len(), 3, "one order per speed");
    for p in &o2 {
        assert!((p - 1.0).abs() <= 0.25, "order {p}");
    }
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let lo = o2.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = o2.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (a, b) = (format!("{lo:.2}"), format!("{hi:.2}"));
    let text = if a == b {
        format!("avian2d {a}, avian3d")
    } else {
        format!("avian2d {a}–{b}, avian3d")
    };
    assert!(readme.contains(&text), "README lacks '{text}'");
    for r in read_csv(&dir.join("paper_plate.csv")) {
        let push = Push {
            duration: 1.0,
            speed: val(&r, "speed"),
            phi: val(&r, "phi"),
        };
        let star = SegmentDynamics::new(&paper_plate(), &push)
            .attractor_from(0.0)
            .unwrap()
            .omega;
        assert!((val(&r, "omega_star") - star).abs() <= 1e-12);
        assert!(rel(val(&r, "omega_avian2d"), star) <= 5e-4);
        let text = format!("| {:.8} | {:.8} (", star, val(&r, "omega_avian2d"));
        assert!(readme.contains(&text), "README lacks '{text}'");
    }
    for bad in ["NaN", " inf"] {
        assert!(!readme.contains(bad), "README holds '{bad}'");
    }
}

#[cfg(feature = "avian")]
#[test]
fn avian_shards_merged_equal_a_single_run_byte_for_byte() {
    shards_merge_into_the_single_run("avian", avian_dir());
}

/// Without the feature, `study avian` exits 2 naming it.
#[cfg(not(feature = "avian"))]
#[test]
fn avian_study_without_the_feature_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = study(&["avian", "--quick"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--features avian"));
}

// ---------------------------------------------------------------------------
// `pushval study physx` (needs the root feature `physx`). Expected values come
// from the closed forms of `pushval_physx::predict`, recomputed here from each
// row's push and PhysX's rest loads (the feet's friction μ̄ N_i), never from
// the study's own columns alone.
// ---------------------------------------------------------------------------

/// One quick PhysX study (its folder `OUT/physx/`), shared by the tests
/// that read it.
#[cfg(feature = "physx")]
fn physx_dir() -> &'static Path {
    static DIR: QuickStudy = OnceLock::new();
    quick_study(&DIR, "physx")
}

/// The paper-plate table against the closed forms: the class of ω = 0 and
/// M₀, H, S from `predict` with the row's loads; locked runs hold the plate
/// (|ω| ≤ 1e-2 |ω*|), runs that turn are within 1e-2 of the law's root,
/// semi-stable runs are at 0 or escaped to the side of M₀; and the welded
/// one-directional model, which Filippov's criterion says turns, is
/// semi-stable on the paper plate and held there.
#[cfg(feature = "physx")]
#[test]
fn physx_paper_plate_follows_its_closed_forms() {
    use pushval_model::{Body, Support};
    use pushval_physx::predict::{at_rest, lock_moments, rest_moments, steady_omega, AtRest};
    use pushval_physx::{FootContacts, FrictionType};
    let rows = read_csv(&physx_dir().join("paper_plate.csv"));
    assert_eq!(
        rows.len(),
        18,
        "6 combinations × 3 speeds on the quick ladder"
    );
    let plate = paper_plate();
    let corners: Vec<[f64; 2]> = plate
        .supports()
        .map(|s| [s.position.x, s.position.y])
        .collect();
    let mut semi_held = 0;
    for r in &rows {
        let friction = FrictionType::ALL
            .into_iter()
            .find(|f| f.as_str() == r["friction"])
            .unwrap();
        let contacts = FootContacts::ALL
            .into_iter()
            .find(|c| c.as_str() == r["contacts"])
            .unwrap();
        let mu = val(r, "mu");
        let feet: Vec<Support> = plate
            .supports()
            .enumerate()
            .map(|(i, s)| Support {
                friction: mu * val(r, &format!("rest_load_{i}")),
                ..s
            })
            .collect();
        let body = Body::new(1.0, plate.inertia_cm(), plate.contact(), &feet).unwrap();
        let push = Push {
            duration: 1.0,
            speed: val(r, "speed"),
            phi: val(r, "phi"),
        };
        let law = friction.law(contacts, &[0, 1, 2, 3], &corners);
        let (m0, h) = lock_moments(&body, &push, law);
        let (_, s) = rest_moments(&body, &push, law);
        for (k, want) in [("M0", m0), ("H", h), ("S", s)] {
            assert!(
                (val(r, k) - want).abs() < 1e-9,
                "{k}: {} vs {want}",
                val(r, k)
            );
        }
        let (w, star) = (val(r, "omega_engine"), val(r, "omega_star"));
        let root = steady_omega(&body, &push, law, 0.0).omega;
        let class = at_rest(&body, &push, law);
        match class {
            AtRest::Locked => assert!(w.abs() <= 1e-2 * star.abs(), "{r:?}"),
            AtRest::Turns => assert!(rel(w, root) <= 1e-2, "{w} vs {root}"),
            AtRest::SemiStable => {
                let held = w.abs() <= 1e-2 * star.abs();
                // Held, or escaped to the side of M₀, where G(0±) points.
                assert!(
                    held || (w * m0 > 0.0 && root * m0 > 0.0),
                    "{w} vs 0 or {root}"
                );
                semi_held += held as usize;
            }
        }
        let name = match class {
            AtRest::Locked => "locked",
            AtRest::SemiStable => "semi-stable",
            AtRest::Turns => "turns",
        };
        assert_eq!(r["at_rest"], name);
        if friction == FrictionType::OneDirectional && contacts == FootContacts::Welded {
            assert_eq!(class, AtRest::SemiStable, "paper plate: H < |M₀| ≤ S");
            assert!(m0.abs() > h && m0.abs() <= s);
        }
    }
    assert_eq!(semi_held, 3, "PhysX holds the semi-stable paper plate");
    let readme = std::fs::read_to_string(physx_dir().join("README.md")).unwrap();
    for bad in ["NaN", " inf"] {
        assert!(!readme.contains(bad), "README holds '{bad}'");
    }
    assert!(readme.contains("| physx_one_directional (welded) | 0.2 |"));
}

#[cfg(feature = "physx")]
#[test]
fn physx_shards_merged_equal_a_single_run_byte_for_byte() {
    shards_merge_into_the_single_run("physx", physx_dir());
}

/// Without the feature, `study physx` exits 2 naming it.
#[cfg(not(feature = "physx"))]
#[test]
fn physx_study_without_the_feature_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = study(&["physx", "--quick"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--features physx"));
}

/// `study NAME --quick` in two shards and a merge writes exactly the files
/// of the single run in `single` (and the shards write no outputs).
#[cfg(any(feature = "avian", feature = "physx"))]
fn shards_merge_into_the_single_run(name: &str, single: &Path) {
    let sharded = tempfile::tempdir().unwrap();
    for k in ["1/2", "2/2"] {
        ok(study(&[name, "--quick", "--shard", k], sharded.path()));
    }
    assert!(!sharded.path().join(name).exists(), "a shard wrote outputs");
    ok(study(&[name, "--quick", "--merge"], sharded.path()));
    let (a, b) = (files(single), files(&sharded.path().join(name)));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.file_name(), y.file_name());
        assert!(
            std::fs::read(x).unwrap() == std::fs::read(y).unwrap(),
            "{} differs between the single and the merged run",
            x.display()
        );
    }
}
