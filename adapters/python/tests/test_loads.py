"""The reference adapters' load_1..load_n and rise columns, at rest.

Run with the adapters' interpreter from the repository root:
``.venv-adapters/bin/python -m unittest discover -s adapters/python/tests``.
Each simulator that is not installed in that interpreter is skipped.

The scene: a triangular plate (scenarios/triangle-statics.toml: 2 kg, feet at
three of its points, pushed on its base edge), so the loads at rest are
statically determined. They are worked here from the statics (force and the
two moments about the centre of mass), not taken from pushval or from an
adapter, and put in the problem document; each adapter's first row (t = 0,
the plate at rest after its settling, before the push) must carry them.
"""

import importlib.util
import json
import math
import os
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ADAPTERS = os.path.dirname(HERE)
ROOT = os.path.dirname(os.path.dirname(ADAPTERS))

MASS = 2.0
GRAVITY = 9.81
POLYGON = [[0.0, 0.0], [0.4, 0.0], [0.1, 0.3]]
COM = [sum(p[0] for p in POLYGON) / 3, sum(p[1] for p in POLYGON) / 3]
FEET = [[0.02, 0.01], [0.37, 0.01], [0.1, 0.27]]
MU = [0.4, 0.5, 0.6]


def statics(feet, com, weight):
    """Loads N_i with sum N_i = W and sum N_i (p_i - c) = 0 (Cramer's rule)."""
    a = [[1.0] * 3, [p[0] - com[0] for p in feet], [p[1] - com[1] for p in feet]]
    b = [weight, 0.0, 0.0]

    def det(m):
        return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))

    d = det(a)
    out = []
    for j in range(3):
        m = [row[:] for row in a]
        for i in range(3):
            m[i][j] = b[i]
        out.append(det(m) / d)
    return out


LOADS = statics(FEET, COM, MASS * GRAVITY)

DOC = {
    "format": "pushval-problem/1",
    "engine": "test",
    "dt": 0.001,
    "object": {"mass": MASS, "inertia_cm": 0.024444444444444446, "center_of_mass": COM, "polygon": POLYGON},
    "supports": [{"point": p, "mu": mu, "normal_force": n} for p, mu, n in zip(FEET, MU, LOADS)],
    "contact": {"point": [0.25, 0.0]},
    "initial": {"position": [0.0, 0.0], "theta": 0.0, "omega": 0.0, "from_rest": True},
    "pushes": [{"t_start": 0.0, "duration": 0.02, "speed": 0.5, "phi": math.pi / 2}],
    "sample_dt": 0.01,
    "gravity": GRAVITY,
    "options": {},
}

# (simulator module, script, arguments)
CASES = [
    ("pydrake", "drake_push.py", ["--approximation", "tamsi"]),
    ("pydrake", "drake_push.py", ["--approximation", "lagged"]),
    ("pydrake", "drake_push.py", ["--approximation", "sap"]),
    ("pydrake", "drake_push.py", ["--approximation", "similar"]),
    ("mujoco", "mujoco_push.py", ["--cone", "pyramidal"]),
    ("mujoco", "mujoco_push.py", ["--cone", "elliptic"]),
    ("pybullet", "pybullet_push.py", ["--mode", "forces"]),
    ("pybullet", "pybullet_push.py", ["--mode", "contact"]),
]


class StaticsTest(unittest.TestCase):
    def test_the_statics_here_balance(self):
        # The worked loads themselves: they carry the weight and no moment.
        self.assertAlmostEqual(sum(LOADS), MASS * GRAVITY, places=12)
        for axis in (0, 1):
            self.assertAlmostEqual(sum(n * (p[axis] - COM[axis]) for n, p in zip(LOADS, FEET)), 0.0, places=12)
        self.assertTrue(all(n > 0 for n in LOADS))

    def check(self, module, script, args):
        if importlib.util.find_spec(module) is None:
            self.skipTest(f"{module} is not installed in {sys.executable}")
        env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
        env.pop("PUSHVAL_SESSION", None)
        run = subprocess.run([sys.executable, os.path.join(ADAPTERS, script), *args], input=json.dumps(DOC),
                             capture_output=True, text=True, env=env, timeout=300)
        self.assertEqual(run.returncode, 0, run.stderr[-2000:])
        lines = run.stdout.splitlines()
        names = ["load_1", "load_2", "load_3", "rise"]
        self.assertEqual(lines[0].split(","), ["t", "x", "y", "theta", "omega", *names])
        rows = [[float(v) for v in line.split(",")] for line in lines[1:]]
        self.assertEqual(len(rows), 1 + 20)
        t, *_, n1, n2, n3, rise = rows[0]
        self.assertEqual((t, rise), (0.0, 0.0))
        weight = MASS * GRAVITY
        self.assertLess(abs(n1 + n2 + n3 - weight) / weight, 1e-3, f"loads {n1, n2, n3} against m g {weight}")
        for k, (got, want) in enumerate(zip((n1, n2, n3), LOADS)):
            self.assertLess(abs(got - want) / want, 1e-3, f"load_{k + 1} {got} N against the statics' {want} N")
        for row in rows:
            self.assertEqual(len(row), 9)
            self.assertTrue(all(math.isfinite(v) for v in row))
            self.assertTrue(all(v >= 0.0 for v in row[5:8]), row)

    def test_drake_tamsi(self):
        self.check(*CASES[0])

    def test_drake_lagged(self):
        self.check(*CASES[1])

    def test_drake_sap(self):
        self.check(*CASES[2])

    def test_drake_similar(self):
        self.check(*CASES[3])

    def test_mujoco_pyramidal(self):
        self.check(*CASES[4])

    def test_mujoco_elliptic(self):
        self.check(*CASES[5])

    def test_pybullet_forces(self):
        self.check(*CASES[6])

    def test_pybullet_contact(self):
        self.check(*CASES[7])


if __name__ == "__main__":
    unittest.main()
