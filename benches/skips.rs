//! What each skip saves: every shortcut pushval takes when a scene does not
//! need the work, timed with and without it side by side in one process.
//! Writes `results/skips.csv` (one row per skip: the two medians and their
//! ratio, and a note on what was compared).
//!
//! `cargo bench --bench skips` (add `-- --quick` for fewer repeats).
//!
//! Times are medians of the calling thread's CPU time, so other load on the
//! machine does not inflate them (everything measured here is single-threaded).

use std::time::Duration;

use pushval_model::{
    DynamicModel, Integrator, KinematicModel, LimitSurfaceModel, Problem, Simulator,
};
use pushval_scenario::Scenario;

struct Row {
    skip: &'static str,
    scene: String,
    without: String,
    without_s: f64,
    with: String,
    with_s: f64,
    note: String,
}

fn thread_cpu_time() -> Duration {
    let ts = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// Median thread CPU time (s) of `runs` calls of `a` and of `b`, alternated
/// so both see the same machine state, and the last results.
fn pair<A, B>(runs: usize, mut a: impl FnMut() -> A, mut b: impl FnMut() -> B) -> (f64, f64, A, B) {
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    let (mut ra, mut rb) = (None, None);
    for _ in 0..runs.max(1) {
        let t0 = thread_cpu_time();
        ra = Some(a());
        let t1 = thread_cpu_time();
        rb = Some(b());
        let t2 = thread_cpu_time();
        ta.push(t1 - t0);
        tb.push(t2 - t1);
    }
    let med = |v: &mut Vec<Duration>| {
        v.sort();
        v[v.len() / 2].as_secs_f64()
    };
    (med(&mut ta), med(&mut tb), ra.unwrap(), rb.unwrap())
}

fn load(root: &std::path::Path, name: &str) -> (Scenario, Problem) {
    let sc = Scenario::from_path(root.join("scenarios").join(name)).unwrap();
    let p = sc.problem();
    (sc, p)
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let reps = if quick { 21 } else { 201 };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut rows: Vec<Row> = Vec::new();

    // 1. Closed-form arcs once a segment has settled.
    let (_, paper) = load(root, "paper-square-v1.0.toml");
    for tol in [1e-10, 1e-8] {
        let m = |skip: bool| DynamicModel {
            integrator: Integrator::Dop853 { tol },
            skip_settled: skip,
            ..Default::default()
        };
        let (full, skip) = (m(false), m(true));
        let (a, b, ta, tb) = pair(
            reps,
            || full.simulate(&paper).unwrap(),
            || skip.simulate(&paper).unwrap(),
        );
        let err = ta
            .samples
            .iter()
            .zip(&tb.samples)
            .map(|(p, q)| ((p.x - q.x).powi(2) + (p.y - q.y).powi(2)).sqrt())
            .fold(0.0, f64::max);
        rows.push(Row {
            skip: "settled_arc",
            scene: "paper-square-v1.0".into(),
            without: format!("DOP853 tol {tol:e}, integrate every segment to its end"),
            without_s: a,
            with: "closed-form tail once settled".into(),
            with_s: b,
            note: format!(
                "{} -> {} RHS evaluations; largest CM distance between the two {err:.1e} m",
                ta.stats.rhs_evals, tb.stats.rhs_evals
            ),
        });
    }

    // 2. The closed-form models run only when a scenario lists them.
    let dynamic = DynamicModel::default();
    let (a, b, _, _) = pair(
        reps,
        || {
            (
                dynamic.simulate(&paper).unwrap(),
                KinematicModel.simulate(&paper).unwrap(),
                LimitSurfaceModel.simulate(&paper).unwrap(),
            )
        },
        || dynamic.simulate(&paper).unwrap(),
    );
    rows.push(Row {
        skip: "unlisted_models",
        scene: "paper-square-v1.0".into(),
        without: "dynamic + kinematic + limit_surface".into(),
        without_s: a,
        with: "dynamic only ([run] models without them)".into(),
        with_s: b,
        note: "the kinematic and limit-surface models are closed-form arcs; skipping them saves little"
            .into(),
    });

    // 3. The assumption checks (pusher force, cone, support speeds per sample).
    let unchecked = DynamicModel {
        check_assumptions: false,
        ..Default::default()
    };
    let (a, b, _, _) = pair(
        reps,
        || dynamic.simulate(&paper).unwrap(),
        || unchecked.simulate(&paper).unwrap(),
    );
    rows.push(Row {
        skip: "assumption_checks (not skipped)",
        scene: "paper-square-v1.0".into(),
        without: "checks at every sample".into(),
        without_s: a,
        with: "check_assumptions = false".into(),
        with_s: b,
        note: "kept on in every harness run: pulling and sticking supports must be reported \
               whether or not a scenario sets [contact] limits"
            .into(),
    });

    // 4. Uniform pressure: the cheapest discretisation for an error in ω*,
    // from `cargo bench --bench support_discretisation`.
    if let Ok(text) = std::fs::read_to_string(root.join("results/support_discretisation.csv")) {
        let recs: Vec<Vec<String>> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect();
        for target in [1e-3, 1e-6] {
            let cheapest = |rule: &str| {
                recs.iter()
                    .filter(|r| {
                        r[0] == rule
                            && r[3].parse::<f64>().unwrap() == 1.0
                            && r[5].parse::<f64>().unwrap() <= target
                    })
                    .min_by_key(|r| r[2].parse::<usize>().unwrap())
                    .cloned()
            };
            if let (Some(g), Some(q)) = (cheapest("grid"), cheapest("gauss_legendre")) {
                rows.push(Row {
                    skip: "support_discretisation",
                    scene: "uniform-pressure square, 1 m/s".into(),
                    without: format!("uniform grid, {} supports", g[2]),
                    without_s: g[6].parse().unwrap(),
                    with: format!("Gauss-Legendre, {} supports", q[2]),
                    with_s: q[6].parse().unwrap(),
                    note: format!(
                        "cheapest of each rule with steady-omega error <= {target:e} \
                         (support_discretisation.csv: grid {}, Gauss {})",
                        g[5], q[5]
                    ),
                });
            }
        }
    }

    let mut csv = String::from("skip,scene,without,without_s,with,with_s,ratio,note\n");
    for r in &rows {
        let q = |s: &str| format!("\"{}\"", s.replace('"', "'"));
        csv.push_str(&format!(
            "{},{},{},{:.4e},{},{:.4e},{:.2},{}\n",
            r.skip,
            q(&r.scene),
            q(&r.without),
            r.without_s,
            q(&r.with),
            r.with_s,
            r.without_s / r.with_s,
            q(&r.note)
        ));
    }
    let dir = root.join("results");
    std::fs::create_dir_all(&dir).unwrap();
    pushval::output::write_atomic(&dir.join("skips.csv"), csv.as_bytes()).unwrap();
    print!("{csv}");
}
