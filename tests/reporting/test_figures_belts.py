"""A belt's speed at an instant, as Fig. 22 and the animation read it from the run's
recorded changes: the change in force at that instant, and at LO the input belt's new
speed with no nudge of the instant, since the run records that change at LO itself."""

from __future__ import annotations

import numpy as np
import pytest

from cell.reporting.figures.tip import belt_speed_at
from cell.sim.simulation import simulate

HISTORY = [(0.0, 3.0), (10.0, 1.0), (20.0, 2.0)]


@pytest.mark.parametrize("history", [HISTORY, np.array(HISTORY)], ids=["rows", "array"])
@pytest.mark.parametrize(("when", "speed"), [(-1.0, 3.0), (0.0, 3.0), (9.999999, 3.0),
                                             (10.0, 1.0), (19.0, 1.0), (20.0, 2.0), (1e6, 2.0)])
def test_a_change_holds_from_its_instant_on(history, when: float, speed: float) -> None:
    assert belt_speed_at(history, when) == speed


def test_the_input_belts_change_at_lo_is_read_at_lo(thesis_cell) -> None:
    """The adaptive controller changes the input belt at LO (§5.3 step 3.1): every picked
    part's ``pick_s`` is the instant of a recorded change, so the speed read at LO is that
    change's and the one read a microsecond before is the previous change's."""
    run = simulate(thesis_cell.with_overrides({"controller.policy": "adaptive", "run.parts": 40}))
    history = run.belts["input"]
    instants = [t for t, _ in history]
    picked = run.parts.loc[run.parts["picked"], "pick_s"].to_numpy(dtype=float)
    assert len(picked) >= 38
    changed = 0
    for lo in picked:
        if lo not in instants:  # told to keep its speed: belts.csv has no row (issue 24)
            assert belt_speed_at(history, lo) == belt_speed_at(history, lo - 1e-6)
            continue
        row = instants.index(lo)  # exactly, not to within a tolerance
        assert row > 0
        assert belt_speed_at(history, lo) == history[row][1]
        assert belt_speed_at(history, lo - 1e-6) == history[row - 1][1]
        assert history[row][1] != history[row - 1][1]  # a real change
        changed += 1
    assert changed >= 30  # most picks do change the input belt
