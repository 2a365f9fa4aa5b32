"""The bound on any controller: the most parts that could be delivered from given arrivals
with the same robot and belts (SPEC §11; docs/model.md, "The bound").

Part i comes at a_i, ``length`` inches before B.  Whatever the controller does, the
input belt runs between its floor v_min and its ceiling v_max, so the part reaches
B no earlier than a_i + L / v_max; the feeder drops it at a_i, or later if the belt
has not cleared a part's size since the last drop, and never later than
D_i = max(a_i, D_{i-1} + size / v_min), so it reaches B no later than D_i + L / v_min.
The robot picks a part at B, and two picks are at least its fastest possible cycle
c_min apart.  Each part then has a window [r_i, d_i]; both ends grow with i, so the
greedy pass in order of arrival (pick i at max(r_i, last pick + c_min) if that is no
later than d_i) fits the most picks into the windows (an exchange argument: any
feasible choice can be turned, pick by pick, into the greedy one).  The windows
ignore that the parts share one belt, so no controller can deliver more; it may not
reach the bound.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from cell.plumbing.types import Array
    from cell.sim.policies.base import CellConstants


def fastest_possible_cycle(k: CellConstants) -> float:
    """The shortest B → B cycle the robot can run: what a cycle may take
    (:meth:`~cell.sim.robot.RobotTiming.shortest_parts`, which the plan check reads too) with
    both belts at the fastest speed the robot can follow (and the belt give).  The check holds
    the output belt at its nominal speed from G; the bound does not lean on that, so it holds
    for a controller that ran the output belt as fast as the robot can follow."""
    t = k.timing
    return sum(t.shortest_parts(*t.fastest_followed(k.input_max, k.output_max)))


def greedy_picks(come_s: Sequence[float] | Array, length_in: float, v_min: float, v_max: float,
                 part_size_in: float, cycle_min_s: float) -> int:
    """The most parts, coming at ``come_s`` (in order), that fit their windows at B with
    picks ``cycle_min_s`` apart: the greedy pass of the module's text, a part at a time."""
    early, late, clear = length_in / v_max, length_in / v_min, part_size_in / v_min
    next_drop = next_pick = -float("inf")  # the latest drop plus clear; the last pick plus c_min
    count = 0
    for come in np.asarray(come_s, dtype=float).tolist():
        latest_drop = come if come > next_drop else next_drop
        next_drop = latest_drop + clear
        pick = come + early
        if pick < next_pick:
            pick = next_pick
        if pick <= latest_drop + late:
            count += 1
            next_pick = pick + cycle_min_s
    return count


def parts_bound(k: CellConstants, come_s: Sequence[float] | Array) -> int:
    """The bound for a run of the cell ``k`` whose parts come at ``come_s``."""
    return greedy_picks(come_s, k.input_length, k.input_min, k.input_max, k.part_size,
                        fastest_possible_cycle(k))
