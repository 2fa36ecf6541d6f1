//! `pushval study MODEL|all` (issue 24, "One study for every engine"): the
//! quick study of every model of this build writes the contract's files,
//! each engine follows its own law in closed form and not Coulomb where
//! the law differs, READMEs state the files' numbers, and hash shards merge
//! into the single run's bytes.
//!
//! Expected values are recomputed here from the engine crates' closed forms
//! and the analytic model (not read from the study's `omega_law` or
//! `omega_coulomb` columns); tolerances are a few times the spread measured
//! on the quick grid (stated at each assertion).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use pushval_engine::rel_err;
use pushval_model::{Problem, SegmentDynamics};

use crate::common::root;

mod sweeps;

fn study(args: &[&str], out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pushval"))
        .current_dir(root())
        .arg("study")
        .args(args)
        .arg("--out")
        .arg(out)
        .env("CI", "1")
        .env_remove("SLURM_ARRAY_TASK_ID")
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

/// One quick `study all`, shared by the tests that read it.
fn quick_dir() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        ok(study(&["all", "--quick"], dir.path()));
        dir
    })
    .path()
}

type Rows = Vec<BTreeMap<String, String>>;

fn read_csv(path: &Path) -> Rows {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|l| {
            header
                .iter()
                .map(|h| h.to_string())
                .zip(l.split(',').map(String::from))
                .collect()
        })
        .collect()
}

fn val(row: &BTreeMap<String, String>, key: &str) -> f64 {
    row[key].parse().unwrap_or(f64::NAN)
}

/// L = |p_c| of the paper plate (m), the Froude number's length.
fn length() -> f64 {
    0.125 * 2f64.sqrt()
}

fn speed_of(fr: f64) -> f64 {
    (fr * 0.5 * 9.81 * length()).sqrt()
}

/// The study's scene: the paper plate (supports moved to `half` if set),
/// one push of `t` s.
fn problem(speed: f64, phi: f64, t: f64, half: Option<f64>) -> Problem {
    pushval::study::plate::paper_plate(speed, phi, t, half)
}

/// The Coulomb model's steady ω from ω = 0, computed here.
fn coulomb(p: &Problem) -> f64 {
    let seg = SegmentDynamics::new(&p.body, &p.pushes[0]);
    seg.attractor(&seg.steady_states(), 0.0).unwrap().omega
}

fn map(model: &str) -> Rows {
    read_csv(&quick_dir().join(model).join("map.csv"))
}

fn available(model: &str) -> bool {
    pushval::registry::engine(model, &Default::default())
        .availability()
        .is_ok()
}

#[test]
fn every_model_of_the_build_writes_the_contract_files() {
    for m in pushval::study::models() {
        let dir = quick_dir().join(&m);
        if !available(&m) {
            assert!(!dir.exists(), "{m} is not in this build but has a folder");
            continue;
        }
        let paper = std::fs::read_to_string(dir.join("paper_plate.csv")).unwrap();
        assert!(
            paper.starts_with("speed,omega_engine,omega_coulomb,omega_law,omega_law_run,"),
            "{m}"
        );
        let speeds: Vec<f64> = read_csv(&dir.join("paper_plate.csv"))
            .iter()
            .map(|r| val(r, "speed"))
            .collect();
        assert_eq!(speeds, [0.2, 0.5, 1.0], "{m}");
        let text = std::fs::read_to_string(dir.join("map.csv")).unwrap();
        assert!(text.starts_with(
            "froude,phi,omega_engine,omega_coulomb,omega_law,class,omega_law_run,law_run_rms,max_rise_m,contact_lost_share,"
        ));
        let rows = map(&m);
        assert_eq!(rows.len(), 25, "{m}: a 5 × 5 quick map");
        let has_law = pushval::registry::engine(&m, &Default::default())
            .law()
            .is_some();
        for r in &rows {
            assert!(val(r, "omega_engine").is_finite(), "{m}: {r:?}");
            assert_eq!(val(r, "omega_law").is_finite(), has_law, "{m}: {r:?}");
            assert!(["turns", "locked", "semi_stable"].contains(&r["class"].as_str()) || !has_law);
            // The Coulomb column is the analytic model's steady ω.
            let p = problem(speed_of(val(r, "froude")), val(r, "phi"), 6.0, None);
            assert!((val(r, "omega_coulomb") - coulomb(&p)).abs() < 1e-12);
        }
        assert!(dir.join("README.md").exists() && dir.join("dt_ladder.csv").exists());
    }
}

#[test]
fn rapier2d_is_coulomb_to_round_off_on_the_map() {
    // Measured on the quick grid: at most 4.2e-7 (second order at 1 ms).
    for r in map("rapier2d") {
        let v = speed_of(val(&r, "froude"));
        let w = val(&r, "omega_engine");
        let p = problem(v, val(&r, "phi"), 6.0, None);
        assert!(rel_err(w, coulomb(&p), v, length()) < 1e-6, "{r:?}");
    }
}

#[test]
fn impulse_disk_follows_its_closed_form_not_coulomb() {
    use pushval_rapier2d::idioms::predicted_steady_omega;
    use pushval_rapier2d::FrictionModel;
    // Measured: engine within 7.9e-7 of the closed form; 8.5e-2 to 0.55
    // off Coulomb.
    for r in map("rapier2d_impulse_disk") {
        let v = speed_of(val(&r, "froude"));
        let p = problem(v, val(&r, "phi"), 6.0, None);
        let pred = predicted_steady_omega(
            FrictionModel::ImpulseDisk,
            &p.body,
            &p.pushes[0],
            1e-3,
            0.0,
            0.0,
        )
        .unwrap();
        let w = val(&r, "omega_engine");
        assert!(rel_err(w, pred, v, length()) < 2e-6, "{r:?} vs {pred}");
        assert!(rel_err(w, coulomb(&p), v, length()) > 5e-2, "{r:?}");
    }
}

#[test]
fn rapier3d_follows_the_effective_mass_law_not_coulomb() {
    use pushval_rapier3d::predict::{predict_steady, Law};
    use pushval_rapier3d::Rapier3dSettings;
    // Measured: within 1.9e-3 of the closed form, 8e-2 to 0.52 off Coulomb.
    for r in map("rapier3d") {
        let v = speed_of(val(&r, "froude"));
        let p = problem(v, val(&r, "phi"), 6.0, None);
        let scene = Rapier3dSettings::default().scene(&p).unwrap();
        let pred = predict_steady(&scene, &p.pushes[0], Law::EffectiveMassDisk, true)
            .unwrap()
            .omega;
        let w = val(&r, "omega_engine");
        assert!(rel_err(w, pred, v, length()) < 4e-3, "{r:?} vs {pred}");
        assert!(rel_err(w, coulomb(&p), v, length()) > 5e-2, "{r:?}");
    }
    // Simplified on one manifold: the twist limit holds the plate still.
    for r in map("rapier3d_simplified") {
        assert!(val(&r, "omega_engine").abs() < 1e-12, "{r:?}");
        assert_eq!(r["class"], "locked");
    }
}

#[test]
fn box2d_motor_joint_locks_the_paper_plate_and_turns_on_inner_supports() {
    use pushval_box2d::predict::{motor_joint_locks, motor_joint_steady};
    // Measured: |ω| at most 9.3e-4 |ω*| on the paper plate's map.
    for r in map("box2d_motor_joint") {
        let v = speed_of(val(&r, "froude"));
        let p = problem(v, val(&r, "phi"), 6.0, None);
        assert!(motor_joint_locks(&p.body, &p.pushes[0]));
        assert!(
            val(&r, "omega_engine").abs() < 2e-3 * coulomb(&p).abs(),
            "{r:?}"
        );
    }
    // Inner supports: measured within 2.4e-4 to 5.6e-4 of the closed form.
    let dir = quick_dir().join("box2d_motor_joint");
    let inner: Rows = read_csv(&dir.join("variants.csv"))
        .into_iter()
        .filter(|r| r["variant"] == "inner")
        .collect();
    assert_eq!(inner.len(), 3);
    for r in inner {
        let v = val(&r, "speed");
        let p = problem(v, val(&r, "phi"), 6.0, Some(0.05));
        let s = motor_joint_steady(&p.body, &p.pushes[0], 0.0).unwrap();
        assert!(!s.locked);
        let w = val(&r, "omega_engine");
        assert!(
            rel_err(w, s.omega, v, length()) < 1.5e-3,
            "{r:?} vs {}",
            s.omega
        );
        assert!(rel_err(w, coulomb(&p), v, length()) > 0.15, "{r:?}");
    }
}

#[test]
fn box2d_is_first_order_by_its_own_ladder() {
    // The order from the engine's ω column (not the file's order column):
    // measured 1.004 on the quick ladder 4, 2, 1 ms.
    let rows = read_csv(&quick_dir().join("box2d/dt_ladder.csv"));
    let w: Vec<f64> = rows.iter().map(|r| val(r, "omega_engine")).collect();
    let order = ((w[1] - w[0]) / (w[2] - w[1])).abs().log2();
    assert!((order - 1.0).abs() < 0.05, "observed order {order}");
    assert!((val(&rows[2], "observed_order") - order).abs() < 1e-12);
}

#[test]
fn readme_numbers_are_the_data() {
    for m in ["rapier2d_impulse_disk", "box2d_motor_joint", "rapier3d"] {
        let dir = quick_dir().join(m);
        let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
        for r in read_csv(&dir.join("paper_plate.csv")) {
            let cell = format!("{:.4e}", val(&r, "omega_engine"));
            assert!(readme.contains(&cell), "{m}: README lacks {cell}");
        }
        let rows = map(m);
        let n = rows.len();
        let locked = rows.iter().filter(|r| r["class"] == "locked").count();
        assert!(readme.contains(&format!("{n} cells")));
        assert!(readme.contains(&format!("locked {locked}")), "{m}");
    }
    let index = std::fs::read_to_string(quick_dir().join("README.md")).unwrap();
    let r = read_csv(&quick_dir().join("rapier3d/paper_plate.csv"));
    assert!(index.contains(&format!("{:.4e}", val(&r[1], "omega_engine"))));
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            if p.file_name().unwrap() != "parts" {
                out.extend(files(&p));
            }
        } else {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// Hash shards merged give the single run's files byte for byte, for a 2-D
/// engine, a 3-D engine with loads and an outside engine in a session (the
/// single run is the shared quick `all`; sharding every model again would
/// double the suite's longest step for no new kind of task).
#[test]
fn hash_shards_merged_equal_a_single_run_byte_for_byte() {
    let single = quick_dir();
    for model in ["box2d_motor_joint", "rapier3d", "pure_python"] {
        if !single.join(model).exists() {
            continue;
        }
        let sharded = tempfile::tempdir().unwrap();
        for k in ["hash:1/2", "hash:2/2"] {
            ok(study(&[model, "--quick", "--shard", k], sharded.path()));
        }
        ok(study(&[model, "--quick", "--merge"], sharded.path()));
        let a = files(&single.join(model));
        let b = files(sharded.path());
        let rel = |v: &[PathBuf], base: &Path| -> Vec<PathBuf> {
            v.iter()
                .map(|p| p.strip_prefix(base).unwrap().to_path_buf())
                .collect()
        };
        assert_eq!(
            rel(&a, &single.join(model)),
            rel(&b, sharded.path()),
            "{model}"
        );
        for (x, y) in a.iter().zip(&b) {
            assert!(
                std::fs::read(x).unwrap() == std::fs::read(y).unwrap(),
                "{model}: {} differs",
                x.display()
            );
        }
    }
}

#[test]
fn merge_names_missing_shards_and_slurm_picks_its_part() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_pushval"))
        .current_dir(root())
        .args(["study", "box2d_motor_joint", "--quick", "--out"])
        .arg(dir.path())
        .env("CI", "1")
        .env("SLURM_ARRAY_TASK_ID", "3")
        .env("SLURM_ARRAY_TASK_MIN", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "3")
        .output()
        .unwrap();
    ok(out);
    assert!(dir
        .path()
        .join("parts/box2d_motor_joint-3-of-3.csv")
        .exists());
    let out = study(&["box2d_motor_joint", "--quick", "--merge"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("hash:1/3") && err.contains("hash:2/3"),
        "{err}"
    );
}

#[test]
fn bad_names_and_study_files_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = study(&["no_such_engine", "--quick"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("rapier2d"));
    if !available("physx_patch") {
        let out = study(&["physx_patch", "--quick"], dir.path());
        assert_eq!(out.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&out.stderr).contains("--features physx"));
    }
    let studies = tempfile::tempdir().unwrap();
    std::fs::write(studies.path().join("box2d.toml"), "t_run = -1.0\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_pushval"))
        .current_dir(root())
        .args(["study", "box2d", "--quick", "--studies"])
        .arg(studies.path())
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("box2d.toml") && err.contains("t_run"), "{err}");
    assert!(!dir.path().join("README.md").exists(), "nothing written");
    // A --studies folder that is not there is refused, not replaced by the
    // shipped study files.
    let missing = studies.path().join("missing");
    let out = Command::new(env!("CARGO_BIN_EXE_pushval"))
        .current_dir(root())
        .args(["study", "box2d", "--quick", "--studies"])
        .arg(&missing)
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--studies") && err.contains("missing"),
        "{err}"
    );
    assert!(!dir.path().join("README.md").exists(), "nothing written");
}

/// The `rect` elements of an SVG as (x, fill, stroke), after checking the
/// text is well-formed XML whose root is `svg`; and the root's width (px).
fn svg_rects(text: &str) -> (f64, Vec<(f64, String, String)>) {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(text);
    let (mut width, mut rects, mut root) = (f64::NAN, Vec::new(), None);
    loop {
        match reader.read_event().expect("map.svg is well-formed XML") {
            Event::Start(e) | Event::Empty(e) => {
                let name = String::from_utf8_lossy(e.name().as_ref()).to_string();
                let attr = |k: &str| {
                    e.attributes()
                        .flatten()
                        .find(|a| a.key.as_ref() == k.as_bytes())
                        .map(|a| String::from_utf8_lossy(&a.value).to_string())
                        .unwrap_or_default()
                };
                if root.is_none() {
                    width = attr("width").parse().unwrap_or(f64::NAN);
                    root = Some(name.clone());
                }
                if name == "rect" {
                    rects.push((attr("x").parse().unwrap(), attr("fill"), attr("stroke")));
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    assert_eq!(root.as_deref(), Some("svg"), "the root element is svg");
    (width, rects)
}

#[test]
fn map_svg_has_one_cell_per_map_row() {
    // map.svg: the Coulomb panel (left half of the plot area, the key is the
    // right-most 230 px) fills one cell per map.csv row; the law panel one
    // per row with an omega_law; locked or semi-stable cells are outlined.
    for m in ["rapier2d", "rapier2d_impulse_box", "box2d_motor_joint"] {
        if !available(m) {
            continue;
        }
        let dir = quick_dir().join(m);
        let rows = map(m);
        let text = std::fs::read_to_string(dir.join("map.svg")).unwrap();
        let (width, rects) = svg_rects(&text);
        let main = width - 230.0;
        let filled = |lo: f64, hi: f64| {
            rects
                .iter()
                .filter(|(x, fill, stroke)| {
                    *x >= lo && *x < hi && stroke == "none" && fill != "#FFFFFF"
                })
                .count()
        };
        let law = rows
            .iter()
            .filter(|r| val(r, "omega_law").is_finite())
            .count();
        assert_eq!(filled(0.0, main / 2.0), rows.len(), "{m}: Coulomb panel");
        assert_eq!(filled(main / 2.0, main), law, "{m}: law panel");
        let marked = rows
            .iter()
            .filter(|r| r["class"] != "turns" && !r["class"].is_empty())
            .count();
        let outlines = rects
            .iter()
            .filter(|(x, fill, _)| *x < main && fill == "none")
            .count();
        // Two panels, plus each panel's plot-area frame at most.
        assert!(
            (2 * marked..=2 * marked + 2).contains(&outlines),
            "{m}: {outlines} outlines for {marked} locked or semi-stable cells"
        );
        let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
        assert!(
            readme.contains("[`map.svg`](map.svg)"),
            "{m}: README links map.svg"
        );
    }
}

/// `results/friction_models/mujoco/creep_law.md` is generated from
/// `creep_law.csv` beside it (`examples/creep_law.rs`): regenerating it from
/// the committed CSV gives the committed text, so every number in it comes
/// from the CSV.
#[test]
fn creep_law_section_comes_from_its_csv() {
    let dir = root().join("results/friction_models/mujoco");
    let csv = std::fs::read_to_string(dir.join("creep_law.csv")).unwrap();
    let md = std::fs::read_to_string(dir.join("creep_law.md")).unwrap();
    assert_eq!(pushval::report::creep_law::markdown(&csv).unwrap(), md);
}

/// Engines whose declared law misses most of their turning cells on the
/// quick map, and why; each study file's `about` says so in these words.
const LAW_MISSES: &[(&str, &str)] = &[
    ("mujoco_elliptic", "hops"),
    ("mujoco4_elliptic", "hops"),
    ("drake_sap", "hops"),
    ("drake_similar", "hops"),
];

/// Every declared law holds its engine: within 1e-2 in most of the cells
/// where the law turns the plate, with the problem's loads or with the
/// run's own; an engine that measures loads fills `omega_law_run`. Misses
/// are listed in [`LAW_MISSES`] with the word their study file explains
/// them with.
#[test]
fn declared_laws_hold_their_engines_on_the_quick_map() {
    for m in pushval::study::models() {
        if !available(&m) {
            continue;
        }
        let engine = pushval::registry::engine(&m, &Default::default());
        if engine.law().is_none() {
            continue;
        }
        let rows = map(&m);
        let paper = read_csv(&quick_dir().join(&m).join("paper_plate.csv"));
        let measures_loads = paper.iter().any(|r| val(r, "max_rise_m").is_finite());
        if measures_loads {
            assert!(
                rows.iter().any(|r| val(r, "omega_law_run").is_finite()),
                "{m} measures loads but no cell has omega_law_run"
            );
        }
        let turning: Vec<_> = rows.iter().filter(|r| r["class"] == "turns").collect();
        if turning.is_empty() {
            continue;
        }
        let within = turning
            .iter()
            .filter(|r| {
                let (we, wc) = (val(r, "omega_engine"), val(r, "omega_coulomb"));
                let speed = speed_of(val(r, "froude"));
                ["omega_law", "omega_law_run"].iter().any(|k| {
                    let wl = val(r, k);
                    wl.is_finite() && pushval::study::err(we, wl, wc, speed) <= 1e-2
                })
            })
            .count();
        let holds = 2 * within > turning.len();
        let listed = LAW_MISSES.iter().find(|(n, _)| *n == m);
        match listed {
            None => assert!(
                holds,
                "{m}: {within}/{} turning cells within 1e-2 of its law",
                turning.len()
            ),
            Some((_, word)) => {
                // Hopping engines scatter about their law from cell to cell:
                // a listed engine may hold on the quick grid; its study file
                // must still say why it misses on the full one.
                let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join(format!("studies/{m}.toml"));
                let text = std::fs::read_to_string(&file).unwrap_or_default();
                assert!(
                    text.contains(word),
                    "{}: its about must say why the law misses ({word})",
                    file.display()
                );
            }
        }
    }
}

/// A plate turning at ω(θ) = c (1 + a sin 4θ) (a law of period π/2 in the
/// angle) has the period mean c √(1 − a²) (∫₀^{2π} dx / (1 + a sin x) =
/// 2π / √(1 − a²)); the whole-period tail gives it from 0.01 s samples,
/// where the plain tail mean, cut mid-period, does not.
#[test]
fn whole_period_tails_give_the_period_mean() {
    use pushval_model::{Sample, Trajectory};
    let (c, a) = (1.0, 0.3);
    let w = |th: f64| c * (1.0 + a * (4.0 * th).sin());
    // RK4 at 1e-4 s, sampled every 0.01 s over 10 s.
    let (mut th, h) = (0.0f64, 1e-4);
    let mut samples = vec![];
    for k in 0..=100_000 {
        if k % 100 == 0 {
            let t = k as f64 * h;
            samples.push(Sample {
                t,
                x: 0.0,
                y: 0.0,
                theta: th,
                omega: w(th),
            });
        }
        let k1 = w(th);
        let k2 = w(th + 0.5 * h * k1);
        let k3 = w(th + 0.5 * h * k2);
        let k4 = w(th + h * k3);
        th += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    let traj = Trajectory {
        samples,
        ..Default::default()
    };
    let p = problem(0.5, 1.0, 10.0, None);
    let exact = c * (1.0 - a * a).sqrt();
    let whole =
        pushval::harness::law::whole_period_omega(&p, &traj, 0.75, std::f64::consts::FRAC_PI_2)
            .unwrap();
    assert!((whole - exact).abs() < 1e-4 * exact, "{whole} vs {exact}");
    let plain = pushval_engine::tail_mean_omega(&p, &traj, 0.75)[0].unwrap();
    assert!(
        (plain - exact).abs() > 10.0 * (whole - exact).abs(),
        "plain {plain}, whole {whole}, exact {exact}"
    );
    // Less than one period in the tail: no whole-period mean.
    assert!(pushval::harness::law::whole_period_omega(&p, &traj, 0.05, 2.0).is_none());
}

/// The law on a run's loads, integrated in time: fed the analytic model's
/// own trajectory (Coulomb, from rest, the transient included) and the loads
/// it was computed with, Coulomb reproduces it sample by sample; with the
/// supports' loads doubled it reproduces the model run on doubled friction
/// and misses the first one. A law with steady states only, taken
/// quasi-statically, misses the transient.
#[test]
fn the_law_integrated_on_a_runs_loads_follows_its_transient() {
    use pushval_engine::{ContactRecord, EngineRun, FrictionLaw, LawSteady, COULOMB};
    struct SteadyOnly;
    impl FrictionLaw for SteadyOnly {
        fn law_name(&self) -> &'static str {
            "Coulomb's steady states, no dynamics (test)"
        }
        fn steady(&self, p: &Problem, seg: usize, dt: f64) -> Option<LawSteady> {
            COULOMB.steady(p, seg, dt)
        }
    }
    let p = problem(0.5, 1.0, 1.5, None);
    let body = &p.body;
    let rest = pushval_laws::mujoco::rest_loads(body, body.mass() * 9.81).unwrap();
    let model = crate::common::adaptive(1e-11, false);
    let judge = |law: &dyn FrictionLaw, traj: &pushval_model::Trajectory, scale: f64| {
        let loads: Vec<Vec<f64>> = traj
            .samples
            .iter()
            .map(|_| rest.iter().map(|l| scale * l).collect())
            .collect();
        let contact = ContactRecord {
            loads,
            max_rise_m: 0.0,
            contact_lost_share: 0.0,
            load_range: [0.0, 0.0],
        };
        let run = EngineRun {
            trajectory: traj.clone(),
            dt: 1e-3,
            steps: 0,
            wall_time: Default::default(),
            diagnostics: serde_json::json!({}),
            contact: Some(contact.clone()),
        };
        pushval::harness::law::law_on_run_loads(law, &p, 0, 1e-3, 1.0, &run, &contact)
    };
    let traj = crate::common::run(&model, &p);
    let w_star = coulomb(&p).abs();
    let mean = traj.samples.iter().map(|s| s.omega).sum::<f64>() / traj.samples.len() as f64;
    let (law_mean, rms) = judge(&COULOMB, &traj, 1.0);
    assert!(rms < 1e-6 * w_star, "rms {rms}");
    assert!(
        (law_mean - mean).abs() < 1e-6 * w_star,
        "{law_mean} vs {mean}"
    );
    // Doubled loads: the model on a plate with twice the friction.
    let doubled =
        pushval_laws::on_loads(&p, &rest.iter().map(|l| 2.0 * l).collect::<Vec<_>>()).unwrap();
    let traj2 = crate::common::run(&model, &doubled);
    let (_, rms2) = judge(&COULOMB, &traj2, 2.0);
    assert!(rms2 < 1e-6 * w_star, "rms {rms2}");
    let (_, wrong) = judge(&COULOMB, &traj2, 1.0);
    assert!(wrong > 1e3 * rms2, "loads ignored: {wrong} vs {rms2}");
    // Quasi-static: the steady ω at every sample, the transient missed.
    let (_, quasi) = judge(&SteadyOnly, &traj, 1.0);
    assert!(
        quasi > 1e3 * rms,
        "quasi-static {quasi} vs integrated {rms}"
    );
}

/// Issue 45, item 7: a project's study files are its `studies/`, else the
/// shipped ones, among them those of engines its registry does not run
/// (Drake, PyBullet, …); `study` passes over every shipped file it does not
/// use in silence, and still notes a study file the user wrote, or changed,
/// for a model the registry lacks.
#[test]
fn study_is_quiet_about_shipped_files_a_project_does_not_use() {
    let (dir, tmp, cache) = (
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
    );
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_pushval"))
            .current_dir(dir.path())
            .args(args)
            .env("CI", "1")
            .env("TMPDIR", tmp.path())
            .env("XDG_CACHE_HOME", cache.path())
            .env_remove("SLURM_ARRAY_TASK_ID")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(out.status.success(), "{err}");
        err
    };
    let skipped = |err: &str| -> Vec<String> {
        err.lines()
            .filter(|l| l.contains("skipping"))
            .map(String::from)
            .collect()
    };
    ok(Command::new(env!("CARGO_BIN_EXE_pushval"))
        .current_dir(dir.path())
        .arg("init")
        .env("TMPDIR", tmp.path())
        .env("XDG_CACHE_HOME", cache.path())
        .output()
        .unwrap());
    // The premise: a shipped study file of a model this project lacks.
    let engines = run(&["engines"]);
    let unused = "pybullet_contact";
    let shipped = pushval::shipped::study_text(unused).expect("shipped");
    assert!(!engines.contains(unused), "{engines}");
    // The shipped files (no studies/ folder): nothing to say.
    let err = run(&["study", "index", "--quick", "--out", "out"]);
    assert!(skipped(&err).is_empty(), "{err}");
    // A studies/ folder with a shipped file as shipped, and the user's own.
    let studies = dir.path().join("studies");
    std::fs::create_dir(&studies).unwrap();
    std::fs::write(studies.join(format!("{unused}.toml")), shipped).unwrap();
    std::fs::write(studies.join("my_own_engine.toml"), "t_run = 2.0\n").unwrap();
    let err = run(&["study", "index", "--quick", "--out", "out"]);
    let lines = skipped(&err);
    assert_eq!(lines.len(), 1, "{err}");
    assert!(lines[0].contains("my_own_engine.toml"), "{err}");
    // A shipped file the user changed is theirs: noted like any other.
    std::fs::write(
        studies.join(format!("{unused}.toml")),
        format!("{shipped}\n# mine now\n"),
    )
    .unwrap();
    let err = run(&["study", "index", "--quick", "--out", "out"]);
    assert_eq!(skipped(&err).len(), 2, "{err}");
    assert!(err.contains(&format!("{unused}.toml")), "{err}");
}
