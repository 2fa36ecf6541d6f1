//! `map.svg`: a model's (Fr, φ) map drawn from its `map.csv` text alone
//! (so `pushval study index` redraws it without running the engine). Two
//! panels: the engine's error against Coulomb and against its own law with
//! the problem's loads, and a third, against its law on the run's own loads
//! (`omega_law_run`), wherever the engine measured its loads: an engine
//! whose feet unload as it turns follows its law there and not with the
//! problem's statics. One coloured cell per row, by decade of the error;
//! cells where the law locks are outlined black, semi-stable ones purple.

use plotters::style::RGBColor;

use super::plate::{err, froude};
use crate::outdir::{field_num as num, records};
use crate::plot::{cell_edges, heat_map, Axis, Cell, Figure, MapCell, Scale, DARK, GREY, PURPLE};

/// The error classes' lower bounds (dimensionless): class k is
/// `BOUNDS[k-1] ≤ error < BOUNDS[k]`.
pub const BOUNDS: [f64; 4] = [1e-4, 1e-3, 1e-2, 1e-1];

const COLORS: [RGBColor; 5] = [
    RGBColor(26, 152, 80),
    RGBColor(166, 217, 106),
    RGBColor(255, 237, 160),
    RGBColor(253, 174, 97),
    RGBColor(215, 48, 39),
];

/// The class of an error: the number of bounds it reaches (NaN stays NaN,
/// drawn grey).
fn class(e: f64) -> f64 {
    if e.is_nan() {
        f64::NAN
    } else {
        BOUNDS.iter().filter(|&&b| e >= b).count() as f64
    }
}

/// Sorted distinct values.
fn grid(mut v: Vec<f64>) -> Vec<f64> {
    v.retain(|x| x.is_finite());
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// A map cell's errors against Coulomb, the law with the problem's loads
/// and the law on the run's own loads (None where the file has no law ω,
/// an absent column or a blank cell): relative with the gate's floor, or
/// |ω|/|ω*| where the reference locks (NaN where the engine's ω is).
pub fn cell_errors(r: &std::collections::BTreeMap<String, String>) -> [Option<f64>; 3] {
    let speed = (num(r, "froude") / froude(1.0)).sqrt();
    let (we, wc) = (num(r, "omega_engine"), num(r, "omega_coulomb"));
    ["omega_coulomb", "omega_law", "omega_law_run"].map(|k| match num(r, k) {
        w if w.is_finite() || k == "omega_coulomb" => Some(err(we, w, wc, speed)),
        _ => None,
    })
}

/// The figure of `map.csv`'s text (columns froude, phi, omega_engine,
/// omega_coulomb, omega_law, class). Errors as in the README: relative with
/// the gate's floor, or |ω|/|ω*| where the reference is a lock.
pub fn map_figure(model: &str, csv: &str) -> anyhow::Result<Figure> {
    let rows = records(csv)?;
    anyhow::ensure!(!rows.is_empty(), "map.csv of {model} has no rows");
    let frs = grid(rows.iter().map(|r| num(r, "froude")).collect());
    let phis = grid(rows.iter().map(|r| num(r, "phi")).collect());
    let (fe, pe) = (cell_edges(&frs, true), cell_edges(&phis, false));
    let at = |v: f64, g: &[f64], e: &[(f64, f64)]| g.iter().position(|&x| x == v).map(|i| e[i]);
    let (mut coulomb, mut law, mut law_run, mut outlines) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for r in &rows {
        let (Some(x), Some(y)) = (
            at(num(r, "froude"), &frs, &fe),
            at(num(r, "phi"), &phis, &pe),
        ) else {
            anyhow::bail!("map.csv of {model}: a row without froude or phi");
        };
        // Absent column or empty cell: no law, or no loads measured there.
        for (cells, e) in [&mut coulomb, &mut law, &mut law_run]
            .into_iter()
            .zip(cell_errors(r))
        {
            cells.extend(e.map(|e| MapCell {
                x,
                y,
                value: class(e),
                mark: String::new(),
            }));
        }
        let color = match r.get("class").map(String::as_str) {
            Some("locked") => Some(DARK),
            Some("semi_stable") => Some(PURPLE),
            _ => None,
        };
        if let Some(color) = color {
            outlines.push(Cell { x, y, color });
        }
    }
    let scale = Scale::Classes(COLORS.to_vec());
    let (xr, yr) = ((fe[0].0, fe[fe.len() - 1].1), (pe[0].0, pe[pe.len() - 1].1));
    let axes = || {
        (
            Axis::log("Froude number Fr = v_c² / (μ̄ g L)").range(xr.0, xr.1),
            Axis::lin("push direction φ (rad)").range(yr.0, yr.1),
        )
    };
    let titles = [
        format!("{model}: error against Coulomb"),
        if law.is_empty() {
            format!("{model}: no law declared")
        } else if law_run.is_empty() {
            format!("{model}: error against its law")
        } else {
            format!("{model}: against its law, problem's loads")
        },
        format!("{model}: against its law, run's own loads"),
    ];
    // The third panel only where the engine measured its loads.
    let panels: Vec<_> = [coulomb, law, law_run]
        .iter()
        .zip(titles)
        .enumerate()
        .filter(|(k, (cells, _))| *k < 2 || !cells.is_empty())
        .map(|(_, (cells, title))| {
            let (x, y) = axes();
            let mut panel = heat_map(title, x, y, cells, &scale);
            panel.outlines.clone_from(&outlines);
            panel
        })
        .collect();
    let labels = [
        "< 1e-4",
        "1e-4 – 1e-3",
        "1e-3 – 1e-2",
        "1e-2 – 1e-1",
        "≥ 1e-1",
    ];
    let refs: &[&str] = if panels.len() == 3 {
        &[
            "engine's law on the problem's",
            "loads (middle), on the run's",
            "own loads (right)",
        ]
    } else {
        &["engine's law (right)"]
    };
    let notes: Vec<String> = [
        "relative steady-ω error",
        "|ω_engine − ω_ref| / |ω_ref|,",
        "ref: Coulomb (left), the",
    ]
    .iter()
    .chain(refs)
    .map(|n| n.to_string())
    .collect();
    let mut key = scale.key("error", &labels, &notes);
    key.entries.push(("undefined".to_string(), GREY));
    key.outlined = vec![
        ("law locks".to_string(), DARK),
        ("law semi-stable".to_string(), PURPLE),
    ];
    Ok(Figure {
        size: (if panels.len() == 3 { 2150 } else { 1500 }, 640),
        cols: panels.len(),
        panels,
        key: Some(key),
    })
}
