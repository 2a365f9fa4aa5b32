"""What a user of minimum-time timing sees: the planner's defaults, the line naming its
bounds, a drive too weak for the arm, and ``cell mintime``'s files."""

from __future__ import annotations

from cell.assembly import geometry_of, motors_of, planner_bounds
from cell.mintime.regimes import fastest_regime_times
from cell.scenario import load_scenario


def _fastest(s):
    return fastest_regime_times(geometry_of(s), motors_of(s), planner_bounds(s))


def test_a_small_file_under_minimum_time_plans_as_the_baseline(tmp_path):
    """A key left out of a what-if file is baseline.yaml's: the dynamic model, no assumed
    acceleration bounds, so the same R II and R IV as the baseline under minimum-time timing."""
    mine = tmp_path / "mt_only.yaml"
    mine.write_text("name: mt-only\nrobot:\n  timing: minimum-time\n")
    s = load_scenario(mine)
    assert s.mintime.dynamics_file == "microbot_dynamics.yaml"
    assert s.mintime.acceleration_bounds is False
    base = load_scenario("baseline", {"robot.timing": "minimum-time"})
    assert _fastest(s) == _fastest(base)
    # a dynamics file of the user's own is then the only bound on the accelerations
    heavy = tmp_path / "heavy_dyn.yaml"
    heavy.write_text("links: {mass_kg: [1.6, 0.6, 0.5, 0.10, 0.20]}\n")
    own = load_scenario(mine, {"mintime.dynamics_file": str(heavy)})
    assert _fastest(own)["R2"] > _fastest(s)["R2"]
