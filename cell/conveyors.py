"""The two belt conveyors (thesis §4.1, §5.2, §6.2 a).

A belt is a speed schedule: piecewise-constant speeds from given instants, so
its travel X(t) is piecewise linear and exact.  Speed changes take effect at
once (§6.2 a: negligible lag).  The controller writes the schedule ahead of
time (a change at LO, the step 6.3 decay at the end of the cycle, the output
belt back to nominal at G); a part's arrival is the instant the belt has
carried it the required distance, so the input conveyor's SimPy process only
wakes when a part reaches B, or when a new plan moves that instant.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable
from typing import Any

import simpy

from cell.mailbox import Mailbox

#: Two instants closer than this are the same instant (float rounding of planned times).
EPS_S = 1e-6


def speed_at(instants: list[float], speeds: list[float], t: float) -> float:
    """A piecewise-constant schedule's speed at t: the last change at or before t."""
    return speeds[max(bisect.bisect_right(instants, t) - 1, 0)]


class Belt:
    """A belt's speed schedule and travel X(t) (inches since t = 0).

    Only the schedule from the present on is kept: a change whose successor has
    started is final and is handed to ``on_change`` (e.g. a ``belts.csv``
    writer) and dropped, so a long run keeps a few entries, not its history.
    """

    def __init__(self, speed_in_s: float,
                 on_change: Callable[[float, float], Any] | None = None):
        self._t: list[float] = [0.0]
        """Instants at which a speed starts."""
        self._x: list[float] = [0.0]
        """Travel at those instants."""
        self._v: list[float] = [speed_in_s]
        """Speed from each instant on (the last one holds for ever)."""
        self.on_change = on_change
        """Told (instant, speed) of every change once it is final."""
        self.max_speed_in_s = speed_in_s
        """The fastest of the settled speeds (of all of them once closed)."""
        self.min_speed_in_s = speed_in_s
        """The slowest of them."""

    def speed(self, t: float) -> float:
        return speed_at(self._t, self._v, t)

    def travel(self, t: float) -> float:
        """X(t): inches the belt has moved by time t (t ≥ the last settled change)."""
        k = bisect.bisect_right(self._t, t) - 1
        return self._x[k] + self._v[k] * (t - self._t[k])

    def time_at(self, x: float) -> float:
        """First instant at which the belt's travel reaches x (speeds are > 0)."""
        k = max(bisect.bisect_right(self._x, x) - 1, 0)
        return self._t[k] + (x - self._x[k]) / self._v[k]

    def plan(self, t1: float, v1: float, t2: float | None = None, v2: float = 0.0) -> None:
        """From instant t1 (now or later) run at v1, and from t2 > t1 at v2, dropping
        later plans.

        A new plan supersedes whatever was planned after t1 (the controller
        replans every cycle); a change within EPS_S of the last one replaces it.
        Changes before ``t1`` whose successors have started are settled.
        """
        if not v1 > 0 or (t2 is not None and not v2 > 0):
            raise ValueError(f"belt speeds must be positive, got {v1!r}, {v2!r}")
        ts, xs, vs = self._t, self._x, self._v
        k = bisect.bisect_right(ts, t1 + EPS_S)
        if k < len(ts):
            del ts[k:], xs[k:], vs[k:]
        self._settle(t1)
        self._append(t1, v1)
        if t2 is not None:
            self._append(t2, v2)

    def _settle(self, now: float) -> None:
        ts, xs, vs = self._t, self._x, self._v
        n = bisect.bisect_right(ts, now) - 1
        if n > 0:
            self._emit(n)
            del ts[:n], xs[:n], vs[:n]

    def _emit(self, n: int) -> None:
        top, bottom = max(self._v[:n]), min(self._v[:n])
        if top > self.max_speed_in_s:
            self.max_speed_in_s = top
        if bottom < self.min_speed_in_s:
            self.min_speed_in_s = bottom
        if self.on_change is not None:
            for t, v in zip(self._t[:n], self._v[:n]):
                self.on_change(t, v)

    def _append(self, t: float, v: float) -> None:
        """Run at v from t on (t at or before the last change: that change's speed is v)."""
        ts, xs, vs = self._t, self._x, self._v
        if t <= ts[-1]:
            vs[-1] = v
        else:
            xs.append(xs[-1] + vs[-1] * (t - ts[-1]))
            ts.append(t)
            vs.append(v)

    def close(self) -> None:
        """Hand every change still held (planned ones included) to ``on_change``."""
        self._emit(len(self._t))
        del self._t[:], self._x[:], self._v[:]


class InputConveyor:
    """Carries parts from the feeder, ``length_in`` upstream of B, to B.

    Its process takes each part the feeder drops (``loaded``), waits until the
    belt has carried it to B, and puts it in ``at_bot`` for the controller.  A
    part nobody picks up rides on to F and falls off (thesis §6.3).
    """

    def __init__(self, env: simpy.Environment, speed_in_s: float, length_in: float,
                 on_change: Callable[[float, float], Any] | None = None):
        self.env = env
        self.belt = Belt(speed_in_s, on_change)
        self.length_in = length_in
        """Feeder drop point to B (in)."""
        self.loaded: Mailbox = Mailbox(env)
        """Parts dropped on the belt by the feeder (their records)."""
        self.at_bot: Mailbox = Mailbox(env)
        """Parts as they reach B."""
        self.x_fed: dict[int, float] = {}
        """Belt travel at the instant each part on the belt was dropped (by index)."""
        self._timing = False
        self.feeder: Any = None
        """The feeder, told of a replan while it holds a part back."""
        self.process = env.process(self.run())

    def drop(self, part: Any) -> float:
        """The feeder puts a part (its record) on the belt now; returns the belt's travel."""
        x = self.x_fed[part.part - 1] = self.belt.travel(self.env.now)
        self.loaded.put(part)
        return x

    def replan(self, t1: float, v1: float, t2: float | None = None, v2: float = 0.0) -> None:
        """New speed plan from the controller (see :meth:`Belt.plan`).

        The controller plans when a part reaches B, before this process times the
        next part (same-instant events run in order); should a plan ever arrive
        while a part is being timed, the process is interrupted and re-times it.
        """
        self.belt.plan(t1, v1, t2, v2)
        if self._timing:
            self.process.interrupt()
        feeder = self.feeder
        if feeder is not None and feeder.holding:
            feeder.process.interrupt()

    def run(self):  # noqa: ANN201 (SimPy generator)
        env, get, timeout = self.env, self.loaded.get, self.env.timeout
        time_at, x_fed, length = self.belt.time_at, self.x_fed, self.length_in
        while True:
            part = yield get()
            x_at_bot = x_fed[part.part - 1] + length
            self._timing = True
            while True:
                try:
                    yield timeout(max(time_at(x_at_bot) - env.now, 0.0))
                    break
                except simpy.Interrupt:  # the plan changed: re-time the part
                    pass
            self._timing = False
            del x_fed[part.part - 1]
            part.at_bot_s = env.now
            # The controller takes the part (and may replan the belt) before this
            # process's next get() is served: same-instant events run in order.
            self.at_bot.put(part)


class OutputConveyor:
    """Takes parts from the robot at TD and records their spacing (thesis §4.3 f).

    Spacing of a part = the output belt's travel between the previous part's
    touch-down and its own: the distance between the two on the belt.  Each part
    set down is handed on to ``delivered`` (the run's log).
    """

    def __init__(self, env: simpy.Environment, speed_in_s: float,
                 delivered: Callable[[Any], Any],
                 on_change: Callable[[float, float], Any] | None = None):
        self.env = env
        self.belt = Belt(speed_in_s, on_change)
        self.placed: Mailbox = Mailbox(env)
        """Parts set down by the robot."""
        self.delivered = delivered
        self.last_td_x: float | None = None
        """Belt travel at the last touch-down (None before the first)."""
        self.last_td_s: float | None = None
        """Instant of the last touch-down (None before the first)."""
        self.process = env.process(self.run())

    def gap_now(self) -> float | None:
        """How far the last part set down has travelled since (None if none yet)."""
        if self.last_td_x is None:
            return None
        return self.belt.travel(self.env.now) - self.last_td_x

    def replan(self, t1: float, v1: float, t2: float | None = None, v2: float = 0.0) -> None:
        self.belt.plan(t1, v1, t2, v2)

    def run(self):  # noqa: ANN201 (SimPy generator)
        env, get, travel, delivered = self.env, self.placed.get, self.belt.travel, self.delivered
        while True:
            part = yield get()
            td = part.touchdown_s
            x = travel(env.now)
            if self.last_td_x is not None:
                part.spacing_in = x - self.last_td_x
                part.delivery_interval_s = td - self.last_td_s
            self.last_td_x, self.last_td_s = x, td
            delivered(part)
