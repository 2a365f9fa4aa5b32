"""A replication for the mid-sweep test: the cell's own, which after ``stop_after`` tasks
sets :data:`STARTED` (the test then closes the scheduler) and waits for the end."""

from __future__ import annotations

import threading
import time

from cell.experiments.sweep.runner import simulate_summary

STARTED = threading.Event()
_state = {"calls": 0, "stop_after": None}


def reset(stop_after: int | None) -> None:
    STARTED.clear()
    _state.update(calls=0, stop_after=stop_after)


def replicate(scenario, seed):
    _state["calls"] += 1
    stop = _state["stop_after"]
    if stop is not None and _state["calls"] > stop:
        STARTED.set()
        time.sleep(1)  # a long replication: the scheduler goes away meanwhile
    return simulate_summary(scenario, seed)
