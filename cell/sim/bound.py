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

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from cell.plumbing.types import Array
    from cell.sim.policies.base import CellConstants


def fastest_possible_cycle(k: CellConstants) -> float:
    """The shortest B → B cycle the robot can run: R II and R IV at the motors' peak, both
    tracking regimes at the fastest belt speed the robot can follow (and the belt give)."""
    t = k.timing
    r1a, r1b = t.r1_time(min(t.input_track_max_in_s, k.input_max))
    r3a, r3b = t.r3_time(min(t.output_track_max_in_s, k.output_max))
    return r1a + r1b + t.r2_min_s + r3a + r3b + t.r4_min_s


def greedy_picks(come_s: Sequence[float] | Array, length_in: float, v_min: float, v_max: float,
                 part_size_in: float, cycle_min_s: float) -> int:
    """The most parts, coming at ``come_s`` (in order), that fit their windows at B with
    picks ``cycle_min_s`` apart (see the module's text).

    The pass in order of arrival: the latest drop D_i = max(a_i, D_{i-1} + size / v_min); part i
    picked at max(a_i + L / v_max, last pick + c_min) if that is no later than D_i + L / v_min.
    Where neither a hold nor a wait comes in (D_i = a_i; part i picked at its earliest, part
    i - 1 too) the pass is read off whole arrays, and only the rest is stepped through, with the
    same float operations: the same count, to the part, as the pass step by step
    (tests/sim/test_bound.py).  For speed: the pass step by step cost 1.1k instructions a part,
    this 0.4k (cachegrind, parts 17.6 s + exp(28 s) apart); ``make bench``'s adaptive run 105.55k
    to 104.77k instructions a part."""
    a = np.asarray(come_s, dtype=float)
    n = a.size
    if n == 0:
        return 0
    early, late, clear = length_in / v_max, length_in / v_min, part_size_in / v_min
    drop = _latest_drops(a, clear)
    first, last = a + early, drop + late  # each part's window at B
    # the parts to step through: the first, and each that may not be picked at its earliest
    # even if the one before it was (the pass needs no step elsewhere)
    stepped = np.flatnonzero(~((first[1:] >= first[:-1] + cycle_min_s) & (first[1:] <= last[1:])))
    count, i = 0, 0  # parts counted before i; part i - 1 picked at its earliest
    for j in [0, *(stepped + 1).tolist(), n]:
        if j < i:
            continue
        count += j - i  # parts i .. j - 1: each at its earliest
        if j == n:
            break
        next_pick = float(first[j - 1]) + cycle_min_s if j > 0 else -math.inf
        while j < n:  # step by step until a part is picked at its earliest again
            pick = float(first[j])
            early_pick = pick >= next_pick
            if not early_pick:
                pick = next_pick
            j += 1
            if pick <= last[j - 1]:
                count += 1
                next_pick = pick + cycle_min_s
                if early_pick:
                    break
        i = j
    return count


def _latest_drops(a: Array, clear: float) -> Array:
    """D_i = max(a_i, D_{i-1} + clear), D_0 = a_0: stepped through only where a hold comes in."""
    drop = a.copy()
    held = np.flatnonzero(a[1:] < a[:-1] + clear) + 1
    j = 0
    for i in held.tolist():
        if i < j:
            continue
        while i < a.size:
            d = drop[i - 1] + clear
            if a[i] > d:
                break
            drop[i] = d
            i += 1
        j = i
    return drop


def parts_bound(k: CellConstants, come_s: Sequence[float] | Array) -> int:
    """The bound for a run of the cell ``k`` whose parts come at ``come_s``."""
    return greedy_picks(come_s, k.input_length, k.input_min, k.input_max, k.part_size,
                        fastest_possible_cycle(k))
