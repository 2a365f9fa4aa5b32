"""The agent's action and the map into the feasible set (docs/rl.md, "Actions").

An action is a float64 vector of one plan's fields (:data:`FIELDS`, thesis §5.3's decision:
the six regime times, the input belt after LO and after the cycle, the output belt until G,
when the output belt drops to its floor, R I + R II, the cycle, and the limits the plan says it
hit).  :func:`to_plan` maps any vector (NaN and infinities included) to a plan that
:class:`cell.sim.policies.check.PlanCheck` passes: each value clipped to the check's own bounds
(R I's at the pace of the input belt the part reached B on), ``to_g`` and ``cycle`` kept where
they are within the check's tolerance of their regimes' sums and replaced by those sums
otherwise, the limits kept to the check's :data:`~cell.sim.policies.check.PLAN_LIMITS`.  A
value the check accepts (with limits among those) is left as it is, to the bit: the map is the
identity on the feasible set, so a decision passed through the environment is the decision.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from cell.sim.policies.base import CellConstants, Plan
from cell.sim.policies.check import (
    ABS,
    MAX_S,
    PLAN_LIMITS,
    REL,
    SUM_S,
    plan_bounds,
    tracking_floors,
)
from cell.sim.policies.fixed import fixed_plan

#: The action's components, in order: the fields of :class:`~cell.sim.policies.base.Plan`.
FIELDS = ("r1_pre", "r1_post", "r2", "r3_pre", "r3_post", "r4", "input_after_lo", "input_next",
          "output_to_g", "output_floor_at", "to_g", "cycle", "limits")
TIMES = FIELDS[:6]
SPEEDS = ("input_after_lo", "input_next", "output_to_g")


class ActionMap:
    """The feasible set of one cell's plans (its constants ``k``) and the map into it."""

    def __init__(self, k: CellConstants):
        self.k = k
        b = plan_bounds(k)
        self.time_lo = b[:6]
        """The check's floors of the six regime times (its slack included)."""
        self.v_lo, self.v_hi = b[6], b[7]
        """The input belt's speed at the pick: its floor and the fastest the robot follows."""
        self.speed_lo = (b[8], b[10], b[12])
        self.speed_hi = (b[9], b[11], b[13])
        self.floors = tracking_floors(k)
        self.nominal = fixed_plan(k, k.cycle_nom)
        """The thesis's nominal cycle: what a NaN stands for."""

    def low_high(self) -> tuple[np.ndarray, np.ndarray]:
        """The action space's bounds: the check's, whatever the input belt's speed at the
        pick (R I's floors at its fastest); infinite where the check sets none."""
        inf = math.inf
        lo = [*self.time_lo, *self.speed_lo, 0.0, 0.0, 0.0, 0.0]
        hi = [inf] * 6 + [*self.speed_hi, inf, inf, inf, float(PLAN_LIMITS)]
        return np.array(lo, dtype=np.float64), np.array(hi, dtype=np.float64)

    def to_plan(self, action: Any, v: float) -> Plan:
        """The plan of ``action`` for a part that reached B on the input belt at ``v``."""
        a = [float(x) for x in np.asarray(action, dtype=np.float64).reshape(-1)[:len(FIELDS)]]
        a += [math.nan] * (len(FIELDS) - len(a))
        nom = self.nominal
        v = min(max(v, self.v_lo), self.v_hi)
        f0, f1 = self.floors(v)
        lo = list(self.time_lo)
        lo[0] = max(lo[0], f0 - ABS - REL * f0)  # as the check's R I at the belt's pace
        lo[1] = max(lo[1], f1 - ABS - REL * f1)
        times = []
        for i, name in enumerate(TIMES):
            x = a[i]
            if x != x:
                x = getattr(nom, name)
            times.append(x if lo[i] <= x <= MAX_S else min(max(x, lo[i]), MAX_S))
        r1a, r1b, r2, r3a, r3b, r4 = times
        if r1a + r1b + r2 + r3a + r3b + r4 >= MAX_S:  # no finite cycle: the nominal one
            r1a, r1b, r2, r3a, r3b, r4 = (max(getattr(nom, n), lo[i]) for i, n in enumerate(TIMES))
        speeds = []
        for j, name in enumerate(SPEEDS):
            x = a[6 + j]
            if x != x:
                x = getattr(nom, name)
            speeds.append(x if self.speed_lo[j] <= x <= self.speed_hi[j] else
                          min(max(x, self.speed_lo[j]), self.speed_hi[j]))
        w, w_next, u = speeds
        to_g, cycle = a[10], a[11]
        sum_g = r1a + r1b + r2
        if not -SUM_S <= to_g - sum_g <= SUM_S:  # the check's comparison, as it makes it
            to_g = sum_g
        sum_b = to_g + r3a + r3b + r4
        if not (-SUM_S <= cycle - sum_b <= SUM_S and cycle < MAX_S):
            cycle = sum_b
        floor_at = a[9]
        td = to_g + r3a
        if not floor_at >= td - SUM_S:  # NaN too: at the touch-down
            floor_at = td
        x = a[12]
        limits = int(round(x)) & PLAN_LIMITS if math.isfinite(x) and x >= 0 else 0
        return Plan(r1_pre=r1a, r1_post=r1b, r2=r2, r3_pre=r3a, r3_post=r3b, r4=r4,
                    input_speed=v, input_after_lo=w, input_next=w_next, output_to_g=u,
                    to_g=to_g, cycle=cycle, limits=limits, steers_belts=True,
                    output_floor_at=floor_at)


def action_of(plan: Plan) -> np.ndarray:
    """The action that is ``plan`` (its fields in :data:`FIELDS`' order)."""
    return np.array([float(getattr(plan, name)) for name in FIELDS], dtype=np.float64)
