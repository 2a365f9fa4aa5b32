"""A replication for the mid-sweep test: the cell's own, which after ``stop_after`` tasks
sets :data:`STARTED` (the test then closes the scheduler and sets :data:`CLOSING`) and keeps
running until the close is under way.

No fixed sleep stands in for the close: a replication past ``stop_after`` waits for
:data:`CLOSING`, then lasts a second more, so the scheduler's close (which waits for the
running replication) always meets one under way, however slowly a loaded machine starts it.
"""

from __future__ import annotations

import threading
import time

from cell.experiments.sweep.runner import simulate_summary

STARTED = threading.Event()
CLOSING = threading.Event()
_state = {"calls": 0, "stop_after": None}


def reset(stop_after: int | None) -> None:
    STARTED.clear()
    CLOSING.clear()
    _state.update(calls=0, stop_after=stop_after)


def replicate(scenario, seed):
    _state["calls"] += 1
    stop = _state["stop_after"]
    if stop is not None and _state["calls"] > stop:
        STARTED.set()
        CLOSING.wait(120)
        time.sleep(1)  # under way while the close begins
    return simulate_summary(scenario, seed)
