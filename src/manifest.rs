//! `pushval manifest`: the one command that writes each file of `results/`.
//!
//! [`RULES`] is the source of truth: one rule per writer (a command of the
//! CLI, a bench, an example, an adapter script), naming the source that
//! writes the files, the files as patterns, and the one command line that
//! regenerates them. `pushval manifest` walks `results/`, matches every file
//! against the rules and writes `results/MANIFEST.csv` (`path,command`,
//! sorted by path); `pushval manifest --check` writes nothing and exits 1
//! when the committed file differs from what the rules give, or when a file
//! of `results/` is matched by no rule (nothing regenerates it) or by two
//! (two commands write it).
//!
//! A pattern is a path relative to the repository root, one `/`-separated
//! segment at a time: `{model}` is a whole segment naming an engine model of
//! the registry (the outside engines of `pushval.toml` included), `*` any
//! run of characters within one segment. The command's `{model}` is the
//! model the folder names. A command `pushval ARGS` runs on the default
//! build; for a model of a crate behind a cargo feature (the registry's
//! row for the crate says which, [`crate::registry::feature_of`]) it
//! becomes `cargo run --release --features F -- ARGS`.
//!
//! Not walked: hidden files (an interrupted atomic write's `.tmp*`) and
//! `parts/` folders (the part files of `--shard`, merged by `--merge`, never
//! committed). Files no command writes any more are listed in [`STALE`]
//! with the evidence, until they are deleted.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};

/// The manifest, relative to the repository root.
pub const MANIFEST: &str = "results/MANIFEST.csv";

/// The command of files written by hand (no command regenerates them).
pub const BY_HAND: &str = "(by hand)";

/// One writer of results files.
#[derive(Debug, Clone, Copy)]
pub struct Rule {
    /// The one command line that regenerates the files (`{model}`: the
    /// folder's model; see the module doc for `pushval` and features).
    pub command: &'static str,
    /// The source that writes them, relative to the repository root (a file
    /// or a folder); empty for [`BY_HAND`].
    pub source: &'static str,
    /// The files, as patterns relative to the repository root.
    pub files: &'static [&'static str],
}

/// Every writer of `results/`.
pub const RULES: &[Rule] = &[
    Rule {
        command: "pushval report",
        source: "src/report",
        files: &[
            "results/README.md",
            "results/key_figures.csv",
            "results/phi_input.csv",
            "results/phi_input.svg",
            "results/omega_paper.csv",
            "results/omega_paper.svg",
            "results/path_v*.csv",
            "results/path_v*.svg",
            "results/slippery_path_v*.csv",
            "results/slippery_path_v*.svg",
            "results/omega_slippery.csv",
            "results/omega_slippery.svg",
            "results/mass.csv",
            "results/mass.svg",
            "results/inertia.csv",
            "results/inertia.svg",
            "results/switching.csv",
            "results/switching.svg",
            "results/kappa.csv",
            "results/kappa.svg",
            "results/tau.csv",
            "results/tau.svg",
            "results/validity.csv",
            "results/validity.svg",
            "results/assumptions.csv",
            "results/assumptions.svg",
        ],
    },
    Rule {
        command: "pushval power",
        source: "src/power",
        files: &["results/gate_power.csv", "results/gate_power.svg"],
    },
    Rule {
        command: "pushval stress",
        source: "src/stress.rs",
        files: &[
            "results/stress/stress.csv",
            "results/stress/stability.csv",
            "results/stress/stress_map.svg",
        ],
    },
    Rule {
        command: "pushval fit-study",
        source: "src/fit/study",
        files: &[
            "results/identifiability.csv",
            "results/identifiability.svg",
            "results/fit.md",
        ],
    },
    Rule {
        command: "pushval track-study",
        source: "src/track/study",
        files: &[
            "results/track_cost.csv",
            "results/track_convergence.csv",
            "results/track_efficiency.csv",
            "results/track_step.csv",
            "results/track_engines.csv",
            "results/track.svg",
            "results/track.md",
        ],
    },
    Rule {
        command: "pushval slide-study",
        source: "src/slide",
        files: &[
            "results/slide/throws.csv",
            "results/slide/engines.csv",
            "results/slide/disc.csv",
            "results/slide/rest.svg",
            "results/slide/README.md",
        ],
    },
    Rule {
        command: "pushval control-study",
        source: "src/control/study.rs",
        files: &[
            "results/closed_loop/success.csv",
            "results/closed_loop/runs.csv",
            "results/closed_loop/goals.csv",
            "results/closed_loop/success.svg",
            "results/closed_loop/paths.svg",
            "results/closed_loop/README.md",
        ],
    },
    Rule {
        command: "pushval control-study --adaptive",
        source: "src/control/adaptive.rs",
        files: &[
            "results/closed_loop/adaptive/success.csv",
            "results/closed_loop/adaptive/runs.csv",
            "results/closed_loop/adaptive/README.md",
        ],
    },
    Rule {
        command: "cargo bench --bench control",
        source: "benches/control.rs",
        files: &["results/control_cost.csv"],
    },
    Rule {
        command: "pushval manifest",
        source: "src/manifest.rs",
        files: &[MANIFEST],
    },
    Rule {
        command: "pushval study {model}",
        source: "src/study/readme.rs",
        files: &[
            "results/friction_models/{model}/README.md",
            "results/friction_models/{model}/paper_plate.csv",
            "results/friction_models/{model}/map.csv",
            "results/friction_models/{model}/map.svg",
            "results/friction_models/{model}/map_*.csv",
            "results/friction_models/{model}/dt_ladder.csv",
            "results/friction_models/{model}/creep.csv",
            "results/friction_models/{model}/variants.csv",
            "results/friction_models/{model}/sweep_*.csv",
            "results/friction_models/{model}/rest_moments.csv",
            "results/friction_models/{model}/coulomb_fit.csv",
        ],
    },
    Rule {
        // `pushval study index` writes it too (and redraws every map.svg),
        // from the model folders as they are.
        command: "pushval study all",
        source: "src/study/readme.rs",
        files: &["results/friction_models/README.md"],
    },
    Rule {
        command: "cargo bench --bench work_precision",
        source: "benches/work_precision.rs",
        files: &[
            "results/work_precision.csv",
            "results/work_precision.svg",
            "results/work_precision_target.csv",
        ],
    },
    Rule {
        command: "cargo bench --bench support_discretisation",
        source: "benches/support_discretisation.rs",
        files: &["results/support_discretisation.csv"],
    },
    Rule {
        command: "cargo bench --bench skips",
        source: "benches/skips.rs",
        files: &["results/skips.csv"],
    },
    Rule {
        command: "cargo bench --bench outside_overhead",
        source: "benches/outside_overhead.rs",
        files: &["results/outside_overhead.csv"],
    },
    Rule {
        command: "cargo bench --features mujoco,avian,physx,jolt --bench engine_work_precision",
        source: "benches/engine_work_precision.rs",
        files: &[
            "results/engine_work_precision.csv",
            "results/engine_work_precision.svg",
            "results/engine_work_precision_summary.csv",
        ],
    },
    Rule {
        command: "cargo run --release --example bullet_law",
        source: "examples/bullet_law.rs",
        files: &[
            "results/friction_models/bullet_contact.csv",
            "results/friction_models/bullet_contact_dt.csv",
            "results/friction_models/bullet_contact_summary.csv",
            "results/friction_models/bullet_law_theta.csv",
        ],
    },
    Rule {
        command: "cargo run --release --features mujoco --example mujoco_versions",
        source: "examples/mujoco_versions.rs",
        files: &["results/friction_models/mujoco_versions.csv"],
    },
    Rule {
        command: "cargo run --release --features mujoco --example creep_law",
        source: "examples/creep_law.rs",
        files: &[
            "results/friction_models/mujoco/creep_law.csv",
            "results/friction_models/mujoco/creep_law.md",
        ],
    },
    Rule {
        command: ".venv-adapters/bin/python adapters/python/drake_measure.py",
        source: "adapters/python/drake_measure.py",
        files: &[
            "results/friction_models/drake/approximations.csv",
            "results/friction_models/drake/sweeps.csv",
        ],
    },
    Rule {
        command: ".venv-adapters/bin/python adapters/python/drake_lift_study.py",
        source: "adapters/python/drake_lift_study.py",
        files: &["results/friction_models/drake/lift.csv"],
    },
    Rule {
        command: ".venv-warp/bin/python scripts/compare_mujoco_warp.py --duration 1.0",
        source: "scripts/compare_mujoco_warp.py",
        files: &["results/friction_models/mujoco_warp/compare.csv"],
    },
    Rule {
        // Their figures are read from the CSVs beside them.
        command: BY_HAND,
        source: "",
        files: &[
            "results/friction_models/drake/README.md",
            "results/friction_models/mujoco_warp/README.md",
        ],
    },
];

/// Files of `results/` that no current command writes, with the evidence,
/// kept out of the manifest until they are deleted (an entry whose file is
/// gone fails `--check`: remove it here then).
pub const STALE: &[(&str, &str)] = &[];

/// The cargo feature a build needs for `model`, if any (the registry's
/// row for its crate).
pub fn feature_of(model: &str) -> Option<&'static str> {
    crate::registry::feature_of(model)
}

/// A command line for `model`: `{model}` replaced and, for a `pushval`
/// command of a model behind a feature, the `cargo run` of that build.
pub fn command_for(template: &str, model: Option<&str>) -> String {
    let Some(m) = model else {
        return template.to_string();
    };
    let cmd = template.replace("{model}", m);
    match (cmd.strip_prefix("pushval "), feature_of(m)) {
        (Some(args), Some(f)) => format!("cargo run --release --features {f} -- {args}"),
        _ => cmd,
    }
}

/// How a generated file names the command: `pushval ARGS` for a `cargo run
/// … -- ARGS` of the CLI (the `pushval` binary of that build), else the
/// command itself.
pub fn pushval_form(command: &str) -> String {
    match command.split_once(" -- ") {
        Some((build, args))
            if build.starts_with("cargo run --release") && !build.contains("--example") =>
        {
            format!("pushval {args}")
        }
        _ => command.to_string(),
    }
}

/// Whether `name` (one segment) matches `pat` (`*`: any run of characters).
fn glob(pat: &str, name: &str) -> bool {
    let parts: Vec<&str> = pat.split('*').collect();
    if parts.len() == 1 {
        return pat == name;
    }
    let (first, last) = (parts[0], parts[parts.len() - 1]);
    if name.len() < first.len() + last.len() || !name.starts_with(first) || !name.ends_with(last) {
        return false;
    }
    let mut rest = &name[first.len()..name.len() - last.len()];
    for p in &parts[1..parts.len() - 1] {
        match rest.find(p) {
            Some(i) => rest = &rest[i + p.len()..],
            None => return false,
        }
    }
    true
}

/// Whether `path` matches `pattern`; `Some(model)` for a `{model}` segment.
fn matches(pattern: &str, path: &str, models: &[String]) -> Option<Option<String>> {
    let (ps, ns): (Vec<&str>, Vec<&str>) =
        (pattern.split('/').collect(), path.split('/').collect());
    if ps.len() != ns.len() {
        return None;
    }
    let mut model = None;
    for (p, n) in ps.iter().zip(&ns) {
        if *p == "{model}" {
            if !models.iter().any(|m| m == n) {
                return None;
            }
            model = Some(n.to_string());
        } else if !glob(p, n) {
            return None;
        }
    }
    Some(model)
}

/// One row of the manifest.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, serde::Deserialize)]
pub struct Row {
    pub path: String,
    pub command: String,
}

/// What the rules say about the files of `results/`.
#[derive(Debug, Default)]
pub struct Walk {
    /// One row per matched file, sorted by path.
    pub rows: Vec<Row>,
    /// Files no rule matches.
    pub unmatched: Vec<String>,
    /// Files two or more rules match, with their commands.
    pub ambiguous: Vec<(String, Vec<String>)>,
    /// Files of the stale list that exist, with the evidence.
    pub stale: Vec<(String, String)>,
    /// Stale-list entries whose file is gone, or that a rule matches.
    pub stale_errors: Vec<String>,
}

/// Every file under `dir`, as paths relative to `root` with `/`, skipping
/// hidden entries and `parts/` folders.
fn files(root: &Path, dir: &Path, out: &mut Vec<String>) -> anyhow::Result<()> {
    let entries = std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?;
    for e in entries {
        let e = e.with_context(|| format!("reading {}", dir.display()))?;
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        let path = e.path();
        let kind = e
            .file_type()
            .with_context(|| format!("reading {}", path.display()))?;
        if kind.is_dir() {
            if name != "parts" {
                files(root, &path, out)?;
            }
        } else {
            let rel = path.strip_prefix(root).unwrap_or(&path);
            let parts: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            out.push(parts.join("/"));
        }
    }
    Ok(())
}

/// Matches every file of `root/results` (and the manifest itself, which
/// this command writes) against `rules`; `models` are the names `{model}`
/// stands for; `stale` the known leftovers.
pub fn walk(
    root: &Path,
    rules: &[Rule],
    stale: &[(&str, &str)],
    models: &[String],
) -> anyhow::Result<Walk> {
    let mut paths = Vec::new();
    files(root, &root.join("results"), &mut paths)?;
    if rules.iter().any(|r| r.files.contains(&MANIFEST)) && !paths.iter().any(|p| p == MANIFEST) {
        paths.push(MANIFEST.to_string());
    }
    paths.sort();
    let mut w = Walk::default();
    for path in paths {
        let mut commands: Vec<String> = Vec::new();
        for r in rules {
            for pat in r.files {
                if let Some(model) = matches(pat, &path, models) {
                    commands.push(command_for(r.command, model.as_deref()));
                }
            }
        }
        let known_stale = stale.iter().find(|(p, _)| *p == path);
        match (commands.len(), known_stale) {
            (0, Some((_, why))) => w.stale.push((path, why.to_string())),
            (_, Some(_)) => w.stale_errors.push(format!(
                "{path}: listed as stale in src/manifest.rs, but a rule matches it ({})",
                commands.join("; ")
            )),
            (0, None) => w.unmatched.push(path),
            (1, None) => w.rows.push(Row {
                path,
                command: commands.remove(0),
            }),
            _ => w.ambiguous.push((path, commands)),
        }
    }
    for (p, _) in stale {
        if !root.join(p).is_file() {
            w.stale_errors.push(format!(
                "{p}: listed as stale in src/manifest.rs but gone: remove the entry"
            ));
        }
    }
    Ok(w)
}

impl Walk {
    /// Why no manifest can be written: unmatched and doubly matched files,
    /// stale-list errors.
    pub fn errors(&self) -> Vec<String> {
        let mut e: Vec<String> = self
            .unmatched
            .iter()
            .map(|p| format!("{p}: no rule of src/manifest.rs matches it (no command writes it: delete it, or add its writer's rule)"))
            .collect();
        e.extend(self.ambiguous.iter().map(|(p, c)| {
            format!(
                "{p}: matched by {} rules (commands: {})",
                c.len(),
                c.join("; ")
            )
        }));
        e.extend(self.stale_errors.iter().cloned());
        e
    }
}

/// The manifest's text (a field is quoted where it holds a comma, a quote
/// or a line break).
pub fn csv(rows: &[Row]) -> String {
    let mut csv = crate::outdir::Csv::new(&["path", "command"]);
    for r in rows {
        csv.row(&[&r.path, &r.command]);
    }
    csv.text().to_string()
}

/// Reads a manifest's rows; errors name the file and the line.
pub fn parse(text: &str, file: &Path) -> anyhow::Result<Vec<Row>> {
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    if !reader
        .headers()
        .is_ok_and(|h| h.iter().eq(["path", "command"]))
    {
        bail!(
            "{}: line 1: expected the header `path,command`",
            file.display()
        );
    }
    reader
        .deserialize()
        .map(|r| {
            r.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line());
                anyhow::anyhow!(
                    "{}: line {line}: expected two fields, path and command ({e})",
                    file.display()
                )
            })
        })
        .collect()
}

/// The command a generated text file names in its first lines: "Generated
/// by `X`" or "Written by `X`".
pub fn named_generator(text: &str) -> Option<String> {
    let head: String = text.lines().take(5).collect::<Vec<_>>().join(" ");
    ["Generated by `", "Written by `"].iter().find_map(|lead| {
        let rest = &head[head.find(lead)? + lead.len()..];
        Some(rest[..rest.find('`')?].to_string())
    })
}

/// Differences between the committed manifest `committed` and the rows the
/// rules give, each a line to print; also every Markdown file whose
/// generator line names another command than its row.
pub fn differences(root: &Path, walk: &Walk, committed: &[Row]) -> Vec<String> {
    let mut out = walk.errors();
    let want: BTreeMap<&str, &str> = walk
        .rows
        .iter()
        .map(|r| (r.path.as_str(), r.command.as_str()))
        .collect();
    let mut have: BTreeMap<&str, &str> = BTreeMap::new();
    for (i, r) in committed.iter().enumerate() {
        let line = i + 2;
        if have.insert(&r.path, &r.command).is_some() {
            out.push(format!("{MANIFEST} line {line}: {} listed twice", r.path));
        }
        if r.path != MANIFEST && !root.join(&r.path).is_file() {
            out.push(format!("{MANIFEST} line {line}: {} does not exist", r.path));
        }
        match want.get(r.path.as_str()) {
            Some(c) if *c != r.command => out.push(format!(
                "{MANIFEST} line {line}: {}: `{}`, the rules say `{c}`",
                r.path, r.command
            )),
            None if root.join(&r.path).is_file() => out.push(format!(
                "{MANIFEST} line {line}: {}: no rule gives a command for it",
                r.path
            )),
            _ => {}
        }
    }
    for r in &walk.rows {
        if !have.contains_key(r.path.as_str()) {
            out.push(format!(
                "{}: missing from {MANIFEST} (the rules say `{}`)",
                r.path, r.command
            ));
        }
    }
    let sorted = committed.windows(2).all(|w| w[0].path < w[1].path);
    if !sorted {
        out.push(format!("{MANIFEST}: rows not sorted by path"));
    }
    for r in walk.rows.iter().filter(|r| r.path.ends_with(".md")) {
        let Ok(text) = std::fs::read_to_string(root.join(&r.path)) else {
            continue;
        };
        if let Some(named) = named_generator(&text) {
            if named != pushval_form(&r.command) {
                out.push(format!(
                    "{}: names its generator `{named}`, the manifest `{}`",
                    r.path, r.command
                ));
            }
        }
    }
    out
}

/// The names `{model}` stands for: every model of the registry.
pub fn models() -> Vec<String> {
    crate::registry::entries()
        .into_iter()
        .map(|e| e.name)
        .collect()
}

/// `pushval manifest [--check]` in the repository `root`.
pub fn cli(root: &Path, check: bool) -> anyhow::Result<ExitCode> {
    let walk = walk(root, RULES, STALE, &models())?;
    for (p, why) in &walk.stale {
        println!("note: {p}: stale, no command writes it ({why})");
    }
    let path: PathBuf = root.join(MANIFEST);
    if check {
        let committed = match std::fs::read_to_string(&path) {
            Ok(text) => parse(&text, &path)?,
            Err(e) => bail!("reading {}: {e}", path.display()),
        };
        let diff = differences(root, &walk, &committed);
        for d in &diff {
            println!("{d}");
        }
        if diff.is_empty() {
            println!("{MANIFEST}: {} files, as the rules say", walk.rows.len());
            return Ok(ExitCode::SUCCESS);
        }
        println!(
            "{MANIFEST} differs from src/manifest.rs's rules ({} problems); `pushval manifest` rewrites it",
            diff.len()
        );
        return Ok(ExitCode::from(1));
    }
    let errors = walk.errors();
    if !errors.is_empty() {
        bail!("no manifest written:\n{}", errors.join("\n"));
    }
    crate::atomic::write_atomic(&path, csv(&walk.rows).as_bytes())?;
    println!("wrote {} ({} files)", path.display(), walk.rows.len());
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glob_segments() {
        assert!(glob("path_v*.csv", "path_v0.2.csv"));
        assert!(!glob("path_v*.csv", "slippery_path_v0.2.csv"));
        assert!(!glob("map_*.csv", "map.csv"));
        assert!(glob("a*b*c", "aXbYc"));
        assert!(!glob("a*b*c", "aXc"));
        assert!(!glob("ab*ba", "aba"));
    }

    #[test]
    fn csv_round_trip() {
        let rows = vec![Row {
            path: "results/a.csv".into(),
            command: "cargo bench --features a,b -- \"x\"".into(),
        }];
        let text = csv(&rows);
        assert_eq!(parse(&text, Path::new("m.csv")).unwrap(), rows);
    }
}
