//! Figure drawing for `pushval report`, `pushval study` and `pushval stress`:
//! line plots (a [`Panel`] of [`Series`]) and heat maps ([`heat_map`]: a
//! panel of coloured cells, with a [`Scale`] from value to colour and an
//! optional mark written in each cell), rendered to SVG text with plotters
//! (no system fonts needed: the SVG names a generic font family and the
//! viewer renders the text).

use anyhow::anyhow;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stroke {
    Solid,
    Dashed,
    /// A line of short dashes (finer than [`Stroke::Dashed`]).
    Dotted,
    /// Small filled circles at the points (for the engine drawn over a model).
    Dots,
}

/// One curve of a panel.
#[derive(Debug, Clone)]
pub struct Series {
    pub label: String,
    pub color: RGBColor,
    pub stroke: Stroke,
    pub width: u32,
    pub points: Vec<(f64, f64)>,
}

impl Series {
    pub fn new(label: impl Into<String>, color: RGBColor, stroke: Stroke) -> Self {
        Self {
            label: label.into(),
            color,
            stroke,
            width: 2,
            points: Vec::new(),
        }
    }
    #[must_use]
    pub fn points(mut self, points: Vec<(f64, f64)>) -> Self {
        self.points = points;
        self
    }
    #[must_use]
    pub fn width(mut self, width: u32) -> Self {
        self.width = width;
        self
    }
}

/// One axis: its label (with the unit) and whether it is logarithmic.
#[derive(Debug, Clone)]
pub struct Axis {
    pub label: String,
    pub log: bool,
    /// Fixed range; None: fitted to the data with a 4 % margin.
    pub range: Option<(f64, f64)>,
    /// Whether the axis has numbered ticks and grid lines (false for a
    /// table drawn as a map: its cells carry their own labels).
    pub ticks: bool,
}

impl Axis {
    pub fn lin(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            log: false,
            range: None,
            ticks: true,
        }
    }
    pub fn log(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            log: true,
            range: None,
            ticks: true,
        }
    }
    /// No numbered ticks and no grid lines.
    #[must_use]
    pub fn without_ticks(mut self) -> Self {
        self.ticks = false;
        self
    }
    #[must_use]
    pub fn range(mut self, lo: f64, hi: f64) -> Self {
        self.range = Some((lo, hi));
        self
    }
}

/// A filled rectangle of a map, in data coordinates.
#[derive(Debug, Clone, Copy)]
pub struct Cell {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub color: RGBColor,
}

/// A short text written centred at a point of a panel (data coordinates).
#[derive(Debug, Clone)]
pub struct Mark {
    pub at: (f64, f64),
    pub text: String,
}

/// Where the legend goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Legend {
    UpperRight,
    UpperLeft,
    LowerRight,
    LowerLeft,
    None,
    /// In a column beside the panels (the figure's key area), one entry per
    /// label over every such panel: nothing is drawn over the data.
    Outside,
}

/// One chart.
#[derive(Debug, Clone)]
pub struct Panel {
    pub title: String,
    pub x: Axis,
    pub y: Axis,
    pub series: Vec<Series>,
    pub cells: Vec<Cell>,
    /// Rectangles drawn as outlines (2 px, in their `color`) over the cells:
    /// a map's cells of some class.
    pub outlines: Vec<Cell>,
    /// Texts drawn over the cells (a heat map's per-cell marks).
    pub marks: Vec<Mark>,
    pub legend: Legend,
    /// Same scale on both axes (for x–y paths).
    pub equal_aspect: bool,
}

impl Panel {
    pub fn new(title: impl Into<String>, x: Axis, y: Axis) -> Self {
        Self {
            title: title.into(),
            x,
            y,
            series: Vec::new(),
            cells: Vec::new(),
            outlines: Vec::new(),
            marks: Vec::new(),
            legend: Legend::UpperRight,
            equal_aspect: false,
        }
    }
    #[must_use]
    pub fn series(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }
    #[must_use]
    pub fn legend(mut self, l: Legend) -> Self {
        self.legend = l;
        self
    }
    #[must_use]
    pub fn equal_aspect(mut self) -> Self {
        self.equal_aspect = true;
        self
    }
}

/// Colour classes drawn as a key beside a map.
#[derive(Debug, Clone, Default)]
pub struct Key {
    pub title: String,
    /// Filled swatches.
    pub entries: Vec<(String, RGBColor)>,
    /// Outlined swatches (a map's cell edges), after the filled ones.
    pub outlined: Vec<(String, RGBColor)>,
    /// Lines of text under the swatches (what the colours measure).
    pub notes: Vec<String>,
}

/// A figure: panels on a grid of `cols` columns, optionally a colour key on
/// the right.
#[derive(Debug, Clone)]
pub struct Figure {
    pub size: (u32, u32),
    pub cols: usize,
    pub panels: Vec<Panel>,
    pub key: Option<Key>,
}

pub const BLUE_: RGBColor = RGBColor(31, 119, 180);
pub const ORANGE: RGBColor = RGBColor(255, 127, 14);
pub const GREEN_: RGBColor = RGBColor(44, 160, 44);
pub const RED_: RGBColor = RGBColor(214, 39, 40);
pub const PURPLE: RGBColor = RGBColor(148, 103, 189);
pub const BROWN: RGBColor = RGBColor(140, 86, 75);
pub const PINK: RGBColor = RGBColor(227, 119, 194);
pub const GREY: RGBColor = RGBColor(110, 110, 110);
pub const OLIVE: RGBColor = RGBColor(188, 189, 34);
pub const CYAN_: RGBColor = RGBColor(23, 190, 207);
pub const DARK: RGBColor = RGBColor(20, 20, 20);

/// A fixed palette for numbered curves.
pub const PALETTE: [RGBColor; 10] = [
    BLUE_, ORANGE, GREEN_, RED_, PURPLE, BROWN, PINK, GREY, OLIVE, CYAN_,
];

const FONT: &str = "sans-serif";

/// How a heat map turns a cell's value into a colour.
#[derive(Debug, Clone, PartialEq)]
pub enum Scale {
    /// The value is a class index (0, 1, …) into these colours.
    Classes(Vec<RGBColor>),
    /// `log10` of the value on a blue (decade `lo`) to red (decade `hi`)
    /// ramp, clamped at both ends; zero and negative values are blue.
    Log10 { lo: f64, hi: f64 },
}

impl Scale {
    /// The colour of `value`; grey where it is NaN (or not a class).
    pub fn color(&self, value: f64) -> RGBColor {
        match self {
            Scale::Classes(colors) => {
                if value.is_nan() || value < 0.0 {
                    return GREY;
                }
                colors.get(value as usize).copied().unwrap_or(GREY)
            }
            Scale::Log10 { lo, hi } => {
                if value.is_nan() {
                    return GREY;
                }
                let s = if value > 0.0 {
                    ((value.log10() - lo) / (hi - lo)).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                RGBColor(
                    (40.0 + 215.0 * s) as u8,
                    (80.0 + 120.0 * (1.0 - (2.0 * s - 1.0).abs())) as u8,
                    (255.0 * (1.0 - s)) as u8,
                )
            }
        }
    }

    /// A key for the scale: for [`Scale::Log10`] one entry per decade from
    /// `lo` to `hi` (the ends read ≤ and ≥), for [`Scale::Classes`] the
    /// classes with `labels`; then `notes` (e.g. what a cell's mark means),
    /// as lines of text.
    pub fn key(&self, title: &str, labels: &[&str], notes: &[String]) -> Key {
        let entries: Vec<(String, RGBColor)> = match self {
            Scale::Classes(colors) => labels
                .iter()
                .zip(colors)
                .map(|(l, c)| (l.to_string(), *c))
                .collect(),
            Scale::Log10 { lo, hi } => {
                let (a, b) = (lo.ceil() as i32, hi.floor() as i32);
                (a..=b)
                    .map(|d| {
                        let label = if d == a {
                            format!("≤ 1e{d}")
                        } else if d == b {
                            format!("≥ 1e{d}")
                        } else {
                            format!("1e{d}")
                        };
                        (label, self.color(10f64.powi(d)))
                    })
                    .collect()
            }
        };
        Key {
            title: title.to_string(),
            entries,
            outlined: Vec::new(),
            notes: notes.to_vec(),
        }
    }
}

/// One cell of a heat map: its extent in data coordinates, its value and a
/// mark written at its centre (empty: none).
#[derive(Debug, Clone, PartialEq)]
pub struct MapCell {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub value: f64,
    pub mark: String,
}

/// The heat map: a panel with one filled rectangle per cell, coloured by
/// `scale`, and each cell's mark written at its centre. Lines (e.g.
/// contours) are added to it as series, like to any panel.
pub fn heat_map(
    title: impl Into<String>,
    x: Axis,
    y: Axis,
    cells: &[MapCell],
    scale: &Scale,
) -> Panel {
    let mut p = Panel::new(title, x, y);
    for c in cells {
        p.cells.push(Cell {
            x: c.x,
            y: c.y,
            color: scale.color(c.value),
        });
        if !c.mark.is_empty() {
            p.marks.push(Mark {
                at: (0.5 * (c.x.0 + c.x.1), 0.5 * (c.y.0 + c.y.1)),
                text: c.mark.clone(),
            });
        }
    }
    p
}

/// Cell extents around sorted grid values: the edges halfway between
/// neighbours (in log10 on a log axis), the outer cells symmetric about their
/// value. A single value gets half a unit (log: half a decade) either side.
pub fn cell_edges(values: &[f64], log: bool) -> Vec<(f64, f64)> {
    let t: Vec<f64> = values
        .iter()
        .map(|&v| if log { v.log10() } else { v })
        .collect();
    let back = |v: f64| if log { 10f64.powf(v) } else { v };
    let n = t.len();
    (0..n)
        .map(|i| {
            let lo = if i > 0 {
                0.5 * (t[i - 1] + t[i])
            } else if n > 1 {
                t[0] - 0.5 * (t[1] - t[0])
            } else {
                t[0] - 0.5
            };
            let hi = if i + 1 < n {
                0.5 * (t[i] + t[i + 1])
            } else if n > 1 {
                t[i] + 0.5 * (t[i] - t[i - 1])
            } else {
                t[0] + 0.5
            };
            (back(lo), back(hi))
        })
        .collect()
}

fn data_range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (0.1, 1.0) } else { (0.0, 1.0) };
    }
    if log {
        let (a, b) = (lo.log10(), hi.log10());
        let m = ((b - a) * 0.04).max(0.05);
        (10f64.powf(a - m), 10f64.powf(b + m))
    } else {
        let m = ((hi - lo) * 0.04).max(1e-9 * hi.abs().max(1.0));
        (lo - m, hi + m)
    }
}

fn ranges(p: &Panel, pixels: (u32, u32)) -> ((f64, f64), (f64, f64)) {
    let xs = p
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|q| q.0))
        .chain(p.cells.iter().flat_map(|c| [c.x.0, c.x.1]));
    let ys = p
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|q| q.1))
        .chain(p.cells.iter().flat_map(|c| [c.y.0, c.y.1]));
    let mut xr = p.x.range.unwrap_or_else(|| data_range(xs, p.x.log));
    let mut yr = p.y.range.unwrap_or_else(|| data_range(ys, p.y.log));
    if p.equal_aspect {
        // Plot area is roughly the panel less the label areas.
        let w = pixels.0.saturating_sub(100).max(1) as f64;
        let h = pixels.1.saturating_sub(90).max(1) as f64;
        let (dx, dy) = (xr.1 - xr.0, yr.1 - yr.0);
        let scale = (dx / w).max(dy / h);
        let (cx, cy) = (0.5 * (xr.0 + xr.1), 0.5 * (yr.0 + yr.1));
        xr = (cx - 0.5 * scale * w, cx + 0.5 * scale * w);
        yr = (cy - 0.5 * scale * h, cy + 0.5 * scale * h);
    }
    (xr, yr)
}

/// Renders the figure to SVG text.
pub fn render(fig: &Figure) -> anyhow::Result<String> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, fig.size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e:?}"))?;
        // Series of the panels whose legend is outside, one per label.
        let mut outside: Vec<&Series> = Vec::new();
        for p in fig.panels.iter().filter(|p| p.legend == Legend::Outside) {
            for s in p.series.iter().filter(|s| !s.label.is_empty()) {
                if !outside.iter().any(|o| o.label == s.label) {
                    outside.push(s);
                }
            }
        }
        let width = if outside.is_empty() { 230 } else { 300 };
        let (main, key_area) = if fig.key.is_some() || !outside.is_empty() {
            let (a, b) = root.split_horizontally(fig.size.0.saturating_sub(width));
            (a, Some(b))
        } else {
            (root.clone(), None)
        };
        let rows = fig.panels.len().div_ceil(fig.cols.max(1));
        let areas = main.split_evenly((rows, fig.cols.max(1)));
        for (area, p) in areas.iter().zip(&fig.panels) {
            panel(area, p).map_err(|e| anyhow!("panel '{}': {e:#}", p.title))?;
        }
        if let Some(a) = key_area {
            let empty = Key::default();
            key(&a, fig.key.as_ref().unwrap_or(&empty), &outside).map_err(|e| anyhow!("{e:?}"))?;
        }
        root.present().map_err(|e| anyhow!("{e:?}"))?;
    }
    Ok(buf)
}

fn key<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    k: &Key,
    series: &[&Series],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let title = (FONT, 17).into_font().color(&BLACK);
    let text = (FONT, 15).into_font().color(&BLACK);
    let small = (FONT, 13).into_font().color(&BLACK);
    let mut y = 60;
    if !k.title.is_empty() {
        area.draw(&Text::new(k.title.clone(), (10, y), title.clone()))?;
        y += 35;
    }
    for (label, color) in &k.entries {
        area.draw(&Rectangle::new([(12, y), (36, y + 20)], color.filled()))?;
        area.draw(&Rectangle::new(
            [(12, y), (36, y + 20)],
            BLACK.stroke_width(1),
        ))?;
        area.draw(&Text::new(label.clone(), (44, y + 3), text.clone()))?;
        y += 32;
    }
    for (label, color) in &k.outlined {
        // A thick edge: the colour filled, a white inset over it (the SVG
        // backend writes no stroke width for rectangles).
        area.draw(&Rectangle::new([(12, y), (36, y + 20)], color.filled()))?;
        area.draw(&Rectangle::new([(15, y + 3), (33, y + 17)], WHITE.filled()))?;
        area.draw(&Text::new(label.clone(), (44, y + 3), text.clone()))?;
        y += 32;
    }
    for note in &k.notes {
        area.draw(&Text::new(note.clone(), (12, y + 3), small.clone()))?;
        y += 22;
    }
    if !series.is_empty() {
        y += 10;
        for s in series {
            let style = ShapeStyle {
                color: s.color.to_rgba(),
                filled: false,
                stroke_width: s.width,
            };
            let yc = y + 9;
            match s.stroke {
                Stroke::Solid => area.draw(&PathElement::new(vec![(10, yc), (40, yc)], style))?,
                Stroke::Dashed => {
                    for x in [10, 23] {
                        area.draw(&PathElement::new(vec![(x, yc), (x + 8, yc)], style))?;
                    }
                }
                Stroke::Dotted => {
                    for x in (10..40).step_by(6) {
                        area.draw(&PathElement::new(vec![(x, yc), (x + 2, yc)], style))?;
                    }
                }
                Stroke::Dots => {
                    for x in [14, 25, 36] {
                        area.draw(&Circle::new((x, yc), 3, s.color.filled()))?;
                    }
                }
            }
            area.draw(&Text::new(s.label.clone(), (48, y + 1), small.clone()))?;
            y += 21;
        }
    }
    Ok(())
}

/// A colour per family and a stroke per member: `names` grouped by the part
/// before the first `_` or `[` (the engine: `rapier2d`, `jolt`, …), each
/// family one colour of [`PALETTE`], its members told apart by
/// [`Stroke::Solid`], [`Stroke::Dashed`], [`Stroke::Dotted`] and
/// [`Stroke::Dots`] in turn (then the next palette colour). No two names
/// share colour and stroke: past the palette's ten colours a family whose
/// pair is taken takes its colour's next free stroke, else the next colour
/// with one; [`GREY`] dashed stays free for reference lines (targets).
pub fn family_styles(names: &[&str]) -> Vec<(RGBColor, Stroke)> {
    const STROKES: [Stroke; 4] = [Stroke::Solid, Stroke::Dashed, Stroke::Dotted, Stroke::Dots];
    let family = |n: &str| n.split(['_', '[']).next().unwrap_or(n).to_string();
    let grey = PALETTE.iter().position(|c| *c == GREY);
    // (colour index, stroke index) pairs taken, the reference line's first.
    let mut used: Vec<(usize, usize)> = grey.map(|g| (g, 1)).into_iter().collect();
    let mut families: Vec<String> = Vec::new();
    let mut members: Vec<usize> = Vec::new();
    let mut colour_of: Vec<usize> = Vec::new();
    let mut next_colour = 0;
    names
        .iter()
        .map(|n| {
            let f = family(n);
            let i = families.iter().position(|g| *g == f).unwrap_or_else(|| {
                families.push(f);
                members.push(0);
                colour_of.push(next_colour);
                next_colour += 1;
                families.len() - 1
            });
            let m = members[i];
            members[i] += 1;
            if m > 0 && m % STROKES.len() == 0 {
                colour_of[i] = next_colour;
                next_colour += 1;
            }
            let (c0, s0) = (colour_of[i] % PALETTE.len(), m % STROKES.len());
            // The preferred pair, else the first free one after it.
            let n_pairs = PALETTE.len() * STROKES.len();
            let (c, s) = (0..n_pairs)
                .map(|k| {
                    let s = (s0 + k) % STROKES.len();
                    let c = (c0 + (s0 + k) / STROKES.len()) % PALETTE.len();
                    (c, s)
                })
                .find(|p| !used.contains(p))
                .unwrap_or((c0, s0));
            used.push((c, s));
            (PALETTE[c], STROKES[s])
        })
        .collect()
}

fn panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let ((x0, x1), (y0, y1)) = ranges(p, area.dim_in_pixel());
    match (p.x.log, p.y.log) {
        (false, false) => draw_in(area, p, x0..x1, y0..y1),
        (true, false) => draw_in(area, p, (x0..x1).log_scale(), y0..y1),
        (false, true) => draw_in(area, p, x0..x1, (y0..y1).log_scale()),
        (true, true) => draw_in(area, p, (x0..x1).log_scale(), (y0..y1).log_scale()),
    }
}

fn short(v: f64) -> String {
    if v.abs() < 1e-12 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e4).contains(&a) {
        return format!("{v:.0e}");
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

fn draw_in<DB: DrawingBackend, X, Y>(
    area: &DrawingArea<DB, Shift>,
    p: &Panel,
    x: X,
    y: Y,
) -> anyhow::Result<()>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("{e:?}");
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, (FONT, 19))
        .margin(12)
        .margin_right(22)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    let fmt = |v: &f64| short(*v);
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(p.x.label.as_str())
        .y_desc(p.y.label.as_str())
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .bold_line_style(RGBColor(225, 225, 225))
        .light_line_style(RGBColor(244, 244, 244));
    if !p.x.ticks {
        mesh.x_labels(0).disable_x_mesh();
    }
    if !p.y.ticks {
        mesh.y_labels(0).disable_y_mesh();
    }
    mesh.draw().map_err(err)?;
    if !p.cells.is_empty() {
        chart
            .draw_series(
                p.cells
                    .iter()
                    .map(|c| Rectangle::new([(c.x.0, c.y.0), (c.x.1, c.y.1)], c.color.filled())),
            )
            .map_err(err)?;
    }
    if !p.outlines.is_empty() {
        chart
            .draw_series(
                p.outlines.iter().map(|c| {
                    Rectangle::new([(c.x.0, c.y.0), (c.x.1, c.y.1)], c.color.stroke_width(2))
                }),
            )
            .map_err(err)?;
    }
    if !p.marks.is_empty() {
        let style = (FONT, 12)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Center));
        chart
            .draw_series(
                p.marks
                    .iter()
                    .map(|m| Text::new(m.text.clone(), m.at, style.clone())),
            )
            .map_err(err)?;
    }
    let mut labelled = false;
    for s in &p.series {
        let style = ShapeStyle {
            color: s.color.to_rgba(),
            filled: false,
            stroke_width: s.width,
        };
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|q| q.0.is_finite() && q.1.is_finite())
            .collect();
        let anno = match s.stroke {
            Stroke::Solid => chart
                .draw_series(LineSeries::new(pts, style))
                .map_err(err)?,
            Stroke::Dashed => chart
                .draw_series(DashedLineSeries::new(pts, 9, 6, style))
                .map_err(err)?,
            Stroke::Dotted => chart
                .draw_series(DashedLineSeries::new(pts, 2, 4, style))
                .map_err(err)?,
            Stroke::Dots => {
                let c = s.color;
                let r = s.width;
                chart
                    .draw_series(pts.into_iter().map(move |q| Circle::new(q, r, c.filled())))
                    .map_err(err)?
            }
        };
        if !s.label.is_empty() {
            labelled = true;
            let c = s.color;
            match s.stroke {
                Stroke::Dots => {
                    anno.label(s.label.as_str())
                        .legend(move |(x, y)| Circle::new((x + 10, y), 3, c.filled()));
                }
                Stroke::Dashed => {
                    anno.label(s.label.as_str()).legend(move |(x, y)| {
                        EmptyElement::at((x, y))
                            + PathElement::new(vec![(0, 0), (8, 0)], style)
                            + PathElement::new(vec![(13, 0), (21, 0)], style)
                    });
                }
                Stroke::Dotted => {
                    anno.label(s.label.as_str()).legend(move |(x, y)| {
                        EmptyElement::at((x, y))
                            + PathElement::new(vec![(0, 0), (2, 0)], style)
                            + PathElement::new(vec![(6, 0), (8, 0)], style)
                            + PathElement::new(vec![(12, 0), (14, 0)], style)
                            + PathElement::new(vec![(18, 0), (20, 0)], style)
                    });
                }
                Stroke::Solid => {
                    anno.label(s.label.as_str())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 21, y)], style));
                }
            }
        }
    }
    let pos = match p.legend {
        Legend::UpperRight => Some(SeriesLabelPosition::UpperRight),
        Legend::UpperLeft => Some(SeriesLabelPosition::UpperLeft),
        Legend::LowerRight => Some(SeriesLabelPosition::LowerRight),
        Legend::LowerLeft => Some(SeriesLabelPosition::LowerLeft),
        Legend::None | Legend::Outside => None,
    };
    if let (true, Some(pos)) = (labelled, pos) {
        chart
            .configure_series_labels()
            .position(pos)
            .background_style(WHITE.mix(0.88))
            .border_style(RGBColor(150, 150, 150))
            .label_font((FONT, 14))
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Members of a family share a colour and differ in stroke; families
    /// differ in colour; a fifth member moves to the next colour.
    #[test]
    fn family_styles_tell_families_by_colour_and_members_by_stroke() {
        let names = [
            "rapier2d[leapfrog]",
            "box2d",
            "rapier2d[body]",
            "jolt_box",
            "jolt_feet",
            "rapier2d[a]",
            "rapier2d[b]",
            "rapier2d[c]",
        ];
        let s = family_styles(&names);
        assert_eq!(s[0].0, s[2].0);
        assert_ne!(s[0].1, s[2].1);
        assert_eq!(s[3].0, s[4].0);
        assert_ne!(s[3].1, s[4].1);
        assert_ne!(s[0].0, s[1].0);
        assert_ne!(s[1].0, s[3].0);
        // Every (colour, stroke) pair is distinct.
        for i in 0..s.len() {
            for j in 0..i {
                assert!(s[i] != s[j], "{} and {} look the same", names[i], names[j]);
            }
        }
    }

    /// More families than the palette has colours (the cost chart's
    /// engines, results/engine_work_precision.csv, in its order): the
    /// palette wraps, yet no two series share colour and stroke (drake_lagged
    /// drew as rapier2d did), and none is the target line's grey dashes.
    #[test]
    fn family_styles_never_repeat_a_pair_when_the_palette_wraps() {
        let names = [
            "rapier2d",
            "rapier2d[body]",
            "rapier2d_impulse_box",
            "rapier2d_impulse_box[body]",
            "rapier2d_impulse_disk",
            "rapier2d_impulse_disk[body]",
            "rapier2d_regularised_linear",
            "rapier2d_regularised_linear[body]",
            "rapier2d_regularised_tanh",
            "rapier2d_regularised_tanh[body]",
            "rapier3d",
            "rapier3d_simplified",
            "box2d",
            "box2d_motor_joint",
            "avian2d",
            "avian3d",
            "mujoco_elliptic",
            "mujoco_pyramidal",
            "physx_patch",
            "physx_one_directional",
            "physx_two_directional",
            "jolt_box",
            "jolt_feet",
            "drake_lagged",
            "drake_sap",
            "drake_similar",
            "drake_tamsi",
            "pure_python",
            "pybullet_forces",
            "mujoco4_elliptic",
        ];
        let s = family_styles(&names);
        for i in 0..s.len() {
            assert!(s[i] != (GREY, Stroke::Dashed), "{}", names[i]);
            for j in 0..i {
                assert!(s[i] != s[j], "{} and {} look the same", names[i], names[j]);
            }
        }
    }
}
