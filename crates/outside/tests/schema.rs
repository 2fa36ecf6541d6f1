//! The emitted `pushval-problem/1` documents validate against the published
//! JSON Schema (adapters/pushval-problem-1.schema.json), read by a small
//! validator of the keywords that file uses; and the document carries the
//! scenario's own numbers.

use std::path::{Path, PathBuf};

mod common;

use pushval_outside::problem_document;
use pushval_scenario::Scenario;
use serde_json::Value;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn schema() -> Value {
    schema_file("adapters/pushval-problem-1.schema.json")
}

fn schema_file(path: &str) -> Value {
    let text = std::fs::read_to_string(root().join(path)).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The errors of `v` against `s` (the keywords the schema file uses; an
/// unknown keyword is itself an error, so the validator cannot silently
/// skip a rule).
fn check(v: &Value, s: &Value, root: &Value, at: &str, errors: &mut Vec<String>) {
    let obj = s.as_object().expect("a schema is an object");
    for (k, rule) in obj {
        match k.as_str() {
            "$schema" | "$id" | "title" | "description" | "$defs" => {}
            "$ref" => {
                let name = rule.as_str().unwrap().strip_prefix("#/$defs/").unwrap();
                check(v, &root["$defs"][name], root, at, errors);
            }
            "type" => {
                let ok = match rule.as_str().unwrap() {
                    "object" => v.is_object(),
                    "array" => v.is_array(),
                    "number" => v.is_number(),
                    "string" => v.is_string(),
                    "boolean" => v.is_boolean(),
                    "integer" => v.is_u64() || v.is_i64(),
                    t => panic!("type {t}"),
                };
                if !ok {
                    errors.push(format!("{at}: not {rule}: {v}"));
                }
            }
            "enum" => {
                if !rule.as_array().unwrap().contains(v) {
                    errors.push(format!("{at}: {v} not one of {rule}"));
                }
            }
            "const" => {
                if v != rule {
                    errors.push(format!("{at}: {v} != {rule}"));
                }
            }
            "required" => {
                for key in rule.as_array().unwrap() {
                    if v.get(key.as_str().unwrap()).is_none() {
                        errors.push(format!("{at}: missing {key}"));
                    }
                }
            }
            "additionalProperties" => {
                assert_eq!(rule, false);
                if let Some(o) = v.as_object() {
                    for key in o.keys() {
                        if obj["properties"].get(key).is_none() {
                            errors.push(format!("{at}: unexpected key {key}"));
                        }
                    }
                }
            }
            "properties" => {
                for (key, sub) in rule.as_object().unwrap() {
                    if let Some(x) = v.get(key) {
                        check(x, sub, root, &format!("{at}.{key}"), errors);
                    }
                }
            }
            "items" => {
                for (i, x) in v.as_array().into_iter().flatten().enumerate() {
                    check(x, rule, root, &format!("{at}[{i}]"), errors);
                }
            }
            "minItems" | "maxItems" => {
                let n = v.as_array().map_or(0, Vec::len) as u64;
                let bound = rule.as_u64().unwrap();
                if (k == "minItems" && n < bound) || (k == "maxItems" && n > bound) {
                    errors.push(format!("{at}: {n} items, {k} {bound}"));
                }
            }
            "minimum" | "exclusiveMinimum" => {
                let x = v.as_f64().unwrap_or(f64::NAN);
                let b = rule.as_f64().unwrap();
                if !(x > b || (k == "minimum" && x == b)) {
                    errors.push(format!("{at}: {x} below {k} {b}"));
                }
            }
            other => panic!("the validator does not know the keyword {other}"),
        }
    }
}

fn errors(doc: &Value) -> Vec<String> {
    let s = schema();
    let mut e = Vec::new();
    check(doc, &s, &s, "$", &mut e);
    e
}

fn doc_of(file: &str, dt: f64) -> (Scenario, Value) {
    let sc = Scenario::from_path(root().join("scenarios").join(file)).unwrap();
    let doc = problem_document("mysim", &sc.problem(), &common::options(&sc), dt);
    (sc, doc)
}

#[test]
fn every_shipped_scenario_gives_a_valid_document() {
    for entry in std::fs::read_dir(root().join("scenarios")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let name = path.file_name().unwrap().to_str().unwrap().to_string();
            let (sc, doc) = doc_of(&name, 1e-3);
            // A protocol 1 engine is refused a problem with a release (a
            // thrown plate has no push): its document is never written.
            if sc.release.is_some() {
                continue;
            }
            assert_eq!(errors(&doc), Vec::<String>::new(), "{name}");
        }
    }
}

#[test]
fn the_validator_rejects_broken_documents() {
    let (_, doc) = doc_of("paper-square-v1.0.toml", 1e-3);
    let mut missing = doc.clone();
    missing.as_object_mut().unwrap().remove("gravity");
    assert!(errors(&missing).iter().any(|e| e.contains("gravity")));
    let mut wrong = doc.clone();
    wrong["supports"][0]["normal_force"] = serde_json::json!(-1.0);
    assert!(errors(&wrong).iter().any(|e| e.contains("normal_force")));
    let mut extra = doc;
    extra["object"]["density"] = serde_json::json!(1.0);
    assert!(errors(&extra).iter().any(|e| e.contains("density")));
}

/// The document states the scenario's numbers in the file's frame: the
/// loads and μ as resolved, points not shifted to the centre of mass.
#[test]
fn the_document_carries_the_scenario_in_its_own_frame() {
    for file in [
        "paper-square-v1.0.toml",
        "triangle-statics.toml",
        "printed-inertia-v1.0.toml",
    ] {
        let (sc, doc) = doc_of(file, 2.5e-4);
        assert_eq!(doc["dt"], 2.5e-4);
        assert_eq!(doc["engine"], "mysim");
        assert_eq!(doc["object"]["mass"], sc.mass);
        assert_eq!(doc["gravity"], sc.gravity);
        let com = &doc["object"]["center_of_mass"];
        assert_eq!(com[0], sc.center_of_mass.x, "{file}");
        assert_eq!(com[1], sc.center_of_mass.y, "{file}");
        for (s, d) in sc.supports.iter().zip(doc["supports"].as_array().unwrap()) {
            let close =
                |a: &Value, b: f64| (a.as_f64().unwrap() - b).abs() <= 1e-12 * b.abs().max(1.0);
            assert!(
                close(&d["point"][0], s.position.x) && close(&d["point"][1], s.position.y),
                "{file}"
            );
            assert!(
                close(&d["mu"], s.mu) && close(&d["normal_force"], s.load),
                "{file}: {d}"
            );
        }
        let c = &doc["contact"]["point"];
        assert!(
            (c[0].as_f64().unwrap() - sc.contact.x).abs() < 1e-12,
            "{file}"
        );
        assert!(
            (c[1].as_f64().unwrap() - sc.contact.y).abs() < 1e-12,
            "{file}"
        );
        assert_eq!(doc["pushes"].as_array().unwrap().len(), sc.pushes.len());
        assert_eq!(doc["initial"]["from_rest"], sc.initial.from_rest);
    }
}

/// Without the scenario's frame (options built by hand), the document is
/// in the centre-of-mass frame and the loads carry m g in proportion to the
/// friction, so μ_i N_i is still the problem's friction.
#[test]
fn without_a_scene_the_loads_sum_to_the_weight() {
    let sc = Scenario::from_path(root().join("scenarios/triangle-statics.toml")).unwrap();
    let doc = problem_document("x", &sc.problem(), &Default::default(), 1e-3);
    assert_eq!(errors(&doc), Vec::<String>::new());
    let body = sc.problem().body;
    let n: f64 = doc["supports"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["normal_force"].as_f64().unwrap())
        .sum();
    assert!((n - body.mass() * 9.81).abs() < 1e-9);
    for (s, d) in body.supports().zip(doc["supports"].as_array().unwrap()) {
        let f = d["mu"].as_f64().unwrap() * d["normal_force"].as_f64().unwrap();
        assert!((f - s.friction).abs() < 1e-12, "{f} vs {}", s.friction);
    }
}

/// Version 2: every shipped scenario's document validates against
/// adapters/pushval-problem-2.schema.json, which is version 1's with
/// `switching` and `limits` added; a version 1 document does not.
#[test]
fn version_2_documents_validate_against_their_schema() {
    use pushval_outside::{problem_document_v2, Limits};
    let s2 = schema_file("adapters/pushval-problem-2.schema.json");
    let errors2 = |doc: &Value| {
        let mut e = Vec::new();
        check(doc, &s2, &s2, "$", &mut e);
        e
    };
    let mut switchings = std::collections::BTreeSet::new();
    for entry in std::fs::read_dir(root().join("scenarios")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let sc = Scenario::from_path(&path).unwrap();
            let p = sc.problem();
            let doc = problem_document_v2(
                "mysim",
                &p,
                &common::options(&sc),
                1e-3,
                Limits::for_problem(&p, 1e-3),
            );
            assert_eq!(errors2(&doc), Vec::<String>::new(), "{}", path.display());
            switchings.insert(doc["switching"].as_str().unwrap().to_string());
        }
    }
    assert!(switchings.contains("impulsive"), "{switchings:?}");
    let (_, v1) = doc_of("paper-square-v1.0.toml", 1e-3);
    let e = errors2(&v1);
    assert!(e.iter().any(|e| e.contains("missing \"limits\"")), "{e:?}");
    let s1 = schema();
    let mut required: Vec<Value> = s1["required"].as_array().unwrap().clone();
    required.extend([Value::from("switching"), Value::from("limits")]);
    assert_eq!(&s2["required"], &Value::from(required));
    let mut bad = problem_document_v2(
        "x",
        &doc_of("paper-square-v1.0.toml", 1e-3).0.problem(),
        &Default::default(),
        1e-3,
        Limits {
            max_rows: 10,
            max_bytes: 100,
        },
    );
    bad["switching"] = Value::from("smooth");
    bad["limits"]["max_rows"] = Value::from(1.5);
    let e = errors2(&bad);
    assert!(
        e.iter().any(|e| e.contains("switching")) && e.iter().any(|e| e.contains("max_rows")),
        "{e:?}"
    );
}
