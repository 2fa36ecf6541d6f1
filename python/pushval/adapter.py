"""The adapter kit: a pushval outside engine in a few lines of Python.

pushval runs an *outside engine* (any simulator) as a process that speaks the
pushval-problem protocol. This module speaks it; the author writes only the
simulator's step::

    from pushval.adapter import Engine, Problem, Push, State, main

    class MyEngine(Engine):
        def reset(self, problem: Problem) -> State:
            ...  # build the scene at t = 0
            return State(x, y, theta, omega)

        def step(self, push: Push, dt: float) -> State:
            ...  # advance dt with the pusher moving as `push` says
            return State(x, y, theta, omega)

    if __name__ == "__main__":
        main(MyEngine)

The protocol (what the kit does around those two methods)
---------------------------------------------------------
Input: a JSON problem document, ``"format": "pushval-problem/1"`` or
``"pushval-problem/2"`` (adapters/pushval-problem-1.schema.json; version 2
adds ``"switching"`` and ``"limits"``). The kit reads it into a `Problem`.

Output: CSV on standard output, header ``t,x,y,theta,omega``, then the first
row at t = 0 (the state `Engine.reset` returns) and one row per engine step:
``x, y`` the centre of mass in the world (m), ``theta`` unwrapped (rad),
``omega`` the angular velocity held over the step ending at ``t`` (rad/s).

Two ways to serve, chosen by one rule pushval relies on:

* **one-shot** (no ``--session`` argument, no ``PUSHVAL_SESSION=1``):
  standard input holds one document, then end of file. The kit writes the
  CSV and exits 0; a document it cannot read exits 2, a failed run exits 1,
  both with the reason on standard error and nothing on standard output.
* **session** (pushval starts the process with ``PUSHVAL_SESSION=1`` in its
  environment, and no argument, when the engine's ``pushval.toml`` table
  says ``session = true``; ``--session`` does the same by hand): standard
  input holds one JSON document per line, each with ``"request": N``, and
  every answer closes with that number. A whole problem (protocol 2) is
  answered with the header, the rows and ``#end N``. Protocol 3 steps:
  ``{"op": "start", "problem": {...}, "rows": "samples"|"steps"}`` (the
  version 2 problem without its ``pushes``) is answered ``#ok N``;
  ``{"op": "advance", "speed": .., "phi": .., "duration": ..}`` by that
  push's rows (the first advance starts with the header and the row at
  t = 0) and ``#end N``; ``{"op": "finish"}`` by ``#end N``. A document
  that cannot be read or a request that fails is answered by one line
  ``#error N MESSAGE`` instead (nothing else), and the session goes on. End
  of file on standard input ends the session (exit 0).

Protocol 3 is served from the same `Engine.reset`, `Engine.switch` and
`Engine.step` (`Stepper`): `reset` receives the problem with the first push
as its schedule, each advance cuts its push into steps as a whole run does,
so stepping push by push writes the rows a whole run writes. With
``"rows": "samples"`` (pushval's default) and an engine without extra
columns, an advance writes only the rows at the sample times and at its
push's end, with a last column ``steps`` (the engine steps each row's
interval took); ω on such a row is the one held over its interval, read at
the interval's middle. Where the ``start`` says ``"compact": true`` the
rows after the header go as one compact line per answer (``!`` and the
numbers as little-endian binary64 in hexadecimal, `_compact`).

The engine object lives for the whole process: `Engine.reset` is called once
per problem (so a session reuses what ``__init__`` loaded), `Engine.close`
after each problem, failed or not.

What the kit does for every problem
-----------------------------------
* **Schedule.** Each push segment ``k`` is cut into ``n_k`` equal steps of
  ``h_k = duration_k / n_k`` (``Engine.step_rule``: ``"ceil"``, the default,
  gives ``n_k = ceil(duration_k / dt)`` so no step is longer than the
  problem's ``dt``; ``"round"`` the nearest count). Row times are
  ``t_start_k + j h_k``, the segment's last row exactly at its end.
* **Switching.** Where one segment follows another the pusher's velocity
  jumps; the kit calls ``Engine.switch(before, after)`` before the new
  segment's first step. An engine whose pusher is a velocity constraint sets
  its ω there with `Problem.omega_after_switch` (which applies the problem's
  rule: ``"impulsive"``, the angular momentum about the contact point is
  kept; ``"continuous"``, ω is kept). An engine whose own contact makes the
  jump ignores it (the default). The start of an object at rest is a switch
  too: `Problem.start_omega` gives ω just after it, for `Engine.reset`.
  An engine that can follow only some rules lists them in
  ``Engine.switching_rules``; a problem asking another is refused.
* **Limits.** With version 2's ``"limits": {"max_rows": N, "max_bytes": B}``
  (pushval kills a process past them), an answer that would exceed them is
  written at the problem's sample times instead of per step (with a note on
  standard error); if even that is too large, the run fails with a message
  saying so instead of being killed. ``Engine.rows = "samples"`` asks for
  rows at the sample times always.
* **Extra columns.** An engine that lists names in
  `Engine.extra_columns` (e.g. ``load_1..load_n`` and ``rise``) gets them in
  the header after ``omega``; the kit calls `Engine.extras` after `reset`
  and after every step and writes its numbers on that row (at a sample time,
  the values of the step holding it, as ω). Engines that list none write
  exactly ``t,x,y,theta,omega``.
* **Checks.** A state that is not four finite numbers fails the run, naming
  the time; so do extras that are not finite or not one per column.
* **Progress.** A run longer than a few seconds reports how far it is on
  standard error (pushval shows an engine's standard error when it fails).
* **Output hygiene.** `main` points file descriptor 1 at standard error
  before the engine is built, and keeps the real standard output for the
  protocol: a library that prints (a banner, a warning) cannot corrupt the
  CSV or a session's framing.

Options every adapter built with `main` accepts: ``--session`` (above) and
``--timing`` (after each answer, ``step_time_s=S steps=N`` on standard error:
the time spent in `Engine.reset`, `Engine.switch` and the steps; in protocol 3
after ``finish``, for the whole problem, with ``answer_time_s=A``: the time
spent answering its requests, from reading each line to the answer ready to
write, the steps included). The engine adds its own with
`Engine.add_arguments`.

Standard library only; Python 3.9 or newer.
"""

from __future__ import annotations

import argparse
import array
import bisect
import dataclasses
import itertools
import json
import math
import operator
import os
import sys
import time
from dataclasses import dataclass
from typing import IO, Any, Callable, ClassVar, Iterable, NamedTuple, Sequence

__all__ = [
    "FORMATS",
    "HEADER",
    "SWITCHING_RULES",
    "AdapterError",
    "Engine",
    "Initial",
    "Limits",
    "Problem",
    "ProblemError",
    "Push",
    "Run",
    "State",
    "Stepper",
    "Support",
    "answer",
    "main",
    "parse_problem",
    "serve",
    "simulate",
]

#: The document formats the kit reads.
FORMATS = ("pushval-problem/1", "pushval-problem/2")

#: The CSV header the kit writes (an engine's `Engine.extra_columns` follow it).
HEADER = "t,x,y,theta,omega"

#: What ω does where the pusher's velocity jumps (version 2's ``switching``).
SWITCHING_RULES = ("impulsive", "continuous")

#: Seconds of stepping before the first progress line, and between lines.
PROGRESS_EVERY_S = 5.0

_INF = math.inf


class ProblemError(ValueError):
    """A problem document the kit cannot read; the message names the key."""


class AdapterError(RuntimeError):
    """A run that failed for a reason the engine states in its message.

    Raise it from an engine for a clean one-line error (no traceback); any
    other exception fails the run too, with its traceback on standard error.
    """


# --------------------------------------------------------------------------
# The problem


class State(NamedTuple):
    """The object's state after a step (or at t = 0)."""

    x: float
    """World x of the centre of mass (m)."""
    y: float
    """World y of the centre of mass (m)."""
    theta: float
    """Object angle, unwrapped (rad)."""
    omega: float
    """Angular velocity (rad/s): the one held over the step that ended."""


@dataclass(frozen=True)
class Support:
    """One support point of the object on the floor."""

    point: tuple[float, float]
    """Position in the scenario file's object frame (m)."""
    offset: tuple[float, float]
    """Position relative to the centre of mass, body frame (m)."""
    mu: float
    """Friction coefficient at this support (>= 0)."""
    normal_force: float
    """Load on this support (N, > 0), as the scenario resolved it."""

    @property
    def friction(self) -> float:
        """Magnitude of the Coulomb friction force while sliding, μ N (N)."""
        return self.mu * self.normal_force


@dataclass(frozen=True)
class Push:
    """One segment of the schedule: the pusher at a constant velocity."""

    index: int
    """Position in the schedule (0 for the first)."""
    t_start: float
    """Start time (s)."""
    duration: float
    """Length (s, > 0)."""
    speed: float
    """Pusher speed (m/s, >= 0)."""
    phi: float
    """Pusher direction in the object frame (rad): the contact point moves at
    ``speed * R(theta) (cos phi, sin phi)``."""

    @property
    def t_end(self) -> float:
        """End time (s)."""
        return self.t_start + self.duration

    def velocity(self) -> tuple[float, float]:
        """The pusher's velocity in the object frame (m/s)."""
        return self.speed * math.cos(self.phi), self.speed * math.sin(self.phi)

    def world_velocity(self, theta: float) -> tuple[float, float]:
        """The pusher's velocity in the world when the object is at angle
        ``theta`` (m/s)."""
        a = theta + self.phi
        return self.speed * math.cos(a), self.speed * math.sin(a)

    def steps(self, dt: float, rule: str = "ceil") -> int:
        """The number of equal steps cutting this segment at about ``dt``:
        ``"ceil"`` (no step longer than dt, to a relative 1e-12) or
        ``"round"`` (the nearest count); at least 1."""
        ratio = self.duration / dt
        if rule == "ceil":
            return max(1, math.ceil(ratio * (1.0 - 1e-12)))
        if rule == "round":
            return max(1, round(ratio))
        raise ValueError(f"unknown step rule {rule!r} (ceil, round)")


@dataclass(frozen=True)
class Initial:
    """The state when the first push starts."""

    position: tuple[float, float]
    """World position of the centre of mass (m)."""
    theta: float
    """Object angle (rad)."""
    omega: float
    """Angular velocity (rad/s); ignored when `from_rest`."""
    from_rest: bool
    """The object is at rest when the pusher starts (the start is a switch
    from zero velocity); otherwise it already moves with the first push at
    ω = `omega`."""
    velocity: tuple[float, float] = (0.0, 0.0)
    """World velocity of the centre of mass (m/s); only a problem without
    pushes sets it (a plate thrown: the free slide starts from it and ω =
    `omega` at t = 0)."""


@dataclass(frozen=True)
class Limits:
    """Version 2's cap on one answer: past it pushval kills the process."""

    max_rows: int | None = None
    """Most data rows (the header and framing lines not counted)."""
    max_bytes: int | None = None
    """Most bytes of the whole answer (header, rows, framing line)."""


@dataclass(frozen=True)
class Problem:
    """One run's problem, as the document states it (SI units).

    Positions of the object's points are given twice: ``point`` in the
    scenario file's object frame (as the document writes them) and
    ``offset`` relative to the centre of mass (the body frame most
    simulators want).
    """

    format: str
    """The document's format (one of `FORMATS`)."""
    engine: str
    """The model name the engine is declared under in pushval.toml."""
    dt: float
    """The time step of this run (s)."""
    mass: float
    """kg."""
    inertia_cm: float
    """Moment of inertia about the centre of mass (kg m²)."""
    center_of_mass: tuple[float, float]
    """In the file's object frame (m)."""
    polygon: tuple[tuple[float, float], ...]
    """The outline, counter-clockwise, in the file's object frame (m)."""
    supports: tuple[Support, ...]
    contact: tuple[float, float]
    """The pusher's contact point, file's object frame (m)."""
    initial: Initial
    pushes: tuple[Push, ...]
    sample_dt: float
    """Spacing of the output samples (s)."""
    gravity: float
    """m/s²."""
    options: dict[str, Any]
    """The scenario's ``[engine]`` table, verbatim."""
    switching: str = "impulsive"
    """What ω does where the pusher's velocity jumps (`SWITCHING_RULES`);
    version 1 documents state none and mean ``"impulsive"``."""
    limits: Limits = Limits()
    """The answer's cap (version 2); no cap when the document gives none."""
    release: float | None = None
    """The release's longest slide (s): after the last push the pusher lets
    go and the plate slides to rest (protocol 3's ``release`` op); None: no
    release."""

    @property
    def version(self) -> int:
        """The protocol version, 1 or 2."""
        return int(self.format.rsplit("/", 1)[1])

    @property
    def contact_offset(self) -> tuple[float, float]:
        """The contact point relative to the centre of mass, body frame (m)."""
        return (
            self.contact[0] - self.center_of_mass[0],
            self.contact[1] - self.center_of_mass[1],
        )

    @property
    def inertia_contact(self) -> float:
        """Moment of inertia about the contact point, I_cm + m |r_c|² (kg m²)."""
        rx, ry = self.contact_offset
        return self.inertia_cm + self.mass * (rx * rx + ry * ry)

    @property
    def duration(self) -> float:
        """The end of the last push (s)."""
        total = 0.0
        for p in self.pushes:  # summed in order, as pushval sums it
            total += p.duration
        return total

    def sample_times(self) -> list[float]:
        """The times pushval samples at: ``k * sample_dt`` up to the end
        (inclusive within a relative 1e-9 of a sample step), the end itself
        last."""
        end = self.duration
        n = math.floor(end / self.sample_dt * (1.0 + 1e-12) + 1e-9)
        times = [k * self.sample_dt for k in range(n + 1)]
        if end - times[-1] > 1e-9 * self.sample_dt:
            times.append(end)
        else:
            times[-1] = end
        return times

    def contact_momentum(self, push: Push | None, omega: float) -> float:
        """Angular momentum about the contact point (kg m²/s) of the object
        turning at ``omega`` while its contact point moves with ``push``
        (None: at rest): ``I_P ω - m (r_c × v_push)``, object frame."""
        h = self.inertia_contact * omega
        if push is None:
            return h
        rx, ry = self.contact_offset
        return h - self.mass * push.speed * (rx * math.sin(push.phi) - ry * math.cos(push.phi))

    def omega_after_switch(self, before: Push | None, after: Push, omega_before: float) -> float:
        """ω just after the pusher switches from ``before`` (None: at rest)
        to ``after``, given ω just before, by the problem's `switching` rule:
        impulsive keeps the angular momentum about the contact point (the
        contact impulse has no moment about it), continuous keeps ω."""
        if self.switching == "continuous":
            return omega_before
        rx, ry = self.contact_offset
        h = self.contact_momentum(before, omega_before)
        lin = self.mass * after.speed * (rx * math.sin(after.phi) - ry * math.cos(after.phi))
        return (h + lin) / self.inertia_contact

    def start_omega(self) -> float:
        """ω when the first push starts: `Initial.omega`, or for an object
        at rest the value just after the start's switch."""
        if not self.initial.from_rest:
            return self.initial.omega
        return self.omega_after_switch(None, self.pushes[0], 0.0)

    def with_inertia(self, inertia_cm: float) -> Problem:
        """The same problem with another I_cm (kg m²), e.g. for an engine
        that is wrong on purpose."""
        return dataclasses.replace(self, inertia_cm=inertia_cm)


# --------------------------------------------------------------------------
# Reading a document


class _Reader:
    """Typed access to one JSON object; every error names the key's path."""

    def __init__(self, value: Any, path: str):
        if not isinstance(value, dict):
            raise ProblemError(f"`{path or 'document'}` must be an object, got {_kind(value)}")
        self.value = value
        self.path = path

    def _key(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        return key in self.value

    def raw(self, key: str) -> Any:
        if key not in self.value:
            raise ProblemError(f"`{self._key(key)}` is missing")
        return self.value[key]

    def obj(self, key: str) -> _Reader:
        return _Reader(self.raw(key), self._key(key))

    def objects(self, key: str) -> list[_Reader]:
        items = self.raw(key)
        if not isinstance(items, list) or not items:
            raise ProblemError(f"`{self._key(key)}` must be a non-empty array, got {_kind(items)}")
        return [_Reader(v, f"{self._key(key)}[{i}]") for i, v in enumerate(items)]

    def number(self, key: str, minimum: float | None = None, strict: bool = False) -> float:
        return _number(self.raw(key), self._key(key), minimum, strict)

    def integer(self, key: str) -> int:
        v = self.raw(key)
        if isinstance(v, bool) or not isinstance(v, int) or v <= 0:
            raise ProblemError(f"`{self._key(key)}` must be a whole number > 0, got {v!r}")
        return v

    def string(self, key: str) -> str:
        v = self.raw(key)
        if not isinstance(v, str):
            raise ProblemError(f"`{self._key(key)}` must be a string, got {_kind(v)}")
        return v

    def boolean(self, key: str) -> bool:
        v = self.raw(key)
        if not isinstance(v, bool):
            raise ProblemError(f"`{self._key(key)}` must be true or false, got {v!r}")
        return v

    def point(self, key: str) -> tuple[float, float]:
        v = self.raw(key)
        return _point(v, self._key(key))


def _kind(v: Any) -> str:
    return {dict: "an object", list: "an array", str: "a string", bool: "a boolean"}.get(
        type(v), "null" if v is None else repr(v)
    )


def _number(v: Any, path: str, minimum: float | None = None, strict: bool = False) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ProblemError(f"`{path}` must be a number, got {_kind(v)}")
    x = float(v)
    if not math.isfinite(x):
        raise ProblemError(f"`{path}` must be finite, got {x!r}")
    if minimum is not None and (x <= minimum if strict else x < minimum):
        raise ProblemError(f"`{path}` must be {'>' if strict else '>='} {minimum:g}, got {x!r}")
    return x


def _point(v: Any, path: str) -> tuple[float, float]:
    if not isinstance(v, list) or len(v) != 2:
        raise ProblemError(f"`{path}` must be a point [x, y], got {_kind(v)}")
    return _number(v[0], f"{path}[0]"), _number(v[1], f"{path}[1]")


def parse_problem(document: str | bytes | dict[str, Any], schedule: bool = True) -> Problem:
    """Reads a pushval-problem document (JSON text or the decoded object).

    Raises `ProblemError` naming the key for a document that is not JSON,
    has another format, or lacks or mistypes a field. Keys the kit does not
    know are ignored (a later version may add some). ``schedule=False``
    reads a protocol 3 ``start``'s problem: ``pushes`` may be absent or
    empty (the pushes come one ``advance`` at a time).
    """
    if isinstance(document, (str, bytes)):
        try:
            document = json.loads(document)
        except ValueError as e:
            raise ProblemError(f"not JSON: {e}") from None
    doc = _Reader(document, "")
    fmt = doc.raw("format")
    if fmt not in FORMATS:
        raise ProblemError(f"`format` is {fmt!r}; this kit reads {' and '.join(FORMATS)}")
    obj = doc.obj("object")
    com = obj.point("center_of_mass")
    supports = []
    for s in doc.objects("supports"):
        point = s.point("point")
        supports.append(
            Support(
                point=point,
                offset=(point[0] - com[0], point[1] - com[1]),
                mu=s.number("mu", 0.0),
                normal_force=s.number("normal_force", 0.0, strict=True),
            )
        )
    ini = doc.obj("initial")
    given = schedule or (doc.has("pushes") and doc.raw("pushes") != [])
    pushes = tuple(
        Push(
            index=i,
            t_start=p.number("t_start", 0.0),
            duration=p.number("duration", 0.0, strict=True),
            speed=p.number("speed", 0.0),
            phi=p.number("phi"),
        )
        for i, p in enumerate(doc.objects("pushes") if given else ())
    )
    polygon = doc.obj("object").raw("polygon")
    if not isinstance(polygon, list) or len(polygon) < 2:
        raise ProblemError(f"`object.polygon` must be an array of at least 2 points, got {_kind(polygon)}")
    options = doc.raw("options")
    if not isinstance(options, dict):
        raise ProblemError(f"`options` must be an object, got {_kind(options)}")
    switching = "impulsive"
    limits = Limits()
    if fmt != FORMATS[0]:
        if doc.has("switching"):
            switching = doc.string("switching")
            if switching not in SWITCHING_RULES:
                raise ProblemError(f"`switching` is {switching!r}; known: {', '.join(SWITCHING_RULES)}")
        if doc.has("limits"):
            lim = doc.obj("limits")
            limits = Limits(
                max_rows=lim.integer("max_rows") if lim.has("max_rows") else None,
                max_bytes=lim.integer("max_bytes") if lim.has("max_bytes") else None,
            )
    return Problem(
        format=fmt,
        engine=doc.string("engine"),
        dt=doc.number("dt", 0.0, strict=True),
        mass=obj.number("mass", 0.0, strict=True),
        inertia_cm=obj.number("inertia_cm", 0.0, strict=True),
        center_of_mass=com,
        polygon=tuple(_point(q, f"object.polygon[{i}]") for i, q in enumerate(polygon)),
        supports=tuple(supports),
        contact=doc.obj("contact").point("point"),
        initial=Initial(
            position=ini.point("position"),
            theta=ini.number("theta"),
            omega=ini.number("omega"),
            from_rest=ini.boolean("from_rest"),
            velocity=ini.point("velocity") if ini.has("velocity") else (0.0, 0.0),
        ),
        pushes=pushes,
        sample_dt=doc.number("sample_dt", 0.0, strict=True),
        gravity=doc.number("gravity", 0.0, strict=True),
        options=options,
        switching=switching,
        limits=limits,
        release=(
            doc.obj("release").number("max_duration", 0.0, strict=True)
            if doc.has("release") and doc.raw("release") is not None
            else None
        ),
    )


# --------------------------------------------------------------------------
# The engine


class Engine:
    """An outside engine: subclass it, implement `reset` and `step`.

    Class attributes tune what the kit does around them (see the module
    docs): `name`, `switching_rules`, `step_rule`, `rows`.
    """

    name: ClassVar[str] = ""
    """How messages name the engine; empty: the script's file name."""
    switching_rules: ClassVar[tuple[str, ...]] = SWITCHING_RULES
    """The switching rules this engine can follow (a problem asking another
    is refused). An engine whose own contact makes the switch follows
    ``("impulsive",)`` only."""
    step_rule: ClassVar[str] = "ceil"
    """How a segment is cut into steps: ``"ceil"`` (no step longer than the
    problem's dt) or ``"round"`` (the nearest count); see `Push.steps`."""
    rows: ClassVar[str] = "steps"
    """``"steps"``: one row per step (best for pushval's resampler);
    ``"samples"``: one row per sample time."""
    can_release: ClassVar[bool] = False
    """Whether `step` slides the plate freely when its ``push`` is None (the
    pusher gone: no contact force), which protocol 3's ``release`` needs; a
    release asked of an engine that cannot is refused, naming the release."""

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        """Adds the engine's own command-line options to ``parser``; their
        values reach ``__init__`` as ``args``. None by default."""

    def __init__(self, args: argparse.Namespace | None = None):
        """Built once per process (load heavy things here: a session reuses
        them). ``args``: the parsed command line."""
        self.args = args if args is not None else argparse.Namespace()

    def reset(self, problem: Problem) -> State:
        """Builds the scene of ``problem`` and returns the state at t = 0
        (the first row). An engine that sets ω itself starts at
        `Problem.start_omega`."""
        raise NotImplementedError(f"{type(self).__name__}.reset")

    def switch(self, before: Push, after: Push) -> None:
        """The pusher's velocity jumps from ``before`` to ``after`` (at
        ``after.t_start``, before its first step). An engine whose pusher is
        a velocity constraint sets ω to
        ``problem.omega_after_switch(before, after, omega)``. Default:
        nothing (the engine's own contact makes the jump)."""

    def step(self, push: Push | None, dt: float) -> State:
        """Advances the scene by ``dt`` (s) with the pusher's contact point
        moving at ``push.world_velocity(theta)``, and returns the state at
        the step's end (ω: the one held over the step). ``push`` None (only
        for an engine that `can_release`): the pusher has let go and the
        plate slides freely on its supports (a plate thrown without pushes
        starts with `Initial.velocity` and `Initial.omega`)."""
        raise NotImplementedError(f"{type(self).__name__}.step")

    def close(self) -> None:
        """Called after every problem, failed or not: release what `reset`
        built. Default: nothing."""

    def extra_columns(self, problem: Problem) -> tuple[str, ...]:
        """Names of columns written after ``omega`` for ``problem`` (called
        after `reset`). The trajectory format defines ``load_1..load_n``
        (normal force on support i in N, the problem's support order, the
        step's value) and ``rise`` (m, the centre of mass's height above its
        resting height); readers ignore columns they do not know. Default:
        none."""
        return ()

    def extras(self) -> Sequence[float]:
        """The values of `extra_columns` for the row just produced (after
        `reset`: the state at t = 0; after a step: that step's). Called only
        when `extra_columns` lists some."""
        return ()


@dataclass
class Run:
    """What `simulate` produced."""

    rows: list[tuple[float, ...]]
    """``(t, x, y, theta, omega, *extras)``: t = 0 first, then one per step."""
    steps: int
    """The number of steps."""
    step_time_s: float
    """Wall time in `Engine.reset`, `Engine.switch` and the steps (s)."""
    columns: tuple[str, ...] = ()
    """The engine's extra columns (`Engine.extra_columns`), after omega."""

    @property
    def header(self) -> str:
        """The CSV header of these rows."""
        return ",".join((HEADER, *self.columns))


def _engine_name(engine: Engine) -> str:
    return engine.name or os.path.basename(sys.argv[0] or "") or type(engine).__name__


def _state(value: Any, t: float) -> tuple[float, float, float, float]:
    try:
        x, y, theta, omega = (float(v) for v in value)
    except (TypeError, ValueError):
        raise AdapterError(
            f"the engine's state at t = {t!r} s is not four numbers (x, y, theta, omega): {value!r}"
        ) from None
    if not all(map(math.isfinite, (x, y, theta, omega))):
        raise AdapterError(
            f"the engine's state at t = {t!r} s is not finite: "
            f"x = {x!r}, y = {y!r}, theta = {theta!r}, omega = {omega!r}"
        )
    return x, y, theta, omega


def _extras(value: Any, columns: Sequence[str], t: float) -> tuple[float, ...]:
    try:
        vals = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise AdapterError(f"the engine's extras at t = {t!r} s are not numbers: {value!r}") from None
    if len(vals) != len(columns):
        raise AdapterError(
            f"the engine's extras at t = {t!r} s are {len(vals)} numbers for "
            f"{len(columns)} columns ({','.join(columns)})"
        )
    for name, v in zip(columns, vals):
        if not math.isfinite(v):
            raise AdapterError(f"the engine's {name} at t = {t!r} s is not finite: {v!r}")
    return vals


#: The pose and ω of a row (columns 1 to 4).
_POSE = operator.itemgetter(1, 2, 3, 4)


def _fine(rows: Sequence[tuple[Any, ...]]) -> bool:
    """Whether columns 1 to 4 (x, y, theta, omega) of every row are finite
    floats: passes in C over the rows, no Python loop (a sum that overflows
    says no, and the caller's exact check row by row decides)."""
    try:
        flat = list(itertools.chain.from_iterable(map(_POSE, rows)))
        return set(map(type, flat)) == {float} and math.isfinite(sum(flat))
    except (TypeError, IndexError):
        return False


REST_SPEED = 1e-5
"""Speed (m/s) below which a released plate counts as at rest: ``|v_cm| +
|ω| L``, ``L`` the farthest support from the centre of mass (pushval's
``pushval_engine::REST_SPEED``)."""

REST_STEPS = 10
"""Consecutive steps below `REST_SPEED` that make a rest (pushval's
``pushval_engine::REST_STEPS``)."""


class Stepper:
    """One problem stepped push by push on an engine (protocol 3, and what
    `simulate` runs): `Engine.reset` before the first push, `Engine.switch`
    between pushes, each push cut into equal steps (`Push.steps`), rows
    kept per step or at the sample times.

    ``problem`` is the problem `Engine.reset` receives with the first push
    as its schedule (a protocol 3 ``start``'s own schedule, if it has one,
    is applied by the first `advance` before its push). ``rows``:
    ``"steps"`` (one row per step) or ``"samples"`` (rows at the problem's
    sample times and at each push's end only; ω on a row is the one held
    over the interval since the row before, read at its middle, as pushval
    reads a step's ω). An engine with `extra_columns` writes every step
    unless its `Engine.rows` is ``"samples"``.
    """

    def __init__(self, engine: Engine, problem: Problem, rows: str = "steps"):
        if rows not in ("steps", "samples"):
            raise ValueError(f"unknown row mode {rows!r} (steps, samples)")
        if problem.switching not in engine.switching_rules:
            raise AdapterError(
                f"the problem asks for {problem.switching} switching; this engine follows "
                f"{' and '.join(engine.switching_rules)} only"
            )
        self.engine = engine
        self.problem = problem
        #: What `Engine.reset` receives; None: ``problem`` with the first
        #: push as its schedule.
        self.reset_problem: Problem | None = None
        self.asked = rows
        self.mode = rows
        self.pending = list(problem.pushes)
        self.applied: list[Push] = []
        self.columns: tuple[str, ...] = ()
        self.end = 0.0
        self.last: tuple[float, ...] | None = None
        self.steps = 0
        self.step_time_s = 0.0
        self.header_sent = False
        self.closed = False
        self.released = False

    def _reset(self, first: Push | None) -> list[tuple[float, ...]]:
        engine = self.engine
        problem = self.reset_problem or dataclasses.replace(
            self.problem, pushes=(first,) if first is not None else ()
        )
        started = time.perf_counter()
        state = engine.reset(problem)
        self.step_time_s += time.perf_counter() - started
        self.columns = tuple(engine.extra_columns(problem))
        extras = _extras(engine.extras(), self.columns, 0.0) if self.columns else ()
        if engine.rows == "samples" or (self.asked == "samples" and not self.columns):
            self.mode = "samples"
        else:
            self.mode = "steps"
        row = (0.0, *_state(state, 0.0), *extras)
        self.last = row
        if self.mode == "samples":
            row += (0,)  # the steps column: none before t = 0
        return [row]

    def apply(
        self,
        push: Push,
        progress: Callable[[float, float], None] | None = None,
        total: float | None = None,
    ) -> list[tuple[float, ...]]:
        """Applies ``push`` as given (its `Push.t_start` is where its rows
        start) and returns its rows: the row at t = 0 first on the first
        push, then the rows in (t_start, t_end], the last at t_end.
        ``progress(t, total)`` is called every 1024 steps."""
        if self.closed:
            raise AdapterError("the problem is finished: start another")
        if self.released:
            raise AdapterError("the plate was released: no push can follow the release")
        out: list[tuple[float, ...]] = []
        if not self.applied:
            out += self._reset(push)
        else:
            # The switch is the engine's own work: timed as its steps are.
            started = time.perf_counter()
            self.engine.switch(self.applied[-1], push)
            self.step_time_s += time.perf_counter() - started
        out += self._segment(push, progress, total)
        self.applied.append(push)
        # Summed in order, as pushval sums it.
        self.end += push.duration
        return out

    def advance(self, speed: float, phi: float, duration: float) -> list[tuple[float, ...]]:
        """Protocol 3's ``advance``: the push (speed m/s, phi rad in the
        object frame, duration s) starting where the pushes applied end;
        the first call applies the start's own schedule first. Returns the
        rows (see `apply`)."""
        if not self.pending:
            return self.apply(Push(len(self.applied), self.end, duration, speed, phi))
        todo = [(p.speed, p.phi, p.duration) for p in self.pending] + [(speed, phi, duration)]
        self.pending = []
        out: list[tuple[float, ...]] = []
        for sp, ph, du in todo:
            push = Push(index=len(self.applied), t_start=self.end, duration=du, speed=sp, phi=ph)
            out += self.apply(push)
        return out

    def release(self, max_duration: float) -> list[tuple[float, ...]]:
        """Protocol 3's ``release``: the pusher lets go after the pushes
        applied (none: the plate is thrown from `Initial`) and the engine
        steps (``push`` None) in equal steps of at most the problem's dt
        until the plate is at rest or ``max_duration`` (s) has passed.

        At rest: the speed ``|v_cm| + |ω| L`` (``v_cm`` from the step's
        displacement, ``L`` the farthest support from the centre of mass)
        below `REST_SPEED` on `REST_STEPS` consecutive steps; the rows end
        at the first of them (the stop time). Rows that end at ``t_release
        + max_duration`` mean the plate had not stopped. Returns the rows
        (after the pushes' last row; the row at t = 0 first for a throw)."""
        if self.closed:
            raise AdapterError("the problem is finished: start another")
        if self.released:
            raise AdapterError("the plate was already released")
        engine = self.engine
        if not engine.can_release:
            raise AdapterError(
                f"{_engine_name(engine)} cannot release: its step has no free slide "
                "(Engine.can_release is False), and a problem with a release is refused "
                "rather than ended at the release"
            )
        out: list[tuple[float, ...]] = []
        if not self.applied:
            self.pending = []
            out += self._reset(None)
        self.released = True
        n = max(1, math.ceil(max_duration / self.problem.dt * (1.0 - 1e-12)))
        h = max_duration / n
        t0 = self.end
        reach = max((math.hypot(*s.offset) for s in self.problem.supports), default=0.0)
        prev = self.last
        assert prev is not None
        px, py = prev[1], prev[2]
        states: list[Any] = []
        more: list[Any] = []
        held, first_rest = 0, None
        step = engine.step
        columns = self.columns
        started = time.perf_counter()
        for k in range(1, n + 1):
            s = step(None, h)
            states.append(s)
            if columns:
                more.append(engine.extras())
            x, y, w = s[0], s[1], s[3]
            speed = math.hypot(x - px, y - py) / h + abs(w) * reach
            px, py = x, y
            if speed < REST_SPEED:
                if first_rest is None:
                    first_rest = k
                held += 1
                if held >= REST_STEPS:
                    break
            else:
                first_rest, held = None, 0
        self.step_time_s += time.perf_counter() - started
        self.steps += len(states)
        m = first_rest if (first_rest is not None and held >= REST_STEPS) else len(states)
        states, more = states[:m], more[:m]
        t_end = t0 + max_duration if m == n else t0 + m * h
        if self.mode == "steps":
            times = [t0 + j * h for j in range(1, m)] + [t_end]
            rows = [
                (t, *_state(s, t), *(_extras(e, columns, t) if columns else ()))
                for t, s, e in zip(times, states, more if columns else itertools.repeat(()))
            ]
        else:
            slide = Push(index=len(self.applied), t_start=t0, duration=t_end - t0, speed=0.0, phi=0.0)
            rows = self._samples(slide, states, more, m, h, t_end)
            # The last row is the rest (or the state at max_duration): its
            # ω the last step's, not the interval's middle.
            r = rows[-1]
            rows[-1] = (*r[:4], float(states[m - 1][3]), *r[5:])
        self.last = rows[-1]
        self.end = t_end
        return out + rows

    def _segment(self, push: Push, progress, total) -> list[tuple[float, ...]]:
        engine = self.engine
        step = engine.step
        n = push.steps(self.problem.dt, engine.step_rule)
        h = push.duration / n
        t0 = push.t_start
        columns = self.columns
        extras = engine.extras
        started = time.perf_counter()
        states: list[Any] = []
        more: list[Any] = []
        for j0 in range(0, n, 1024):
            m = min(n, j0 + 1024) - j0
            if columns:
                for _ in range(m):
                    states.append(step(push, h))
                    more.append(extras())
            else:
                states += [step(push, h) for _ in range(m)]
            if progress is not None and j0 + m < n:
                progress(t0 + (j0 + m) * h, total if total is not None else t0 + push.duration)
        self.step_time_s += time.perf_counter() - started
        self.steps += n
        t_end = t0 + push.duration
        if self.mode == "steps":
            times = [t0 + j * h for j in range(1, n)] + [t_end]
            if columns:
                rows = [(t, *s, *_extras(e, columns, t)) for t, s, e in zip(times, states, more)]
            else:
                rows = [(t, *s) for t, s in zip(times, states)]
            if not (_fine(rows) and set(map(len, rows)) == {5 + len(columns)}):
                # Not four finite floats somewhere: checked row by row (the
                # first bad one named), numbers made floats.
                rows = [
                    (t, *_state(s, t), *(_extras(e, columns, t) if columns else ()))
                    for t, s, e in zip(times, states, more if columns else itertools.repeat(()))
                ]
        else:
            rows = self._samples(push, states, more, n, h, t_end)
        self.last = rows[-1]
        return rows

    def _samples(self, push: Push, states, more, n: int, h: float, t_end: float):
        """The rows at the sample times in (t_start, t_end) and at t_end."""
        t0 = push.t_start
        sdt = self.problem.sample_dt
        tol = 1e-9 * sdt
        k = math.floor(t0 / sdt * (1.0 + 1e-12) + 1e-9) + 1
        times = []
        while k * sdt < t_end - tol:
            times.append(k * sdt)
            k += 1
        times.append(t_end)
        prev = self.last
        assert prev is not None
        x0, y0, th0 = prev[1], prev[2], prev[3]
        rows: list[tuple[Any, ...]] = []
        append = rows.append
        t_prev = t0 if prev[0] < t0 else prev[0]
        columns = self.columns
        j_prev = 0
        ceil = math.ceil
        for t in times:
            u = (t - t0) / h
            j = round(u)
            if 1 <= j <= n and abs(u - j) < 1e-9:
                # On a step end (the usual case: sample_dt a whole number
                # of steps): that step's pose, exactly.
                b = states[j - 1]
                x, y, th = b[0], b[1], b[2]
            else:
                # Between the step ends around t.
                j = min(n, max(1, ceil(u - 1e-9)))
                b = states[j - 1]
                a = states[j - 2] if j >= 2 else (x0, y0, th0)
                s = u - (j - 1)
                x, y, th = a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2])
            # ω held over (t_prev, t], read at its middle.
            i = ceil(((t_prev + t) / 2 - t0) / h)
            if i > n:
                i = n
            elif i < 1:
                i = 1
            # The last number: the engine steps the row's interval took
            # (pushval's count).
            if columns:
                append((t, x, y, th, states[i - 1][3], *_extras(more[i - 1], columns, t), j - j_prev))
            else:
                append((t, x, y, th, states[i - 1][3], j - j_prev))
            t_prev, j_prev = t, j
        # Four finite floats each (checked at once; else row by row, the
        # first bad row named).
        if not _fine(rows):
            rows = [(r[0], *_state(r[1:5], r[0]), *r[5:]) for r in rows]
        return rows

    def close(self) -> None:
        """Ends the problem (`Engine.close`), once."""
        if not self.closed:
            self.closed = True
            self.engine.close()

    @property
    def header(self) -> str:
        """The CSV header of the rows: `HEADER`, the engine's extra columns,
        and with rows at the sample times ``steps`` (the engine steps each
        row's interval took)."""
        return ",".join((HEADER, *self.columns, *(("steps",) if self.mode == "samples" else ())))


def simulate(
    engine: Engine,
    problem: Problem,
    progress: Callable[[float, float], None] | None = None,
) -> Run:
    """Runs ``problem`` on ``engine``: `Engine.reset`, then every segment's
    steps (with `Engine.switch` between segments), `Engine.close` at the
    end; one row per step. ``progress(t, end)`` is called now and then
    (every 1024 steps).

    Raises `AdapterError` for a switching rule the engine does not follow or
    a state that is not four finite numbers.
    """
    stepper = Stepper(engine, dataclasses.replace(problem, pushes=()), "steps")
    stepper.reset_problem = problem
    end = problem.duration
    try:
        rows: list[tuple[float, ...]] = []
        for push in problem.pushes:
            rows += stepper.apply(push, progress, end)
    finally:
        stepper.close()
    return Run(rows=rows, steps=stepper.steps, step_time_s=stepper.step_time_s, columns=stepper.columns)


# --------------------------------------------------------------------------
# Writing an answer


def _sampled(problem: Problem, rows: Sequence[tuple[float, ...]]) -> list[tuple[float, ...]]:
    """The rows at the problem's sample times: the pose interpolated
    linearly between the step ends around each, ω (and any extra column) the
    one of the step holding it (at t = 0, the first row's)."""
    times = [r[0] for r in rows]
    out = []
    for t in problem.sample_times():
        k = bisect.bisect_left(times, t)
        if k == 0:
            out.append((t, *rows[0][1:]))
            continue
        if k >= len(rows):
            out.append((t, *rows[-1][1:]))
            continue
        a, b = rows[k - 1], rows[k]
        s = (t - a[0]) / (b[0] - a[0])
        out.append((t, a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2]), a[3] + s * (b[3] - a[3]), *b[4:]))
    return out


def _csv(rows: Iterable[tuple[float, ...]]) -> str:
    return "".join(",".join(map(repr, r)) + "\n" for r in rows)


def _compact(rows: Sequence[tuple[float, ...]]) -> str:
    """``rows`` as one compact line (protocol 3, where pushval's ``start``
    says ``"compact": true``): ``!`` then the numbers, row after row, as
    hexadecimal little-endian IEEE 754 binary64 (16 digits each); exact, and
    far cheaper to write than decimal text."""
    numbers = array.array("d", itertools.chain.from_iterable(rows))
    if sys.byteorder != "little":
        numbers.byteswap()
    return "!" + numbers.tobytes().hex() + "\n"


def answer(
    problem: Problem,
    run: Run,
    mode: str = "steps",
    framing: str = "",
    note: Callable[[str], None] | None = None,
) -> str:
    """The CSV answer to ``problem``: header and rows (per step, or per
    sample for ``mode = "samples"``), then ``framing`` (``"#end\\n"`` in a
    session). Within the problem's `Limits`: rows per step that would exceed
    them are written per sample (``note`` says so); if those exceed them too,
    `AdapterError`. The header is `HEADER` followed by the run's extra
    columns, if any."""
    if mode not in ("steps", "samples"):
        raise ValueError(f"unknown row mode {mode!r} (steps, samples)")
    lim = problem.limits
    head = run.header + "\n"

    def within(rows: Sequence[tuple[float, ...]]) -> tuple[str | None, str]:
        """Why ``rows`` exceed the limits (None: they fit), and their text."""
        if lim.max_rows is not None and len(rows) > lim.max_rows:
            return f"{len(rows)} rows (the limit is {lim.max_rows})", ""
        text = _csv(rows)
        if lim.max_bytes is not None:
            size = len(head) + len(text.encode()) + len(framing.encode())
            if size > lim.max_bytes:
                return f"{size} bytes (the limit is {lim.max_bytes})", ""
        return None, text

    if mode == "samples":
        why, text = within(_sampled(problem, run.rows))
        if why:
            raise AdapterError(f"the answer exceeds the problem's limits: {why}")
        return head + text + framing
    why, text = within(run.rows)
    if why:
        samples = _sampled(problem, run.rows)
        why_samples, text = within(samples)
        if why_samples:
            raise AdapterError(
                f"the answer exceeds the problem's limits: {run.steps} steps would be {why}, "
                f"and its {len(samples)} sample times still {why_samples}"
            )
        if note is not None:
            note(f"{run.steps} steps would be {why}: writing the {len(samples)} sample times instead")
    return head + text + framing


# --------------------------------------------------------------------------
# Serving


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


class _Server:
    """Reads problems, runs them, writes answers."""

    def __init__(self, engine: Engine, out: IO[str], err: IO[str], timing: bool):
        self.engine = engine
        self.compact = False
        self.out = out
        self.err = err
        self.timing = timing
        #: Wall time answering the current protocol 3 problem's requests
        #: (from reading each line to its answer ready to write), for
        #: --timing.
        self.answer_time_s = 0.0
        self.name = _engine_name(engine)

    def say(self, text: str) -> None:
        self.err.write(f"{self.name}: {text}\n")
        self.err.flush()

    def progress(self) -> Callable[[float, float], None]:
        start = time.monotonic()
        next_at = [start + PROGRESS_EVERY_S]

        def report(t: float, end: float) -> None:
            now = time.monotonic()
            if now >= next_at[0]:
                next_at[0] = now + PROGRESS_EVERY_S
                self.say(f"t = {t:.4g} of {end:.4g} s ({100 * t / end:.0f} %), {now - start:.1f} s so far")

        return report

    def solve(self, problem: Problem, framing: str) -> str:
        run = simulate(self.engine, problem, self.progress())
        if self.timing:
            self.err.write(f"step_time_s={run.step_time_s!r} steps={run.steps}\n")
            self.err.flush()
        return answer(problem, run, self.engine.rows, framing, self.say)

    def failure(self, e: BaseException) -> str:
        """Reports a failed run on standard error; returns its one-line
        message."""
        if isinstance(e, (AdapterError, ProblemError)):
            message = str(e)
        else:
            import traceback

            traceback.print_exception(type(e), e, e.__traceback__, file=self.err)
            message = f"{type(e).__name__}: {e}"
        return _one_line(message)

    def one_shot(self, stdin: IO[str]) -> int:
        try:
            problem = parse_problem(stdin.read())
        except ProblemError as e:
            self.say(f"the problem document on standard input: {e}")
            return 2
        try:
            text = self.solve(problem, "")
        except Exception as e:  # noqa: BLE001 - every failure is reported
            self.say(f"the run failed: {self.failure(e)}")
            return 1
        self.out.write(text)
        self.out.flush()
        return 0

    def session(self, stdin: IO[str]) -> int:
        number = 0
        self.stepper: Stepper | None = None
        try:
            while True:
                line = stdin.readline()
                if not line:
                    return 0
                if not line.strip():
                    continue
                number += 1
                started = time.perf_counter()
                text = self.request(line, number)
                self.answer_time_s += time.perf_counter() - started
                # One write a request: the answer and its closing line.
                self.out.write(text)
                self.out.flush()
        finally:
            self.drop_stepper()

    def drop_stepper(self) -> None:
        if self.stepper is not None:
            stepper, self.stepper = self.stepper, None
            stepper.close()

    def request(self, line: str, number: int) -> str:
        """The answer to one session document (its closing line included)."""
        tag = ""
        what = f"problem {number}"
        try:
            try:
                doc = json.loads(line)
            except ValueError as e:
                raise ProblemError(f"not JSON: {e}") from None
            if not isinstance(doc, dict):
                raise ProblemError(f"must be an object, got {_kind(doc)}")
            request = doc.get("request")
            if request is not None:
                if isinstance(request, bool) or not isinstance(request, int) or request <= 0:
                    raise ProblemError(f"`request` must be a whole number > 0, got {request!r}")
                tag = f" {request}"
                what = f"request {request}"
            op = doc.get("op")
            if op is None:
                # A whole problem (protocols 1 and 2): whatever was being
                # stepped is abandoned.
                self.drop_stepper()
                return self.solve(parse_problem(doc), f"#end{tag}\n")
            return self.step(doc, op, tag)
        except ProblemError as e:
            self.drop_stepper()
            text = f"#error{tag} {what}: the document: {_one_line(str(e))}\n"
        except Exception as e:  # noqa: BLE001 - every failure is answered
            self.drop_stepper()
            text = f"#error{tag} {what}: {self.failure(e)}\n"
        self.say(text.split(" ", 1 + bool(tag))[-1].rstrip())
        return text

    def step(self, doc: dict[str, Any], op: Any, tag: str) -> str:
        """Protocol 3: ``start``, ``advance`` or ``finish``."""
        if op == "advance" and self.stepper is not None:
            # The usual advance (three finite floats, as pushval writes
            # them) without the reader's checks; anything else takes the
            # checked path below, whose errors name the key.
            speed, phi, duration = doc.get("speed"), doc.get("phi"), doc.get("duration")
            if (
                type(speed) is float
                and type(phi) is float
                and type(duration) is float
                and 0.0 <= speed < _INF
                and -_INF < phi < _INF
                and 0.0 < duration < _INF
            ):
                return self.rows(self.stepper, self.stepper.advance(speed, phi, duration), tag)
        r = _Reader(doc, "")
        if op == "start":
            self.drop_stepper()
            self.answer_time_s = 0.0
            rows = r.string("rows") if r.has("rows") else "steps"
            if rows not in ("steps", "samples"):
                raise ProblemError(f"`rows` is {rows!r}; known: steps, samples")
            problem = parse_problem(r.raw("problem"), schedule=False)
            self.stepper = Stepper(self.engine, problem, rows)
            self.compact = r.has("compact") and r.boolean("compact")
            return f"#ok{tag}\n"
        if op not in ("advance", "release", "finish"):
            raise ProblemError(f"`op` is {op!r}; known: start, advance, release, finish")
        if self.stepper is None:
            raise ProblemError(f"`{op}` without a `start` before it (or after a failed request)")
        stepper = self.stepper
        if op == "finish":
            self.drop_stepper()
            if self.timing:
                self.err.write(
                    f"step_time_s={stepper.step_time_s!r} steps={stepper.steps} "
                    f"answer_time_s={self.answer_time_s!r}\n"
                )
                self.err.flush()
            return f"#end{tag}\n"
        if op == "release":
            return self.rows(stepper, stepper.release(r.number("max_duration", 0.0, strict=True)), tag)
        rows = stepper.advance(
            r.number("speed", 0.0), r.number("phi"), r.number("duration", 0.0, strict=True)
        )
        return self.rows(stepper, rows, tag)

    def rows(self, stepper: Stepper, rows: Sequence[tuple[float, ...]], tag: str) -> str:
        """An advance's answer: the header (after ``start``, once), the
        rows (one compact line, or text) and ``#end N``."""
        head = ""
        if not stepper.header_sent:
            stepper.header_sent = True
            head = stepper.header + "\n"
        body = _compact(rows) if self.compact else _csv(rows)
        return head + body + f"#end{tag}\n"

def serve(
    engine: Engine,
    session: bool = False,
    stdin: IO[str] | None = None,
    stdout: IO[str] | None = None,
    stderr: IO[str] | None = None,
    timing: bool = False,
) -> int:
    """Serves problems from ``stdin`` on ``engine`` (one-shot, or a session
    of one document per line), answering on ``stdout``; returns the exit
    status (see the module docs). The streams default to the process's."""
    server = _Server(engine, stdout or sys.stdout, stderr or sys.stderr, timing)
    stdin = stdin or sys.stdin
    return server.session(stdin) if session else server.one_shot(stdin)


def _protocol_stdout() -> IO[str]:
    """The real standard output for the protocol alone; file descriptor 1
    (and so anything else that prints) goes to standard error from now on."""
    try:
        sys.stdout.flush()
        fd = os.dup(1)
        os.dup2(2, 1)
    except (OSError, ValueError, AttributeError):
        return sys.stdout  # not a real file (an embedding host): keep it
    return os.fdopen(fd, "w", encoding="utf-8", newline="\n")


def main(engine: Callable[[argparse.Namespace], Engine], argv: Sequence[str] | None = None) -> None:
    """Runs an adapter process: parses the command line (``--session``,
    ``--timing`` and the engine's own options, see
    `Engine.add_arguments`), builds the engine once, serves standard input
    and exits with the status of `serve`. A bad command line exits 2."""
    parser = argparse.ArgumentParser(
        prog=getattr(engine, "name", "") or None,
        description=(getattr(engine, "__doc__", None) or "").strip().split("\n\n")[0] or None,
    )
    parser.add_argument(
        "--session",
        action="store_true",
        help="serve one problem document per line until standard input closes "
        "(answers closed by #end N, #ok N or #error N MESSAGE; pushval sets PUSHVAL_SESSION=1 instead)",
    )
    parser.add_argument(
        "--timing",
        action="store_true",
        help="after each answer print step_time_s=S steps=N on standard error",
    )
    add = getattr(engine, "add_arguments", None)
    if add is not None:
        add(parser)
    args = parser.parse_args(argv)
    out = _protocol_stdout()
    stdin = open(sys.stdin.fileno(), encoding="utf-8", closefd=False)
    try:
        instance = engine(args)
    except AdapterError as e:
        sys.stderr.write(f"{parser.prog}: {e}\n")
        sys.exit(1)
    try:
        # pushval starts a session with PUSHVAL_SESSION=1 in the environment
        # (`session = true` in pushval.toml); --session does the same by hand.
        session = args.session or os.environ.get("PUSHVAL_SESSION") == "1"
        status = serve(instance, session, stdin, out, sys.stderr, args.timing)
    except BrokenPipeError:
        status = 1  # pushval stopped reading: nothing more to say
    except KeyboardInterrupt:
        status = 130
    sys.exit(status)
