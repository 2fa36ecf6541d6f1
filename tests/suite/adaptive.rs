//! Adaptive MPC, plants that differ from the file, and sensors. Expected
//! values come from the plant's own scene (the friction and inertia it was
//! given), from the seed's determinism, and from the delay the sensor was
//! asked for.

use std::process::Command;

use pushval::control::mpc::{run_loop, LoopOutcome, LoopSpec, Observer, Period, PlantScale};
use pushval::control::plan::PlanSpec;
use pushval::control::sensor::SensorSpec;
use pushval::control::{At, Goal, ModelKind as Predictor, Reach};
use pushval_model::{Body, Problem, Support};

use crate::common::root;

const GOAL: Goal = Goal {
    x: 0.8,
    y: 0.2,
    theta: -0.5,
};

fn plate() -> Problem {
    let sc = pushval::registry::load(root().join("scenarios/paper-square-v1.0.toml")).unwrap();
    let mut p = sc.problem();
    p.initial.from_rest = true;
    p
}

/// The plate with support 1 (the corner at (+, −)) five times as slippery.
fn slippery_foot(p: &Problem) -> Problem {
    let supports: Vec<Support> = p
        .body
        .supports()
        .enumerate()
        .map(|(i, s)| Support {
            friction: if i == 1 { s.friction / 5.0 } else { s.friction },
            ..s
        })
        .collect();
    let b = &p.body;
    Problem {
        body: Body::new(b.mass(), b.inertia_cm(), b.contact(), &supports).unwrap(),
        ..p.clone()
    }
}

fn spec(adapt: bool, sensor: SensorSpec) -> LoopSpec {
    LoopSpec {
        plan: PlanSpec {
            segments: 6,
            speed: 1.0,
            predictor: Predictor::Dynamic,
            at: At::Release,
        },
        period: 0.02,
        reach: Reach::default(),
        adapt,
        sensor,
    }
}

fn run(plant: &Problem, spec: LoopSpec, observer: &mut dyn Observer) -> LoopOutcome {
    let p = plate();
    let engine = pushval::registry::entry("rapier2d")
        .unwrap()
        .default_engine();
    let dt = engine.default_dt();
    let mut session = engine.start(plant, dt).unwrap();
    let out = run_loop(&p, session.as_mut(), dt, GOAL, spec, observer).unwrap();
    session.finish().unwrap();
    out
}

#[test]
fn the_estimate_converges_to_the_plants_own_friction_and_inertia() {
    // μ × 0.8 and I_cm × 1.2 at every support: the centre of friction stays
    // at the centre of mass.
    let p = plate();
    let plant = PlantScale::PERTURBED.apply(&p).unwrap();
    let out = run(&plant, spec(true, SensorSpec::default()), &mut ());
    let last = out.estimates.last().expect("an estimate every period");
    let [mu, cx, cy, i] = last.value;
    assert!((mu - 0.8).abs() < 0.03, "mu_scale {mu}");
    assert!(
        (i / (1.2 * p.body.inertia_cm()) - 1.0).abs() < 0.05,
        "I_cm {i} against {}",
        1.2 * p.body.inertia_cm()
    );
    assert!(cx.hypot(cy) < 3e-3, "centre of friction ({cx}, {cy}) m");
    let id = out.identified.unwrap();
    assert!(
        id.mu_scale && id.inertia_cm && id.center_of_friction,
        "{id:?}"
    );
    assert_eq!(out.estimates.len(), out.estimator_cpu_us.len());
    assert!(
        out.success,
        "{} m {} rad",
        out.position_error, out.angle_error
    );
}

#[test]
fn adaptive_mpc_reaches_on_a_slippery_foot_where_plain_mpc_misses() {
    let plant = slippery_foot(&plate());
    let plain = run(&plant, spec(false, SensorSpec::default()), &mut ());
    let adaptive = run(&plant, spec(true, SensorSpec::default()), &mut ());
    assert!(
        !plain.success,
        "plain MPC: {} m {} rad",
        plain.position_error, plain.angle_error
    );
    assert!(
        adaptive.success,
        "adaptive: {} m {} rad",
        adaptive.position_error, adaptive.angle_error
    );
    // The slippery foot cuts the total friction to 3.2/4 of the file's; the
    // estimator's μ scale with its centre of friction explains the pushed
    // motion, so it lies below 1.
    assert!(adaptive.estimates.last().unwrap().value[0] < 0.95);
}

#[test]
fn a_seed_gives_the_same_loop_and_another_seed_another() {
    let plant = plate();
    let noisy = |seed| SensorSpec {
        sigma_position: 5e-4,
        sigma_theta: 3.5e-3,
        sigma_omega: 0.05,
        sigma_velocity: 5e-3,
        latency: 0.0,
        seed,
    };
    let a = run(&plant, spec(true, noisy(3)), &mut ());
    let b = run(&plant, spec(true, noisy(3)), &mut ());
    let c = run(&plant, spec(true, noisy(4)), &mut ());
    let pushes = |o: &LoopOutcome| o.applied.iter().map(|a| a.push).collect::<Vec<_>>();
    assert_eq!(pushes(&a), pushes(&b));
    assert_eq!(a.release, b.release);
    assert_ne!(pushes(&a), pushes(&c));
}

#[test]
fn a_delayed_sensor_reads_the_state_of_latency_earlier_and_the_loop_still_reaches() {
    struct Times(Vec<(usize, f64)>);
    impl Observer for Times {
        fn period(&mut self, p: &Period<'_>) {
            self.0.push((p.index, p.state.t));
        }
    }
    let latency = 0.05; // 2.5 periods: the reading falls inside a period
    let mut times = Times(Vec::new());
    let out = run(
        &plate(),
        spec(
            false,
            SensorSpec {
                latency,
                ..SensorSpec::default()
            },
        ),
        &mut times,
    );
    assert!((out.latency - latency).abs() < 1e-12);
    for (k, t) in times.0 {
        let want = (k as f64 * 0.02 - latency).max(0.0);
        assert!(
            (t - want).abs() < 1e-9,
            "period {k}: read {t} s, want {want} s"
        );
    }
    assert!(
        out.success,
        "{} m {} rad",
        out.position_error, out.angle_error
    );
}

fn pushval() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pushval"))
}

#[test]
fn loop_adapt_writes_estimate_csv_and_refuses_a_plant_of_another_outline() {
    let dir = tempfile::tempdir().unwrap();
    let file = root().join("scenarios/paper-square-v1.0.toml");
    let text = std::fs::read_to_string(&file).unwrap();
    // A plant of another outline (and a sensor key that does not exist):
    // exit 2, naming the key, nothing written.
    let other = dir.path().join("other.toml");
    std::fs::write(
        &other,
        text.replace(
            "polygon = [[-0.125, -0.125], [0.125, -0.125], [0.125, 0.125], [-0.125, 0.125]]",
            "polygon = [[-0.125, -0.125], [0.135, -0.125], [0.125, 0.125], [-0.125, 0.125]]",
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = pushval()
        .arg("loop")
        .arg(&file)
        .args([
            "--goal",
            "0.8,0.2,-0.5",
            "--speed",
            "1",
            "--engine",
            "rapier2d",
        ])
        .arg("--plant")
        .arg(&other)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("object.polygon") && err.contains("other.toml"),
        "{err}"
    );
    assert!(!out.exists());
    let o = pushval()
        .arg("loop")
        .arg(&file)
        .args([
            "--goal",
            "0.8,0.2,-0.5",
            "--speed",
            "1",
            "--engine",
            "rapier2d",
        ])
        .args(["--sensor", "sigma_pos=0.001"])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("sigma_pos"));
    // A plant with a slippery foot from a file, adaptive, judged at the
    // release: estimate.csv has a row per period, loop.json the estimate.
    let slip = dir.path().join("slip.toml");
    std::fs::write(
        &slip,
        text.replace("mu = 0.5\n", "mu = [0.5, 0.1, 0.5, 0.5]\n"),
    )
    .unwrap();
    let o = pushval()
        .arg("loop")
        .arg(&file)
        .args([
            "--goal",
            "0.8,0.2,-0.5",
            "--speed",
            "1",
            "--engine",
            "rapier2d",
        ])
        .args(["--at", "release", "--adapt"])
        .arg("--plant")
        .arg(&slip)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("loop.json")).unwrap()).unwrap();
    let steps = doc["steps"].as_u64().unwrap() as usize;
    let csv = std::fs::read_to_string(out.join("estimate.csv")).unwrap();
    assert_eq!(csv.lines().count(), steps + 1);
    assert!(csv.starts_with("t,center_of_friction_x,center_of_friction_x_std,"));
    assert!(doc["estimate"]["mu_scale"]["value"].as_f64().unwrap() < 0.95);
    assert!(doc["estimator_cpu_us_median"].as_f64().unwrap() > 0.0);
    assert!(doc["plant"]["file"]
        .as_str()
        .unwrap()
        .ends_with("slip.toml"));
    // applied.toml is the plant's scene: its supports' mu is the file's.
    let applied = std::fs::read_to_string(out.join("applied.toml")).unwrap();
    assert!(applied.contains("0.1"), "{applied}");
    let sc = pushval::registry::load(out.join("applied.toml")).unwrap();
    assert!((sc.supports[1].mu - 0.1).abs() < 1e-12);
}

#[test]
fn the_quick_adaptive_study_runs_every_mode_plant_and_sensor_and_says_what_it_cannot_hold() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("adaptive");
    let o = pushval()
        .args([
            "control-study",
            "--adaptive",
            "--quick",
            "--only",
            "rapier2d,rapier3d",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let runs = std::fs::read_to_string(out.join("runs.csv")).unwrap();
    // Per engine, goal and rule: open on 6 plants (exact only), MPC and
    // adaptive on 6 plants × 2 sensors, the oracle on the 5 plants that
    // differ × 2: 40 runs; 3 goals × 2 rules × 2 engines.
    assert_eq!(runs.lines().count() - 1, 40 * 3 * 2 * 2);
    for mode in ["open", "mpc", "adaptive", "oracle"] {
        assert!(runs.contains(&format!(",{mode},")), "{mode}");
    }
    assert!(!runs.contains(",oracle,nominal,"));
    let readme = std::fs::read_to_string(out.join("README.md")).unwrap();
    // rapier3d's compound feet carry one coefficient: the plants that move
    // or split the friction are not applicable there, and said to be.
    let r3 = &readme[readme.find("## rapier3d").unwrap()..];
    assert!(r3.contains("cannot hold the plants loads_side"), "{r3}");
    assert!(r3.contains("| slippery_near | n/a |"), "{r3}");
    // rapier2d applies Coulomb friction per support: adaptive MPC reaches
    // the slippery foot off the line at the release, exact sensor.
    let success = std::fs::read_to_string(out.join("success.csv")).unwrap();
    let row = success
        .lines()
        .find(|l| l.starts_with("rapier2d,1,release,adaptive,slippery_near,exact,"))
        .unwrap();
    assert!(row.contains(",3,3,"), "{row}");
    // Judged at rest the support under the contact matters: no pushed
    // motion reveals it, and the scene keeps the file's value there (the
    // true one on this plate), so adaptive MPC reaches the rest poses plain
    // MPC misses.
    let count = |key: &str| {
        let l = success.lines().find(|l| l.starts_with(key)).unwrap();
        l.split(',').nth(6).unwrap().parse::<usize>().unwrap()
    };
    assert_eq!(count("rapier2d,1,rest,adaptive,slippery_near,exact,"), 3);
    assert_eq!(count("rapier2d,1,rest,mpc,slippery_near,exact,"), 0);
}
