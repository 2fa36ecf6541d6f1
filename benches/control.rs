//! The closed loop's costs: one plan from rest (6 pushes and the duration,
//! Levenberg–Marquardt on the dynamic model's final pose; target median
//! ≤ 1 ms) and one MPC period's re-plan from a measured state, warm-started
//! from the last plan and its Jacobian (target median ≤ 100 µs, p99 ≤ 1 ms;
//! the control study's loop.json rows give the p99 over whole runs).
//!
//! Goals: the control study's first three (0.3–1 m away, turns up to
//! ±90°), at 0.5 and 1 m/s. The MPC period re-plans at t = 0.2 s of the plan
//! after a 0.02 s period on a plant with μ × 0.8 (the dynamic model as the
//! plant), so the warm start has something to correct.
//!
//! The cost table (`results/control_cost.csv`) adds adaptive MPC's period
//! (the estimator's update and the re-plan on the estimate) at 50 Hz and
//! 1 kHz on a plate with one slippery foot.
//!
//! `cargo bench --bench control`

mod replan;

use criterion::{criterion_group, BatchSize, BenchmarkId, Criterion};
use pushval::control::mpc::PlantScale;
use pushval::control::plan::{straight_time, PlanSpec, Planner};
use pushval::control::predict::Start;
use pushval::control::study::{goals, scene};
use pushval::control::{ModelKind as Predictor, Reach};
use pushval::outdir::Csv;

fn control(c: &mut Criterion) {
    let problem = scene().unwrap();
    let speeds = [0.5, 1.0];
    let goals = goals(&problem, &speeds, 3);
    let start = Start::of_problem(&problem);
    let reach = Reach::default();
    let mut g = c.benchmark_group("plan");
    g.sample_size(30);
    for &v in &speeds {
        for (i, goal) in goals.iter().enumerate() {
            let spec = PlanSpec {
                segments: 6,
                speed: v,
                predictor: Predictor::Dynamic,
                at: pushval::control::At::Release,
            };
            let planner =
                Planner::new(&problem, *goal, spec, straight_time(&start, goal, v), reach);
            assert!(planner.clone().plan(&start).unwrap().converged);
            g.bench_with_input(
                BenchmarkId::new("from_rest_6_segments", format!("goal{i}_{v}mps")),
                &planner,
                |b, planner| {
                    b.iter_batched(
                        || planner.clone(),
                        |mut p| p.plan(&start),
                        BatchSize::SmallInput,
                    )
                },
            );
        }
    }
    g.finish();

    let mut g = c.benchmark_group("mpc_period");
    g.sample_size(50);
    for &v in &speeds {
        for (i, goal) in goals.iter().enumerate() {
            let spec = PlanSpec {
                segments: 6,
                speed: v,
                predictor: Predictor::Dynamic,
                at: pushval::control::At::Release,
            };
            let mut planner =
                Planner::new(&problem, *goal, spec, straight_time(&start, goal, v), reach);
            let plan = planner.plan(&start).unwrap();
            // The plant (μ × 0.8) runs the plan's first push for 0.2 s.
            let (from, warm) = replan::replan_case(&problem, &planner, &plan);
            g.bench_with_input(
                BenchmarkId::new("replan_warm", format!("goal{i}_{v}mps")),
                &planner,
                |b, planner| {
                    b.iter_batched(
                        || (planner.clone(), warm.clone()),
                        |(mut p, w)| p.solve(&from, w, 4),
                        BatchSize::SmallInput,
                    )
                },
            );
        }
    }
    g.finish();
}

/// The targets over the study's whole goal list, into
/// `results/control_cost.csv`: every plan from rest (20 goals × 3 speeds,
/// each the median of 5 solves, wall clock), and every MPC period's re-plan
/// of the dynamic predictor with rapier2d as the perturbed plant (20 goals
/// at 1 m/s; `loop.json`'s `predictor_us_*` over the pooled periods).
fn cost_table() {
    use pushval::control::mpc::{run_loop, LoopSpec};
    use pushval::control::stats::median_p99;
    let problem = scene().unwrap();
    let speeds = [0.1, 0.5, 1.0];
    let goals = goals(&problem, &speeds, 20);
    let start = Start::of_problem(&problem);
    let reach = Reach::default();
    // Plans judged at the release and plans aimed at rest (the slide in the
    // prediction), timed side by side: for each goal and speed, five solves
    // of each, alternately.
    let mut plan_us = Vec::new();
    let mut rest_us = Vec::new();
    for &v in &speeds {
        for goal in &goals {
            let planner_at = |at| {
                let spec = PlanSpec {
                    segments: 6,
                    speed: v,
                    predictor: Predictor::Dynamic,
                    at,
                };
                Planner::new(&problem, *goal, spec, straight_time(&start, goal, v), reach)
            };
            let planners = [
                planner_at(pushval::control::At::Release),
                planner_at(pushval::control::At::Rest),
            ];
            let mut t = [Vec::new(), Vec::new()];
            for _ in 0..5 {
                for (k, planner) in planners.iter().enumerate() {
                    let mut p = planner.clone();
                    let c = std::time::Instant::now();
                    std::hint::black_box(p.plan(&start));
                    t[k].push(c.elapsed().as_secs_f64() * 1e6);
                }
            }
            for v in &mut t {
                v.sort_by(f64::total_cmp);
            }
            plan_us.push(t[0][2]);
            rest_us.push(t[1][2]);
        }
    }
    let engine = pushval::registry::engine("rapier2d", &Default::default());
    let mut period_us = Vec::new();
    let mut period_cpu_us = Vec::new();
    let mut reached = 0;
    for goal in &goals {
        let spec = LoopSpec {
            plan: PlanSpec {
                segments: 6,
                speed: 1.0,
                predictor: Predictor::Dynamic,
                at: pushval::control::At::Release,
            },
            period: 0.02,
            reach,
            adapt: false,
            sensor: Default::default(),
        };
        let plant = PlantScale::PERTURBED.apply(&problem).unwrap();
        let dt = engine.default_dt();
        let mut session = engine.start(&plant, dt).unwrap();
        let out = run_loop(&problem, session.as_mut(), dt, *goal, spec, &mut ()).unwrap();
        period_us.extend(out.predictor_us);
        period_cpu_us.extend(out.predictor_cpu_us);
        reached += usize::from(out.success);
    }
    // Adaptive MPC on a plate with one slippery foot (the adaptive study's
    // `slippery_near`), judged at the release, at 50 Hz (20 goals) and at
    // 1 kHz (the first 5): every period's estimator update and re-plan,
    // thread CPU time, pooled.
    let slippery = pushval::control::adaptive::PlantKind::SlipperyNear
        .apply(&problem)
        .unwrap();
    let adaptive_loops = |period: f64, goals: &[pushval::control::Goal]| {
        let (mut per, mut est, mut ok) = (Vec::new(), Vec::new(), 0usize);
        for goal in goals {
            let spec = LoopSpec {
                plan: PlanSpec {
                    segments: 6,
                    speed: 1.0,
                    predictor: Predictor::Dynamic,
                    at: pushval::control::At::Release,
                },
                period,
                reach,
                adapt: true,
                sensor: Default::default(),
            };
            let dt = engine.default_dt();
            let mut session = engine.start(&slippery, dt).unwrap();
            let out = run_loop(&problem, session.as_mut(), dt, *goal, spec, &mut ()).unwrap();
            per.extend(
                out.predictor_cpu_us
                    .iter()
                    .zip(&out.estimator_cpu_us)
                    .map(|(p, e)| p + e),
            );
            est.extend(out.estimator_cpu_us);
            ok += usize::from(out.success);
        }
        (per, est, ok)
    };
    let (ad_per, ad_est, ad_ok) = adaptive_loops(0.02, &goals);
    let (khz_per, khz_est, khz_ok) = adaptive_loops(0.001, &goals[..5]);
    let nan = (f64::NAN, f64::NAN);
    let (pm, pp) = median_p99(&plan_us).unwrap_or(nan);
    let (rm, rp) = median_p99(&rest_us).unwrap_or(nan);
    let (mm, mp) = median_p99(&period_us).unwrap_or(nan);
    let (cm, cp) = median_p99(&period_cpu_us).unwrap_or(nan);
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "NaN".into());
    let us = |v: f64| format!("{v:.1}");
    let mut csv = Csv::new(&["quantity", "value", "unit", "target", "note"]);
    let mut row = |quantity: &str, value: String, unit: &str, target: &str, note: &str| {
        csv.row(&[quantity, &value, unit, target, note]);
    };
    let plans = format!(
        "{} plans from rest (20 study goals x 0.1/0.5/1 m/s), 6 pushes, each the median of 5 solves",
        plan_us.len()
    );
    row("plan_solve_median", us(pm), "us", "1000", &plans);
    row("plan_solve_p99", us(pp), "us", "", "same plans");
    row(
        "plan_rest_solve_median",
        us(rm),
        "us",
        "1000",
        "the same plans aimed at rest (the slide to rest in every prediction), timed alternately with them",
    );
    row("plan_rest_solve_p99", us(rp), "us", "", "same plans");
    let periods = format!(
        "{} re-plans of the dynamic predictor, rapier2d plant with mu x 0.8 and I_cm x 1.2, 20 goals at 1 m/s, period 0.02 s",
        period_us.len()
    );
    row("mpc_period_median", us(mm), "us", "100", &periods);
    row(
        "mpc_period_p99",
        us(mp),
        "us",
        "1000",
        "same periods (a stalled warm start runs one stage of the fallback search: a fresh Jacobian, or one starting guess)",
    );
    row(
        "mpc_period_cpu_median",
        us(cm),
        "us",
        "100",
        "the same periods' thread CPU time (what the predictor computes; wall time adds the waits of a shared machine)",
    );
    row("mpc_period_cpu_p99", us(cp), "us", "1000", "same");
    let (am, ap) = median_p99(&ad_per).unwrap_or(nan);
    let (em, ep) = median_p99(&ad_est).unwrap_or(nan);
    let adaptive = format!(
        "{} periods of adaptive MPC (estimator update and re-plan, thread CPU), rapier2d plant with one slippery foot, 20 goals at 1 m/s, period 0.02 s, {ad_ok} reached",
        ad_per.len()
    );
    row("adaptive_period_cpu_median", us(am), "us", "100", &adaptive);
    row(
        "adaptive_period_cpu_p99",
        us(ap),
        "us",
        "1000",
        "same periods",
    );
    row(
        "adaptive_estimator_cpu_median",
        us(em),
        "us",
        "",
        "the estimator alone in those periods",
    );
    row("adaptive_estimator_cpu_p99", us(ep), "us", "", "same");
    let (km, kp) = median_p99(&khz_per).unwrap_or(nan);
    let (kem, _) = median_p99(&khz_est).unwrap_or(nan);
    let khz = format!(
        "{} periods of the same adaptive MPC at 1 kHz (period 0.001 s), the first 5 goals, {khz_ok} reached; the estimator alone {kem:.1} us median",
        khz_per.len()
    );
    row(
        "adaptive_1khz_period_cpu_median",
        us(km),
        "us",
        "1000",
        &khz,
    );
    row(
        "adaptive_1khz_period_cpu_p99",
        us(kp),
        "us",
        "1000",
        "same periods",
    );
    row(
        "load_average_1min",
        load,
        "processes",
        "",
        "the machine's 1-minute load average at the end (2 cores)",
    );
    let reached_note = format!(
        "of the {} goals of those loops (final position within 20 mm, angle within 5 deg)",
        goals.len()
    );
    row(
        "mpc_goals_reached",
        reached.to_string(),
        "goals",
        "19",
        &reached_note,
    );
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("results/control_cost.csv");
    pushval::atomic::write_atomic(&path, csv.as_bytes()).unwrap();
    eprint!("{}", csv.text());
}

criterion_group!(benches, control);

fn main() {
    benches();
    cost_table();
    Criterion::default().configure_from_args().final_summary();
}
