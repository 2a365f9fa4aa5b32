"""The non-adaptive robot (thesis §6.3, Table 7.1): one fixed cycle for every part.

The regimes run at their nominal times, R IV shortened by (nominal − ideal
cycle) as in Table 7.1; the belts are never touched.  A part that reaches B
while the robot is busy rides on and falls off at F; a late part is waited for.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from cell.plumbing.errors import ScenarioError
from cell.sim import accounting
from cell.sim.policies.base import Accounting, CellConstants, CellView, Plan, Policy
from cell.sim.records import R4_PEAK, RunSummary

#: The thesis's figures are rounded to 4 decimals: a requested R IV this much
#: below the motors' minimum is taken as the minimum (20.0907 s in Table 7.1 is
#: 0.3 ms under the 9.9855 · 0.75-based figure).
ROUNDING_S = 5e-4


def fixed_plan(k: CellConstants, ideal_cycle_s: float, file: object = None) -> Plan:
    """The non-adaptive robot's one cycle (§6.3): nominal regimes, R IV shortened
    by (nominal - ideal) as in Table 7.1.  A cycle the base cannot make is an error."""
    t = k.timing
    r4 = k.r4_nom - (k.cycle_nom - ideal_cycle_s)
    if r4 < t.r4_min_s - ROUNDING_S:
        raise ScenarioError(file, "controller.ideal_cycle_s", ideal_cycle_s,
                            f"R IV would take {r4:.4f} s but the base needs at least "
                            f"{t.r4_min_s:.4f} s at its peak rate: the shortest cycle is "
                            f"{k.shortest_cycle_s:.4f} s")
    r4 = max(r4, t.r4_min_s)
    to_g = k.r1_pre_nom + k.r1_post_nom + k.r2_nom
    return Plan(r1_pre=k.r1_pre_nom, r1_post=k.r1_post_nom, r2=k.r2_nom, r3_pre=k.r3_pre_nom,
                r3_post=k.r3_post_nom, r4=r4, input_speed=k.v_nom, input_after_lo=k.v_nom,
                input_next=k.v_nom, output_to_g=k.u_nom, to_g=to_g,
                cycle=to_g + k.r3_pre_nom + k.r3_post_nom + r4,
                limits=R4_PEAK if r4 <= t.r4_min_s else 0, steers_belts=False)


class FixedCycle(Policy):
    """``non-adaptive``: the same cycle for every part, ``controller.ideal_cycle_s``."""

    name = "non-adaptive"

    def __init__(self, k: CellConstants, controller: Any, file: object = None):
        super().__init__(k, controller, file)
        ideal = controller.ideal_cycle_s
        self._ideal = float(ideal if ideal is not None else k.cycle_nom)
        self.cycle = fixed_plan(k, self._ideal, file)

    @property
    def ideal_cycle_s(self) -> float:
        return self._ideal

    def plan(self, view: CellView) -> Plan:
        return self.cycle

    def accounting(self) -> Accounting:
        return ReconstructedAccounting(self)


class ReconstructedAccounting(Accounting):
    """How the thesis computed Table 7.1 (reconstructed, docs/accounting.md): part i is
    lost when T_i < C − s whatever the robot is doing; its interval is D_i = T_i, or
    T_i + C when lost; IP = T(i+1) / (2 D_i); actual cycle = Σ D / parts delivered.

    The rule of :func:`cell.sim.accounting.thesis_non_adaptive`, applied one part at a time
    as parts complete (so each record carries its columns); tests/sim/test_accounting.py
    checks a run's summary against that function on the run's own draws."""

    policy: FixedCycle

    def __init__(self, policy: FixedCycle):
        super().__init__(policy)
        self.cycle_s = policy.ideal_cycle_s
        """The robot's fixed cycle C."""
        self._lost_below = self.cycle_s - accounting.THESIS_SLACK_S
        """C − s: a part that comes sooner than this after the last is lost."""

    def part(self, plan: Any, picked: bool, interarrival_s: float) -> None:
        t = interarrival_s
        lost = t < self._lost_below
        self.interval.append(t + self.cycle_s if lost else t)
        self.lost.append(lost)

    def last(self, next_interarrival_s: float) -> tuple[bool, float, float]:
        d = self.interval[-1]
        return bool(self.lost[-1]), d, next_interarrival_s / (2.0 * d)

    def finish(self, s: RunSummary, start: int, picked_r4_s: np.ndarray,
               t_next: np.ndarray) -> None:
        d = np.frombuffer(self.interval)[start:]
        ip = t_next[start:] / (2.0 * d)  # each part's IP, as its record has it
        ideal = self.policy.ideal_cycle_s
        missed = self._lost_after(start)
        s.parts_missed_thesis = missed
        s.actual_cycle_thesis_s = float(d.sum() / (len(d) - missed)) if len(d) > missed \
            else math.nan
        s.ip_thesis = float(ip.mean()) if len(ip) else math.nan
        s.cycle_vs_nominal_pct = accounting.pct_off(s.actual_cycle_thesis_s, ideal)
        s.r4_s = self.policy.cycle.r4
        s.thesis_slack_s = accounting.THESIS_SLACK_S
