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

import simpy

from cell.mailbox import Mailbox

#: Two instants closer than this are the same instant (float rounding of planned times).
EPS_S = 1e-6


class Belt:
    """A belt's speed schedule and travel X(t) (inches since t = 0)."""

    def __init__(self, speed_in_s: float):
        self._t: list[float] = [0.0]
        """Instants at which a speed starts."""
        self._x: list[float] = [0.0]
        """Travel at those instants."""
        self._v: list[float] = [speed_in_s]
        """Speed from each instant on (the last one holds for ever)."""

    def speed(self, t: float) -> float:
        return self._v[bisect.bisect_right(self._t, t) - 1]

    def travel(self, t: float) -> float:
        """X(t): inches the belt has moved by time t (t ≥ 0)."""
        k = bisect.bisect_right(self._t, t) - 1
        return self._x[k] + self._v[k] * (t - self._t[k])

    def time_at(self, x: float) -> float:
        """First instant at which the belt's travel reaches x (speeds are > 0)."""
        k = max(bisect.bisect_right(self._x, x) - 1, 0)
        return self._t[k] + (x - self._x[k]) / self._v[k]

    def plan(self, t1: float, v1: float, t2: float | None = None, v2: float = 0.0) -> None:
        """From instant t1 run at v1 (and from t2 > t1 at v2), dropping later plans.

        A new plan supersedes whatever was planned after t1 (the controller
        replans every cycle); a change within EPS_S of the last one replaces it.
        """
        ts, xs, vs = self._t, self._x, self._v
        k = bisect.bisect_right(ts, t1 + EPS_S)
        if k < len(ts):
            del ts[k:], xs[k:], vs[k:]
        if not v1 > 0 or (t2 is not None and not v2 > 0):
            raise ValueError(f"belt speeds must be positive, got {v1!r}, {v2!r}")
        self._append(t1, v1)
        if t2 is not None:
            self._append(t2, v2)

    def _append(self, t: float, v: float) -> None:
        """Run at v from t on (t at or before the last change: that change's speed is v)."""
        ts, xs, vs = self._t, self._x, self._v
        if t <= ts[-1]:
            vs[-1] = v
        else:
            xs.append(xs[-1] + vs[-1] * (t - ts[-1]))
            ts.append(t)
            vs.append(v)

    def max_speed(self) -> float:
        """The fastest the belt has been (or is planned to be)."""
        return float(max(self._v))

    def history(self) -> list[tuple[float, float]]:
        """(instant, speed) of every speed change, for plots and checks."""
        return list(zip(self._t, self._v))


class InputConveyor:
    """Carries parts from the feeder, ``length_in`` upstream of B, to B.

    Its process takes each part the feeder drops (``loaded``), waits until the
    belt has carried it to B, and puts it in ``at_bot`` for the controller.  A
    part nobody picks up rides on to F and falls off (thesis §6.3).
    """

    def __init__(self, env: simpy.Environment, speed_in_s: float, length_in: float,
                 n_parts: int):
        self.env = env
        self.belt = Belt(speed_in_s)
        self.length_in = length_in
        """Feeder drop point to B (in)."""
        self.loaded: Mailbox = Mailbox(env)
        """Parts dropped on the belt by the feeder (part numbers)."""
        self.at_bot: Mailbox = Mailbox(env)
        """Parts as they reach B."""
        self.x_fed: list[float] = [float("nan")] * n_parts
        """Belt travel at the instant each part was dropped on."""
        self._timing = False
        self.process = env.process(self.run())

    def drop(self, part: int) -> None:
        """The feeder puts a part on the belt now."""
        self.x_fed[part] = self.belt.travel(self.env.now)
        self.loaded.put(part)

    def time_at_bot(self, part: int) -> float:
        """When a dropped part reaches B under the current schedule."""
        return self.belt.time_at(self.x_fed[part] + self.length_in)

    def replan(self, t1: float, v1: float, t2: float | None = None, v2: float = 0.0) -> None:
        """New speed plan from the controller (see :meth:`Belt.plan`).

        The controller plans when a part reaches B, before this process times the
        next part (same-instant events run in order); should a plan ever arrive
        while a part is being timed, the process is interrupted and re-times it.
        """
        self.belt.plan(t1, v1, t2, v2)
        if self._timing:
            self.process.interrupt()

    def run(self):  # noqa: ANN201 (SimPy generator)
        env, get, timeout = self.env, self.loaded.get, self.env.timeout
        time_at, x_fed, length = self.belt.time_at, self.x_fed, self.length_in
        while True:
            part = yield get()
            self._timing = True
            while True:
                try:
                    yield timeout(max(time_at(x_fed[part] + length) - env.now, 0.0))
                    break
                except simpy.Interrupt:  # the plan changed: re-time the part
                    pass
            self._timing = False
            # The controller takes the part (and may replan the belt) before this
            # process's next get() is served: same-instant events run in order.
            self.at_bot.put(part)


class OutputConveyor:
    """Takes parts from the robot at TD and records their spacing (thesis §4.3 f).

    Spacing of a part = the output belt's travel between the previous part's
    touch-down and its own: the distance between the two on the belt.
    """

    def __init__(self, env: simpy.Environment, speed_in_s: float, n_parts: int):
        self.env = env
        self.belt = Belt(speed_in_s)
        self.placed: Mailbox = Mailbox(env)
        """Parts set down by the robot."""
        self.spacing_in: list[float] = [float("nan")] * n_parts
        self.last_td_x: float | None = None
        """Belt travel at the last touch-down (None before the first)."""
        self.process = env.process(self.run())

    def gap_now(self) -> float | None:
        """How far the last part set down has travelled since (None if none yet)."""
        if self.last_td_x is None:
            return None
        return self.belt.travel(self.env.now) - self.last_td_x

    def replan(self, t1: float, v1: float, t2: float | None = None, v2: float = 0.0) -> None:
        self.belt.plan(t1, v1, t2, v2)

    def run(self):  # noqa: ANN201 (SimPy generator)
        while True:
            part = yield self.placed.get()
            x = self.belt.travel(self.env.now)
            if self.last_td_x is not None:
                self.spacing_in[part] = x - self.last_td_x
            self.last_td_x = x
