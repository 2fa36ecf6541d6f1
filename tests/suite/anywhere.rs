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

/// The exit code and standard output + error of pushval run in `dir` with
/// `args`, with `TMPDIR` and `XDG_CACHE_HOME` set to `tmp` and `cache`.
fn run_with(dir: &Path, tmp: &Path, cache: &Path, args: &[&str]) -> (Option<i32>, String) {
    let out = pushval_in(dir)
        .args(args)
        .env("TMPDIR", tmp)
        .env("XDG_CACHE_HOME", cache)
        .output()
        .unwrap();
    let text = format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.code(), text)
}

/// The init adapter's Heun step (`step` in assets/init/adapter.py) replaced
/// by explicit Euler: first order in dt, everything else the same.
fn switch_init_adapter_to_euler(dir: &Path) {
    let p = dir.join("adapter.py");
    let text = std::fs::read_to_string(&p).unwrap();
    let heun = "        b = self.rates(self.theta + dt * a[0], self.omega + dt * a[1], push)
        self.theta += 0.5 * dt * (a[0] + b[0])
        self.omega += 0.5 * dt * (a[1] + b[1])
        self.x += 0.5 * dt * (a[2] + b[2])
        self.y += 0.5 * dt * (a[3] + b[3])";
    let euler = "        self.theta += dt * a[0]
        self.omega += dt * a[1]
        self.x += dt * a[2]
        self.y += dt * a[3]";
    assert!(
        text.contains(heun),
        "the init adapter's step changed: {text}"
    );
    std::fs::write(&p, text.replace(heun, euler)).unwrap();
}

/// The order the row reports as observed (`order P observed`).
fn observed_order(text: &str) -> f64 {
    let at = text.find(" observed, ").unwrap_or_else(|| panic!("{text}"));
    let head = &text[..at];
    let start = head.rfind("order ").unwrap() + "order ".len();
    head[start..]
        .parse()
        .unwrap_or_else(|e| panic!("{e}: {text}"))
}

/// Issue 40, item 1: the order is measured on the trajectory, not trusted.
/// Heun's method (the init adapter) is second order and shows it; explicit
/// Euler (first order, a truncation error O(dt) per unit time) declared as
/// order 2 fails the gate on the init scenario, naming both orders, where
/// the ladder's Richardson estimate (divided by 2^2 − 1 = 3 instead of 1)
/// would otherwise back a tolerance three times too tight for its error and
/// let it pass. Declared honestly, the order no longer fails it.
#[test]
fn a_first_order_step_declaring_order_2_fails_naming_both_orders() {
    let dir = tempfile::tempdir().unwrap();
    let (tmp, cache) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let d = dir.path();
    let run = |args: &[&str]| run_with(d, tmp.path(), cache.path(), args);
    let (code, text) = run(&["init"]);
    assert_eq!(code, Some(0), "{text}");
    let (code, text) = run(&[]);
    assert_eq!(code, Some(0), "{text}");
    let heun = observed_order(&text);
    assert!((1.8..=2.2).contains(&heun), "Heun: {heun}: {text}");

    switch_init_adapter_to_euler(d);
    let (code, text) = run(&[]);
    assert_eq!(code, Some(1), "{text}");
    let fail = text
        .lines()
        .find(|l| l.starts_with("FAIL my-engine-square / my_engine"))
        .unwrap_or_else(|| panic!("no FAIL line: {text}"));
    assert!(fail.contains("declares order 2"), "{fail}");
    let euler = observed_order(&text);
    assert!((0.8..=1.2).contains(&euler), "Euler: {euler}: {text}");
    assert!(fail.contains(&format!("shows order {euler:.2}")), "{fail}");

    let toml = d.join("pushval.toml");
    let decl = std::fs::read_to_string(&toml).unwrap();
    assert!(decl.contains("\norder = 2\n"), "{decl}");
    std::fs::write(&toml, decl.replace("\norder = 2\n", "\norder = 1\n")).unwrap();
    let (_, text) = run(&[]);
    assert!(!text.contains("declares order"), "{text}");
    assert!(text.contains("1 declared"), "{text}");
}

/// An empty folder: the main job validates the shipped scenarios of the
/// compiled-in engines and passes; those of pushval's own outside engines
/// are skipped and named.
///
/// Issue 40, item 5: the shipped files it reads by path are written under
/// `$XDG_CACHE_HOME/pushval/`, every level owner-only (0700), and nothing
/// is left in `$TMPDIR`.
#[test]
fn main_job_in_an_empty_folder_runs_the_shipped_scenarios() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let (tmp, cache) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let out = pushval_in(dir.path())
        .env("TMPDIR", tmp.path())
        .env("XDG_CACHE_HOME", cache.path())
        .output()
        .unwrap();
    assert_eq!(
        std::fs::read_dir(tmp.path()).unwrap().count(),
        0,
        "pushval left files in TMPDIR"
    );
    // A study reads its shipped study files by path: from the cache.
    let elsewhere = tempfile::tempdir().unwrap();
    let study = pushval_in(dir.path())
        .args(["study", "rapier2d_impulse_disk", "--quick", "--out"])
        .arg(elsewhere.path())
        .env("TMPDIR", tmp.path())
        .env("XDG_CACHE_HOME", cache.path())
        .output()
        .unwrap();
    assert_eq!(study.status.code(), Some(0), "{study:?}");
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0);
    let root = cache.path().join("pushval");
    let mut levels = vec![root.clone()];
    for e in std::fs::read_dir(&root).unwrap() {
        let v = e.unwrap().path();
        levels.push(v.join("studies"));
        levels.push(v);
    }
    assert!(levels.len() >= 3, "{levels:?}");
    for d in &levels {
        let mode = std::fs::symlink_metadata(d).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o700, "{}", d.display());
    }
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

/// A cache folder another user could enter (mode 0777) or a symlink in its
/// place is never used: the command says why on stderr, writes nothing
/// there, and reads the study file from the binary instead.
#[test]
fn an_open_or_linked_cache_folder_is_refused() {
    use std::os::unix::fs::PermissionsExt;
    for kind in ["open", "symlink"] {
        let dir = tempfile::tempdir().unwrap();
        let (tmp, cache) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let target = cache.path().join("elsewhere");
        std::fs::create_dir(&target).unwrap();
        let ours = cache.path().join("pushval");
        match kind {
            "open" => {
                std::fs::create_dir(&ours).unwrap();
                std::fs::set_permissions(&ours, std::fs::Permissions::from_mode(0o777)).unwrap();
            }
            _ => std::os::unix::fs::symlink(&target, &ours).unwrap(),
        }
        let (code, text) = run_with(
            dir.path(),
            tmp.path(),
            cache.path(),
            &["study", "rapier2d_impulse_disk", "--quick", "--out", "s"],
        );
        assert_eq!(code, Some(0), "{kind}: {text}");
        assert!(
            text.contains(&format!("{}:", ours.display())) && text.contains("not used"),
            "{kind}: {text}"
        );
        assert_eq!(std::fs::read_dir(&target).unwrap().count(), 0, "{kind}");
        assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0, "{kind}");
    }
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
/// (pybullet_contact) are skipped, neither fatal nor noted.
#[test]
fn study_runs_in_an_empty_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = pushval_in(dir.path())
        .args(["study", "rapier2d_impulse_disk", "--quick", "--out", "s"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    // The shipped study files of models this registry lacks are passed
    // over in silence (issue 45, item 7).
    assert!(!stderr.contains("pybullet_contact"), "{stderr}");
    assert!(dir.path().join("s/map.csv").is_file());
}

/// The `pushval` lines of README.md's user section, as a user copies them
/// (comments dropped), split into arguments; `pushval init` left out.
fn readme_user_lines() -> Vec<Vec<String>> {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let section = readme
        .split("## Gate your own engine in five minutes")
        .nth(1)
        .expect("README.md has its user section");
    let block = section
        .split("```sh")
        .nth(1)
        .unwrap()
        .split("```")
        .next()
        .unwrap();
    block
        .lines()
        .map(|l| l.split('#').next().unwrap().trim())
        .filter(|l| l.starts_with("pushval") && *l != "pushval init")
        .map(|l| l.split_whitespace().skip(1).map(String::from).collect())
        .collect()
}

/// `pushval init` in an empty folder, then every line of README.md's user
/// section, verbatim (issue 40, item 2): each exits 0 and writes rows (the
/// gate, the study's map and its Coulomb fit, run, fit, track and power's
/// gate_power.csv with rows for the init engine); every fit verdict that is
/// not a success has its reason; the kit is named as it is installed, never
/// as a registry package. A second `init` refuses to overwrite, exit 2
/// naming the file. Nothing is left in `$TMPDIR`.
#[test]
fn init_then_every_readme_line_in_an_empty_folder() {
    let dir = tempfile::tempdir().unwrap();
    let (tmp, cache) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let d = dir.path();
    let run = |args: &[&str]| run_with(d, tmp.path(), cache.path(), args);
    let (code, text) = run(&["init"]);
    assert_eq!(code, Some(0), "{text}");
    for f in ["pushval.toml", "adapter.py", "scenarios/my_engine.toml"] {
        assert!(d.join(f).is_file(), "{f}");
        let body = std::fs::read_to_string(d.join(f)).unwrap();
        assert!(!body.contains("pip install pushval"), "{f}: {body}");
    }
    assert!(!text.contains("pip install pushval"), "{text}");
    assert!(
        text.contains("pip install PATH/TO/pushval") || text.contains("as installed"),
        "{text}"
    );
    let lines = readme_user_lines();
    assert!(lines.len() >= 6, "{lines:?}");
    let mut ran = Vec::new();
    for args in &lines {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, text) = run(&args);
        assert_eq!(code, Some(0), "pushval {}: {text}", args.join(" "));
        ran.push(args.first().copied().unwrap_or("(gate)"));
        if args.is_empty() {
            assert!(
                text.contains("my_engine") && text.contains("PASS"),
                "{text}"
            );
        }
    }
    for cmd in [
        "(gate)", "study", "run", "fit", "track", "power", "plan", "loop",
    ] {
        assert!(ran.contains(&cmd), "the README runs no `{cmd}`: {lines:?}");
    }
    let rows = |f: &str| {
        std::fs::read_to_string(d.join(f))
            .unwrap_or_else(|e| panic!("{f}: {e}"))
            .lines()
            .count()
            .saturating_sub(1)
    };
    for f in [
        "run/trajectory.csv",
        "track/track.csv",
        "results/friction_models/my_engine/map.csv",
        "results/friction_models/my_engine/coulomb_fit.csv",
        "loop/trajectory.csv",
        "plan/plan.toml",
    ] {
        assert!(rows(f) > 0, "{f}: no rows");
    }
    let looped: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("loop/loop.json")).unwrap()).unwrap();
    assert_eq!(looped["success"], true, "{looped}");
    assert_eq!(
        looped["engine_replayed_each_period"], false,
        "the kit steps: {looped}"
    );
    let power = std::fs::read_to_string(d.join("power/gate_power.csv")).unwrap();
    assert!(
        power
            .lines()
            .skip(1)
            .any(|l| l.starts_with("my-engine-square,my_engine,")),
        "{power}"
    );
    let fits = std::fs::read_to_string(d.join("results/friction_models/my_engine/coulomb_fit.csv"))
        .unwrap();
    let header: Vec<&str> = fits.lines().next().unwrap().split(',').collect();
    let (iv, ir) = (
        header.iter().position(|h| *h == "verdict").unwrap(),
        header.iter().position(|h| *h == "reason").unwrap(),
    );
    for l in fits.lines().skip(1) {
        let f: Vec<&str> = l.split(',').collect();
        // The kit's Coulomb forces are Coulomb's law: the fit explains them.
        assert_eq!(f[iv], "explained", "{l}");
        if ["failed", "degenerate", "unidentifiable"].contains(&f[iv]) {
            assert!(!f[ir].is_empty(), "{l}");
        }
    }
    let (code, text) = run(&["init"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("pushval.toml: already exists"), "{text}");
    assert_eq!(
        std::fs::read_dir(tmp.path()).unwrap().count(),
        0,
        "pushval left files in TMPDIR"
    );
}

/// `power` in a folder whose scenarios gate nothing writes nothing and
/// exits 1 saying why, never 0 with no rows.
#[test]
fn power_with_nothing_to_measure_exits_1() {
    let dir = tempfile::tempdir().unwrap();
    let (tmp, cache) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let d = dir.path();
    assert_eq!(run_with(d, tmp.path(), cache.path(), &["init"]).0, Some(0));
    let sc = d.join("scenarios/my_engine.toml");
    let text = std::fs::read_to_string(&sc).unwrap();
    // No `gate` line: the default gate (rapier2d) only where `models` lists
    // it, and it does not: my_engine is an informational row (an empty
    // `gate` is refused at load).
    let ungated: String = text
        .lines()
        .filter(|l| !l.starts_with("gate = "))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(ungated, text);
    std::fs::write(&sc, ungated).unwrap();
    let (code, text) = run_with(
        d,
        tmp.path(),
        cache.path(),
        &["power", "--quick", "--out", "p"],
    );
    assert_eq!(code, Some(1), "{text}");
    assert!(text.contains("gates an engine"), "{text}");
    assert!(!d.join("p/gate_power.csv").exists());
}

/// A study whose engine fails on every run (an adapter that exits with an
/// error) is not a success: it exits non-zero naming the failure, and the
/// Coulomb fit's row says at which stage it failed (issue 40, item 2).
#[test]
fn a_study_of_an_engine_that_always_fails_exits_non_zero_saying_why() {
    let dir = tempfile::tempdir().unwrap();
    let (tmp, cache) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let d = dir.path();
    assert_eq!(run_with(d, tmp.path(), cache.path(), &["init"]).0, Some(0));
    std::fs::write(
        d.join("adapter.py"),
        "import sys\nsys.exit('adapter.py: broken on purpose')\n",
    )
    .unwrap();
    let (code, text) = run_with(
        d,
        tmp.path(),
        cache.path(),
        &["study", "my_engine", "--quick", "--out", "s"],
    );
    assert_ne!(code, Some(0), "{text}");
    assert!(text.contains("engine run(s) failed"), "{text}");
    assert!(text.contains("broken on purpose"), "{text}");
    let fits = std::fs::read_to_string(d.join("s/coulomb_fit.csv")).unwrap();
    let row = fits.lines().nth(1).unwrap();
    assert!(
        row.contains(",failed,the engine's run of the schedule failed"),
        "{fits}"
    );
}

/// `power` from any folder measures the gates of the project that
/// `--engines FILE` names (its `scenarios/` beside the file): rows for the
/// init engine, and none for engines the project does not gate.
#[test]
fn power_measures_the_project_named_by_engines() {
    let (project, elsewhere) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let (tmp, cache) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    assert_eq!(
        run_with(project.path(), tmp.path(), cache.path(), &["init"]).0,
        Some(0)
    );
    let file = project.path().join("pushval.toml");
    let (code, text) = run_with(
        elsewhere.path(),
        tmp.path(),
        cache.path(),
        &[
            "--engines",
            file.to_str().unwrap(),
            "power",
            "--quick",
            "--out",
            "p",
        ],
    );
    assert_eq!(code, Some(0), "{text}");
    let csv = std::fs::read_to_string(elsewhere.path().join("p/gate_power.csv")).unwrap();
    let engines: std::collections::BTreeSet<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    assert_eq!(
        engines.into_iter().collect::<Vec<_>>(),
        ["my_engine"],
        "{csv}"
    );
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0);
}
