use super::*;
use pushval_model::{Body, Initial, Push, Support, Switching, Vec2};
use pushval_model::{ModelError, Problem};

/// The push loop, as a session runs it: [`Stepping`] with one
/// [`advance`](Stepping::advance) per push.
fn run_pushes<W: PlateWorld>(
    world: &mut W,
    problem: &Problem,
    cfg: &StepLoop,
    start: W::State,
) -> Result<Stepped, ModelError> {
    let mut stepping = Stepping::new(world, problem, *cfg, start);
    for push in &problem.pushes {
        stepping.advance(push)?;
    }
    Ok(stepping.finish().1)
}

/// An object carried rigidly by the pusher: it moves at the commanded
/// velocity, turns at a constant rate `w` and rises linearly; every
/// support carries a fixed load and friction force.
struct Carried {
    w: f64,
    state: Plate,
    vel: [f64; 2],
    drives: usize,
    nan_at: Option<usize>,
    steps: usize,
    tail_calls: usize,
    segment_ends: Vec<f64>,
}

impl PlateWorld for Carried {
    type State = Plate;
    fn plate(&self, s: &Plate) -> Plate {
        *s
    }
    fn drive(&mut self, _: &Plate, velocity: [f64; 2], _h: f64) -> f64 {
        self.vel = velocity;
        self.drives += 1;
        // The first drive (the start) reports a large drift.
        if self.drives == 1 {
            100.0
        } else {
            1e-3 * self.drives as f64
        }
    }
    fn step(&mut self, h: f64, _t1: f64) -> Result<(), ModelError> {
        self.steps += 1;
        let s = &mut self.state;
        s.x += self.vel[0] * h;
        s.y += self.vel[1] * h;
        s.z += 0.5 * h;
        s.theta += self.w * h;
        s.omega = self.w;
        s.tilt = 0.01 * self.steps as f64;
        if self.nan_at == Some(self.steps) {
            s.x = f64::NAN;
        }
        Ok(())
    }
    fn state(&mut self, _: &Plate) -> Plate {
        self.state
    }
    fn support_forces(&mut self, _: &Plate, _h: f64) -> Result<Option<SupportForces>, ModelError> {
        Ok(Some(SupportForces {
            normal: vec![1.0, 2.0, 3.0],
            friction: Some(vec![0.5, 0.25, 0.0]),
        }))
    }
    fn slip(&self, _: &Plate, i: usize) -> Option<f64> {
        (i == 0).then_some(0.125 * self.steps as f64)
    }
    fn tail_step(&mut self, _: &Plate, _h: f64) -> Result<(), ModelError> {
        self.tail_calls += 1;
        Ok(())
    }
    fn end_segment(&mut self, tail_time: f64, _t: f64) -> Result<(), ModelError> {
        self.segment_ends.push(tail_time);
        Ok(())
    }
}

fn problem(pushes: Vec<Push>) -> Problem {
    let supports: Vec<Support> = [[-0.1, -0.1], [0.1, -0.1], [0.0, 0.1]]
        .iter()
        .map(|c| Support {
            position: Vec2::new(c[0], c[1]),
            friction: 1.0,
        })
        .collect();
    Problem {
        body: Body::new(1.0, 0.01, Vec2::new(-0.1, 0.0), &supports).unwrap(),
        limits: Default::default(),
        pushes,
        initial: Initial::default(),
        switching: Switching::Impulsive,
        sample_dt: 0.05,
        release: None,
    }
}

fn carried(w: f64, nan_at: Option<usize>) -> Carried {
    Carried {
        w,
        state: Plate {
            omega: w,
            ..Default::default()
        },
        vel: [0.0; 2],
        drives: 0,
        nan_at,
        steps: 0,
        tail_calls: 0,
        segment_ends: Vec::new(),
    }
}

const CFG: StepLoop = StepLoop {
    dt: 0.1,
    supports: 3,
    z_rest: 0.0,
    forces_every_step: true,
    tail: TailSteps::Floor,
    tail_weight: TailWeight::Time,
    clock: StepClock::FromStepStart,
};

/// 1.1 / 0.1 is 11.000000000000002 in floating point: still 11 steps;
/// 0.35 / 0.1 gives 4 steps of 0.0875. Times are contiguous and each
/// segment ends exactly at its end time.
#[test]
fn schedule_cuts_segments_into_equal_steps() {
    let p = problem(vec![
        Push {
            duration: 1.1,
            speed: 0.1,
            phi: 0.0,
        },
        Push {
            duration: 0.35,
            speed: 0.1,
            phi: 0.5,
        },
    ]);
    let mut w = carried(0.0, None);
    let start = w.state;
    let run = run_pushes(&mut w, &p, &CFG, start).unwrap();
    assert_eq!(run.steps, 15);
    assert_eq!(run.history.len(), 16);
    let h = &run.history;
    assert_eq!((h[0].t0, h[0].t1), (0.0, 0.0));
    // Contiguous to rounding: t0 = t_seg + k h, the previous t1 = t0' + h.
    assert_eq!(h[1].t0, 0.0);
    for k in 2..h.len() {
        assert!((h[k].t0 - h[k - 1].t1).abs() < 1e-15, "{k}");
    }
    assert_eq!(h[11].t1, 1.1);
    assert_eq!(h[11].segment, 0);
    assert_eq!(h[12].segment, 1);
    assert!((h[12].t1 - h[12].t0 - 0.0875).abs() < 1e-15);
    assert_eq!(h[15].t1, 1.1 + 0.35);
    // Tails: steps 8..11 of the first segment (floor(0.8 · 11) = 8) and
    // step 3 of the second (floor(0.8 · 4) = 3).
    assert_eq!(w.tail_calls, 3 + 1);
    assert_eq!(w.segment_ends.len(), 2);
    assert!((w.segment_ends[0] - 0.3).abs() < 1e-12);
    assert!((w.segment_ends[1] - 0.0875).abs() < 1e-12);
}

/// The pusher moves at the contact velocity turned by the mid-step yaw
/// θ + ω h/2; a carried object follows it exactly.
#[test]
fn pusher_velocity_is_set_at_the_mid_step_heading() {
    let (speed, phi, w0) = (0.2, 0.3, 1.5);
    let p = problem(vec![Push {
        duration: 0.1,
        speed,
        phi,
    }]);
    let mut w = carried(w0, None);
    let start = w.state;
    let run = run_pushes(&mut w, &p, &CFG, start).unwrap();
    assert_eq!(run.steps, 1);
    let a = phi + 0.5 * 0.1 * w0;
    let r = run.history[1];
    assert!((r.x - 0.1 * speed * a.cos()).abs() < 1e-15);
    assert!((r.y - 0.1 * speed * a.sin()).abs() < 1e-15);
}

/// Tail means of constants are the constants; the drift of the first
/// drive is left out; the smallest slip is over the tail only; the lift
/// and tilt are the largest over the run.
#[test]
fn tails_and_extremes() {
    let p = problem(vec![Push {
        duration: 1.0,
        speed: 0.1,
        phi: 0.0,
    }]);
    let mut w = carried(0.7, None);
    let start = w.state;
    let run = run_pushes(&mut w, &p, &CFG, start).unwrap();
    assert_eq!(run.steps, 10);
    assert!((run.segment_tail_omega[0] - 0.7).abs() < 1e-12);
    assert!(run.segment_tail_omega_std[0] < 1e-6);
    for (got, want) in run.segment_tail_loads[0].iter().zip([1.0, 2.0, 3.0]) {
        assert!((got - want).abs() < 1e-12);
    }
    for (got, want) in run.segment_tail_friction[0].iter().zip([0.5, 0.25, 0.0]) {
        assert!((got - want).abs() < 1e-12);
    }
    for (got, want) in run.loads.iter().zip([1.0, 2.0, 3.0]) {
        assert!((got - want).abs() < 1e-12);
    }
    assert_eq!(run.min_loads, vec![1.0, 2.0, 3.0]);
    // Tail steps are 9 and 10 (k = 8, 9): slip 0.125 · 9.
    assert_eq!(run.segment_tail_min_slip[0][0], 0.125 * 9.0);
    assert_eq!(run.segment_tail_min_slip[0][1], f64::INFINITY);
    assert!((run.max_joint_drift - 1e-3 * 10.0).abs() < 1e-15);
    assert!((run.max_lift - 0.5).abs() < 1e-12);
    assert!((run.max_tilt - 0.1).abs() < 1e-12);
}

#[test]
fn a_non_finite_state_stops_the_run() {
    let p = problem(vec![Push {
        duration: 1.0,
        speed: 0.1,
        phi: 0.0,
    }]);
    let mut w = carried(0.0, Some(4));
    let start = w.state;
    match run_pushes(&mut w, &p, &CFG, start) {
        Err(ModelError::NonFinite { t, step }) => {
            assert_eq!(step, 4);
            assert!((t - 0.4).abs() < 1e-12);
        }
        other => panic!("{other:?}"),
    }
}

/// The other conventions: the last `max(n / 5, 1)` steps as the tail,
/// weighted equally, and step ends counted from the segment's start.
#[test]
fn last_fifth_by_steps_from_the_segment_start() {
    let p = problem(vec![
        Push {
            duration: 1.1,
            speed: 0.1,
            phi: 0.0,
        },
        Push {
            duration: 0.35,
            speed: 0.1,
            phi: 0.5,
        },
    ]);
    let cfg = StepLoop {
        tail: TailSteps::LastFifth,
        tail_weight: TailWeight::Steps,
        clock: StepClock::FromSegmentStart,
        ..StepLoop::new(0.1, 3, 0.0)
    };
    let mut w = carried(0.7, None);
    let start = w.state;
    let run = run_pushes(&mut w, &p, &cfg, start).unwrap();
    // 11 steps: the last 2; 4 steps: the last 1 (4 / 5 = 0, at least 1).
    assert_eq!(w.segment_ends, vec![2.0, 1.0]);
    assert_eq!(w.tail_calls, 3);
    let h = 1.1 / 11.0;
    for k in 1..11 {
        assert_eq!(run.history[k].t1, 0.0 + k as f64 * h);
    }
    assert_eq!(run.history[11].t1, 1.1);
    assert!((run.segment_tail_omega[0] - 0.7).abs() < 1e-12);
    for (got, want) in run.segment_tail_loads[1].iter().zip([1.0, 2.0, 3.0]) {
        assert!((got - want).abs() < 1e-12);
    }
}

/// A session that applies fewer pushes than the start's schedule
/// announced ends with the run of the pushes applied: its run tail,
/// loads and samples are those of a run of that schedule, bit for bit.
#[test]
fn finish_gathers_the_run_of_the_pushes_applied() {
    let one = Push {
        duration: 1.0,
        speed: 0.1,
        phi: 0.0,
    };
    let two = Push {
        duration: 0.5,
        speed: 0.1,
        phi: 0.4,
    };
    let announced = problem(vec![one, two]);
    let mut w = carried(0.7, None);
    let start = w.state;
    let mut s = Stepping::new(&mut w, &announced, CFG, start);
    s.advance(&one).unwrap();
    assert_eq!(s.time(), 1.0);
    assert_eq!(s.steps(), 10);
    let state = s.engine_state();
    assert!((state.theta - 0.7).abs() < 1e-12 && state.omega == 0.7);
    let (_, got, applied) = s.finish();
    assert_eq!(applied.pushes, vec![one]);
    let mut w = carried(0.7, None);
    let start = w.state;
    let want = run_pushes(&mut w, &problem(vec![one]), &CFG, start).unwrap();
    assert_eq!(got, want);
    assert_eq!(
        got.trajectory(&applied),
        want.trajectory(&problem(vec![one]))
    );
}

/// A world's own step lengths are kept, the last one ending at the
/// segment's end; the layout is asked once per push applied.
#[test]
fn worlds_lay_out_their_own_steps() {
    struct Laid {
        inner: Carried,
        laid: usize,
    }
    impl PlateWorld for Laid {
        type State = Plate;
        fn plate(&self, s: &Plate) -> Plate {
            *s
        }
        fn segment_steps(&mut self, _: &Push, n: usize, h: f64) -> Option<StepLayout> {
            self.laid += 1;
            let mut l = vec![0.25 * h, 0.75 * h];
            l.extend(std::iter::repeat_n(h, n - 1));
            Some(StepLayout::Lengths(l))
        }
        fn drive(&mut self, s: &Plate, v: [f64; 2], h: f64) -> f64 {
            self.inner.drive(s, v, h)
        }
        fn step(&mut self, h: f64, t1: f64) -> Result<(), ModelError> {
            self.inner.step(h, t1)
        }
        fn state(&mut self, s: &Plate) -> Plate {
            self.inner.state(s)
        }
        fn support_forces(
            &mut self,
            _: &Plate,
            _: f64,
        ) -> Result<Option<SupportForces>, ModelError> {
            Ok(None)
        }
    }
    let push = Push {
        duration: 0.3,
        speed: 0.1,
        phi: 0.0,
    };
    let p = problem(vec![push, push]);
    let mut w = Laid {
        inner: carried(0.0, None),
        laid: 0,
    };
    let start = w.inner.state;
    let run = run_pushes(&mut w, &p, &CFG, start).unwrap();
    assert_eq!(w.laid, 2);
    // 3 steps of 0.1 each, the first cut in two: 4 per segment.
    assert_eq!(run.steps, 8);
    let h = &run.history;
    assert!((h[1].t1 - 0.025).abs() < 1e-15 && (h[2].t1 - 0.1).abs() < 1e-15);
    assert_eq!(h[4].t1, 0.3);
    assert_eq!(h[5].t0, 0.3);
    assert_eq!(h[8].t1, 0.6);
    assert!(run.contact.is_none());
}
