//! The stress sweep on a small grid, and near-singular physics: a support
//! that stops sliding, a push through the centre of friction, the contact on
//! top of a support, several steady states, zero-speed segments, a 1,000 s
//! horizon. Each is handled (no NaN, no panic) and reported, by the model
//! and by rapier2d.

use std::f64::consts::FRAC_PI_4;
use std::process::Command;

use approx::assert_relative_eq;
use pushval::stress::{self, Case, Solver, Status};
use pushval_model::{
    arc_advance, rotate, Body, DynamicModel, Initial, Integrator, Problem, Push, RootKind,
    SegmentDynamics, Simulator, Support, Trajectory, Vec2,
};
use pushval_rapier2d::{tail_mean_omega, DetailedEngine, EngineSettings, RapierSimulator};

use crate::common::*;

fn engine(dt: f64) -> RapierSimulator {
    RapierSimulator::new(EngineSettings {
        dt,
        ..Default::default()
    })
}

#[track_caller]
fn all_finite(tr: &Trajectory) {
    assert!(
        tr.samples.iter().all(|s| [s.t, s.x, s.y, s.theta, s.omega]
            .iter()
            .all(|v| v.is_finite())),
        "{} has a non-finite sample",
        tr.model
    );
}

// ---------------------------------------------------------------- the sweep

#[test]
fn small_grid_sorts_runs_into_ok_degraded_and_unstable() {
    let cases = stress::quick_grid();
    let out = stress::run_grid(&cases, None).unwrap();
    assert_eq!(out.len(), cases.len());
    let find = |solver: Solver, dt: f64, v: f64| {
        out.iter()
            .find(|o| {
                o.case.sweep == "map"
                    && o.case.solver == solver
                    && (solver == Solver::Adaptive || o.case.dt == dt)
                    && o.case.speed == v
            })
            .unwrap()
    };
    // Fine steps and the adaptive integrator are within tolerance.
    for v in [0.1, 10.0] {
        assert_eq!(find(Solver::Adaptive, 0.0, v).status, Status::Ok, "{v}");
    }
    assert_eq!(find(Solver::Rk4, 1e-3, 0.1).status, Status::Ok);
    assert_eq!(find(Solver::Engine, 1e-3, 0.1).status, Status::Ok);
    // dt = 0.1 s is far beyond the relaxation time at 0.1 m/s (τ ≈ 0.03 s).
    assert_ne!(find(Solver::Engine, 0.1, 0.1).status, Status::Ok);
    assert_ne!(find(Solver::Rk4, 0.1, 0.1).status, Status::Ok);
    // RK4 at dt = 0.1 s and v_c = 10 m/s: the inertial term's rate |k|/I_P
    // ≈ 40 /s puts dt |λ| ≈ 4 outside RK4's stability interval (≈ 2.8).
    let b = find(Solver::Rk4, 0.1, 10.0);
    assert_eq!(b.status, Status::Unstable, "{b:?}");
    let bu = b.blowup.as_ref().unwrap();
    assert!(bu.step >= 1 && bu.t > 0.0 && bu.t <= 2.0, "{bu:?}");
    assert!(b.position_err.is_none() && b.omega_rel_err.is_none());
    for o in &out {
        match o.status {
            Status::Unstable => assert!(o.blowup.is_some()),
            _ => {
                assert!(o.blowup.is_none());
                for e in [o.position_err, o.theta_err, o.omega_rel_err] {
                    assert!(e.unwrap().is_finite(), "{o:?}");
                }
            }
        }
    }
}

/// ω started beyond the outermost steady state of a push with
/// `p_c · n_φ > 0`: it runs away exponentially for every solver. Each run is
/// reported unstable with the step where it left the bound or the finite
/// numbers, and its row in the CSV carries no numbers for the errors.
#[test]
fn runaway_is_reported_unstable_with_its_step() {
    for solver in Solver::ALL {
        let c = Case {
            sweep: "runaway",
            phi: -2.6,
            speed: 8.0,
            omega0: 5.0,
            horizon: 30.0,
            ..Case::base(solver)
        };
        let seg = SegmentDynamics::new(&c.problem().body, &c.problem().pushes[0]);
        let roots = seg.steady_states();
        assert!(roots.iter().all(|r| r.omega < c.omega0), "{roots:?}");
        let o = stress::run_case(&c);
        assert_eq!(o.status, Status::Unstable, "{o:?}");
        let b = o.blowup.clone().unwrap();
        assert!(b.t > 0.0 && b.t < 1.0, "{solver:?}: {b:?}");
        if solver != Solver::Adaptive {
            assert!(b.step >= 1, "{solver:?}: {b:?}");
        }
        let csv = stress::csv(&[o]);
        let row = csv.lines().nth(1).unwrap();
        let cols: Vec<&str> = row.split(',').collect();
        assert_eq!(cols.len(), 15, "{row}");
        assert_eq!(cols[8], "unstable");
        assert!(cols[9..12].iter().all(|c| c.is_empty()), "{row}");
        assert!(!cols[12].is_empty() && !cols[14].is_empty(), "{row}");
    }
    // Left alone long enough, the state overflows: the model says where.
    let c = Case {
        phi: -2.6,
        speed: 8.0,
        omega0: 5.0,
        horizon: 40.0,
        ..Case::base(Solver::Rk4)
    };
    let e = DynamicModel {
        integrator: Integrator::Rk4 { dt: 1e-3 },
        skip_settled: false,
        ..Default::default()
    }
    .simulate(&c.problem())
    .unwrap_err();
    assert!(
        matches!(e, pushval_model::ModelError::Runaway { step, .. } if step > 10),
        "{e}"
    );
    // rapier2d does not follow the exponential runaway: its ω levels off
    // (about 2,000 rad/s here), finite but far beyond every steady state.
    let e = engine(1e-3).simulate(&c.problem()).unwrap();
    all_finite(&e);
    let w_end = e.samples.last().unwrap().omega;
    let seg = SegmentDynamics::new(&c.problem().body, &c.problem().pushes[0]);
    let w_max = seg
        .steady_states()
        .iter()
        .fold(0.0f64, |a, r| a.max(r.omega.abs()));
    assert!(w_end > 100.0 * w_max, "{w_end} vs {w_max}");
}

#[test]
fn stress_command_writes_finite_csvs_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("stress");
    let st = Command::new(env!("CARGO_BIN_EXE_pushval"))
        .args(["stress", "--quick", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["stability.csv", "stress.csv", "stress_map.svg"]);
    let svg = std::fs::read_to_string(out.join("stress_map.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("rapier2d"),
        "the map figure renders"
    );
    let text = std::fs::read_to_string(out.join("stress.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), stress::quick_grid().len() + 1);
    for line in &lines[1..] {
        let cols: Vec<&str> = line.split(',').collect();
        assert_eq!(cols.len(), 15, "{line}");
        assert!(["ok", "degraded", "unstable"].contains(&cols[8]), "{line}");
        for c in &cols[2..14] {
            if !c.is_empty() && *c != cols[8] {
                let v: f64 = c.parse().unwrap_or_else(|_| panic!("{c} in {line}"));
                assert!(v.is_finite(), "{line}");
            }
        }
    }
    for f in ["stress.csv", "stability.csv"] {
        let t = std::fs::read_to_string(out.join(f)).unwrap().to_lowercase();
        assert!(!t.contains("nan") && !t.contains("inf"), "{f}");
    }
    assert!(String::from_utf8_lossy(&st.stdout).contains("largest dt"));
}

// ------------------------------------------------------ near-singular physics

/// The model reports the pivot (RootKind::Pivot, assumptions.sticking); the
/// engine, whose friction at the stuck support chatters, turns at the same
/// ω = v / |r| on average and stays finite, its slowest support nearly at rest.
#[test]
fn pivot_is_reported_by_the_model_and_reproduced_by_the_engine() {
    let v = 0.2;
    let p = one_push(pivot_body(), 2.0, v, 0.0);
    let seg = SegmentDynamics::new(&p.body, &p.pushes[0]);
    let roots = seg.steady_states();
    assert!(matches!(
        roots[..],
        [pushval_model::SteadyState {
            kind: RootKind::Pivot { support: 3, .. },
            ..
        }]
    ));
    let w_p = v / 0.25;
    let tr = run(&adaptive(1e-10, true), &p);
    all_finite(&tr);
    assert_eq!(tr.assumptions.sticking.unwrap().support, Some(3));
    let er = engine(1e-3).run(&p).unwrap();
    all_finite(&er.trajectory);
    let w = tail_mean_omega(&p, &er.trajectory, 0.2)[0].unwrap();
    // Friction at the stuck support is applied explicitly and chatters, so
    // the engine turns somewhat slower than the pivot rate (8 % at 1 ms).
    assert!((w - w_p).abs() < 0.15 * w_p, "engine {w}, pivot {w_p}");
    assert!(
        er.trajectory.assumptions.min_support_speed < 1e-2 * v,
        "{}",
        er.trajectory.assumptions.min_support_speed
    );
    // RK4 handles the jump in ω̇ too.
    let rk = run(
        &DynamicModel {
            integrator: Integrator::Rk4 { dt: 1e-3 },
            ..Default::default()
        },
        &p,
    );
    all_finite(&rk);
    assert!(rk.assumptions.sticking.is_some());
}

/// Pushing through the centre of friction of the symmetric plate: ω* = 0;
/// the engine does not turn it either (up to rounding).
#[test]
fn push_through_the_centre_of_friction_does_not_turn_the_engine() {
    let p = one_push(paper_plate(), 2.0, 0.5, FRAC_PI_4);
    let tr = engine(1e-3).simulate(&p).unwrap();
    for s in &tr.samples {
        assert!(s.theta.abs() < 1e-9 && s.omega.abs() < 1e-9, "{s:?}");
    }
    let end = tr.samples.last().unwrap();
    assert_relative_eq!(end.x, 1.0 * FRAC_PI_4.cos(), max_relative = 1e-9);
}

/// A support right under the contact point: its lever arm about the contact
/// is zero, it always slides at the pusher's velocity, and contributes no
/// moment. Model and engine agree, with no NaN, also when the pusher stops.
#[test]
fn contact_on_top_of_a_support() {
    let a = 0.125;
    let mut sup: Vec<Support> = [(-a, -a), (a, -a), (a, a), (-a, a)]
        .iter()
        .map(|&(x, y)| Support {
            position: Vec2::new(x, y),
            friction: 0.5 * G / 4.0,
        })
        .collect();
    sup[0].friction *= 3.0;
    let body = Body::new(1.0, 0.25f64.powi(2) / 6.0, Vec2::new(-a, -a), &sup).unwrap();
    let mut p = one_push(body, 1.5, 0.3, PHI);
    p.pushes.push(Push {
        duration: 0.5,
        speed: 0.0,
        phi: PHI,
    });
    let seg = SegmentDynamics::new(&p.body, &p.pushes[0]);
    let roots = seg.steady_states();
    assert_eq!(roots.len(), 1);
    assert_eq!(roots[0].kind, RootKind::Stable, "{roots:?}");
    let m = run(&adaptive(1e-10, true), &p);
    all_finite(&m);
    assert!(m.assumptions.sticking.is_none());
    let e = engine(1e-3).simulate(&p).unwrap();
    all_finite(&e);
    let (dp, dth) = max_diff(&m, &e);
    assert!(dp < 5e-3 && dth < 1e-2, "{dp} {dth}");
}

/// Several steady states (`p_c · n_φ > 0` at high speed): the model lists
/// them with alternating stability; started between two, model and engine
/// settle on the same stable one, whichever side they start from.
#[test]
fn several_steady_states_model_and_engine_pick_the_same_attractor() {
    let body = paper_plate();
    let phi = -2.6;
    let (v, seg, roots) = [0.5, 1.0, 2.0, 4.0, 8.0]
        .into_iter()
        .map(|v| {
            let push = Push {
                duration: 1.0,
                speed: v,
                phi,
            };
            let seg = SegmentDynamics::new(&body, &push);
            let roots = seg.steady_states();
            (v, seg, roots)
        })
        .find(|(_, _, r)| r.len() >= 3)
        .expect("some speed gives several steady states");
    for pair in roots.windows(2) {
        assert_ne!(pair[0].is_stable(), pair[1].is_stable());
    }
    let unstable: Vec<f64> = roots
        .iter()
        .filter(|r| !r.is_stable())
        .map(|r| r.omega)
        .collect();
    let mut checked = 0;
    for &wu in &unstable {
        for side in [-1.0, 1.0] {
            let w0 = wu + side * 0.05 * (1.0 + wu.abs());
            // Beyond the outermost unstable root ω runs away (tested above).
            let Some(target) = seg.attractor(&roots, w0) else {
                continue;
            };
            checked += 1;
            assert!(target.is_stable());
            // Far from the attractor the relaxation is slow (ω̇ is small near
            // the unstable root): give it 30 s.
            let mut p = one_push(body.clone(), 30.0, v, phi);
            p.initial.omega = w0;
            let m = run(&adaptive(1e-10, true), &p);
            all_finite(&m);
            let wm = m.samples.last().unwrap().omega;
            // ω moves monotonically from the start to the attractor.
            let dir = (target.omega - w0).signum();
            for pair in m.samples.windows(2) {
                assert!(
                    (pair[1].omega - pair[0].omega) * dir >= -1e-9,
                    "start {w0}: not monotone"
                );
            }
            assert!(
                (wm - target.omega).abs() < 1e-6 * (1.0 + target.omega.abs()),
                "start {w0}: model ends at {wm}, attractor {}",
                target.omega
            );
            let e = engine(1e-3).simulate(&p).unwrap();
            let we = tail_mean_omega(&p, &e, 0.2)[0].unwrap();
            assert!(
                (we - wm).abs() < 0.01 * (1.0 + wm.abs()),
                "start {w0}: engine {we}, model {wm}"
            );
        }
    }
    assert!(checked >= 2, "{roots:?}");
}

/// A schedule with zero-speed segments between pushes: the contact is held,
/// friction stops the rotation in finite time; model and engine agree.
#[test]
fn zero_speed_segments_in_model_and_engine() {
    let mut p = one_push(paper_plate(), 0.5, 0.8, PHI);
    p.pushes.extend([
        Push {
            duration: 0.5,
            speed: 0.0,
            phi: PHI,
        },
        Push {
            duration: 0.5,
            speed: 0.8,
            phi: PHI - 0.4,
        },
        Push {
            duration: 0.3,
            speed: 0.0,
            phi: 0.0,
        },
    ]);
    let m = run(&adaptive(1e-10, true), &p);
    all_finite(&m);
    // At rest at the end of each zero-speed segment.
    assert_eq!(m.segments[1].omega_end, 0.0);
    assert_eq!(m.segments[3].omega_end, 0.0);
    let e = engine(2.5e-4).simulate(&p).unwrap();
    all_finite(&e);
    let (dp, dth) = max_diff(&m, &e);
    assert!(dp < 5e-3 && dth < 1e-2, "{dp} {dth}");
    // The engine's explicit Coulomb force chatters about ω = 0 once stopped.
    let w_end = e.samples.last().unwrap().omega;
    assert!(w_end.abs() < 1e-2, "{w_end}");
}

/// 1,000 s started on the steady state: the object turns hundreds of radians.
/// Unwrapped θ keeps its precision — the integrated model stays on the
/// closed-form steady arc (θ = θ₀ + ω* t, the contact point on its circle),
/// and the engine's unwrapped θ equals the sum of its steps' ω h.
#[test]
fn thousand_second_horizon_keeps_theta_precise() {
    let t_end = 1000.0;
    let v = 0.2;
    let body = paper_plate();
    let push = Push {
        duration: t_end,
        speed: v,
        phi: PHI,
    };
    let ws = SegmentDynamics::new(&body, &push).steady_states()[0].omega;
    let initial = Initial {
        theta: 0.3,
        omega: ws,
        position: Vec2::new(1.0, -2.0),
        from_rest: false,
        velocity: pushval_model::Vec2::zeros(),
    };
    let p = Problem {
        sample_dt: 1.0,
        ..problem(
            body.clone(),
            vec![push],
            initial,
            pushval_model::Switching::Impulsive,
        )
    };
    assert!((ws * t_end).abs() > 100.0, "{ws}");
    let c0 = initial.position + rotate(initial.theta, &body.contact());
    let closed = |t: f64| {
        let (c, th) = arc_advance(c0, initial.theta, ws, &push.velocity(), t);
        (c - rotate(th, &body.contact()), th)
    };
    for skip in [true, false] {
        let tr = run(&adaptive(1e-10, skip), &p);
        all_finite(&tr);
        let mut worst = (0.0f64, 0.0f64);
        for s in &tr.samples {
            let (x, th) = closed(s.t);
            worst.0 = worst.0.max((Vec2::new(s.x, s.y) - x).norm());
            worst.1 = worst.1.max((s.theta - th).abs());
        }
        let (dp, dth) = worst;
        // Relative to the angle turned: a few ulps when the closed form is
        // followed, the integrator's tolerance when integrated.
        let lim = if skip { 1e-10 } else { 1e-6 };
        assert!(dp < lim && dth < lim, "skip {skip}: {dp:e} m, {dth:e} rad");
    }
    let er = engine(1e-2).run(&p).unwrap();
    all_finite(&er.trajectory);
    let turned: f64 = er
        .history
        .iter()
        .skip(1)
        .map(|r| (r.t1 - r.t0) * r.omega)
        .sum();
    let end = er.history.last().unwrap();
    // Not to rounding: the joint's position correction turns the body a
    // little beyond Σ ω h. But no 2π slip of the unwrapping over ~35 turns.
    assert!(
        (end.theta - initial.theta - turned).abs() < 1e-5 * turned.abs(),
        "{} vs {turned}",
        end.theta - initial.theta
    );
    // And it turned at the steady rate.
    assert_relative_eq!(turned / t_end, ws, max_relative = 1e-3);
}
