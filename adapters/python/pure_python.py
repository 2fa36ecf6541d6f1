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

Released (protocol 3's release; the step receives no push), the plate slides
freely on its supports: each step's support impulses are implicit Coulomb
friction, each within its disc |P_i| <= mu_i N_i h and leaving the support's
slip zero at the step's end where the disc allows it (solved jointly by
projected Gauss-Seidel, as pushval_engine::slide does), so a plate that one
step can stop comes to rest instead of chattering; then the velocities take
the impulses and the pose moves with the new velocities (semi-implicit Euler,
first order). With --scheme heun, a slide step in which every support slides
throughout (each implicit impulse at its disc's edge) is Heun's: the Coulomb
impulses at the step's start and at the implicit step's end averaged, the
pose moved with the mean velocity; the step of the stop keeps the implicit
impulses (one step's O(h^2) error), so the slide's rest is second order as
the pushes are, and `order = 2` holds for a problem with a release too.

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
    can_release = True

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
        # A plate thrown (no pushes) starts with its initial velocity and ω.
        self.w = self.problem.start_omega() if problem.pushes else problem.initial.omega
        # The centre of mass's world velocity (m/s), kept for the release.
        self.vx, self.vy = problem.initial.velocity
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

    def slide(self, h):
        """One step of the free slide: implicit Coulomb support impulses,
        then the pose with the new velocities."""
        c, s = math.cos(self.th), math.sin(self.th)
        m, i_cm = self.m, self.problem.inertia_cm
        sup = [(c * sx - s * sy, s * sx + c * sy, max(f, 0.0) * h) for sx, sy, f in self.sup]
        cap_max = max((q[2] for q in sup), default=0.0)
        acc = [[0.0, 0.0] for _ in sup]
        vx, vy, w = self.vx, self.vy, self.w
        for _ in range(500):
            change = 0.0
            for (rx, ry, cap), a in zip(sup, acc):
                if cap <= 0.0:
                    continue
                ux, uy = vx - w * ry, vy + w * rx
                k = 1.0 / m + (rx * rx + ry * ry) / i_cm
                px, py = a[0] - ux / k, a[1] - uy / k
                n = math.hypot(px, py)
                if n > cap:
                    px, py = px * cap / n, py * cap / n
                dx, dy = px - a[0], py - a[1]
                vx += dx / m
                vy += dy / m
                w += (rx * dy - ry * dx) / i_cm
                a[0], a[1] = px, py
                change = max(change, math.hypot(dx, dy))
            if change <= 1e-13 * cap_max:
                break
        sliding = all(cap <= 0.0 or math.hypot(*a) >= cap * (1.0 - 1e-12) for (_, _, cap), a in zip(sup, acc))
        if self.args.scheme == "heun" and sliding:
            return self.slide_heun(h, sup, vx, vy, w)
        self.vx, self.vy, self.w = vx, vy, w
        self.th += h * w
        self.x += h * vx
        self.y += h * vy
        return State(self.x, self.y, self.th, w)

    def slide_heun(self, h, sup, vx1, vy1, w1):
        """A slide step of Heun's method, for a step in which every support
        slides throughout (each implicit impulse at its cap): the Coulomb
        impulses at the step's start and at the implicit step's end (pose
        and velocities), averaged; the pose with the mean of the start and
        end velocities. Second order, like the pushes' steps; a step in
        which a support stops or sticks (the stop itself) keeps the implicit
        impulses, an O(h^2) error at an isolated step."""
        m, i_cm = self.m, self.problem.inertia_cm
        vx0, vy0, w0 = self.vx, self.vy, self.w
        th1 = self.th + 0.5 * h * (w0 + w1)

        def impulses(th, vx, vy, w):
            c, s = math.cos(th), math.sin(th)
            px = py = q = 0.0
            for (sx, sy, f), (_, _, cap) in zip(self.sup, sup):
                rx, ry = c * sx - s * sy, s * sx + c * sy
                ux, uy = vx - w * ry, vy + w * rx
                n = math.hypot(ux, uy)
                if cap > 0.0 and n > 1e-15:
                    dx, dy = -cap * ux / n, -cap * uy / n
                    px += dx
                    py += dy
                    q += rx * dy - ry * dx
            return px, py, q

        a = impulses(self.th, vx0, vy0, w0)
        b = impulses(th1, vx1, vy1, w1)
        vx = vx0 + 0.5 * (a[0] + b[0]) / m
        vy = vy0 + 0.5 * (a[1] + b[1]) / m
        w = w0 + 0.5 * (a[2] + b[2]) / i_cm
        self.th += 0.5 * h * (w0 + w)
        self.x += 0.5 * h * (vx0 + vx)
        self.y += 0.5 * h * (vy0 + vy)
        self.vx, self.vy, self.w = vx, vy, w
        return State(self.x, self.y, self.th, w)

    def step(self, push, h):
        if push is None:
            return self.slide(h)
        state = self.pushed(push, h)
        # The centre of mass's velocity the constraint gives at the new pose.
        rcx, rcy = self.rc
        c, s = math.cos(self.th), math.sin(self.th)
        pcx, pcy = c * rcx - s * rcy, s * rcx + c * rcy
        vpx, vpy = push.world_velocity(self.th)
        self.vx, self.vy = vpx + self.w * pcy, vpy - self.w * pcx
        return state

    def pushed(self, push, h):
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
