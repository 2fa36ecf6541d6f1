//! The catalogue of friction laws (`pushval-laws`): `pushval laws` lists
//! every law, every compiled-in engine's declared law is the catalogue's
//! under its name, outside engines may declare any of them with parameters,
//! and the regularised laws reach Coulomb's in the limit v_s → 0.

use std::f64::consts::FRAC_PI_4;
use std::process::Command;

use pushval::study::plate::paper_plate;
use pushval_engine::FrictionLaw;
use pushval_laws::{catalog, law_entry};
use pushval_model::{Problem, Vec2};

use crate::common::root;

fn pushval() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_pushval"));
    c.current_dir(root());
    c
}

/// The paper plate pushed at its corner at `speed`, φ = π/4 + 0.3, for 2 s.
fn plate(speed: f64) -> Problem {
    paper_plate(speed, FRAC_PI_4 + 0.3, 2.0, None)
}

/// The law's steady ω, class and loads on `p` at dt = 1 ms.
#[track_caller]
fn assert_same_law(a: &dyn FrictionLaw, b: &dyn FrictionLaw, p: &Problem, what: &str) {
    assert_eq!(a.law_name(), b.law_name(), "{what}");
    let (sa, sb) = (a.steady(p, 0, 1e-3), b.steady(p, 0, 1e-3));
    assert_eq!(sa.is_some(), sb.is_some(), "{what}");
    if let (Some(sa), Some(sb)) = (sa, sb) {
        assert_eq!(
            sa.omega.to_bits(),
            sb.omega.to_bits(),
            "{what}: {sa:?} {sb:?}"
        );
        assert_eq!(sa.class.as_str(), sb.class.as_str(), "{what}");
    }
    assert_eq!(a.loads(p, 0, 1e-3), b.loads(p, 0, 1e-3), "{what}");
}

/// `pushval laws` prints one row per catalogue law, in catalogue order,
/// and `--json` the same names with their parameters.
#[test]
fn pushval_laws_lists_every_catalogue_law() {
    let o = pushval().arg("laws").output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let rows: Vec<&str> = text
        .lines()
        .skip(1)
        .take_while(|l| !l.is_empty())
        .filter(|l| !l.starts_with(' '))
        .map(|l| l.split_whitespace().next().unwrap())
        .collect();
    let names: Vec<&str> = catalog().iter().map(|e| e.name).collect();
    assert_eq!(rows, names, "{text}");
    // The repository's pushval.toml declares `pybullet_contact` with
    // Bullet's rows on the disc: the row names it among the engines.
    let rows_disk = text
        .lines()
        .find(|l| l.starts_with("impulse_rows_disk "))
        .unwrap();
    assert!(rows_disk.contains("pybullet_contact"), "{rows_disk}");

    let o = pushval().args(["laws", "--json"]).output().unwrap();
    assert!(o.status.success());
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let laws = json.as_array().unwrap();
    let json_names: Vec<&str> = laws.iter().map(|l| l["name"].as_str().unwrap()).collect();
    assert_eq!(json_names, names);
    let tanh = &laws[names.iter().position(|n| *n == "regularised_tanh").unwrap()];
    assert_eq!(tanh["params"][0]["name"], "slip_speed");
    assert_eq!(tanh["params"][0]["default"], 0.01);
    assert_eq!(tanh["params"][0]["unit"], "m/s");
    assert_eq!(tanh["loads"], "problem");
    assert!(tanh["engines"]
        .as_array()
        .unwrap()
        .contains(&"rapier2d_regularised_tanh".into()));
    for l in laws {
        assert!(
            ["problem", "law"].contains(&l["loads"].as_str().unwrap()),
            "{l}"
        );
        assert!(!l["about"].as_str().unwrap().is_empty());
    }
}

/// The compiled-in models each catalogue law has, as the listing joins them
/// (the catalogue names no engine: each model declares its law through
/// `Engine::law`). Columns: law, models in registry order.
const DECLARED: &[(&str, &[&str])] = &[
    ("coulomb", &["rapier2d", "box2d", "avian2d"]),
    ("impulse_disk", &["rapier2d_impulse_disk"]),
    ("impulse_box", &["rapier2d_impulse_box"]),
    ("impulse_rows_disk", &[]),
    ("regularised_linear", &["rapier2d_regularised_linear"]),
    ("regularised_tanh", &["rapier2d_regularised_tanh"]),
    ("rapier3d_contact_disk", &["rapier3d"]),
    ("rapier3d_simplified_twist", &["rapier3d_simplified"]),
    ("mujoco_elliptic", &["mujoco_elliptic"]),
    ("physx_patch", &["physx_patch"]),
    ("physx_two_directional", &["physx_two_directional"]),
    ("physx_one_directional", &["physx_one_directional"]),
    ("box2d_motor_joint", &["box2d_motor_joint"]),
    ("avian3d_tilt", &["avian3d"]),
    ("jolt_box", &["jolt_box"]),
    ("jolt_feet", &["jolt_feet"]),
    ("drake_sap", &[]),
    ("drake_similar", &[]),
];

/// The listing's join of engines to laws: every compiled-in model that
/// declares a law (with default options) is listed under exactly one
/// catalogue law, whose default value is the same law (same name, steady ω
/// bit for bit, class and loads on the paper plate), the join is the one
/// `DECLARED` states, and the join's key (`registry::law_key`: a law's
/// catalogue name where it has one, else its name) tells the catalogue's
/// laws apart.
#[test]
fn every_compiled_in_law_is_in_the_catalogue() {
    let models: Vec<_> = pushval::registry::ENGINE_CRATES
        .iter()
        .flat_map(|c| (c.models)())
        .collect();
    let keys: Vec<&str> = catalog()
        .iter()
        .map(|e| pushval::registry::law_key(&*e.default_law()))
        .collect();
    for (i, k) in keys.iter().enumerate() {
        assert!(
            !keys[..i].contains(k),
            "two catalogue laws have the key {k:?}"
        );
    }
    // Other tests load pushval.toml files: keep the compiled-in models.
    let joined: Vec<(String, Vec<String>)> = pushval::registry::declarations()
        .into_iter()
        .map(|(e, engines)| {
            let compiled = engines
                .into_iter()
                .filter(|n| models.iter().any(|m| m.name == n))
                .collect();
            (e.name.to_string(), compiled)
        })
        .collect();
    let want: Vec<(String, Vec<String>)> = DECLARED
        .iter()
        .map(|(l, ms)| (l.to_string(), ms.iter().map(|m| m.to_string()).collect()))
        .collect();
    assert_eq!(joined, want);
    let p = plate(0.5);
    let mut declared = 0;
    for m in &models {
        let engine = m.default_engine();
        let under: Vec<&str> = joined
            .iter()
            .filter(|(_, ms)| ms.iter().any(|n| n == m.name))
            .map(|(l, _)| l.as_str())
            .collect();
        let Some(law) = engine.law() else {
            assert!(under.is_empty(), "{} declares no law", m.name);
            continue;
        };
        declared += 1;
        assert_eq!(under.len(), 1, "{}: listed under one law", m.name);
        let entry = law_entry(under[0]).unwrap();
        assert_same_law(law, &*entry.default_law(), &p, m.name);
    }
    // Every model but mujoco_pyramidal declares one.
    assert_eq!(declared, models.len() - 1);
}

/// Outside engines declaring `jolt_feet` and `mujoco_elliptic` (with
/// heights as `law_params`) are accepted; the law the registry gives them
/// is the catalogue's law with those parameters, value for value; the
/// parameters reach it (raised, the elliptic cone's loads leave the equal
/// rest loads m g/4 of the square plate and its ω leaves Coulomb's).
#[test]
fn outside_engines_declare_catalogue_laws_with_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("pushval.toml");
    std::fs::write(
        &file,
        "[engine.feet_sim]\ncommand = [\"python3\", \"sim.py\"]\nlaw = \"jolt_feet\"\n\n\
         [engine.cone_sim]\ncommand = [\"python3\", \"sim.py\"]\nlaw = \"mujoco_elliptic\"\n\
         law_params = { cm_height = 0.02, push_height = 0.05 }\n",
    )
    .unwrap();
    let config = pushval_outside::Config::from_path(&file).unwrap();
    let p = plate(0.5);
    for spec in &config.engines {
        let law = pushval::registry::outside_law(spec)
            .unwrap_or_else(|e| panic!("{e}"))
            .expect("declared");
        match spec.name.as_str() {
            "feet_sim" => {
                assert_same_law(&*law, &pushval_laws::jolt::JoltFeet, &p, "feet_sim");
                assert!(law.steady(&p, 0, 1e-3).unwrap().omega.is_finite());
            }
            "cone_sim" => {
                let direct = pushval_laws::mujoco::MujocoElliptic {
                    cm_height: 0.02,
                    push_height: 0.05,
                    gravity: 9.81,
                };
                assert_same_law(&*law, &direct, &p, "cone_sim");
                let loads = law.loads(&p, 0, 1e-3).unwrap();
                let w = p.body.mass() * 9.81;
                assert!((loads.iter().sum::<f64>() - w).abs() < 1e-9, "{loads:?}");
                assert!(
                    loads.iter().any(|n| (n - w / 4.0).abs() > 1e-3),
                    "{loads:?}"
                );
                let star = pushval_engine::coulomb_steady(&p, 0).unwrap();
                let omega = law.steady(&p, 0, 1e-3).unwrap().omega;
                assert!((omega - star).abs() > 1e-6 * star.abs(), "{omega} {star}");
            }
            other => panic!("{other}"),
        }
    }
    // The command line accepts the file and lists both under their laws.
    let o = pushval()
        .arg("--engines")
        .arg(&file)
        .args(["laws", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let engines_of = |name: &str| {
        json.as_array()
            .unwrap()
            .iter()
            .find(|l| l["name"] == name)
            .unwrap()["engines"]
            .clone()
    };
    assert!(engines_of("jolt_feet")
        .as_array()
        .unwrap()
        .contains(&"feet_sim".into()));
    assert!(engines_of("mujoco_elliptic")
        .as_array()
        .unwrap()
        .contains(&"cone_sim".into()));
}

/// Bad laws in `pushval.toml`: exit 2 naming the file and the key.
#[test]
fn bad_outside_laws_name_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("pushval.toml");
    for (table, key, says) in [
        (
            "law = \"stribeck\"",
            "engine.sim.law",
            "unknown law \"stribeck\"; known: coulomb,",
        ),
        (
            "law = \"mujoco_elliptic\"\nlaw_params = { cm_hieght = 0.1 }",
            "engine.sim.law_params.cm_hieght",
            "unknown parameter; known for \"mujoco_elliptic\": cm_height, push_height, gravity",
        ),
        (
            "law = \"regularised_tanh\"\nlaw_params = { slip_speed = -1 }",
            "engine.sim.law_params.slip_speed",
            "must be finite and > 0, got -1",
        ),
        (
            "law = \"physx_patch\"\nlaw_params = { contacts = \"glued\" }",
            "engine.sim.law_params.contacts",
            "must be one of \"welded\", \"separate\"",
        ),
        (
            "law = \"regularised_tanh\"\nlaw_params = { slip_speed = [1] }",
            "engine.sim.law_params.slip_speed",
            "must be a number or a string",
        ),
        (
            "law_params = { slip_speed = 0.1 }",
            "engine.sim.law_params",
            "set `law` as well",
        ),
    ] {
        std::fs::write(
            &file,
            format!("[engine.sim]\ncommand = [\"python3\", \"sim.py\"]\n{table}\n"),
        )
        .unwrap();
        let o = pushval()
            .arg("--engines")
            .arg(&file)
            .arg("laws")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{table}: {err}");
        assert!(err.contains(&file.display().to_string()), "{err}");
        assert!(err.contains(&format!("{key}: ")), "{table}: {err}");
        assert!(err.contains(says), "{table}: {err}");
    }
}

/// The limit v_s → 0 of the regularised laws is Coulomb's law: with
/// v_s = 1e-6 m/s, far below every support's slip (checked > 0.01 m/s at
/// Coulomb's steady ω), the catalogue's `regularised_tanh` and
/// `regularised_linear` give the analytic model's ω* within 1e-6 rad/s.
#[test]
fn regularised_laws_reach_coulomb_as_the_slip_speed_vanishes() {
    for speed in [0.2, 0.5, 1.0] {
        let p = plate(speed);
        let star = pushval_engine::coulomb_steady(&p, 0).unwrap();
        let push = &p.pushes[0];
        let pc = p.body.contact();
        for s in p.body.supports() {
            let d = s.position - pc;
            let u = push.velocity() + Vec2::new(-d.y, d.x) * star;
            assert!(
                u.norm() > 0.01,
                "support at {:?} slides at {}",
                s.position,
                u.norm()
            );
        }
        for name in ["regularised_tanh", "regularised_linear"] {
            let mut params = serde_json::Map::new();
            params.insert("slip_speed".into(), 1e-6.into());
            let law = law_entry(name).unwrap().build(&params).unwrap();
            let w = law.steady(&p, 0, 1e-3).unwrap().omega;
            assert!(
                (w - star).abs() < 1e-6,
                "{name} at {speed} m/s: {w} vs {star}"
            );
        }
    }
}
