"""An equipment's failure clock: budgets used at the rates of what the equipment does, and one
event at the instant the first runs out (docs/model.md, "When equipment fails").

The budget and its rates come from an :class:`Exposure`, the hook for a wear model: the
default (:class:`Distributed`) is a time to failure on the operating or calendar clock; a wear
model (:class:`cell.sim.wear_clock.WearExposure`) gives one budget per motor and a rate per leg
of each cycle.  The robot's clock is told each cycle's legs as the cycle starts
(:meth:`FailureClock.cycle`): when no budget runs out in it, the cycle's use is taken at once
and nothing else happens until the cycle ends; otherwise the robot tells the clock each leg
as it comes (:meth:`FailureClock.follow`).  Either way the clock keeps one event, moved only
when the instant its budget runs out moves.

While no budget is near its end, a cycle costs the clock one comparison: the exposure bounds
the use a second (:meth:`Exposure.peak_rates`), so until half the smallest budget's time at
that rate has passed no cycle can use a budget up, and the cycles' legs are kept and their use
taken when the clock next looks at its budgets (in the cycles' order: the same floats).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, Protocol

import numpy as np
import simpy

from cell.sim.conveyors import EPS_S

#: Legs of a cycle (the stretches a wear model times: cell.arm.steptable's segments).
LEGS = ("r1_pre", "r1_post", "r2", "r3_pre", "r3_post", "r4")
#: What the failure clock is told the robot is doing: a leg (0-5) in motion, or
MOVING_NOT, STOPPED = -1, -2
"""up and not in motion (at B, or held by a belt), or stopped (down, in maintenance)."""


class Exposure(Protocol):
    """What a failure clock counts down (the hook for wear, :mod:`cell.sim.wear`)."""

    cause: str
    """failures.csv's ``cause`` of a failure it brings: ``failure`` or ``wear``."""

    def thresholds(self) -> list[float]:
        """The budget of each component (a motor) at the start."""

    def renew(self, component: int) -> float:
        """A new budget for a component once repaired (replaced)."""

    def rates(self, leg: int) -> Sequence[float]:
        """Each component's budget used per second while the equipment does ``leg``."""

    def cycle(self, legs_s: Sequence[float]) -> Sequence[float] | None:
        """A cycle starts whose legs (:data:`LEGS`) take these times: each component's budget
        the whole cycle uses (None: not known ahead, the clock then counts leg by leg)."""

    def cycles(self, legs_s: Sequence[Sequence[float]]) -> np.ndarray:
        """(n, components): :meth:`cycle` of each of n cycles, in order (the same floats)."""

    def peak_rates(self) -> Sequence[float] | None:
        """Each component's most budget used a second, whatever the equipment does (None: no
        bound, or budget used at rest: the clock then takes every cycle's use as it starts)."""


class Distributed:
    """A time to failure drawn from a distribution, on the operating or calendar clock."""

    cause = "failure"

    def __init__(self, draw: Callable[[], float], clock: str):
        self.draw, self.calendar = draw, clock == "calendar"

    def thresholds(self) -> list[float]:
        return [self.draw()]

    def renew(self, component: int) -> float:
        return self.draw()

    def rates(self, leg: int) -> Sequence[float]:
        return (1.0,) if leg >= 0 or (self.calendar and leg == MOVING_NOT) else (0.0,)

    def cycle(self, legs_s: Sequence[float]) -> Sequence[float]:
        return (sum(legs_s),)  # 1 a second in every leg, on either clock

    def cycles(self, legs_s: Sequence[Sequence[float]]) -> np.ndarray:
        return np.array([sum(legs) for legs in legs_s], dtype=float).reshape(-1, 1)

    def peak_rates(self) -> Sequence[float] | None:
        return None if self.calendar else (1.0,)


class FailureClock:
    """An equipment's failure clock: a budget per component (:meth:`Exposure.thresholds`),
    used at the rates of what the equipment does (:meth:`Exposure.rates`), and one event, at
    the instant the first budget runs out, moved only when what the equipment will do changes
    (:meth:`follow`, :meth:`cycle`).  When it comes the equipment fails (``fail``, a SimPy
    generator: the stop, the crew, the repair), and the component gets a new budget."""

    def __init__(self, env: simpy.Environment, exposure: Exposure,
                 fail: Callable[[int, str], Any], leg: int):
        self.env, self.exposure, self.fail = env, exposure, fail
        self.left = exposure.thresholds()
        """Each component's budget as of :attr:`since`."""
        self.since = env.now
        self.plan: list[tuple[float, Sequence[float]]] = [(env.now, exposure.rates(leg))]
        """(from, rates) of what the equipment does from :attr:`since` on; the last holds."""
        self.due_s = math.inf
        """When the first budget runs out, as planned (inf: never)."""
        self.failing = False
        """True from the failure to the repair (the clock stands meanwhile)."""
        self.pending: list[Sequence[float]] = []
        """The legs of the cycles whose use is not yet taken from :attr:`left` (the clock's
        text: taken, in order, when the clock next looks at its budgets)."""
        self.safe_s = -math.inf
        """Till when a cycle (the equipment idle between cycles) cannot use a budget up."""
        self.peak = exposure.peak_rates()
        self._due: simpy.Event | None = None
        self._first = -1
        self._arm()

    def follow(self, leg: int) -> None:
        """The equipment does ``leg`` from now on (a leg, MOVING_NOT or STOPPED)."""
        now = self.env.now
        self._use_to(now)
        self.plan = [(now, self.exposure.rates(leg))]
        self.safe_s = -math.inf
        self._arm()

    def cycle(self, legs_s: Sequence[float], end_s: float, clear: bool = True) -> bool:
        """A cycle starts now whose legs (:data:`LEGS`) take ``legs_s``, back at rest at
        ``end_s``.  If nothing else can stop the equipment till then (``clear``) and no budget
        runs out before then, the cycle's use is taken from the budgets at once, the clock
        stands until the cycle's end, and the answer is True; else False, and the caller tells
        the clock each leg as it comes (:meth:`follow`)."""
        # speed: docs/performance.md#kept-cycles
        if clear and end_s <= self.safe_s:  # no budget can run out: its use taken later
            self.pending.append(legs_s)
            return True
        now, exposure = self.env.now, self.exposure
        self._use_to(now)
        use = exposure.cycle(legs_s)
        if use is None or self.failing or not clear:
            return False
        left = [b - u for b, u in zip(self.left, use)]
        for b, u in zip(left, use):
            if b <= u * 1e-9 + 1e-12:  # it may run out in this cycle (a margin for rounding)
                return False
        self.left, self.since = left, end_s
        idle = exposure.rates(MOVING_NOT)
        self.plan = [(end_s, idle)]
        if self.due_s < math.inf or any(idle):
            self._arm()
        elif self.peak is not None:  # idle uses nothing: safe for half the budget at the peak
            self.safe_s = end_s + 0.5 * min(
                x / r if r > 0 else math.inf for x, r in zip(left, self.peak))
        return True

    def settle(self) -> None:
        """Take the kept cycles' use now (the run's end: the exposure's totals complete)."""
        if self.pending:
            self._take_pending()

    def _take_pending(self) -> None:
        """Take the kept cycles' use from the budgets, cycle by cycle (the same floats as one
        by one: ``subtract.accumulate`` subtracts in order)."""
        uses = self.exposure.cycles(self.pending)
        self.pending = []
        left = np.subtract.accumulate(np.vstack([self.left, uses]), axis=0)
        if (left[1:] <= uses * 1e-9 + 1e-12).any():  # the bound let a cycle use a budget up
            raise RuntimeError("a failure clock's kept cycles used a budget up")
        self.left = left[-1].tolist()

    def _use_to(self, t: float) -> None:
        """Take from the budgets what the plan used from :attr:`since` to ``t`` (nothing
        while the equipment is being repaired: the clock stands)."""
        if self.pending:
            self._take_pending()
        plan, left, since = self.plan, self.left, self.since
        if t <= since:
            return
        k = 0
        while True:
            start, rates = plan[k]
            end = plan[k + 1][0] if k + 1 < len(plan) else math.inf
            a, b = max(start, since), min(end, t)
            if b > a and not self.failing and any(rates):
                left = [max(x - (b - a) * r, 0.0) for x, r in zip(left, rates)]
            if end > t:
                break
            k += 1
        self.left, self.since, self.plan = left, t, plan[k:]

    def _arm(self) -> None:
        """The failure's instant for the plan; its event moved if the instant moved."""
        due, first = math.inf, -1
        if not self.failing:
            left, t, plan = self.left, self.since, self.plan
            for k, (start, rates) in enumerate(plan):
                end = plan[k + 1][0] if k + 1 < len(plan) else math.inf
                if not any(rates):
                    continue
                a = max(start, t)
                waits = [x / r if r > 0 else math.inf for x, r in zip(left, rates)]
                wait = min(waits)
                if a + wait < end:
                    due, first = a + wait, waits.index(wait)
                    break
                left = [max(x - (end - a) * r, 0.0) for x, r in zip(left, rates)]
        if due == self.due_s or (abs(due - self.due_s) <= EPS_S and first == self._first):
            return  # the plan changed, not the instant (a leg's rounding)
        self.due_s, self._first = due, first
        self._due = None
        if due < math.inf:
            event = self._due = self.env.timeout(max(due - self.env.now, 0.0))
            event.callbacks.append(self._fires)

    def _fires(self, event: simpy.Event) -> None:
        if event is not self._due:  # moved since: a later (or no) failure is planned
            return
        self._due, self.due_s, self.safe_s = None, math.inf, -math.inf
        self._use_to(self.env.now)
        self.failing = True
        self.env.process(self._failed(self._first))

    def _failed(self, component: int):  # noqa: ANN202 (SimPy generator)
        yield from self.fail(component, self.exposure.cause)
        self._use_to(self.env.now)  # (nothing used while failing: the plan brought to now)
        self.left[component] = self.exposure.renew(component)
        self.failing = False
        self._arm()
