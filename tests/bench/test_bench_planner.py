"""The planner's accuracy figure in reports/bench.json: the Richardson limit of a
second-order sequence, and R IV planned alone as the planner plans it beside R II."""

from __future__ import annotations

import pytest

from cell.arm.mintime.regimes import FREE_REGIMES, plan_regimes, regime_path
from cell.bench.planner_speed import RICHARDSON, converged_time, regime_time
from cell.scenario.schema import load_scenario
from cell.sim.physics_checks import step_table
from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds


@pytest.mark.parametrize("error", [0.37, -2.5])
def test_a_second_order_error_extrapolates_to_the_limit(error: float) -> None:
    """T(h) = T∞ + C h², h halving with each doubling of the grid: the limit is exact."""
    limit = 3.141
    times = [limit + error * (1 / n) ** 2 for n in RICHARDSON]
    assert converged_time(times) == pytest.approx(limit, rel=1e-12)
    assert converged_time(times) != pytest.approx(times[-1], rel=1e-12)


@pytest.mark.parametrize("n", [None, 920])
def test_a_regime_planned_alone_takes_the_time_planned_beside_the_other(n: int | None) -> None:
    s = load_scenario("baseline")
    geometry, motors, bounds = geometry_of(s), motors_of(s), planner_bounds(s)
    assert bounds.dynamics is not None       # the torque case, as the benchmark's
    both = plan_regimes(geometry, motors, bounds, n)
    table = step_table(s)
    for r in FREE_REGIMES:
        alone = regime_time(regime_path(table, r, geometry), motors, bounds, geometry, n)
        assert alone == both[r].profile.time_s
