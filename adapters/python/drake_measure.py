#!/usr/bin/env python3
"""Measures drake_push.py's four approximations on the paper scene.

Writes results/friction_models/drake/{approximations,sweeps}.csv (see the
README there). Run from the repository root with the adapters' venv:

    .venv-adapters/bin/python adapters/python/drake_measure.py [PROBLEM.json]

PROBLEM.json: `pushval problem scenarios/paper-square-v1.0.toml --protocol 2`
(written to a temporary file when not given). The first 2 s segment is run;
"steady ω" is the mean ω over its last 0.5 s, compared with Coulomb's: the
kit's pure_python.py (Heun, dt = 1e-4 s) on the same problem, whose own
error there is below 1e-6 relative.
"""

import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "python"))

from pushval.adapter import parse_problem, simulate  # noqa: E402

import drake_push  # noqa: E402
import pure_python  # noqa: E402

OUT = os.path.join(ROOT, "results", "friction_models", "drake")
STEADY_WINDOW = 0.5


def engine_args(approx, **kw):
    a = argparse.Namespace(approximation=approx, stiction_tolerance=drake_push.DEFAULT_STICTION,
                           relaxation_time=None, dissipation=None, penetration=drake_push.DEFAULT_PENETRATION,
                           near_rigid_threshold=1.0, check=False, diag=None)
    for k, v in kw.items():
        setattr(a, k, v)
    return a


def steady(rows, end):
    w = [r[4] for r in rows if r[0] >= end - STEADY_WINDOW - 1e-12]
    return sum(w) / len(w)


def measure(doc, approx, dt, **kw):
    d = dict(doc)
    d["dt"] = dt
    problem = parse_problem(json.dumps(d))
    diag = tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False).name
    os.unlink(diag)
    eng = drake_push.DrakePush(engine_args(approx, diag=diag, **kw))
    t0 = time.perf_counter()
    run = simulate(eng, problem)
    wall = time.perf_counter() - t0
    eng.diag.close()
    rise, lost_steps, steps, load_err, dir_err, ratio = 0.0, set(), set(), 0.0, 0.0, []
    vs = eng.settings.stiction_tolerance
    with open(diag) as f:
        for r in csv.DictReader(f):
            t = float(r["t"])
            steps.add(t)
            rise = max(rise, float(r["rise_m"]))
            load_err = max(load_err, abs(float(r["sum_normal_n"]) - float(r["weight_n"])) / float(r["weight_n"]))
            if r["in_contact"] == "0":
                lost_steps.add(t)
            elif r["direction_error_rad"] and float(r["slip_speed"]) > 10 * vs:
                dir_err = max(dir_err, float(r["direction_error_rad"]))
                ratio.append(float(r["friction_ratio"]))
    os.unlink(diag)
    s = eng.settings
    return {
        "approximation": approx, "dt": dt,
        "stiction_tolerance": s.stiction_tolerance, "relaxation_time": s.relaxation_time,
        "hunt_crossley_dissipation": s.dissipation, "penetration": s.penetration,
        "omega_steady": steady(run.rows, problem.duration),
        "max_rise_m": rise, "contact_lost_share": len(lost_steps) / len(steps),
        "max_direction_error_rad": dir_err,
        "friction_ratio_min": min(ratio) if ratio else float("nan"),
        "friction_ratio_max": max(ratio) if ratio else float("nan"),
        "max_load_error_rel": load_err,
        "wall_s_per_sim_s_with_diag": wall / problem.duration,
        "wall_s_per_sim_s": None,
    }


def cost(doc, approx, dt):
    d = dict(doc)
    d["dt"] = dt
    problem = parse_problem(json.dumps(d))
    eng = drake_push.DrakePush(engine_args(approx))
    run = simulate(eng, problem)
    return run.step_time_s / problem.duration


def main():
    if len(sys.argv) > 1:
        doc = json.load(open(sys.argv[1]))
    else:
        text = subprocess.run(["pushval", "problem", os.path.join(ROOT, "scenarios", "paper-square-v1.0.toml"),
                               "--protocol", "2"], check=True, capture_output=True, text=True).stdout
        doc = json.loads(text)
    doc["pushes"] = doc["pushes"][:1]
    ref_doc = dict(doc, dt=1e-4)
    ref = simulate(pure_python.PurePython(argparse.Namespace(scheme="heun", inertia_scale=1.0)),
                   parse_problem(json.dumps(ref_doc)))
    w_ref = steady(ref.rows, doc["pushes"][0]["duration"])
    print(f"Coulomb steady omega {w_ref!r} rad/s", file=sys.stderr)
    os.makedirs(OUT, exist_ok=True)
    rows = []
    for approx in drake_push.APPROXIMATIONS:
        for dt in (1e-3, 5e-4, 2e-4):
            r = measure(doc, approx, dt)
            r["wall_s_per_sim_s"] = cost(doc, approx, dt)
            rows.append(r)
            print(approx, dt, r["omega_steady"], r["max_rise_m"], r["contact_lost_share"], file=sys.stderr)
    sweeps = []
    for approx in ("sap", "similar"):
        for tau in (1e-3, 1e-2, 1e-1):
            if approx == "sap":
                sweeps.append(measure(doc, approx, 1e-3, relaxation_time=tau))
        for d in (0.0, 10.0, 200.0):
            if approx == "similar":
                sweeps.append(measure(doc, approx, 1e-3, dissipation=d))
        for pen in (1e-5, 1e-3):
            sweeps.append(measure(doc, approx, 1e-3, penetration=pen))
    for approx in ("tamsi", "lagged"):
        for vs in (1e-4, 1e-2):
            sweeps.append(measure(doc, approx, 1e-3, stiction_tolerance=vs))
    for name, data in (("approximations.csv", rows), ("sweeps.csv", sweeps)):
        with open(os.path.join(OUT, name), "w", newline="") as f:
            keys = list(data[0].keys()) + ["omega_coulomb", "omega_rel_error"]
            w = csv.DictWriter(f, fieldnames=keys, lineterminator="\n")
            w.writeheader()
            for r in data:
                r["omega_coulomb"] = w_ref
                r["omega_rel_error"] = (r["omega_steady"] - w_ref) / abs(w_ref)
                w.writerow({k: ("" if v is None else (f"{v:.6g}" if isinstance(v, float) else v)) for k, v in r.items()})


if __name__ == "__main__":
    main()
