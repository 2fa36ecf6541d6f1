//! The slide study's figure and README: every number and every sentence
//! computed from the study's rows.

use crate::plot::{self, Axis, Figure, Legend, Panel, Series, Stroke};

use super::measure::{EngineRow, Row, Status, Study, SCENE};

/// Values below this are drawn at it on the figure's log axes.
const FLOOR: f64 = 1e-12;

/// The ratio of the largest rest-position gap at h to the one at h/2 above
/// which the gap is called the step's: 2^0.6 (order 0.6; a first-order
/// gap halves, ratio 2, and a gap that does not depend on the step stays
/// near 1).
const SHRINKS: f64 = 1.515_716_566_510_398;

/// The figures of one engine at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gaps {
    /// Throws measured (both rests present).
    pub n: usize,
    /// Throws where the engine did not stop (or the model did not).
    pub unstopped: usize,
    pub position_median: f64,
    pub position_max: f64,
    pub theta_max: f64,
    pub t_stop_max: f64,
    /// Mean signed stop-time difference (s): > 0 the engine stops later.
    pub t_stop_mean: f64,
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// [`Gaps`] over `rows`.
pub fn gaps<'a>(rows: impl Iterator<Item = &'a Row>) -> Gaps {
    let rows: Vec<&Row> = rows.collect();
    let ok: Vec<&&Row> = rows.iter().filter(|r| r.d_position().is_finite()).collect();
    let max = |f: &dyn Fn(&Row) -> f64| ok.iter().map(|r| f(r).abs()).fold(0.0, f64::max);
    Gaps {
        n: ok.len(),
        unstopped: rows.len() - ok.len(),
        position_median: median(ok.iter().map(|r| r.d_position()).collect()),
        position_max: max(&|r| r.d_position()),
        theta_max: max(&|r| r.d_theta()),
        t_stop_max: max(&|r| r.d_t_stop()),
        t_stop_mean: ok.iter().map(|r| r.d_t_stop()).sum::<f64>() / ok.len().max(1) as f64,
    }
}

/// An engine's gaps at its step h and at h/2.
pub fn engine_gaps(study: &Study, name: &str, h: f64) -> (Gaps, Gaps) {
    let at = |dt: f64| gaps(study.rows.iter().filter(|r| r.engine == name && r.dt == dt));
    (at(h), at(h / 2.0))
}

/// The released engines' rests against the model's, at each engine's
/// step: where each comes to rest beside the model, the rest-position gap against the model's slide distance, angle gap
/// against the model's turn, stop-time gap against the model's stop time.
pub fn figure(study: &Study) -> Figure {
    let released: Vec<&EngineRow> = study
        .engines
        .iter()
        .filter(|e| e.status == Status::Released)
        .collect();
    let mut panels = vec![
        Panel::new(
            "rest position: engine against model",
            Axis::lin("model's slide distance (m)"),
            Axis::log("distance between the rest positions (m)"),
        ),
        Panel::new(
            "rest angle: engine against model",
            Axis::lin("model's turn to rest (rad)"),
            Axis::log("|engine's rest angle - model's| (rad)"),
        ),
        Panel::new(
            "stop time: engine against model",
            Axis::lin("model's stop time (s)"),
            Axis::log("|engine's stop time - model's| (s)"),
        ),
    ];
    // Where each comes to rest, beside the model, at the slide's own scale.
    let mut map = Panel::new(
        "rest positions (throws from the origin)",
        Axis::lin("x (m)"),
        Axis::lin("y (m)"),
    )
    .equal_aspect();
    let first = |r: &&Row| {
        released
            .first()
            .is_some_and(|e| r.engine == e.name && r.dt == e.dt)
    };
    map.series.push(
        Series::new("dynamic model", plot::DARK, Stroke::Dots)
            .width(5)
            .points(
                study
                    .rows
                    .iter()
                    .filter(first)
                    .filter_map(|r| r.model.map(|m| (m.x, m.y)))
                    .collect(),
            ),
    );
    for (k, e) in released.iter().enumerate() {
        map.series.push(
            Series::new(
                e.name.clone(),
                plot::PALETTE[k % plot::PALETTE.len()],
                Stroke::Dots,
            )
            .points(
                study
                    .rows
                    .iter()
                    .filter(|r| r.engine == e.name && r.dt == e.dt)
                    .filter_map(|r| r.engine_rest.map(|m| (m.x, m.y)))
                    .collect(),
            ),
        );
    }
    for (k, e) in released.iter().enumerate() {
        let color = plot::PALETTE[k % plot::PALETTE.len()];
        let rows: Vec<&Row> = study
            .rows
            .iter()
            .filter(|r| r.engine == e.name && r.dt == e.dt && r.d_position().is_finite())
            .collect();
        let pts = |f: &dyn Fn(&Row) -> (f64, f64)| -> Vec<(f64, f64)> {
            rows.iter()
                .map(|r| {
                    let (x, y) = f(r);
                    (x, y.abs().max(FLOOR))
                })
                .collect()
        };
        let label = format!("{} (dt {} s)", e.name, e.dt);
        let model = |r: &Row| r.model.expect("finite gap: the model stopped");
        let series = [
            pts(&|r| (model(r).x.hypot(model(r).y), r.d_position())),
            pts(&|r| (model(r).theta.abs(), r.d_theta())),
            pts(&|r| (model(r).t, r.d_t_stop())),
        ];
        for (p, s) in panels.iter_mut().zip(series) {
            p.series
                .push(Series::new(label.clone(), color, Stroke::Dots).points(s));
        }
    }
    panels.insert(0, map);
    for p in &mut panels {
        p.legend = Legend::Outside;
    }
    Figure {
        size: (1300, 1000),
        cols: 2,
        panels,
        key: None,
    }
}

fn sci(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2e}")
    } else {
        "-".into()
    }
}

/// What one engine's numbers say about its stop, from its declared law.
fn engine_paragraph(study: &Study, e: &EngineRow) -> String {
    let (law_name, law_about) = e
        .law
        .clone()
        .unwrap_or_else(|| ("none".into(), "it declares no law in closed form.".into()));
    let (a, b) = engine_gaps(study, &e.name, e.dt);
    let mut s = format!(
        "**{}** declares `{law_name}`: {law_about}\nOver {} throws at dt = {} s its rest lies a median {} m (at most {} m) and at most {} rad from the model's, and it stops at most {} s from the model's stop time, on average {} s {}.",
        e.name,
        a.n,
        e.dt,
        sci(a.position_median),
        sci(a.position_max),
        sci(a.theta_max),
        sci(a.t_stop_max),
        sci(a.t_stop_mean.abs()),
        if a.t_stop_mean >= 0.0 { "later" } else { "earlier" },
    );
    if a.unstopped > 0 {
        s.push_str(&format!(
            " On {} throws it did not stop within the release's max_duration, or the model did not.",
            a.unstopped
        ));
    }
    let ratio = a.position_max / b.position_max;
    let order = ratio.log2();
    s.push_str(&format!(
        " At dt = {} s the largest rest-position gap is {} m, {} times smaller (order {:.2})",
        e.dt / 2.0,
        sci(b.position_max),
        format_args!("{ratio:.2}"),
        order
    ));
    let coulomb = law_name == "coulomb";
    let shrinks = ratio >= SHRINKS;
    s.push_str(&match (coulomb, shrinks) {
        (true, true) => format!(
            ": the gap is its time step's, as a law that is the model's own predicts; the stop time is read at the end of a step, and its largest gap {} s is {} the step.",
            sci(a.t_stop_max),
            if a.t_stop_max <= e.dt { "within" } else { "more than" }
        ),
        (true, false) => ": the gap does not shrink with the step although the engine declares the model's own law. This is a disagreement between the engine and its declaration, reported here and not tuned away.".to_string(),
        (false, true) => ": the gap shrinks with the step, so at these throws its law acts on the slide as Coulomb's does; its gap is its step's.".to_string(),
        (false, false) => ": the gap does not shrink with the step, so it is the engine's friction law's, not its step's: the law above is not Coulomb's at the problem's loads, and the plate stops elsewhere.".to_string(),
    });
    if shrinks && e.declared_order > order + 0.5 {
        s.push_str(&format!(
            " It declares order {} for a problem with a release, but its slide converges at order {order:.2}: a gate on a thrown plate would refuse its auto tolerances until its declaration says {}.",
            e.declared_order,
            order.round().max(1.0)
        ));
    }
    s
}

/// The largest distance (m) and angle (rad) between the rests of engines
/// `a` and `b` at step `h` over the throws both measured.
fn between(study: &Study, a: &str, b: &str, h: f64) -> (f64, f64) {
    let rows = |n: &str| -> Vec<&Row> {
        study
            .rows
            .iter()
            .filter(|r| r.engine == n && r.dt == h)
            .collect()
    };
    let (ra, rb) = (rows(a), rows(b));
    let mut out = (0.0f64, 0.0f64);
    for x in &ra {
        let Some(y) = rb.iter().find(|y| y.throw == x.throw) else {
            continue;
        };
        if let (Some(p), Some(q)) = (x.engine_rest, y.engine_rest) {
            out.0 = out.0.max((p.x - q.x).hypot(p.y - q.y));
            out.1 = out.1.max((p.theta - q.theta).abs());
        }
    }
    out
}

/// The sentence on the engines that declare Coulomb's law, against one
/// another and against the model (None with fewer than two at one step).
fn coulomb_paragraph(study: &Study) -> Option<String> {
    let coulomb: Vec<&EngineRow> = study
        .engines
        .iter()
        .filter(|e| e.status == Status::Released)
        .filter(|e| e.law.as_ref().is_some_and(|l| l.0 == "coulomb"))
        .collect();
    let first = coulomb.first()?;
    let same: Vec<&&EngineRow> = coulomb.iter().filter(|e| e.dt == first.dt).collect();
    if same.len() < 2 {
        return None;
    }
    let mut d = (0.0f64, 0.0f64);
    for (i, a) in same.iter().enumerate() {
        for b in &same[i + 1..] {
            let x = between(study, &a.name, &b.name, first.dt);
            d = (d.0.max(x.0), d.1.max(x.1));
        }
    }
    let to_model = same
        .iter()
        .map(|e| engine_gaps(study, &e.name, e.dt).0.position_max)
        .fold(0.0, f64::max);
    let names: Vec<&str> = same.iter().map(|e| e.name.as_str()).collect();
    Some(format!(
        "The {} engines that declare `coulomb` ({}) come to rest within {} m and {} rad of one another on every throw at dt = {} s, {} than any of them comes to the model ({} m at most){}.",
        same.len(),
        names.join(", "),
        sci(d.0),
        sci(d.1),
        first.dt,
        if d.0 < to_model { "closer" } else { "no closer" },
        sci(to_model),
        if d.0 < 1e-2 * to_model {
            "; in rest.svg their dots lie on one another"
        } else {
            ""
        }
    ))
}

/// The generated README.md.
pub fn readme(study: &Study) -> String {
    let g = &study.grid;
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{}", (x * 1e4).round() / 1e4))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut s = String::from("# The slide to rest in every engine\n\n");
    s.push_str(&format!(
        "Written by `pushval slide-study{}`. The seed's plate (scenario `{}`: 0.25 m square, 1 kg, mu 0.5 on its four corners) is thrown from the origin at angle 0 with speeds {} m/s, spins {} rad/s and directions {} rad ({} throws), with no pusher, and slides to rest. The dynamic model locates each stop as an event; each engine runs at its default step dt and at dt/2, and the rest rule of its session (speed below 1e-5 m/s for 10 steps) gives its stop time. `throws.csv` has one row per engine, step and throw; `engines.csv` one row per engine; `rest.svg` draws each engine's gaps at its step.\n\n",
        if study.quick { " --quick" } else { "" },
        SCENE.trim_end_matches(".toml"),
        list(&g.speeds),
        list(&g.spins),
        list(&g.directions),
        g.throws().len(),
    ));
    let released: Vec<_> = study
        .engines
        .iter()
        .filter(|e| e.status == Status::Released)
        .collect();
    s.push_str("## Engines that let go\n\n");
    for e in &released {
        s.push_str(&engine_paragraph(study, e));
        s.push_str("\n\n");
    }
    if let Some(p) = coulomb_paragraph(study) {
        s.push_str(&p);
        s.push_str("\n\n");
    }
    let refused: Vec<_> = study
        .engines
        .iter()
        .filter_map(|e| match &e.status {
            Status::Refused(why) => Some((e, why)),
            _ => None,
        })
        .collect();
    if !refused.is_empty() {
        s.push_str(&format!(
            "## Engines that cannot let go ({})\n\nNot applicable to a slide: each refuses a problem with a release rather than ending it at the release.\n\n",
            refused.len()
        ));
        for (e, why) in refused {
            s.push_str(&format!("- {}: {why}\n", e.name));
        }
        s.push('\n');
    }
    let failed: Vec<_> = study
        .engines
        .iter()
        .filter_map(|e| match &e.status {
            Status::Failed(why) => Some((e, why)),
            _ => None,
        })
        .collect();
    if !failed.is_empty() {
        s.push_str("## Engines that failed to run\n\n");
        for (e, why) in failed {
            s.push_str(&format!("- {}: {why}\n", e.name));
        }
        s.push('\n');
    }
    s
}
