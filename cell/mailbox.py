"""A light FIFO hand-off between two SimPy processes.

``simpy.Store`` makes an event for every put and every get; between the cell's
processes a put never has to wait (the belts and the robot cannot refuse a
part), so here a hand-off costs at most one event, and none when the item is
already there:

* ``put(item)`` is a plain call: it wakes the waiting process (one event, now)
  or queues the item;
* ``put_after(item, delay)`` hands the item to the waiting process ``delay``
  seconds from now: the one event *is* the item's arrival (a part reaching B,
  a part set down), and the sender may wait on it too, to resume just after the
  receiver has taken it;
* ``yield box.get()`` takes the next item: if one is queued the process goes on
  at once (SimPy resumes a process at once on an event already processed),
  otherwise it waits for the next ``put``.

Same-instant hand-offs are served in the order they were made.

Hand-written for speed (every part passes through four of these): an event is
scheduled by pushing it onto SimPy's event queue exactly as
``Environment.schedule`` does, one Python call less per event.
"""

from __future__ import annotations

from collections import deque
from heapq import heappush
from typing import Any

import simpy
from simpy.events import NORMAL, Event


def _taken(env: simpy.Environment, item: Any) -> Event:
    """An event already processed with ``item`` as its value: yielding it does not wait."""
    event = Event.__new__(Event)
    event.env = env
    event.callbacks = None  # type: ignore[assignment]
    event._ok = True
    event._value = item
    return event


class Mailbox:
    """Unbounded FIFO: ``put(item)`` now, ``put_after(item, delay)``, ``yield box.get()``."""

    __slots__ = ("env", "items", "_getter", "_queue", "_eid")

    def __init__(self, env: simpy.Environment):
        self.env = env
        self.items: deque[Any] = deque()
        """Items put but not yet taken."""
        self._getter: Event | None = None
        # what Environment.schedule pushes onto: the queue and its event counter
        self._queue, self._eid = env._queue, env._eid

    def put(self, item: Any) -> None:
        getter = self._getter
        if getter is not None:  # the receiver is waiting: its get() succeeds now
            self._getter = None
            getter._ok = True
            getter._value = item
            heappush(self._queue, (self.env._now, NORMAL, next(self._eid), getter))
        else:
            self.items.append(item)

    def put_after(self, item: Any, delay: float) -> Event:
        """Hand ``item`` to the process waiting on :meth:`get` ``delay`` s from now;
        returns the event, which others may wait on as well (they resume after it).

        Only for a hand-off the receiver is already waiting for, with nothing queued.
        """
        getter = self._getter
        if getter is None or self.items:
            raise RuntimeError("Mailbox.put_after needs a process waiting on an empty mailbox")
        self._getter = None
        getter._ok = True
        getter._value = item
        heappush(self._queue, (self.env._now + delay, NORMAL, next(self._eid), getter))
        return getter

    def get(self) -> Event:
        items = self.items
        if items:
            return _taken(self.env, items.popleft())
        if self._getter is not None:
            raise RuntimeError("a Mailbox serves one waiting process at a time")
        event = self._getter = Event(self.env)
        return event

    def __len__(self) -> int:
        return len(self.items)

