"""The feeder (thesis §6.2 d): drops part i on the input belt T_i after part i − 1.

The times come from :mod:`cell.arrivals` (eq. 6.9 draws or a trace); the
feeder is the SimPy process that makes each part's record and puts the part on
the input conveyor when its time comes.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
import simpy
from numpy.typing import NDArray

from cell.records import PartRecord


class Loadable(Protocol):
    """Where the feeder drops parts: the input conveyor."""

    def drop(self, part: Any) -> None: ...


class Feeder:
    """Drops part i on the input conveyor T_i after part i − 1 (SimPy process)."""

    def __init__(self, env: simpy.Environment, interarrival_s: NDArray[np.float64],
                 conveyor: Loadable, n_parts: int):
        self.env = env
        self.interarrival_s = interarrival_s.tolist()
        """All the run's draws; the one after the last part is the controller's look-ahead."""
        self.fed_s: list[float] = np.cumsum(interarrival_s).tolist()
        """When each part is (or would be) dropped: the upstream process's schedule."""
        self.n_parts = n_parts
        self.conveyor = conveyor
        self.process = env.process(self.run())

    def run(self):  # noqa: ANN201 (SimPy generator)
        env, drop, fed, t = self.env, self.conveyor.drop, self.fed_s, self.interarrival_s
        for i in range(self.n_parts):
            yield env.timeout(fed[i] - env.now)
            drop(PartRecord(i + 1, fed[i], t[i]))
