"""The feeder (thesis §6.2 d): drops part i on the input belt T_i after part i − 1.

The times come from :mod:`cell.scenario.arrivals` (eq. 6.9 draws or a trace); the
feeder is the SimPy process that makes each part (:class:`~cell.sim.records.Part`) and puts it on
the input conveyor when its time comes.  Parts are solid: a part is dropped
only once the belt has carried the previous one at least a part's size away
(centre to centre); until then the feeder holds it back, like an escapement,
and the hold is recorded (``feed_delay_s``).  On the thesis's arrivals (at least
17.6 s apart) no part is ever held.  While the input belt is stopped by a failure it
carries nothing clear, so the feeder holds every part that comes until it runs again.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
import simpy

from cell.sim.conveyors import EPS_S
from cell.sim.mailbox import Timer
from cell.sim.records import HELD_AT_FEEDER, Part

#: Belt travel this close to clear counts as clear (the rounding of travel and its inverse).
CLEAR_TOL_IN = 1e-9


class Loadable(Protocol):
    """Where the feeder drops parts: the input conveyor."""

    belt: Any

    def drop(self, part: Part, x: float, now: float) -> None: ...

    def changed(self) -> simpy.Event: ...


class Feeder:
    """Drops part i on the input conveyor T_i after part i − 1, when the belt is clear
    (SimPy process)."""

    def __init__(self, env: simpy.Environment, interarrival_s: list[float],
                 conveyor: Loadable, n_parts: int, part_size_in: float, flag: Any = None):
        self.env = env
        self.interarrival_s = interarrival_s
        """All the run's draws; the one after the last part is the controller's look-ahead."""
        self.fed_s: list[float] = np.cumsum(interarrival_s).tolist()
        """When each part comes (is due to be dropped): the upstream process's schedule."""
        self.n_parts = n_parts
        self.conveyor = conveyor
        self.part_size_in = part_size_in
        self.flag = flag
        """Told (part, limit bits) of a part held back."""
        self.process = env.process(self.run())

    def run(self):  # noqa: ANN201 (SimPy generator)
        """Part i comes ``fed_s[i]`` into the run; dropped then, or held till the belt is clear."""
        env, drop, fed = self.env, self.conveyor.drop, self.fed_s
        timeout, travel, flag = env.timeout, self.conveyor.belt.travel, self.flag
        after = Timer(env).after  # speed: docs/performance.md#mailbox
        size = self.part_size_in
        clear_at = -float("inf")
        now = env.now
        for i in range(self.n_parts):
            f = fed[i]
            now = yield after(f - now if f > now else 0.0)  # after a hold it may be due
            x = travel(now)
            if x < clear_at - CLEAR_TOL_IN:  # held back till the belt has carried the last clear
                belt = self.conveyor.belt
                while x < clear_at - CLEAR_TOL_IN:
                    changed = self.conveyor.changed()  # a replan, a stop, a restart: timed again
                    if belt.stopped:  # a failure: wait for the restart
                        yield changed
                    else:
                        yield timeout(max(belt.time_at(clear_at) - env.now, EPS_S)) | changed
                    x = travel(env.now)
                now = env.now
                part = Part(i, now, now - f)
                if flag is not None:
                    flag(part, HELD_AT_FEEDER)
            else:
                part = Part(i, f)
            drop(part, x, now)
            clear_at = x + size
