"""The part in flight, from the feeder to the output belt or the floor (split from
:mod:`cell.sim.records`, which re-exports it: each slot's one writer is told there)."""

from __future__ import annotations

import math
from typing import Any

NAN = math.nan


class Part:
    """A part in flight, from the feeder to the output belt (or the floor).

    Each slot is written once, by its owner (see the module's text): ``index`` (0 … N − 1, the one
    numbering of parts inside the model; parts.csv's ``part`` is ``index + 1``), ``arrival_s`` and
    ``feed_delay_s`` by the feeder, ``at_bot_s`` by the input conveyor, ``plan`` (the policy's
    :class:`~cell.sim.policies.base.Plan`, or None: not picked) by the controller, ``pick_s`` by the
    robot, ``touchdown_s``, ``spacing_in`` and ``delivery_interval_s`` by the output conveyor;
    in a layout (docs/layout.md) ``buffer_wait_s`` by a buffer, which also writes ``at_bot_s``
    when its gate lets the part go (its tracking begins then), and ``station`` by the line.
    A part that comes to a second station has the slots of its visit written again there,
    by the same owners: its row tells of the last station that handled it.
    """

    __slots__ = ("index", "arrival_s", "feed_delay_s", "at_bot_s", "plan", "pick_s",
                 "touchdown_s", "spacing_in", "delivery_interval_s", "buffer_wait_s", "station")

    def __init__(self, index: int, arrival_s: float, feed_delay_s: float = 0.0):
        self.index, self.arrival_s, self.feed_delay_s = index, arrival_s, feed_delay_s
        self.at_bot_s = self.pick_s = self.touchdown_s = self.spacing_in = self.delivery_interval_s = NAN
        self.plan: Any = None
        self.buffer_wait_s = 0.0
        self.station: str | None = None

    def begin_visit(self) -> None:
        """The part comes to a series station: the slots of its visit to the station before
        (B, plan, lift-off, set-down) cleared for this one's owners to write."""
        self.at_bot_s = self.pick_s = self.touchdown_s = self.spacing_in = self.delivery_interval_s = NAN
        self.plan = None
