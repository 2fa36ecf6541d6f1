//! Every figure in README.md, docs/*.md and results/README.md comes from a
//! committed results file (issue 22, item 6).
//!
//! A *figure* is a number followed by a unit (ns, µs, ms, s, min, ×, %, m,
//! mm, µm, rad, mrad, µrad, m/s, rad/s, s/s, kg, N, …), or a range
//! `a–b unit`. Numbers inside code (fenced blocks, `inline code`) are
//! commands, formulas and the scenario format, not figures. A figure is
//! traced when a number in a results file equals it at the precision it is
//! written with: "18.7 µs" is traced by 18.7, 18.72 or 1.87e-5 (s), not by
//! 18.76 or 1.876e-5; "2.9 %" by 2.9 or 0.029; an exact fraction "1/60 s"
//! by any number that rounds it, 1.666667e-2.
//!
//! Where it must be traced:
//!
//! * README.md and docs/*.md: in a results file the text *names beside it*: in the same
//!   paragraph, list item or table row, or in the paragraph that introduces
//!   the list or table (an SVG stands for the CSV of its data beside it; a
//!   folder for every text file in it);
//! * results/README.md (written by `pushval report`): in its section's
//!   `Data:` files, else in any committed results file (`results/**` csv,
//!   json, txt and md other than itself).
//!
//! Not figures to trace: numbers of the shipped scenarios (inputs, in
//! `scenarios/*.toml`) and the phrases of [`ALLOWED`], each a physical
//! constant or a named constant of the code, with its reason. An allow-list
//! entry that no longer occurs fails the test too.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::common::root;

/// Phrases whose figures are inputs or constants of the code, not results:
/// (file, phrase, reason). The figure's whole text must lie in the phrase.
const ALLOWED: &[(&str, &str, &str)] = &[
    // README.md and docs/
    (
        "docs/closed-loop.md",
        "floored at 0.2 mm, 2 mrad and\n  0.05 rad/s (`estimate::FLOOR`)",
        "the estimator's weight floors, constants of crates/control/src/estimate.rs",
    ),
    (
        "docs/benchmarks.md",
        "paper trajectory (10 s, five segments)",
        "the paper scene's duration: five 2 s segments of scenarios/paper-square-v1.0.toml",
    ),
    (
        "docs/benchmarks.md",
        "1/60 s to 1/1920 s",
        "the time-step ladder of benches/engine_work_precision.rs (a constant of the bench)",
    ),
    (
        "docs/ci-gate.md",
        "(1/60 s halved down to 1e-4 s)",
        "the auto-tolerance ladder, src/harness/tolerance.rs (its first step and floor)",
    ),
    (
        "docs/benchmarks.md",
        "I_cm ±0.5 %, μ ±0.5 %, a 0.5 mm contact offset, a 0.5 mm\ncentre-of-friction shift",
        "the power targets, constants of src/power (also the target column of gate_power.csv)",
    ),
    (
        "docs/benchmarks.md",
        "(noise\n`--sigma-position` 1 mm and `--sigma-theta` 1 mrad by default)",
        "pushval fit's default σ, constants of src/fit",
    ),
    (
        "docs/benchmarks.md",
        "μ within 1 % and I_cm within 2 % at 2σ",
        "the fit study's targets, constants of src/fit_study",
    ),
    (
        "docs/benchmarks.md",
        "κ within 1 %",
        "the κ closed forms' tolerance, a constant of src/report (kappa.csv's columns are per it)",
    ),
    (
        "docs/benchmarks.md",
        "ω(t) at 0.2–1.0 m/s",
        "the pusher speeds of the paper figures (scenario inputs of pushval report)",
    ),
    // results/README.md
    (
        "results/README.md",
        "0.25 m, 1 kg square",
        "the seed paper's plate (scenarios/paper-square-v1.0.toml: polygon ±0.125 m, mass 1 kg)",
    ),
    (
        "results/README.md",
        "dt = 1 ms",
        "rapier2d's default step, pushval_rapier2d::EngineSettings::default().dt",
    ),
    (
        "results/README.md",
        "5 segments of 2 s",
        "the paper schedule (scenarios/paper-square-v1.0.toml)",
    ),
    (
        "results/README.md",
        "at 1 ms sampling",
        "the switching figure's sample interval, a constant of src/report",
    ),
    (
        "results/README.md",
        "over one 1 ms step",
        "rapier2d's default step, pushval_rapier2d::EngineSettings::default().dt",
    ),
    (
        "results/README.md",
        "ε reaches 1 %, 5 %, 10 %",
        "the validity map's error classes, constants of src/report",
    ),
    (
        "results/README.md",
        "| 1 % |",
        "the validity map's error classes, constants of src/report",
    ),
    (
        "results/README.md",
        "| 5 % |",
        "the validity map's error classes, constants of src/report",
    ),
    (
        "results/README.md",
        "| 10 % |",
        "the validity map's error classes, constants of src/report",
    ),
    (
        "results/README.md",
        "within 1 % of the exact κ",
        "the κ closed forms' tolerance, a constant of src/report",
    ),
    (
        "results/README.md",
        "1 kg and at 10 kg",
        "the mass figure's two masses (scenario inputs of pushval report)",
    ),
    (
        "results/README.md",
        "a 0.5 m plate's value",
        "the plate the seed paper's printed inertia belongs to (m side² / 6 with side 0.5 m)",
    ),
    (
        "results/README.md",
        "v_c = 0.2 m/s",
        "a pusher speed of the paper figures (scenario input of pushval report)",
    ),
    (
        "results/README.md",
        "v_c = 1 m/s",
        "a pusher speed of the paper figures (scenario input of pushval report)",
    ),
    (
        "results/README.md",
        "at 0.025 m/s and in",
        "the slowest cell centre of the assumptions map's speed grid (a constant of src/report)",
    ),
    (
        "results/README.md",
        "at 1.975 m/s",
        "the fastest cell centre of the assumptions map's speed grid (a constant of src/report)",
    ),
    (
        "results/README.md",
        "Along the paper schedule at 1 m/s",
        "a pusher speed of the paper figures (scenario input of pushval report)",
    ),
];

/// Units a figure may carry, longest first, with the factor to SI.
const UNITS: &[(&str, f64)] = &[
    ("rad/s²", 1.0),
    ("rad/s", 1.0),
    ("m/s²", 1.0),
    ("m/s", 1.0),
    ("s/s", 1.0),
    ("kg m²", 1.0),
    ("N m", 1.0),
    ("minutes", 60.0),
    ("mrad", 1e-3),
    ("µrad", 1e-6),
    ("μrad", 1e-6),
    ("rad", 1.0),
    ("min", 60.0),
    ("mm", 1e-3),
    ("µm", 1e-6),
    ("μm", 1e-6),
    ("cm", 1e-2),
    ("km", 1e3),
    ("ns", 1e-9),
    ("µs", 1e-6),
    ("μs", 1e-6),
    ("us", 1e-6),
    ("ms", 1e-3),
    ("kg", 1.0),
    ("Hz", 1.0),
    ("GiB", 1.0),
    ("m", 1.0),
    ("s", 1.0),
    ("N", 1.0),
    ("×", 1.0),
    ("%", 1e-2),
    ("°", 1.0),
];

/// A number as written: its value, half a unit of its last digit (0 for
/// an exact fraction), and where it is.
#[derive(Debug, Clone, Copy)]
struct Num {
    value: f64,
    half_ulp: f64,
    start: usize,
    end: usize,
}

/// A figure: a number and its unit's factor to SI.
#[derive(Debug, Clone)]
struct Figure {
    num: Num,
    unit: &'static str,
    scale: f64,
    /// The figure as written, number to unit.
    text: String,
}

fn is_word(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The number starting at byte `i` of `s` (which must be an ASCII digit not
/// preceded by a word character or a '.'), with thousands separators when
/// `grouping` (prose), an exponent and a `/N` denominator.
fn number_at(s: &str, i: usize, grouping: bool) -> Option<Num> {
    let b = s.as_bytes();
    if !b.get(i)?.is_ascii_digit() {
        return None;
    }
    if let Some(prev) = s[..i].chars().next_back() {
        if is_word(prev) || prev == '.' {
            return None;
        }
    }
    let digits = |mut j: usize| {
        while j < b.len() && b[j].is_ascii_digit() {
            j += 1;
        }
        j
    };
    let mut j = digits(i);
    let mut mantissa = s[i..j].to_string();
    if grouping {
        // ",ddd" groups, each exactly three digits.
        while j + 3 < b.len() + 1
            && b[j] == b','
            && b.get(j + 1..j + 4)
                .is_some_and(|g| g.iter().all(u8::is_ascii_digit))
            && !b.get(j + 4).is_some_and(u8::is_ascii_digit)
        {
            mantissa.push_str(&s[j + 1..j + 4]);
            j += 4;
        }
    }
    let mut decimals = 0i32;
    if b.get(j) == Some(&b'.') && b.get(j + 1).is_some_and(u8::is_ascii_digit) {
        let k = digits(j + 1);
        decimals = (k - j - 1) as i32;
        mantissa.push_str(&s[j..k]);
        j = k;
    }
    let mut exponent = 0i32;
    if matches!(b.get(j), Some(b'e' | b'E')) {
        let mut k = j + 1;
        let mut neg = false;
        if matches!(b.get(k), Some(b'-' | b'+')) {
            neg = b[k] == b'-';
            k += 1;
        } else if s[k..].starts_with('−') {
            neg = true;
            k += '−'.len_utf8();
        }
        let e = digits(k);
        if e > k {
            exponent = s[k..e].parse::<i32>().ok()? * if neg { -1 } else { 1 };
            j = e;
        }
    }
    let value = mantissa.parse::<f64>().ok()? * 10f64.powi(exponent);
    // An exact fraction 1/N (no decimals, no exponent on either side).
    if decimals == 0 && exponent == 0 && b.get(j) == Some(&b'/') {
        let k = digits(j + 1);
        if k > j + 1
            && !s[k..]
                .chars()
                .next()
                .is_some_and(|c| is_word(c) || c == '.')
        {
            let den: f64 = s[j + 1..k].parse().ok()?;
            if den > 0.0 {
                return Some(Num {
                    value: value / den,
                    half_ulp: 0.0,
                    start: i,
                    end: k,
                });
            }
        }
    }
    if s[j..].chars().next().is_some_and(is_word) && !s[j..].starts_with(['x', 'e']) {
        // "3d", "2D", "2σ": an identifier, not a number.
        return None;
    }
    Some(Num {
        value,
        half_ulp: 0.5 * 10f64.powi(exponent - decimals),
        start: i,
        end: j,
    })
}

/// Every number in a results file (no thousands grouping: CSV commas).
fn numbers(s: &str) -> Vec<Num> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        if s.is_char_boundary(i) {
            if let Some(n) = number_at(s, i, false) {
                out.push(n);
                i = n.end;
                continue;
            }
        }
        i += 1;
    }
    out
}

/// The unit right after byte `j` (at most one space between).
fn unit_at(s: &str, j: usize) -> Option<(&'static str, f64, usize)> {
    let mut k = j;
    if let Some(c) = s[k..].chars().next() {
        if matches!(c, ' ' | '\u{a0}' | '\u{202f}') {
            k += c.len_utf8();
        }
    }
    let rest = &s[k..];
    UNITS.iter().find_map(|&(u, f)| {
        let after = rest.strip_prefix(u)?;
        let next = after.chars().next();
        // A letter unit must end the word ("5 segments" is no figure).
        let letter = u.chars().last().is_some_and(char::is_alphabetic);
        if letter && next.is_some_and(|c| is_word(c) || c == '²') {
            return None;
        }
        Some((u, f, k + u.len()))
    })
}

/// `text` with fenced code blocks and inline code blanked (same byte
/// offsets).
fn mask_code(text: &str) -> String {
    fn blank(out: &mut String, line: &str) {
        for c in line.chars() {
            if c == '\n' {
                out.push(c);
            } else {
                out.extend(std::iter::repeat_n(' ', c.len_utf8()));
            }
        }
    }
    let mut out = String::with_capacity(text.len());
    let mut fenced = false;
    for line in text.split_inclusive('\n') {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            blank(&mut out, line);
            continue;
        }
        if fenced {
            blank(&mut out, line);
            continue;
        }
        let mut inline = false;
        for c in line.chars() {
            if c == '`' {
                inline = !inline;
                out.push(' ');
            } else if inline {
                out.extend(std::iter::repeat_n(' ', c.len_utf8()));
            } else {
                out.push(c);
            }
        }
    }
    assert_eq!(out.len(), text.len());
    out
}

/// Every figure of a README (code masked).
fn figures(text: &str) -> Vec<Figure> {
    let s = mask_code(text);
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        if !s.is_char_boundary(i) {
            i += 1;
            continue;
        }
        let Some(first) = number_at(&s, i, true) else {
            i += 1;
            continue;
        };
        // A range "a–b unit" or "a-b unit": the unit is both's.
        let mut nums = vec![first];
        let mut j = first.end;
        for dash in ['–', '-'] {
            if s[j..].starts_with(dash) {
                if let Some(second) = number_at(&s, j + dash.len_utf8(), true) {
                    nums.push(second);
                    j = second.end;
                }
                break;
            }
        }
        // Sign glyphs before the first number do not matter: values are
        // compared by magnitude.
        if let Some((unit, scale, end)) = unit_at(&s, j) {
            for n in nums {
                out.push(Figure {
                    num: n,
                    unit,
                    scale,
                    text: text[n.start..end].to_string(),
                });
            }
        }
        i = j.max(i + 1);
    }
    out
}

/// The numbers of some files, by magnitude.
#[derive(Default)]
struct Pool(Vec<(f64, f64)>);

impl Pool {
    fn add(&mut self, text: &str) {
        self.0
            .extend(numbers(text).iter().map(|n| (n.value.abs(), n.half_ulp)));
    }
    fn sort(mut self) -> Self {
        self.0.sort_by(|a, b| a.0.total_cmp(&b.0));
        self
    }
    /// A number equal to `value` at the precision `half_ulp` (0: exact, then
    /// at the file number's own precision).
    fn has(&self, value: f64, half_ulp: f64) -> bool {
        let v = value.abs();
        let slack = 1e-9 * v;
        let (lo, hi) = if half_ulp > 0.0 {
            (v - half_ulp - slack, v + half_ulp + slack)
        } else {
            (v * (1.0 - 1e-2), v * (1.0 + 1e-2))
        };
        let from = self.0.partition_point(|p| p.0 < lo);
        self.0[from..]
            .iter()
            .take_while(|p| p.0 <= hi)
            .any(|&(f, h)| half_ulp > 0.0 || (f - v).abs() <= h + slack)
    }
    /// The figure as written or in SI.
    fn traces(&self, f: &Figure) -> bool {
        self.has(f.num.value, f.num.half_ulp)
            || (f.scale != 1.0 && self.has(f.num.value * f.scale, f.num.half_ulp * f.scale))
    }
}

/// Results files (`results/**` csv, json, txt, md) by path relative to the
/// repository, each with its text.
fn results_files(root: &Path) -> BTreeMap<String, String> {
    fn walk(dir: &Path, root: &Path, out: &mut BTreeMap<String, String>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, root, out);
            } else if p
                .extension()
                .is_some_and(|x| ["csv", "json", "txt", "md"].contains(&x.to_str().unwrap_or("")))
            {
                let rel = p.strip_prefix(root).unwrap().to_string_lossy().to_string();
                out.insert(rel, std::fs::read_to_string(&p).unwrap_or_default());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(&root.join("results"), root, &mut out);
    out
}

/// The results files a piece of text names (`results/x.csv`, `x.svg` for
/// its CSV, `results/friction_models/rapier3d/` for what is in it), as keys
/// of `files`.
fn named_files(text: &str, files: &BTreeMap<String, String>) -> Vec<String> {
    let mut names = Vec::new();
    for word in text.split(|c: char| c.is_whitespace() || "`()\"';:".contains(c)) {
        let word = word.trim_end_matches([',', '.']);
        // "x.{csv,svg}" names x.csv and x.svg.
        let expanded: Vec<String> = match word.split_once(".{") {
            Some((stem, exts)) => exts
                .trim_end_matches('}')
                .split(',')
                .map(|e| format!("{stem}.{e}"))
                .collect(),
            None => vec![word.to_string()],
        };
        for w in expanded {
            let w = w.strip_prefix("results/").unwrap_or(&w);
            let w = match w.strip_suffix(".svg") {
                Some(stem) => format!("{stem}.csv"),
                None => w.to_string(),
            };
            if w.is_empty() || !(w.contains('.') || w.ends_with('/')) {
                continue;
            }
            for key in files.keys() {
                let rel = key.strip_prefix("results/").unwrap_or(key);
                let hit = if w.ends_with('/') {
                    rel.starts_with(&w)
                } else {
                    rel == w || rel.ends_with(&format!("/{w}"))
                };
                if hit && !names.contains(key) {
                    names.push(key.clone());
                }
            }
        }
    }
    names
}

/// For each byte of a README, the text whose named files trace a figure
/// there: its block (paragraph, list item, table row), the paragraph that
/// introduces a list or table, and the section's `Data:` line.
fn context_of(text: &str) -> Vec<(usize, usize, String)> {
    let mut out = Vec::new();
    let mut intro = String::new();
    let mut data = String::new();
    let mut block: Option<(usize, String, bool)> = None;
    let mut offset = 0;
    let mut close =
        |block: &mut Option<(usize, String, bool)>, end: usize, intro: &mut String, data: &str| {
            if let Some((start, body, listy)) = block.take() {
                let ctx = if listy {
                    format!("{body}\n{intro}\n{data}")
                } else {
                    format!("{body}\n{data}")
                };
                out.push((start, end, ctx));
                if !listy {
                    *intro = body;
                }
            }
        };
    for line in text.split_inclusive('\n') {
        let t = line.trim();
        let listy = t.starts_with("- ") || t.starts_with('|');
        if t.starts_with('#') {
            close(&mut block, offset, &mut intro, &data);
            intro.clear();
            data.clear();
        } else if t.is_empty() || listy {
            close(&mut block, offset, &mut intro, &data);
        }
        if t.starts_with("Data:") {
            data = t.to_string();
        }
        if !t.is_empty() && !t.starts_with('#') {
            match &mut block {
                Some((_, body, _)) => body.push_str(line),
                None => block = Some((offset, line.to_string(), listy)),
            }
            if t.starts_with('|') {
                // One table row per block.
                close(&mut block, offset + line.len(), &mut intro, &data);
            }
        }
        offset += line.len();
    }
    close(&mut block, offset, &mut intro, &data);
    out
}

/// The figures of `readme` (its path relative to the repository) that
/// nothing traces, each with why; and the allow-list phrases it uses.
fn untraced(
    readme: &str,
    text: &str,
    files: &BTreeMap<String, String>,
    inputs: &Pool,
    allowed: &[(&str, &str, &str)],
    anywhere: bool,
) -> (Vec<String>, Vec<usize>) {
    let pools: BTreeMap<&str, Pool> = files
        .iter()
        .filter(|(k, _)| k.as_str() != readme)
        .map(|(k, v)| {
            let mut p = Pool::default();
            p.add(v);
            (k.as_str(), p.sort())
        })
        .collect();
    let mut all = Pool::default();
    for (k, v) in files {
        if k != readme {
            all.add(v);
        }
    }
    let all = all.sort();
    // Allowed spans of this README.
    let mut spans = Vec::new();
    for (n, &(file, phrase, _)) in allowed.iter().enumerate() {
        if file == readme {
            for (at, _) in text.match_indices(phrase) {
                spans.push((at, at + phrase.len(), n));
            }
        }
    }
    let contexts = context_of(text);
    let mut used = Vec::new();
    let mut bad = Vec::new();
    for f in figures(text) {
        let end = f.num.start + f.text.len();
        if let Some(&(_, _, n)) = spans
            .iter()
            .find(|(a, b, _)| *a <= f.num.start && end <= *b)
        {
            used.push(n);
            continue;
        }
        if inputs.traces(&f) {
            continue;
        }
        let ctx = contexts
            .iter()
            .find(|(a, b, _)| *a <= f.num.start && f.num.start < *b)
            .map_or("", |c| c.2.as_str());
        let named: Vec<String> = named_files(ctx, files)
            .into_iter()
            .filter(|k| k != readme)
            .collect();
        if named.iter().any(|k| pools[k.as_str()].traces(&f)) {
            continue;
        }
        if anywhere && all.traces(&f) {
            continue;
        }
        let line = text[..f.num.start].matches('\n').count() + 1;
        let why = if named.is_empty() && !anywhere {
            "names no results file beside it".to_string()
        } else if named.is_empty() {
            "in no results file".to_string()
        } else {
            format!("in none of {}", named.join(", "))
        };
        bad.push(format!(
            "{readme}:{line}: \"{}\" ({}): {why}",
            f.text, f.unit
        ));
    }
    (bad, used)
}

/// The numbers of the shipped scenarios: inputs, not results.
fn scenario_numbers(root: &Path) -> Pool {
    let mut p = Pool::default();
    let mut paths: Vec<PathBuf> = std::fs::read_dir(root.join("scenarios"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    for path in paths {
        p.add(&std::fs::read_to_string(path).unwrap());
    }
    p.sort()
}

/// The documents whose figures are checked, each with whether a figure may
/// be traced anywhere in `results/` (`results/README.md`) or only in a file
/// named beside it (README.md and every `docs/*.md`).
fn documents(root: &Path) -> Vec<(String, bool)> {
    let mut docs: Vec<String> = std::fs::read_dir(root.join("docs"))
        .map(|d| {
            d.flatten()
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "md"))
                .map(|p| format!("docs/{}", p.file_name().unwrap().to_string_lossy()))
                .collect()
        })
        .unwrap_or_default();
    docs.sort();
    let mut out = vec![("README.md".to_string(), false)];
    out.extend(docs.into_iter().map(|d| (d, false)));
    out.push(("results/README.md".to_string(), true));
    out
}

#[test]
fn readme_figures_come_from_results_files() {
    let root = root();
    let files = results_files(&root);
    let inputs = scenario_numbers(&root);
    let mut bad = Vec::new();
    let mut used = Vec::new();
    for (readme, anywhere) in documents(&root) {
        let text = std::fs::read_to_string(root.join(&readme)).unwrap();
        let (b, u) = untraced(&readme, &text, &files, &inputs, ALLOWED, anywhere);
        bad.extend(b);
        used.extend(u);
    }
    for (n, (file, phrase, reason)) in ALLOWED.iter().enumerate() {
        assert!(
            !reason.is_empty(),
            "allow-list entry {phrase:?} needs a reason"
        );
        if !used.contains(&n) {
            bad.push(format!(
                "{file}: allow-list phrase {phrase:?} covers no figure: remove it"
            ));
        }
    }
    assert!(
        bad.is_empty(),
        "{} README figure(s) not traced to a results file:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

/// The matcher on made-up text: what traces a figure and what does not.
#[test]
fn matcher_flags_an_untraceable_figure() {
    let mut files = BTreeMap::new();
    files.insert(
        "results/t.csv".to_string(),
        "method,median_s,frac,dt_s\npushval,1.8720e-5,0.029,1.666667e-2\nother,7.1e-4,3.56x,2\n"
            .to_string(),
    );
    let inputs = Pool(vec![(0.5, 0.0)]);
    let check = |text: &str| {
        untraced("README.md", text, &files, &inputs, &[], false)
            .0
            .len()
    };
    // Traced at the written precision, as written or in SI.
    assert_eq!(check("It takes 18.7 µs (`results/t.csv`)."), 0);
    assert_eq!(check("It takes 1.87e-5 s (`t.csv`)."), 0);
    assert_eq!(check("A share of 2.9 % (`t.svg`)."), 0);
    assert_eq!(check("At dt = 1/60 s, 0.71 ms (`results/t.csv`)."), 0);
    assert_eq!(check("Faster: 3.56× (`t.csv`)."), 0);
    assert_eq!(check("Pushed at 0.5 m/s, an input."), 0);
    // A list item traced by the file its introducing paragraph names.
    assert_eq!(check("In `t.csv`:\n\n- it takes 18.7 µs;\n"), 0);
    // Not traced: a more precise figure the file rounds differently, a
    // number no file holds, a figure whose file is not named beside it.
    assert_eq!(check("It takes 18.75 µs (`t.csv`)."), 1);
    assert_eq!(check("It takes 18.8 µs (`t.csv`)."), 1);
    assert_eq!(
        check("A run of 5.9 / 3.35 ms in one such run (`t.csv`)."),
        1
    );
    assert_eq!(check("The sweep takes 3.35 ms and 3.16× (`t.csv`)."), 2);
    assert_eq!(check("It takes 18.7 µs.\n\nSee `t.csv`."), 1);
    assert_eq!(check("1.04–1.11 ns per support (`t.csv`)"), 2);
    // Code and words are not figures.
    assert_eq!(
        check("`cargo bench -- 5.9 ms` and 5 segments, rapier3d, 2D."),
        0
    );
    // A thousands separator in prose.
    assert_eq!(
        check("10,000 s (`t.csv`) is not 10 s."),
        2,
        "10,000 s and 10 s are both untraced"
    );
    // The allow-list covers a phrase, and only it.
    let allowed = [("README.md", "for 5.9 ms by design", "a constant")];
    let (bad, used) = untraced(
        "README.md",
        "Waits for 5.9 ms by design; 3.35 ms not.",
        &files,
        &inputs,
        &allowed,
        false,
    );
    assert_eq!((bad.len(), used), (1, vec![0]));
}
