#!/usr/bin/env python3
"""A pushval outside engine written without the adapter kit: protocol 1 only.

What a user's own adapter looks like when it speaks pushval-problem/1 by
hand (any language would do the same): read one JSON document from standard
input to its end, write CSV `t,x,y,theta,omega` to standard output (the row
at t = 0, then one row per step), exit 0; on a document it cannot run,
print the reason on standard error and exit 1. It knows nothing of sessions,
request numbers or stepping: pushval advances it push by push by re-running
the schedule applied so far (a replay, which its outputs say), so it can
still be the plant of `pushval loop`.

The physics is pure_python.py's semi-implicit Euler (Coulomb force per
support, the pusher a velocity constraint, impulsive or continuous
switches), written out line for line so that the two agree to the last bit:
tests compare them.
"""

import json
import math
import sys


def main():
    doc = json.load(sys.stdin)
    if doc.get("format") not in ("pushval-problem/1", "pushval-problem/2"):
        print(f"plain_protocol1.py: format {doc.get('format')!r} is not pushval-problem/1", file=sys.stderr)
        return 1
    obj = doc["object"]
    m, i_cm = obj["mass"], obj["inertia_cm"]
    cx, cy = obj["center_of_mass"]
    rcx, rcy = doc["contact"]["point"][0] - cx, doc["contact"]["point"][1] - cy
    sup = [(s["point"][0] - cx, s["point"][1] - cy, s["mu"] * s["normal_force"]) for s in doc["supports"]]
    i_p = i_cm + m * (rcx * rcx + rcy * rcy)
    continuous = doc.get("switching", "impulsive") == "continuous"
    dt = doc["dt"]
    ini = doc["initial"]
    x, y = ini["position"]
    th = ini["theta"]

    def momentum(push, w):
        # Angular momentum about the contact point, object frame.
        h = i_p * w
        if push is None:
            return h
        return h - m * push["speed"] * (rcx * math.sin(push["phi"]) - rcy * math.cos(push["phi"]))

    def after_switch(before, after, w):
        if continuous:
            return w
        lin = m * after["speed"] * (rcx * math.sin(after["phi"]) - rcy * math.cos(after["phi"]))
        return (momentum(before, w) + lin) / i_p

    pushes = doc["pushes"]
    w = after_switch(None, pushes[0], 0.0) if ini["from_rest"] else ini["omega"]
    out = ["t,x,y,theta,omega", f"{0.0!r},{x!r},{y!r},{th!r},{w!r}"]
    before = None
    for push in pushes:
        if before is not None:
            w = after_switch(before, push, w)
        before = push
        speed, phi = push["speed"], push["phi"]
        n = max(1, round(push["duration"] / dt))
        h = push["duration"] / n
        t0 = push["t_start"]
        for j in range(1, n + 1):
            c, s = math.cos(th), math.sin(th)
            pcx, pcy = c * rcx - s * rcy, s * rcx + c * rcy
            vpx, vpy = speed * math.cos(th + phi), speed * math.sin(th + phi)
            vx, vy = vpx + w * pcy, vpy - w * pcx
            torque = m * w * (pcx * vpx + pcy * vpy)
            for sx, sy, f in sup:
                px, py = c * sx - s * sy, s * sx + c * sy
                ux, uy = vx - w * py, vy + w * px
                norm = math.hypot(ux, uy)
                if norm > 1e-15:
                    fx, fy = -f * ux / norm, -f * uy / norm
                    torque += (px - pcx) * fy - (py - pcy) * fx
            w += h * torque / i_p
            th += h * w
            c, s = math.cos(th), math.sin(th)
            pcx, pcy = c * rcx - s * rcy, s * rcx + c * rcy
            a = th + phi
            vpx, vpy = speed * math.cos(a), speed * math.sin(a)
            x += h * (vpx + w * pcy)
            y += h * (vpy - w * pcx)
            t = t0 + push["duration"] if j == n else t0 + j * h
            out.append(f"{t!r},{x!r},{y!r},{th!r},{w!r}")
    sys.stdout.write("\n".join(out) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
