"""The adaptive controller (thesis §5.3; steps 1.0-2.1 reconstructed, docs/model.md).

One part ahead:

1.0  the next part's distance and the belt speeds are read;
2.x  R I tracks the input belt at its current speed v; the difference from the
     nominal R I time is given to (2.1) or taken from (2.2) R II, so the cycle
     stays at the ideal 22.5872 s unless R II is already at its fastest;
3.1  next part late: after the tracking lag (B → LO) the input belt speeds up so
     that the part reaches B as the robot gets back (with a look-ahead margin, a part
     may reach B early, before the belt's change at the margin's end: then no faster
     than the robot can follow, and the part comes later, the robot waiting for it);
3.2  next part early: the time is made up in R IV down to the base's maximum rate,
     then the input belt slows for the rest;
5.0  the output belt runs, until the robot reaches G, at the average of the
     speeds that would give 44.75 and 45.25 in spacing, then nominal;
6.2  the thesis's "time between deliveries": motion time to TD plus the previous
     cycle's residual (TD → K and R IV), idle waits not counted;
6.3  after the cycle, an input speed above nominal becomes (current + nominal)/2.

Where the thesis's rules alone would let the cell run away on other arrivals, the
plan adds floors and one restoring rule (:func:`adaptive_plan`); the limits a
cycle hits are flagged for its part's record.  These departures (docs/model.md) do not
bind on the thesis's arrivals: step 3.2 slows the input belt no further than its floor,
taking time off R II (down to its fastest) before that, and a part still too early is let
go (it reaches B while the robot is busy); step 6.3 also raises a belt left slower than
R II can absorb (``k.input_absorb``), so a slowed belt never lengthens the next cycle;
step 5.0 keeps the output belt within its floor and ceiling, and the spacing contract
steers it after TD as well.

The spacing contract (docs/model.md): the output belt drops to its floor after this part's
touch-down, at ``output_floor_at`` s from the start of the cycle.  The next part is expected
at B at ``t_e`` (the look-ahead's part at the planned input speeds: ``w`` until the cycle
ends, ``v_next`` after; the robot back at ``cycle``).  If the belt at nominal until a margin
after ``t_e`` still leaves room for 45 in, the floor is planned for then: a decision on time
replans first, and nothing changes.  A wait foreseen too long for that, or no part in sight,
slows the belt at TD, so that the gap grows as slowly as the belt allows until the next part
is planned.

Targets are physical: the controller knows the belts' schedules, so it aims
the next part at B for the instant the robot gets back, and the spacing at 45 in,
exactly; only motor and belt limits can make it miss, and then it says so.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from cell.plumbing.errors import ScenarioError
from cell.sim import accounting
from cell.sim.policies.base import CellConstants, CellView, MotionTimeAccounting, Plan, Policy
from cell.sim.records import (
    INPUT_CEILING,
    INPUT_FLOOR,
    INPUT_TRACKING,
    OUTPUT_CEILING,
    OUTPUT_FLOOR,
    R2_PEAK,
    R4_PEAK,
    SPACING_UNFORESEEN,
    SPACING_WAIT,
    RunSummary,
)

_new = object.__new__
#: The spacing contract plans the output belt's floor this long after the instant the next
#: part is expected at B (a decision on time replans first, so nothing changes then).
FLOOR_MARGIN_S = 1.0


def adaptive_plan(k: CellConstants, v: float, nxt: tuple[float, float] | None,
                  gap_in: float | None, lag: float | None = None,
                  idle_s: float | None = None) -> Plan:
    """Thesis §5.3 steps 2.0-6.3 for one part (pure), within the belts' and motors' limits (the
    departures: the module's text).  ``v``: the input belt's speed now; ``nxt = (a, b)``: the
    next part reaches B a + b/w s from now if the belt runs at w from LO on (a: the lag B → LO,
    b: its pseudo-distance then; a part not yet on the belt: a until the feeder drops it, b the
    belt's length), None: none is coming; ``gap_in``: the output belt's travel since the last
    touch-down (None: none yet); ``lag``: B → LO at v, if known; ``idle_s``: seconds since that
    touch-down (None: both spacing causes marked, :class:`Adaptive` names the one).  Steps 3.1,
    5.0 and the spacing contract are inline, their rare cases called (3.2: :func:`aim_early`,
    5.0's limits: :func:`output_speed`)."""
    t, flags = k.timing, 0
    r1a = t.r1_pre.time(v) if lag is None else lag
    r1b = t.r1_post.time(v)
    # 2.1-2.3: R I's difference from nominal goes to R II.
    r2 = k.r2_nom + (k.r1_nom - r1a - r1b)
    if r2 < t.r2_min_s:
        r2, flags = t.r2_min_s, R2_PEAK
    r3a, r3b, r4 = k.r3_pre_nom, k.r3_post_nom, k.r4_nom
    cycle, w = r1a + r1b + r2 + r3a + r3b + r4, v
    if nxt is not None:  # 3.0: the next part at B late at v: 3.1, after the lag, speed up
        a, b = nxt
        m = k.lookahead_margin_s  # the next part aimed at B this long after the robot is back
        if a + b / v > cycle + m:
            w = b / (cycle + m - a) if cycle + m > a else math.inf
            if w > k.input_max or (m > 0.0 and w > t.input_track_max_in_s):
                w, flags = late_speed_cap(k, m, flags)
        else:  # early (3.2) or on time
            w, r2, r4, cycle, flags = aim_early(k, nxt, v, r2, r4, cycle, flags)
    # 6.3: decay toward nominal after the cycle; departure: never below what R II absorbs.
    v_next = 0.5 * (w + k.v_nom) if w > k.v_nom else \
        (k.input_absorb if k.input_absorb > w else w)  # max(w, absorb)
    if v_next > t.input_track_max_in_s:
        v_next = t.input_track_max_in_s
        flags |= INPUT_TRACKING
    ttsot = r1a + r1b + r2
    u = u_nom = k.u_nom  # step 5.0 (:func:`output_speed`, inline)
    if gap_in is not None:
        rest = gap_in + u_nom * r3a
        u = 0.5 * ((k.spacing - k.tol - rest) / ttsot + (k.spacing + k.tol - rest) / ttsot)
        if not k.output_min <= u <= k.output_max:  # at the floor or the ceiling
            u, out_flags = output_speed(k, gap_in, ttsot, r3a, idle_s)
            flags |= out_flags
    floor = td = ttsot + r3a
    if nxt is not None:  # the spacing contract (the module's text)
        switch = cycle + m
        run = switch - a
        eta = a + b / w if b <= w * run else (switch if switch > a else a) + \
            (b - (w * run if run > 0 else 0.0)) / v_next
        t_e = (eta if eta > cycle else cycle) + FLOOR_MARGIN_S
        if u_nom * (t_e - td) <= k.floor_gap_in:
            floor = t_e
    plan = _new(Plan)  # field by field, by name (a third of the keyword call's cost)
    plan.r1_pre, plan.r1_post, plan.r2, plan.r3_pre, plan.r3_post, plan.r4 = \
        r1a, r1b, r2, r3a, r3b, r4
    plan.input_speed, plan.input_after_lo, plan.input_next, plan.output_to_g = v, w, v_next, u
    plan.to_g, plan.cycle, plan.limits, plan.steers_belts, plan.output_floor_at = \
        ttsot, cycle, flags, True, floor
    return plan


def late_speed_cap(k: CellConstants, m: float, flags: int) -> tuple[float, int]:
    """Step 3.1's fastest input belt after LO, and ``flags`` with the limit it hits: the belt's
    ceiling; with a look-ahead margin ``m`` > 0 also the fastest the robot can follow, since the
    part aimed at B ``m`` after the robot is back may reach B early, while the belt still runs at
    this speed (the module's text): the part then comes later, and the robot waits for it."""
    track = k.timing.input_track_max_in_s
    if m > 0.0 and track < k.input_max:
        return track, flags | INPUT_TRACKING
    return k.input_max, flags | INPUT_CEILING


def aim_early(k: CellConstants, nxt: tuple[float, float], v: float, r2: float, r4: float,
              cycle: float, flags: int) -> tuple[float, float, float, float, int]:
    """Thesis §5.3 step 3.2: the next part ``nxt = (a, b)`` (as in :func:`adaptive_plan`), not
    late at the belt's speed v (3.0; 3.1, late, is :func:`adaptive_plan`'s), aimed at B a
    look-ahead margin after the robot is back.

    Early: the time is made up in R IV down to its fastest, then the input belt slows;
    departure (docs/model.md): no further than its floor, R II (down to its fastest) taking
    time off first, and a part still too early is let go.  On time: nothing changes.  Returns
    the input speed after LO ``w``, R II, R IV, the cycle and ``flags`` with the limits hit added.
    """
    t = k.timing
    w = v
    m = k.lookahead_margin_s  # the next part aimed at B this long after the robot is back
    a, b = nxt
    eta = a + b / v                       # 3.0: next arrival at the current speed
    if eta < cycle + m:                       # 3.2: early; R IV first, then the belt
        need = cycle + m - eta
        if r4 - need >= t.r4_min_s:
            r4 -= need
            cycle -= need
        else:
            cycle -= r4 - t.r4_min_s
            r4 = t.r4_min_s
            flags |= R4_PEAK
            w = b / (cycle + m - a)
            if w < k.input_min:           # departure: the belt's floor, R II first
                over = cycle + m - (a + b / k.input_min)  # the cycle past the floor's arrival
                spare = min(r2 - t.r2_min_s, over)
                if spare > 0:
                    r2 -= spare
                    cycle -= spare
                    w = b / (cycle + m - a)
                if w < k.input_min:  # also by a rounding once R II took it all up
                    w = k.input_min
                    if spare < over:  # R II could not: the next part comes early
                        flags |= INPUT_FLOOR
    return w, r2, r4, cycle, flags


def output_speed(k: CellConstants, gap_in: float, ttsot: float, r3a: float,
                 idle_s: float | None) -> tuple[float, int]:
    """Step 5.0: the output belt until G, the average of the speeds that set the part down
    44.75 and 45.25 in behind the last, within the belt's floor and ceiling; the limits hit
    (and, spacing off at the floor, its cause)."""
    rest = gap_in + k.u_nom * r3a
    lo = (k.spacing - k.tol - rest) / ttsot
    hi = (k.spacing + k.tol - rest) / ttsot
    u = 0.5 * (lo + hi)
    if u < k.output_min:
        u = k.output_min
        flags = OUTPUT_FLOOR
        if rest + u * ttsot > k.spacing + k.tol:  # off: name the cause
            flags |= spacing_cause(k, idle_s, ttsot, r3a) if idle_s is not None else \
                SPACING_CAUSE
        return u, flags
    if u > k.output_max:
        return k.output_max, OUTPUT_CEILING
    return u, 0


#: Both spacing causes: the mark of a part set down off spacing whose cause is still to name.
SPACING_CAUSE = SPACING_WAIT | SPACING_UNFORESEEN


def spacing_cause(k: CellConstants, idle_s: float | None, ttsot: float, r3a: float) -> int:
    """Why a part is set down off spacing with the output belt at its floor: the wait since
    the last touch-down was too long even for the floor from then (``spacing_wait``), or
    the belt was slowed too late, the look-ahead not having foreseen the wait."""
    if idle_s is None:
        return 0
    shortest = k.output_min * (idle_s + ttsot) + k.u_nom * r3a
    return SPACING_WAIT if shortest > k.spacing + k.tol else SPACING_UNFORESEEN


class Adaptive(Policy):
    """``adaptive``: thesis §5.3, steps 1.0-7.0."""

    name = "adaptive"

    def __init__(self, k: CellConstants, controller: Any, file: object = None):
        super().__init__(k, controller, file)
        ideal = controller.ideal_cycle_s
        if ideal is not None and ideal != k.cycle_nom:
            raise ScenarioError(file, "controller.ideal_cycle_s", ideal,
                                "the adaptive policy runs at the nominal cycle; "
                                "set controller.nominal_cycle_s instead")
        self._lag = k.timing.r1_pre.time
        """B → LO tracking the input belt at a speed (R I's part before lift-off)."""

    def plan(self, view: CellView) -> Plan:
        v = view.input_speed()
        lag = self._lag(v)
        plan = adaptive_plan(self.k, v, view.next_part(lag, v), view.output_gap(), lag)
        if plan.limits & SPACING_CAUSE:  # spacing off: name why (the time since TD, read
            plan.limits = plan.limits & ~SPACING_CAUSE | spacing_cause(  # only then)
                self.k, view.since_touchdown(), plan.to_g, plan.r3_pre)
        return plan

    def accounting(self) -> MotionTimeAccounting:
        return AdaptiveAccounting(self)


class AdaptiveAccounting(MotionTimeAccounting):
    """Step 6.2, and beside it the memoryless reading that reproduces the published IP
    (each next arrival counted from the current pick-up; docs/accounting.md)."""

    def finish(self, s: RunSummary, start: int, picked_r4_s: np.ndarray,
               t_next: np.ndarray) -> None:
        super().finish(s, start, picked_r4_s, t_next)
        k = self.policy.k
        memo = accounting.thesis_adaptive_memoryless(t_next[start:], k.cycle_nom,
                                                     k.shortest_cycle_s)
        s.ip_thesis_memoryless = float(memo.mean_ip)
        s.cycle_vs_nominal_memoryless_pct = accounting.pct_off(float(memo.actual_cycle_s),
                                                               k.cycle_nom)
