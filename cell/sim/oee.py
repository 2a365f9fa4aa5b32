"""The run's time accounted for: each piece of equipment's states, the robot's shares of
them, and OEE as plants define it (ISO 22400-2; docs/model.md, "OEE as plants define it").

The work unit is the robot; its belts bring it parts and take them away.  Its time:

* planned busy time (PBT): the run less planned stops (the robot's maintenance; a calendar's
  time off shift will be taken out here too);
* inside PBT, each instant is downtime (the robot failed or worn: waiting for a crew or under
  repair), actual production time (APT: the robot in motion), blocked (up and still while the
  output belt stands: it cannot set a part down) or starved (up and still otherwise: no part to
  pick, the input belt's stops included);
* availability = APT / PBT, so 1 − A = loss_downtime + loss_starved + loss_blocked;
* performance (the standard's effectiveness) = planned cycle (the nominal cycle,
  controller.nominal_cycle_s as resolved) × produced quantity / APT, its loss
  loss_speed = (APT − cycle × produced) / PBT (negative when the robot beats its nominal cycle);
* quality = good quantity / produced quantity, by the scenario's ``quality.rule``: a part set
  down is produced, a part scrapped from the hand in a failure is produced and not good, and
  under ``spacing`` a part set down outside the spacing tolerance is not good either; its loss
  loss_quality = cycle × (produced − good) / PBT;
* OEE = A × P × Q = cycle × good / PBT, and OEE plus the five losses is 1.

Time and counts cover the whole run (a warm-up in parts is cut from neither).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from cell.sim.records import LIMIT_BIT, RunSummary, StateSpan
from cell.sim.timeline import ROBOT_STATES, fractions, states

_EMPTY = np.empty(0)


def _spans(stops: Sequence[tuple[str, str, float, float, Any]], keep: Callable[[str, str], bool]
           ) -> tuple[np.ndarray, np.ndarray]:
    chosen = [(a, b) for name, cause, a, b, _ in stops if keep(name, cause)]
    if not chosen:
        return _EMPTY, _EMPTY
    arr = np.asarray(chosen, dtype=float)
    return arr[:, 0], arr[:, 1]


def _named(equipment: str) -> Callable[[str, str], bool]:
    return lambda name, cause: name == equipment


def _robot_down(name: str, cause: str) -> bool:
    return name == "robot" and cause != "maintenance"


def _maintenance(name: str, cause: str) -> bool:
    return name == "robot" and cause == "maintenance"


def _busy(column: Callable[[str], np.ndarray], downtime: Any, end_s: float
          ) -> tuple[np.ndarray, np.ndarray]:
    """The robot's motion: as the failure clock logged it, or (nothing stopping the robot
    mid-cycle) each picked part's cycle from its arrival at B."""
    if downtime is not None:
        return downtime.robot.busy(end_s)
    picked = column("picked") != 0
    at_bot = column("at_bot")[picked]
    return at_bot, at_bot + column("cycle")[picked]


def timelines(column: Callable[[str], np.ndarray], downtime: Any, end_s: float,
              stops: Sequence[tuple[str, str, float, float, Any]] = (),
              off_shift: tuple[np.ndarray, np.ndarray] | None = None
              ) -> dict[str, list[tuple[str, float, float]]]:
    """Each piece of equipment's (state, from, to) over [0, end_s]; ``column`` gives the run
    log's per-part values (every part, warm-up included); ``stops``: the run's (failures.csv's
    rows, as :meth:`cell.sim.failures.Downtime.all_stops` gives them); ``off_shift``: a
    calendar's time off shift, every equipment's state ``off_shift`` then (before any other)."""
    off = [] if off_shift is None else [("off_shift", *off_shift)]
    out = {"robot": states(end_s, [
        *off, ("down", *_spans(stops, _robot_down)), ("maintenance", *_spans(stops, _maintenance)),
        ("busy", *_busy(column, downtime, end_s)), ("waiting", column("arrival"),
                                                     column("at_bot"))], "idle")}
    for belt in ("input_belt", "output_belt"):
        out[belt] = states(end_s, [*off, ("down", *_spans(stops, _named(belt)))], "running")
    if downtime is not None and downtime.spec.sensor is not None:
        out["sensor"] = states(end_s, [*off, ("down", *_spans(stops, lambda n, c: n == "sensor"))],
                               "up")
    return out


def state_spans(lines: dict[str, list[tuple[str, float, float]]], station: str | None = None
                ) -> list[StateSpan]:
    """states.csv's rows, equipment by equipment (``station``: whose, in a layout)."""
    return [StateSpan(name, state, a, b, station) for name, rows in lines.items()
            for state, a, b in rows]


def _covered(starts: np.ndarray, ends: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """The length of [a_j, b_j) lying inside the sorted, disjoint intervals [starts, ends)."""
    if not starts.size or not a.size:
        return 0.0
    before = np.concatenate([[0.0], np.cumsum(ends - starts)])

    def upto(t: np.ndarray) -> np.ndarray:  # covered length in [0, t)
        k = np.searchsorted(starts, t, side="right") - 1
        inside = np.minimum(t, ends[np.maximum(k, 0)]) - starts[np.maximum(k, 0)]
        return np.where(k >= 0, before[np.maximum(k, 0)] + inside, 0.0)
    return float(np.sum(upto(b) - upto(a)))


def fast_shares(column: Callable[[str], np.ndarray], end_s: float) -> dict[str, float]:
    """The robot's shares without failures, in a few passes over the parts: its cycles are
    back to back (sorted, disjoint) and the parts reach B in order, so the busy stretches and
    the stretches with a part on the input belt are unions made without sorting."""
    picked = column("picked") != 0
    start = np.minimum(column("at_bot")[picked], end_s)
    stop = np.minimum(start + column("cycle")[picked], end_s)
    busy = float(np.sum(stop - start))
    a, b = np.minimum(column("arrival"), end_s), np.minimum(column("at_bot"), end_s)
    if a.size:  # [arrival, at B) in part order: starts and ends both non-decreasing
        new = np.concatenate([[True], a[1:] > b[:-1]])
        first, last = np.flatnonzero(new), np.append(np.flatnonzero(new)[1:] - 1, a.size - 1)
        a, b = a[first], b[last]
    on_belt = float(np.sum(b - a))
    waiting = on_belt - _covered(start, stop, a, b)
    out = dict.fromkeys(ROBOT_STATES, 0.0)
    if end_s > 0:
        out.update(busy=busy / end_s, waiting=waiting / end_s,
                   idle=max(end_s - busy - waiting, 0.0) / end_s)
    return out




#: The work unit's states over the planned busy time (ISO 22400-2), in order of precedence.
UNIT_STATES = ("down", "busy", "blocked", "starved")
#: summary.csv's OEE losses, each a share of the planned busy time; with ``oee`` they sum to 1.
LOSSES = ("loss_downtime", "loss_starved", "loss_blocked", "loss_speed", "loss_quality")


def unit_seconds(column: Callable[[str], np.ndarray], downtime: Any, end_s: float,
                 stops: Sequence[tuple[str, str, float, float, Any]],
                 planned_off: Sequence[tuple[np.ndarray, np.ndarray]] = ()) -> dict[str, float]:
    """Seconds of the robot (the work unit) in each of :data:`UNIT_STATES` and ``planned``
    (the planned busy time: the run less its planned stops, the robot's maintenance and any
    ``planned_off`` spans, such as a calendar's time off shift).  The states tile the planned
    busy time."""
    if downtime is None and not stops and not planned_off:  # nothing stops: direct sums
        share = fast_shares(column, end_s)
        busy = share["busy"] * end_s
        return {"planned": end_s, "down": 0.0, "busy": busy, "blocked": 0.0,
                "starved": max(end_s - busy, 0.0)}
    off = [("off", s, e) for s, e in planned_off]
    rows = states(end_s, [
        *off, ("maintenance", *_spans(stops, _maintenance)),
        ("down", *_spans(stops, _robot_down)), ("busy", *_busy(column, downtime, end_s)),
        ("blocked", *_spans(stops, _named("output_belt")))], "starved")
    seconds = dict.fromkeys(("off", "maintenance", *UNIT_STATES), 0.0)
    for state, a, b in rows:
        seconds[state] += b - a
    seconds["planned"] = sum(seconds[k] for k in UNIT_STATES)
    return seconds


def produced_and_good(column: Callable[[str], np.ndarray], rule: str) -> tuple[int, int]:
    """The run's produced quantity (parts set down, and parts scrapped from the hand in a
    failure) and good quantity under ``rule`` (the scenario's ``quality.rule``), every part counted."""
    limits = column("limits").astype(np.int_)
    set_down = int(np.count_nonzero(np.isfinite(column("touchdown"))))
    produced = set_down + int(np.count_nonzero(limits & LIMIT_BIT["scrapped"]))
    good = set_down
    if rule == "spacing":
        good -= int(np.count_nonzero(np.isfinite(column("touchdown"))
                                     & (limits & LIMIT_BIT["spacing_off"] != 0)))
    return produced, good


def oee_figures(seconds: dict[str, float], cycle_s: float, produced: int, good: int
                ) -> dict[str, float]:
    """Availability, performance, quality, OEE and the five losses (shares of the planned
    busy time) from the work unit's seconds (:func:`unit_seconds`), the planned cycle and the
    quantities.  A figure with no value is NaN: performance without motion, quality and OEE
    when nothing was produced, everything without planned time."""
    pbt, apt = seconds["planned"], seconds["busy"]
    nan = math.nan
    if not pbt > 0:
        return {"planned_time_s": pbt, **dict.fromkeys(
            ("availability", "performance", "quality", "oee", *LOSSES), nan)}
    ideal_s = cycle_s * produced  # the planned cycle's time for what was produced
    return {
        "planned_time_s": pbt, "availability": apt / pbt,
        "performance": ideal_s / apt if apt > 0 else nan,
        "quality": good / produced if produced else nan,
        "oee": cycle_s * good / pbt if produced else nan,
        "loss_downtime": seconds["down"] / pbt, "loss_starved": seconds["starved"] / pbt,
        "loss_blocked": seconds["blocked"] / pbt, "loss_speed": (apt - ideal_s) / pbt,
        "loss_quality": cycle_s * (produced - good) / pbt}


def measure(r: RunSummary, column: Callable[[str], np.ndarray], downtime: Any,
            nominal_cycle_s: float, end_s: float,
            stops: list[tuple[str, str, float, float, Any]], quality_rule: str = "set_down",
            off_shift: tuple[np.ndarray, np.ndarray] | None = None
            ) -> dict[str, list[tuple[str, float, float]]]:
    """Fill the summary's time shares, OEE (ISO 22400-2) and reliability figures from the
    run's ``stops`` (failures.csv's rows: its failures', or wear's alone); the timelines (with
    failures or wear only: without, the shares are summed directly, and no timeline is
    made)."""
    if downtime is None and not stops:
        lines: dict[str, list[tuple[str, float, float]]] = {}
        share = fast_shares(column, end_s)
    else:
        lines = timelines(column, downtime, end_s, stops, off_shift)
        share = fractions(lines["robot"], end_s, ROBOT_STATES)
    r.robot_busy_fraction, r.robot_waiting_fraction = share["busy"], share["waiting"]
    r.robot_idle_fraction, r.robot_down_fraction = share["idle"], share["down"]
    r.robot_maintenance_fraction = share["maintenance"]
    produced, good = produced_and_good(column, quality_rule)
    planned_off = () if off_shift is None else (off_shift,)
    figures = oee_figures(unit_seconds(column, downtime, end_s, stops, planned_off),
                          nominal_cycle_s, produced, good)
    for name, value in figures.items():
        setattr(r, name, value)
    r.service_level = r.parts_delivered / r.parts_arrived if r.parts_arrived else math.nan
    limits = column("limits").astype(np.int_)[r.warmup_parts:]
    r.parts_lost_downtime = int(np.count_nonzero(limits & LIMIT_BIT["lost_downtime"]))
    r.parts_scrapped = int(np.count_nonzero(limits & LIMIT_BIT["scrapped"]))
    failures = sum(1 for name, cause, *_ in stops if _robot_down(name, cause))
    r.robot_failures = failures
    # (with a calendar, MTBF and MTTR in working time: off shift is neither up nor down)
    robot_up_s = end_s * (1.0 - share["down"] - share["maintenance"] - share.get("off_shift", 0.0))
    r.mtbf_observed_s = robot_up_s / failures if failures else math.nan
    r.mttr_observed_s = share["down"] * end_s / failures if failures else math.nan
    return lines


#: The steps of OEE's loss waterfall (ISO 22400-2), summary.csv's columns, in order, then OEE.
WATERFALL = (*LOSSES, "oee")


def loss_waterfall(r: RunSummary) -> list[tuple[str, float]]:
    """OEE's loss waterfall: the share of the planned busy time lost at each step
    (:data:`LOSSES`), then OEE; they sum to 1."""
    return [(name, getattr(r, name)) for name in WATERFALL]
