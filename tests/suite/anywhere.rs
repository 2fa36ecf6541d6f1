//! pushval used outside its source tree: the installed binary in an empty
//! folder finds what it ships inside itself, finds `pushval.toml` in the
//! folder's parents as cargo finds `Cargo.toml`, and skips (with a note)
//! what a user's registry does not list.

use std::path::Path;
use std::process::Command;

fn pushval_in(dir: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_pushval"));
    c.current_dir(dir).env_remove("CI");
    c
}

/// An empty folder: the main job validates the shipped scenarios of the
/// compiled-in engines and passes; those of pushval's own outside engines
/// are skipped and named.
#[test]
fn main_job_in_an_empty_folder_runs_the_shipped_scenarios() {
    let dir = tempfile::tempdir().unwrap();
    let out = pushval_in(dir.path()).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(stdout.contains("every gated tolerance holds"), "{stdout}");
    assert!(stdout.contains("paper-square-v1.0"), "{stdout}");
    // pushval's own outside engine (declared in the repository's
    // pushval.toml) is not in this folder's registry.
    assert!(
        stderr.contains("skipping shipped:scenarios/outside-pure-python.toml"),
        "{stderr}"
    );
    // Nothing is written into the user's folder.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// `pushval shipped` writes the embedded files out, byte for byte the
/// repository's, and refuses to overwrite them without --force.
#[test]
fn shipped_writes_the_embedded_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = pushval_in(dir.path()).arg("shipped").output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    for rel in ["scenarios/paper-square-v1.0.toml", "studies/rapier2d.toml"] {
        let a = std::fs::read(dir.path().join(rel)).unwrap();
        let b = std::fs::read(repo.join(rel)).unwrap();
        assert_eq!(a, b, "{rel}");
    }
    assert!(dir
        .path()
        .join("schemas/pushval-problem-1.schema.json")
        .is_file());
    let again = pushval_in(dir.path()).arg("shipped").output().unwrap();
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("already exists"));
}

/// A `pushval.toml` in a parent folder applies in its subfolders; its
/// engines then appear in `pushval engines`.
#[test]
fn engines_file_is_found_in_a_parent_folder() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("pushval.toml"),
        "[engine.my_sim]\ncommand = [\"python3\", \"adapter.py\"]\norder = 1\n",
    )
    .unwrap();
    let sub = dir.path().join("a/b");
    std::fs::create_dir_all(&sub).unwrap();
    let out = pushval_in(&sub).arg("engines").output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert!(stdout.contains("my_sim"), "{stdout}");
    // --engines overrides the search: an empty file declares nothing.
    let empty = dir.path().join("empty.toml");
    std::fs::write(&empty, "").unwrap();
    let out = pushval_in(&sub)
        .arg("--engines")
        .arg(&empty)
        .arg("engines")
        .output()
        .unwrap();
    assert!(!String::from_utf8_lossy(&out.stdout).contains("my_sim"));
}

/// A study of a compiled-in engine runs in an empty folder: the study files
/// come from the binary, and those of models this registry lacks
/// (pybullet_contact) are skipped with a note, not fatal.
#[test]
fn study_runs_in_an_empty_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = pushval_in(dir.path())
        .args(["study", "rapier2d_impulse_disk", "--quick", "--out", "s"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("pybullet_contact"), "{stderr}");
    assert!(dir.path().join("s/map.csv").is_file());
}

/// `pushval init` in an empty folder, then the main job: the init adapter
/// (Coulomb forces per support, in Python) passes its gate; its trajectory
/// feeds `fit` and `track`, and `study` maps it. A second `init` refuses to
/// overwrite, exit 2 naming the file.
#[test]
fn init_then_gate_study_fit_and_track_in_an_empty_folder() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |args: &[&str]| {
        let out = pushval_in(d).args(args).output().unwrap();
        let text = format!(
            "{}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        (out.status.code(), text)
    };
    let (code, text) = run(&["init"]);
    assert_eq!(code, Some(0), "{text}");
    for f in ["pushval.toml", "adapter.py", "scenarios/my_engine.toml"] {
        assert!(d.join(f).is_file(), "{f}");
    }
    let (code, text) = run(&[]);
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.contains("my_engine") && text.contains("PASS"),
        "{text}"
    );
    let (code, text) = run(&["init"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("pushval.toml: already exists"), "{text}");
    let (code, text) = run(&["run", "scenarios/my_engine.toml", "--out", "r"]);
    assert_eq!(code, Some(0), "{text}");
    let (code, text) = run(&[
        "fit",
        "scenarios/my_engine.toml",
        "--trajectory",
        "r/trajectory.csv",
        "--model",
        "my_engine",
        "--params",
        "mu_scale",
        "--out",
        "f",
    ]);
    assert_eq!(code, Some(0), "{text}");
    let (code, text) = run(&[
        "track",
        "scenarios/my_engine.toml",
        "--trajectory",
        "r/trajectory.csv",
        "--model",
        "my_engine",
        "--params",
        "mu_scale",
        "--out",
        "k",
    ]);
    assert_eq!(code, Some(0), "{text}");
    let (code, text) = run(&["study", "my_engine", "--quick", "--out", "s"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(d.join("s/map.csv").is_file(), "{text}");
}
