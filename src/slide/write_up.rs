//! The slide study's figure and README: every number and every sentence
//! computed from the study's rows.

use crate::plot::{self, Axis, Figure, Legend, Panel, Series, Stroke};

use super::disc::Status;
use super::measure::{EngineRow, Row, Study, SCENE};

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

/// How a plate comes to rest under the law `name` (a catalogue name), as
/// its form says: what decelerates it while it slides and what ends the
/// slide. Empty for a law this study has no sentence for.
pub fn law_stop(name: &str) -> &'static str {
    match name {
        "coulomb" => "Coulomb friction does not depend on the speed: the plate decelerates at a rate bounded below (μg for a translation) and stops in finite time, translation and spin at the same instant (Goyal, Ruina & Papadopoulos 1991); an engine that integrates it with capped or implicit impulses ends the slide within a step, one that regularises it near zero slip creeps there instead.",
        "impulse_disk" => "A friction joint per support: while it slides each joint's impulse is at its cap μNΔt along −K⁻¹u, bent from −u towards the direction of the larger effective mass (on the square thrown along an edge only 0.857 of μg acts against the motion, so it slides 17 % farther than Coulomb's v²/(2μg); along a diagonal it is Coulomb's); once the caps can hold the plate the joints, solved together, stop it within a step: no creep.",
        "impulse_box" => "The stopping impulse capped per world axis: a translation along an axis decelerates at μg, one along a diagonal at √2 μg (both rows at their caps), so the law depends on the direction of the throw and on the plate's angle; once the rows' caps can hold the plate they stop it within a step: no creep.",
        "impulse_rows_disk" => "Bullet's two rows per contact scaled onto the disc: Coulomb's magnitude while sliding, its direction bent towards the row with the larger effective mass (exactly Coulomb's where every support has r_x² = r_y²); the solver's rows stop the plate within a step once the disc can hold it.",
        "regularised_linear" => "Coulomb above the slip speed v_s, viscous below it: the last v_s of slip decays exponentially (rate μg/v_s) instead of stopping, which adds about v_s²/(2μg) to the distance and the time to decay from v_s to the rest rule's 1e-5 m/s (a few ln(v_s/1e-5) v_s/(μg)) to the stop.",
        "regularised_tanh" => "Coulomb smoothed everywhere by tanh(|u|/v_s): Coulomb's for slips well above v_s, viscous below, so the slide ends in an exponential creep (rate μg/v_s) that adds π²v_s²/(12μg) to the distance and ln-many time constants to the stop.",
        "rapier3d_contact_disk" => "Each foot's friction along −K⁻¹u capped at μN, as the friction joint's, with the feet's loads from the tilting balance (springs ∝ effective mass): the direction bends as the joint's does and the loads shift with the deceleration, so it stops where a Coulomb plate with those loads would, within a step once the caps hold.",
        "rapier3d_simplified_twist" => "One friction disc μΣN at the feet's mean and a separate twist limit μΣN|p−c|: translation and spin are capped each on its own, as a motor joint caps them, so they need not stop at the same instant, and the rest differs from Coulomb's wherever the throw spins.",
        "mujoco_elliptic" => "A soft elliptic cone: Coulomb's bound μN against the slip while the feet slide; near the stop the friction is a soft constraint whose slip decays with its time constant τ (about 10 ms at the default solref), a tail that adds up to μgτ² to the distance and τ ln(μgτ/1e-5 m/s) to the time to rest.",
        "physx_patch" => "Box-clamped rows (t0 and t1 each clamped on its own, not as a disc) at two anchors of the welded patch, each capped at half μΣN: against a slip along a diagonal of the rows the box allows up to √2 times Coulomb's friction, along a row Coulomb's; whether the rows, re-anchored on the patch's contacts every step, hold the plate still at the end is the engine's solver's, not the law's (the numbers below say).",
        "physx_two_directional" => "At every foot one row along the centre of mass's velocity and one across it, each clamped at μN: along the motion Coulomb's magnitude, across it a second cap (a box in the velocity's frame), so a spinning throw meets more friction than Coulomb's; the rows stop the plate within a step once they hold.",
        "physx_one_directional" => "One clamped row per foot, along and across the centre of mass's velocity by turns on a welded patch: the friction acts along one direction a step, so a sliding, spinning plate is decelerated in alternation and comes to rest elsewhere than Coulomb's.",
        "box2d_motor_joint" => "A motor joint to the ground holding the velocity at zero with its force capped at ΣμN and its torque at ΣμN|p_i|, each on its own: the translation stops after v/(μg) at v²/(2μg), the spin after Iω/T_max, each within a step (a velocity constraint, no creep), but not at the same instant as Coulomb's do, and the path is straight.",
        "avian3d_tilt" => "Coulomb along −u at every foot with its soft contacts' loads, moved by the couple of the raised centre of mass: Coulomb's stop with loads shifted forward while it decelerates, ended by the solver's velocity constraints.",
        "jolt_box" => "One friction disc μΣN at the corners' mean with world-axis rows and a twist row clamped at μΣdᵢNᵢ: translation and spin capped each on its own (as the motor joint's), so they need not stop together.",
        "jolt_feet" => "A disc μN per foot along the effective-mass direction of world-axis rows (yaw-dependent, no twist row): the friction joint's bend, in the world axes, stopped within a step once the discs hold.",
        "drake_sap" | "drake_similar" => "Coulomb at every foot with the loads of a convex relaxation that lifts a sliding foot; regularised near zero slip (Drake's stiction tolerance), so the slide ends in a short creep, and the hops of the lift move the loads.",
        _ => "",
    }
}

/// What one engine's numbers say about its stop, from its declared law.
fn engine_paragraph(study: &Study, e: &EngineRow) -> String {
    let (law_name, law_about) = e
        .law
        .clone()
        .unwrap_or_else(|| ("none".into(), "it declares no law in closed form.".into()));
    let (a, b) = engine_gaps(study, &e.name, e.dt);
    let stop = law_stop(&law_name);
    let mut s = format!(
        "**{}** declares `{law_name}`: {law_about}{}{stop}\nOver {} throws at dt = {} s its rest lies a median {} m (at most {} m) and at most {} rad from the model's, and it stops at most {} s from the model's stop time, on average {} s {}.",
        e.name,
        if stop.is_empty() { "" } else { " How it stops: " },
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
        let ends: Vec<&Row> = study
            .rows
            .iter()
            .filter(|r| r.engine == e.name && r.dt == e.dt && r.engine_end.is_some())
            .collect();
        let speeds: Vec<f64> = ends
            .iter()
            .filter_map(|r| r.engine_end.map(|x| x.1))
            .collect();
        let far = ends.iter().map(|r| r.d_end()).fold(0.0, f64::max);
        s.push_str(&format!(
            " On {} of the throws it did not stop within the release's max_duration ({} s) by the rest rule",
            a.unstopped,
            ends.first().and_then(|r| r.engine_end).map_or("-".into(), |x| format!("{}", x.0.t)),
        ));
        if !speeds.is_empty() {
            s.push_str(&format!(
                ": at the end it still moved at a median {} m/s (at most {} m/s), {} m at most from the model's rest",
                sci(median(speeds.clone())),
                sci(speeds.iter().cloned().fold(0.0, f64::max)),
                sci(far),
            ));
        }
        s.push_str(". It is reported, not tuned away.");
    }
    if a.n == 0 || b.n == 0 {
        s.push_str(" With no rest at one of its two steps, how its gap moves with the step is not measured.");
        return s;
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

/// The disc's section: the ratio v/(Rω) near the stop, per engine.
fn disc_section(study: &Study) -> String {
    let d = &study.disc;
    let mut s = format!(
        "## The thrown disc: v/(Rω) at the stop\n\nA uniform disc sliding and spinning stops translating and turning together, and its ratio v/(Rω) tends to 0.653 at the stop whatever the throw (Farkas, Bartels, Unger & Wolf 2003). Each engine runs the shipped `{}` scenario (R = {} m, {} supports on its 20 mm grid, thrown at 0.3 m/s and 3 rad/s) at its step h, a row every step; `disc.csv` has the ratio at 40, 20 and 10 steps before its stop (v from the last step's displacement) and their Aitken extrapolation, beside the dynamic model's at the same times before the model's stop ({} s). On this grid the model's own limit is {:.4} (its jagged rim moves it off the continuous disc's 0.653; the model's test holds finer grids to 0.653).\n\n| engine | h (s) | stop (s) | ratio 40h, 20h, 10h before | extrapolated | model at the same times | model extrapolated |\n|---|---|---|---|---|---|---|\n",
        super::disc::DISC_SCENE.trim_end_matches(".toml"),
        d.radius,
        d.supports,
        format_args!("{:.4}", d.model_t_stop),
        d.model_limit,
    );
    let f3 = |v: &[f64; 3]| {
        v.iter()
            .map(|x| {
                if x.is_finite() {
                    format!("{x:.3}")
                } else {
                    "-".into()
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let f = |x: f64| {
        if x.is_finite() {
            format!("{x:.3}")
        } else {
            "-".into()
        }
    };
    for r in &d.rows {
        let stop = match (&r.status, r.t_stop) {
            (Status::Released, Some(t)) => format!("{t:.4}"),
            (Status::Released, None) => "not stopped".into(),
            (Status::Refused(_), _) => "refused".into(),
            (Status::Failed(_), _) => "failed".into(),
        };
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} |\n",
            r.engine,
            r.dt,
            stop,
            f3(&r.ratios),
            f(r.extrapolated()),
            f3(&r.model_ratios),
            f(r.model_extrapolated()),
        ));
    }
    let read: Vec<&super::disc::DiscRow> = d
        .rows
        .iter()
        .filter(|r| r.ratios.iter().all(|x| x.is_finite()))
        .collect();
    if !read.is_empty() {
        let gaps: Vec<f64> = read
            .iter()
            .map(|r| (r.ratios[2] - r.model_ratios[2]).abs())
            .collect();
        let close = read
            .iter()
            .zip(&gaps)
            .filter(|(_, g)| **g <= 0.05)
            .map(|(r, _)| r.engine.as_str())
            .collect::<Vec<_>>();
        let apart = read
            .iter()
            .zip(&gaps)
            .filter(|(_, g)| **g > 0.05)
            .map(|(r, g)| format!("{} ({:.3})", r.engine, g))
            .collect::<Vec<_>>();
        s.push_str(&format!(
            "\nTen steps before the stop, {} of the {} engines whose ratio could be read follow the model's ratio within 0.05{}{}.",
            close.len(),
            read.len(),
            if close.is_empty() { String::new() } else { format!(" ({})", close.join(", ")) },
            if apart.is_empty() {
                String::new()
            } else {
                format!("; the others differ from it by {} (the engines' paragraphs above say how each law stops)", apart.join(", "))
            },
        ));
    }
    let unread: Vec<String> = d
        .rows
        .iter()
        .filter(|r| !r.ratios.iter().all(|x| x.is_finite()))
        .map(|r| match &r.status {
            Status::Refused(why) | Status::Failed(why) => format!("{} ({why})", r.engine),
            Status::Released if r.t_stop.is_none() => format!("{} (did not stop)", r.engine),
            Status::Released => format!(
                "{} (stopped within 40 steps of the throw, or its rows missed the read times)",
                r.engine
            ),
        })
        .collect();
    if !unread.is_empty() {
        s.push_str(&format!(" Not read: {}.", unread.join("; ")));
    }
    s.push_str("\n\n");
    s
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
    s.push_str(&disc_section(study));
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
