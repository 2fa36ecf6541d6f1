//! Closed loop: `plan`, `loop`, the sessions they stand on, and the switch
//! checks. Expected values come from the model itself run independently
//! (the written plan re-loaded and simulated at the default tolerance),
//! from the plate's mirror symmetry, from the quasi-static limit, and from
//! closed forms of the switch impulse.

use std::f64::consts::FRAC_PI_2;
use std::process::Command;

use pushval::control::mpc::{open_loop, run_loop, LoopSpec, PlantScale};
use pushval::control::plan::{make_plan, straight_time, switch_checks, Bounds, PlanSpec, Planner};
use pushval::control::predict::Start;
use pushval::control::{Goal, ModelKind as Predictor, Reach};
use pushval_model::{DynamicModel, Problem, Push, Simulator};

use crate::common::root;

fn pushval() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pushval"))
}

/// The seed's plate from rest, pushed at its corner.
fn plate() -> Problem {
    let sc = pushval::registry::load(root().join("scenarios/paper-square-v1.0.toml")).unwrap();
    let mut p = sc.problem();
    p.initial.from_rest = true;
    p
}

fn final_pose(p: &Problem, pushes: &[Push]) -> [f64; 3] {
    let mut q = p.clone();
    q.pushes = pushes.to_vec();
    let s = *DynamicModel::default()
        .simulate(&q)
        .unwrap()
        .samples
        .last()
        .unwrap();
    [s.x, s.y, s.theta]
}

fn spec(speed: f64, predictor: Predictor) -> PlanSpec {
    PlanSpec {
        segments: 6,
        speed,
        predictor,
        at: pushval::control::At::Release,
    }
}

const GOAL: Goal = Goal {
    x: 0.8,
    y: 0.2,
    theta: -0.5,
};

#[test]
fn a_dynamic_plan_reaches_its_goal_when_the_model_runs_it_at_full_accuracy() {
    let p = plate();
    for v in [0.1, 0.5, 1.0] {
        let out = make_plan(
            &p,
            GOAL,
            spec(v, Predictor::Dynamic),
            Reach::default(),
            &Bounds::default(),
        )
        .unwrap();
        assert!(out.solution.converged, "{v} m/s: did not converge");
        // The planner's predictor runs at 1e-9; the default model at 1e-10
        // must land on the goal too, well inside the success tolerance.
        let f = final_pose(&p, &out.solution.pushes);
        let d = (f[0] - GOAL.x).hypot(f[1] - GOAL.y);
        assert!(d < 2e-3, "{v} m/s: {d} m from the goal");
        assert!((f[2] - GOAL.theta).abs() < 5e-3, "{v} m/s: {f:?}");
        // Every push stays in the pushing cone: the corner's normals [0, π/2]
        // widened by half the contact's friction angle (μ_c = 0.8) each side.
        let w = 0.5 * 0.8_f64.atan();
        assert_eq!(pushval::control::push_cone(&p), (-w, FRAC_PI_2 + w));
        for q in &out.solution.pushes {
            assert!((-w - 1e-9..=FRAC_PI_2 + w + 1e-9).contains(&q.phi), "{q:?}");
        }
    }
}

#[test]
fn the_mirror_image_of_a_plan_reaches_the_mirror_image_of_its_goal() {
    // The square plate pushed at its corner (−a, −a) is symmetric about the
    // diagonal y = x: reflecting it maps φ to π/2 − φ, (x, y) to (y, x) and
    // θ to −θ. So a plan's reflection reaches the reflected goal.
    let p = plate();
    let out = make_plan(
        &p,
        GOAL,
        spec(0.5, Predictor::Dynamic),
        Reach::default(),
        &Bounds::default(),
    )
    .unwrap();
    let mirrored: Vec<Push> = out
        .solution
        .pushes
        .iter()
        .map(|q| Push {
            phi: FRAC_PI_2 - q.phi,
            ..*q
        })
        .collect();
    let a = final_pose(&p, &out.solution.pushes);
    let b = final_pose(&p, &mirrored);
    assert!(
        (a[0] - b[1]).abs() < 1e-8 && (a[1] - b[0]).abs() < 1e-8,
        "{a:?} {b:?}"
    );
    assert!((a[2] + b[2]).abs() < 1e-8, "{a:?} {b:?}");
}

#[test]
fn a_kinematic_plan_misses_more_the_faster_the_push() {
    // The quasi-static model is the dynamic one's limit of small Froude
    // number: slow, its plan works in the dynamic model; fast, it misses.
    let p = plate();
    let miss = |v: f64| {
        let out = make_plan(
            &p,
            GOAL,
            spec(v, Predictor::Kinematic),
            Reach::default(),
            &Bounds::default(),
        )
        .unwrap();
        assert!(
            out.solution.converged,
            "{v} m/s: the kinematic plan did not converge"
        );
        let f = final_pose(&p, &out.solution.pushes);
        (f[0] - GOAL.x).hypot(f[1] - GOAL.y)
    };
    let (slow, mid, fast) = (miss(0.05), miss(0.5), miss(1.0));
    assert!(
        slow < 0.02,
        "at 0.05 m/s the kinematic plan misses by {slow} m"
    );
    assert!(slow < mid && mid < fast, "{slow} {mid} {fast}");
    assert!(fast > 0.02, "at 1 m/s it should miss: {fast}");
}

#[test]
fn a_switch_impulse_and_its_ramp_meet_the_friction_cone_exactly() {
    let p = plate();
    let out = make_plan(
        &p,
        GOAL,
        spec(1.0, Predictor::Dynamic),
        Reach::default(),
        &Bounds::default(),
    )
    .unwrap();
    let mut q = p.clone();
    q.pushes = out.solution.pushes.clone();
    let traj = DynamicModel::default().simulate(&q).unwrap();
    let checks = switch_checks(&q, &traj, true);
    assert_eq!(checks.len(), 6, "the start and five switches");
    let mu = q.limits.mu.unwrap();
    // The start from rest: H = 0 before, so the impulse is m v_cm just after,
    // v_cm = v_P − ω⁺ perp(p_c) with ω⁺ = m (p_c × v_P) / I_P.
    let first = &q.pushes[0];
    let pc = q.body.contact();
    let vp = first.velocity();
    let w = q.body.mass() * (pc.x * vp.y - pc.y * vp.x) / q.body.inertia_contact();
    let j = (vp - pushval_model::perp(&pc) * w) * q.body.mass();
    assert!((checks[0].impulse[0] - j.x).abs() < 1e-9 && (checks[0].impulse[1] - j.y).abs() < 1e-9);
    for c in &checks {
        assert_eq!(
            c.inside,
            c.cone_angle_rad <= mu.atan() + 1e-12 || (c.impulse[0].hypot(c.impulse[1]) < 1e-12)
        );
        if let (false, Some(tau)) = (c.inside, c.ramp_s) {
            // The ramp found puts the force on the cone's edge.
            let k = c.segment;
            let w1 = traj.segments[k].omega_start;
            let steady =
                pushval_model::SegmentDynamics::new(&q.body, &q.pushes[k]).pusher_force(w1);
            let f = steady + pushval_model::Vec2::new(c.impulse[0], c.impulse[1]) / tau;
            assert!((q.limits.cone_angle(&f) - mu.atan()).abs() < 1e-6, "{c:?}");
        }
    }
}

#[test]
fn mpc_reaches_on_a_perturbed_rapier2d_plant_where_the_open_loop_plan_misses() {
    let p = plate();
    let engine = pushval::registry::engine("rapier2d", &Default::default());
    let dt = engine.default_dt();
    let reach = Reach::default();
    let start = Start::of_problem(&p);
    let mut planner = Planner::new(
        &p,
        GOAL,
        spec(1.0, Predictor::Dynamic),
        straight_time(&start, &GOAL, 1.0),
        reach,
    );
    let plan = planner.plan(&start).unwrap();
    let open = |scale: PlantScale| {
        let plant = scale.apply(&p).unwrap();
        let mut session = engine.start(&plant, dt).unwrap();
        let st = open_loop(session.as_mut(), &plan.pushes).unwrap();
        pushval::control::pose_errors(st.x, st.y, st.theta, &GOAL)
    };
    let (pe_nom, ae_nom) = open(PlantScale::default());
    assert!(
        reach.holds(pe_nom, ae_nom),
        "open loop, nominal: {pe_nom} m {ae_nom} rad"
    );
    let (pe, ae) = open(PlantScale::PERTURBED);
    assert!(
        !reach.holds(pe, ae),
        "open loop on the perturbed plant: {pe} m {ae} rad"
    );
    let spec = LoopSpec {
        plan: spec(1.0, Predictor::Dynamic),
        period: 0.02,
        reach,
        adapt: false,
        sensor: Default::default(),
    };
    let plant = PlantScale::PERTURBED.apply(&p).unwrap();
    let mut session = engine.start(&plant, dt).unwrap();
    let mut periods = 0usize;
    struct Count<'a>(&'a mut usize);
    impl pushval::control::mpc::Observer for Count<'_> {
        fn period(&mut self, period: &pushval::control::mpc::Period<'_>) {
            *self.0 += 1;
            assert_eq!(period.index, *self.0);
        }
    }
    let out = run_loop(
        &p,
        session.as_mut(),
        dt,
        GOAL,
        spec,
        &mut Count(&mut periods),
    )
    .unwrap();
    let run = session.finish().unwrap();
    assert!(
        out.success,
        "MPC: {} m {} rad",
        out.position_error, out.angle_error
    );
    assert!(out.position_error < pe && out.angle_error < ae);
    assert!(out.steps > 10);
    assert_eq!(periods, out.steps, "the observer hears every period");
    // The applied pushes tile the run: their durations add up to its end.
    let total: f64 = out.applied.iter().map(|a| a.push.duration).sum();
    let end = run.trajectory.samples.last().unwrap().t;
    assert!((total - end).abs() < 1e-9, "{total} {end}");
    // Every applied duration is a whole number of the plant's steps.
    for a in &out.applied {
        let k = a.push.duration / dt;
        assert!(
            (k - k.round()).abs() < 1e-6 && k.round() >= 1.0,
            "{} s is {k} steps of {dt} s",
            a.push.duration
        );
    }
}

/// Speeds, goals and periods out of range are refused at once, exit 2,
/// naming the flag, with nothing written; each within a bounded time
/// (the commands used to allocate 704 GB or run for minutes).
#[test]
fn out_of_range_requests_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    for (args, flag) in [
        (
            vec!["plan", "--goal=0.5,0.1,0.3", "--speed", "1e-9"],
            "--speed",
        ),
        (
            vec!["plan", "--goal=0.5,0.1,0.3", "--speed", "-1"],
            "--speed",
        ),
        (vec!["plan", "--goal=1e300,0,0", "--speed", "1"], "--goal"),
        (vec!["plan", "--goal=1e5,0,0", "--speed", "1"], "--goal"),
        (vec!["plan", "--goal=0.5,0,1e9", "--speed", "1"], "--goal"),
        (
            vec!["plan", "--goal=0.5,0,0", "--segments", "40"],
            "--segments",
        ),
        (
            vec![
                "loop",
                "--goal=0.5,0.1,0.3",
                "--engine",
                "rapier2d",
                "--period",
                "1e-6",
            ],
            "--period",
        ),
    ] {
        let out = dir.path().join("o");
        let clock = std::time::Instant::now();
        let st = pushval()
            .arg(args[0])
            .arg(root().join("scenarios/paper-square-v1.0.toml"))
            .args(&args[1..])
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(st.status.code(), Some(2), "{args:?}: {st:?}");
        let err = String::from_utf8_lossy(&st.stderr);
        assert!(err.contains(flag), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
        // A behaviour bound (refused before any search), not a benchmark.
        assert!(clock.elapsed().as_secs_f64() < 20.0, "{args:?}");
    }
}

/// The goal the old planner called unreachable with 6 pushes ("a turn or
/// a sideways move it cannot give") is reached once the search tries more
/// pushes, and plan.json says what it tried.
#[test]
fn the_search_tries_more_pushes_before_calling_a_goal_unreachable() {
    let p = plate();
    let goal = Goal {
        x: 0.5,
        y: 0.1,
        theta: 0.3,
    };
    let out = make_plan(
        &p,
        goal,
        spec(1.0, Predictor::Dynamic),
        Reach::default(),
        &Bounds::default(),
    )
    .unwrap();
    assert!(out.attempts.len() > 1, "it tried more pushes");
    if out.reached {
        assert!(out.why.is_none());
        // Checked independently: the default model at 1e-10 lands on the goal.
        let f = final_pose(&p, &out.solution.pushes);
        assert!((f[0] - goal.x).hypot(f[1] - goal.y) < 0.02, "{f:?}");
        assert!((f[2] - goal.theta).abs() < 5f64.to_radians(), "{f:?}");
        assert!(out.assumptions.pulling_impulse.is_none());
    } else {
        // Plans of more pushes reach it on the model but need a pulling
        // impulse: the reason says so first, not "a turn it cannot give".
        let refused: usize = out.attempts.iter().map(|a| a.refused_pulling).sum();
        assert!(refused > 0, "{:?}", out.why);
        let why = out.why.unwrap();
        assert!(
            why.starts_with(&format!("{refused} plans reach the goal")),
            "{why}"
        );
    }
}

/// A failed plan replaces the folder of an earlier success: no plan.toml is
/// left to be run as if it reached the goal.
#[test]
fn a_failed_plan_leaves_no_plan_toml() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p");
    let plan = |goal: &str| {
        pushval()
            .args(["plan"])
            .arg(root().join("scenarios/paper-square-v1.0.toml"))
            .args([goal, "--speed", "0.5", "--out"])
            .arg(&out)
            .output()
            .unwrap()
    };
    assert!(plan("--goal=0.8,0.2,-0.5").status.success());
    assert!(out.join("plan.toml").exists());
    let st = plan("--goal=-0.6,-0.6,0");
    assert_eq!(st.status.code(), Some(1));
    assert!(
        !out.join("plan.toml").exists(),
        "a stale plan.toml survived"
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
    assert_eq!(doc["reached"], false);
    assert!(
        doc["why_missed"].as_str().unwrap().contains("tried"),
        "{doc}"
    );
    // No temporary folder is left beside it.
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 1, "{left:?}");
}

#[test]
fn plan_writes_a_scenario_every_command_takes_and_its_checks() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plan");
    let st = pushval()
        .args(["plan"])
        .arg(root().join("scenarios/paper-square-v1.0.toml"))
        .args([
            "--goal=0.8,0.2,-0.5",
            "--speed",
            "1.0",
            "--at",
            "release",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
    assert_eq!(doc["at"], "release");
    assert!(doc["rest_pose"].is_null());
    assert!(!std::fs::read_to_string(out.join("plan.toml"))
        .unwrap()
        .contains("[release]"));
    assert_eq!(doc["converged"], true);
    assert_eq!(doc["reached"], true);
    assert!(doc["why_missed"].is_null());
    assert_eq!(doc["segments"].as_array().unwrap().len(), 6);
    assert!(doc["position_error_m"].as_f64().unwrap() < 1e-3);
    assert_eq!(doc["checks"]["switches"].as_array().unwrap().len(), 6);
    // The plan runs in an engine like any scenario and ends at the goal.
    let run = dir.path().join("run");
    let st = pushval()
        .args(["run"])
        .arg(out.join("plan.toml"))
        .arg("--out")
        .arg(&run)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let csv = std::fs::read_to_string(run.join("trajectory.csv")).unwrap();
    let last = csv
        .lines()
        .rfind(|l| l.starts_with("rapier2d,"))
        .unwrap()
        .split(',')
        .map(|f| f.parse::<f64>().unwrap_or(f64::NAN))
        .collect::<Vec<_>>();
    assert!((last[2] - 0.8).hypot(last[3] - 0.2) < 0.02, "{last:?}");
}

#[test]
fn an_unreachable_goal_exits_1_naming_the_nearest_pose() {
    let dir = tempfile::tempdir().unwrap();
    // Behind the start: the pusher only pushes.
    let st = pushval()
        .args(["plan"])
        .arg(root().join("scenarios/paper-square-v1.0.toml"))
        .args(["--goal=-0.6,-0.6,0", "--speed", "0.5", "--out"])
        .arg(dir.path().join("p"))
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(1));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(err.contains("nearest pose"), "{err}");
}

#[test]
fn bad_goal_and_plant_exit_2_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    for (args, flag) in [
        (vec!["plan", "--goal=1,2"], "--goal"),
        (vec!["plan", "--goal=1,2,x"], "--goal"),
        (
            vec!["plan", "--goal=1,0,0", "--predictor", "magic"],
            "--predictor",
        ),
        (
            vec![
                "loop",
                "--goal=1,0,0",
                "--engine",
                "rapier2d",
                "--plant",
                "mu_scale=-1",
            ],
            "--plant",
        ),
        (
            vec!["loop", "--goal=1,0,0", "--engine", "no_such_engine"],
            "--engine",
        ),
    ] {
        let out = dir.path().join("o");
        let st = pushval()
            .arg(args[0])
            .arg(root().join("scenarios/paper-square-v1.0.toml"))
            .args(&args[1..])
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(st.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&st.stderr);
        assert!(err.contains(flag), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
}

#[test]
fn loop_writes_the_applied_push_and_loop_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("loop");
    let st = pushval()
        .args(["loop"])
        .arg(root().join("scenarios/paper-square-v1.0.toml"))
        .args(["--goal=0.8,0.2,-0.5", "--speed", "1.0", "--engine", "box2d"])
        .args([
            "--plant",
            "mu_scale=0.8,inertia_scale=1.2",
            "--at",
            "release",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("loop.json")).unwrap()).unwrap();
    assert_eq!(doc["success"], true);
    assert_eq!(doc["engine"], "box2d");
    assert_eq!(doc["plant"]["mu_scale"], 0.8);
    assert!(doc["predictor_us_median"].as_f64().unwrap() > 0.0);
    assert_eq!(doc["tolerance"]["position_m"], 0.02);
    for k in ["omega", "vx", "vy"] {
        assert!(doc["release_state"][k].as_f64().is_some(), "{k}: {doc}");
    }
    // applied.toml is the scenario the plant ran: `pushval run` on it
    // reproduces the loop's plant trajectory.
    let run = dir.path().join("run");
    let st = pushval()
        .arg("run")
        .arg(out.join("applied.toml"))
        .arg("--out")
        .arg(&run)
        .output()
        .unwrap();
    // Exit 0, or 1 where a gate of the plant against the model fails: the
    // rows are written either way.
    assert!(
        matches!(st.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let last_row = |csv: &str| -> Vec<f64> {
        csv.lines()
            .rfind(|l| l.starts_with("box2d,"))
            .unwrap()
            .split(',')
            .skip(1)
            .take(4)
            .map(|f| f.parse::<f64>().unwrap())
            .collect()
    };
    let a = last_row(&std::fs::read_to_string(out.join("trajectory.csv")).unwrap());
    let b = last_row(&std::fs::read_to_string(run.join("trajectory.csv")).unwrap());
    for (x, y) in a.iter().zip(&b) {
        assert!(
            (x - y).abs() < 1e-9,
            "loop {a:?}, run of applied.toml {b:?}"
        );
    }
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "model,t,x,y,theta,omega,speed,phi");
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        let speed: f64 = f[6].parse().unwrap();
        let phi: f64 = f[7].parse().unwrap();
        assert_eq!(speed, 1.0, "{l}");
        let w = 0.5 * 0.8_f64.atan();
        assert!((-w - 1e-9..=FRAC_PI_2 + w + 1e-9).contains(&phi), "{l}");
    }
}

#[test]
fn a_protocol_1_adapter_without_the_kit_is_a_plant_under_loop() {
    // plain_protocol1.py speaks protocol 1 with no kit: it cannot step, so
    // the loop replays the schedule applied so far every period, and says so.
    let dir = tempfile::tempdir().unwrap();
    let engines = dir.path().join("pushval.toml");
    std::fs::write(
        &engines,
        format!(
            "[engine.plain]\ncommand = [\"python3\", \"{}\"]\norder = 1\ndt = 0.001\ntimeout_s = 60\nversion = \"plain_protocol1.py\"\n",
            root().join("adapters/python/plain_protocol1.py").display()
        ),
    )
    .unwrap();
    let out = dir.path().join("loop");
    let st = pushval()
        .arg("--engines")
        .arg(&engines)
        .arg("loop")
        .arg(root().join("scenarios/paper-square-v1.0.toml"))
        .args([
            "--goal=0.3,0.4,0.3",
            "--speed",
            "1.0",
            "--engine",
            "plain",
            "--at",
            "release",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("loop.json")).unwrap()).unwrap();
    assert_eq!(doc["success"], true);
    assert_eq!(doc["engine_replayed_each_period"], true);
    assert!(doc["steps"].as_u64().unwrap() >= 5, "{doc}");
}

/// A control-study list may name an engine this build lacks: the shard of
/// the engines it has runs (one engine per `K/N` range shard when N is the
/// number of engines), the other shard says which engine is missing and
/// why, and the merge names the shard still to run.
#[test]
fn a_shard_needs_only_its_own_engines() {
    if cfg!(feature = "mujoco") {
        return; // mujoco_elliptic is compiled in: nothing is missing.
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    let study = |extra: &[&str]| {
        pushval()
            .current_dir(root())
            .args([
                "control-study",
                "--quick",
                "--only",
                "rapier2d,mujoco_elliptic",
            ])
            .args(extra)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap()
    };
    let first = study(&["--shard", "1/2"]);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let part = std::fs::read_to_string(out.join("parts/control-1-of-2.csv")).unwrap();
    let rows = part.lines().skip(1).count();
    assert!(rows > 0 && rows % 8 == 0, "{rows} rows in part 1");
    let second = study(&["--shard", "2/2"]);
    assert!(!second.status.success());
    let err = String::from_utf8_lossy(&second.stderr);
    assert!(
        err.contains("mujoco_elliptic") && err.contains("not available"),
        "{err}"
    );
    let merge = study(&["--merge"]);
    assert!(!merge.status.success());
    let err = String::from_utf8_lossy(&merge.stderr);
    assert!(err.contains("2/2"), "{err}");
}

/// A `--only` list that names nothing, an unknown engine or one engine
/// twice is bad input: exit 2 naming the flag, nothing written.
#[test]
fn control_study_only_lists_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    for (list, says) in [
        (",", "names no engine"),
        ("no_such_engine", "no_such_engine"),
        ("rapier2d,rapier2d", "named twice"),
    ] {
        let st = pushval()
            .current_dir(root())
            .args(["control-study", "--quick", "--only", list, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(st.status.code(), Some(2), "{list}");
        let err = String::from_utf8_lossy(&st.stderr);
        assert!(
            err.contains("--only") && err.contains(says),
            "{list}: {err}"
        );
        assert!(!out.exists(), "{list} wrote {}", out.display());
    }
}

/// Judged at rest (the default): the plan aims for the pose where the plate
/// stops after the pusher lets go. Checked independently: the dynamic model
/// at its default tolerance, run through the slide on the written
/// plan.toml, comes to rest at the goal, and the plate is still moving at
/// the release (so the rule is not the release's).
#[test]
fn a_plan_judged_at_rest_stops_at_the_goal_after_its_slide() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plan");
    let st = pushval()
        .args(["plan"])
        .arg(root().join("scenarios/paper-square-v1.0.toml"))
        .args(["--goal=0.8,0.2,-0.5", "--speed", "1.0", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
    assert_eq!(doc["at"], "rest");
    let sc = pushval::registry::load(out.join("plan.toml")).unwrap();
    let p = sc.problem();
    assert!(p.release.is_some(), "plan.toml carries [release]");
    let traj = DynamicModel::default().simulate(&p).unwrap();
    let rest = *traj.samples.last().unwrap();
    let slide = traj.slide.as_ref().unwrap();
    let t_stop = slide.t_stop.expect("the plate stops");
    assert!(t_stop > slide.t_release + 0.05, "{slide:?}");
    assert!((rest.x - GOAL.x).hypot(rest.y - GOAL.y) < 2e-3, "{rest:?}");
    assert!((rest.theta - GOAL.theta).abs() < 5e-3, "{rest:?}");
    // At the release the plate is elsewhere: the slide matters at 1 m/s.
    let release = traj
        .samples
        .iter()
        .rfind(|s| s.t <= slide.t_release + 1e-9)
        .unwrap();
    assert!(
        (release.x - rest.x).hypot(release.y - rest.y) > 0.02,
        "{release:?} {rest:?}"
    );
}

/// A loop judged at rest releases the plant after the last push and judges
/// the pose where it stops: on a nominal Box2D plate (Coulomb per support,
/// the model's law) it reaches the goal at rest, and the rest comes after
/// the release with the plate stopped.
#[test]
fn a_loop_judged_at_rest_releases_the_plant_and_judges_its_rest() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("loop");
    let st = pushval()
        .args(["loop"])
        .arg(root().join("scenarios/paper-square-v1.0.toml"))
        .args([
            "--goal=0.8,0.2,-0.5",
            "--speed",
            "0.5",
            "--engine",
            "box2d",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("loop.json")).unwrap()).unwrap();
    assert!(
        st.status.success(),
        "{}\n{doc}",
        String::from_utf8_lossy(&st.stderr)
    );
    assert_eq!(doc["at"], "rest");
    let rest = &doc["rest_pose"];
    let release = &doc["release_state"];
    assert!(rest["t"].as_f64().unwrap() > release["t"].as_f64().unwrap());
    let v = release["vx"]
        .as_f64()
        .unwrap()
        .hypot(release["vy"].as_f64().unwrap());
    assert!(v > 0.1, "the plate moves at the release: {release}");
    let d = (rest["x"].as_f64().unwrap() - GOAL.x).hypot(rest["y"].as_f64().unwrap() - GOAL.y);
    assert!(d < 0.02, "{doc}");
    assert!(std::fs::read_to_string(out.join("applied.toml"))
        .unwrap()
        .contains("[release]"));
}

/// The control study judges every run by both rules: the quick grid in
/// rapier2d (Coulomb friction at every support, the model's law) has each
/// (predictor, mode, plant) at the release and at rest, runs.csv's `at` is
/// the rule asked and `judged_at` what judged it (rapier2d releases, so the
/// same). From the physics: at 1 m/s the plate slides v²/(2μg) ≈ 0.1 m
/// after the release (μ = 0.5), five tolerances, yet the dynamic plans aimed
/// at rest reach, open loop on the nominal plant, the goals the plans aimed
/// at the release reach (within one), and their median miss at rest is
/// inside the 20 mm tolerance: the model's slide is the engine's.
#[test]
fn the_control_study_judges_both_rules_and_a_coulomb_engine_keeps_its_goals_at_rest() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    let st = pushval()
        .current_dir(root())
        .args(["control-study", "--quick", "--only", "rapier2d", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let table = |name: &str| -> (Vec<String>, Vec<Vec<String>>) {
        let text = std::fs::read_to_string(out.join(name)).unwrap();
        let mut lines = text.lines();
        let head = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| l.split(',').map(String::from).collect())
            .collect();
        (head, rows)
    };
    let col = |head: &[String], name: &str| head.iter().position(|h| h == name).unwrap();
    let (head, rows) = table("runs.csv");
    let (at, judged) = (col(&head, "at"), col(&head, "judged_at"));
    // 3 goals × 2 predictors × 2 modes × 2 plants, per rule, at 1 m/s.
    for rule in ["release", "rest"] {
        let n = rows.iter().filter(|r| r[at] == rule).count();
        assert_eq!(n, 24, "{rule}: {n} runs");
    }
    assert_eq!(rows.len(), 48);
    for r in &rows {
        assert_eq!(r[at], r[judged], "{r:?}");
    }
    let (head, rows) = table("success.csv");
    let (at, pr, mode, plant, ok, goals, pe, judged) = (
        col(&head, "at"),
        col(&head, "predictor"),
        col(&head, "mode"),
        col(&head, "plant"),
        col(&head, "successes"),
        col(&head, "goals"),
        col(&head, "median_position_error_m"),
        col(&head, "judged_at"),
    );
    assert_eq!(rows.len(), 16, "8 groups per rule");
    let cell = |rule: &str| {
        rows.iter()
            .find(|r| {
                r[at] == rule && r[pr] == "dynamic" && r[mode] == "open" && r[plant] == "nominal"
            })
            .unwrap_or_else(|| panic!("no {rule} row"))
            .clone()
    };
    let (release, rest) = (cell("release"), cell("rest"));
    assert_eq!(rest[judged], "rest");
    assert_eq!(release[judged], "release");
    assert_eq!(rest[goals], "3");
    let n = |r: &Vec<String>, i: usize| r[i].parse::<f64>().unwrap();
    assert!(
        n(&rest, ok) >= n(&release, ok) - 1.0,
        "at rest {rest:?}, at the release {release:?}"
    );
    assert!(n(&rest, pe) < 0.02, "{rest:?}");
}
