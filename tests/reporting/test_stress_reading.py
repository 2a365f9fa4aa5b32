"""The stress map's sentences about the input belt's floor, against the counts they read."""

from __future__ import annotations

import pandas as pd

from cell.reporting.maps.stress import reading, table
from tests.prose import in_order


def point(cv: float, mean_s: float, lost: float, floor: float, n: int = 4) -> pd.DataFrame:
    """``n`` replications of one point: the adaptive robot loses ``lost`` parts a run, and
    ``floor`` of them follow a cycle that slowed the input belt to its floor."""
    rows = []
    for policy, missed, at_floor in (("non-adaptive", lost + 40, 0.0), ("adaptive", lost, floor)):
        for r in range(n):
            d = 500.0 - missed + (r % 2)
            rows.append({"policy": policy, "replication": r, "arrivals.distribution": "gamma",
                         "arrivals.cv": cv, "arrivals.mean_s": mean_s, "parts_delivered": d,
                         "parts_missed": 500.0 - d, "parts_per_hr_wallclock": d / 3.0,
                         "fastest_cycle_s": 18.0841, "offered_load": 18.0841 / mean_s,
                         "spacing_outside_tol": 0.0, "limit_input_floor": at_floor,
                         "limit_r4_peak": 0.0, "limit_r2_peak": 0.0, "limit_input_ceiling": 0.0,
                         "limit_output_floor": 0.0, "parts_held": 2.0})
    return pd.DataFrame(rows)


def test_the_floor_count_is_read_as_part_of_the_parts_let_go():
    """Entry 8: the floor count is not the number let go; the reading says how many of those
    let go it is, in both the overloaded and the widely spread sentence."""
    reps = pd.concat([point(1.0, 16.2757, 150.0, 100.0), point(0.1, 19.8925, 0.0, 0.0)])
    text = " ".join(reading(table(reps)))
    # the overloaded point lets 150 go a run, 100 of them counted at the floor
    assert in_order(text, "Of the 150 parts a run", "lets go", "100 reach B")
    assert in_order(text, "still lets it go", "(100 of the 150 parts")
