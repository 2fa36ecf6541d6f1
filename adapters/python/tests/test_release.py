"""The reference adapters let go (protocol 3's ``release``): each plate
slides to rest under its engine's friction, and a release after a push
continues from the pushed state.

Run with the adapters' interpreter from the repository root:
``.venv-adapters/bin/python -m unittest discover -s adapters/python/tests``.
Each simulator that is not installed in that interpreter is skipped.

The scene is the seed plate (0.25 m square, 1 kg, mu 0.5 on its four
corners), thrown without pushes or pushed and then released, in protocol 3
sessions served in this process. What each engine's law predicts for a throw
in pure translation at v (closed form: v^2/(2 mu g) after v/(mu g)):

* PyBullet, forces mode: implicit Coulomb support impulses
  (coulomb_slide.py): the closed form, the distance short by v h/2 (the pose
  moves with the step's end velocity) and the stop within a step.
* PyBullet, contact mode, Drake (TAMSI): velocity-level friction solved
  implicitly. On a plate square to the world axes Coulomb's stop, the
  distance short by v h/2; Drake's regularised friction (mu N u / v_s below
  the stiction tolerance v_s = 1e-3 m/s) adds a tail of about
  v_s/(mu g) ln(v_s/v_rest), under 1 ms, to the stop. Bullet's contact
  friction on a turned plate is not Coulomb's (it slides farther, off its
  line): there it must stop, and is not held to the closed form.
* MuJoCo 4 (either cone) along a world axis, and the elliptic cone in any
  direction: the closed form plus the soft contact's tail (the slip decays
  as du/dt = -u/tau, tau = d_max timeconst/(2 d) <= 10.6 ms: at most
  mu g tau^2 farther and tau ln(mu g tau / v_rest) later); the pyramidal
  cone on a diagonal of the world axes: the diamond |f1| + |f2| <= mu N
  gives between mu N/sqrt(2) and mu N, so it slides farther, at most
  sqrt(2) times as far.

The rest rule is pushval's: |v_cm| + |omega| L below 1e-5 m/s on 10
consecutive steps (the kit's REST_SPEED and REST_STEPS); the slide's last row
is the rest.
"""

import argparse
import importlib.util
import io
import json
import math
import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ADAPTERS = os.path.dirname(HERE)
ROOT = os.path.dirname(os.path.dirname(ADAPTERS))
sys.path.insert(0, os.path.join(ROOT, "python"))

from pushval.adapter import serve  # noqa: E402

A, MU, G = 0.125, 0.5, 9.81
H = 0.001
MAX_DURATION = 3.0
# MuJoCo's soft friction: the slowest time constant at the defaults (s).
TAU_MAX = 0.95 * 0.02 / (2 * 0.9)
# Drake's stiction tolerance (m/s) and the rest speed (m/s).
V_S, V_REST = 1e-3, 1e-5


def installed(module):
    return importlib.util.find_spec(module) is not None


def engine(script, cls, **args):
    """An engine of adapters/python/SCRIPT.py with its default options
    updated by ``args``."""
    path = os.path.join(ADAPTERS, script + ".py")
    spec = importlib.util.spec_from_file_location(script, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    engine_cls = getattr(module, cls)
    parser = argparse.ArgumentParser()
    engine_cls.add_arguments(parser)
    ns = parser.parse_args([])
    for k, v in args.items():
        setattr(ns, k, v)
    return engine_cls(ns)


def square(initial):
    """The seed plate as a version 2 document, no pushes."""
    a = A
    corners = [[-a, -a], [a, -a], [a, a], [-a, a]]
    return {
        "format": "pushval-problem/2", "engine": "test", "switching": "impulsive",
        "dt": H, "sample_dt": 0.01, "gravity": G, "options": {},
        "object": {"mass": 1.0, "inertia_cm": (2 * a) ** 2 / 6, "center_of_mass": [0.0, 0.0],
                   "polygon": corners},
        "supports": [{"point": p, "mu": MU, "normal_force": G / 4} for p in corners],
        "contact": {"point": [-a, 0.0]},
        "initial": initial,
    }


def thrown(v, theta):
    return square({"position": [0.0, 0.0], "theta": theta, "omega": 0.0, "from_rest": False,
                   "velocity": list(v)})


def session(eng, problem, ops):
    """Serves a protocol 3 session; returns the rows (t, x, y, theta,
    omega) of every answer, in order."""
    docs = [{"request": 1, "op": "start", "rows": "steps", "problem": problem}]
    docs += [dict(op, request=2 + i) for i, op in enumerate(ops)]
    docs.append({"request": 2 + len(ops), "op": "finish"})
    out, err = io.StringIO(), io.StringIO()
    status = serve(eng, True, io.StringIO("\n".join(map(json.dumps, docs)) + "\n"), out, err)
    assert status == 0, err.getvalue()[-2000:] + out.getvalue()[-500:]
    rows = []
    for line in out.getvalue().splitlines():
        if line.startswith("#error"):
            raise AssertionError(line)
        if line and not line.startswith(("t,", "#")):
            rows.append([float(x) for x in line.split(",")[:5]])
    return rows


PUSHES = [
    {"op": "advance", "speed": 0.6, "phi": 0.0, "duration": 0.3},
    {"op": "advance", "speed": 0.8, "phi": 0.4, "duration": 0.2},
]
T_PUSH = 0.5


class Release:
    """The checks every adapter answers; subclasses set `make` and the law's
    tolerances."""

    # Extra time (s) the law allows after v/(mu g), and extra distance (m)
    # beyond v^2/(2 mu g), for a throw along a world axis.
    tail_time = 2 * H
    tail_distance = 0.0
    # Whether the first 10 steps after a push stay within mu g T^2 of the
    # pushed motion (rigid contacts: friction at most mu m g).
    bounded_start = True

    def make(self):
        raise NotImplementedError

    def rest(self, problem, ops):
        rows = session(self.make(), problem, ops + [{"op": "release", "max_duration": MAX_DURATION}])
        t_release = sum(op["duration"] for op in ops)
        slide = [r for r in rows if r[0] > t_release + 1e-9]
        self.assertLess(slide[-1][0], t_release + MAX_DURATION - 1e-9, "no rest")
        return rows, slide

    def test_a_throw_along_a_world_axis_stops_at_the_closed_form(self):
        v = 1.0
        _, slide = self.rest(thrown((v, 0.0), 0.0), [])
        t, x, y, theta, _ = slide[-1]
        t_cf, d_cf = v / (MU * G), v * v / (2 * MU * G)
        print(f"{self.id()}: stop {t:.4f} s (v/(mu g) {t_cf:.4f}), {x:.5f} m (v^2/(2 mu g) {d_cf:.5f})",
              file=sys.stderr)
        self.assertGreaterEqual(t, t_cf - 1e-9)
        self.assertLessEqual(t, t_cf + self.tail_time)
        self.assertGreaterEqual(x, d_cf - v * H)
        self.assertLessEqual(x, d_cf + self.tail_distance)
        self.assertLess(abs(y), 1e-4 * d_cf)
        self.assertLess(abs(theta), 1e-3)

    def test_a_release_after_a_push_continues_from_the_pushed_state(self):
        """The slide starts where the push ended, moving as it was: over the
        first 10 steps the plate's displacement differs from v T by at most
        mu g T^2 (friction at most mu m g; twice the Euler bound
        a T^2 (1 + 1/n) / 2), and it then comes to rest. A soft contact's
        bounce (MuJoCo) loosens the first check into the stop time: the
        normal impulse m (g T - v_z) caps the friction's, so the slide lasts
        at least v/(mu g) - 0.1/g (|v_z| < 0.1 m/s)."""
        rows, slide = self.rest(square({"position": [0.0, 0.0], "theta": 0.0, "omega": 0.0,
                                        "from_rest": True}), PUSHES)
        push = [r for r in rows if r[0] <= T_PUSH + 1e-9]
        a, b = push[-2], push[-1]
        self.assertAlmostEqual(b[0], T_PUSH, places=9)
        vx, vy = (b[1] - a[1]) / (b[0] - a[0]), (b[2] - a[2]) / (b[0] - a[0])
        speed = math.hypot(vx, vy)
        self.assertGreater(speed, 0.3)
        c = slide[9]
        t = c[0] - b[0]
        self.assertAlmostEqual(t, 10 * H, places=9)
        dev = math.hypot(c[1] - b[1] - vx * t, c[2] - b[2] - vy * t)
        stop = slide[-1][0] - T_PUSH
        print(f"{self.id()}: released at {speed:.3f} m/s, {dev:.2e} m off v T after {t} s, rest after {stop:.3f} s",
              file=sys.stderr)
        if self.bounded_start:
            self.assertLessEqual(dev, MU * G * t * t)
        self.assertGreater(dev, 0.0)
        self.assertGreaterEqual(stop, speed / (MU * G) - 0.1 / G)


@unittest.skipUnless(installed("pybullet"), "pybullet is not installed")
class PyBulletForces(Release, unittest.TestCase):
    tail_time = H

    def make(self):
        return engine("pybullet_push", "PyBulletPush", mode="forces")

    def test_a_turned_throw_is_coulombs_in_any_direction(self):
        v = (0.3, -0.4)
        _, slide = self.rest(thrown(v, 0.7), [])
        t, x, y, theta, _ = slide[-1]
        d_cf = 0.25 / (2 * MU * G)
        self.assertLessEqual(t, 0.5 / (MU * G) + H)
        self.assertLess(abs(math.hypot(x, y) - d_cf), 0.5 * H)
        self.assertAlmostEqual(x * 0.4 + y * 0.3, 0.0, places=9)
        self.assertAlmostEqual(theta, 0.7, places=9)


@unittest.skipUnless(installed("pybullet"), "pybullet is not installed")
class PyBulletContact(Release, unittest.TestCase):
    def make(self):
        return engine("pybullet_push", "PyBulletPush", mode="contact")

    def test_a_turned_throw_stops(self):
        v = (0.3, -0.4)
        _, slide = self.rest(thrown(v, 0.7), [])
        t, x, y, _, _ = slide[-1]
        print(f"{self.id()}: {math.hypot(x, y) / (0.25 / (2 * MU * G)):.3f} x v^2/(2 mu g), "
              f"{math.atan2(y, x) - math.atan2(v[1], v[0]):.3f} rad off its line, stop {t:.4f} s",
              file=sys.stderr)


@unittest.skipUnless(installed("mujoco"), "mujoco is not installed")
class MujocoElliptic(Release, unittest.TestCase):
    tail_time = TAU_MAX * math.log(MU * G * TAU_MAX / V_REST) + 2 * H
    tail_distance = MU * G * TAU_MAX ** 2
    bounded_start = False

    def make(self):
        return engine("mujoco_push", "MujocoPush", cone="elliptic")


@unittest.skipUnless(installed("mujoco"), "mujoco is not installed")
class MujocoPyramidal(MujocoElliptic):
    def make(self):
        return engine("mujoco_push", "MujocoPush", cone="pyramidal")

    def test_the_pyramid_slides_farther_off_its_axes(self):
        v = (0.3, -0.4)
        _, slide = self.rest(thrown(v, 0.7), [])
        _, x, y, _, _ = slide[-1]
        d_cf = 0.25 / (2 * MU * G)
        d = math.hypot(x, y)
        self.assertGreater(d, 1.1 * d_cf)
        self.assertLessEqual(d, math.sqrt(2) * d_cf + self.tail_distance)


@unittest.skipUnless(installed("pydrake"), "drake is not installed")
class DrakeTamsi(Release, unittest.TestCase):
    tail_time = V_S / (MU * G) * math.log(V_S / V_REST) + 2 * H

    def make(self):
        return engine("drake_push", "DrakePush")


del Release

if __name__ == "__main__":
    unittest.main()
