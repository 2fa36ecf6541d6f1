//! The listings: `pushval engines` (every engine model) and `pushval laws`
//! (every catalogue law, with the engines that declare it).
//!
//! The catalogue of laws names no engine; each engine declares its law
//! (`Engine::law`, an outside engine `law = "NAME"` in `pushval.toml`), and
//! the laws' listing joins the two here.

use pushval_engine::FrictionLaw;
use pushval_laws::{LawEntry, ParamKind, ParamSpec};
use pushval_scenario::ANALYTIC_MODELS;

use super::models::{crate_entries, entries};
use super::project::outside_engines;

/// The `pushval engines` table: one row per engine model.
pub fn engines_table() -> String {
    let rows: Vec<[String; 6]> = entries()
        .iter()
        .map(|e| {
            let engine = e.default_engine();
            [
                e.name.clone(),
                engine.adapter().to_string(),
                engine.version(),
                format!("{}", engine.order()),
                if engine.gateable() { "yes" } else { "no" }.to_string(),
                match engine.availability() {
                    Ok(()) => "yes".to_string(),
                    Err(why) => format!("no: {why}"),
                },
            ]
        })
        .collect();
    let header = [
        "model",
        "crate",
        "engine",
        "order",
        "gateable",
        "in this build",
    ];
    let mut width = header.map(str::len);
    for r in &rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: &[String]| {
        let mut s = String::new();
        for (i, (c, w)) in cells.iter().zip(width).enumerate() {
            if i + 1 == cells.len() {
                s.push_str(c);
            } else {
                s.push_str(&format!("{c:<w$}  "));
            }
        }
        s.trim_end().to_string() + "\n"
    };
    let mut out = line(&header.map(String::from));
    for r in &rows {
        out.push_str(&line(r));
    }
    out.push_str(&format!(
        "\norder: of accuracy in dt of the steady ω and trajectory. Analytic models (always in the build): {}.\n",
        ANALYTIC_MODELS.join(", ")
    ));
    out
}

/// Each catalogue law with the engines that declare it, in catalogue order.
///
/// A compiled-in model declares the entry whose default law is the law it
/// follows with its default options (`Engine::law`), told by [`law_key`]; an
/// outside engine of the loaded `pushval.toml` declares the entry it names
/// (`law = "NAME"`). Compiled-in models come first, in registry order.
pub fn declarations() -> Vec<(LawEntry, Vec<String>)> {
    let models: Vec<(String, &'static str)> = crate_entries()
        .iter()
        .filter_map(|m| {
            let engine = m.default_engine();
            let law = law_key(engine.law()?);
            Some((m.name.to_string(), law))
        })
        .collect();
    let outside = outside_engines();
    pushval_laws::catalog()
        .into_iter()
        .map(|entry| {
            let law = law_key(&*entry.default_law());
            let engines = models
                .iter()
                .filter(|(_, l)| *l == law)
                .map(|(m, _)| m.clone())
                .chain(
                    outside
                        .iter()
                        .filter(|s| s.law.as_deref() == Some(entry.name))
                        .map(|s| s.name.clone()),
                )
                .collect();
            (entry, engines)
        })
        .collect()
}

/// What tells a law's catalogue entry: the entry it names
/// ([`FrictionLaw::catalog_name`]), else its name ([`FrictionLaw::law_name`];
/// a test checks that these keys tell every catalogue entry apart).
pub fn law_key(law: &dyn FrictionLaw) -> &'static str {
    law.catalog_name().unwrap_or_else(|| law.law_name())
}

/// A parameter's default as `pushval laws` shows it (`0.01 m/s`, `"welded"`).
fn param_text(p: &ParamSpec) -> String {
    let default = match (&p.default, p.kind) {
        (serde_json::Value::String(s), ParamKind::Choice(all)) => {
            format!("{s} (of {})", all.join("|"))
        }
        (v, _) => v.to_string(),
    };
    if p.unit.is_empty() {
        format!("{}={default}", p.name)
    } else {
        format!("{}={default} {}", p.name, p.unit)
    }
}

/// The `pushval laws` table: one row per catalogue law (name, the engines
/// that declare it, its parameters with defaults, where its loads come
/// from), each followed by its one-sentence description.
pub fn laws_table() -> String {
    let laws = declarations();
    let rows: Vec<[String; 4]> = laws
        .iter()
        .map(|(e, engines)| {
            let params: Vec<String> = e.params.iter().map(param_text).collect();
            [
                e.name.to_string(),
                if engines.is_empty() {
                    "-".into()
                } else {
                    engines.join(",")
                },
                if params.is_empty() {
                    "-".into()
                } else {
                    params.join(", ")
                },
                e.loads.as_str().to_string(),
            ]
        })
        .collect();
    let header = ["law", "engines", "parameters (defaults)", "loads"];
    let mut width = header.map(|h| h.chars().count());
    for r in &rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: &[String]| {
        let mut s = String::new();
        for (c, w) in cells.iter().zip(width) {
            s.push_str(c);
            s.push_str(&" ".repeat(w - c.chars().count() + 2));
        }
        s.trim_end().to_string() + "\n"
    };
    let mut out = line(&header.map(String::from));
    for (r, (e, _)) in rows.iter().zip(&laws) {
        out.push_str(&line(r));
        out.push_str(&format!("    {}\n", e.about));
    }
    out.push_str(
        "\nloads: problem = the problem's support loads (its statics); law = the law's own prediction from the problem's geometry and mass.\nAn engine in pushval.toml declares one with law = \"NAME\" and, optionally, law_params = { key = value }.\n",
    );
    out
}

/// `pushval laws --json`: an array with one object per catalogue law:
/// `name`, `engines`, `params` (`name`, `default`, `unit`, `meaning`),
/// `loads` and `about`.
pub fn laws_json() -> serde_json::Value {
    declarations()
        .iter()
        .map(|(e, engines)| {
            serde_json::json!({
                "name": e.name,
                "engines": engines,
                "params": e.params.iter().map(|p| serde_json::json!({
                    "name": p.name,
                    "default": p.default,
                    "unit": p.unit,
                    "meaning": p.meaning,
                })).collect::<Vec<_>>(),
                "loads": e.loads.as_str(),
                "about": e.about,
            })
        })
        .collect()
}
