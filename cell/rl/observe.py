"""What the agent sees at a decision (docs/rl.md, "Observations"): only what the controller may
know when a part reaches B with the robot free, never the feeder's schedule.

The components (:data:`FIELDS`): the time; the part's number; the input belt's speed; the
output belt's travel since the last touch-down and the seconds since it (-1: none yet); the
next part as the controller's look-ahead reports it, ``(a, b)`` of
:meth:`cell.sim.policies.base.CellView.next_part` at R I's tracking lag (-1, -1: none in sight);
the seconds the robot has waited at B; whether the look-ahead sensor is up; and how many parts
the sensor has reported ahead (-1 with the thesis's ideal look-ahead, which reports only the
next part).  With ``sensor.lookahead: sensor`` the look-ahead is the sensor's reports; with
``ideal`` it is the thesis's (§5.3) knowledge of the next part's arrival, one part ahead.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

FIELDS = ("time_s", "part", "input_speed_in_s", "output_gap_in", "since_touchdown_s",
          "next_a_s", "next_b_in", "robot_idle_s", "sensor_up", "reported")
#: What a component is when there is nothing to report.
NONE = -1.0


def low_high() -> tuple[np.ndarray, np.ndarray]:
    """The observation space's bounds."""
    lo = np.array([0.0, 0.0, 0.0, NONE, NONE, NONE, NONE, 0.0, 0.0, NONE], dtype=np.float64)
    return lo, np.full(len(FIELDS), math.inf, dtype=np.float64)


def observe(view: Any, robot_free_at_s: float) -> np.ndarray:
    """The observation of the decision ``view`` is at (the controller's view of the cell)."""
    v = view.input_speed()
    nxt = view.next_part(view.k.timing.r1_pre.time(v), v)
    gap, since = view.output_gap(), view.since_touchdown()
    sensor = getattr(view, "sensor", None)
    return np.array([
        view.now, view.part, v, NONE if gap is None else gap, NONE if since is None else since,
        NONE if nxt is None else nxt[0], NONE if nxt is None else nxt[1],
        max(view.now - robot_free_at_s, 0.0), 1.0 if view.sensor_up else 0.0,
        NONE if sensor is None else len(sensor.reports)], dtype=np.float64)


def empty() -> np.ndarray:
    """The observation after the run's end (nothing to decide)."""
    return low_high()[0].copy()
