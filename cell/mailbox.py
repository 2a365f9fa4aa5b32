"""A light FIFO hand-off between two SimPy processes.

``simpy.Store`` makes an event for every put and every get; between the cell's
processes a put never has to wait (the belts and the robot cannot refuse a
part), so here ``put`` is a plain call and only ``get`` is an event: one event
per hand-off instead of two, which matters at tens of thousands of parts a
second.  Same-instant hand-offs are served in the order they were made.
"""

from __future__ import annotations

from collections import deque
from typing import Any

import simpy
from simpy.events import Event


class Mailbox:
    """Unbounded FIFO: ``put(item)`` now, ``yield box.get()`` for the next item."""

    __slots__ = ("env", "items", "_getter")

    def __init__(self, env: simpy.Environment):
        self.env = env
        self.items: deque[Any] = deque()
        """Items put but not yet taken."""
        self._getter: Event | None = None

    def put(self, item: Any) -> None:
        getter = self._getter
        if getter is not None:
            self._getter = None
            getter.succeed(item)
        else:
            self.items.append(item)

    def get(self) -> Event:
        event = Event(self.env)
        if self.items:
            event.succeed(self.items.popleft())
        elif self._getter is not None:
            raise RuntimeError("a Mailbox serves one waiting process at a time")
        else:
            self._getter = event
        return event

    def __len__(self) -> int:
        return len(self.items)
