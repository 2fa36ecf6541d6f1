#!/usr/bin/env python3
"""The lift of Drake's convex approximations (SAP, Similar): measured and predicted.

Writes results/friction_models/drake/lift.csv (see the README there, section
"The lift of SAP and Similar"). Run from the repository root with the
adapters' venv (Drake installed):

    .venv-adapters/bin/python adapters/python/drake_lift_study.py [PROBLEM.json] [--quick]

PROBLEM.json: `pushval problem scenarios/paper-square-v1.0.toml --protocol 2`
(run through target/release/pushval, else `pushval` on the PATH, when not
given). Only its first segment is run (2 s, φ = π/4 + 0.3, at the corner),
at the speeds 0.2, 0.5 and 1.0 m/s. The scene is drake_push.py's, unchanged
(its --diag rows are what is measured here).

Measured per run (the last 0.5 s of the segment is "steady"):
  omega_steady        mean ω (rad/s)
  rise_max_m          largest rise of the centre of mass above its rest height
  rise_steady_m       mean rise
  airborne_share      share of steps with at least one foot out of contact
  load_mean_k         mean normal force of foot k over the steady window (N;
                      0 while out of contact), against the problem's N_k
  direction_err_mean  mean angle between the friction force and minus the
                      slip (rad), feet in contact sliding faster than 10 v_s
  friction_ratio_mean mean |f_t| / (μ N) of the same rows

Predicted (the closed form of the README, implemented here on its own and
in crates/laws/src/drake.rs):
  regime              "glide" (every foot keeps penetrating), "hop" (not)
  rise_pred_m         glide: the centre of mass's rise, the plane fitted to
                      the feet's lifts; hop: the ballistic estimate
  omega_pred          glide: Coulomb with the glide's loads; hop: Coulomb
  load_pred_k         the glide's loads (hop: the problem's)
"""

import argparse
import csv
import json
import math
import os
import shutil
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

OUT = os.path.join(ROOT, "results", "friction_models", "drake", "lift.csv")
STEADY_WINDOW = 0.5
SPEEDS = (0.2, 0.5, 1.0)
# The carriages' mass over the plate's: drake_push.py's 1e6, and 1e3, at
# which SAP's solver converges on the plate's yaw (README).
CARRIAGES = (1e6, 1e3)


# ----------------------------------------------------------------------
# Coulomb's steady ω (the analytic model's moment balance, object frame)

def slips(p, push, omega):
    """Slip velocity (object frame) of each support at ω."""
    cx, cy = p.contact_offset
    vx, vy = push.speed * math.cos(push.phi), push.speed * math.sin(push.phi)
    out = []
    for s in p.supports:
        rx, ry = s.offset[0] - cx, s.offset[1] - cy
        out.append((vx - ry * omega, vy + rx * omega))
    return out


def moment(p, push, omega, forces):
    """I_P ω̇ (N m) under Coulomb with friction magnitudes `forces`."""
    cx, cy = p.contact_offset
    dx, dy = math.cos(push.phi), math.sin(push.phi)
    g = p.mass * push.speed * omega * (cx * dx + cy * dy)
    for s, u, f in zip(p.supports, slips(p, push, omega), forces):
        rx, ry = s.offset[0] - cx, s.offset[1] - cy
        n = math.hypot(*u)
        if n > 0:
            g += rx * (-f * u[1] / n) - ry * (-f * u[0] / n)
    return g


def coulomb_omega(p, push, forces, lo=-50.0, hi=50.0):
    """The root of `moment` the flow from ω = 0 reaches: G is decreasing
    through a stable root; bracket from 0 outwards in the sign of G(0)."""
    g0 = moment(p, push, 0.0, forces)
    if g0 == 0.0:
        return 0.0
    step = 1e-3 if g0 > 0 else -1e-3
    a, b = 0.0, step
    while moment(p, push, b, forces) * g0 > 0:
        a, b = b, b * 1.5
        if abs(b) > 1e4:
            return float("nan")
    for _ in range(200):
        m = 0.5 * (a + b)
        if moment(p, push, m, forces) * g0 > 0:
            a = m
        else:
            b = m
    return 0.5 * (a + b)


# ----------------------------------------------------------------------
# The closed form (README: "The lift of SAP and Similar")

def contact_constants(approx, settings, h, mu, v, n_rest):
    """(K, a): a sliding foot's steady normal force is N = K (a − z), z its
    rise above the rest height (m), while a − z > 0 (it penetrates).

    SAP (sliding mode of the friction-cone projection, μ² R_t ≪ R_n):
        N = k (δ + (δt + τ_d) μ |v_t| − z)
    Similar (n(z) with z = v_n − μ |v_t|, v_n = 0 in the glide):
        N = k (1 + d μ |v_t|) (δ + δt μ |v_t| − z)
    with δ the rest penetration, k = N_rest / δ."""
    pen = settings.penetration
    k = n_rest / pen
    if approx == "sap":
        return k, pen + (h + settings.relaxation_time) * mu * v
    return k * (1.0 + settings.dissipation * mu * v), pen + h * mu * v


def plane_loads(p, K, a, weight):
    """The rigid plate's glide: loads N_i = K_i (a_i − z0 − b·p_i) with
    Σ N_i = m g and Σ p_i N_i = 0; returns (loads, z0, [a_i − z_i])."""
    pts = [s.offset for s in p.supports]
    # Unknowns z0, bx, by: Σ K (a − z0 − bx x − by y) [1, x, y] = [W, 0, 0].
    rows = []
    rhs = []
    for wgt, tgt in ((lambda q: 1.0, weight), (lambda q: q[0], 0.0), (lambda q: q[1], 0.0)):
        rows.append([sum(Ki * wgt(q) for Ki, q in zip(K, pts)),
                     sum(Ki * wgt(q) * q[0] for Ki, q in zip(K, pts)),
                     sum(Ki * wgt(q) * q[1] for Ki, q in zip(K, pts))])
        rhs.append(sum(Ki * ai * wgt(q) for Ki, ai, q in zip(K, a, pts)) - tgt)
    z = solve3(rows, rhs)
    if z is None:
        return None
    z0, bx, by = z
    gaps = [ai - (z0 + bx * q[0] + by * q[1]) for ai, q in zip(a, pts)]
    loads = [Ki * g for Ki, g in zip(K, gaps)]
    return loads, z0, gaps


def solve3(m, b):
    import numpy as np

    try:
        return [float(x) for x in np.linalg.solve(np.array(m), np.array(b))]
    except np.linalg.LinAlgError:
        return None


def launch_speed(approx, settings, h, mu, v, n_rest, g):
    """The normal velocity (m/s) one step's contact impulse gives a foot of
    mass m_i = N_i / g touching at zero penetration and zero normal velocity
    while sliding at v: SAP, u = c μ v / (1 + c), c = δt k (δt + τ_d) / m_i;
    Similar, u = μ v − w with c' w (1 + d w) = μ v − w, c' = δt² k / m_i."""
    k = n_rest / settings.penetration
    m = n_rest / g
    if approx == "sap":
        c = h * k * (h + settings.relaxation_time) / m
        return c * mu * v / (1.0 + c)
    c = h * h * k / m
    d = settings.dissipation
    if d * c * mu * v < 1e-12:
        return c * mu * v / (1.0 + c)
    w = (-(1.0 + c) + math.sqrt((1.0 + c) ** 2 + 4.0 * d * c * mu * v)) / (2.0 * d * c)
    return mu * v - w


def predict(p, push, approx, settings, h):
    """(regime, rise of the centre of mass (m), ω (rad/s), loads (N))."""
    rest = [s.normal_force for s in p.supports]
    mus = [s.mu for s in p.supports]
    weight = p.mass * p.gravity
    w = coulomb_omega(p, push, [m * n for m, n in zip(mus, rest)])
    regime, loads, rise = "glide", rest, 0.0
    for _ in range(60):
        v = [math.hypot(*u) for u in slips(p, push, w)]
        K, a = zip(*(contact_constants(approx, settings, h, m, vi, n) for m, vi, n in zip(mus, v, rest)))
        sol = plane_loads(p, K, a, weight)
        # Glide while every foot still penetrates: its rise z_i = a_i − gap_i
        # stays below the rest penetration δ.
        if sol is None or max(ai - g for ai, g in zip(a, sol[2])) >= settings.penetration:
            regime = "hop"
            break
        loads, rise, _ = sol
        w_new = coulomb_omega(p, push, [m * n for m, n in zip(mus, loads)])
        done = abs(w_new - w) < 1e-13 * max(1.0, abs(w))
        w = w_new
        if done:
            break
    if regime == "hop":
        loads = rest
        w = coulomb_omega(p, push, [m * n for m, n in zip(mus, rest)])
        v = [math.hypot(*u) for u in slips(p, push, w)]
        # A hopping foot is launched from zero penetration by one step's
        # impulse: its share of the mass m_i = N_i / g leaves at u_i
        # (launch_speed); the centre of mass, the feet's mean, stays δ
        # above its rest height plus the mean height of ballistic arcs
        # u²/(2g), (2/3) u²/(2g) = u²/(3g).
        u2 = [launch_speed(approx, settings, h, m, vi, n, p.gravity) ** 2 for m, vi, n in zip(mus, v, rest)]
        rise = settings.penetration + sum(u2) / len(u2) / (3.0 * p.gravity)
    return regime, rise, w, loads


# ----------------------------------------------------------------------
# Measurement (drake_push.py's scene and diagnostics)

def engine_args(approx, **kw):
    a = argparse.Namespace(approximation=approx, stiction_tolerance=drake_push.DEFAULT_STICTION,
                           relaxation_time=None, dissipation=None, penetration=drake_push.DEFAULT_PENETRATION,
                           near_rigid_threshold=1.0, check=False, diag=None)
    for k, v in kw.items():
        setattr(a, k, v)
    return a


def measure(doc, approx, speed, dt, carriage=drake_push.CARRIAGE_MASS_RATIO, **kw):
    d = json.loads(json.dumps(doc))
    d["dt"] = dt
    d["pushes"] = [dict(d["pushes"][0], speed=speed)]
    problem = parse_problem(json.dumps(d))
    fd, diag = tempfile.mkstemp(suffix=".csv")
    os.close(fd)
    os.unlink(diag)
    eng = drake_push.DrakePush(engine_args(approx, diag=diag, **kw))
    shipped = drake_push.CARRIAGE_MASS_RATIO
    drake_push.CARRIAGE_MASS_RATIO = carriage  # read by build(); restored below
    t0 = time.perf_counter()
    try:
        run = simulate(eng, problem)
    finally:
        drake_push.CARRIAGE_MASS_RATIO = shipped
    wall = time.perf_counter() - t0
    eng.diag.close()
    end = problem.duration
    nf = len(problem.supports)
    vs = eng.settings.stiction_tolerance
    steps, lost, rise_max = set(), set(), 0.0
    rise_win = {}
    load_sum = [0.0] * nf
    win_steps = set()
    dir_err, ratio = [], []
    with open(diag) as f:
        for r in csv.DictReader(f):
            t = float(r["t"])
            steps.add(t)
            rise = float(r["rise_m"])
            rise_max = max(rise_max, rise)
            if r["in_contact"] == "0":
                lost.add(t)
            if t >= end - STEADY_WINDOW - 1e-12:
                win_steps.add(t)
                rise_win[t] = rise
                load_sum[int(r["foot"])] += float(r["normal_n"])
                if r["in_contact"] == "1" and r["direction_error_rad"] and float(r["slip_speed"]) > 10 * vs:
                    dir_err.append(float(r["direction_error_rad"]))
                    ratio.append(float(r["friction_ratio"]))
    os.unlink(diag)
    w_rows = [row[4] for row in run.rows if row[0] >= end - STEADY_WINDOW - 1e-12]
    nwin = len(win_steps)
    s = eng.settings
    out = {
        "approximation": approx, "carriage_mass_ratio": carriage, "speed": speed, "dt": dt,
        "relaxation_time": s.relaxation_time, "hunt_crossley_dissipation": s.dissipation,
        "penetration": s.penetration,
        "omega_steady": sum(w_rows) / len(w_rows),
        "omega_std": math.sqrt(max(0.0, sum(x * x for x in w_rows) / len(w_rows) - (sum(w_rows) / len(w_rows)) ** 2)),
        "rise_max_m": rise_max,
        "rise_steady_m": sum(rise_win.values()) / len(rise_win),
        "airborne_share": len(lost) / len(steps),
        "direction_err_mean": sum(dir_err) / len(dir_err) if dir_err else float("nan"),
        "direction_err_max": max(dir_err) if dir_err else float("nan"),
        "friction_ratio_mean": sum(ratio) / len(ratio) if ratio else float("nan"),
        "wall_s": wall,
    }
    for k in range(nf):
        out[f"load_mean_{k}"] = load_sum[k] / nwin
    regime, rise_p, w_p, loads_p = predict(problem, problem.pushes[0], approx, s, dt)
    w_c = coulomb_omega(problem, problem.pushes[0], [sp.mu * sp.normal_force for sp in problem.supports])
    out.update({
        "regime": regime, "rise_pred_m": rise_p, "omega_pred": w_p, "omega_coulomb": w_c,
        "omega_err_vs_coulomb": (out["omega_steady"] - w_c) / abs(w_c),
        "omega_err_vs_pred": (out["omega_steady"] - w_p) / abs(w_p),
    })
    for k in range(nf):
        out[f"load_pred_{k}"] = loads_p[k]
    w_l = coulomb_omega(problem, problem.pushes[0],
                        [sp.mu * out[f"load_mean_{k}"] for k, sp in enumerate(problem.supports)])
    out["omega_coulomb_measured_loads"] = w_l
    out["omega_err_vs_measured_loads"] = (out["omega_steady"] - w_l) / abs(w_l)
    out["load_problem"] = problem.supports[0].normal_force
    return out


def grid(quick):
    """(approximation, speed, dt, options) of every run."""
    runs = []
    dts = (4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4)
    if quick:
        dts = (1e-3, 2.5e-4)
    for approx in ("sap", "similar"):
        for v in SPEEDS:
            for h in dts:
                runs.append((approx, v, h, {}))
    # The dissipation: SAP's relaxation time, Similar's Hunt–Crossley d.
    for v in SPEEDS:
        for tau in (0.0, 1e-4, 1e-3, 1e-2, 1e-1):
            runs.append(("sap", v, 1e-3, {"relaxation_time": tau}))
        for d in (0.0, 1.0, 10.0, 200.0):
            runs.append(("similar", v, 1e-3, {"dissipation": d}))
    # The glide: soft feet (δ = 1 mm), small steps; dissipation none, low,
    # critical (None: the adapter's default).
    for v in SPEEDS:
        for h in (1e-3, 2.5e-4):
            for tau in (0.0, 2e-3, None):
                runs.append(("sap", v, h, {"relaxation_time": tau, "penetration": 1e-3}))
            for d in (0.0, 2.0, None):
                runs.append(("similar", v, h, {"dissipation": d, "penetration": 1e-3}))
    return runs


def problem_doc(path):
    if path:
        with open(path) as f:
            return json.load(f)
    exe = os.path.join(ROOT, "target", "release", "pushval")
    if not os.path.exists(exe):
        exe = shutil.which("pushval") or "pushval"
    text = subprocess.run([exe, "problem", os.path.join(ROOT, "scenarios", "paper-square-v1.0.toml"),
                           "--protocol", "2"], check=True, capture_output=True, text=True, cwd=ROOT).stdout
    return json.loads(text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("problem", nargs="?", help="pushval-problem JSON (default: the paper scene)")
    ap.add_argument("--quick", action="store_true", help="two steps per ladder only")
    ap.add_argument("--out", default=OUT)
    args = ap.parse_args()
    doc = problem_doc(args.problem)
    rows = []
    for carriage, (approx, v, h, kw) in [(c, g) for c in CARRIAGES for g in grid(args.quick)]:
        r = measure(doc, approx, v, h, carriage=carriage, **kw)
        rows.append(r)
        print(f"{carriage:g} {approx:8s} v={v} dt={h:g} tau={r['relaxation_time']:.3g} d={r['hunt_crossley_dissipation']:.3g} "
              f"pen={r['penetration']:g}: w={r['omega_steady']:.6f} (coulomb {r['omega_coulomb']:.6f}, "
              f"pred {r['omega_pred']:.6f} {r['regime']}) rise max {r['rise_max_m']:.3e} steady "
              f"{r['rise_steady_m']:.3e} pred {r['rise_pred_m']:.3e} airborne {r['airborne_share']:.3f} "
              f"loads {[round(r[f'load_mean_{k}'], 3) for k in range(4)]} "
              f"dir {r['direction_err_mean']:.2e} ratio {r['friction_ratio_mean']:.4f} "
              f"w(measured loads) {r['omega_coulomb_measured_loads']:.6f} ({r['wall_s']:.1f} s)",
              file=sys.stderr, flush=True)
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w", newline="") as f:
        keys = list(rows[0].keys())
        w = csv.DictWriter(f, fieldnames=keys, lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})


if __name__ == "__main__":
    main()
