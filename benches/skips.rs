//! What each skip saves: every shortcut pushval takes when a scene does not
//! need the work, timed with and without it side by side in one process.
//! Writes `results/skips.csv` (one row per skip: the two medians and their
//! ratio, and a note on what was compared).
//!
//! `cargo bench --bench skips` (add `-- --quick` for fewer repeats).
//!
//! Times are medians of the calling thread's CPU time, so other load on the
//! machine does not inflate them (everything measured here is single-threaded).

use std::hint::black_box;
use std::time::Duration;

use pushval::outdir::{field_num, records, Csv};
use pushval_model::{
    Body, DynamicModel, Integrator, KinematicModel, LimitSurfaceModel, Problem, Push,
    SegmentDynamics, Simulator, Support, Vec2,
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
        let recs = records(&text).expect("support_discretisation.csv is CSV");
        for target in [1e-3, 1e-6] {
            let cheapest = |rule: &str| {
                recs.iter()
                    .filter(|r| {
                        r["rule"] == rule
                            && field_num(r, "speed") == 1.0
                            && field_num(r, "rel_err") <= target
                    })
                    .min_by_key(|r| r["supports"].parse::<usize>().unwrap())
                    .cloned()
            };
            if let (Some(g), Some(q)) = (cheapest("grid"), cheapest("gauss_legendre")) {
                rows.push(Row {
                    skip: "support_discretisation",
                    scene: "uniform-pressure square, 1 m/s".into(),
                    without: format!("uniform grid, {} supports", g["supports"]),
                    without_s: field_num(&g, "steady_time_s"),
                    with: format!("Gauss-Legendre, {} supports", q["supports"]),
                    with_s: field_num(&q, "steady_time_s"),
                    note: format!(
                        "cheapest of each rule with steady-omega error <= {target:e} \
                         (support_discretisation.csv: grid {}, Gauss {})",
                        g["rel_err"], q["rel_err"]
                    ),
                });
            }
        }
    }

    // 5. Symmetric support sets: the friction sum over a set that is its own
    // mirror image, with the production loop against a folded loop that
    // stores one half and forms each mirror partner from the same loads.
    {
        let (seg, half) = mirror_set(1024);
        let w = -0.6;
        let calls = 200;
        let (a, b, ga, gb) = pair(
            reps,
            || {
                let mut g = 0.0;
                for k in 0..calls {
                    g += seg.friction_moment_at(1.0, black_box(w + 1e-9 * k as f64));
                }
                g
            },
            || {
                let mut g = 0.0;
                for k in 0..calls {
                    g += half.moment(1.0, black_box(w + 1e-9 * k as f64));
                }
                g
            },
        );
        let (m_all, m_half) = (seg.friction_moment_at(1.0, w), half.moment(1.0, w));
        assert!((ga - gb).abs() <= 1e-12 * ga.abs(), "{ga} against {gb}");
        rows.push(Row {
            skip: "symmetric_fold",
            scene: "1024 supports, mirror-symmetric about a line through the contact".into(),
            without: "paired friction loop over all supports".into(),
            without_s: a / calls as f64,
            with: "folded loop over 512 mirror pairs".into(),
            with_s: b / calls as f64,
            note: format!(
                "a mirror pair's sliding speeds differ when omega != 0, so folding saves loads, \
                 not the square roots and divisions that bound the loop; not shipped \
                 (moments {m_all:.17e} and {m_half:.17e} N m)"
            ),
        });
    }

    let mut csv = Csv::new(&[
        "skip",
        "scene",
        "without",
        "without_s",
        "with",
        "with_s",
        "ratio",
        "note",
    ]);
    for r in &rows {
        csv.row(&[
            r.skip.to_string(),
            r.scene.clone(),
            r.without.clone(),
            format!("{:.4e}", r.without_s),
            r.with.clone(),
            format!("{:.4e}", r.with_s),
            format!("{:.2}", r.without_s / r.with_s),
            r.note.clone(),
        ]);
    }
    let dir = root.join("results");
    std::fs::create_dir_all(&dir).unwrap();
    pushval::atomic::write_atomic(&dir.join("skips.csv"), csv.as_bytes()).unwrap();
    print!("{}", csv.text());
}

/// One half of a support set that is mirror-symmetric about the x axis of the
/// contact frame: `(F_i, x_i, ±y_i)` relative to the contact point.
struct MirrorHalf {
    f: Vec<f64>,
    rx: Vec<f64>,
    ry: Vec<f64>,
    dir: Vec2,
}

impl MirrorHalf {
    /// `−Σ F_i (r_i × u_i)/|u_i|` over both halves, each pair from one load of
    /// `(F, x, y)`, with the production loop's pairing over one division.
    fn moment(&self, v: f64, omega: f64) -> f64 {
        let (vx, vy) = (v * self.dir.x, v * self.dir.y);
        let floor = pushval_model::dynamic::U2_FLOOR;
        let n = self.f.len();
        let (f, rx, ry) = (&self.f[..n], &self.rx[..n], &self.ry[..n]);
        let mut acc = [0.0f64; 2];
        for c in 0..n / 2 {
            for (l, acc) in acc.iter_mut().enumerate() {
                let i = 2 * c + l;
                let (fi, x0, y0) = (f[i], rx[i], ry[i]);
                let uy = vy + omega * x0;
                let (ux1, ux2) = (vx - omega * y0, vx + omega * y0);
                let x = (ux1 * ux1 + uy * uy).max(floor);
                let y = (ux2 * ux2 + uy * uy).max(floor);
                let a = fi * (x0 * uy - y0 * ux1);
                let b = fi * (x0 * uy + y0 * ux2);
                *acc += (a * y * x.sqrt() + b * x * y.sqrt()) * (1.0 / (x * y));
            }
        }
        -(acc[0] + acc[1])
    }
}

/// A mirror-symmetric set of `n` supports (golden-angle spiral in the upper
/// half, mirrored), as a segment and as its folded half.
fn mirror_set(n: usize) -> (SegmentDynamics, MirrorHalf) {
    let h = n / 2;
    let upper: Vec<(f64, f64)> = (0..h)
        .map(|i| {
            let r = 0.125 * ((i as f64 + 0.5) / h as f64).sqrt();
            let t = i as f64 * 2.399_963_229_728_653;
            (0.2 + r * t.cos(), 0.01 + (r * t.sin()).abs())
        })
        .collect();
    let f = 0.5 * 9.81 / n as f64;
    let sup: Vec<Support> = upper
        .iter()
        .copied()
        .chain(upper.iter().map(|&(x, y)| (x, -y)))
        .map(|(x, y)| Support {
            position: Vec2::new(x, y),
            friction: f,
        })
        .collect();
    let push = Push {
        duration: 1.0,
        speed: 1.0,
        phi: 0.3,
    };
    let body = Body::new(1.0, 0.01, Vec2::zeros(), &sup).unwrap();
    let seg = SegmentDynamics::new(&body, &push);
    let half = MirrorHalf {
        f: vec![f; h],
        rx: upper.iter().map(|p| p.0).collect(),
        ry: upper.iter().map(|p| p.1).collect(),
        dir: push.direction(),
    };
    (seg, half)
}
