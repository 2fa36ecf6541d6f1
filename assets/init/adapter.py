#!/usr/bin/env python3
"""my_engine: a plate pushed at one point, sliding on its supports.

pushval runs this file as the outside engine `my_engine` (pushval.toml). The
kit `pushval.adapter` reads each problem pushval sends, calls `reset` once
and `step` for every time step, and writes the trajectory back. To validate
your own simulator, keep the class and replace what `reset` and `step` do by
calls to it.

The physics here (a small reference simulator):
  * each support i pushes back on the plate with a Coulomb friction force of
    magnitude mu_i N_i, opposite the velocity with which it slides;
  * the pusher holds the contact point: it moves at the pusher's velocity,
    speed * R(theta) (cos phi, sin phi). The plate keeps one free motion,
    its rotation omega about the contact point, and

        I_P domega/dt = m omega (r_c . v_p) + sum_i (r_i - r_c) x f_i

    (I_P: inertia about the contact point; r: offsets from the centre of
    mass in the world frame; v_p: the pusher's velocity);
  * a step is Heun's method, second order in dt: pushval.toml declares
    `order = 2`.

When you change the step, change `order` in pushval.toml with it: 1 for
explicit or semi-implicit (symplectic) Euler and most game engines, 2 for
Heun, midpoint or leapfrog. pushval measures the order on the trajectory at
successive time steps and fails the gate, naming both orders, when the
declared one is higher than what it measures (its error estimate would be
too small).
"""

import math
import sys

try:
    from pushval.adapter import Engine, Problem, Push, State, main
except ImportError:
    sys.exit(
        f"adapter.py: {sys.executable} cannot import the adapter kit pushval.adapter. "
        "`pushval init` writes it beside this file (pushval/adapter.py) when python3 "
        "lacks it: run `pushval init --force` again here, or install pushval's "
        "source folder (the one with pyproject.toml) with "
        "`python3 -m pip install PATH/TO/pushval`, or name a Python that has it in "
        "pushval.toml's command (pushval is on no package registry)"
    )


def rotate(theta, point):
    """``point`` (object frame) turned by ``theta``: its world-frame offset."""
    c, s = math.cos(theta), math.sin(theta)
    return c * point[0] - s * point[1], s * point[0] + c * point[1]


class MyEngine(Engine):
    """Coulomb friction per support; the pusher holds the contact point."""

    def reset(self, problem: Problem) -> State:
        """The plate at the start of the problem."""
        self.problem = problem
        self.x, self.y = problem.initial.position
        self.theta = problem.initial.theta
        # Moving with the first push already, or set in motion by it (the
        # kit's helper applies the problem's switching rule).
        self.omega = problem.start_omega()
        return State(self.x, self.y, self.theta, self.omega)

    def switch(self, before: Push, after: Push) -> None:
        """The pusher changes velocity: the contact's impulse changes omega."""
        self.omega = self.problem.omega_after_switch(before, after, self.omega)

    def step(self, push: Push, dt: float) -> State:
        """Heun's method: the mean of the rates at the start and at an Euler
        guess of the end."""
        a = self.rates(self.theta, self.omega, push)
        b = self.rates(self.theta + dt * a[0], self.omega + dt * a[1], push)
        self.theta += 0.5 * dt * (a[0] + b[0])
        self.omega += 0.5 * dt * (a[1] + b[1])
        self.x += 0.5 * dt * (a[2] + b[2])
        self.y += 0.5 * dt * (a[3] + b[3])
        return State(self.x, self.y, self.theta, self.omega)

    def rates(self, theta, omega, push):
        """(dtheta/dt, domega/dt, dx/dt, dy/dt) at angle theta, rate omega."""
        p = self.problem
        rcx, rcy = rotate(theta, p.contact_offset)
        vpx, vpy = push.world_velocity(theta)
        # The centre of mass moves with the contact point, minus omega x r_c.
        vx, vy = vpx + omega * rcy, vpy - omega * rcx
        torque = p.mass * omega * (rcx * vpx + rcy * vpy)
        for support in p.supports:
            sx, sy = rotate(theta, support.offset)
            ux, uy = vx - omega * sy, vy + omega * sx  # its sliding velocity
            slip = math.hypot(ux, uy)
            if slip > 1e-15:
                fx = -support.friction * ux / slip
                fy = -support.friction * uy / slip
                torque += (sx - rcx) * fy - (sy - rcy) * fx
        return omega, torque / p.inertia_contact, vx, vy


if __name__ == "__main__":
    main(MyEngine)
