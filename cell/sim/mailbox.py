"""The cell's one adapter to SimPy's internals: a light FIFO hand-off and a reusable timeout.

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

Same-instant hand-offs are served in the order they were made.  :class:`Timer` is
``env.timeout`` for a process that waits on one timeout at a time.

Why private attributes, and which. Every part passes through four mailboxes and one timer;
scheduling an event by pushing it onto SimPy's queue exactly as ``Environment.schedule`` does,
and reusing a box's events rather than making one per hand-off, is what keeps the model near
SimPy's own speed (speed: docs/performance.md#mailbox); ``tests/sim/test_mailbox.py`` runs the
whole model with :class:`StoreMailbox` and :class:`TimeoutTimer` (``simpy.Store``,
``env.timeout``) in their place and finds every part's record the same to the last bit.
The accesses, all in this module (``grep -rnE
"\\._(now|queue|eid|ok|value)\\b" cell/`` finds no other):

* ``env._queue``, ``env._eid``: the event heap and its counter, pushed onto as
  ``Environment.schedule`` does (same ordering key: time, priority, event id);
* ``env._now``: the clock, read once per push (``env.now`` is a property over it);
* ``event._ok``, ``event._value``: set as ``Event.succeed`` sets them when a hand-off
  is scheduled; ``_value`` reset to ``PENDING`` when a box re-arms its event, so
  ``event.triggered`` is False while a receiver waits, as on a fresh ``env.event()``;
* ``event.callbacks``: public; ``None`` once SimPy has processed the event, which is
  how a box knows its event may be re-armed.

These are SimPy 4.1's (``pyproject.toml`` pins ``simpy>=4.1.1,<4.2``); :func:`check_simpy`
refuses another version at import with a message saying what to install.
"""

from __future__ import annotations

from collections import deque
from heapq import heappush
from typing import Any

import simpy
from simpy.events import NORMAL, PENDING, Event

#: The SimPy versions whose internals this module was written against and is tested with.
SUPPORTED = ((4, 1), (4, 2))  # [from, to)


def check_simpy(version: str = simpy.__version__) -> None:
    """Raise ImportError with a clear message unless ``version`` is a supported SimPy and its
    environment still has the attributes this module uses."""
    try:
        major_minor = tuple(int(p) for p in version.split(".")[:2])
    except ValueError:
        major_minor = (0, 0)
    env = simpy.Environment()
    missing = [name for name in ("_queue", "_eid", "_now") if not hasattr(env, name)]
    if not SUPPORTED[0] <= major_minor < SUPPORTED[1] or missing:
        raise ImportError(
            f"cell needs SimPy 4.1 (found SimPy {version}): cell/sim/mailbox.py schedules events on "
            "SimPy 4.1's own event queue; install it with: pip install 'simpy>=4.1.1,<4.2'")


check_simpy()


class Mailbox:
    """Unbounded FIFO: ``put(item)`` now, ``put_after(item, delay)``, ``yield box.get()``.

    Its events are reused (an event is a Python object with an ``__init__``): the
    receiver's ``get`` re-arms one of the box's two waiting events, the one SimPy
    processed before the last, and an item already there comes in the box's one already-processed event, which
    SimPy reads as soon as it is yielded.  A process that yields ``put_after``'s event
    is resumed with the item, as the receiver is.
    """

    __slots__ = ("env", "items", "_getter", "_queue", "_eid", "_wait", "_spare", "_taken")

    def __init__(self, env: simpy.Environment):
        self.env = env
        self.items: deque[Any] = deque()
        """Items put but not yet taken."""
        self._getter: Event | None = None
        """The receiver's event while it waits (None: it does not)."""
        # what Environment.schedule pushes onto: the queue and its event counter
        self._queue, self._eid = env._queue, env._eid
        self._wait, self._spare = _processed(env), _processed(env)
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
        # Two events, used in turn: the one SimPy is processing now (whose later callbacks,
        # a sender's, still read its value) is re-armed only at the next hand-off.
        event, self._spare = self._spare, self._wait
        if event.callbacks is None:  # processed: re-armed, not triggered while it waits
            event.callbacks = []
            event._value = PENDING
        else:  # still scheduled (its receiver was interrupted): a fresh one
            event = Event(self.env)
        self._wait = event
        self._getter = event
        return event

    def __len__(self) -> int:
        return len(self.items)


class Timer:
    """``now = yield timer.after(delay)``: a timeout for a process that waits on one at a time,
    whose value is the instant it fires.

    One event, re-armed once SimPy has processed it, scheduled exactly as
    ``env.timeout(delay, value=env.now + delay)`` would be (triggered at once, as a timeout is).
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
        at = event._value = self.env._now + delay
        heappush(self._queue, (at, NORMAL, next(self._eid), event))
        return event


class StoreMailbox:
    """:class:`Mailbox` in SimPy's public API (``simpy.Store``, ``env.timeout``): the reference
    the tests and the bench hold the fast one to (same items, same instants, same order)."""

    def __init__(self, env: simpy.Environment):
        self.env, self.store = env, simpy.Store(env)

    def put(self, item: Any) -> None:
        self.store.put(item)

    def put_after(self, item: Any, delay: float) -> Event:
        if not self.store.get_queue or self.store.items:
            raise RuntimeError("Mailbox.put_after needs a process waiting on an empty mailbox")
        getter = self.store.get_queue[0]  # the receiver's get: the sender resumes after it
        def deliver(_: Event) -> None:
            self.store.put(item)

        self.env.timeout(delay).callbacks.append(deliver)
        return getter

    def get(self) -> Event:
        return self.store.get()

    def __len__(self) -> int:
        return len(self.store.items)


class TimeoutTimer:
    """:class:`Timer` in SimPy's public API: a new ``env.timeout`` each time."""

    def __init__(self, env: simpy.Environment):
        self.env = env

    def after(self, delay: float) -> Event:
        return self.env.timeout(delay, self.env.now + delay)


def _processed(env: simpy.Environment) -> Event:
    """An event as SimPy leaves it once processed (succeeded, no callbacks)."""
    event = Event(env)
    event.callbacks = None  # type: ignore[assignment]
    event._ok = True
    event._value = None
    return event
