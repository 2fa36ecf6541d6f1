#!/usr/bin/env python3
"""A pushval outside engine in MuJoCo's Python bindings (mujoco==4.0.0).

Reads one pushval-problem/1 document on standard input, writes CSV
`t,x,y,theta,omega` (one row per step, the first at t = 0) on standard output.

The scene is the one of pushval's compiled-in MuJoCo 3.17 adapter
(crates/mujoco/src/scene.rs and sim.rs), so the two versions can be run side
by side on one problem:

  * the object: a free body (mass m, inertia I_cm about z, half that about x
    and y) with its centre of mass at floor height, on one sphere foot
    (radius 5 mm, condim 3) under each support, on a frictionless plane;
  * the pusher: a carriage (mass 1e6 m) on two horizontal slide joints whose
    velocity is set every step to speed * R(theta_mid) (cos phi, sin phi)
    (theta_mid: the object's yaw extrapolated to the step's middle), and a
    light gravity-compensated tip (1e-3 m) on a vertical slide, joined to
    the object's contact point by a connect constraint (time constant 2 dt);
  * the friction: the plate first settles 0.3 s at rest; each foot's
    friction coefficient is then set to mu_i N_i / (its load at rest), so
    that mu times MuJoCo's load is the force the problem asks for;
  * the solver: timestep dt (each segment's duration / its step count),
    Euler integrator (semi-implicit: omega after a step is the one held over
    it), 100 iterations, impratio 1, no noslip, contact solref 0.02 1 and
    solimp 0.9 0.95 0.001 0.5 2.

Options:
  --cone pyramidal|elliptic   MuJoCo's friction cone (default pyramidal)
"""

import json
import math
import sys

FOOT_RADIUS = 0.005
CARRIAGE_MASS_RATIO = 1e6
TIP_MASS_RATIO = 1e-3
SETTLE_TIME = 0.3
SOLREF = (0.02, 1.0)
SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)


def main(argv):
    cone = "pyramidal"
    args = list(argv)
    while args:
        a = args.pop(0)
        if a == "--cone" and args:
            cone = args.pop(0)
        else:
            print(f"mujoco_push.py: unknown argument {a!r}", file=sys.stderr)
            return 2
    if cone not in ("pyramidal", "elliptic"):
        print(f"mujoco_push.py: unknown cone {cone!r} (pyramidal, elliptic)", file=sys.stderr)
        return 2
    doc = json.load(sys.stdin)
    if doc.get("format") != "pushval-problem/1":
        print(f"mujoco_push.py: unsupported format {doc.get('format')!r}", file=sys.stderr)
        return 2
    import mujoco

    # For the record (pushval shows an adapter's stderr only on errors).
    print(f"mujoco_push.py: MuJoCo {mujoco.mj_versionString()}, {cone} cone", file=sys.stderr)
    rows = simulate(mujoco, doc, cone)
    out = sys.stdout
    out.write("t,x,y,theta,omega\n")
    out.write("\n".join(",".join(map(repr, r)) for r in rows))
    out.write("\n")
    return 0


def mjcf(doc, cone, dt, mus):
    """The scene's MJCF, the object at its initial pose (crates/mujoco/src/scene.rs)."""
    obj = doc["object"]
    m = float(obj["mass"])
    i_z = float(obj["inertia_cm"])
    cx, cy = obj["center_of_mass"]
    ini = doc["initial"]
    th = float(ini["theta"])
    px, py = ini["position"]
    rc = (doc["contact"]["point"][0] - cx, doc["contact"]["point"][1] - cy)
    c, s = math.cos(th), math.sin(th)
    kx, ky = px + c * rc[0] - s * rc[1], py + s * rc[0] + c * rc[1]
    qc, qs = math.cos(0.5 * th), math.sin(0.5 * th)
    g = float(doc["gravity"])
    r = FOOT_RADIUS
    si = " ".join(map(repr, SOLIMP))
    sr = " ".join(map(repr, SOLREF))
    x = ['<mujoco model="pushval">', '  <compiler angle="radian"/>',
         f'  <option timestep="{dt!r}" gravity="0 0 {-g!r}" cone="{cone}" impratio="1" '
         f'iterations="100" noslip_iterations="0" integrator="Euler"/>',
         '  <worldbody>',
         f'    <geom name="floor" type="plane" size="0 0 1" friction="0 0 0" condim="3" solref="{sr}" solimp="{si}"/>',
         f'    <body name="object" pos="{px!r} {py!r} 0" quat="{qc!r} 0 0 {qs!r}">',
         '      <freejoint name="object"/>',
         f'      <inertial pos="0 0 0" mass="{m!r}" diaginertia="{0.5 * i_z!r} {0.5 * i_z!r} {i_z!r}"/>']
    for k, sup in enumerate(doc["supports"]):
        sx, sy = sup["point"][0] - cx, sup["point"][1] - cy
        x.append(f'      <geom name="foot{k}" type="sphere" size="{r!r}" pos="{sx!r} {sy!r} {r!r}" mass="0" '
                 f'friction="{mus[k]!r} 0 0" condim="3" priority="1" solref="{sr}" solimp="{si}"/>')
    x.append(f'      <site name="contact" pos="{rc[0]!r} {rc[1]!r} 0"/>')
    x.append('    </body>')
    mc = CARRIAGE_MASS_RATIO * m
    mt = TIP_MASS_RATIO * m
    x += [f'    <body name="carriage" pos="{kx!r} {ky!r} 0">',
          '      <joint name="carriage_x" type="slide" axis="1 0 0"/>',
          '      <joint name="carriage_y" type="slide" axis="0 1 0"/>',
          f'      <inertial pos="0 0 0" mass="{mc!r}" diaginertia="{mc!r} {mc!r} {mc!r}"/>',
          '      <body name="tip" pos="0 0 0" gravcomp="1">',
          '        <joint name="tip_z" type="slide" axis="0 0 1"/>',
          f'        <inertial pos="0 0 0" mass="{mt!r}" diaginertia="{mt * 1e-4!r} {mt * 1e-4!r} {mt * 1e-4!r}"/>',
          '        <site name="tip"/>',
          '      </body>',
          '    </body>',
          '  </worldbody>',
          '  <equality>',
          f'    <connect site1="contact" site2="tip" solref="{2 * dt!r} 1" solimp="0.99 0.999 0.001 0.5 2"/>',
          '  </equality>',
          '</mujoco>']
    return "\n".join(x)


OBJECT = 1
CARRIAGE_DOF = 6


def yaw_and_omega(data):
    mat = data.xmat[OBJECT]
    wl = data.qvel[3:6]
    # Free joint: angular velocity in the body frame; world z = row 3 of R.
    wz = mat[6] * wl[0] + mat[7] * wl[1] + mat[8] * wl[2]
    return math.atan2(mat[3], mat[0]), float(wz)


def simulate(mujoco, doc, cone):
    dt = float(doc["dt"])
    sup = doc["supports"]
    n = len(sup)
    forces = [float(s["mu"]) * float(s["normal_force"]) for s in sup]
    model = mujoco.MjModel.from_xml_string(mjcf(doc, cone, dt, [1.0] * n))
    data = mujoco.MjData(model)
    # 1. Settle at rest; calibrate each foot's coefficient to its load.
    for _ in range(math.ceil(SETTLE_TIME / dt)):
        mujoco.mj_step(model, data)
    loads = [0.0] * n
    import numpy as np

    f6 = np.zeros(6)
    for i in range(data.ncon):
        con = data.contact[i]
        gi = max(con.geom[0], con.geom[1])
        if 1 <= gi <= n:
            mujoco.mj_contactForce(model, data, i, f6)
            loads[gi - 1] += f6[0]
    for k in range(n):
        if forces[k] == 0.0:
            model.geom_friction[k + 1][0] = 0.0
            continue
        if not loads[k] > 1e-9:
            raise SystemExit(f"mujoco_push.py: support {k} carries no load at rest ({loads[k]} N)")
        model.geom_friction[k + 1][0] = forces[k] / loads[k]

    # 2. The start.
    obj = doc["object"]
    cx, cy = obj["center_of_mass"]
    pc = (doc["contact"]["point"][0] - cx, doc["contact"]["point"][1] - cy)
    ini = doc["initial"]
    pushes = doc["pushes"]
    yaw, _ = yaw_and_omega(data)

    def command(yaw, push):
        a = yaw + float(push["phi"])
        return push["speed"] * math.cos(a), push["speed"] * math.sin(a)

    if ini["from_rest"]:
        lin, w = (0.0, 0.0), 0.0
    else:
        w = float(ini["omega"])
        p0 = pushes[0]
        vcx, vcy = p0["speed"] * math.cos(p0["phi"]), p0["speed"] * math.sin(p0["phi"])
        lx, ly = vcx + w * pc[1], vcy - w * pc[0]
        c, s = math.cos(yaw), math.sin(yaw)
        lin = (c * lx - s * ly, s * lx + c * ly)
    mat = data.xmat[OBJECT]
    data.qvel[0:3] = [lin[0], lin[1], 0.0]
    data.qvel[3:6] = [mat[6] * w, mat[7] * w, mat[8] * w]
    cvx, cvy = command(yaw, pushes[0])
    data.qvel[CARRIAGE_DOF:CARRIAGE_DOF + 3] = [cvx, cvy, 0.0]

    theta = float(ini["theta"]) + math.remainder(yaw - float(ini["theta"]), 2 * math.pi)
    rows = [(0.0, float(data.qpos[0]), float(data.qpos[1]), theta, 0.0 if ini["from_rest"] else w)]
    t = 0.0
    for push in pushes:
        nk = max(1, math.ceil(push["duration"] / dt * (1.0 - 1e-12)))
        hk = push["duration"] / nk
        model.opt.timestep = hk
        t_seg = t
        for k in range(nk):
            yaw, wz = yaw_and_omega(data)
            cvx, cvy = command(yaw + 0.5 * hk * wz, push)
            data.qvel[CARRIAGE_DOF] = cvx
            data.qvel[CARRIAGE_DOF + 1] = cvy
            mujoco.mj_step(model, data)
            t = t_seg + push["duration"] if k + 1 == nk else t_seg + (k + 1) * hk
            yaw, wz = yaw_and_omega(data)
            theta += math.remainder(yaw - theta, 2 * math.pi)
            rows.append((t, float(data.qpos[0]), float(data.qpos[1]), theta, float(wz)))
        for name in ("mjWARN_BADQACC", "mjWARN_BADQVEL", "mjWARN_BADQPOS"):
            if data.warning[getattr(mujoco.mjtWarning, name)].number > 0:
                raise SystemExit(f"mujoco_push.py: MuJoCo warned {name} at t = {t}: the run is unstable")
    return rows


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
