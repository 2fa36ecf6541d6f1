#!/usr/bin/env python3
"""MuJoCo Warp 4.0 (CPU) against MuJoCo C 4.0 on the identical scene.

Writes results/friction_models/mujoco_warp/compare.csv. Run from the
repository root after scripts/setup-warp.sh:

    .venv-warp/bin/python scripts/compare_mujoco_warp.py [--duration S]

The problem: scenarios/paper-square-v1.0.toml's plate (0.25 m, 1 kg, four
feet of 2.4525 N, mu 0.5), pushed at its corner at phi = pi/4 + 0.3 from
rest, dt = 1e-3 s, at 0.2, 0.5 and 1.0 m/s, both cones; the same
mujoco_push.py MJCF stepped by MuJoCo C (mujoco_push.py) and by MuJoCo Warp
(mujoco_warp_push.py). Per run: steady omega (mean over the last quarter),
each foot's mean load over the last quarter, the largest angle between a
sliding foot's friction force and its slip (feet sliding faster than 1e-2
m/s, from mj_contactForce and the plate's velocity), the largest rise, the
share of steps with a foot out of contact (load 0), and wall seconds per
simulated second of the steps (reset and settling excluded).
"""

import argparse
import csv
import json
import math
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "adapters", "python"))
sys.path.insert(0, os.path.join(ROOT, "python"))

import numpy as np  # noqa: E402

from pushval.adapter import parse_problem  # noqa: E402
import mujoco_push  # noqa: E402
import mujoco_warp_push  # noqa: E402

PHI = math.pi / 4 + 0.3
HALF = 0.125


def problem(speed, duration, dt):
    corners = [[-HALF, -HALF], [HALF, -HALF], [HALF, HALF], [-HALF, HALF]]
    doc = {
        "format": "pushval-problem/1", "engine": "compare", "dt": dt,
        "object": {"mass": 1.0, "inertia_cm": 1.0 * (2 * HALF) ** 2 / 6, "center_of_mass": [0.0, 0.0],
                   "polygon": corners},
        "supports": [{"point": c, "mu": 0.5, "normal_force": 9.81 / 4} for c in corners],
        "contact": {"point": [-HALF, -HALF]},
        "initial": {"position": [0.0, 0.0], "theta": 0.0, "omega": 0.0, "from_rest": True},
        "pushes": [{"t_start": 0.0, "duration": duration, "speed": speed, "phi": PHI}],
        "sample_dt": 0.01, "gravity": 9.81, "options": {},
    }
    return parse_problem(json.dumps(doc))


def direction_errors(mj, model, data, n, f6):
    """Per sliding foot: the angle between its friction force and minus its
    slip velocity (rad)."""
    out = []
    mat = data.xmat[mujoco_push.OBJECT].reshape(3, 3)
    v = data.qvel[0:3]
    w = mat @ data.qvel[3:6]
    com = data.xpos[mujoco_push.OBJECT]
    for i in range(data.ncon):
        con = data.contact[i]
        g1, g2 = con.geom[0], con.geom[1]
        gi = max(g1, g2)
        if not 1 <= gi <= n:
            continue
        mj.mj_contactForce(model, data, i, f6)
        fr = con.frame.reshape(3, 3)
        ft = f6[1] * fr[1] + f6[2] * fr[2]  # on geom2 by geom1, world
        if g2 != gi:
            ft = -ft
        r = con.pos - com
        vp = v + np.cross(w, r)
        vt = vp - np.dot(vp, fr[0]) * fr[0]
        s, fm = np.linalg.norm(vt), np.linalg.norm(ft)
        if s > 1e-2 and fm > 0:
            c = -np.dot(ft, vt) / (s * fm)
            out.append(math.acos(max(-1.0, min(1.0, c))))
    return out


def run(engine, prob, data_of):
    state = engine.reset(prob)
    n = len(prob.supports)
    push = prob.pushes[0]
    steps = round(push.duration / prob.dt)
    h = push.duration / steps
    rows, loads, rises, lost, dirs = [], [], [], 0, []
    f6 = np.zeros(6)
    t0 = time.perf_counter()
    step_time = 0.0
    for k in range(steps):
        a = time.perf_counter()
        st = engine.step(push, h)
        step_time += time.perf_counter() - a
        ex = engine.extras()
        rows.append(((k + 1) * h, st.omega))
        loads.append(ex[:n])
        rises.append(ex[n])
        lost += 1 if min(ex[:n]) <= 0.0 else 0
        model, data = data_of(engine)
        dirs += direction_errors(engine.mj, model, data, n, f6)
    del t0
    q = [i for i, (t, _) in enumerate(rows) if t >= 0.75 * push.duration]
    return {
        "omega_steady": float(np.mean([rows[i][1] for i in q])),
        "loads": [float(np.mean([loads[i][j] for i in q])) for j in range(n)],
        "max_direction_error_rad": max(dirs) if dirs else float("nan"),
        "max_rise_m": max(rises),
        "contact_lost_share": lost / steps,
        "wall_s_per_sim_s": step_time / push.duration,
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--dt", type=float, default=1e-3)
    ap.add_argument("--speeds", default="0.2,0.5,1.0")
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "friction_models", "mujoco_warp", "compare.csv"))
    a = ap.parse_args()
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    fields = ["engine", "cone", "speed", "dt", "duration", "omega_steady", "load_1", "load_2", "load_3", "load_4",
              "max_direction_error_rad", "max_rise_m", "contact_lost_share", "wall_s_per_sim_s"]
    with open(a.out, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(fields)
        for cone in ("elliptic", "pyramidal"):
            ns = argparse.Namespace(cone=cone)
            c_engine = mujoco_push.MujocoPush(ns)
            w_engine = mujoco_warp_push.MujocoWarpPush(ns)
            for speed in map(float, a.speeds.split(",")):
                prob = problem(speed, a.duration, a.dt)
                for name, eng, data_of in (("mujoco_c", c_engine, lambda e: (e.model, e.data)),
                                           ("mujoco_warp", w_engine, lambda e: (e.mjm, e.mjd))):
                    r = run(eng, prob, data_of)
                    w.writerow([name, cone, speed, a.dt, a.duration, f"{r['omega_steady']:.6g}",
                                *(f"{x:.6g}" for x in r["loads"]), f"{r['max_direction_error_rad']:.3g}",
                                f"{r['max_rise_m']:.3g}", f"{r['contact_lost_share']:.4g}",
                                f"{r['wall_s_per_sim_s']:.3g}"])
                    fh.flush()
                    print(name, cone, speed, r, file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
