#!/usr/bin/env python3
"""A pushval outside engine in PyBullet (pybullet==3.2.7).

Reads one pushval-problem/1 document on standard input, writes CSV
`t,x,y,theta,omega` (one row per step) on standard output.

Modes:
  --mode forces   the plate floats (no gravity, no ground); every step each
                  support's Coulomb force mu_i N_i, opposite that support's
                  velocity at the step start, is applied with
                  applyExternalForce. Gated like any first-order engine.
  --mode contact  the plate rests on four small spheres (feet, under the
                  supports) on a plane, under gravity; Bullet's own contact
                  friction acts (lateralFriction = mu, the plane's 1, so the
                  product Bullet uses is mu). Informational: Bullet's friction
                  law is not Coulomb's (see adapters/python/README.md).

In both, the pusher is a kinematic body moved each step at
speed * R(theta) (cos phi, sin phi), joined to the plate's contact point by a
point-to-point constraint. Bullet steps semi-implicitly (velocities, then
positions): first order in dt.

In contact mode the constraint must not hold the plate up: a point-to-point
joint fixes all three coordinates, and a pusher at a fixed height carries
part of the weight (the plate then hangs from the pusher and rests on its far
foot: loads 0, 0, 0 and 5 N instead of 2.45 N each). So the pusher is a
fixed-base body with one light link on a free vertical prismatic joint (its
weight cancelled each step), and the joint's pivot sits at the feet's
contact height, so the pushing force does not tip the plate either.
"""

import json
import math
import sys


def main(argv):
    mode = "forces"
    args = list(argv)
    while args:
        a = args.pop(0)
        if a == "--mode":
            mode = args.pop(0)
        else:
            print(f"pybullet_push.py: unknown argument {a!r}", file=sys.stderr)
            return 2
    if mode not in ("forces", "contact"):
        print(f"pybullet_push.py: unknown mode {mode!r} (forces, contact)", file=sys.stderr)
        return 2
    doc = json.load(sys.stdin)
    import pybullet as p  # imported late: its banner goes to stdout otherwise

    rows = simulate(p, doc, mode)
    out = sys.stdout
    out.write("t,x,y,theta,omega\n")
    out.write("\n".join(",".join(map(repr, r)) for r in rows))
    out.write("\n")
    return 0


def simulate(p, doc, mode):
    client = p.connect(p.DIRECT)
    obj = doc["object"]
    m = float(obj["mass"])
    i_cm = float(obj["inertia_cm"])
    cx, cy = obj["center_of_mass"]
    sup = [(s["point"][0] - cx, s["point"][1] - cy, s["mu"], s["normal_force"]) for s in doc["supports"]]
    rc = (doc["contact"]["point"][0] - cx, doc["contact"]["point"][1] - cy)
    dt = float(doc["dt"])
    g = float(doc["gravity"])
    p.setPhysicsEngineParameter(fixedTimeStep=dt, numSubSteps=0, numSolverIterations=50, physicsClientId=client)
    thick = 0.005
    foot = 0.0025
    z0 = foot * 2 + thick / 2 if mode == "contact" else 0.0
    xs = [q[0] - cx for q in obj["polygon"]]
    ys = [q[1] - cy for q in obj["polygon"]]
    half = [(max(xs) - min(xs)) / 2, (max(ys) - min(ys)) / 2, thick / 2]
    plate_shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    links = []
    if mode == "contact":
        # Feet: small spheres fixed under the supports (massless links would
        # change the inertia, so they are tiny compound children instead).
        foot_shape = p.createCollisionShape(p.GEOM_SPHERE, radius=foot, physicsClientId=client)
        links = [(foot_shape, (sx, sy, -thick / 2 - foot)) for sx, sy, _, _ in sup]
    ini = doc["initial"]
    th0 = float(ini["theta"])
    body = p.createMultiBody(
        baseMass=m,
        baseCollisionShapeIndex=plate_shape if mode == "contact" else -1,
        basePosition=[ini["position"][0], ini["position"][1], z0],
        baseOrientation=p.getQuaternionFromEuler([0, 0, th0]),
        linkMasses=[1e-9] * len(links),
        linkCollisionShapeIndices=[s for s, _ in links],
        linkVisualShapeIndices=[-1] * len(links),
        linkPositions=[pos for _, pos in links],
        linkOrientations=[[0, 0, 0, 1]] * len(links),
        linkInertialFramePositions=[[0, 0, 0]] * len(links),
        linkInertialFrameOrientations=[[0, 0, 0, 1]] * len(links),
        linkParentIndices=[0] * len(links),
        linkJointTypes=[p.JOINT_FIXED] * len(links),
        linkJointAxis=[[0, 0, 1]] * len(links),
        physicsClientId=client,
    )
    # The plate's inertia about z is the problem's; x and y large enough
    # that it does not rock on its feet (and that rocking adds little to a
    # friction row's effective mass: (h/1)^2/(100 I_cm), h = 7.5 mm).
    p.changeDynamics(
        body, -1, localInertiaDiagonal=[100 * i_cm, 100 * i_cm, i_cm],
        linearDamping=0, angularDamping=0, physicsClientId=client,
    )
    if mode == "contact":
        plane = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client)
        ground = p.createMultiBody(0, plane, physicsClientId=client)
        p.changeDynamics(ground, -1, lateralFriction=1.0, physicsClientId=client)
        mus = [s[2] for s in sup]
        for j in range(len(links)):
            p.changeDynamics(body, j, lateralFriction=mus[j], physicsClientId=client)
        p.changeDynamics(body, -1, lateralFriction=0.0, physicsClientId=client)
        p.setGravity(0, 0, -g, physicsClientId=client)
        # Settle on the feet before the clock starts.
        for _ in range(int(0.2 / dt)):
            p.stepSimulation(physicsClientId=client)
        p.resetBasePositionAndOrientation(
            body, [ini["position"][0], ini["position"][1], p.getBasePositionAndOrientation(body, physicsClientId=client)[0][2]],
            p.getQuaternionFromEuler([0, 0, th0]), physicsClientId=client)
    # The pusher: a kinematic (mass 0) point moved each step, joined to the
    # contact point. In contact mode the joint acts at the feet's contact
    # height through a light link free to slide vertically (see the top).
    zp = -(thick / 2 + 2 * foot) if mode == "contact" else 0.0
    base = contact_world(body, rc, p, client)
    base[2] += zp
    slider_mass = 1e-3
    if mode == "contact":
        pusher = p.createMultiBody(
            0, -1, basePosition=base,
            linkMasses=[slider_mass], linkCollisionShapeIndices=[-1], linkVisualShapeIndices=[-1],
            linkPositions=[[0, 0, 0]], linkOrientations=[[0, 0, 0, 1]],
            linkInertialFramePositions=[[0, 0, 0]], linkInertialFrameOrientations=[[0, 0, 0, 1]],
            linkParentIndices=[0], linkJointTypes=[p.JOINT_PRISMATIC], linkJointAxis=[[0, 0, 1]],
            physicsClientId=client)
        p.changeDynamics(pusher, 0, linearDamping=0, angularDamping=0, jointDamping=0, physicsClientId=client)
        p.setJointMotorControl2(pusher, 0, p.VELOCITY_CONTROL, force=0, physicsClientId=client)
        cid = p.createConstraint(body, -1, pusher, 0, p.JOINT_POINT2POINT, [0, 0, 0], [rc[0], rc[1], zp], [0, 0, 0], physicsClientId=client)
    else:
        pusher = p.createMultiBody(0, -1, basePosition=base, physicsClientId=client)
        cid = p.createConstraint(body, -1, pusher, -1, p.JOINT_POINT2POINT, [0, 0, 0], [rc[0], rc[1], 0], [0, 0, 0], physicsClientId=client)
    p.changeConstraint(cid, maxForce=1e6, erp=0.8, physicsClientId=client)

    pushes = doc["pushes"]
    w0 = 0.0 if ini["from_rest"] else float(ini["omega"])
    set_velocity(body, pushes[0], th0, w0, rc, p, client, moving=not ini["from_rest"])
    rows = [(0.0, ini["position"][0], ini["position"][1], th0, w0)]
    th_unwrapped = th0
    for push in pushes:
        n = max(1, round(push["duration"] / dt))
        h = push["duration"] / n
        p.setPhysicsEngineParameter(fixedTimeStep=h, physicsClientId=client)
        for j in range(n):
            pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
            yaw = p.getEulerFromQuaternion(orn)[2]
            if mode == "forces":
                v, w = p.getBaseVelocity(body, physicsClientId=client)
                c, s = math.cos(yaw), math.sin(yaw)
                for sx, sy, mu, nf in sup:
                    px, py = c * sx - s * sy, s * sx + c * sy
                    ux, uy = v[0] - w[2] * py, v[1] + w[2] * px
                    norm = math.hypot(ux, uy)
                    if norm > 1e-15:
                        f = mu * nf / norm
                        p.applyExternalForce(body, -1, [-f * ux, -f * uy, 0],
                                             [pos[0] + px, pos[1] + py, pos[2]], p.WORLD_FRAME,
                                             physicsClientId=client)
            a = yaw + push["phi"]
            pp = p.getBasePositionAndOrientation(pusher, physicsClientId=client)[0]
            target = [pp[0] + h * push["speed"] * math.cos(a), pp[1] + h * push["speed"] * math.sin(a), pp[2]]
            p.resetBasePositionAndOrientation(pusher, target, [0, 0, 0, 1], physicsClientId=client)
            if mode == "contact":
                p.applyExternalForce(pusher, 0, [0, 0, slider_mass * g], [0, 0, 0], p.LINK_FRAME, physicsClientId=client)
            p.stepSimulation(physicsClientId=client)
            pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
            v, w = p.getBaseVelocity(body, physicsClientId=client)
            yaw = p.getEulerFromQuaternion(orn)[2]
            th_unwrapped += math.remainder(yaw - th_unwrapped, 2 * math.pi)
            rows.append((push["t_start"] + (j + 1) * h, pos[0], pos[1], th_unwrapped, w[2]))
    p.disconnect(physicsClientId=client)
    return rows


def contact_world(body, rc, p, client):
    pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
    yaw = p.getEulerFromQuaternion(orn)[2]
    c, s = math.cos(yaw), math.sin(yaw)
    return [pos[0] + c * rc[0] - s * rc[1], pos[1] + s * rc[0] + c * rc[1], pos[2]]


def set_velocity(body, push, th, w, rc, p, client, moving):
    """The plate moving with the pusher at omega = w (not from rest)."""
    if not moving:
        return
    c, s = math.cos(th), math.sin(th)
    px, py = c * rc[0] - s * rc[1], s * rc[0] + c * rc[1]
    a = th + push["phi"]
    vx, vy = push["speed"] * math.cos(a) + w * py, push["speed"] * math.sin(a) - w * px
    p.resetBaseVelocity(body, [vx, vy, 0], [0, 0, w], physicsClientId=client)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
