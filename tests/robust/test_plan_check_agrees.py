"""The controller's inline plan check (cell.sim.controller, for speed) and the spelled-out one
(cell.sim.policies.check.problem, which words the message) agree: a run stops on a plug-in's
plan exactly when :func:`problem` finds something wrong with it, whatever the plan holds
(hypothesis: any field set to any number, NaN, an infinity, a huge integer, a boolean, text or
None, or nudged just past its bound; the output belt's floor there or not)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cell.scenario import registry
from cell.scenario.schema import default_scenario
from cell.sim.assembly import assemble
from cell.sim.policies.base import Policy
from cell.sim.policies.check import SPEEDS, TIMES, PolicyError, _bounds, problem
from cell.sim.policies.fixed import fixed_plan
from cell.sim.simulation import simulate

FIELDS = (*TIMES, *SPEEDS, "to_g", "cycle", "limits", "steers_belts", "output_floor_at")
NAME = "agreement-test-policy"


class _Planned(Policy):
    """Plans what the test sets, for every part."""

    name = NAME
    planned: object = None

    def plan(self, view):
        return _Planned.planned


@pytest.fixture(scope="module")
def scenario():
    """Three parts of the thesis's cell under the test's policy, assembled once (``k``: its
    constants)."""
    registry.register(_Planned)
    yield assemble(default_scenario().with_overrides({"run.parts": 3, "controller.policy": NAME}))
    registry.unregister(NAME)


def _near_bound(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Values a hair inside and outside a bound (the check's slack is 1e-9 relative and absolute)."""
    ends = [b for b in (lo, hi) if math.isfinite(b)]
    return st.sampled_from(ends).flatmap(
        lambda b: st.sampled_from([-1e-6, -1e-8, -1e-10, 0.0, 1e-10, 1e-8, 1e-6]).map(
            lambda d: b + d * max(1.0, abs(b))))


ODD = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                st.integers(min_value=-10**400, max_value=10**400), st.booleans(),
                st.none(), st.text(max_size=3))


@st.composite
def plans(draw, k):
    base = fixed_plan(k, k.cycle_nom)
    fields = {f: getattr(base, f) for f in FIELDS}
    bounds = _bounds(k)
    for name in draw(st.lists(st.sampled_from(FIELDS), max_size=3, unique=True)):
        near = _near_bound(*bounds[name]) if name in bounds else st.nothing()
        fields[name] = draw(st.one_of(near, ODD) if name in bounds else ODD)
    if draw(st.booleans()):  # a plug-in's record may leave out the floor (read when it steers)
        del fields["output_floor_at"]
    return SimpleNamespace(**fields)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_a_run_stops_exactly_when_problem_finds_something(scenario, k, data):
    plan = data.draw(plans(k))
    why = problem(plan, k)
    _Planned.planned = plan
    if why is None:
        simulate(scenario, keep_parts=False, keep_belts=False)
    else:
        with pytest.raises(PolicyError, match=f"policy '{NAME}' planned "):
            simulate(scenario, keep_parts=False, keep_belts=False)


@pytest.mark.parametrize("outcome", ["let_go", "spacing_off", "held_at_feeder", "lost_downtime",
                                     "scrapped", "buffer_full"])
def test_a_plan_claiming_what_became_of_its_part_is_refused(scenario, k, outcome):
    """What became of a part is the cell's to record: a plan claiming it (which would count a
    part set down as lost or scrapped) is refused, naming its limits; its own bits pass."""
    from cell.sim.records import LIMIT_BIT

    base = fixed_plan(k, k.cycle_nom)
    fields = {f: getattr(base, f) for f in FIELDS}
    _Planned.planned = SimpleNamespace(**{**fields, "limits": base.limits | LIMIT_BIT["r4_peak"]})
    simulate(scenario, keep_parts=False, keep_belts=False)  # a plan's own bit: passes
    claimed = SimpleNamespace(**{**fields, "limits": base.limits | LIMIT_BIT[outcome]})
    assert (problem(claimed, k) or "").startswith("limits = ")
    _Planned.planned = claimed
    with pytest.raises(PolicyError, match=f"policy '{NAME}' planned limits = "):
        simulate(scenario, keep_parts=False, keep_belts=False)
