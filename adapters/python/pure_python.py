#!/usr/bin/env python3
"""A pushval outside engine in plain Python (no dependencies).

Reads one pushval-problem/1 document on standard input, writes CSV
`t,x,y,theta,omega` (one row per step, the first at t = 0) on standard output.

The scene: a rigid plate sliding on its support points, each with a Coulomb
force of magnitude mu_i N_i opposite its own sliding velocity, evaluated at
the start of the step (explicit). The pusher is a velocity constraint: the
contact point moves at speed * R(theta) (cos phi, sin phi). With that
constraint the plate has one degree of freedom, omega, and (angular momentum
about the contact point)

    (I_cm + m |rho_c|^2) domega/dt = m omega (rho_c . v_p) + sum (rho_i - rho_c) x f_i

(rho: world-frame offsets from the centre of mass). A step is semi-implicit
Euler: omega first, then theta with the new omega, then the centre of mass
with the velocity the constraint gives at the new pose. First order in dt.
When the pusher velocity jumps (every segment start; the start too when the
object starts from rest), the contact impulse has no moment about the
contact point, so the angular momentum about it is kept and omega jumps.

Options (command line, for tests and measurements):
  --scheme euler|heun the step: semi-implicit Euler (default, first order) or
                      Heun's method on (theta, omega, x, y) (second order;
                      declare order = 2 for it)
  --inertia-scale S   multiply I_cm by S (a deliberately wrong engine)
  --timing            print the stepping time on standard error
"""

import json
import math
import sys
import time


def main(argv):
    inertia_scale = 1.0
    timing = False
    scheme = "euler"
    args = list(argv)
    while args:
        a = args.pop(0)
        if a == "--inertia-scale":
            inertia_scale = float(args.pop(0))
        elif a == "--timing":
            timing = True
        elif a == "--scheme":
            scheme = args.pop(0)
            if scheme not in ("euler", "heun"):
                print(f"pure_python.py: unknown scheme {scheme!r} (euler, heun)", file=sys.stderr)
                return 2
        else:
            print(f"pure_python.py: unknown argument {a!r}", file=sys.stderr)
            return 2
    doc = json.load(sys.stdin)
    if doc.get("format") != "pushval-problem/1":
        print(f"pure_python.py: unsupported format {doc.get('format')!r}", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    rows = simulate(doc, inertia_scale, scheme)
    t1 = time.perf_counter()
    out = sys.stdout
    out.write("t,x,y,theta,omega\n")
    out.write("\n".join(",".join(map(repr, r)) for r in rows))
    out.write("\n")
    out.flush()
    if timing:
        print(f"step_time_s={t1 - t0!r} steps={len(rows) - 1}", file=sys.stderr)
    return 0


def simulate(doc, inertia_scale=1.0, scheme="euler"):
    obj = doc["object"]
    m = float(obj["mass"])
    i_cm = float(obj["inertia_cm"]) * inertia_scale
    cx, cy = obj["center_of_mass"]
    # Body-frame offsets from the centre of mass.
    sup = [(p["point"][0] - cx, p["point"][1] - cy, p["mu"] * p["normal_force"]) for p in doc["supports"]]
    rcx = doc["contact"]["point"][0] - cx
    rcy = doc["contact"]["point"][1] - cy
    i_p = i_cm + m * (rcx * rcx + rcy * rcy)
    ini = doc["initial"]
    x, y = ini["position"]
    th = float(ini["theta"])
    w = 0.0 if ini["from_rest"] else float(ini["omega"])
    dt = float(doc["dt"])
    # The pusher velocity before the first segment: at rest, or moving with
    # the first push (no jump).
    prev = None if ini["from_rest"] else doc["pushes"][0]
    rows = []

    def pusher(push, th):
        a = th + push["phi"]
        return push["speed"] * math.cos(a), push["speed"] * math.sin(a)

    def momentum(push, w):
        # Angular momentum about the contact point, body frame (rotation
        # invariant): I_P w - m v_c (r_c x n_phi).
        if push is None:
            return i_p * w
        nx, ny = math.cos(push["phi"]), math.sin(push["phi"])
        return i_p * w - m * push["speed"] * (rcx * ny - rcy * nx)

    def cm_velocity(push, th, w):
        c, s = math.cos(th), math.sin(th)
        px, py = c * rcx - s * rcy, s * rcx + c * rcy
        vpx, vpy = pusher(push, th)
        return vpx + w * py, vpy - w * px

    def omega_dot(c, s, pcx, pcy, vpx, vpy, vx, vy, w):
        # Torque about the contact point (times I_P: returns I_P domega/dt).
        torque = m * w * (pcx * vpx + pcy * vpy)
        for sx, sy, f in sup:
            px, py = c * sx - s * sy, s * sx + c * sy
            ux, uy = vx - w * py, vy + w * px
            norm = math.hypot(ux, uy)
            if norm > 1e-15:
                fx, fy = -f * ux / norm, -f * uy / norm
                torque += (px - pcx) * fy - (py - pcy) * fx
        return torque

    def rates(th, w, speed, phi):
        c, s = math.cos(th), math.sin(th)
        pcx, pcy = c * rcx - s * rcy, s * rcx + c * rcy
        vpx, vpy = speed * math.cos(th + phi), speed * math.sin(th + phi)
        vx, vy = vpx + w * pcy, vpy - w * pcx
        return w, omega_dot(c, s, pcx, pcy, vpx, vpy, vx, vy, w) / i_p, vx, vy

    for k, push in enumerate(doc["pushes"]):
        h_total = float(push["duration"])
        n = max(1, round(h_total / dt))
        h = h_total / n
        if push is not prev:
            hm = momentum(prev, w)
            nx, ny = math.cos(push["phi"]), math.sin(push["phi"])
            w = (hm + m * push["speed"] * (rcx * ny - rcy * nx)) / i_p
        prev = push
        if k == 0:
            rows.append((0.0, x, y, th, w))
        speed = push["speed"]
        phi = push["phi"]
        t_start = float(push["t_start"])
        if scheme == "heun":
            for j in range(n):
                d1 = rates(th, w, speed, phi)
                d2 = rates(th + h * d1[0], w + h * d1[1], speed, phi)
                th += 0.5 * h * (d1[0] + d2[0])
                w += 0.5 * h * (d1[1] + d2[1])
                x += 0.5 * h * (d1[2] + d2[2])
                y += 0.5 * h * (d1[3] + d2[3])
                rows.append((t_start + (j + 1) * h, x, y, th, w))
            continue
        for j in range(n):
            c, s = math.cos(th), math.sin(th)
            pcx, pcy = c * rcx - s * rcy, s * rcx + c * rcy
            vpx, vpy = speed * math.cos(th + phi), speed * math.sin(th + phi)
            vx, vy = vpx + w * pcy, vpy - w * pcx
            w += h * omega_dot(c, s, pcx, pcy, vpx, vpy, vx, vy, w) / i_p
            th += h * w
            vx, vy = cm_velocity(push, th, w)
            x += h * vx
            y += h * vy
            rows.append((t_start + (j + 1) * h, x, y, th, w))
    return rows


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
