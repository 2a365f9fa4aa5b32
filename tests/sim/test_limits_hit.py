"""What the limits-hit counts of ``cell run`` and summary.csv mean, on whole runs."""

from __future__ import annotations

from cell.scenario import catalog
from cell.scenario.schema import load_scenario
from cell.sim.records import LIMIT_COUNTS
from cell.sim.simulation import simulate

OVERLOADED = {"run.parts": 200, "controller.nominal_cycle_s": None,
              "arrivals.distribution": "gamma", "arrivals.cv": 0.05,
              "arrivals.mean_s": 16.2757}  # 0.9 of the robot's fastest cycle


def test_input_floor_counts_picked_parts_whose_next_part_is_let_go():
    """The flag is on the part picked; the floor's effect is on the next part, which the
    label names (entry 8: it read as if the counted part itself was let go)."""
    r = simulate(load_scenario(catalog.path("baseline"), OVERLOADED))
    p = r.parts
    floor = p["limits"].fillna("").str.contains("input_floor").to_numpy()
    missed = p["missed"].to_numpy()
    assert floor.sum() > 20 and r.summary["limit_input_floor"] == floor.sum()
    assert p["picked"].to_numpy()[floor].all()            # the counted parts were picked
    assert missed[1:][floor[:-1]].all()                   # and each one's next part let go
    label = LIMIT_COUNTS["input_floor"].label   # counts picks, not the parts lost (issue 24)
    assert label.startswith("picks") and "the part after each let go" in label


def test_no_floor_is_counted_when_r2_takes_up_the_whole_wait():
    """A belt slowed exactly to its floor, R II having taken up the rest, lets no part go:
    it is not counted (a rounding of w = b / (cycle - a) used to flag it; a nominal cycle
    in ms, 22587 s, flagged some 45 % of the parts with none lost)."""
    r = simulate(load_scenario(catalog.path("baseline"), {"run.parts": 60,
                                                          "controller.nominal_cycle_s": 22587}))
    p = r.parts
    floor = p["limits"].fillna("").str.contains("input_floor").to_numpy()
    missed = p["missed"].to_numpy()
    assert not missed.any()
    assert floor.sum() == r.summary["limit_input_floor"] == 0
