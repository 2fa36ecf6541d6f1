//! The one trajectory format (docs/architecture.md, "One trajectory format"): the same
//! trajectory with or without `model`, with or without `omega` and with a
//! column pushval does not know is accepted alike by `compare`, `fit` and
//! `track`; a file holding several models needs `--model NAME`; and a bad
//! field is named by file, line and column, in the same words by all three.
//!
//! The trajectory is the dynamic model's own run of the paper scenario
//! (DOP853 at 1e-11), so it agrees with the model; what is checked is that
//! the reading does not depend on the optional columns. `fit` and `track`
//! (without `--sigma-omega`) never use ω, so their answers must be the same
//! to the last digit whether ω was read or derived.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use pushval_model::{DynamicModel, Integrator, Sample, Simulator};

use crate::common::{load, root};

fn pushval() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pushval"))
}

fn scenario() -> PathBuf {
    root().join("scenarios/paper-square-v1.0.toml")
}

fn exact() -> Vec<Sample> {
    let sc = load(&scenario());
    DynamicModel {
        integrator: Integrator::Dop853 { tol: 1e-11 },
        check_assumptions: false,
        ..Default::default()
    }
    .simulate(&sc.problem())
    .unwrap()
    .samples
}

/// The samples as CSV with the columns `header` names (any of model, t, x,
/// y, theta, omega, note; `model` is `name`, `note` a word).
fn csv(samples: &[Sample], header: &str, name: &str) -> String {
    let mut s = format!("{header}\n");
    for p in samples {
        let f: Vec<String> = header
            .split(',')
            .map(|c| match c {
                "model" => name.to_string(),
                "t" => p.t.to_string(),
                "x" => p.x.to_string(),
                "y" => p.y.to_string(),
                "theta" => p.theta.to_string(),
                "omega" => p.omega.to_string(),
                _ => "n/a".to_string(),
            })
            .collect();
        s += &f.join(",");
        s += "\n";
    }
    s
}

fn run(cmd: &str, csv: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut c = pushval();
    c.arg(cmd).arg(scenario()).arg("--trajectory").arg(csv);
    if cmd != "compare" {
        c.args(["--params", "mu_scale", "--out"]).arg(out);
    }
    c.args(extra).output().unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn optional_columns_do_not_change_what_compare_fit_and_track_read() {
    let dir = tempfile::tempdir().unwrap();
    let samples = exact();
    let variants = [
        "model,t,x,y,theta,omega",
        "t,x,y,theta,omega",
        "model,t,x,y,theta",
        "theta,note,y,x,t",
    ];
    let mut fits = Vec::new();
    let mut tracks = Vec::new();
    for (i, header) in variants.iter().enumerate() {
        let file = dir.path().join(format!("v{i}.csv"));
        std::fs::write(&file, csv(&samples, header, "mine")).unwrap();
        let derived = !header.contains("omega");

        let o = run("compare", &file, &dir.path().join("c"), &[]);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(0), "{header}: {t}");
        assert_eq!(
            t.contains("omega derived from theta"),
            derived,
            "{header}: {t}"
        );

        let out = dir.path().join(format!("fit{i}"));
        let o = run("fit", &file, &out, &[]);
        assert_eq!(o.status.code(), Some(0), "{header}: {}", text(&o));
        assert_eq!(text(&o).contains("omega derived from theta"), derived);
        fits.push(json(&out.join("fit.json"))["parameters"].clone());

        let out = dir.path().join(format!("track{i}"));
        let o = run("track", &file, &out, &[]);
        assert_ne!(o.status.code(), Some(2), "{header}: {}", text(&o));
        let j = json(&out.join("track.json"));
        assert_eq!(
            j["settings"]["omega"]
                .as_str()
                .unwrap()
                .starts_with("absent"),
            derived
        );
        tracks.push((o.status.code(), j["parameters"].clone()));
    }
    // The exact trajectory: μ as in the file.
    let mu = fits[0]["mu_scale"]["value"].as_f64().unwrap();
    assert!((mu - 1.0).abs() < 1e-6, "{mu}");
    for i in 1..variants.len() {
        assert_eq!(fits[i], fits[0], "fit: {} vs {}", variants[i], variants[0]);
        assert_eq!(
            tracks[i], tracks[0],
            "track: {} vs {}",
            variants[i], variants[0]
        );
    }
}

/// Two models in one file: without `--model` all three commands exit 2 with
/// the same words, naming the file and every model; with it they read the
/// one named.
#[test]
fn a_file_of_several_models_needs_model_name() {
    let dir = tempfile::tempdir().unwrap();
    let samples = exact();
    let body = csv(&samples, "model,t,x,y,theta,omega", "mine");
    let other = csv(&samples, "model,t,x,y,theta,omega", "theirs");
    let third = csv(&samples[..3], "model,t,x,y,theta,omega", "third");
    let file = dir.path().join("several.csv");
    let skip_header = |s: &str| s.split_once('\n').unwrap().1.to_string();
    std::fs::write(
        &file,
        format!("{body}{}{}", skip_header(&other), skip_header(&third)),
    )
    .unwrap();
    let second_line = samples.len() + 2;
    let want = format!(
        "{}: line {second_line}: column `model`: the file holds more than one model (mine, theirs, third); choose one with --model NAME",
        file.display()
    );
    for cmd in ["compare", "fit", "track"] {
        let out = dir.path().join(cmd);
        let o = run(cmd, &file, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{cmd}: {err}");
        assert!(err.contains(&want), "{cmd}: {err}");
        assert!(!out.exists(), "{cmd}: nothing may be written");
        let o = run(cmd, &file, &out, &["--model", "theirs"]);
        assert_ne!(o.status.code(), Some(2), "{cmd}: {}", text(&o));
        let o = run(cmd, &file, &dir.path().join("x"), &["--model", "nobody"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{cmd}: {err}");
        assert!(
            err.contains(
                "column `model`: no rows of model `nobody` (the file holds mine, theirs, third)"
            ),
            "{cmd}: {err}"
        );
    }
}

/// A bad field, a missing column and a short row: exit 2 naming the file,
/// the line and the column in the same words from every command.
#[test]
fn format_errors_name_file_line_and_column_alike() {
    let dir = tempfile::tempdir().unwrap();
    let samples = exact();
    let good = csv(&samples, "t,x,y,theta", "");
    let mut lines: Vec<String> = good.lines().map(str::to_string).collect();
    lines[4] = "0.03,0,0,zz".into();
    let bad_field = lines.join("\n");
    let cases = [
        (
            "field.csv",
            bad_field,
            "line 5: column `theta`: `zz` is not a number",
        ),
        (
            "header.csv",
            good.replacen("t,x,y,theta", "t,x,why,theta", 1),
            "line 1: the header lacks the column `y`",
        ),
        (
            "short.csv",
            good.replacen("\n0.01,", "\n0.01,0\n0.01,", 1),
            "line 3: 2 fields, the header has 4",
        ),
        (
            "twice.csv",
            good.replacen("t,x,y,theta", "t,x,y,theta,x", 1),
            "line 1: column `x`: the header names this column twice",
        ),
    ];
    for (name, body, words) in cases {
        let file = dir.path().join(name);
        std::fs::write(&file, body).unwrap();
        let want = format!("{}: {words}", file.display());
        for cmd in ["compare", "fit", "track"] {
            let out = dir.path().join(format!("{cmd}-{name}"));
            let o = run(cmd, &file, &out, &[]);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{cmd} {name}: {err}");
            assert!(err.contains(&want), "{cmd} {name}: `{want}` not in {err}");
            assert!(!out.exists());
        }
    }
}
