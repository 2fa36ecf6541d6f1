//! The `pushval-problem/1` and `/2` documents: one run's problem, as JSON.

use pushval_engine::EngineOptions;
use pushval_model::{Problem, Switching};
use serde_json::{json, Value};

use crate::limits::Limits;

/// The document's `format` value (version 1).
pub const FORMAT: &str = "pushval-problem/1";
/// The document's `format` value (version 2).
pub const FORMAT_V2: &str = "pushval-problem/2";

/// The gravity (m/s²) a document states when the options carry no scene.
const DEFAULT_GRAVITY: f64 = 9.81;

/// The `pushval-problem/1` document of one run of `engine` at step `dt` (s).
///
/// The physics comes from `problem` (mass, inertia, each support's friction
/// `μ_i N_i`, the contact, the schedule, the start, the sampling), so a
/// problem a caller changed (a study's speed, a power test's perturbed I_cm)
/// is the problem the process receives. The scenario's frame, outline,
/// gravity and loads come from `options.scene`: points are written in the
/// file's object frame, `normal_force` is the scenario's load and
/// `mu = μ_i N_i / N_i`. Without a scene (or with loads that no longer sum to
/// `m g`, or a different support count), the frame is the centre of mass's,
/// the outline is the convex hull of the supports and the contact, g is
/// 9.81 m/s² and the loads share `m g` in proportion to the friction.
/// `options` is the scenario's `[engine]` table without its `dt`: the step
/// of this run is the document's `dt` alone (the table's `dt` is where the
/// dt ladder starts, and its 2·dt rung runs at another step).
pub fn problem_document(
    engine: &str,
    problem: &Problem,
    options: &EngineOptions,
    dt: f64,
) -> Value {
    let body = &problem.body;
    let m = body.mass();
    let supports: Vec<_> = body.supports().collect();
    let total_friction: f64 = supports.iter().map(|s| s.friction).sum();
    let scene = options.scene.as_ref();
    let gravity = scene.map_or(DEFAULT_GRAVITY, |s| s.gravity);
    let weight = m * gravity;
    let scene_loads = scene.map(|s| &s.normal_forces).filter(|n| {
        n.len() == supports.len()
            && n.iter().all(|x| *x > 0.0)
            && (n.iter().sum::<f64>() - weight).abs() <= 1e-9 * weight
    });
    let offset = scene.map_or([0.0, 0.0], |s| s.center_of_mass);
    let at = |x: f64, y: f64| json!([x + offset[0], y + offset[1]]);
    let support_rows: Vec<Value> = supports
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let n = match scene_loads {
                Some(loads) => loads[i],
                None if total_friction > 0.0 => weight * s.friction / total_friction,
                None => weight / supports.len() as f64,
            };
            json!({
                "point": at(s.position.x, s.position.y),
                "mu": s.friction / n,
                "normal_force": n,
            })
        })
        .collect();
    let polygon: Vec<[f64; 2]> = match scene {
        Some(s) if s.polygon.len() >= 3 => s.polygon.clone(),
        _ => {
            let mut pts: Vec<[f64; 2]> = supports
                .iter()
                .map(|s| [s.position.x, s.position.y])
                .chain(std::iter::once([body.contact().x, body.contact().y]))
                .collect();
            pts = convex_hull(&mut pts);
            pts.iter()
                .map(|p| [p[0] + offset[0], p[1] + offset[1]])
                .collect()
        }
    };
    let times = problem.segment_times();
    let pushes: Vec<Value> = problem
        .pushes
        .iter()
        .zip(&times)
        .map(|(p, (t0, _))| {
            json!({"t_start": t0, "duration": p.duration, "speed": p.speed, "phi": p.phi})
        })
        .collect();
    // The step travels once, as the document's `dt`: the `[engine]` table's
    // own `dt` is the step the ladder starts from, not this run's (its 2·dt
    // rung differs), so `options` never carries it.
    let mut opts = serde_json::Map::new();
    for (k, v) in &options.values {
        opts.insert(k.clone(), v.clone());
    }
    let init = &problem.initial;
    json!({
        "format": FORMAT,
        "engine": engine,
        "dt": dt,
        "object": {
            "mass": m,
            "inertia_cm": body.inertia_cm(),
            "center_of_mass": offset,
            "polygon": polygon,
        },
        "supports": support_rows,
        "contact": {"point": at(body.contact().x, body.contact().y)},
        "initial": {
            "position": [init.position.x, init.position.y],
            "theta": init.theta,
            "omega": init.omega,
            "from_rest": init.from_rest,
        },
        "pushes": pushes,
        "sample_dt": problem.sample_dt,
        "gravity": gravity,
        "options": opts,
    })
}

/// The `pushval-problem/2` document: the version 1 document of
/// [`problem_document`] with `format` = [`FORMAT_V2`], `switching` (what ω
/// does when the pusher's velocity jumps: `"impulsive"`, the angular
/// momentum about the contact is kept, or `"continuous"`) and `limits`
/// (`max_rows`, `max_bytes`: pushval's cap on this run's output; past it the
/// process is killed and the run is an error).
pub fn problem_document_v2(
    engine: &str,
    problem: &Problem,
    options: &EngineOptions,
    dt: f64,
    limits: Limits,
) -> Value {
    let mut doc = problem_document(engine, problem, options, dt);
    let o = doc.as_object_mut().expect("the document is an object");
    o.insert("format".into(), json!(FORMAT_V2));
    o.insert(
        "switching".into(),
        json!(match problem.switching {
            Switching::Impulsive => "impulsive",
            Switching::Continuous => "continuous",
        }),
    );
    o.insert(
        "limits".into(),
        json!({"max_rows": limits.max_rows, "max_bytes": limits.max_bytes}),
    );
    // The slide: written only when the problem has one (a release, a
    // thrown plate's velocity), so that other documents are unchanged.
    if let Some(r) = &problem.release {
        o.insert("release".into(), json!({"max_duration": r.max_duration}));
    }
    let v = problem.initial.velocity;
    if v.x != 0.0 || v.y != 0.0 {
        if let Some(Value::Object(init)) = o.get_mut("initial") {
            init.insert("velocity".into(), json!([v.x, v.y]));
        }
    }
    doc
}

/// Counter-clockwise convex hull (Andrew's monotone chain), collinear
/// points dropped; fewer than three distinct points are returned as they are.
fn convex_hull(pts: &mut [[f64; 2]]) -> Vec<[f64; 2]> {
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let mut uniq: Vec<[f64; 2]> = Vec::new();
    for p in pts.iter() {
        if uniq.last() != Some(p) {
            uniq.push(*p);
        }
    }
    if uniq.len() < 3 {
        return uniq;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(uniq.iter())
        } else {
            Box::new(uniq.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}
