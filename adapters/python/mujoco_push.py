#!/usr/bin/env python3
"""A pushval outside engine in MuJoCo's Python bindings (mujoco==4.0.0).

One row per MuJoCo step, with the columns load_1..load_n (each foot's normal
force in the step, mj_contactForce, N, the problem's support order) and rise
(the object's centre of mass above its height at the end of the settling,
m); the protocol (one-shot or --session, limits,
progress, --timing) is pushval.adapter's (adapters/python/README.md). MuJoCo's
contact makes the pusher's velocity jumps itself: impulsive switching only.

The scene is the one of pushval's compiled-in MuJoCo 3.17 adapter
(crates/engines/mujoco/src/scene.rs and sim.rs), so the two versions can be run side
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

Released (protocol 3's release; the step receives no push), the connect is
turned off (data.eq_active) and the carriage stopped: the plate slides on its
feet under MuJoCo's soft contact friction until at rest. Sliding, a foot's
friction is the cone's bound (elliptic: mu N against the slip; pyramidal: the
diamond |f1| + |f2| <= mu N of the world axes); near the stop friction is a
soft constraint, the slip decaying as du/dt = -u/tau, tau = d_max
timeconst/(2 d) (10 to 10.6 ms here), so it never reverses (no chattering)
but the rest comes about 70 ms after Coulomb's stop (as in
crates/engines/mujoco). A plate thrown without pushes starts the slide with
its initial velocity and omega.

Options:
  --cone pyramidal|elliptic   MuJoCo's friction cone (default pyramidal)
"""

import math
import os
import sys

try:
    from pushval.adapter import AdapterError, Engine, State, main
except ImportError:  # run from the source tree without the wheel installed
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
    from pushval.adapter import AdapterError, Engine, State, main

FOOT_RADIUS = 0.005
CARRIAGE_MASS_RATIO = 1e6
TIP_MASS_RATIO = 1e-3
SETTLE_TIME = 0.3
SOLREF = (0.02, 1.0)
SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
OBJECT = 1
CARRIAGE_DOF = 6
UNSTABLE = ("mjWARN_BADQACC", "mjWARN_BADQVEL", "mjWARN_BADQPOS")


def mjcf(problem, cone, dt, mus):
    """The scene's MJCF, the object at its initial pose (crates/engines/mujoco/src/scene.rs)."""
    m = problem.mass
    i_z = problem.inertia_cm
    th = problem.initial.theta
    px, py = problem.initial.position
    rc = problem.contact_offset
    c, s = math.cos(th), math.sin(th)
    kx, ky = px + c * rc[0] - s * rc[1], py + s * rc[0] + c * rc[1]
    qc, qs = math.cos(0.5 * th), math.sin(0.5 * th)
    g = problem.gravity
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
    for k, sup in enumerate(problem.supports):
        sx, sy = sup.offset
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


def foot_loads(mujoco, model, data, n, f6):
    """Each foot's normal force (N) in the step just taken: the sum of
    mj_contactForce's normal component over the foot's contacts (geoms
    1..n are the feet, 0 the floor)."""
    loads = [0.0] * n
    for i in range(data.ncon):
        con = data.contact[i]
        gi = max(con.geom[0], con.geom[1])
        if 1 <= gi <= n:
            mujoco.mj_contactForce(model, data, i, f6)
            loads[gi - 1] += float(f6[0])
    return loads


def yaw_and_omega(data):
    mat = data.xmat[OBJECT]
    wl = data.qvel[3:6]
    # Free joint: angular velocity in the body frame; world z = row 3 of R.
    wz = mat[6] * wl[0] + mat[7] * wl[1] + mat[8] * wl[2]
    return math.atan2(mat[3], mat[0]), float(wz)


class MujocoPush(Engine):
    """The scene of crates/engines/mujoco in MuJoCo 4's Python bindings."""

    name = "mujoco_push.py"
    switching_rules = ("impulsive",)

    @classmethod
    def add_arguments(cls, parser):
        parser.add_argument(
            "--cone",
            choices=("pyramidal", "elliptic"),
            default="pyramidal",
            help="MuJoCo's friction cone",
        )

    def __init__(self, args=None):
        super().__init__(args)
        try:
            import mujoco
            import numpy
        except ImportError as e:
            raise AdapterError(f"{e}; install it with scripts/setup-adapters.sh") from None
        self.mj = mujoco
        self.np = numpy
        # For the record (pushval shows an adapter's stderr only on errors).
        print(f"mujoco_push.py: MuJoCo {mujoco.mj_versionString()}, {self.args.cone} cone", file=sys.stderr)

    can_release = True

    def reset(self, problem):
        mujoco = self.mj
        self.released = False
        dt = problem.dt
        n = len(problem.supports)
        forces = [s.friction for s in problem.supports]
        model = self.model = mujoco.MjModel.from_xml_string(mjcf(problem, self.args.cone, dt, [1.0] * n))
        data = self.data = mujoco.MjData(model)
        # 1. Settle at rest; calibrate each foot's coefficient to its load.
        for _ in range(math.ceil(SETTLE_TIME / dt)):
            mujoco.mj_step(model, data)
        self.f6 = self.np.zeros(6)
        loads = foot_loads(mujoco, model, data, n, self.f6)
        self.rest_height = float(data.qpos[2])
        self.row_extras = (*loads, 0.0)
        for k in range(n):
            if forces[k] == 0.0:
                model.geom_friction[k + 1][0] = 0.0
                continue
            if not loads[k] > 1e-9:
                raise AdapterError(f"support {k} carries no load at rest ({loads[k]} N)")
            model.geom_friction[k + 1][0] = forces[k] / loads[k]

        # 2. The start.
        pc = problem.contact_offset
        ini = problem.initial
        p0 = problem.pushes[0] if problem.pushes else None
        yaw, _ = yaw_and_omega(data)
        if p0 is None:
            # Thrown: the slide starts with the initial velocity and omega
            # (the carriage stays at rest; the first step releases).
            lin, w = tuple(ini.velocity), ini.omega
        elif ini.from_rest:
            lin, w = (0.0, 0.0), 0.0
        else:
            w = ini.omega
            vcx, vcy = p0.velocity()
            lx, ly = vcx + w * pc[1], vcy - w * pc[0]
            c, s = math.cos(yaw), math.sin(yaw)
            lin = (c * lx - s * ly, s * lx + c * ly)
        mat = data.xmat[OBJECT]
        data.qvel[0:3] = [lin[0], lin[1], 0.0]
        data.qvel[3:6] = [mat[6] * w, mat[7] * w, mat[8] * w]
        cvx, cvy = p0.world_velocity(yaw) if p0 is not None else (0.0, 0.0)
        data.qvel[CARRIAGE_DOF:CARRIAGE_DOF + 3] = [cvx, cvy, 0.0]
        self.theta = ini.theta + math.remainder(yaw - ini.theta, 2 * math.pi)
        self.t = 0.0
        return State(float(data.qpos[0]), float(data.qpos[1]), self.theta, w)

    def step(self, push, h):
        mujoco, model, data = self.mj, self.model, self.data
        model.opt.timestep = h
        yaw, wz = yaw_and_omega(data)
        if push is None:
            if not self.released:
                # The pusher lets go: its connect off, the carriage still.
                data.eq_active[0] = 0
                self.released = True
            cvx, cvy = 0.0, 0.0
        else:
            # The carriage follows the pusher's direction at the step's middle.
            cvx, cvy = push.world_velocity(yaw + 0.5 * h * wz)
        data.qvel[CARRIAGE_DOF] = cvx
        data.qvel[CARRIAGE_DOF + 1] = cvy
        mujoco.mj_step(model, data)
        self.t += h
        for name in UNSTABLE:
            if data.warning[getattr(mujoco.mjtWarning, name)].number > 0:
                raise AdapterError(f"MuJoCo warned {name} at t = {self.t:.6g} s: the run is unstable")
        yaw, wz = yaw_and_omega(data)
        self.theta += math.remainder(yaw - self.theta, 2 * math.pi)
        loads = foot_loads(mujoco, model, data, len(self.row_extras) - 1, self.f6)
        self.row_extras = (*loads, float(data.qpos[2]) - self.rest_height)
        return State(float(data.qpos[0]), float(data.qpos[1]), self.theta, wz)

    def extra_columns(self, problem):
        return (*(f"load_{i + 1}" for i in range(len(problem.supports))), "rise")

    def extras(self):
        return self.row_extras


if __name__ == "__main__":
    main(MujocoPush)
