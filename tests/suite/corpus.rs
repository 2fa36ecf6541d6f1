//! The corpus of malformed scenario files in `tests/bad_scenarios/`, run
//! through the command-line binary, and the loader under arbitrary text.
//!
//! Each corpus file starts with `# expect: KEY: FRAGMENT`: `pushval run FILE
//! --out DIR` must exit 2, print an error naming the file, the key and the
//! fragment, and create nothing (not even DIR). An empty fragment accepts any
//! message (TOML syntax errors word themselves).

use std::path::{Path, PathBuf};
use std::process::Command;

use proptest::prelude::*;

use crate::common::root;

fn corpus() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("tests/bad_scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

/// `(key, fragment)` from the file's first line.
fn expectation(path: &Path) -> (String, String) {
    let bytes = std::fs::read(path).unwrap();
    let first = bytes.split(|b| *b == b'\n').next().unwrap();
    let line = std::str::from_utf8(first).unwrap();
    let rest = line
        .strip_prefix("# expect: ")
        .unwrap_or_else(|| panic!("{}: no `# expect:` line", path.display()));
    let (key, frag) = rest
        .split_once(": ")
        .unwrap_or((rest.trim_end_matches(':'), ""));
    (key.to_string(), frag.to_string())
}

#[test]
fn corpus_has_at_least_thirty_files_each_with_an_expectation() {
    let files = corpus();
    assert!(files.len() >= 30, "{} files", files.len());
    for f in &files {
        let (key, _) = expectation(f);
        assert!(!key.is_empty(), "{}", f.display());
    }
}

#[test]
fn every_bad_file_is_refused_by_the_loader_with_its_key_and_fragment() {
    let mut wrong = Vec::new();
    for f in corpus() {
        let (key, frag) = expectation(&f);
        match pushval::registry::load(&f) {
            Ok(_) => wrong.push(format!("{}: accepted", f.display())),
            Err(e) => {
                if e.key != key || !e.message.contains(&frag) || e.file != f {
                    wrong.push(format!("{}: expected {key}: {frag}; got {e}", f.display()));
                }
            }
        }
    }
    assert!(wrong.is_empty(), "\n{}", wrong.join("\n"));
}

#[test]
fn every_bad_file_exits_2_through_the_cli_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mut wrong = Vec::new();
    for (i, f) in corpus().iter().enumerate() {
        let (key, frag) = expectation(f);
        let out = dir.path().join(format!("out{i}"));
        let st = Command::new(env!("CARGO_BIN_EXE_pushval"))
            .arg("run")
            .arg(f)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&st.stderr);
        let named = format!("{}: {key}: ", f.display());
        if st.status.code() != Some(2) {
            wrong.push(format!("{}: exit {:?}", f.display(), st.status.code()));
        }
        if !err.contains(&named) || !err.contains(&frag) {
            wrong.push(format!(
                "{}: stderr lacks `{named}{frag}`: {err}",
                f.display()
            ));
        }
        if out.exists() {
            wrong.push(format!("{}: created {}", f.display(), out.display()));
        }
        if !st.stdout.is_empty() {
            wrong.push(format!("{}: printed to stdout", f.display()));
        }
    }
    // Nothing else appeared beside the outputs either.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    assert!(wrong.is_empty(), "\n{}", wrong.join("\n"));
}

#[test]
fn validate_refuses_a_mix_of_good_and_bad_files_before_any_work() {
    let good = root().join("scenarios/paper-square-v0.2.toml");
    let bad = root().join("tests/bad_scenarios/zero_mass.toml");
    let st = Command::new(env!("CARGO_BIN_EXE_pushval"))
        .arg("validate")
        .arg(&good)
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(2));
    assert!(
        st.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&st.stdout)
    );
    assert!(String::from_utf8_lossy(&st.stderr).contains("zero_mass.toml: object.mass"));
}

/// An interrupted run leaves no half-written file: outputs appear whole
/// (temporary file and rename) or not at all. Runs `pushval run` and kills
/// it at staggered moments; every file present afterwards is one of the two
/// outputs and complete, and no temporary file remains once a run finishes.
#[test]
fn killed_runs_leave_no_partial_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = root().join("scenarios/paper-square-v0.2.toml");
    let full = {
        let out = dir.path().join("full");
        let st = Command::new(env!("CARGO_BIN_EXE_pushval"))
            .arg("run")
            .arg(&scenario)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(st.status.success());
        let names = ["summary.json", "trajectory.csv"];
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 2);
        names.map(|n| std::fs::read_to_string(out.join(n)).unwrap())
    };
    for (k, delay_ms) in [5u64, 40, 120, 250, 400].iter().enumerate() {
        let out = dir.path().join(format!("killed{k}"));
        let mut child = Command::new(env!("CARGO_BIN_EXE_pushval"))
            .arg("run")
            .arg(&scenario)
            .arg("--out")
            .arg(&out)
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(*delay_ms));
        let _ = child.kill();
        child.wait().unwrap();
        if !out.exists() {
            continue;
        }
        for e in std::fs::read_dir(&out).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            match name.as_str() {
                "trajectory.csv" => {
                    assert_eq!(std::fs::read_to_string(&p).unwrap(), full[1], "{name}")
                }
                "summary.json" => {
                    // Whole and parseable (wall times differ between runs).
                    let text = std::fs::read_to_string(&p).unwrap();
                    serde_json::from_str::<serde_json::Value>(&text).unwrap();
                }
                // A kill between creating and renaming the temporary file can
                // leave it (SIGKILL runs no destructor); it never carries an
                // output's name, so no reader mistakes it for one.
                _ => assert!(name.starts_with(".tmp"), "unexpected file {name}"),
            }
        }
    }
}

const GOOD: &str = r#"name = "t"
[object]
mass = 1.0
polygon = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]
[supports]
points = [[-0.125,-0.125],[0.125,-0.125],[0.125,0.125],[-0.125,0.125]]
mu = 0.5
load = "statics"
[contact]
point = [-0.125, -0.125]
mu = 0.8
[initial]
theta = 0.1
from_rest = true
[[push]]
duration = 1.0
speed = 0.5
phi = 0.8
[run]
sample_dt = 0.01
switching = "continuous"
[tolerance]
theta_max = 0.02
[engine]
dt = 0.001
"#;

/// Tokens a mutation may splice in: numbers at the edges of their domains,
/// TOML punctuation, keys of other tables.
const TOKENS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "0",
    "-0.0",
    "1e308",
    "-1e-308",
    "[",
    "]",
    "=",
    "\"",
    "[[push]]",
    "[object]",
    "mass",
    "1",
    "true",
    "[]",
    "[[0,0]]",
    "\n",
    ",",
    "#",
    "'",
    "{",
    "}",
    "0x10",
    "1e400",
    "9999999999999999999999",
    "uniform_grid = 1e-9",
    "load = \"uniform\"",
    "gravity = 1e308",
    "mass = 1e300",
    "dt = 1e-300",
    "auto_ceiling = [1e-3]",
];

fn load_never_panics(text: &str) {
    // Ok or a ScenarioError; a valid scene must also build its problem.
    if let Ok(sc) = pushval::registry::from_toml(text, Path::new("fuzz.toml")) {
        let p = sc.problem();
        assert!(p.check().is_ok());
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    /// Arbitrary text: refused or accepted, never a panic.
    #[test]
    fn loader_never_panics_on_arbitrary_text(text in "\\PC{0,300}") {
        load_never_panics(&text);
    }

    /// Arbitrary text shaped like TOML (keys, tables, numbers).
    #[test]
    fn loader_never_panics_on_toml_like_text(
        text in "((\\[\\[?[a-z]{1,8}\\]\\]?|[a-z_]{1,12} = (-?[0-9.e]{1,6}|nan|inf|\"[a-z]{0,5}\"|\\[[0-9., \\[\\]-]{0,20}\\]))\n){0,20}"
    ) {
        load_never_panics(&text);
    }

    /// A valid file with a few bytes deleted, replaced or inserted.
    #[test]
    fn loader_never_panics_on_mutated_valid_files(
        edits in proptest::collection::vec((0usize..10_000, 0usize..4, 0usize..TOKENS.len()), 1..5)
    ) {
        let mut text = GOOD.to_string();
        for (pos, op, tok) in edits {
            let mut at = pos % (text.len() + 1);
            while !text.is_char_boundary(at) {
                at -= 1;
            }
            let end = (at + 1 + pos % 7).min(text.len());
            let end = (end..=text.len()).find(|e| text.is_char_boundary(*e)).unwrap();
            match op {
                0 => text.replace_range(at..end, ""),
                1 => text.replace_range(at..end, TOKENS[tok]),
                _ => text.insert_str(at, TOKENS[tok]),
            }
        }
        load_never_panics(&text);
    }

    /// Every number of the valid file replaced by an arbitrary f64 (NaN,
    /// infinities, subnormals, huge values included).
    #[test]
    fn loader_never_panics_on_arbitrary_numbers(
        values in proptest::collection::vec(proptest::num::f64::ANY, 40)
    ) {
        let mut k = 0;
        let mut out = String::new();
        let mut num = String::new();
        let flush = |num: &mut String, out: &mut String, k: &mut usize| {
            if !num.is_empty() {
                let v = values[*k % values.len()];
                *k += 1;
                let s = if v.is_nan() { "nan".to_string() } else if v.is_infinite() {
                    if v > 0.0 { "inf".into() } else { "-inf".into() }
                } else { format!("{v:e}") };
                out.push_str(&s);
                num.clear();
            }
        };
        for ch in GOOD.chars() {
            if ch.is_ascii_digit() || ch == '-' || (ch == '.' && !num.is_empty()) {
                num.push(ch);
            } else {
                flush(&mut num, &mut out, &mut k);
                out.push(ch);
            }
        }
        flush(&mut num, &mut out, &mut k);
        load_never_panics(&out);
    }
}
