#!/usr/bin/env python3
"""A pushval outside engine in MuJoCo Warp 4.0 (mujoco-warp==4.0.0,
warp-lang==1.19.0) on the CPU: the scene of mujoco_push.py, stepped by Warp.

Opt-in: its own virtual environment, made by scripts/setup-warp.sh
(.venv-warp). The model is mujoco_push.py's MJCF (imported from it: same
feet, carriage, connect constraint, solver options, settling and friction
calibration); MuJoCo Warp compiles it with put_model and steps it with
mujoco_warp.step on Warp's CPU device (single world). MuJoCo Warp computes in
float32, MuJoCo C in float64.

One row per step, with load_1..load_n (each foot's normal force in the step,
N: the Warp data copied back with get_data_into and read with MuJoCo C's
mj_contactForce) and rise (the centre of mass above its settled height, m).
Impulsive switching only, as mujoco_push.py.

Cost: the first run compiles Warp's kernels for the CPU (minutes; cached in
Warp's kernel cache afterwards); then about 36 ms a step on this machine's
CPU (results/friction_models/mujoco_warp/README.md).

Options:
  --cone pyramidal|elliptic   MuJoCo's friction cone (default pyramidal)
"""

import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
try:
    from pushval.adapter import AdapterError, Engine, State, main
except ImportError:  # run from the source tree without the wheel installed
    sys.path.insert(0, os.path.join(HERE, "..", "..", "python"))
    from pushval.adapter import AdapterError, Engine, State, main

from mujoco_push import CARRIAGE_DOF, OBJECT, SETTLE_TIME, foot_loads, mjcf, yaw_and_omega  # noqa: E402

NCONMAX = 32
NJMAX = 128


class MujocoWarpPush(Engine):
    """mujoco_push.py's scene stepped by MuJoCo Warp on the CPU."""

    name = "mujoco_warp_push.py"
    switching_rules = ("impulsive",)

    @classmethod
    def add_arguments(cls, parser):
        parser.add_argument("--cone", choices=("pyramidal", "elliptic"), default="pyramidal",
                            help="MuJoCo's friction cone")

    def __init__(self, args=None):
        super().__init__(args)
        try:
            import mujoco
            import numpy
            import warp
        except ImportError as e:
            raise AdapterError(f"{e}; install it with scripts/setup-warp.sh") from None
        warp.config.quiet = True
        warp.init()
        warp.set_device("cpu")
        import mujoco_warp

        self.mj, self.np, self.wp, self.mjw = mujoco, numpy, warp, mujoco_warp
        print(f"mujoco_warp_push.py: MuJoCo {mujoco.mj_versionString()}, mujoco-warp "
              f"{getattr(mujoco_warp, '__version__', '?')}, warp {warp.__version__} (cpu), {self.args.cone} cone",
              file=sys.stderr)

    def pull(self):
        """The Warp data copied into the MuJoCo C data (for contact forces)."""
        self.mjw.get_data_into(self.mjd, self.mjm, self.d)

    def reset(self, problem):
        mujoco, np, mjw = self.mj, self.np, self.mjw
        dt = problem.dt
        n = len(problem.supports)
        self.n = n
        forces = [s.friction for s in problem.supports]
        mjm = self.mjm = mujoco.MjModel.from_xml_string(mjcf(problem, self.args.cone, dt, [1.0] * n))
        mjd = self.mjd = mujoco.MjData(mjm)
        mujoco.mj_forward(mjm, mjd)
        self.m = mjw.put_model(mjm)
        self.d = mjw.put_data(mjm, mjd, nconmax=NCONMAX, njmax=NJMAX)
        self.h = dt
        # 1. Settle at rest; calibrate each foot's coefficient to its load.
        for _ in range(math.ceil(SETTLE_TIME / dt)):
            mjw.step(self.m, self.d)
        self.pull()
        self.f6 = np.zeros(6)
        loads = foot_loads(mujoco, mjm, mjd, n, self.f6)
        fr = self.m.geom_friction.numpy()
        for k in range(n):
            if forces[k] == 0.0:
                fr[..., k + 1, 0] = 0.0
                continue
            if not loads[k] > 1e-9:
                raise AdapterError(f"support {k} carries no load at rest ({loads[k]} N)")
            fr[..., k + 1, 0] = forces[k] / loads[k]
        self.m.geom_friction.assign(fr)
        self.rest_height = float(mjd.qpos[2])
        self.row_extras = (*loads, 0.0)

        # 2. The start (as mujoco_push.py).
        pc = problem.contact_offset
        ini = problem.initial
        p0 = problem.pushes[0]
        yaw, _ = yaw_and_omega(mjd)
        if ini.from_rest:
            lin, w = (0.0, 0.0), 0.0
        else:
            w = ini.omega
            vcx, vcy = p0.velocity()
            lx, ly = vcx + w * pc[1], vcy - w * pc[0]
            c, s = math.cos(yaw), math.sin(yaw)
            lin = (c * lx - s * ly, s * lx + c * ly)
        mat = mjd.xmat[OBJECT]
        qvel = self.d.qvel.numpy()
        qvel[0, 0:3] = [lin[0], lin[1], 0.0]
        qvel[0, 3:6] = [mat[6] * w, mat[7] * w, mat[8] * w]
        cvx, cvy = p0.world_velocity(yaw)
        qvel[0, CARRIAGE_DOF:CARRIAGE_DOF + 3] = [cvx, cvy, 0.0]
        self.d.qvel.assign(qvel)
        self.theta = ini.theta + math.remainder(yaw - ini.theta, 2 * math.pi)
        self.t = 0.0
        return State(float(mjd.qpos[0]), float(mjd.qpos[1]), self.theta, w)

    def step(self, push, h):
        mjw = self.mjw
        if h != self.h:
            ts = self.m.opt.timestep.numpy()
            ts[...] = h
            self.m.opt.timestep.assign(ts)
            self.h = h
        mjd = self.mjd
        yaw, wz = yaw_and_omega(mjd)
        cvx, cvy = push.world_velocity(yaw + 0.5 * h * wz)
        qvel = self.d.qvel.numpy()
        qvel[0, CARRIAGE_DOF] = cvx
        qvel[0, CARRIAGE_DOF + 1] = cvy
        self.d.qvel.assign(qvel)
        mjw.step(self.m, self.d)
        self.t += h
        self.pull()
        if not (self.np.all(self.np.isfinite(mjd.qpos)) and self.np.all(self.np.isfinite(mjd.qvel))):
            raise AdapterError(f"MuJoCo Warp's state is not finite at t = {self.t:.6g} s")
        yaw, wz = yaw_and_omega(mjd)
        self.theta += math.remainder(yaw - self.theta, 2 * math.pi)
        loads = foot_loads(self.mj, self.mjm, mjd, self.n, self.f6)
        self.row_extras = (*loads, float(mjd.qpos[2]) - self.rest_height)
        return State(float(mjd.qpos[0]), float(mjd.qpos[1]), self.theta, wz)

    def extra_columns(self, problem):
        return (*(f"load_{i + 1}" for i in range(len(problem.supports))), "rise")

    def extras(self):
        return self.row_extras


if __name__ == "__main__":
    main(MujocoWarpPush)
