"""How long a run is: ``run.parts`` parts, or the parts that come in ``run.hours``.

With ``run.hours`` the inter-arrival times are drawn (from the feeder's one stream, so the
first k are the same whatever the length) until they pass the end; the run then stops at
the end sharp, and the parts still in the cell are counted as such.  ``run.parts`` and
``run.hours`` are exclusive (a scenario giving both is refused).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from cell.plumbing.errors import ScenarioError
from cell.scenario.arrivals import interarrival_times, mean_interarrival
from cell.scenario.run_length import horizon_s, working_s


def run_arrivals(s: Any, seed: Any) -> tuple[np.ndarray, int, float | None]:
    """(T_1 … T_{n+1}, n, horizon in s or None): ``run.parts`` parts, or with ``run.hours``
    (``run.days``, ``run.weeks``) the parts that come before its end.  With a calendar the
    times are drawn in working time and laid out on the calendar (:func:`on_calendar`)."""
    horizon = horizon_s(s)
    if horizon is None:
        n = s.run.parts
        return on_calendar(s, interarrival_times(s.arrivals, n + 1, seed, s.base_dir)), n, None

    m = int(working_s(s, horizon) / mean_interarrival(s.arrivals, s.base_dir) * 1.1) + 64
    while True:
        t = on_calendar(s, interarrival_times(s.arrivals, m, seed, s.base_dir))
        fed = np.cumsum(t)
        n = int(np.searchsorted(fed, horizon, side="left"))  # parts due before the end
        if n < m:
            break
        m *= 2
    if n == 0:
        key = next(k for k in ("hours", "days", "weeks") if getattr(s.run, k) is not None)
        raise ScenarioError(s.source, f"run.{key}", getattr(s.run, key),
                            "no part comes in that time; make the run longer")
    return t[:n + 1], n, horizon


def on_calendar(s: Any, gaps: np.ndarray) -> np.ndarray:
    """Inter-arrival times counted in working time (a profile's included: its clock is then
    working time) as the calendar's: each part comes once its working time has passed, never
    off shift (one due as work stops comes as it resumes).  Without a calendar, ``gaps``."""
    if getattr(s, "calendar", None) is None:
        return gaps
    from cell.scenario.calendar_section import working_week

    times = working_week(s.calendar, s.source).instant(np.cumsum(gaps))
    return np.maximum(np.diff(times, prepend=0.0), 0.0)


def run_until_done(env: Any, log: Any, horizon: float | None, finished: Any) -> None:
    """Run to the horizon, or (failure clocks never end) until the last part is done
    (``finished``, the run log's event)."""
    if horizon is not None:
        env.run(until=horizon)
        log.flush()
        return
    env.run(until=finished)
