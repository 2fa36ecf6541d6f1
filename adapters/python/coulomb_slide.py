"""The supports' implicit Coulomb impulses over one step of the free slide,
for the reference adapters whose supports' friction is applied by hand (the
Python twin of pushval_engine::slide, as pure_python.py's slide solves it).

A Coulomb force applied as a fixed force mu_i N_i per step overshoots once a
support's slip is smaller than what one step's friction removes: the slip
reverses every step and the plate never rests. Here the impulses P_i of a
step of length h are implicit Coulomb friction: each within its disc |P_i| <=
mu_i N_i h, they leave a support's slip zero at the step's end where the disc
allows it and otherwise oppose its end-of-step slip with the whole disc.
Solved jointly by projected Gauss-Seidel over the supports, each update a
gradient step of length 1/k_i, k_i = 1/m + |r_i|^2/I, projected on the disc.
"""

import math

SWEEPS = 500
"""Largest number of sweeps over the supports per step."""

SWEEP_TOL = 1e-13
"""The sweeps stop once no impulse changed by more than this share of the
largest cap."""


def coulomb_impulses(mass, inertia_cm, v, omega, supports):
    """The supports' friction impulses (N s, world frame) over a slide step
    of a plate of mass ``mass`` (kg) and inertia ``inertia_cm`` (kg m^2)
    moving at ``v`` (m/s, its centre of mass) and ``omega`` (rad/s) at the
    step's start. ``supports``: each support's offset from the centre of
    mass (m, world frame) and its cap mu_i N_i h (N s). Returns the impulses
    and the velocities after them: (impulses, (vx, vy), omega)."""
    acc = [[0.0, 0.0] for _ in supports]
    cap_max = max((cap for _, cap in supports), default=0.0)
    vx, vy, w = v[0], v[1], omega
    for _ in range(SWEEPS):
        change = 0.0
        for ((rx, ry), cap), a in zip(supports, acc):
            if cap <= 0.0:
                continue
            ux, uy = vx - w * ry, vy + w * rx
            k = 1.0 / mass + (rx * rx + ry * ry) / inertia_cm
            px, py = a[0] - ux / k, a[1] - uy / k
            n = math.hypot(px, py)
            if n > cap:
                px, py = px * cap / n, py * cap / n
            dx, dy = px - a[0], py - a[1]
            vx += dx / mass
            vy += dy / mass
            w += (rx * dy - ry * dx) / inertia_cm
            a[0], a[1] = px, py
            change = max(change, math.hypot(dx, dy))
        if change <= SWEEP_TOL * cap_max:
            break
    return acc, (vx, vy), w
