//! Every scenario file is its own test case.

use std::path::PathBuf;

use approx::assert_relative_eq;
use pushval::{output, run_scenario, RunOptions};
use pushval_model::{DynamicModel, Simulator};
use pushval_rapier2d::{drive, DetailedEngine, EngineSettings, RapierSimulator};
use rstest::rstest;

use crate::common::*;

/// Loads, runs every model, writes the contract outputs; they parse, carry the
/// contract's fields, and hold no NaN.
#[rstest]
fn scenario_runs_and_writes_contract_outputs(#[files("scenarios/*.toml")] path: PathBuf) {
    let sc = load(&path);
    let report = run_scenario(&sc, &RunOptions::default()).unwrap();
    let summary = output::summary(&report);
    let text = serde_json::to_string(&summary).unwrap();
    // Non-finite numbers would appear as bare NaN / inf values.
    for bad in ["NaN", ":inf", ":-inf", "Infinity"] {
        assert!(!text.contains(bad), "summary holds {bad}");
    }
    assert_eq!(summary["scenario"], sc.name);
    let segs = summary["segments"].as_array().unwrap();
    assert_eq!(segs.len(), sc.pushes.len());
    for key in [
        "index",
        "t_start",
        "t_end",
        "speed",
        "phi",
        "froude",
        "omega_kinematic",
        "omega_steady",
        "tau",
    ] {
        // A thrown plate has no segment.
        assert!(
            segs.iter().all(|s| s.get(key).is_some()),
            "a segment lacks {key}"
        );
    }
    for (name, m) in summary["models"].as_object().unwrap() {
        for key in [
            "position_max",
            "theta_max",
            "omega_steady_rel_max",
            "pass",
            "rest",
        ] {
            assert!(m.get(key).is_some(), "models.{name} lacks {key}");
        }
    }
    // The engine's time step and where it came from (the choice's reason
    // included) are part of its settings.
    let gated = sc.gate.first().map_or("rapier2d", String::as_str);
    let engine = &summary["models"][gated]["settings"];
    assert!(engine["dt"].as_f64().is_some_and(|dt| dt > 0.0));
    assert!(["automatic", "scenario"].contains(&engine["dt_source"].as_str().unwrap()));
    assert!(engine["dt_choice"]["reason"]
        .as_str()
        .is_some_and(|r| r.starts_with("dt = ")));
    assert!(summary["assumptions"].is_object());
    let csv = output::trajectory_csv(&report);
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "model,t,x,y,theta,omega");
    let rows: Vec<&str> = lines.collect();
    // Through a slide each run has its own number of samples (to its stop).
    let n_samples: usize = if sc.release.is_some() {
        report.runs.iter().map(|r| r.trajectory.samples.len()).sum()
    } else {
        sc.problem().sample_times().len() * report.runs.len()
    };
    assert_eq!(rows.len(), n_samples);
    for r in rows {
        let f: Vec<&str> = r.split(',').collect();
        assert_eq!(f.len(), 6);
        for v in &f[1..] {
            assert!(v.parse::<f64>().unwrap().is_finite());
        }
    }
}

/// Segments at least this many relaxation times long must settle: the tail
/// window (the last 20 %) then starts after 24 τ, where a linear transient has
/// shrunk by e^−24 ≈ 4e-11, far below the 1e-6 a settled segment needs even
/// against the floor `1e-3 v/L` of a zero ω*.
const MUST_SETTLE_TAUS: f64 = 30.0;
/// A scenario with a segment this many τ long has at least one segment that
/// settles (e^−12 ≈ 6e-6 at the window's start: most, not all, settle).
const LONG_TAUS: f64 = 15.0;

/// `(long, must_settle)` for one segment: its length in τ of the smooth
/// stable root it runs to, against [`LONG_TAUS`] and [`MUST_SETTLE_TAUS`].
fn segment_length_class(s: &pushval::SegmentInfo) -> (bool, bool) {
    let stable = s
        .omega_steady
        .is_some_and(|r| matches!(r.kind, pushval_model::RootKind::Stable));
    match s.tau().filter(|_| stable) {
        Some(tau) => {
            let n = (s.t_end - s.t_start) / tau;
            (n >= LONG_TAUS, n >= MUST_SETTLE_TAUS)
        }
        None => (false, false),
    }
}

/// Every scenario: each segment that runs toward a smooth stable root for at
/// least [`MUST_SETTLE_TAUS`] relaxation times settles, a scenario with a
/// segment [`LONG_TAUS`] long has a settled segment, and the dynamic model's
/// ω at the end of each settled segment is its steady root
/// (`settle_checks_are_not_vacuous` makes sure these cases occur).
#[rstest]
fn scenario_segments_settle_on_their_roots(#[files("scenarios/*.toml")] path: PathBuf) {
    let sc = load(&path);
    let report = run_scenario(&sc, &RunOptions::default()).unwrap();
    let dynamic = &report.dynamic().trajectory;
    let mut long = 0;
    for s in &report.segments {
        let (is_long, must) = segment_length_class(s);
        long += usize::from(is_long);
        if must {
            assert!(
                s.settles(),
                "segment {} ({} s, τ = {:?} s) does not settle: tail deviation {:?}",
                s.index,
                s.t_end - s.t_start,
                s.tau(),
                s.tail_deviation
            );
        }
    }
    let settled = report.segments.iter().filter(|s| s.settles()).count();
    assert!(
        long == 0 || settled > 0,
        "{}: {long} segments of ≥ {LONG_TAUS} τ, none settled",
        path.display()
    );
    for s in report.segments.iter().filter(|s| s.settles()) {
        let ws = s.omega_steady.unwrap().omega;
        let we = dynamic.segments[s.index].omega_end;
        assert!(
            (we - ws).abs() <= 1e-6 * ws.abs().max(1e-3 * s.speed / sc.froude_length()),
            "segment {}: {we} vs {ws}",
            s.index
        );
    }
}

/// The settle checks above cannot pass vacuously: over the shipped scenarios
/// some segments are long enough that they must settle, several scenarios
/// have a long segment, and segments do settle. Only the dynamic model runs.
#[test]
fn settle_checks_are_not_vacuous() {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(root().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    let (mut must, mut with_long, mut settled) = (0, 0, 0);
    for path in &paths {
        let sc = load(path);
        let problem = sc.problem();
        let dynamic = DynamicModel::default().simulate(&problem).unwrap();
        let segs = pushval::harness::analyse_segments(&sc, &problem, &dynamic);
        let classes: Vec<(bool, bool)> = segs.iter().map(segment_length_class).collect();
        must += classes.iter().filter(|c| c.1).count();
        with_long += usize::from(classes.iter().any(|c| c.0));
        settled += segs.iter().filter(|s| s.settles()).count();
    }
    assert!(must >= 2, "only {must} segments of ≥ {MUST_SETTLE_TAUS} τ");
    assert!(
        2 * with_long >= paths.len(),
        "only {with_long} of {} scenarios have a segment of ≥ {LONG_TAUS} τ",
        paths.len()
    );
    assert!(settled >= must, "{settled} segments settled");
}

/// Mirror symmetry over every scenario: reflect the file's geometry across the
/// x-axis and negate φ and the initial angle: θ, ω and y change sign.
#[rstest]
fn scenario_mirror_symmetry(#[files("scenarios/*.toml")] path: PathBuf) {
    let sc = load(&path);
    let mut m = sc.clone();
    let flip = |v: &mut pushval_model::Vec2| v.y = -v.y;
    m.polygon.iter_mut().for_each(flip);
    m.polygon.reverse();
    m.supports
        .iter_mut()
        .for_each(|s| s.position.y = -s.position.y);
    flip(&mut m.contact);
    flip(&mut m.center_of_mass);
    flip(&mut m.contact_limits.normals.0);
    flip(&mut m.contact_limits.normals.1);
    m.pushes.iter_mut().for_each(|p| p.phi = -p.phi);
    m.initial.theta = -m.initial.theta;
    m.initial.omega = -m.initial.omega;
    m.initial.position.y = -m.initial.position.y;
    m.initial.velocity.y = -m.initial.velocity.y;
    let model = DynamicModel::default();
    let a = model.simulate(&sc.problem()).unwrap();
    let b = model.simulate(&m.problem()).unwrap();
    for (p, q) in a.samples.iter().zip(&b.samples) {
        assert!(
            (p.omega + q.omega).abs() < 1e-7 * (1.0 + p.omega.abs()),
            "{p:?} {q:?}"
        );
        assert!(
            (p.theta + q.theta).abs() < 1e-7
                && (p.x - q.x).abs() < 1e-7
                && (p.y + q.y).abs() < 1e-7
        );
    }
}

/// Mass independence over every scenario: scaling mass, loads and inertia by
/// 7.3 leaves the trajectory unchanged.
#[rstest]
fn scenario_mass_independence(#[files("scenarios/*.toml")] path: PathBuf) {
    let sc = load(&path);
    let mut h = sc.clone();
    h.mass *= 7.3;
    h.inertia_cm *= 7.3;
    h.supports.iter_mut().for_each(|s| s.load *= 7.3);
    let model = DynamicModel::default();
    let (a, b) = (
        model.simulate(&sc.problem()).unwrap(),
        model.simulate(&h.problem()).unwrap(),
    );
    // Through a slide the last row is the stop, the same to rounding.
    let stop = |t: &pushval_model::Trajectory| t.slide.as_ref().and_then(|s| s.t_stop);
    if let (Some(sa), Some(sb)) = (stop(&a), stop(&b)) {
        assert!((sa - sb).abs() < 1e-9, "{sa} {sb}");
    }
    let (dp, dt) = pushval::harness::paired(&a, &b)
        .expect("the same samples")
        .iter()
        .fold((0.0f64, 0.0f64), |(p, t), (x, y)| {
            (
                p.max((x.x - y.x).hypot(x.y - y.y)),
                t.max((x.theta - y.theta).abs()),
            )
        });
    assert!(dp < 1e-9 && dt < 1e-9, "{dp} {dt}");
}

/// The 10 kg scenario file moves exactly like the 1 kg one.
#[test]
fn heavy_file_matches_paper_file() {
    let a = load(&root().join("scenarios/paper-square-v1.0.toml"));
    let b = load(&root().join("scenarios/heavy-square-v1.0.toml"));
    assert_eq!(b.mass, 10.0 * a.mass);
    let model = DynamicModel::default();
    let (dp, dt) = max_diff(
        &model.simulate(&a.problem()).unwrap(),
        &model.simulate(&b.problem()).unwrap(),
    );
    assert!(dp < 1e-9 && dt < 1e-9);
}

/// Statics loads balance force and moment about the centre of mass.
#[test]
fn statics_loads_balance() {
    let sc = load(&root().join("scenarios/triangle-statics.toml"));
    let w = sc.mass * sc.gravity;
    let sum: f64 = sc.supports.iter().map(|s| s.load).sum();
    assert_relative_eq!(sum, w, max_relative = 1e-12);
    let m = sc
        .supports
        .iter()
        .fold(pushval_model::Vec2::zeros(), |a, s| {
            a + (s.position - sc.center_of_mass) * s.load
        });
    assert!(m.norm() < 1e-12 * w);
    assert!(sc.supports.iter().all(|s| s.load > 0.0));
}

/// The printed-inertia file states 0.1667 kg m² about the contact point:
/// the centre-of-mass inertia follows by the parallel-axis theorem, and it is
/// the contact-point inertia of a 0.5 m plate, four times the 0.25 m plate's.
#[test]
fn printed_inertia_is_read_about_the_contact() {
    let printed = load(&root().join("scenarios/printed-inertia-v1.0.toml"));
    let geometric = load(&root().join("scenarios/paper-square-v1.0.toml"));
    assert_relative_eq!(
        geometric.inertia_cm,
        0.25f64.powi(2) / 6.0,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        printed.body().inertia_contact(),
        0.1667,
        max_relative = 1e-12
    );
    // A 0.5 m, 1 kg plate about its corner: 0.5²/6 + 2 (0.25)² = 0.16667.
    assert_relative_eq!(
        0.5f64.powi(2) / 6.0 + 2.0 * 0.25f64.powi(2),
        0.1667,
        max_relative = 1e-3
    );
    // The 0.25 m plate about its corner: 0.0417, as the text's plate should have.
    assert_relative_eq!(
        geometric.body().inertia_contact(),
        0.0417,
        max_relative = 1e-3
    );
}

/// Uniform pressure: the grid's loads sum to m g and are centred on the centroid.
#[test]
fn uniform_grid_is_centred_and_complete() {
    let sc = load(&root().join("scenarios/uniform-pressure-square.toml"));
    assert_eq!(sc.supports.len(), 100);
    let w: f64 = sc.supports.iter().map(|s| s.load).sum();
    assert_relative_eq!(w, sc.mass * sc.gravity, max_relative = 1e-12);
    let c = sc
        .supports
        .iter()
        .fold(pushval_model::Vec2::zeros(), |a, s| a + s.position * s.load)
        / w;
    assert!(c.norm() < 1e-12);
}

/// Colliders on every scenario's own polygon (massless, interacting with
/// nothing: `EngineSettings::colliders`) leave the engine's run unchanged,
/// bit for bit.
#[rstest]
fn scenario_engine_colliders_change_nothing(#[files("scenarios/*.toml")] path: PathBuf) {
    let sc = load(&path);
    let problem = sc.problem();
    // The crate's own run drives pushes only; a release goes through the
    // engine's session (tests/suite/release.rs).
    if problem.release.is_some() {
        return;
    }
    let outline: Vec<[f64; 2]> = sc
        .polygon
        .iter()
        .map(|p| [p.x - sc.center_of_mass.x, p.y - sc.center_of_mass.y])
        .collect();
    let settings =
        pushval_rapier2d::engine::settings_from(&pushval::registry::engine_options(&sc)).unwrap();
    let a = RapierSimulator::new(settings).run(&problem).unwrap();
    let b = RapierSimulator::new(EngineSettings {
        colliders: true,
        ..settings
    })
    .start_with_outline(&problem, &outline)
    .and_then(|s| drive(s, &problem))
    .unwrap();
    assert_eq!(a.trajectory.samples, b.trajectory.samples);
}
