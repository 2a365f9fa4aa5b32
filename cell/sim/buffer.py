"""The buffer (``buffer:``; docs/layout.md): an accumulating section ending at a gate at B.

A SimPy process between the input conveyor and the controller.  A part that reaches B while
the robot is back and nobody waits goes on to the controller at once, moving, as in the
thesis's cell.  Otherwise it takes a place in the queue (the places behind the gate, ``places``
of them); with every place taken it rides on past the buffer and is lost to it
(``when_full: ride_off``: :data:`~cell.sim.records.BUFFER_FULL`), or stands behind it, the line
before it held (``hold_feeder``).  The moment the robot is back at B with a part at the gate,
the gate lets that part go: its tracking begins then (its ``at_bot_s``), the belt carrying it
off the gate at the belt's speed, so the robot's R I is the one it makes for a part that came
moving.  For the fixed-cycle robot the buffer is thus a queue whose service is the fixed
cycle C.  The queue's occupancy is integrated over time (:attr:`Buffer.area`) and its most
kept (:attr:`Buffer.most`).
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

import simpy

from cell.sim.conveyors import EPS_S
from cell.sim.mailbox import Mailbox
from cell.sim.records import BUFFER_FULL, Part


class Buffer:
    """Parts waiting at the gate at B for the robot (SimPy process; the module's text)."""

    def __init__(self, env: simpy.Environment, settings: Any, robot: Any, arriving: Mailbox,
                 log: Any):
        self.env, self.robot, self.arriving, self.log = env, robot, arriving, log
        self.places: int = settings.places
        self.hold = settings.when_full == "hold_feeder"
        self.gate: Mailbox = Mailbox(env)
        """Parts the gate lets go, each the instant the robot is back for it (the controller
        takes them from here)."""
        self.waiting: deque[tuple[Part, float]] = deque()
        """(part, when it reached the gate's queue) of the parts in the places, first first."""
        self.behind: deque[tuple[Part, float]] = deque()
        """The same for parts standing behind a full buffer (``hold_feeder``)."""
        self.area = 0.0
        """The integral of the occupancy over time so far (part-seconds)."""
        self.most = 0
        """The most parts that waited at once."""
        self._since = 0.0
        self._handed = -math.inf
        """When a part was last handed to the controller (its order may not be given yet)."""
        self._wake: simpy.Event | None = None
        self.process = env.process(self.run())
        self.releasing = env.process(self.release())

    def _count(self, now: float) -> None:
        """The occupancy is about to change now: its integral brought up to now."""
        self.area += len(self.waiting) * (now - self._since)
        self._since = now

    def occupancy_mean(self, end_s: float) -> float:
        """The mean number of parts waiting over [0, end_s]."""
        area = self.area + len(self.waiting) * (end_s - self._since)
        return area / end_s if end_s > 0 else math.nan

    def run(self):  # noqa: ANN201 (SimPy generator)
        """Each part as it reaches B: on to the controller, into a place, or past (or behind)
        a full buffer."""
        get, robot, waiting, gate = self.arriving.get, self.robot, self.waiting, self.gate
        while True:
            part: Part = yield get()
            now = part.at_bot_s
            if not waiting and robot.free_at_s <= now + EPS_S and now > self._handed + EPS_S:
                self._handed = now  # taken moving
                gate.put(part)
                continue
            if len(waiting) < self.places:
                self._count(now)
                waiting.append((part, now))
                if len(waiting) > self.most:
                    self.most = len(waiting)
                wake, self._wake = self._wake, None
                if wake is not None:
                    wake.succeed()
            elif self.hold:
                self.behind.append((part, now))
            else:
                self.log.flag(part, BUFFER_FULL)
                self.log.missed(part)

    def release(self):  # noqa: ANN201 (SimPy generator)
        """The part at the gate let go the moment the robot is back at B (and handed to the
        controller, which orders the robot before this process looks again)."""
        env, robot, waiting, behind = self.env, self.robot, self.waiting, self.behind
        while True:
            if not waiting:
                self._wake = env.event()
                yield self._wake
                continue
            free = robot.free_at_s
            if free > env.now + EPS_S:
                if free < math.inf:
                    yield env.timeout(free - env.now)
                else:  # stopped: until it is told when it will be free
                    yield robot.stops.freed()
                continue
            now = env.now
            self._count(now)
            part, since = waiting.popleft()
            if behind:  # the part standing behind moves up into the freed place
                waiting.append(behind.popleft())
            part.buffer_wait_s += now - since
            part.at_bot_s = now  # tracking begins as the gate lets it go
            self._handed = now
            yield self.gate.put_after(part, 0.0)  # the controller orders the robot first
