"""One PlanCheck over many plans: R I's floors are those of each plan's own input belt speed,
whatever speed the plan before it had (the check keeps the floors of the last speed it saw:
docs/performance.md#r-i-floors).  The independent fact: R I's floors are
:meth:`~cell.sim.robot.RobotTiming.r1_time` at the plan's speed (:func:`problem`'s reading)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from cell.scenario.schema import default_scenario
from cell.sim.assembly import assemble
from cell.sim.policies.adaptive import adaptive_plan
from cell.sim.policies.check import PlanCheck, PolicyError, problem


@pytest.fixture(scope="module")
def k():
    return assemble(default_scenario()).k


def _shortened(plan, by: float):
    """``plan`` with B → LO ``by`` s shorter, its sums kept consistent."""
    return replace(plan, r1_pre=plan.r1_pre - by, to_g=plan.to_g - by, cycle=plan.cycle - by)


def test_a_plan_is_held_to_the_floors_of_its_own_speed(k) -> None:
    check = PlanCheck(k, "test")
    fast, slow = k.timing.input_track_max_in_s, k.v_nom
    at_fast, at_slow = adaptive_plan(k, fast, None, None), adaptive_plan(k, slow, None, None)
    pre = k.timing.r1_pre.time
    gap = pre(slow) - pre(fast)  # a slower belt: a longer B → LO
    assert gap > 1e-3
    # below its speed's floor, though above the fastest speed's: refused right after a plan
    # at the same speed passed, and right after one at another speed
    too_short = _shortened(at_slow, gap / 2)
    assert problem(too_short, k) is not None
    for before in (at_slow, at_fast):
        check.passes(before)
        with pytest.raises(PolicyError):
            check.passes(too_short)
    # at the fast speed, B → LO at that speed's floor passes, after a plan at the slow one
    for plan in (at_slow, at_fast, at_slow, at_fast):
        assert problem(plan, k) is None
        check.passes(plan)
