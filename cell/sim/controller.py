"""The controller (thesis §5.3 step 1.0 and 6.0-7.0): a thin SimPy process.

When a part reaches B it reads the cell's state, asks the scenario's
:class:`~cell.sim.policies.Policy` for the part's cycle, hands the belt speeds to
the conveyors and the order to the robot.  A part that reaches B while the
robot is not back rides on and falls off at F (§6.3).  The decisions are the
policy's; nothing here knows which policy runs.
"""

from __future__ import annotations

import math
from typing import Any, Protocol

import simpy

from cell.plumbing.errors import CellError
from cell.sim.conveyors import EPS_S, InputConveyor, OutputConveyor
from cell.sim.mailbox import Mailbox
from cell.sim.policies.base import CellConstants, Policy
from cell.sim.policies.check import PlanCheck, plan_failed
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
        self.queue: Any = None
        """The parts waiting at a buffer's gate (None: no buffer): while one waits, it is the
        next part, at B as soon as the robot is back (docs/layout.md)."""

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
        look-ahead, which reads the feeder's schedule (``sensor.lookahead: ideal``); None
        while the sensor is down (``failures.sensor``)."""
        if not self.sensor_up:
            return None
        now, fed_s, length, n = self.now, self.fed_s, self._length, self.n
        x_now = None
        j = self.part + 1
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
        if self.queue:
            return (lag, 0.0)
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
                 name: str = "", source: Mailbox | None = None):
        self.env, self.k, self.policy, self.view = env, k, policy, view
        self.name = name or getattr(policy, "name", "")
        """The policy's name, as the scenario gives it (for a bad plan's message)."""
        self.conveyor, self.output, self.robot, self.log = conveyor, output, robot, log
        self.source = conveyor.at_bot if source is None else source
        """Where parts at B come from: the input conveyor, or a buffer's gate."""
        self.steers_input = source is None
        """Whether a plan's input belt speeds are set: not with a buffer, whose gate holds a
        part that comes early (the belt then runs at its nominal speed: docs/layout.md)."""
        self.check = PlanCheck(k, self.name)
        """The plan check (:class:`cell.sim.policies.check.PlanCheck`)."""
        self.process = env.process(self.run())

    def rides_on(self, part: Part, now: float, floor_after_td: float) -> None:
        """A part reaches B while the robot is not back: it rides on, let go or lost to
        downtime (RODE_OFF); a wait now foreseen, the output belt's floor from the last planned
        TD (or now; ``floor_after_td`` nan: none planned)."""
        self.log.flag(part, self.robot.loss(now))
        self.log.missed(part)
        if floor_after_td == floor_after_td:
            self.output.belt.plan(max(now, floor_after_td), self.k.output_min)

    def run(self):  # noqa: ANN201 (SimPy generator)
        """Once per part: the part at B taken the instant it gets there (its ``at_bot_s``),
        the policy asked for its plan (checked, :meth:`.PlanCheck.passes`), the
        belts set and the robot told its order."""
        robot, view, k, log = self.robot, self.view, self.k, self.log
        conveyor, plan_for, name = self.conveyor, self.policy.plan, self.name
        output = self.output.belt  # the output belt's plan set directly (nothing else to tell)
        aim = k.lookahead_margin_s  # step 6.3 from when the next part is aimed at B
        u_nom, u_min = k.u_nom, k.output_min  # the output belt's nominal speed and floor
        floor_after_td = math.nan  # the last planned TD (the spacing contract; nan: none)
        passes, passed = self.check.passes, None  # the last plan that passed the check
        get, steers_input = self.source.get, self.steers_input
        while True:
            part: Part = yield get()
            now = part.at_bot_s
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
            if plan is not passed:  # checked before the cell acts on it; the fixed
                passes(plan)  # robot's one plan, once
                passed = plan
            r1a, to_g, r3a, cycle = plan.r1_pre, plan.to_g, plan.r3_pre, plan.cycle
            if plan.steers_belts:
                if steers_input:
                    conveyor.replan(now + r1a, plan.input_after_lo, now + cycle + aim,
                                    plan.input_next)
                at_g = now + to_g
                if plan.output_floor_at < INF:  # the spacing contract: the belt's floor after TD
                    output.plan(now, plan.output_to_g, at_g, u_nom, now + plan.output_floor_at,
                                u_min)
                    floor_after_td = at_g + r3a
                else:
                    output.plan(now, plan.output_to_g, at_g, u_nom)
            part.plan = plan  # the part's regime times and belt speeds (read as its row is made)
            if plan.limits:
                log.flag(part, plan.limits)
            # B → TD summed as LO + (LO → TD), the order the robot's legs are timed in
            robot.order(part, r1a, r1a + (to_g - r1a + r3a), cycle, now)
