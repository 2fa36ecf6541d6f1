//! The models as registry rows, with or without the `avian` feature.

use pushval_avian::{models, AVAILABLE};
use pushval_engine::EngineOptions;

/// Two rows, named as the models call themselves, with the engine crates
/// and their versions; available exactly when the feature is on, and
/// otherwise naming the feature.
#[test]
fn rows_name_the_models_and_the_feature() {
    let rows = models();
    let names: Vec<_> = rows.iter().map(|r| r.name).collect();
    assert_eq!(names, ["avian2d", "avian3d"]);
    for r in &rows {
        let e = r.default_engine();
        assert_eq!(e.name(), r.name);
        assert_eq!(e.engine_crate().name, r.name);
        assert_eq!(e.engine_crate().version, "0.7.0");
        assert_eq!(e.settings(1e-3)["dt"], 1e-3);
        assert_eq!(e.settings(1e-3)["substeps"], 16);
        let available = e.availability();
        assert_eq!(available.is_ok(), AVAILABLE);
        if let Err(why) = available {
            assert!(why.contains("--features avian"), "{why}");
        }
    }
}

/// `[engine] substeps` is read by both models and checked.
#[test]
fn substeps_option_is_read_and_checked() {
    let mut opts = EngineOptions::default();
    opts.values.insert("substeps".into(), serde_json::json!(4));
    for r in models() {
        let e = (r.build)(&opts).unwrap();
        assert_eq!(e.settings(1e-3)["substeps"], 4);
        assert!(e.option_keys().contains(&"substeps"));
    }
    for bad in [
        serde_json::json!(0),
        serde_json::json!(5000),
        serde_json::json!("x"),
    ] {
        opts.values.insert("substeps".into(), bad);
        for r in models() {
            let err = (r.build)(&opts).err().expect("refused");
            assert_eq!(err.key, "substeps");
        }
    }
}
