"""The controller (thesis §5.3 step 1.0 and 6.0-7.0): a thin SimPy process.

When a part reaches B it reads the cell's state, asks the scenario's
:class:`~cell.policies.Policy` for the part's cycle, hands the belt speeds to
the conveyors and the order to the robot.  A part that reaches B while the
robot is not back rides on and falls off at F (§6.3).  The decisions are the
policy's; nothing here knows which policy runs.
"""

from __future__ import annotations

from typing import Any, Protocol

import simpy

from cell.conveyors import EPS_S, InputConveyor, OutputConveyor
from cell.policies.base import CellConstants, Policy
from cell.records import LET_GO, PartRecord
from cell.robot import Robot


class RunLog(Protocol):
    """Where a part's limits are noted, and where a part lost at B goes."""

    def flag(self, part: PartRecord, limits: int) -> None: ...

    def missed(self, part: PartRecord) -> None: ...


class View:
    """What a policy may read of the cell when a part is at B (:class:`cell.policies.CellView`).

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

    def input_speed(self) -> float:
        return self._input_speed(self.now + EPS_S)

    def output_gap(self) -> float | None:
        """How far the last part set down has travelled since (None if none yet)."""
        last = self.output.last_td_x
        return None if last is None else self._output_travel(self.now) - last

    def next_part(self, lag: float, v: float) -> tuple[float, float] | None:
        """(a, b) of the first part after this one that can still be caught."""
        now, fed_s, length = self.now, self.fed_s, self._length
        x_now = None
        for j in range(self.part + 1, self.n):
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
        return None


class Controller:
    """Decides each part's cycle when it reaches B (SimPy process)."""

    def __init__(self, env: simpy.Environment, k: CellConstants, policy: Policy, view: View,
                 conveyor: InputConveyor, output: OutputConveyor, robot: Robot, log: RunLog):
        self.env, self.k, self.policy, self.view = env, k, policy, view
        self.conveyor, self.output, self.robot, self.log = conveyor, output, robot, log
        self.process = env.process(self.run())

    def run(self):  # noqa: ANN201 (SimPy generator)
        """Once per part, with locals bound."""
        env, robot, view, plan_for = self.env, self.robot, self.view, self.policy.plan
        replan_in, replan_out, u_nom = self.conveyor.replan, self.output.replan, self.k.u_nom
        get, flag, missed, order = self.conveyor.at_bot.get, self.log.flag, self.log.missed, \
            robot.order
        t = self.k.timing
        l1, l2, l3, l4 = t.r1_length_in, t.r2.length_in, t.r3_length_in, t.r4.length_in
        # the previous cycle's TD → K and R IV (step 5.0, 6.2); nominal before the first
        residual = self.k.r3_post_nom + self.k.r4_nom
        while True:
            part: Any = yield get()
            now = env.now
            if not robot.free_at_s <= now + EPS_S:  # the robot is not back: the part rides on
                part.missed = True
                flag(part, LET_GO)
                missed(part)
                continue
            view.part, view.now = part.part - 1, now
            (r1_pre, r1_post, r2, r3_pre, r3_post, r4, input_speed, input_after_lo, input_next,
             output_to_g, to_g, cycle, limits, steers_belts) = plan_for(view)
            if steers_belts:
                replan_in(now + r1_pre, input_after_lo, now + cycle, input_next)
                replan_out(now, output_to_g, now + to_g, u_nom)
            r1, r3 = r1_pre + r1_post, r3_pre + r3_post
            part.picked = True
            part.motion_cycle_s = cycle
            part.input_speed_in_s, part.output_speed_in_s = input_speed, output_to_g
            part.r1_s, part.r2_s, part.r3_s, part.r4_s = r1, r2, r3, r4
            part.v_r1_in_s, part.v_r2_in_s = l1 / r1, l2 / r2
            part.v_r3_in_s, part.v_r4_in_s = l3 / r3, l4 / r4
            if limits:
                flag(part, limits)
            # step 6.2: motion time to TD plus the previous cycle's residual
            part.thesis_interval_s = to_g + r3_pre + residual
            residual = r3_post + r4
            # B → TD summed as LO + (LO → TD), the order the robot's legs are timed in
            order(part, r1_pre, r1_pre + (to_g - r1_pre + r3_pre), cycle)
