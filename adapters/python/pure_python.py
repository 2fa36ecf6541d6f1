#!/usr/bin/env python3
"""A pushval outside engine in plain Python (no dependencies but the kit).

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
Where the pusher velocity jumps (every segment start; the start too when the
object starts from rest), omega jumps by the problem's switching rule
(impulsive: the angular momentum about the contact point is kept).

The protocol (one-shot or --session, limits, progress, --timing) is
pushval.adapter's; see adapters/python/README.md.
"""

import math
import os
import sys

try:
    from pushval.adapter import Engine, State, main
except ImportError:  # run from the source tree without the wheel installed
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
    from pushval.adapter import Engine, State, main


class PurePython(Engine):
    """Coulomb friction per support, the pusher as a velocity constraint."""

    name = "pure_python.py"
    step_rule = "round"

    @classmethod
    def add_arguments(cls, parser):
        parser.add_argument(
            "--scheme",
            choices=("euler", "heun"),
            default="euler",
            help="the step: semi-implicit Euler (default, first order) or Heun's method "
            "on (theta, omega, x, y) (second order; declare order = 2 for it)",
        )
        parser.add_argument(
            "--inertia-scale",
            type=float,
            default=1.0,
            metavar="S",
            help="multiply I_cm by S (a deliberately wrong engine)",
        )

    def reset(self, problem):
        # A wrong inertia is wrong everywhere, the switches included.
        self.problem = problem.with_inertia(problem.inertia_cm * self.args.inertia_scale)
        self.m = problem.mass
        self.i_p = self.problem.inertia_contact
        self.rc = self.problem.contact_offset
        self.sup = [(s.offset[0], s.offset[1], s.friction) for s in problem.supports]
        self.x, self.y = problem.initial.position
        self.th = problem.initial.theta
        self.w = self.problem.start_omega()
        return State(self.x, self.y, self.th, self.w)

    def switch(self, before, after):
        self.w = self.problem.omega_after_switch(before, after, self.w)

    def rates(self, th, w, speed, phi):
        """(dtheta, domega, dx, dy)/dt at angle th and angular velocity w."""
        rcx, rcy = self.rc
        c, s = math.cos(th), math.sin(th)
        pcx, pcy = c * rcx - s * rcy, s * rcx + c * rcy
        vpx, vpy = speed * math.cos(th + phi), speed * math.sin(th + phi)
        vx, vy = vpx + w * pcy, vpy - w * pcx
        return w, self.omega_dot(c, s, pcx, pcy, vpx, vpy, vx, vy, w) / self.i_p, vx, vy

    def omega_dot(self, c, s, pcx, pcy, vpx, vpy, vx, vy, w):
        """The torque about the contact point (I_P domega/dt)."""
        torque = self.m * w * (pcx * vpx + pcy * vpy)
        for sx, sy, f in self.sup:
            px, py = c * sx - s * sy, s * sx + c * sy
            ux, uy = vx - w * py, vy + w * px
            norm = math.hypot(ux, uy)
            if norm > 1e-15:
                fx, fy = -f * ux / norm, -f * uy / norm
                torque += (px - pcx) * fy - (py - pcy) * fx
        return torque

    def step(self, push, h):
        speed, phi = push.speed, push.phi
        if self.args.scheme == "heun":
            d1 = self.rates(self.th, self.w, speed, phi)
            d2 = self.rates(self.th + h * d1[0], self.w + h * d1[1], speed, phi)
            self.th += 0.5 * h * (d1[0] + d2[0])
            self.w += 0.5 * h * (d1[1] + d2[1])
            self.x += 0.5 * h * (d1[2] + d2[2])
            self.y += 0.5 * h * (d1[3] + d2[3])
            return State(self.x, self.y, self.th, self.w)
        rcx, rcy = self.rc
        th, w = self.th, self.w
        c, s = math.cos(th), math.sin(th)
        pcx, pcy = c * rcx - s * rcy, s * rcx + c * rcy
        vpx, vpy = speed * math.cos(th + phi), speed * math.sin(th + phi)
        vx, vy = vpx + w * pcy, vpy - w * pcx
        w += h * self.omega_dot(c, s, pcx, pcy, vpx, vpy, vx, vy, w) / self.i_p
        th += h * w
        # The centre of mass moves with the velocity the constraint gives at
        # the new pose.
        c, s = math.cos(th), math.sin(th)
        pcx, pcy = c * rcx - s * rcy, s * rcx + c * rcy
        vpx, vpy = push.world_velocity(th)
        self.x += h * (vpx + w * pcy)
        self.y += h * (vpy - w * pcx)
        self.th, self.w = th, w
        return State(self.x, self.y, th, w)


if __name__ == "__main__":
    main(PurePython)
