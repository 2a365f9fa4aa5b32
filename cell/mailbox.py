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
``Environment.schedule`` does, one Python call less per event, and a box reuses
its events rather than making one per hand-off.  :class:`Timer` does the same for
a process's timeouts.  This reaches into SimPy 4.1's internals (the environment's
``_queue``, ``_eid`` and ``_now``; an event's ``callbacks``, ``_ok`` and ``_value``),
as do the cell's processes, which read the clock as ``env._now`` (``env.now`` without
its property call), so ``pyproject.toml`` pins ``simpy<4.2``; ``tests/test_mailbox.py``
checks the order of deliveries against ``simpy.Store`` and ``env.timeout`` as the reference.
"""

from __future__ import annotations

from collections import deque
from heapq import heappush
from typing import Any

import simpy
from simpy.events import NORMAL, Event


class Mailbox:
    """Unbounded FIFO: ``put(item)`` now, ``put_after(item, delay)``, ``yield box.get()``.

    Its events are reused (hand-written for speed, an event is a Python object with
    an ``__init__``): the receiver's ``get`` re-arms the box's one waiting event once
    SimPy has processed it, and an item already there comes in the box's one
    already-processed event, which SimPy reads as soon as it is yielded.  A process
    that yields ``put_after``'s event is resumed with the item, as the receiver is.
    """

    __slots__ = ("env", "items", "_getter", "_queue", "_eid", "_wait", "_taken")

    def __init__(self, env: simpy.Environment):
        self.env = env
        self.items: deque[Any] = deque()
        """Items put but not yet taken."""
        self._getter: Event | None = None
        """The receiver's event while it waits (None: it does not)."""
        # what Environment.schedule pushes onto: the queue and its event counter
        self._queue, self._eid = env._queue, env._eid
        self._wait = _processed(env)
        self._taken = _processed(env)

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
        if items:  # yielding an event already processed does not wait
            taken = self._taken
            taken._value = items.popleft()
            return taken
        if self._getter is not None:
            raise RuntimeError("a Mailbox serves one waiting process at a time")
        event = self._wait
        if event.callbacks is None:  # processed: re-armed (the receiver has been resumed)
            event.callbacks = []
        else:  # still scheduled (its receiver was interrupted): a fresh one
            event = self._wait = Event(self.env)
        self._getter = event
        return event

    def __len__(self) -> int:
        return len(self.items)


class Timer:
    """``yield timer.after(delay)``: a timeout for a process that waits on one at a time.

    Hand-written for speed (the feeder waits on one a part): one event, re-armed
    once SimPy has processed it, scheduled exactly as ``env.timeout(delay)`` would be.
    """

    __slots__ = ("env", "_event", "_queue", "_eid")

    def __init__(self, env: simpy.Environment):
        self.env = env
        self._event = _processed(env)
        self._queue, self._eid = env._queue, env._eid

    def after(self, delay: float) -> Event:
        event = self._event
        if event.callbacks is None:  # processed: re-armed
            event.callbacks = []
        else:  # still scheduled (its process was interrupted): a fresh one
            event = self._event = _processed(self.env)
            event.callbacks = []
        heappush(self._queue, (self.env._now + delay, NORMAL, next(self._eid), event))
        return event


def _processed(env: simpy.Environment) -> Event:
    """An event as SimPy leaves it once processed (succeeded, no callbacks)."""
    event = Event(env)
    event.callbacks = None  # type: ignore[assignment]
    event._ok = True
    event._value = None
    return event

