"""Tests of the adapter kit `pushval.adapter` (standard library only).

Run from the repository root: ``python3 -m unittest discover -s python/tests``.

Expected values come from the protocol's text (header, framing, step counts,
times) and from mechanics worked by hand (the switch impulse, a push through
the centre), never from the kit's own output.
"""

import copy
import io
import json
import math
import os
import subprocess
import sys
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "python"))

from pushval import adapter  # noqa: E402
from pushval.adapter import AdapterError, Engine, State, parse_problem, serve, simulate  # noqa: E402

# A 2 kg plate, I_cm 0.01 kg m², pushed at (0, -0.1) from its centre of
# mass, which sits at (0.5, 0.5) in the file's frame; two segments.
DOC = {
    "format": "pushval-problem/1",
    "engine": "test",
    "dt": 0.03,
    "object": {
        "mass": 2.0,
        "inertia_cm": 0.01,
        "center_of_mass": [0.5, 0.5],
        "polygon": [[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]],
    },
    "supports": [
        {"point": [0.4, 0.4], "mu": 0.5, "normal_force": 9.81},
        {"point": [0.6, 0.6], "mu": 0.25, "normal_force": 9.81},
    ],
    "contact": {"point": [0.5, 0.4]},
    "initial": {"position": [1.0, 2.0], "theta": 0.1, "omega": 0.0, "from_rest": True},
    "pushes": [
        {"t_start": 0.0, "duration": 0.25, "speed": 0.5, "phi": 0.0},
        {"t_start": 0.25, "duration": 0.1, "speed": 0.5, "phi": math.pi / 2},
    ],
    "sample_dt": 0.1,
    "gravity": 9.81,
    "options": {"dt": 0.03},
}


def doc(**changes):
    """DOC with top-level keys replaced (a v2 document with `switching`)."""
    d = copy.deepcopy(DOC)
    d.update(changes)
    return d


class Recorder(Engine):
    """Records what the kit asks; the state is (t, 0, 0, 0) so rows show
    the kit's times. Fails on a push of speed 0.7 (a failing run)."""

    name = "recorder"

    def __init__(self, args=None):
        super().__init__(args)
        self.calls = []

    def reset(self, problem):
        self.calls.append(("reset", problem.engine))
        self.t = 0.0
        return State(0.0, 0.0, 0.0, 0.0)

    def switch(self, before, after):
        self.calls.append(("switch", before.index, after.index))

    def step(self, push, dt):
        if push.speed == 0.7:
            raise AdapterError("no licence for speed 0.7")
        self.calls.append(("step", push.index, dt))
        self.t += dt
        return State(self.t, 0.0, 0.0, 0.0)

    def close(self):
        self.calls.append(("close",))


class ParseTest(unittest.TestCase):
    def test_offsets_friction_and_inertia(self):
        p = parse_problem(json.dumps(DOC))
        self.assertEqual(p.version, 1)
        self.assertEqual(p.switching, "impulsive")
        self.assertEqual(p.supports[0].offset, (-0.09999999999999998, -0.09999999999999998))
        self.assertAlmostEqual(p.supports[1].friction, 0.25 * 9.81)
        self.assertAlmostEqual(p.contact_offset[0], 0.0)
        self.assertAlmostEqual(p.contact_offset[1], -0.1)
        # I_P = I_cm + m |r_c|^2 = 0.01 + 2 * 0.01
        self.assertAlmostEqual(p.inertia_contact, 0.03)
        self.assertEqual(p.options, {"dt": 0.03})

    def test_version_2_fields(self):
        p = parse_problem(doc(format="pushval-problem/2", switching="continuous", limits={"max_rows": 7}))
        self.assertEqual((p.version, p.switching, p.limits.max_rows, p.limits.max_bytes), (2, "continuous", 7, None))

    def test_errors_name_the_key(self):
        bad = doc()
        bad["supports"][1]["mu"] = -1
        with self.assertRaisesRegex(adapter.ProblemError, r"supports\[1\]\.mu"):
            parse_problem(bad)
        with self.assertRaisesRegex(adapter.ProblemError, r"`format`"):
            parse_problem(doc(format="pushval-problem/9"))
        with self.assertRaisesRegex(adapter.ProblemError, r"switching"):
            parse_problem(doc(format="pushval-problem/2", switching="sticky"))
        with self.assertRaisesRegex(adapter.ProblemError, r"not JSON"):
            parse_problem("{")
        missing = doc()
        del missing["initial"]["from_rest"]
        with self.assertRaisesRegex(adapter.ProblemError, r"initial\.from_rest` is missing"):
            parse_problem(missing)

    def test_sample_times(self):
        # 0.35 s at 0.1 s: the grid, then the end.
        times = parse_problem(DOC).sample_times()
        self.assertEqual(len(times), 5)
        for got, want in zip(times, [0.0, 0.1, 0.2, 0.3, 0.35]):
            self.assertAlmostEqual(got, want, places=12)
        # 0.4 s: the last grid point is the end itself.
        d = doc(pushes=[{"t_start": 0.0, "duration": 0.4, "speed": 1.0, "phi": 0.0}])
        self.assertEqual(parse_problem(d).sample_times()[-1], 0.4)


class SwitchingTest(unittest.TestCase):
    def test_impulsive_start_from_rest(self):
        # Contact r_c = (0, -b) pushed along +x at s from rest: the angular
        # momentum about the contact point stays 0, so
        # I_cm w - m b (s - w b) = 0, w = m b s / (I_cm + m b^2).
        p = parse_problem(DOC)
        self.assertAlmostEqual(p.start_omega(), 2 * 0.1 * 0.5 / (0.01 + 2 * 0.01), places=12)

    def test_impulsive_switch_keeps_the_momentum_about_the_contact(self):
        p = parse_problem(DOC)
        w = p.omega_after_switch(p.pushes[0], p.pushes[1], 1.0)
        # Before: H = I_P w - m (r_c x v) with r_c x v = (0)(0) - (-0.1)(0.5) = 0.05.
        h_before = 0.03 * 1.0 - 2 * 0.05
        # After (v along +y): r_c x v = 0 * 0.5 - (-0.1) * 0 = 0, so H = I_P w'.
        self.assertAlmostEqual(w, h_before / 0.03, places=12)

    def test_continuous_keeps_omega(self):
        p = parse_problem(doc(format="pushval-problem/2", switching="continuous"))
        self.assertEqual(p.omega_after_switch(p.pushes[0], p.pushes[1], 1.25), 1.25)
        self.assertEqual(p.start_omega(), 0.0)

    def test_an_engine_refuses_a_rule_it_does_not_follow(self):
        class Impulsive(Recorder):
            switching_rules = ("impulsive",)

        p = parse_problem(doc(format="pushval-problem/2", switching="continuous"))
        with self.assertRaisesRegex(AdapterError, "continuous switching"):
            simulate(Impulsive(), p)


class ScheduleTest(unittest.TestCase):
    def test_ceil_cuts_segments_into_steps_no_longer_than_dt(self):
        e = Recorder()
        run = simulate(e, parse_problem(DOC))
        # 0.25 / 0.03 = 8.33 -> 9 steps; 0.1 / 0.03 = 3.33 -> 4 steps.
        steps = [c for c in e.calls if c[0] == "step"]
        self.assertEqual([c[1] for c in steps], [0] * 9 + [1] * 4)
        for c in steps[:9]:
            self.assertAlmostEqual(c[2], 0.25 / 9, places=15)
        for c in steps[9:]:
            self.assertAlmostEqual(c[2], 0.1 / 4, places=15)
        self.assertEqual(run.steps, 13)
        # One switch, between the segments, before the second's first step;
        # close after the last step.
        self.assertEqual(e.calls[0], ("reset", "test"))
        self.assertEqual(e.calls[10], ("switch", 0, 1))
        self.assertEqual(e.calls[-1], ("close",))
        # Row times: t = 0, then t_start + j h, each segment's last exactly
        # at its end.
        times = [r[0] for r in run.rows]
        self.assertEqual(times[0], 0.0)
        self.assertEqual(times[9], 0.25)
        self.assertEqual(times[13], 0.25 + 0.1)
        self.assertAlmostEqual(times[5], 5 * 0.25 / 9, places=15)
        self.assertTrue(all(b > a for a, b in zip(times, times[1:])))

    def test_a_segment_ends_exactly_at_its_end_time(self):
        # 1.0 s in 49 steps: 49 * (1.0 / 49) is 0.9999999999999999 in
        # floating point; the row still lands on the switch at 1.0 s.
        d = doc(dt=1.0 / 49, pushes=[{"t_start": 0.0, "duration": 1.0, "speed": 0.5, "phi": 0.0},
                                     {"t_start": 1.0, "duration": 0.5, "speed": 0.5, "phi": 0.0}])
        times = [r[0] for r in simulate(Recorder(), parse_problem(d)).rows]
        self.assertEqual(times[49], 1.0)
        self.assertEqual(times[-1], 1.5)

    def test_round_takes_the_nearest_count(self):
        class Rounding(Recorder):
            step_rule = "round"

        run = simulate(Rounding(), parse_problem(DOC))
        self.assertEqual(run.steps, 8 + 3)

    def test_a_non_finite_state_fails_naming_the_time(self):
        class Diverging(Recorder):
            def step(self, push, dt):
                super().step(push, dt)
                return State(math.nan, 0.0, 0.0, 0.0)

        with self.assertRaisesRegex(AdapterError, r"t = 0\.0277.* not finite"):
            simulate(Diverging(), parse_problem(DOC))


def answers(text):
    """A session's output split into answers (lists of lines, framing
    included)."""
    out, cur = [], []
    for line in text.splitlines():
        cur.append(line)
        if line.split(" ")[0] in ("#end", "#ok", "#error"):
            out.append(cur)
            cur = []
    assert not cur, f"unframed output at the end: {cur}"
    return out


class ServeTest(unittest.TestCase):
    def serve(self, engine, text, session):
        out, err = io.StringIO(), io.StringIO()
        status = serve(engine, session, io.StringIO(text), out, err)
        return status, out.getvalue(), err.getvalue()

    def test_one_shot_writes_the_header_and_a_row_per_step(self):
        status, out, _ = self.serve(Recorder(), json.dumps(DOC, indent=2), session=False)
        self.assertEqual(status, 0)
        lines = out.splitlines()
        self.assertEqual(lines[0], "t,x,y,theta,omega")
        self.assertEqual(len(lines), 1 + 1 + 13)
        self.assertEqual(lines[1], "0.0,0.0,0.0,0.0,0.0")
        self.assertFalse(any(line.startswith("#") for line in lines))

    def test_one_shot_failures_write_nothing(self):
        status, out, err = self.serve(Recorder(), "{", session=False)
        self.assertEqual((status, out), (2, ""))
        self.assertIn("not JSON", err)
        d = doc(pushes=[{"t_start": 0.0, "duration": 0.1, "speed": 0.7, "phi": 0.0}])
        status, out, err = self.serve(Recorder(), json.dumps(d), session=False)
        self.assertEqual((status, out), (1, ""))
        self.assertIn("no licence for speed 0.7", err)

    def test_session_frames_answers_and_goes_on_after_an_error(self):
        failing = doc(pushes=[{"t_start": 0.0, "duration": 0.1, "speed": 0.7, "phi": 0.0}])
        text = "\n".join([json.dumps(DOC), "not json", "", json.dumps(failing), json.dumps(DOC)]) + "\n"
        e = Recorder()
        status, out, _ = self.serve(e, text, session=True)
        self.assertEqual(status, 0)
        got = answers(out)
        self.assertEqual(len(got), 4)
        for a in (got[0], got[3]):
            self.assertEqual(a[0], "t,x,y,theta,omega")
            self.assertEqual(a[-1], "#end")
            self.assertEqual(len(a), 1 + 14 + 1)
        self.assertEqual(len(got[1]), 1)
        self.assertRegex(got[1][0], r"^#error .*not JSON")
        self.assertEqual(got[2], ["#error problem 3: no licence for speed 0.7"])
        # One engine for the whole session, closed after every problem.
        self.assertEqual([c for c in e.calls if c[0] != "step"].count(("close",)), 3)

    def test_session_answers_close_with_the_request_number(self):
        failing = doc(pushes=[{"t_start": 0.0, "duration": 0.1, "speed": 0.7, "phi": 0.0}])
        docs = [dict(DOC, request=7), dict(failing, request=8), {"request": 9, "op": "finish"}]
        status, out, _ = self.serve(Recorder(), "\n".join(map(json.dumps, docs)) + "\n", session=True)
        self.assertEqual(status, 0)
        got = answers(out)
        self.assertEqual(got[0][-1], "#end 7")
        self.assertEqual(got[1], ["#error 8 request 8: no licence for speed 0.7"])
        self.assertRegex(got[2][0], r"^#error 9 request 9: the document: `finish` without a `start`")

    def stepped(self, rows):
        """A protocol 3 session of DOC's two pushes on a Recorder."""
        problem = {k: v for k, v in doc(format="pushval-problem/2", switching="impulsive").items() if k != "pushes"}
        docs = [{"request": 1, "op": "start", "rows": rows, "problem": problem}]
        for i, p in enumerate(DOC["pushes"]):
            docs.append({"request": 2 + i, "op": "advance", "speed": p["speed"], "phi": p["phi"], "duration": p["duration"]})
        docs.append({"request": 4, "op": "finish"})
        e = Recorder()
        status, out, _ = self.serve(e, "\n".join(map(json.dumps, docs)) + "\n", session=True)
        self.assertEqual(status, 0)
        return e, answers(out)

    def test_protocol_3_steps_with_reset_switch_and_step(self):
        e, got = self.stepped("steps")
        self.assertEqual([a[-1] for a in got], ["#ok 1", "#end 2", "#end 3", "#end 4"])
        self.assertEqual(got[0], ["#ok 1"])
        # The header once, the row at t = 0, then ceil(0.25 / 0.03) = 9
        # rows; the second push ceil(0.1 / 0.03) = 4 rows, no header.
        self.assertEqual(got[1][0], "t,x,y,theta,omega")
        self.assertEqual(len(got[1]), 1 + 1 + 9 + 1)
        self.assertEqual(len(got[2]), 4 + 1)
        self.assertEqual(got[3], ["#end 4"])
        self.assertEqual(float(got[1][-2].split(",")[0]), 0.25)
        self.assertEqual(float(got[2][-2].split(",")[0]), 0.25 + 0.1)
        calls = [c if c[0] != "step" else c[:2] for c in e.calls]
        self.assertEqual(
            calls,
            [("reset", "test")] + [("step", 0)] * 9 + [("switch", 0, 1)] + [("step", 1)] * 4 + [("close",)],
        )
        # The same rows as a one-shot run of the whole document.
        _, one, _ = self.serve(Recorder(), json.dumps(DOC), session=False)
        self.assertEqual(one.splitlines(), got[1][:-1] + got[2][:-1])

    def test_protocol_3_sample_rows(self):
        _, got = self.stepped("samples")
        rows = [list(map(float, l.split(","))) for a in got[1:3] for l in a[:-1] if not l.startswith("t,")]
        # The sample times 0, 0.1, 0.2, each push's end 0.25 and 0.35, and
        # 0.3 (sample_dt 0.1).
        self.assertEqual([r[0] for r in rows], [0.0, 0.1, 0.2, 0.25, 0.30000000000000004, 0.35])
        # The recorder's x is the time: interpolated, x is the row's time.
        for r in rows:
            self.assertAlmostEqual(r[1], r[0], places=12)
        # The steps each interval took: 9 steps of 0.25/9 s hold 0.1 and 0.2
        # after 4 and 8 steps (ceil(0.1 / 0.02778) = 4), then 1 to 0.25;
        # 4 steps of 0.025 s reach 0.3 after 2 and 0.35 after 2 more.
        self.assertEqual(got[1][0], "t,x,y,theta,omega,steps")
        self.assertEqual([len(r) for r in rows], [6] * 6)
        self.assertEqual([r[5] for r in rows], [0, 4, 4, 1, 2, 2])

    def test_compact_rows_are_little_endian_binary64_in_hex(self):
        # 1.5 is 0x3FF8000000000000: little-endian digits 000000000000f83f.
        self.assertEqual(adapter._compact([(0.0, 1.5)]), "!" + "0" * 16 + "000000000000f83f\n")

    def test_limits_fall_back_to_sample_rows_then_fail(self):
        d = doc(format="pushval-problem/2", limits={"max_rows": 6})
        status, out, err = self.serve(Recorder(), json.dumps(d), session=False)
        self.assertEqual(status, 0)
        lines = out.splitlines()
        # The five sample times 0, 0.1, 0.2, 0.3, 0.35 instead of 14 rows.
        self.assertEqual(len(lines), 1 + 5)
        self.assertEqual([float(l.split(",")[0]) for l in lines[1:]][-1], 0.35)
        # The recorder's x is the time, so interpolated x equals the sample time.
        for line in lines[1:]:
            t, x = map(float, line.split(",")[:2])
            self.assertAlmostEqual(x, t, places=12)
        self.assertIn("sample times instead", err)
        d = doc(format="pushval-problem/2", limits={"max_rows": 4})
        status, out, err = self.serve(Recorder(), json.dumps(d), session=True)
        self.assertRegex(out, r"^#error .*limits.*5 rows \(the limit is 4\)\n$")
        d = doc(format="pushval-problem/2", limits={"max_bytes": 40})
        status, out, err = self.serve(Recorder(), json.dumps(d), session=True)
        self.assertRegex(out, r"^#error .*bytes \(the limit is 40\)\n$")


class Loaded(Recorder):
    """The recorder with extra columns: load_1, load_2 and rise, the loads
    being (step number, -step number) and the rise the time."""

    def extra_columns(self, problem):
        return tuple(f"load_{i + 1}" for i in range(len(problem.supports))) + ("rise",)

    def reset(self, problem):
        self.k = 0
        return super().reset(problem)

    def step(self, push, dt):
        self.k += 1
        return super().step(push, dt)

    def extras(self):
        return (float(self.k), -float(self.k), self.t)


class ExtraColumnsTest(unittest.TestCase):
    def serve(self, engine, d):
        out, err = io.StringIO(), io.StringIO()
        status = serve(engine, False, io.StringIO(json.dumps(d)), out, err)
        return status, out.getvalue(), err.getvalue()

    def test_extra_columns_follow_omega_on_every_row(self):
        status, out, err = self.serve(Loaded(), DOC)
        self.assertEqual(status, 0, err)
        lines = out.splitlines()
        self.assertEqual(lines[0], "t,x,y,theta,omega,load_1,load_2,rise")
        self.assertEqual(len(lines), 1 + 1 + 13)
        self.assertEqual(lines[1], "0.0,0.0,0.0,0.0,0.0,0.0,-0.0,0.0")
        for k, line in enumerate(lines[1:]):
            v = [float(x) for x in line.split(",")]
            self.assertEqual(len(v), 8)
            self.assertEqual((v[5], v[6]), (k, -k))
            # The recorder's x and the rise are both the engine's clock.
            self.assertEqual(v[7], v[1])

    def test_sample_rows_carry_the_holding_steps_extras(self):
        d = doc(format="pushval-problem/2", limits={"max_rows": 6})
        status, out, err = self.serve(Loaded(), d)
        self.assertEqual(status, 0, err)
        lines = out.splitlines()
        self.assertEqual(lines[0], "t,x,y,theta,omega,load_1,load_2,rise")
        # Sample 0.1 s lies in the 4th step of 0.25/9 s (ends at 0.111 s).
        v = [float(x) for x in lines[2].split(",")]
        self.assertEqual(v[0], 0.1)
        self.assertEqual(v[5], 4.0)
        self.assertAlmostEqual(v[7], 4 * 0.25 / 9, places=12)

    def test_wrong_or_non_finite_extras_fail_naming_the_column(self):
        class Short(Loaded):
            def extras(self):
                return (1.0,)

        class Nan(Loaded):
            def extras(self):
                return (1.0, 2.0, math.nan)

        with self.assertRaisesRegex(AdapterError, r"1 numbers for 3 columns \(load_1,load_2,rise\)"):
            simulate(Short(), parse_problem(DOC))
        with self.assertRaisesRegex(AdapterError, r"rise at t = 0\.0 s is not finite"):
            simulate(Nan(), parse_problem(DOC))


class ProcessTest(unittest.TestCase):
    """`main` in a real process: the command line and output hygiene."""

    SCRIPT = (
        "import sys\n"
        "from pushval.adapter import Engine, State, main\n"
        "class Noisy(Engine):\n"
        "    def reset(self, problem):\n"
        "        print('a banner a library prints')\n"
        "        return State(0.0, 0.0, 0.0, 0.0)\n"
        "    def step(self, push, dt):\n"
        "        return State(0.0, 0.0, 0.0, 0.0)\n"
        "main(Noisy)\n"
    )

    def run_script(self, args, stdin):
        env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
        return subprocess.run(
            [sys.executable, "-c", self.SCRIPT, *args],
            input=stdin, capture_output=True, text=True, env=env, timeout=60,
        )

    def test_prints_go_to_stderr_and_session_is_chosen_by_the_argument(self):
        one = self.run_script([], json.dumps(DOC, indent=1))
        self.assertEqual(one.returncode, 0, one.stderr)
        self.assertTrue(one.stdout.startswith("t,x,y,theta,omega\n"), one.stdout[:80])
        self.assertNotIn("#end", one.stdout)
        self.assertIn("a banner", one.stderr)
        two = self.run_script(["--session"], json.dumps(DOC) + "\n" + json.dumps(DOC) + "\n")
        self.assertEqual(two.returncode, 0, two.stderr)
        self.assertEqual([a[-1] for a in answers(two.stdout)], ["#end", "#end"])
        self.assertNotIn("banner", two.stdout)

    def test_an_unknown_argument_exits_2(self):
        bad = self.run_script(["--frobnicate"], "")
        self.assertEqual(bad.returncode, 2)
        self.assertIn("--frobnicate", bad.stderr)


class TemplateTest(unittest.TestCase):
    """The `pushval init` adapter (assets/init/adapter.py) on a push whose
    answer is known: a symmetric plate pushed at the middle of an edge,
    straight through its centre, translates without turning at the pusher's
    speed (by symmetry the friction forces have no moment about the line of
    push)."""

    def test_a_push_through_the_centre_translates(self):
        sys.path.insert(0, os.path.join(ROOT, "assets", "init"))
        try:
            import importlib

            template = importlib.import_module("adapter")
        finally:
            sys.path.pop(0)
        a = 0.1
        d = doc(
            dt=0.001,
            object={"mass": 1.0, "inertia_cm": (2 * a) ** 2 / 6, "center_of_mass": [0.0, 0.0],
                    "polygon": [[-a, -a], [a, -a], [a, a], [-a, a]]},
            supports=[{"point": p, "mu": 0.5, "normal_force": 9.81 / 4} for p in [[-a, -a], [a, -a], [a, a], [-a, a]]],
            contact={"point": [-a, 0.0]},
            initial={"position": [0.0, 0.0], "theta": 0.0, "omega": 0.0, "from_rest": True},
            pushes=[{"t_start": 0.0, "duration": 0.5, "speed": 0.4, "phi": 0.0}],
        )
        run = simulate(template.MyEngine(), parse_problem(d))
        t, x, y, theta, omega = run.rows[-1]
        self.assertEqual(t, 0.5)
        self.assertAlmostEqual(x, 0.4 * 0.5, places=12)
        self.assertAlmostEqual(y, 0.0, places=12)
        self.assertAlmostEqual(theta, 0.0, places=12)
        self.assertAlmostEqual(omega, 0.0, places=12)


if __name__ == "__main__":
    unittest.main()


def _pure_python():
    """adapters/python/pure_python.py's engine class."""
    import importlib.util

    path = os.path.join(ROOT, "adapters", "python", "pure_python.py")
    spec = importlib.util.spec_from_file_location("pure_python", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.PurePython


class ReleaseTest(unittest.TestCase):
    """Protocol 3's ``release``: the kit steps the engine with no push until
    the plate rests, and refuses an engine that cannot release."""

    A = 0.125
    MU = 0.5

    def square(self, **changes):
        """The seed plate (0.25 m square, 1 kg, mu 0.5 on its corners), v2."""
        a = self.A
        d = doc(
            format="pushval-problem/2",
            switching="impulsive",
            dt=0.001,
            sample_dt=0.01,
            object={"mass": 1.0, "inertia_cm": (2 * a) ** 2 / 6, "center_of_mass": [0.0, 0.0],
                    "polygon": [[-a, -a], [a, -a], [a, a], [-a, a]]},
            supports=[{"point": p, "mu": self.MU, "normal_force": 9.81 / 4}
                      for p in [[-a, -a], [a, -a], [a, a], [-a, a]]],
            contact={"point": [-a, 0.0]},
        )
        d.update(changes)
        d.pop("pushes", None)
        return d

    def session(self, engine, problem, ops, rows="steps"):
        docs = [{"request": 1, "op": "start", "rows": rows, "problem": problem}]
        for i, op in enumerate(ops):
            docs.append(dict(op, request=2 + i))
        docs.append({"request": 2 + len(ops), "op": "finish"})
        out, err = io.StringIO(), io.StringIO()
        status = serve(engine, True, io.StringIO("\n".join(map(json.dumps, docs)) + "\n"), out, err)
        self.assertEqual(status, 0)
        return answers(out.getvalue())

    def rows(self, answer):
        return [list(map(float, l.split(","))) for l in answer[:-1] if not l.startswith("t,")]

    def test_pure_python_translation_stops_at_the_closed_form(self):
        """Supports symmetric about the centre of mass, no spin: the plate
        stops after v/(mu g), v^2/(2 mu g) along its velocity (within a step
        and v h: the implicit friction's first-order error)."""
        engine = _pure_python()(argparse_namespace())
        v, h, g = 1.0, 0.001, 9.81
        problem = self.square(initial={"position": [0.0, 0.0], "theta": 0.3, "omega": 0.0,
                                       "from_rest": False, "velocity": [0.6 * v, 0.8 * v]})
        got = self.session(engine, problem, [{"op": "release", "max_duration": 10.0}])
        rows = self.rows(got[1])
        t, x, y, theta, omega = rows[-1]
        t_exact, d_exact = v / (self.MU * g), v * v / (2 * self.MU * g)
        self.assertTrue(t_exact - 1e-9 <= t <= t_exact + h + 1e-9, (t, t_exact))
        self.assertLess(abs(math.hypot(x, y) - d_exact), v * h)
        self.assertAlmostEqual(x * 0.8 - y * 0.6, 0.0, places=12)
        self.assertAlmostEqual(theta, 0.3, places=12)
        self.assertEqual(rows[0][0], 0.0)

    def test_pure_python_rests_after_a_push_without_chattering(self):
        """After a push the plate slides on; its last rows are the rest (no
        reversal: the speed falls monotonically to zero)."""
        engine = _pure_python()(argparse_namespace())
        problem = self.square(initial={"position": [0.0, 0.0], "theta": 0.0, "omega": 0.0, "from_rest": True})
        got = self.session(engine, problem, [
            {"op": "advance", "speed": 0.5, "phi": 0.3, "duration": 0.4},
            {"op": "release", "max_duration": 10.0},
        ])
        rows = self.rows(got[1]) + self.rows(got[2])
        slide = [r for r in rows if r[0] >= 0.4]
        speeds = [math.hypot(b[1] - a[1], b[2] - a[2]) / (b[0] - a[0]) for a, b in zip(slide, slide[1:])]
        self.assertTrue(all(s2 <= s1 + 1e-9 for s1, s2 in zip(speeds, speeds[1:])), speeds[-5:])
        self.assertLess(slide[-1][0], 0.4 + 10.0)
        self.assertLess(abs(slide[-1][4]), 1e-9)

    def test_a_short_slide_ends_at_max_duration(self):
        engine = _pure_python()(argparse_namespace())
        problem = self.square(initial={"position": [0.0, 0.0], "theta": 0.0, "omega": 2.0,
                                       "from_rest": False, "velocity": [1.0, 0.0]})
        got = self.session(engine, problem, [{"op": "release", "max_duration": 0.05}], rows="samples")
        rows = self.rows(got[1])
        self.assertEqual([r[0] for r in rows][-1], 0.05)
        self.assertEqual(got[1][0], "t,x,y,theta,omega,steps")

    def test_an_engine_that_cannot_release_is_refused_naming_the_release(self):
        problem = self.square(initial={"position": [0.0, 0.0], "theta": 0.0, "omega": 0.0, "from_rest": True})
        got = self.session(Recorder(), problem, [{"op": "release", "max_duration": 1.0}])
        self.assertRegex(got[1][0], r"^#error 2 .*cannot release")


def argparse_namespace(**kw):
    import argparse

    ns = argparse.Namespace(scheme="euler", inertia_scale=1.0)
    for k, v in kw.items():
        setattr(ns, k, v)
    return ns
