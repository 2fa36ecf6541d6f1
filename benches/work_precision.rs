//! Work–precision on the 10 s paper trajectory (1 m/s, five segments):
//! every method's median run time against its error, measured side by side in
//! one process. Writes `results/work_precision.csv`, the figure
//! `results/work_precision.svg`, and `results/work_precision_target.csv`: the
//! cheapest pushval and ode_solvers Dop853 settings at 1e-9 m maximum
//! position error, timed alternately and compared, the same for the final
//! state alone (at those settings, and at each method's cheapest setting
//! for 1e-9 m at the final pose), then the medians of the model-predictive
//! controller's unit of work
//! (`model_short_horizon`: 6 segments from rest, two samples, assumption
//! checks off; `short_horizon/mod.rs`), the last also with its pushes'
//! analysis cached from an earlier call.
//!
//! `cargo bench --bench work_precision` (add `-- --quick` for fewer repeats).
//!
//! Run time is the median thread CPU time over repeated runs (robust to other
//! load on the machine; every method here is single-threaded).
//!
//! Error is measured against a DOP853 run at 1e-13: the largest centre-of-mass
//! distance over the samples (m) and the largest relative steady-ω error over
//! the settled segments. Methods: pushval's DOP853 and Dormand–Prince 5(4)
//! (with the settled-arc shortcut), fixed-step RK4, ode_solvers' Dopri5 and
//! Dop853 on the same right-hand side, and rapier2d (f64, f32; friction
//! velocity body / constraint / midpoint; plain and Richardson-extrapolated).

use std::cell::Cell;
use std::time::Duration;

use ode_solvers::{Dop853, Dopri5, OutputType, System, Vector4};
use pushval::harness::{analyse_segments, rel_err, tail_omega, SegmentInfo};
use pushval::outdir::csv_line;
use pushval_model::{
    DynamicModel, Integrator, Problem, PushCache, Rotor, SegmentDynamics, Simulator, Switching,
    Trajectory, Vec2,
};
use pushval_scenario::Scenario;

mod replan;
mod short_horizon;

struct Row {
    method: String,
    family: String,
    setting: String,
    rhs_evals: Option<usize>,
    median_s: f64,
    position_err: f64,
    omega_rel_err: Option<f64>,
}

/// CPU time of the calling thread (`CLOCK_THREAD_CPUTIME_ID`). Unlike wall
/// time it does not count the time the thread waits while other processes
/// run, so medians stay comparable on a shared machine.
fn thread_cpu_time() -> Duration {
    let ts = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// Median thread CPU time of `runs` calls (at least one), and the last result.
fn time<T>(runs: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs.max(1) {
        let t0 = thread_cpu_time();
        let r = f();
        times.push(thread_cpu_time() - t0);
        last = Some(r);
    }
    times.sort();
    (times[times.len() / 2], last.expect("ran at least once"))
}

fn errors(
    sc: &Scenario,
    segs: &[SegmentInfo],
    reference: &Trajectory,
    tr: &Trajectory,
    tail: bool,
) -> (f64, Option<f64>) {
    let pos = tr
        .samples
        .iter()
        .zip(&reference.samples)
        .map(|(p, q)| ((p.x - q.x).powi(2) + (p.y - q.y).powi(2)).sqrt())
        .fold(0.0, f64::max);
    // The same reading of the steady ω on the method and on the reference
    // (a segment's ω need not have reached ω* exactly by its end).
    let mut om: Option<f64> = None;
    for s in segs.iter().filter(|s| s.settles()) {
        let read = |tr: &Trajectory| {
            if tail {
                tail_omega(tr, s.t_start, s.t_end)
            } else {
                tr.segments.get(s.index).map(|r| r.omega_end)
            }
        };
        if let (Some(w), Some(wr)) = (read(tr), read(reference)) {
            let e = rel_err(w, wr, s.speed, sc.froude_length());
            om = Some(om.map_or(e, |m: f64| m.max(e)));
        }
    }
    (pos, om)
}

/// The pushing ODE for one segment in ode_solvers' terms: [θ, ω, c_x, c_y].
/// The same right-hand side as pushval's: `R(θ)` from a [`Rotor`] (in a
/// `Cell`, since ode_solvers passes `&self`).
struct Peer<'a> {
    seg: &'a SegmentDynamics,
    vel: Vec2,
    rotor: Cell<Rotor>,
}

impl System<f64, Vector4<f64>> for Peer<'_> {
    fn system(&self, _t: f64, y: &Vector4<f64>, dy: &mut Vector4<f64>) {
        let mut rotor = self.rotor.get();
        let (s, c) = rotor.sin_cos(y[0]);
        self.rotor.set(rotor);
        dy[0] = y[1];
        dy[1] = self.seg.omega_dot(y[1]);
        dy[2] = c * self.vel.x - s * self.vel.y;
        dy[3] = s * self.vel.x + c * self.vel.y;
    }
}

/// Runs the problem segment by segment with an ode_solvers method, the same
/// impulsive switches as the model, dense output at the sample times.
fn peer(problem: &Problem, tol: f64, eighth: bool) -> (Trajectory, usize) {
    let body = &problem.body;
    let pc = body.contact();
    let mut theta = problem.initial.theta;
    let mut c = problem.initial.position + pushval_model::rotate(theta, &pc);
    let mut omega = problem.initial.omega;
    let mut evals = 0usize;
    let mut tr = Trajectory {
        model: "peer".into(),
        ..Default::default()
    };
    let n = problem.pushes.len();
    for (j, (push, (t0, t1))) in problem
        .pushes
        .iter()
        .zip(problem.segment_times())
        .enumerate()
    {
        if j > 0 {
            omega = problem.omega_after_switch(Some(&problem.pushes[j - 1]), push, omega);
        }
        let seg = SegmentDynamics::new(body, push);
        let sys = Peer {
            seg: &seg,
            vel: push.velocity(),
            rotor: Cell::new(Rotor::new()),
        };
        let y0 = Vector4::new(theta, omega, c.x, c.y);
        let (xs, ys) = if eighth {
            let mut s = Dop853::new(sys, t0, t1, problem.sample_dt, y0, tol, tol);
            let st = s.integrate().expect("peer integration");
            evals += st.num_eval as usize;
            let (x, y) = s.results().get();
            (x.clone(), y.clone())
        } else {
            let mut s = Dopri5::new(sys, t0, t1, problem.sample_dt, y0, tol, tol);
            let st = s.integrate().expect("peer integration");
            evals += st.num_eval as usize;
            let (x, y) = s.results().get();
            (x.clone(), y.clone())
        };
        for (t, y) in xs.iter().zip(&ys) {
            if (*t < t1 - 1e-9 || j + 1 == n) && tr.samples.last().is_none_or(|s| *t > s.t + 1e-9) {
                let p = Vec2::new(y[2], y[3]) - pushval_model::rotate(y[0], &pc);
                tr.samples.push(pushval_model::Sample {
                    t: *t,
                    x: p.x,
                    y: p.y,
                    theta: y[0],
                    omega: y[1],
                });
            }
        }
        let last = ys.last().expect("at least the end point");
        theta = last[0];
        omega = last[1];
        c = Vec2::new(last[2], last[3]);
        tr.segments.push(pushval_model::SegmentReport {
            index: j,
            t_start: t0,
            t_end: t1,
            omega_end: omega,
            ..Default::default()
        });
    }
    (tr, evals)
}

/// The peer asked only for the state at the end, as a predictor asks:
/// ode_solvers' Dop853 with `OutputType::Sparse` (the state after each step,
/// no dense output; otherwise `Dop853::new`'s settings), the same switches.
/// Returns the centre of mass's final (x, y, θ) and the evaluations.
fn peer_final(problem: &Problem, tol: f64) -> ([f64; 3], usize) {
    let body = &problem.body;
    let pc = body.contact();
    let mut theta = problem.initial.theta;
    let mut c = problem.initial.position + pushval_model::rotate(theta, &pc);
    let mut omega = problem.initial.omega;
    let mut evals = 0usize;
    for (j, (push, (t0, t1))) in problem
        .pushes
        .iter()
        .zip(problem.segment_times())
        .enumerate()
    {
        if j > 0 {
            omega = problem.omega_after_switch(Some(&problem.pushes[j - 1]), push, omega);
        }
        let seg = SegmentDynamics::new(body, push);
        let sys = Peer {
            seg: &seg,
            vel: push.velocity(),
            rotor: Cell::new(Rotor::new()),
        };
        let y0 = Vector4::new(theta, omega, c.x, c.y);
        let span = t1 - t0;
        let mut s = Dop853::from_param(
            sys,
            t0,
            t1,
            span,
            y0,
            tol,
            tol,
            0.9,
            0.0,
            0.333,
            6.0,
            span,
            0.0,
            100_000,
            1000,
            OutputType::Sparse,
        );
        let st = s.integrate().expect("peer integration");
        evals += st.num_eval as usize;
        let last = s.y_out().last().expect("at least the end point");
        (theta, omega, c) = (last[0], last[1], Vec2::new(last[2], last[3]));
    }
    let p = c - pushval_model::rotate(theta, &pc);
    ([p.x, p.y, theta], evals)
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    // `--model-only`: the adaptive methods and the peer only, printed, no files.
    let model_only = std::env::args().any(|a| a == "--model-only");
    let reps = if quick { 3 } else { 15 };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let sc = Scenario::from_path(root.join("scenarios/paper-square-v1.0.toml")).unwrap();
    let problem = sc.problem();
    assert_eq!(problem.switching, Switching::Impulsive);
    // The reference integrates every segment to its end: it shares no
    // shortcut with the methods it measures.
    let reference = DynamicModel {
        integrator: Integrator::Dop853 { tol: 1e-13 },
        skip_settled: false,
        ..Default::default()
    }
    .simulate(&problem)
    .unwrap();
    let segs = analyse_segments(&sc, &problem, &reference);
    let mut rows: Vec<Row> = Vec::new();
    let tols = [
        1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12,
    ];
    for tol in tols {
        for (name, integrator) in [
            ("pushval DOP853", Integrator::Dop853 { tol }),
            ("pushval DP5(4)", Integrator::Adaptive { tol }),
        ] {
            let m = DynamicModel {
                integrator,
                check_assumptions: false,
                ..Default::default()
            };
            let (d, tr) = time(reps, || m.simulate(&problem).unwrap());
            let (pe, oe) = errors(&sc, &segs, &reference, &tr, false);
            rows.push(Row {
                method: name.into(),
                family: "model".into(),
                setting: format!("tol={tol:e}"),
                rhs_evals: Some(tr.stats.rhs_evals),
                median_s: d.as_secs_f64(),
                position_err: pe,
                omega_rel_err: oe,
            });
        }
        for (name, eighth) in [("ode_solvers Dop853", true), ("ode_solvers Dopri5", false)] {
            let (d, (tr, ev)) = time(reps, || peer(&problem, tol, eighth));
            let (pe, oe) = errors(&sc, &segs, &reference, &tr, false);
            rows.push(Row {
                method: name.into(),
                family: "peer".into(),
                setting: format!("tol={tol:e}"),
                rhs_evals: Some(ev),
                median_s: d.as_secs_f64(),
                position_err: pe,
                omega_rel_err: oe,
            });
        }
        eprint!(".");
    }
    let mut target = target_comparison(
        &sc,
        &segs,
        &problem,
        &reference,
        if quick { 21 } else { 61 },
    );
    target.push_str(&short_horizon_line(root, if quick { 201 } else { 2001 }));
    target.push_str(&mpc_pattern_line(if quick { 3 } else { 11 }));
    target.push_str(&load_line());
    if model_only {
        eprintln!();
        print!("{target}");
        for r in &rows {
            println!(
                "{:20} {:10} evals {:5} median {:8.2} us  pos err {:.2e}",
                r.method,
                r.setting,
                r.rhs_evals.unwrap_or(0),
                r.median_s * 1e6,
                r.position_err
            );
        }
        return;
    }
    for dt in [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4] {
        let m = DynamicModel {
            integrator: Integrator::Rk4 { dt },
            skip_settled: false,
            check_assumptions: false,
            ..Default::default()
        };
        let (d, tr) = time(reps, || m.simulate(&problem).unwrap());
        let (pe, oe) = errors(&sc, &segs, &reference, &tr, false);
        rows.push(Row {
            method: "pushval RK4".into(),
            family: "model".into(),
            setting: format!("dt={dt:e}"),
            rhs_evals: Some(tr.stats.rhs_evals),
            median_s: d.as_secs_f64(),
            position_err: pe,
            omega_rel_err: oe,
        });
    }
    let dts: &[f64] = if quick {
        &[1.0 / 60.0, 1e-3]
    } else {
        &[1.0 / 60.0, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5]
    };
    // The default gated engine through the registry, in each precision and
    // friction-velocity mode its `[engine]` options offer.
    let gate = pushval_scenario::DEFAULT_GATE[0];
    for precision in ["f64", "f32"] {
        for mode in ["body", "constraint", "midpoint", "leapfrog"] {
            let mut options = pushval_engine::EngineOptions::default();
            options
                .values
                .insert("precision".into(), serde_json::json!(precision));
            options
                .values
                .insert("friction_velocity".into(), serde_json::json!(mode));
            let engine = pushval::registry::engine(gate, &options);
            for &dt in dts {
                let run = |dt: f64| engine.run(&problem, dt).unwrap().trajectory;
                let r = if dt < 2e-4 { 1 } else { reps.min(5) };
                let (d, tr) = time(r, || run(dt));
                let (pe, oe) = errors(&sc, &segs, &reference, &tr, true);
                let name = format!("{gate} {precision} {mode}");
                rows.push(Row {
                    method: name.clone(),
                    family: "engine".into(),
                    setting: format!("dt={dt:e}"),
                    rhs_evals: None,
                    median_s: d.as_secs_f64(),
                    position_err: pe,
                    omega_rel_err: oe,
                });
                // Richardson at the scheme's order p: x(h) + (x(h) − x(2h)) / (2^p − 1)
                // on the common samples; its cost is both runs.
                let (d2, tr2) = time(r, || run(2.0 * dt));
                let k = 2f64.powf(engine.order()) - 1.0;
                let mut rich = tr.clone();
                for (s, c) in rich.samples.iter_mut().zip(&tr2.samples) {
                    s.x += (s.x - c.x) / k;
                    s.y += (s.y - c.y) / k;
                    s.theta += (s.theta - c.theta) / k;
                    s.omega += (s.omega - c.omega) / k;
                }
                let (pe, oe) = errors(&sc, &segs, &reference, &rich, true);
                rows.push(Row {
                    method: format!("{name} richardson"),
                    family: "engine".into(),
                    setting: format!("dt={dt:e}"),
                    rhs_evals: None,
                    median_s: (d + d2).as_secs_f64(),
                    position_err: pe,
                    omega_rel_err: oe,
                });
            }
            eprint!(".");
        }
    }
    eprintln!();
    let mut csv = csv_line(&[
        "method",
        "family",
        "setting",
        "rhs_evals",
        "median_s",
        "position_err_m",
        "omega_steady_rel_err",
    ]);
    for r in &rows {
        csv.push_str(&csv_line(&[
            r.method.to_string(),
            r.family.to_string(),
            r.setting.to_string(),
            r.rhs_evals.map_or(String::new(), |n| n.to_string()),
            format!("{:.6e}", r.median_s),
            format!("{:.3e}", r.position_err),
            r.omega_rel_err
                .map_or(String::new(), |e| format!("{e:.3e}")),
        ]));
    }
    let dir = root.join("results");
    std::fs::create_dir_all(&dir).unwrap();
    pushval::atomic::write_atomic(&dir.join("work_precision_target.csv"), target.as_bytes())
        .unwrap();
    pushval::atomic::write_atomic(&dir.join("work_precision.csv"), csv.as_bytes()).unwrap();
    pushval::atomic::write_atomic(&dir.join("work_precision.svg"), figure(&rows).as_bytes())
        .unwrap();
    print!("{csv}");
}

/// Maximum position error the speed target is set at (m).
const TARGET_ERR: f64 = 1e-9;

/// The cheapest setting of pushval's DOP853 and of ode_solvers' Dop853 that
/// keeps the maximum position error at or below [`TARGET_ERR`], each found
/// on the same fine tolerance ladder (eight steps per decade, from 1e-5 down:
/// the first tolerance that meets the target), then timed side by side: runs
/// alternate between the two, `runs` each, and the medians are compared.
/// Then the final state alone (pushval's `final_state`, the peer without
/// dense output), timed the same way twice: at those tolerances, and at
/// each method's cheapest tolerance on the ladder that keeps the final
/// position within [`TARGET_ERR`]. Returns CSV: one row per method, each
/// pair followed by its ratio as a comment line.
fn target_comparison(
    sc: &Scenario,
    segs: &[SegmentInfo],
    problem: &Problem,
    reference: &Trajectory,
    runs: usize,
) -> String {
    let ours = |tol: f64| {
        let m = DynamicModel {
            integrator: Integrator::Dop853 { tol },
            check_assumptions: false,
            ..Default::default()
        };
        let tr = m.simulate(problem).unwrap();
        let n = tr.stats.rhs_evals;
        (tr, n)
    };
    let theirs = |tol: f64| peer(problem, tol, true);
    let ladder: Vec<f64> = (0..=56)
        .map(|i| 1e-5 * 10f64.powf(-i as f64 / 8.0))
        .collect();
    let cheapest = |run: &dyn Fn(f64) -> (Trajectory, usize)| {
        ladder.iter().find_map(|&tol| {
            let (tr, n) = run(tol);
            let (pe, _) = errors(sc, segs, reference, &tr, false);
            (pe <= TARGET_ERR).then_some((tol, n, pe))
        })
    };
    let a = cheapest(&ours).expect("pushval meets the target on the ladder");
    let b = cheapest(&theirs).expect("the peer meets the target on the ladder");
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        ta.push(time(1, || ours(a.0)).0);
        tb.push(time(1, || theirs(b.0)).0);
    }
    ta.sort();
    tb.sort();
    let (ma, mb) = (ta[runs / 2].as_secs_f64(), tb[runs / 2].as_secs_f64());
    // Records with `#` comment lines between them: written a line at a time.
    let line = |name: &str, tol: f64, n: usize, pe: f64, m: f64| {
        csv_line(&[
            format!("{TARGET_ERR:e}"),
            name.to_string(),
            format!("{tol:.3e}"),
            n.to_string(),
            format!("{pe:.3e}"),
            format!("{m:.6e}"),
        ])
    };
    let mut out = csv_line(&[
        "target_position_err_m",
        "method",
        "tol",
        "rhs_evals",
        "position_err_m",
        "median_s",
    ]);
    for (name, (tol, n, pe), m) in [("pushval DOP853", a, ma), ("ode_solvers Dop853", b, mb)] {
        out.push_str(&line(name, tol, n, pe, m));
    }
    out.push_str(&format!("# speed-up at the target: {:.2}x\n", mb / ma));
    // Asked for the final state alone, as a predictor asks: pushval's
    // `final_state` against the peer without dense output. Error: the
    // distance from the reference's final position. Timed twice: at the
    // sampled runs' tolerances above, and at each method's own cheapest
    // tolerance on the same ladder for TARGET_ERR at the final pose (what
    // a predictor is held to: only the end counts).
    let end = reference.samples.last().expect("the reference ends");
    let final_err = |x: f64, y: f64| (x - end.x).hypot(y - end.y);
    let ours_final = |tol: f64| {
        DynamicModel {
            integrator: Integrator::Dop853 { tol },
            check_assumptions: false,
            ..Default::default()
        }
        .final_state(problem)
        .unwrap()
    };
    let fa_tol = ladder
        .iter()
        .copied()
        .find(|&tol| {
            let f = ours_final(tol);
            final_err(f.x, f.y) <= TARGET_ERR
        })
        .expect("pushval's final state meets the target on the ladder");
    let fb_tol = ladder
        .iter()
        .copied()
        .find(|&tol| {
            let (f, _) = peer_final(problem, tol);
            final_err(f[0], f[1]) <= TARGET_ERR
        })
        .expect("the peer's final state meets the target on the ladder");
    for (label, (ta_tol, tb_tol)) in [
        ("the same tolerances as the sampled runs", (a.0, b.0)),
        (
            "each method's cheapest tolerance for the target at the final pose",
            (fa_tol, fb_tol),
        ),
    ] {
        let model = DynamicModel {
            integrator: Integrator::Dop853 { tol: ta_tol },
            check_assumptions: false,
            ..Default::default()
        };
        let ours = || model.final_state(problem).unwrap();
        let theirs = || peer_final(problem, tb_tol);
        let fa = ours();
        let (fb, nb) = theirs();
        let (ea, eb) = (final_err(fa.x, fa.y), final_err(fb[0], fb[1]));
        let (mut ta, mut tb) = (Vec::new(), Vec::new());
        for _ in 0..runs {
            ta.push(time(1, ours).0);
            tb.push(time(1, theirs).0);
        }
        ta.sort();
        tb.sort();
        let (fma, fmb) = (ta[runs / 2].as_secs_f64(), tb[runs / 2].as_secs_f64());
        out.push_str(&line(
            "pushval DOP853 final state",
            ta_tol,
            fa.stats.rhs_evals,
            ea,
            fma,
        ));
        out.push_str(&line("ode_solvers Dop853 final state", tb_tol, nb, eb, fmb));
        out.push_str(&format!(
            "# speed-up at the target, final state only ({label}; no samples, the peer without dense output): {:.2}x\n",
            fmb / fma
        ));
    }
    out
}

/// The median thread CPU time of `runs` dynamic-model runs of the
/// short horizon (`short_horizon/mod.rs`), as comment lines of
/// `work_precision_target.csv`: the sampled run (two samples) at the
/// bench's tolerance, then the final state alone at that tolerance and at
/// the predictor's ([`short_horizon::PREDICTOR_TOL`]), and that with the
/// pushes' analysis cached from an earlier call ([`PushCache`]), timed
/// alternately.
fn short_horizon_line(root: &std::path::Path, runs: usize) -> String {
    let problem = short_horizon::problem(root);
    let model = short_horizon::model();
    let tol = match model.integrator {
        Integrator::Dop853 { tol } => tol,
        other => panic!("the short horizon runs DOP853, not {other:?}"),
    };
    let predictor = short_horizon::predictor();
    let tr = model.simulate(&problem).unwrap();
    let end = model.final_state(&problem).unwrap();
    let end9 = predictor.final_state(&problem).unwrap();
    // The predictor's call again with its pushes seen before (the cache
    // warm): what a repeated push spares, the same state to the bit.
    let mut cache = PushCache::new();
    assert_eq!(
        predictor.final_state_cached(&problem, &mut cache).unwrap(),
        end9
    );
    let (mut ts, mut tf, mut tp, mut tc) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for _ in 0..runs {
        ts.push(time(1, || model.simulate(&problem).unwrap()).0);
        tf.push(time(1, || model.final_state(&problem).unwrap()).0);
        tp.push(time(1, || predictor.final_state(&problem).unwrap()).0);
        tc.push(
            time(1, || {
                predictor.final_state_cached(&problem, &mut cache).unwrap()
            })
            .0,
        );
    }
    let median = |v: &mut Vec<Duration>| {
        v.sort();
        v[v.len() / 2].as_secs_f64()
    };
    let (ms, mf, mp, mc) = (
        median(&mut ts),
        median(&mut tf),
        median(&mut tp),
        median(&mut tc),
    );
    let mut out = format!(
        "# model_short_horizon ({} segments from rest, {:.2} s, {} samples, checks off, DOP853 tol {tol:e}): median {ms:.6e} s, {} RHS evaluations\n",
        short_horizon::SEGMENTS,
        problem.duration(),
        tr.samples.len(),
        tr.stats.rhs_evals
    );
    out.push_str(&format!(
        "# model_short_horizon final state only (DOP853 tol {tol:e}): median {mf:.6e} s, {} RHS evaluations\n",
        end.stats.rhs_evals
    ));
    out.push_str(&format!(
        "# model_short_horizon final state only at the predictor's tolerance (DOP853 tol {:e}): median {mp:.6e} s, {} RHS evaluations\n",
        short_horizon::PREDICTOR_TOL,
        end9.stats.rhs_evals
    ));
    out.push_str(&format!(
        "# model_short_horizon final state only at the predictor's tolerance, every push seen before (PushCache warm; the same state to the bit): median {mc:.6e} s\n",
    ));
    out
}

/// The predictor's calls as the model-predictive controller makes them, as
/// a comment line of `work_precision_target.csv`: for each of the control
/// study's 20 goals at 1 m/s, the plan from rest (6 pushes), then one
/// period's warm re-plan as `benches/control.rs` times it (the plan's first
/// push run for 0.2 s on the dynamic model with μ × 0.8, then at most four
/// Levenberg–Marquardt iterations from there, warm-started from the plan
/// and from the predictor's cache of it). Each re-plan is timed `runs`
/// times on a copy of the planner (thread CPU time, median); the line gives
/// the median re-plan, the predictor calls it makes, and the re-plans' time
/// over their calls: a call's cost in the controller's own pattern (the
/// solver's own work included, a small part).
fn mpc_pattern_line(runs: usize) -> String {
    use pushval::control::plan::{straight_time, PlanSpec, Planner};
    use pushval::control::predict::Start;
    use pushval::control::study::{goals, scene};
    use pushval::control::{At, ModelKind, Reach};
    let problem = scene().unwrap();
    let goals = goals(&problem, &[1.0], 20);
    let start = Start::of_problem(&problem);
    let reach = Reach::default();
    let (mut replans, mut total, mut calls) = (Vec::new(), 0.0, 0usize);
    for goal in &goals {
        let spec = PlanSpec {
            segments: 6,
            speed: 1.0,
            predictor: ModelKind::Dynamic,
            at: At::Release,
        };
        let mut planner = Planner::new(
            &problem,
            *goal,
            spec,
            straight_time(&start, goal, 1.0),
            reach,
        );
        let Some(plan) = planner.plan(&start) else {
            continue;
        };
        let (from, warm) = replan::replan_case(&problem, &planner, &plan);
        let mut times = Vec::with_capacity(runs);
        let mut n = 0;
        for _ in 0..runs {
            let mut p = planner.clone();
            let r0 = p.predict.runs();
            let t0 = thread_cpu_time();
            std::hint::black_box(p.solve(&from, warm.clone(), 4));
            times.push((thread_cpu_time() - t0).as_secs_f64());
            n = p.predict.runs() - r0;
        }
        times.sort_by(f64::total_cmp);
        let m = times[times.len() / 2];
        replans.push(m);
        total += m;
        calls += n;
    }
    replans.sort_by(f64::total_cmp);
    format!(
        "# MPC pattern ({} warm re-plans, one per study goal at 1 m/s, 6 pushes, the predictor's cache warm from the plan): median re-plan {:.6e} s, {:.1} predictor calls per re-plan, {:.6e} s per call (all re-plans' time over all their calls)\n",
        replans.len(),
        replans[replans.len() / 2],
        calls as f64 / replans.len() as f64,
        total / calls as f64
    )
}

/// The machine's load averages (1, 5, 15 min, from `/proc/loadavg`) when
/// the timings end, as a comment line: thread CPU time leaves out waiting,
/// but cores shared with other work still slow every method, so the
/// absolute medians read with it (the ratios, timed alternately, less so).
fn load_line() -> String {
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let avg: Vec<&str> = load.split_whitespace().take(3).collect();
    format!(
        "# load averages at the end of the timings (1, 5, 15 min; {} cores): {}\n",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        if avg.len() == 3 {
            avg.join(", ")
        } else {
            "unknown".into()
        }
    )
}

/// Log–log work–precision figure: error against median run time, one line per
/// method (position error left, steady-ω error right). Errors below 1e-12
/// are round-off and drawn at 1e-12.
fn figure(rows: &[Row]) -> String {
    use pushval::plot::{Axis, Figure, Legend, Panel, Series, Stroke, PALETTE};
    let shown = [
        ("pushval DOP853", Stroke::Solid),
        ("pushval DP5(4)", Stroke::Solid),
        ("pushval RK4", Stroke::Solid),
        ("ode_solvers Dop853", Stroke::Dashed),
        ("ode_solvers Dopri5", Stroke::Dashed),
        ("rapier2d f64 leapfrog", Stroke::Dots),
        ("rapier2d f64 leapfrog richardson", Stroke::Dots),
        ("rapier2d f64 midpoint", Stroke::Dots),
        ("rapier2d f64 constraint", Stroke::Dots),
        ("rapier2d f64 body", Stroke::Dots),
        ("rapier2d f32 leapfrog", Stroke::Dots),
    ];
    let panel = |title: &str, ylabel: &str, pick: &dyn Fn(&Row) -> Option<f64>| {
        let mut p = Panel::new(title, Axis::log("median run time (s)"), Axis::log(ylabel))
            .legend(Legend::UpperRight);
        for (k, (name, stroke)) in shown.iter().enumerate() {
            let mut pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.method == *name)
                .filter_map(|r| {
                    pick(r)
                        .filter(|e| *e > 0.0 && e.is_finite())
                        .map(|e| (r.median_s, e.max(1e-12)))
                })
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            if !pts.is_empty() {
                p = p.series(Series::new(*name, PALETTE[k % PALETTE.len()], *stroke).points(pts));
            }
        }
        p
    };
    let fig = Figure {
        size: (1400, 620),
        cols: 2,
        panels: vec![
            panel(
                "Work–precision, 10 s paper trajectory: position",
                "max CM position error (m)",
                &|r| Some(r.position_err),
            ),
            panel(
                "Work–precision: steady ω",
                "max relative steady-ω error",
                &|r| r.omega_rel_err,
            ),
        ],
        key: None,
    };
    pushval::plot::render(&fig).expect("figure renders")
}
