#!/usr/bin/env python3
"""A pushval outside engine in PyBullet (pybullet==3.2.7).

One row per Bullet step, with the columns load_1..load_n (N, the problem's
support order) and rise (m): in contact mode each foot's normal force in the
step (getContactPoints' normalForce, summed per foot) and the plate's centre
of mass above its settled height; in forces mode the loads the applied
Coulomb forces use (the problem's) and the height above its start (the plate
floats: 0 unless the constraint moves it). The protocol (one-shot or --session, limits,
progress, --timing) is pushval.adapter's (adapters/python/README.md). Bullet's
contact makes the pusher's velocity jumps itself: impulsive switching only.

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

Released (protocol 3's release; the step receives no push), the pusher's
constraint is removed and the plate slides freely. In forces mode each
step's support impulses are implicit Coulomb friction (coulomb_slide.py:
each within its disc |P_i| <= mu_i N_i h, jointly the ones that leave the
supports' slip zero where the discs allow), given to the plate as its
velocity before Bullet's step moves the pose: a plate one step can stop comes
to rest instead of its slip reversing every step. In contact mode Bullet's
own contact friction slides it: velocity-level friction rows whose impulses
are clamped by mu lambda, so a slip one step can remove is removed and the
plate sticks. A plate thrown without pushes starts with its initial velocity
and omega.

In contact mode the constraint must not hold the plate up: a point-to-point
joint fixes all three coordinates, and a pusher at a fixed height carries
part of the weight (the plate then hangs from the pusher and rests on its far
foot: loads 0, 0, 0 and 5 N instead of 2.45 N each). So the pusher is a
fixed-base body with one light link on a free vertical prismatic joint (its
weight cancelled each step), and the joint's pivot sits at the feet's
contact height, so the pushing force does not tip the plate either.

The `[engine]` option `pusher = "fixed_height"` (contact mode) builds that
pitfall on purpose, for the study's variant that measures it: the pusher a
plain kinematic point at the contact point's height, joined by the
point-to-point constraint, which then carries part of the plate's weight.
"""

import math
import os
import sys

try:
    from pushval.adapter import AdapterError, Engine, State, main
except ImportError:  # run from the source tree without the wheel installed
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
    from pushval.adapter import AdapterError, Engine, State, main

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from coulomb_slide import coulomb_impulses  # noqa: E402

THICK = 0.005
FOOT = 0.0025
SLIDER_MASS = 1e-3
SETTLE_AGAIN = 0.3


class PyBulletPush(Engine):
    """A plate pushed in PyBullet 3.2.7 (forces or Bullet's own contact)."""

    name = "pybullet_push.py"
    step_rule = "round"
    switching_rules = ("impulsive",)
    can_release = True

    @classmethod
    def add_arguments(cls, parser):
        parser.add_argument(
            "--mode",
            choices=("forces", "contact"),
            default="forces",
            help="forces: Coulomb forces per support applied by hand; "
            "contact: Bullet's own contact friction on four feet",
        )

    def __init__(self, args=None):
        super().__init__(args)
        try:
            import pybullet
        except ImportError as e:
            raise AdapterError(f"{e}; install it with scripts/setup-adapters.sh") from None
        self.p = pybullet
        self.client = None

    def reset(self, problem):
        p = self.p
        mode = self.args.mode
        client = self.client = p.connect(p.DIRECT)
        m = problem.mass
        i_cm = problem.inertia_cm
        cx, cy = problem.center_of_mass
        self.sup = sup = [(s.offset[0], s.offset[1], s.mu, s.normal_force) for s in problem.supports]
        self.rc = rc = problem.contact_offset
        dt = problem.dt
        self.g = g = problem.gravity
        p.setPhysicsEngineParameter(fixedTimeStep=dt, numSubSteps=0, numSolverIterations=50, physicsClientId=client)
        self.h = dt
        z0 = FOOT * 2 + THICK / 2 if mode == "contact" else 0.0
        xs = [q[0] - cx for q in problem.polygon]
        ys = [q[1] - cy for q in problem.polygon]
        half = [(max(xs) - min(xs)) / 2, (max(ys) - min(ys)) / 2, THICK / 2]
        plate_shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
        links = []
        if mode == "contact":
            # Feet: small spheres fixed under the supports (massless links would
            # change the inertia, so they are tiny compound children instead).
            foot_shape = p.createCollisionShape(p.GEOM_SPHERE, radius=FOOT, physicsClientId=client)
            links = [(foot_shape, (sx, sy, -THICK / 2 - FOOT)) for sx, sy, _, _ in sup]
        ini = problem.initial
        th0 = ini.theta
        self.body = body = p.createMultiBody(
            baseMass=m,
            baseCollisionShapeIndex=plate_shape if mode == "contact" else -1,
            basePosition=[ini.position[0], ini.position[1], z0],
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
            # Settle on the feet before the clock starts: 0.2 s from the
            # drop, the pose put back level at the initial x, y and yaw (the
            # settled height kept), then SETTLE_AGAIN s more. The drop's
            # rest is not the statics: Bullet keeps the feet's unequal
            # landing penetrations and reports loads that do not balance
            # the weight's moment (a three-foot plate: 5.84, 6.38, 7.42 N
            # against the statics' 6.16, 6.67, 6.79 N, unchanged after 0.5 s);
            # from the level pose it comes to rest near the statics. The
            # last reset keeps that rest's height, roll and pitch and only
            # puts x, y and yaw back (about 1e-7 of drift).
            for _ in range(int(0.2 / dt)):
                p.stepSimulation(physicsClientId=client)
            z0 = p.getBasePositionAndOrientation(body, physicsClientId=client)[0][2]
            p.resetBasePositionAndOrientation(
                body, [ini.position[0], ini.position[1], z0],
                p.getQuaternionFromEuler([0, 0, th0]), physicsClientId=client)
            for _ in range(int(SETTLE_AGAIN / dt)):
                p.stepSimulation(physicsClientId=client)
            self.ground = ground
            rest_loads = self.foot_loads()
            pos0, orn0 = p.getBasePositionAndOrientation(body, physicsClientId=client)
            z0 = pos0[2]
            roll, pitch, _ = p.getEulerFromQuaternion(orn0)
            p.resetBasePositionAndOrientation(
                body, [ini.position[0], ini.position[1], z0],
                p.getQuaternionFromEuler([roll, pitch, th0]), physicsClientId=client)
        else:
            rest_loads = [s[3] for s in sup]
        self.rest_height = z0
        self.row_extras = (*rest_loads, 0.0)
        # The pusher: a kinematic (mass 0) point moved each step, joined to the
        # contact point. In contact mode the joint acts at the feet's contact
        # height through a light link free to slide vertically (see the top).
        pusher_kind = problem.options.get("pusher", "sliding")
        if pusher_kind not in ("sliding", "fixed_height"):
            raise AdapterError(f'[engine] pusher = "{pusher_kind}": expected "sliding" or "fixed_height"')
        fixed = mode == "forces" or pusher_kind == "fixed_height"
        zp = -(THICK / 2 + 2 * FOOT) if not fixed else 0.0
        base = self.contact_world()
        base[2] += zp
        self.slider = not fixed
        if not fixed:
            pusher = p.createMultiBody(
                0, -1, basePosition=base,
                linkMasses=[SLIDER_MASS], linkCollisionShapeIndices=[-1], linkVisualShapeIndices=[-1],
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
        self.pusher = pusher
        self.constraint = cid
        self.mass, self.i_cm = m, i_cm

        w0 = 0.0 if ini.from_rest else ini.omega
        if not problem.pushes:
            # Thrown: the slide starts with the initial velocity and omega.
            vx, vy = ini.velocity
            p.resetBaseVelocity(body, [vx, vy, 0], [0, 0, ini.omega], physicsClientId=client)
        elif not ini.from_rest:
            # The plate moving with the first push at omega = w0.
            c, s = math.cos(th0), math.sin(th0)
            px, py = c * rc[0] - s * rc[1], s * rc[0] + c * rc[1]
            vpx, vpy = problem.pushes[0].world_velocity(th0)
            p.resetBaseVelocity(body, [vpx + w0 * py, vpy - w0 * px, 0], [0, 0, w0], physicsClientId=client)
        self.theta = th0
        return State(ini.position[0], ini.position[1], th0, w0)

    def foot_loads(self):
        """Each foot's normal force (N) in the step just taken (contact
        mode): getContactPoints' normalForce (Bullet's applied impulse / dt)
        summed over the contacts of that foot's link with the ground."""
        loads = [0.0] * len(self.sup)
        for c in self.p.getContactPoints(self.body, self.ground, physicsClientId=self.client):
            j = c[3]  # linkIndexA: the foot
            if 0 <= j < len(loads):
                loads[j] += c[9]
        return loads

    def extra_columns(self, problem):
        return (*(f"load_{i + 1}" for i in range(len(problem.supports))), "rise")

    def extras(self):
        return self.row_extras

    def contact_world(self):
        """The contact point in the world, at the plate's height."""
        p = self.p
        pos, orn = p.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        yaw = p.getEulerFromQuaternion(orn)[2]
        c, s = math.cos(yaw), math.sin(yaw)
        rc = self.rc
        return [pos[0] + c * rc[0] - s * rc[1], pos[1] + s * rc[0] + c * rc[1], pos[2]]

    def slide(self, yaw, h):
        """Forces mode, released: the step's implicit Coulomb support
        impulses, given to the plate as its velocity before the step."""
        p, client, body = self.p, self.client, self.body
        v, w = p.getBaseVelocity(body, physicsClientId=client)
        c, s = math.cos(yaw), math.sin(yaw)
        sup = [((c * sx - s * sy, s * sx + c * sy), max(mu * nf, 0.0) * h) for sx, sy, mu, nf in self.sup]
        _, (vx, vy), wz = coulomb_impulses(self.mass, self.i_cm, (v[0], v[1]), w[2], sup)
        p.resetBaseVelocity(body, [vx, vy, v[2]], [w[0], w[1], wz], physicsClientId=client)

    def step(self, push, h):
        p, client, body = self.p, self.client, self.body
        if h != self.h:
            p.setPhysicsEngineParameter(fixedTimeStep=h, physicsClientId=client)
            self.h = h
        pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
        yaw = p.getEulerFromQuaternion(orn)[2]
        if push is None:
            if self.constraint is not None:
                p.removeConstraint(self.constraint, physicsClientId=client)
                self.constraint = None
            if self.args.mode == "forces":
                self.slide(yaw, h)
            return self.finish_step()
        if self.args.mode == "forces":
            v, w = p.getBaseVelocity(body, physicsClientId=client)
            c, s = math.cos(yaw), math.sin(yaw)
            for sx, sy, mu, nf in self.sup:
                px, py = c * sx - s * sy, s * sx + c * sy
                ux, uy = v[0] - w[2] * py, v[1] + w[2] * px
                norm = math.hypot(ux, uy)
                if norm > 1e-15:
                    f = mu * nf / norm
                    p.applyExternalForce(body, -1, [-f * ux, -f * uy, 0],
                                         [pos[0] + px, pos[1] + py, pos[2]], p.WORLD_FRAME,
                                         physicsClientId=client)
        a = yaw + push.phi
        pp = p.getBasePositionAndOrientation(self.pusher, physicsClientId=client)[0]
        target = [pp[0] + h * push.speed * math.cos(a), pp[1] + h * push.speed * math.sin(a), pp[2]]
        p.resetBasePositionAndOrientation(self.pusher, target, [0, 0, 0, 1], physicsClientId=client)
        if self.slider:
            p.applyExternalForce(self.pusher, 0, [0, 0, SLIDER_MASS * self.g], [0, 0, 0], p.LINK_FRAME, physicsClientId=client)
        return self.finish_step()

    def finish_step(self):
        """Steps Bullet and reads the plate."""
        p, client, body = self.p, self.client, self.body
        p.stepSimulation(physicsClientId=client)
        pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
        v, w = p.getBaseVelocity(body, physicsClientId=client)
        yaw = p.getEulerFromQuaternion(orn)[2]
        self.theta += math.remainder(yaw - self.theta, 2 * math.pi)
        loads = self.foot_loads() if self.args.mode == "contact" else self.row_extras[:-1]
        self.row_extras = (*loads, pos[2] - self.rest_height)
        return State(pos[0], pos[1], self.theta, w[2])

    def close(self):
        if self.client is not None:
            self.p.disconnect(physicsClientId=self.client)
            self.client = None


if __name__ == "__main__":
    main(PyBulletPush)
