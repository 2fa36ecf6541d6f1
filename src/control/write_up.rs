//! The control study's README, written from the counts beside it
//! (`study::write_outputs` gathers them into [`Counts`]), and the line each
//! engine's paragraph quotes from its declared law ([`law_line`]).

use std::collections::BTreeMap;

use pushval_control::mpc::PlantScale;
use pushval_engine::{Engine, FrictionLaw};
use pushval_model::{Problem, Push};

use super::figures::Group;
use super::grid::{PERIOD, QUICK_SPEEDS, SCENE, SEGMENTS, SPEEDS};

/// The law's steady ω against Coulomb's for the scene's middle push at
/// `speed`: (law name, law ω, Coulomb ω, class).
pub(crate) fn law_line(problem: &Problem, engine: &dyn Engine, speed: f64) -> Option<String> {
    let law = engine.law()?;
    let mut p = problem.clone();
    p.pushes = vec![Push {
        duration: 2.0,
        speed,
        phi: std::f64::consts::FRAC_PI_4 + 0.3,
    }];
    let dt = engine.default_dt();
    let w_law = law.steady(&p, 0, dt)?;
    let w_c = pushval_engine::COULOMB.steady(&p, 0, dt)?;
    Some(format!(
        "its law ({}) turns at {:.3} rad/s where Coulomb's turns at {:.3} rad/s (φ = π/4 + 0.3, {speed} m/s; ω = 0 {})",
        law.law_name(),
        w_law.omega,
        w_c.omega,
        match w_law.class {
            pushval_engine::LawClass::Turns => "is not held".to_string(),
            other => format!("is {}", other.as_str()),
        }
    ))
}

/// One goal's runs by both rules: engine, speed (bits), predictor, mode,
/// plant, goal.
pub(crate) type PairKey = (String, u64, &'static str, &'static str, &'static str, usize);

/// One (engine, speed, predictor, mode, plant) cell, both rules.
pub(crate) type Move = (String, u64, &'static str, &'static str, &'static str);

/// The old grid's wall time (s of runs, summed over `runs.csv`'s `wall_s`,
/// judged at the release only, 28 engines): at 0.1 m/s and in all
/// (results/closed_loop/runs.csv of commit 32437d4).
const OLD_SLOW_WALL_S: f64 = 5724.0;
const OLD_TOTAL_WALL_S: f64 = 7316.0;

/// What the README is written from.
pub(crate) struct Counts<'a> {
    pub(crate) names: &'a [String],
    pub(crate) speeds: &'a [f64],
    pub(crate) goals: usize,
    pub(crate) summary: &'a BTreeMap<Group, (usize, usize, f64, f64)>,
    /// Per cell: goals reached at rest and not at the release (gained),
    /// and reached at the release and not at rest (lost).
    pub(crate) moves: BTreeMap<Move, (usize, usize)>,
    /// Runs that ended with an engine error, per engine.
    pub(crate) failed_runs: BTreeMap<String, usize>,
    /// Rest runs judged at the release (the engine cannot release), per
    /// engine.
    pub(crate) at_release: BTreeMap<String, usize>,
    pub(crate) quick: bool,
}

/// A count moved from the release rule to the rest rule: `(=)`, `(+2)`,
/// `(−3)` or `(+1 −2)` (goals gained and lost).
fn moved(gained: usize, lost: usize) -> String {
    match (gained, lost) {
        (0, 0) => "(=)".into(),
        (g, 0) => format!("(+{g})"),
        (0, l) => format!("(−{l})"),
        (g, l) => format!("(+{g} −{l})"),
    }
}

/// `a, b and c`.
fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

pub(crate) fn readme(problem: &Problem, c: &Counts) -> String {
    let (names, speeds, goals) = (c.names, c.speeds, c.goals);
    let vmax = speeds.iter().copied().fold(f64::MIN, f64::max);
    let get =
        |n: &str, v: f64, at: &'static str, pr: &'static str, m: &'static str, pl: &'static str| {
            c.summary
                .get(&(n.to_string(), v.to_bits(), at, pr, m, pl))
                .copied()
                .unwrap_or((0, 0, f64::NAN, f64::NAN))
        };
    let mv = |n: &str, v: f64, pr: &'static str, m: &'static str, pl: &'static str| {
        c.moves
            .get(&(n.to_string(), v.to_bits(), pr, m, pl))
            .copied()
            .unwrap_or((0, 0))
    };
    let released = |n: &str| c.at_release.get(n).copied().unwrap_or(0) == 0;
    let errors = |n: &str| c.failed_runs.get(n).copied().unwrap_or(0);
    let coulomb = |e: &dyn Engine| {
        e.law()
            .is_some_and(|l| l.law_name() == pushval_engine::COULOMB.law_name())
    };
    let engine = |n: &str| crate::registry::entry(n).expect("listed").default_engine();
    let mut s = String::new();
    s.push_str("# Closed loop: plans and MPC made on the model, in every engine\n\n");
    s.push_str("Written by `pushval control-study");
    if c.quick {
        s.push_str(" --quick");
    }
    s.push_str("` (docs/closed-loop.md); do not edit.\n\n");
    let goal_speeds: &[f64] = if c.quick { &QUICK_SPEEDS } else { &SPEEDS };
    let list_speeds =
        |v: &[f64]| and_list(&v.iter().map(|v| format!("{v} m/s")).collect::<Vec<_>>());
    s.push_str(&format!(
        "The seed paper's plate (`{SCENE}`, from rest), {goals} goals 0.3–1 m away with turns up to ±90° (`goals.csv`), each reachable at rest by the dynamic model at {}. The grid runs {}, every run by two rules (column `at`): judged at the release, when the last push ends and the plate still moves (the plan aims at that pose, as `--at release`), and judged at rest, after the pusher lets go and the plate slides to a stop (the plan aims at that pose; the default of `plan` and `loop`). A plan is {SEGMENTS} pushes of equal duration; success is the centre of mass within 20 mm of the goal and the angle within 5°. MPC re-plans every {PERIOD} s from the engine's state until the last push ends; at rest its plant then slides with no feedback. The perturbed plant has μ × 0.8 and I_cm × 1.2; the predictor keeps the nominal values. An engine that cannot release the plate is judged at the release in its rest runs too (column `judged_at` of `runs.csv` and `success.csv`).\n\n",
        list_speeds(goal_speeds),
        list_speeds(speeds),
    ));
    // The slide of a plate released in pure translation at v under the
    // scene's supports: deceleration Σ μᵢNᵢ / m, distance v² m / (2 Σ μᵢNᵢ).
    let decel = problem.body.total_friction() / problem.body.mass();
    let slow = 0.1;
    let slide = slow * slow / (2.0 * decel);
    if !speeds.contains(&slow) {
        s.push_str(&format!(
            "{slow} m/s is not in the grid. A plate released at {slow} m/s slides about v²/(2μg) = {:.1} mm (μg = Σ μᵢNᵢ / m = {decel:.2} m/s² on this scene), {:.0} times less than the 20 mm tolerance, so the two rules judge alike there; and that speed took {OLD_SLOW_WALL_S:.0} of the {OLD_TOTAL_WALL_S:.0} s of runs ({:.0} %) of the grid that had it (28 engines judged at the release; `runs.csv` column `wall_s` of commit 32437d4).\n\n",
            slide * 1e3,
            0.02 / slide,
            100.0 * OLD_SLOW_WALL_S / OLD_TOTAL_WALL_S,
        ));
    }
    s.push_str("Files: `success.csv` (one row per engine, speed, rule, plan predictor, mode and plant), `runs.csv` (every run), `success.svg` (a panel per speed and rule), `paths.svg` (goal 0 at rest in every engine).\n\n");

    // Per engine, at rest, with the move from the release rule.
    use super::figures::COLUMNS;
    s.push_str("## Per engine, at rest\n\n");
    s.push_str("Goals reached at rest, and in brackets how that moved against the release rule: goals gained at rest (+) and lost (−), `(=)` none. dyn/kin: the plan made on the dynamic / kinematic model; open loop or MPC; nom/pert: the nominal or the perturbed plant.\n\n");
    let mut cannot: Vec<String> = Vec::new();
    for &v in speeds {
        s.push_str(&format!("### {v} m/s\n\n| engine |"));
        for col in COLUMNS.iter() {
            s.push_str(&format!(" {} |", super::figures::short(col)));
        }
        s.push_str("\n|---|");
        s.push_str(&"---|".repeat(COLUMNS.len()));
        s.push('\n');
        for n in names {
            let mark = if released(n) { "" } else { " †" };
            s.push_str(&format!("| {n}{mark} |"));
            for &(pr, m, pl) in COLUMNS.iter() {
                let (ok, tot, _, _) = get(n, v, "rest", pr, m, pl);
                let (g, l) = mv(n, v, pr, m, pl);
                s.push_str(&format!(" {ok}/{tot} {} |", moved(g, l)));
            }
            s.push('\n');
        }
        s.push('\n');
    }
    for n in names {
        if !released(n) {
            cannot.push(n.clone());
        }
    }
    if !cannot.is_empty() {
        s.push_str(&format!(
            "† cannot release the plate ({}): its rest runs are judged at the release, so its counts cannot move.\n\n",
            and_list(&cannot)
        ));
    }

    // Across engines.
    s.push_str("## At rest against the release rule, across engines\n\n");
    let able: Vec<&String> = names
        .iter()
        .filter(|n| released(n) && errors(n) * 2 < 2 * 8 * goals * speeds.len())
        .collect();
    s.push_str(&format!(
        "{} of {} engines release the plate{}.",
        able.len(),
        names.len(),
        if cannot.is_empty() {
            String::new()
        } else {
            format!(
                "; {} cannot and {} judged at the release by both rules",
                and_list(&cannot),
                if cannot.len() == 1 { "is" } else { "are" }
            )
        }
    ));
    let (mut gained, mut lost, mut pairs) = (0, 0, 0);
    for n in &able {
        for &v in speeds {
            for &(pr, m, pl) in COLUMNS.iter() {
                let (g, l) = mv(n, v, pr, m, pl);
                gained += g;
                lost += l;
                pairs += get(n, v, "rest", pr, m, pl).1;
            }
        }
    }
    if !able.is_empty() {
        s.push_str(&format!(
            " Over their {pairs} goals run by both rules (every speed, predictor, mode and plant), {gained} are reached at rest and not at the release, and {lost} at the release and not at rest."
        ));
    }
    s.push_str("\n\n");
    for &v in speeds {
        for (m, what) in [("open", "open loop"), ("mpc", "under MPC")] {
            let (mut more, mut fewer, mut same) = (Vec::new(), Vec::new(), 0);
            for n in &able {
                let (rel, tot, _, _) = get(n, v, "release", "dynamic", m, "nominal");
                let (rest, _, _, _) = get(n, v, "rest", "dynamic", m, "nominal");
                let cell = format!("{n} {rel}/{tot} → {rest}/{tot}");
                match rest.cmp(&rel) {
                    std::cmp::Ordering::Greater => more.push(cell),
                    std::cmp::Ordering::Less => fewer.push(cell),
                    std::cmp::Ordering::Equal => same += 1,
                }
            }
            if able.is_empty() {
                continue;
            }
            s.push_str(&format!(
                "- {v} m/s, the dynamic plan {what} on the nominal plant: as many goals at rest as at the release in {same} of {} engines",
                able.len()
            ));
            if !fewer.is_empty() {
                s.push_str(&format!(
                    "; fewer in {} ({})",
                    fewer.len(),
                    fewer.join(", ")
                ));
            }
            if !more.is_empty() {
                s.push_str(&format!("; more in {} ({})", more.len(), more.join(", ")));
            }
            s.push_str(".\n");
        }
    }
    s.push('\n');
    // The perturbed plant's slide: μ × 0.8 makes it 1/0.8 times as long as
    // the predictor's, which no feedback corrects once the pusher has let go.
    let mu_scale = PlantScale::PERTURBED.mu_scale;
    let extra = |v: f64| v * v / (2.0 * decel) * (1.0 / mu_scale - 1.0);
    let mut pert = Vec::new();
    for n in &able {
        let (rel, tot, _, _) = get(n, vmax, "release", "dynamic", "mpc", "perturbed");
        let (rest, _, _, _) = get(n, vmax, "rest", "dynamic", "mpc", "perturbed");
        if rel >= rest + 2 {
            pert.push(format!("{n} {rel}/{tot} → {rest}/{tot}"));
        }
    }
    if !pert.is_empty() {
        s.push_str(&format!(
            "On the perturbed plant (μ × {mu_scale}) a plate released at the pusher's speed slides 1/{mu_scale} times as far as the predictor expects: about {:.1} mm further at {vmax} m/s{}, and no feedback acts once the pusher has let go. MPC on the perturbed plant loses two or more goals at rest against the release rule at {vmax} m/s in {} of {} engines that release ({}).\n\n",
            extra(vmax) * 1e3,
            speeds
                .iter()
                .filter(|&&v| v < vmax)
                .map(|&v| format!(" ({:.1} mm at {v} m/s)", extra(v) * 1e3))
                .collect::<String>(),
            pert.len(),
            able.len(),
            pert.join(", ")
        ));
    }
    // Where the goals lost at rest (dynamic plan, open loop, nominal plant,
    // at least two at some speed) come from, from what each engine declares.
    let (mut slide, mut integ, mut push, mut nolaw) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for n in &able {
        let e = engine(n);
        let mut worst: Option<(f64, usize, usize, usize)> = None;
        for &v in speeds {
            let (rel, tot, _, _) = get(n, v, "release", "dynamic", "open", "nominal");
            let (rest, _, _, _) = get(n, v, "rest", "dynamic", "open", "nominal");
            if rel >= rest + 2 && worst.is_none_or(|w| rel - rest > w.1 - w.2) {
                worst = Some((v, rel, rest, tot));
            }
        }
        let Some((v, rel, rest, tot)) = worst else {
            continue;
        };
        let cell = format!("{n} ({rel}/{tot} at the release, {rest}/{tot} at rest at {v} m/s)");
        if coulomb(e.as_ref()) {
            integ.push(cell);
        } else if e.law().is_none() {
            nolaw.push(cell);
        } else if rel as f64 >= 0.95 * tot as f64 {
            slide.push(format!(
                "{n} ({}; {rel}/{tot} at the release, {rest}/{tot} at rest at {v} m/s)",
                e.law().map(|l| l.law_name()).unwrap_or_default()
            ));
        } else {
            push.push(cell);
        }
    }
    if slide.is_empty() && integ.is_empty() && push.is_empty() && nolaw.is_empty() {
        s.push_str("No engine that releases loses two or more goals at rest with the dynamic plan open loop on the nominal plant.\n\n");
    } else {
        s.push_str("Engines that lose two or more goals at rest with the dynamic plan open loop on the nominal plant (at their worst speed):\n\n");
        if !slide.is_empty() {
            s.push_str(&format!(
                "- the push moves the plate as the model predicts (at least 95 % of the goals at the release), so the goals are lost in the slide, and the engine declares a law other than Coulomb's, whose slide the plans aim through: {}.\n",
                slide.join("; ")
            ));
        }
        if !integ.is_empty() {
            s.push_str(&format!(
                "- the engine declares Coulomb's law, the model's, so the difference is not its law but how it integrates the push or the slide (its step, its solver): {}.\n",
                integ.join("; ")
            ));
        }
        if !push.is_empty() {
            s.push_str(&format!(
                "- the engine declares a law other than Coulomb's and misses at the release too (below 95 %): these counts do not separate its slide from its push: {}.\n",
                push.join("; ")
            ));
        }
        if !nolaw.is_empty() {
            s.push_str(&format!(
                "- the engine declares no law in closed form, so nothing here says why: {}.\n",
                nolaw.join("; ")
            ));
        }
        s.push('\n');
    }

    s.push_str(&format!(
        "## Why each engine succeeds or fails, at rest at {vmax} m/s\n\n"
    ));
    for n in names {
        let e = engine(n);
        let (ok_open, tot, pe_open, ae_open) = get(n, vmax, "rest", "dynamic", "open", "nominal");
        let (ok_mpc, _, _, _) = get(n, vmax, "rest", "dynamic", "mpc", "nominal");
        let (ok_mpc_p, _, _, _) = get(n, vmax, "rest", "dynamic", "mpc", "perturbed");
        let share = |k: usize| if tot == 0 { 0.0 } else { k as f64 / tot as f64 };
        let law = law_line(problem, e.as_ref(), vmax);
        let coulomb = coulomb(e.as_ref());
        let errors_n = errors(n);
        let mm = |v: f64| {
            if v.is_finite() {
                format!("{:.1} mm", v * 1e3)
            } else {
                "no final pose".to_string()
            }
        };
        // Every clause below is chosen by the numbers it states.
        let why = if tot == 0 {
            "no runs".to_string()
        } else if errors_n * 2 >= 2 * 8 * goals * speeds.len() {
            format!(
                "{errors_n} of its runs ended with an engine error, so its counts say nothing of its friction"
            )
        } else if share(ok_open) >= 0.95 {
            if coulomb {
                "it applies Coulomb friction at every support, the model's law, so the plan made on the dynamic model works as it is".to_string()
            } else {
                format!(
                    "the plan works as it is: on this scene its friction moves the plate as Coulomb's does{}",
                    law.as_ref().map(|l| format!(" ({l})")).unwrap_or_default()
                )
            }
        } else if share(ok_mpc) >= 0.95 {
            let cause = if coulomb {
                "its declared law is Coulomb's, the model's, so the open-loop misses come from how it integrates the scene (its step, its solver), not from its friction law".to_string()
            } else {
                law.clone().unwrap_or_else(|| {
                    "it declares no law in closed form, and its turn rate differs from the model's"
                        .into()
                })
            };
            format!(
                "open loop reaches {ok_open}/{tot} (median final error {}, the tolerance 20 mm): {cause}; feedback every {PERIOD} s corrects the drift",
                mm(pe_open)
            )
        } else {
            let cause = if coulomb {
                "its declared law is Coulomb's, the model's, so the misses come from how it integrates the scene, not from its friction law".to_string()
            } else if e.law().is_some_and(|l| l.coulomb_on_run_loads()) {
                format!(
                    "{}; its friction is Coulomb's on the loads it carries, so the misses come from those loads or from how it integrates the scene, not from the shape of its law",
                    law.clone().unwrap_or_default()
                )
            } else {
                format!(
                    "{}; a controller whose predictor has the model's law cannot steer a plate that turns otherwise",
                    law.clone()
                        .unwrap_or_else(|| "it declares no law in closed form".into())
                )
            };
            format!(
                "open loop reaches {ok_open}/{tot} (median final error {}, {:.3} rad) and MPC {ok_mpc}/{tot}: {cause}",
                mm(pe_open),
                ae_open
            )
        };
        let errors = match errors_n {
            0 => String::new(),
            k => format!(
                " {k} of its runs ended with an engine error and count as misses (`runs.csv`, column `error`; the study prints the message)."
            ),
        };
        let against = if released(n) {
            let parts: Vec<String> = speeds
                .iter()
                .map(|&v| {
                    let o = |m| {
                        let (rel, t, _, _) = get(n, v, "release", "dynamic", m, "nominal");
                        let (rest, _, _, _) = get(n, v, "rest", "dynamic", m, "nominal");
                        format!("{rel}/{t} → {rest}/{t}")
                    };
                    format!("open loop {}, MPC {} at {v} m/s", o("open"), o("mpc"))
                })
                .collect();
            format!(
                " From the release rule to the rest rule (dynamic plan, nominal plant): {}.",
                parts.join("; ")
            )
        } else {
            format!(
                " {} of its rest runs were judged at the release: it cannot release the plate.",
                c.at_release.get(n.as_str()).copied().unwrap_or(0)
            )
        };
        s.push_str(&format!(
            "- **{n}** ({ok_open}/{tot} open, {ok_mpc}/{tot} MPC, {ok_mpc_p}/{tot} MPC on the perturbed plant): {why}.{errors}{against}\n"
        ));
    }
    s.push_str("\n## The kinematic plan against speed, at rest\n\n| engine | ");
    s.push_str(
        &speeds
            .iter()
            .map(|v| format!("{v} m/s"))
            .collect::<Vec<_>>()
            .join(" | "),
    );
    s.push_str(" |\n|---|");
    s.push_str(&"---|".repeat(speeds.len()));
    s.push('\n');
    let (mut grows, mut other) = (Vec::new(), Vec::new());
    for n in names {
        s.push_str(&format!("| {n} |"));
        let mut errs = Vec::new();
        for &v in speeds {
            let (ok, tot, pe, _) = get(n, v, "rest", "kinematic", "open", "nominal");
            let cell = if pe.is_finite() {
                format!("{:.1} mm", pe * 1e3)
            } else {
                "no final pose".into()
            };
            s.push_str(&format!(" {ok}/{tot} ({cell}) |"));
            errs.push(pe);
        }
        s.push('\n');
        if errs.len() > 1 {
            if errs.windows(2).all(|w| w[1] > w[0]) {
                grows.push(n.as_str());
            } else {
                other.push(n.as_str());
            }
        }
    }
    s.push_str("\nA plan made on the quasi-static model ignores the plate's inertia, its slide included (median final position error in brackets, failed runs counted as infinite).");
    if speeds.len() > 1 {
        s.push_str(&format!(
            " The median miss grows with every step up in speed in {} of {} engines{}",
            grows.len(),
            names.len(),
            if other.is_empty() {
                ".".to_string()
            } else {
                format!("; it does not in {}.", other.join(", "))
            }
        ));
    }
    s.push('\n');
    s
}
