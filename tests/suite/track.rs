//! `pushval track` and `pushval track-study`: the command streams estimates
//! from standard input as rows arrive and recovers known truths (the
//! dynamic model with μ × 1.1 and I_cm × 0.95, 1 mm / 1 mrad noise of a fixed
//! seed); bad input exits 2 naming the line and column with nothing
//! written; a model that cannot explain the data exits 1.

use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use pushval::fit::{noise, Param, Parametrised};
use pushval_model::{DynamicModel, Integrator, Sample, Simulator};
use pushval_scenario::Scenario;

use crate::common::{load, root};

fn pushval() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pushval"))
}

fn paper() -> Scenario {
    load(&root().join("scenarios/paper-square-v1.0.toml"))
}

/// The paper push with μ × `mu` and I_cm × `inertia`, sampled every 0.01 s,
/// plus 1 mm / 1 mrad noise (seed `seed`).
fn altered(sc: &Scenario, mu: f64, inertia: f64, seed: u64) -> Vec<Sample> {
    let pm = Parametrised::new(sc, &[Param::InertiaCm, Param::MuScale]).unwrap();
    let problem = pm.problem(&[sc.inertia_cm * inertia, mu]).unwrap();
    let exact = DynamicModel {
        integrator: Integrator::Dop853 { tol: 1e-11 },
        check_assumptions: false,
        ..Default::default()
    }
    .simulate(&problem)
    .unwrap()
    .samples;
    noise::add_noise(&exact, 1e-3, 1e-3, seed)
}

fn rows(samples: &[Sample]) -> Vec<String> {
    samples
        .iter()
        .map(|p| format!("{},{},{},{},{}", p.t, p.x, p.y, p.theta, p.omega))
        .collect()
}

fn track_cli(scenario: &Path, csv: &Path, out: &Path, extra: &[&str]) -> Output {
    pushval()
        .arg("track")
        .arg(scenario)
        .arg("--trajectory")
        .arg(csv)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Rows written to standard input come back as estimate rows on standard
/// output before the input ends (the first half is answered while the
/// second is still unwritten), and the run converges to the truth within
/// 1 % (μ), 2 % (I_cm) and 1 mm (centre of friction), naming the times.
#[test]
fn track_streams_from_stdin_and_recovers_mu_and_inertia() {
    let sc = paper();
    let data = altered(&sc, 1.1, 0.95, 11);
    let lines = rows(&data);
    let half = lines.len() / 2;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mut child = pushval()
        .arg("track")
        .arg(&sc.path)
        .args(["--trajectory", "-", "--out"])
        .arg(&out)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let stdout = child.stdout.take().unwrap();
    let (tx, rx) = mpsc::channel::<String>();
    let reader = std::thread::spawn(move || {
        for l in BufReader::new(stdout).lines() {
            if tx.send(l.unwrap()).is_err() {
                break;
            }
        }
    });
    writeln!(stdin, "t,x,y,theta,omega").unwrap();
    for l in &lines[..half] {
        writeln!(stdin, "{l}").unwrap();
    }
    stdin.flush().unwrap();
    // The header and one row per sample so far, with the input still open.
    let mut got = Vec::new();
    for _ in 0..=half {
        got.push(
            rx.recv_timeout(Duration::from_secs(60))
                .expect("an estimate row for every row written so far, before the input ends"),
        );
    }
    assert!(got[0].starts_with("t,center_of_friction_x,"), "{}", got[0]);
    let last_t: f64 = got[half].split(',').next().unwrap().parse().unwrap();
    assert!((last_t - data[half - 1].t).abs() < 1e-12);
    for l in &lines[half..] {
        writeln!(stdin, "{l}").unwrap();
    }
    drop(stdin);
    let status = child.wait().unwrap();
    reader.join().unwrap();
    got.extend(rx.try_iter());
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    assert_eq!(status.code(), Some(0), "{err}");
    assert_eq!(got.len(), lines.len() + 1);

    let j = read_json(&out.join("track.json"));
    let p = &j["parameters"];
    let mu = p["mu_scale"]["value"].as_f64().unwrap();
    let inertia = p["inertia_cm"]["value"].as_f64().unwrap();
    let c = p["center_of_friction"]["value"].as_array().unwrap();
    assert!((mu / 1.1 - 1.0).abs() < 0.01, "mu_scale {mu}");
    assert!(
        (inertia / (0.95 * sc.inertia_cm) - 1.0).abs() < 0.02,
        "inertia_cm {inertia}"
    );
    for (k, v) in c.iter().enumerate() {
        let v = v.as_f64().unwrap();
        assert!(
            (v - sc.center_of_mass[k]).abs() < 1e-3,
            "centre of friction {c:?}"
        );
    }
    for name in ["mu_scale", "inertia_cm", "center_of_friction"] {
        let at = j["converged_at"][name].as_f64().unwrap();
        assert!((0.0..=10.0).contains(&at), "{name}: {at}");
        assert!(p[name]["std"].is_number() || p[name]["std"].is_array());
    }
    assert!(j["update_time_median_s"].as_f64().unwrap() > 0.0);
    assert_eq!(j["converged"], true);
    // track.csv: one row per sample, the contract's columns.
    let csv = std::fs::read_to_string(out.join("track.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for col in [
        "t",
        "mu_scale",
        "mu_scale_std",
        "inertia_cm",
        "inertia_cm_std",
        "center_of_friction_x",
        "center_of_friction_y_std",
        "friction_force",
        "friction_moment",
        "friction_point_x",
        "friction_point_y",
    ] {
        assert!(header.contains(&col), "track.csv lacks {col}");
    }
    assert_eq!(csv.lines().count(), lines.len() + 1);
    // The friction force at the end: between the smallest (all supports
    // turning) and largest (pure translation) value, ≤ μ m g.
    let force = j["friction"]["force"].as_f64().unwrap();
    assert!(
        force > 0.0 && force <= 1.1 * 0.5 * 9.81 * (1.0 + 1e-9),
        "{force}"
    );
}

/// Input the command cannot use: exit 2, the message names the file (or
/// `<stdin>`), the line and the column, and nothing is written.
#[test]
fn track_bad_input_exits_2_naming_line_and_column() {
    let sc = paper();
    let data = altered(&sc, 1.0, 1.0, 3);
    let lines = rows(&data);
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, header: &str, body: &[String]| {
        let p = dir.path().join(name);
        let mut s = format!("{header}\n");
        for l in body {
            s += l;
            s += "\n";
        }
        std::fs::write(&p, s).unwrap();
        p
    };
    let mut bad_number = lines.clone();
    bad_number[4] = {
        let mut f: Vec<&str> = bad_number[4].split(',').collect();
        f[1] = "abc";
        f.join(",")
    };
    let mut backwards = lines.clone();
    backwards.swap(7, 8);
    let mut beyond = lines.clone();
    beyond.push("10.5,0,0,0,0".into());
    let two: Vec<String> = lines[..3]
        .iter()
        .map(|l| format!("a,{l}"))
        .chain(lines[3..6].iter().map(|l| format!("b,{l}")))
        .collect();
    let header = "t,x,y,theta,omega";
    let cases: Vec<(std::path::PathBuf, &str, Vec<&str>)> = vec![
        (
            write("no_theta.csv", "t,x,y,omega", &[]),
            "mu_scale",
            vec!["no_theta.csv", "line 1", "`theta`"],
        ),
        (
            write("number.csv", header, &bad_number),
            "mu_scale",
            vec!["number.csv", "line 6", "column `x`", "abc"],
        ),
        (
            write("backwards.csv", header, &backwards),
            "mu_scale",
            vec!["backwards.csv", "line 10", "column `t`"],
        ),
        (
            write("beyond.csv", header, &beyond),
            "mu_scale",
            vec!["beyond.csv", "line 1003", "schedule"],
        ),
        (
            write("fields.csv", header, &["0,0,0".to_string()]),
            "mu_scale",
            vec!["fields.csv", "line 2", "3 fields"],
        ),
        (
            write("two.csv", &format!("model,{header}"), &two),
            "mu_scale",
            vec!["two.csv", "line 5", "--model"],
        ),
        (
            write("empty.csv", header, &[]),
            "mu_scale",
            vec!["empty.csv", "no data rows"],
        ),
        (
            write("ok.csv", header, &lines),
            "mu_scale,friction",
            vec!["--params", "friction"],
        ),
        (
            write("ok2.csv", header, &lines),
            "contact",
            vec!["--params", "contact"],
        ),
    ];
    for (i, (csv, params, words)) in cases.iter().enumerate() {
        let out = dir.path().join(format!("out{i}"));
        let st = track_cli(&sc.path, csv, &out, &["--params", params]);
        let err = String::from_utf8_lossy(&st.stderr);
        assert_eq!(st.status.code(), Some(2), "case {i}: {err}");
        for w in words {
            assert!(err.contains(w), "case {i}: `{w}` not in: {err}");
        }
        assert!(!out.exists(), "case {i}: nothing may be written");
    }
    // The same from standard input names `<stdin>`.
    let out = dir.path().join("stdin_out");
    let mut child = pushval()
        .arg("track")
        .arg(&sc.path)
        .args(["--trajectory", "-", "--out"])
        .arg(&out)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    writeln!(stdin, "{header}\n{}\n0.01,1,2,x,0", lines[0]).unwrap();
    drop(stdin);
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("<stdin>: line 3: column `theta`"), "{err}");
    assert!(!out.exists());
}

/// μ held at the file's value (`--params inertia_cm`) on data made with
/// μ × 1.1: the model cannot explain the data; the lack of fit is reported
/// on standard error while the rows stream and the exit is 1.
#[test]
fn track_exits_1_when_the_model_cannot_explain_the_data() {
    let sc = paper();
    let data = altered(&sc, 1.1, 1.0, 5);
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("t.csv");
    let mut s = String::from("t,x,y,theta,omega\n");
    for l in rows(&data) {
        s += &l;
        s += "\n";
    }
    std::fs::write(&csv, s).unwrap();
    let out = dir.path().join("out");
    let st = track_cli(&sc.path, &csv, &out, &["--params", "inertia_cm"]);
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(st.status.code(), Some(1), "{err}");
    assert!(err.contains("lack of fit at t ="), "{err}");
    assert!(err.contains("does not explain the data"), "{err}");
    let j = read_json(&out.join("track.json"));
    assert!(!j["lack_of_fit"].as_array().unwrap().is_empty());
    assert_eq!(j["converged"], false);
}

/// `pushval track-study --quick` writes its tables, figure and text, and
/// every number of the text's cost table is in `track_cost.csv`.
#[test]
fn track_study_quick_writes_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let st = pushval()
        .args(["track-study", "--quick", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(
        st.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    for f in [
        "track_cost.csv",
        "track_convergence.csv",
        "track_efficiency.csv",
        "track_step.csv",
        "track_engines.csv",
        "track.svg",
        "track.md",
    ] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
    let cost = std::fs::read_to_string(dir.path().join("track_cost.csv")).unwrap();
    let md = std::fs::read_to_string(dir.path().join("track.md")).unwrap();
    for l in cost.lines().skip(1) {
        let f: Vec<&str> = l.split(',').collect();
        assert!(
            md.contains(&format!("| {} | {} | {} |", f[0], f[3], f[4])),
            "{l}"
        );
    }
    let engines = std::fs::read_to_string(dir.path().join("track_engines.csv")).unwrap();
    assert!(engines.lines().any(|l| l.starts_with("rapier2d,")));
    assert!(engines.lines().any(|l| l.starts_with("dynamic,")));
}

/// Every number with three or more decimals in the README's `track`
/// section (README.md once merged, else README-track-section.md) appears in
/// one of `results/track_*.csv`: the README quotes the files, it does not
/// round or invent.
#[test]
fn readme_track_numbers_come_from_the_results_files() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let marker = "### Online friction estimation: `pushval track`";
    let section = match readme.find(marker) {
        Some(i) => {
            let rest = &readme[i + marker.len()..];
            let end = rest
                .find("\n## ")
                .or_else(|| rest.find("\n### "))
                .unwrap_or(rest.len());
            rest[..end].to_string()
        }
        None => std::fs::read_to_string(root().join("README-track-section.md")).unwrap(),
    };
    let mut results = String::new();
    for e in std::fs::read_dir(root().join("results")).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if name.starts_with("track_") && name.ends_with(".csv") {
            results += &std::fs::read_to_string(&p).unwrap();
        }
    }
    let mut checked = 0;
    for token in section.split(|c: char| !(c.is_ascii_digit() || c == '.')) {
        let token = token.trim_matches('.');
        if let Some((_, frac)) = token.split_once('.') {
            if frac.len() >= 3 {
                assert!(
                    results.contains(token),
                    "README number {token} is in no results/track_*.csv"
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 10, "only {checked} numbers checked");
}

/// `track`'s final estimate obeys the fit's degeneracy rule: a μ scale near
/// zero (a frictionless plate) or an I_cm near zero explains nothing, and
/// says which; the truth of the paper push (μ × 1.1, I_cm × 0.95) does not.
#[test]
fn a_degenerate_final_estimate_is_reported() {
    use pushval::track::{summary, Outcome, Row};
    let sc = paper();
    let row = |mu: f64, inertia: f64| Row {
        t: 1.0,
        value: [mu, 0.0, 0.0, inertia],
        std: [0.0; 4],
        force: 0.0,
        moment: 0.0,
        point: pushval_model::Vec2::zeros(),
        friction_std: [0.0; 4],
        nis: 0.0,
        lack_of_fit: false,
        update_time: 1e-6,
    };
    let outcome = |r: Row| Outcome {
        rows: vec![r],
        episodes: vec![],
        lack_at_end: false,
        diverged: None,
        omega_read: true,
    };
    let params = [Param::MuScale, Param::InertiaCm];
    let settings = pushval_model::track::EkfSettings::default();
    let (json, _, why) = summary(&sc, &params, &settings, &outcome(row(2.5e-9, 2.1e-9)));
    assert_eq!(why.len(), 2, "{why:?}");
    assert!(
        why[0].starts_with("mu_scale") && why[1].starts_with("inertia_cm"),
        "{why:?}"
    );
    assert_eq!(json["converged"], false);
    let (json, _, why) = summary(
        &sc,
        &params,
        &settings,
        &outcome(row(1.1, 0.95 * sc.inertia_cm)),
    );
    assert!(why.is_empty(), "{why:?}");
    assert_eq!(json["degenerate"], serde_json::json!([]));
}
