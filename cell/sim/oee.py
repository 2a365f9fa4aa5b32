"""The run's time accounted for: each piece of equipment's states, the robot's shares of
them, and OEE = availability × performance × quality (Nakajima; SPEC §10; docs/model.md,
"When equipment fails").

* availability: the time the cell was not down (the robot or a belt failed; the sensor's
  failures do not stop it) over the run less its planned maintenance;
* performance: the robot's fastest cycle × parts delivered over that up time;
* quality: parts set down within the spacing tolerance over parts delivered.

Time measures cover the whole run (a warm-up in parts is not cut from them).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from cell.sim.records import LIMIT_BIT, RunSummary, StateSpan
from cell.sim.timeline import ROBOT_STATES, fractions, states

_EMPTY = np.empty(0)


def _spans(stops: list[tuple[str, str, float, float, Any]], keep: Callable[[str, str], bool]
           ) -> tuple[np.ndarray, np.ndarray]:
    chosen = [(a, b) for name, cause, a, b, _ in stops if keep(name, cause)]
    if not chosen:
        return _EMPTY, _EMPTY
    arr = np.asarray(chosen, dtype=float)
    return arr[:, 0], arr[:, 1]


def _named(equipment: str) -> Callable[[str, str], bool]:
    return lambda name, cause: name == equipment


def timelines(column: Callable[[str], np.ndarray], downtime: Any, end_s: float
              ) -> dict[str, list[tuple[str, float, float]]]:
    """Each piece of equipment's (state, from, to) over [0, end_s]; ``column`` gives the run
    log's per-part values (every part, warm-up included)."""
    stops = downtime.all_stops(end_s) if downtime is not None else []
    arrival, at_bot = column("arrival"), column("at_bot")
    if downtime is not None:
        busy = downtime.robot.busy(end_s)
    else:
        picked = column("picked") != 0
        busy = (at_bot[picked], at_bot[picked] + column("cycle")[picked])
    out = {"robot": states(end_s, [
        ("down", *_spans(stops, lambda n, c: n == "robot" and c != "maintenance")),
        ("maintenance", *_spans(stops, lambda n, c: n == "robot" and c == "maintenance")),
        ("busy", *busy), ("waiting", arrival, at_bot)], "idle")}
    for belt in ("input_belt", "output_belt"):
        out[belt] = states(end_s, [("down", *_spans(stops, _named(belt)))], "running")
    if downtime is not None and downtime.spec.sensor is not None:
        out["sensor"] = states(end_s, [("down", *_spans(stops, lambda n, c: n == "sensor"))],
                               "up")
    return out


def state_spans(lines: dict[str, list[tuple[str, float, float]]]) -> list[StateSpan]:
    """states.csv's rows, equipment by equipment."""
    return [StateSpan(name, state, a, b) for name, rows in lines.items() for state, a, b in rows]


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


def measure(r: RunSummary, column: Callable[[str], np.ndarray], downtime: Any,
            fastest_cycle_s: float, end_s: float) -> dict[str, list[tuple[str, float, float]]]:
    """Fill the summary's time shares, OEE and reliability figures; the timelines (with
    failures only: without, the shares are summed directly, and no timeline is made)."""
    if downtime is None:
        lines: dict[str, list[tuple[str, float, float]]] = {}
        share = fast_shares(column, end_s)
    else:
        lines = timelines(column, downtime, end_s)
        share = fractions(lines["robot"], end_s, ROBOT_STATES)
    r.robot_busy_fraction, r.robot_waiting_fraction = share["busy"], share["waiting"]
    r.robot_idle_fraction, r.robot_down_fraction = share["idle"], share["down"]
    r.robot_maintenance_fraction = share["maintenance"]
    stops = downtime.all_stops(end_s) if downtime is not None else []
    if not stops:
        cell_share = {"maintenance": 0.0, "down": 0.0, "up": 1.0 if end_s > 0 else math.nan}
    else:
        cell_share = fractions(states(end_s, [
            ("maintenance", *_spans(stops, lambda n, c: n == "robot" and c == "maintenance")),
            ("down", *_spans(stops, lambda n, c: n != "sensor" and c != "maintenance"))], "up"),
            end_s, ("maintenance", "down", "up"))
    planned = cell_share["up"] + cell_share["down"]  # the run less planned stops (exactly 1 × up
    up_s = cell_share["up"] * end_s                   # when nothing failed, never above it)
    r.availability = cell_share["up"] / planned if planned > 0 else math.nan
    r.performance = fastest_cycle_s * r.parts_delivered / up_s if up_s > 0 else math.nan
    good = r.parts_delivered - r.spacing_outside_tol
    r.quality = good / r.parts_delivered if r.parts_delivered else math.nan
    r.oee = r.availability * r.performance * r.quality
    r.service_level = r.parts_delivered / r.parts_arrived if r.parts_arrived else math.nan
    limits = column("limits").astype(np.int_)[r.warmup_parts:]
    r.parts_lost_downtime = int(np.count_nonzero(limits & LIMIT_BIT["lost_downtime"]))
    r.parts_scrapped = int(np.count_nonzero(limits & LIMIT_BIT["scrapped"]))
    failures = sum(1 for name, cause, *_ in stops if name == "robot" and cause != "maintenance")
    r.robot_failures = failures
    robot_up_s = end_s * (1.0 - share["down"] - share["maintenance"])
    r.mtbf_observed_s = robot_up_s / failures if failures else math.nan
    r.mttr_observed_s = share["down"] * end_s / failures if failures else math.nan
    return lines


#: The steps of OEE's loss waterfall (Nakajima), in order.
WATERFALL = ("downtime (availability)", "speed and waiting (performance)",
             "spacing off (quality)")


def loss_waterfall(availability: float, performance: float, quality: float
                   ) -> list[tuple[str, float]]:
    """OEE's loss waterfall: the share of the planned time lost at each step, then OEE.

    Downtime costs 1 − A of the planned time, the robot's pace costs A (1 − P) of it, parts
    set down off spacing A P (1 − Q); what is left is OEE = A P Q, so the four shares sum
    to 1."""
    a, p, q = availability, performance, quality
    return [(WATERFALL[0], 1.0 - a), (WATERFALL[1], a * (1.0 - p)),
            (WATERFALL[2], a * p * (1.0 - q)), ("OEE", a * p * q)]
