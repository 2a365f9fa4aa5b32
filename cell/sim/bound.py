"""The bound on any controller: the most parts that could be delivered from given arrivals
with the same robot and belts (SPEC §11; docs/model.md, "The bound").

Part i comes at a_i, ``length`` inches before B.  Whatever the controller does, the input
belt runs between its floor v_min and its ceiling v_max (the plan check holds every speed a
policy asks to them), so the part reaches B no earlier than r_i = a_i + L / v_max; the feeder
drops it at a_i, or later if the belt has not cleared a part's size since the last drop, and
never later than D_i = max(a_i, D_{i-1} + size / v_min), so it reaches B no later than
d_i = D_i + L / v_min.  The robot picks a part as it reaches B, and two picks are at least its
fastest possible cycle c apart (less :data:`~cell.sim.conveyors.EPS_S`: a part that comes
that close to the robot's return is taken).

**One belt.**  The parts ride one belt and keep their distances on it.  Part k is dropped a
part's size behind part k - 1 if the feeder held it, else at a_k, when the belt has carried
part k - 1 at most v_max (a_k - a_{k-1}) since its drop (no earlier than a_{k-1}); so the
belt's distance between them is at most g_k = max(size, v_max (a_k - a_{k-1})) (plus
:data:`SLACK_IN` for the feeder's roundings).  Two parts i < j both picked reach B the time
the belt takes to carry that distance apart, at the floor at most: with s_i the sum of
g_k / v_min up to i, t_j - t_i <= s_j - s_i.  Two picks in a row are at least c apart in time,
so s_j - s_i >= c too: a burst of m parts the feeder drops a part's size apart yields at most
1 + (m - 1) size / v_min / c of them.

**The pass.**  Both ends of the windows and s grow with i, so the greedy pass in order of
arrival (pick i at max(r_i, last pick + c) if that is no later than d_i and s_i is at least
the last pick's s plus c) fits the most picks: if any run picks o_1 < o_2 < ..., the pass's
k-th pick g_k is at or before o_k, in index and in time (by induction: o_{k+1} is a candidate
after g_k, as its s is at least s(o_k) + c >= s(g_k) + c and its earliest time no later than
o_{k+1}'s; the pass takes the first candidate, whose earliest time is no later).  So no
controller whose plans pass the check delivers more; it may not reach the bound (the belt's
speed during a pick and the output belt are left out).  The coupling is only as good as the
belt's floor: where the belt stood (a failure, a shift calendar) the pass leaves it out
(``one_belt=False``: the windows alone).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from cell.sim.conveyors import EPS_S  # a part this close before the robot is back is taken

if TYPE_CHECKING:
    from cell.plumbing.types import Array
    from cell.sim.conveyors import Belt
    from cell.sim.policies.base import CellConstants

#: Room on the belt's distance between two drops (in) for the feeder's roundings (it drops a
#: held part up to EPS_S of belt travel past a part's size clear) and the MILP's slack
#: (:data:`cell.experiments.hindsight.milp.HOLD_IN`).
SLACK_IN = 1e-3


def fastest_possible_cycle(k: CellConstants) -> float:
    """The shortest B → B cycle the robot can run: what a cycle may take
    (:meth:`~cell.sim.robot.RobotTiming.shortest_parts`, which the plan check reads too) with
    both belts at the fastest speed the robot can follow (and the belt give).  The check holds
    the output belt at its nominal speed from G; the bound does not lean on that, so it holds
    for a controller that ran the output belt as fast as the robot can follow."""
    t = k.timing
    return sum(t.shortest_parts(*t.fastest_followed(k.input_max, k.output_max)))


def greedy_picks(come_s: Sequence[float] | Array, length_in: float, v_min: float, v_max: float,
                 part_size_in: float, cycle_min_s: float, one_belt: bool = True) -> int:
    """The most parts, coming at ``come_s`` (in order), that fit their windows at B with
    picks ``cycle_min_s`` apart and, with ``one_belt``, their belt's distance between them
    at least a cycle at the floor: :func:`greedy_pass`, or all of them where
    :func:`all_picked` finds from the whole array at once that the pass picks every one."""
    come = np.asarray(come_s, dtype=float)
    args = (length_in, v_min, v_max, part_size_in, cycle_min_s, one_belt)
    if all_picked(come, *args):
        return int(come.size)  # speed: docs/performance.md#bound-at-once
    return greedy_pass(come, *args)


class PassConstants(NamedTuple):
    """What the greedy pass works with, from the cell's figures (:func:`pass_constants`)."""

    early: float
    """B reached at the belt's ceiling after the drop (s)."""
    late: float
    """B reached at the belt's floor after the drop (s)."""
    clear: float
    """The floor's time to carry a part's size (s): the feeder's next drop at the earliest."""
    cycle: float
    """Two picks at least this far apart (the fastest cycle less EPS_S)."""
    per_s: float
    """v_max / v_min: a second between arrivals, in seconds of the floor."""
    slack_s: float
    """SLACK_IN at the floor (s)."""
    gap_min: float
    """The belt's shortest distance to the last part, at the floor: its size and SLACK_IN (s)."""


def pass_constants(length_in: float, v_min: float, v_max: float, part_size_in: float,
                   cycle_min_s: float) -> PassConstants:
    """The pass's constants for a belt of ``length_in`` between ``v_min`` and ``v_max``,
    parts ``part_size_in`` long and the fastest cycle ``cycle_min_s``."""
    return PassConstants(length_in / v_max, length_in / v_min, part_size_in / v_min,
                         cycle_min_s - EPS_S, v_max / v_min, SLACK_IN / v_min,
                         (part_size_in + SLACK_IN) / v_min)


def greedy_pass(come_s: Sequence[float] | Array, length_in: float, v_min: float, v_max: float,
                part_size_in: float, cycle_min_s: float, one_belt: bool = True) -> int:
    """:func:`greedy_picks` worked out by the greedy pass of the module's text, a part at a
    time."""
    early, late, clear, cycle, per_s, slack_s, gap_min = pass_constants(
        length_in, v_min, v_max, part_size_in, cycle_min_s)
    next_drop = next_pick = -float("inf")  # the latest drop plus clear; the last pick plus c
    at, next_at = 0.0, -float("inf")  # the part's s; the last pick's s plus c (one belt)
    last = None
    count = 0
    for come in np.asarray(come_s, dtype=float).tolist():
        if last is not None:
            gap = per_s * (come - last) + slack_s
            at += gap if gap > gap_min else gap_min
        last = come
        latest_drop = come if come > next_drop else next_drop
        next_drop = latest_drop + clear
        pick = come + early
        if pick < next_pick:
            pick = next_pick
        if pick <= latest_drop + late and at >= next_at:
            count += 1
            next_pick = pick + cycle
            if one_belt:
                next_at = at + cycle
    return count


def all_picked(come: Array, length_in: float, v_min: float, v_max: float, part_size_in: float,
               cycle_min_s: float, one_belt: bool = True) -> bool:
    """Whether :func:`greedy_pass` picks every part coming at ``come``, each at its earliest,
    found without the pass (in its constants, :func:`pass_constants`): the earliest picks
    r_i = a_i + early are each a cycle after the one before (the same floats as the pass's r_i
    and last pick plus c); a part's window ends no earlier than it starts (early <= late, so
    r_i <= D_i + late, as D_i >= a_i); and with ``one_belt`` each part's belt gap at the
    floor, the pass's g_i = max(per_s (a_i - a_(i-1)) + slack_s, gap_min), is a cycle at
    least, so s_i >= s_(i-1) + c.  Arrivals not all finite are left to the pass."""
    c = pass_constants(length_in, v_min, v_max, part_size_in, cycle_min_s)
    if not come.size or not c.early <= c.late:
        return False
    first = come + c.early
    if not np.isfinite(first).all() or not (first[1:] >= first[:-1] + c.cycle).all():
        return False
    if not one_belt:
        return True
    gap = np.maximum(c.per_s * np.diff(come) + c.slack_s, c.gap_min)
    return bool((gap >= c.cycle).all())


def parts_bound(k: CellConstants, come_s: Sequence[float] | Array, belt: Belt | None = None,
                one_belt: bool = True) -> int:
    """The bound for a run of the cell ``k`` whose parts come at ``come_s``.  ``belt``: the
    run's input belt once closed; if it stood (its slowest speed 0), or ``one_belt`` is
    False, the windows alone."""
    if belt is not None and not belt.min_speed_in_s > 0.0:
        one_belt = False
    return greedy_picks(come_s, k.input_length, k.input_min, k.input_max, k.part_size,
                        fastest_possible_cycle(k), one_belt)
