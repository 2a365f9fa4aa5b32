"""The controller (thesis §5.3 step 1.0 and 6.0-7.0): a thin SimPy process.

When a part reaches B it reads the cell's state, asks the scenario's
:class:`~cell.sim.policies.Policy` for the part's cycle, hands the belt speeds to
the conveyors and the order to the robot.  A part that reaches B while the
robot is not back rides on and falls off at F (§6.3).  The decisions are the
policy's; nothing here knows which policy runs.
"""

from __future__ import annotations

import math
from typing import Protocol

import simpy

from cell.plumbing.errors import CellError
from cell.sim.conveyors import EPS_S, InputConveyor, OutputConveyor
from cell.sim.policies.base import CellConstants, Policy
from cell.sim.policies.check import (
    ABS,
    ALL_LIMITS,
    MAX_S,
    REL,
    SUM_S,
    plan_bounds,
    plan_failed,
    refuse,
    tracking_floors,
)
from cell.sim.records import Part
from cell.sim.robot import Robot
from cell.sim.sensor import Sensor

INF = math.inf


class RunLog(Protocol):
    """Where a part's limits are noted, and where a part lost at B goes."""

    def flag(self, part: Part, limits: int) -> None: ...

    def missed(self, part: Part) -> None: ...


class View:
    """What a policy may read of the cell when a part is at B (:class:`cell.sim.policies.CellView`).

    The controller sets ``part`` and ``now`` before it asks the policy.
    """

    def __init__(self, k: CellConstants, fed_s: list[float], n_parts: int,
                 conveyor: InputConveyor, output: OutputConveyor):
        self.k, self.fed_s, self.n, self.output = k, fed_s, n_parts, output
        self._input_speed, self._output_travel = conveyor.belt.speed, output.belt.travel
        self._input_travel, self._x_fed = conveyor.belt.travel, conveyor.x_fed
        self._length = k.input_length
        self.part = 0
        """Index of the part at B."""
        self.now = 0.0
        """The instant it reached B (the simulation's clock)."""
        self.sensor_up = True
        """False while the look-ahead sensor is down (a failure): it then reports nothing,
        the ideal look-ahead included, and ``next_part`` is None."""

    def input_speed(self) -> float:
        return self._input_speed(self.now + EPS_S)

    def output_gap(self) -> float | None:
        """How far the last part set down has travelled since (None if none yet)."""
        last = self.output.last_td_x
        return None if last is None else self._output_travel(self.now) - last

    def since_touchdown(self) -> float | None:
        """Seconds since the last part was set down (None if none yet)."""
        return None if self.output.last_td_x is None else self.now - self.output.last_td_s

    def next_part(self, lag: float, v: float) -> tuple[float, float] | None:
        """(a, b) of the first part after this one that can still be caught: the ideal
        look-ahead, which reads the feeder's schedule (``sensor.lookahead: ideal``)."""
        now, fed_s, length, n = self.now, self.fed_s, self._length, self.n
        x_now = None
        j = self.part + 1  # for speed, a while, not a ``range`` (making one is dear, and one part
        # is looked at, mostly): the adaptive run 106.57k to 104.77k instructions a part, cachegrind
        while j < n:
            f = fed_s[j]
            if f > now + lag:
                return (f - now, length)
            if x_now is None:
                x_now = self._input_travel(now)
            x_fed = self._x_fed.get(j)
            if x_fed is None:  # dropped between now and LO (or held back): not on the belt yet
                x_fed = x_now + v * (max(f, now) - now)
            d = x_fed + length - (x_now + v * lag)
            if d > 0:
                return (lag, d)
            j += 1
        return None


class FallibleView(View):
    """The ideal look-ahead of a run whose sensor can fail (``failures.sensor``): nothing
    while it is down.  Chosen when the run is assembled, so that a run without failures
    does not ask (``make bench``: one test a part, a fraction of a percent)."""

    def next_part(self, lag: float, v: float) -> tuple[float, float] | None:
        return View.next_part(self, lag, v) if self.sensor_up else None


class SensorView(View):
    """The view with a physical look-ahead (``sensor.lookahead: sensor``): the next part is
    the first the sensor has reported that can still be caught, where the report puts it;
    the feeder's schedule is not given to it, so no arrival the sensor has not seen is read."""

    def __init__(self, k: CellConstants, sensor: Sensor, n_parts: int,
                 conveyor: InputConveyor, output: OutputConveyor):
        super().__init__(k, [], n_parts, conveyor, output)
        self.sensor = sensor

    def next_part(self, lag: float, v: float) -> tuple[float, float] | None:
        """(lag, b) of the first reported part after this one still short of B at LO (its
        reported distance less the belt's travel since the report); None if none."""
        sensor, now = self.sensor, self.now
        sensor.update(now, self.part)
        if not self.sensor_up:
            return None
        ahead = self._input_travel(now) + v * lag  # the belt's travel at LO
        for _, distance, x_told in sensor.reports:
            d = distance - (ahead - x_told)
            if d > 0:
                return (lag, d)
        return None


class Controller:
    """Decides each part's cycle when it reaches B (SimPy process)."""

    def __init__(self, env: simpy.Environment, k: CellConstants, policy: Policy, view: View,
                 conveyor: InputConveyor, output: OutputConveyor, robot: Robot, log: RunLog,
                 name: str = ""):
        self.env, self.k, self.policy, self.view = env, k, policy, view
        self.name = name or getattr(policy, "name", "")
        """The policy's name, as the scenario gives it (for a bad plan's message)."""
        self.conveyor, self.output, self.robot, self.log = conveyor, output, robot, log
        self.process = env.process(self.run())

    def rides_on(self, part: Part, now: float, floor_after_td: float) -> None:
        """A part reaches B while the robot is not back: it rides on, let go or lost to
        downtime (RODE_OFF); a wait now foreseen, the output belt's floor from the last planned
        TD (or now; ``floor_after_td`` nan: none planned)."""
        self.log.flag(part, self.robot.loss(now))
        self.log.missed(part)
        if floor_after_td == floor_after_td:
            self.output.replan(max(now, floor_after_td), self.k.output_min)

    def run(self):  # noqa: ANN201 (SimPy generator)
        """Once per part, locals bound, the clock read from the part's arrival at B, the plan checked
        inline (for speed: :meth:`.Feeder.run`, :mod:`cell.sim.policies.check`), each field read once
        and the robot's order given its instant: with :func:`.adaptive_plan`'s inline steps, the
        adaptive run 122.5k to 118.4k instructions per part, cachegrind (20,000 parts)."""
        robot, view, plan_for = self.robot, self.view, self.policy.plan
        replan_in, replan_out, u_nom = self.conveyor.replan, self.output.replan, self.k.u_nom
        replan_out_floor, u_min, aim = self.output.replan_then, self.k.output_min, self.k.lookahead_margin_s
        floor_after_td = math.nan  # the last planned TD (the spacing contract; nan: none)
        a1, a2, a3, a4, a5, a6, c1, d1, c2, d2, c3, d3, c4, d4 = plan_bounds(self.k)
        bad_bits, top, eps, name, passed = ~ALL_LIMITS, MAX_S, SUM_S, self.name, None
        get, flag, order, r1 = self.conveyor.at_bot.get, self.log.flag, robot.order, tracking_floors(self.k)
        while True:
            part: Part = yield get()
            now = part.at_bot_s  # env.now: the part is taken the instant it reaches B
            if not robot.free_at_s <= now + EPS_S:  # the robot is not back: the part rides on
                self.rides_on(part, now, floor_after_td)
                continue
            view.part, view.now = part.index, now
            try:
                plan = plan_for(view)
            except CellError:
                raise
            except Exception as exc:  # noqa: BLE001 - a plug-in's failure, named
                raise plan_failed(name, exc) from exc
            if plan is not passed:  # checked at the boundary (cell.sim.policies.check)
                try:  # an ``if``'s tests (CPython specialises their float comparisons, not a value's)
                    r1a, r1b, r2, r3a, r3b, r4 = \
                        plan.r1_pre, plan.r1_post, plan.r2, plan.r3_pre, plan.r3_post, plan.r4
                    w, w_next, u, to_g, cycle, limits, steers, v = \
                        plan.input_after_lo, plan.input_next, plan.output_to_g, plan.to_g, \
                        plan.cycle, plan.limits, plan.steers_belts, plan.input_speed
                    off_g, off_b = to_g - (r1a + r1b + r2), cycle - (to_g + r3a + r3b + r4)
                    floor_at = plan.output_floor_at if steers else INF  # at or after TD
                    if (a1 <= r1a and a2 <= r1b and a3 <= r2 and a4 <= r3a and a5 <= r3b and a6 <= r4
                            and c1 <= v and v <= d1 and c2 <= w and w <= d2 and c3 <= w_next
                            and w_next <= d3 and c4 <= u and u <= d4 and -eps <= off_g and off_g <= eps
                            and -eps <= off_b and off_b <= eps and cycle < top and limits.__class__ is int
                            and not limits & bad_bits and steers.__class__ is bool
                            and floor_at >= to_g + r3a - eps  # and R I at the belt's pace (v checked):
                            and (f := r1(v))[0] - ABS - REL * f[0] <= r1a and f[1] - ABS - REL * f[1] <= r1b):
                        passed = plan
                except Exception:  # noqa: BLE001 - a field missing or not a number: said below
                    pass
                if plan is not passed:
                    refuse(plan, name, self.k)
                    passed = plan
            if steers:
                replan_in(now + r1a, w, now + cycle + aim, w_next)  # 6.3 as the next part is aimed at B
                if floor_at < INF:  # the spacing contract: the belt's floor after TD
                    at_g = now + to_g
                    replan_out_floor(now, u, at_g, u_nom, now + floor_at, u_min)
                    floor_after_td = at_g + r3a
                else:
                    replan_out(now, u, now + to_g, u_nom)
            part.plan = plan  # the part's regime times and belt speeds (read as its row is made)
            if limits:
                flag(part, limits)
            # B → TD summed as LO + (LO → TD), the order the robot's legs are timed in
            order(part, r1a, r1a + (to_g - r1a + r3a), cycle, now)
