"""The two belt conveyors (thesis §4.1, §5.2, §6.2 a).

A belt is a speed schedule: piecewise-constant speeds from given instants, so its travel X(t) is
piecewise linear and exact.  Speed changes take effect at once (§6.2 a: negligible lag).  The
controller writes the schedule ahead of time (a change at LO, the step 6.3 decay at the end of the
cycle, the output belt back to nominal at G); a part's arrival is the instant the belt has carried
it the required distance, so the input conveyor's SimPy process only wakes when a part reaches B
(the controller, which replans only then, having taken it first), and the output conveyor's when a
part is set down.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import simpy

from cell.sim.mailbox import Mailbox
from cell.sim.records import Part

if TYPE_CHECKING:
    from collections.abc import Sequence

    from cell.plumbing.types import Array

#: Two instants closer than this are the same instant (float rounding of planned times).
EPS_S = 1e-6


def speed_at(instants: Sequence[float] | Array, speeds: Sequence[float] | Array,
             t: float) -> float:
    """A piecewise-constant schedule's speed at t: the last change at or before t
    (``instants`` in time order; lists or arrays alike, neither copied)."""
    return speeds[max(bisect_right(instants, t) - 1, 0)]


class Belt:
    """A belt's speed schedule and travel X(t) (inches since t = 0).

    Only the schedule from the present on is kept: a change whose successor has started is final and
    is handed to ``on_change`` (e.g. a ``belts.csv`` writer) and dropped, so a long run keeps a few
    entries, not its history.
    """

    __slots__ = ("_t", "_x", "_v", "on_change", "max_speed_in_s", "min_speed_in_s", "_halted",
                 "stoppable", "_at_t", "_at_x", "_at_v")

    def __init__(self, speed_in_s: float, on_change: Callable[[float, float], Any] | None = None,
                 stoppable: bool = False):
        self._t, self._x, self._v = [0.0], [0.0], [speed_in_s]
        """Instants at which a speed starts, the travel then, and the speed from then on (the last
        holds for ever)."""
        self.on_change = on_change
        """Told (instant, speed) of every change once it is final."""
        self.max_speed_in_s = self.min_speed_in_s = speed_in_s
        """The fastest and the slowest of the settled speeds (of all of them once closed)."""
        self._halted: tuple[float, list[tuple[float, float]]] | None = None
        """While stopped by a failure: the speed it ran at and the changes planned after."""
        self.stoppable = stoppable  # by a failure or the calendar: only then is the below kept
        self._at_t, self._at_x, self._at_v = 0.0, 0.0, speed_in_s
        """The last settled change (instant, travel, speed), in force when a replan from a later
        instant has settled past the present (a stop starts from it; kept if ``stoppable``)."""

    @classmethod
    def of_history(cls, history: Sequence[Sequence[float]]) -> Belt:
        """The belt that ran ``history``, its (from_s, speed_in_s) changes in time order (as
        ``belts.csv`` has them), held whole (the animation's: one rule of travel)."""
        belt = cls(history[0][1])
        belt._t[0] = history[0][0]
        for t, v in history[1:]:
            belt._run_from(t, v)
        return belt

    @property
    def held(self) -> int:
        """Speed segments held: the one in force and those planned (memory stays flat)."""
        return len(self._t)

    def speed(self, t: float) -> float:
        """The speed at t."""
        return self._v[bisect_right(self._t, t, 1) - 1]  # lo=1: the first change if t is before it

    def travel(self, t: float) -> float:
        """X(t): inches the belt has moved by time t (t ≥ the last settled change, or a
        rounding before it: a replan within EPS_S of a change may settle up to it)."""
        k = bisect_right(self._t, t, 1) - 1  # lo=1: k >= 0, the first change if t is before it
        return self._x[k] + self._v[k] * (t - self._t[k])

    def time_at(self, x: float) -> float:
        """First instant at which the belt's travel reaches x (speeds are > 0)."""
        k = bisect_right(self._x, x, 1) - 1  # lo=1: k >= 0, as in travel
        return self._t[k] + (x - self._x[k]) / self._v[k]

    def plan(self, t1: float, v1: float, t2: float | None = None, v2: float = 0.0,
             t3: float | None = None, v3: float = 0.0) -> None:
        """From instant t1 (now or later) run at v1, from t2 > t1 at v2 and from t3 > t2 at v3
        (the output belt's floor), dropping later plans: a new plan supersedes what was planned
        after t1, a change within EPS_S of the last one replaces it, and the changes before t1
        whose successors have started are settled.  The controller's case first."""
        if not v1 > 0 or (t2 is not None and not v2 > 0) or (t3 is not None and not v3 > 0):
            raise ValueError(f"belt speeds must be positive, got {v1!r}, {v2!r}, {v3!r}")
        if self._halted is not None:  # stopped by a failure: the plan is for the restart
            self._plan_stopped(t1, v1, t2, v2, t3, v3)
            return
        ts, xs, vs = self._t, self._x, self._v
        t0 = ts[-1]
        if t0 > t1 + EPS_S and len(ts) > 1 and ts[-2] < t1:  # one change planned after t1
            del ts[-1], xs[-1], vs[-1]  # (the output belt's floor): dropped, as below
            t0 = ts[-1]
        if t0 < t1 and t2 is not None and t1 < t2 and (t3 is None or t2 < t3):
            # the controller's every replan: all after the last change, which alone is kept
            n = len(ts) - 1
            if n > 0:
                self._settle(n)
            x0, v0 = xs[-1], vs[-1]
            x1 = x0 + v0 * (t1 - t0)
            x2 = x1 + v1 * (t2 - t1)
            if t3 is None:
                self._t, self._x, self._v = [t0, t1, t2], [x0, x1, x2], [v0, v1, v2]
            else:
                self._t, self._x, self._v = \
                    [t0, t1, t2, t3], [x0, x1, x2, x2 + v2 * (t3 - t2)], [v0, v1, v2, v3]
            return
        k = bisect_right(ts, t1 + EPS_S)
        if k == 0:  # would rewrite what is settled (and leave no schedule at all)
            raise ValueError(f"a belt's plan cannot start at {t1!r}, before its earliest "
                             f"held change ({ts[0]!r})")
        if k < len(ts):
            del ts[k:], xs[k:], vs[k:]
        n = bisect_right(ts, t1) - 1
        if n > 0:  # settle the changes whose successors have started
            self._settle(n)
            del ts[:n], xs[:n], vs[:n]
        self._run_from(t1, v1)
        if t2 is not None:
            self._run_from(t2, v2)
        if t3 is not None:
            self.then(t3, v3)

    def then(self, t: float, v: float) -> None:
        """And from instant t, after every change planned, run at v (a third change)."""
        ts, xs, vs = self._t, self._x, self._v
        t0 = ts[-1]
        if not v > 0 or not t > t0:
            raise ValueError(f"a belt's further change must come after its last and be "
                             f"positive, got {t!r}, {v!r}")
        xs.append(xs[-1] + vs[-1] * (t - t0))
        ts.append(t)
        vs.append(v)

    def _run_from(self, t: float, v: float) -> None:
        """Run at v from instant t on (at or before the last change: that change's speed is v)."""
        ts, xs, vs = self._t, self._x, self._v
        t0 = ts[-1]
        if t <= t0:
            vs[-1] = v
        else:
            xs.append(xs[-1] + vs[-1] * (t - t0))
            ts.append(t)
            vs.append(v)

    def _settle(self, n: int) -> None:
        """The first ``n`` changes are final: note their speeds and tell ``on_change`` (the
        last of them kept as the anchor a stop starts from, if the belt is ``stoppable``)."""
        if n and self.stoppable:
            self._at_t, self._at_x, self._at_v = self._t[n - 1], self._x[n - 1], self._v[n - 1]
        vs = self._v
        hi, lo = self.max_speed_in_s, self.min_speed_in_s
        for v in vs[:n]:
            if v > hi:
                hi = v
            elif v < lo:  # lo <= hi: a speed above hi is not below lo
                lo = v
        self.max_speed_in_s, self.min_speed_in_s = hi, lo
        told = self.on_change
        if told is not None:
            ts = self._t
            for i in range(n):
                told(ts[i], vs[i])

    @property
    def stopped(self) -> bool:
        """Whether the belt stands (a failure, :meth:`stop`) until :meth:`restart`."""
        return self._halted is not None

    def _plan_stopped(self, t1: float, v1: float, t2: float | None = None, v2: float = 0.0,
                      t3: float | None = None, v3: float = 0.0) -> None:
        """:meth:`plan` while stopped: the plan takes effect from the restart on."""
        assert self._halted is not None
        running, later = self._halted
        later = [(t, v) for t, v in later if t < t1 - EPS_S] + [(t1, v1)]
        later += [(t, v) for t, v in ((t2, v2), (t3, v3)) if t is not None]
        self._halted = (running, later)

    def restart(self, t: float) -> None:
        """Run again from instant t (now), at the speed the plan has for t."""
        assert self._halted is not None
        v, later = self._halted
        self._halted = None
        ahead = []
        for tp, vp in later:
            if tp <= t:
                v = vp
            else:
                ahead.append((tp, vp))
        self._run_from(t, v)
        for tp, vp in ahead:
            self._run_from(tp, vp)

    def stop(self, t: float) -> None:
        """Stand from instant t (now) on: speed 0, parts stay where they are; what was
        planned after t is kept for :meth:`restart` (docs/model.md, "When equipment fails");
        only a belt built ``stoppable``."""
        if not self.stoppable:
            raise RuntimeError("a belt built as one nothing can stop was stopped")
        ts, vs = self._t, self._v
        if ts[0] > t:  # a replan from a later instant settled the change in force now: stop
            t0, x0, v0 = self._at_t, self._at_x, self._at_v  # from it, every held change kept for the restart
            self._halted = (v0, list(zip(ts, vs)))
            self._t, self._x, self._v = [t], [x0 + v0 * (t - t0)], [0.0]
            return
        k = bisect_right(ts, t)
        later = list(zip(ts[k:], vs[k:]))
        running = vs[k - 1] if k > 0 else vs[0]
        del ts[k:], self._x[k:], vs[k:]
        self._run_from(t, 0.0)
        self._halted = (running, later)

    def close(self, until: float | None = None) -> None:
        """Hand every change still held (planned ones included) to ``on_change``; with ``until``
        (the run's end), those planned to start then or later, which never took effect, dropped."""
        if until is not None:
            keep = max(bisect_left(self._t, until - EPS_S), 1)
            del self._t[keep:], self._x[keep:], self._v[keep:]
        self._settle(len(self._t))
        del self._t[:], self._x[:], self._v[:]


class InputConveyor:
    """Carries parts from the feeder, ``length_in`` upstream of B, to B.

    Its process takes each part the feeder drops (``loaded``), works out when the belt will have
    carried it to B, and hands it to the controller (``at_bot``) due at that instant: one event,
    which wakes the controller and then this process, so the controller plans (and may replan the
    belt) before the next part is timed.  A part nobody picks up rides on to F and falls off (§6.3).

    The controller replans the belt only when a part reaches B, so a part on its way to B never has
    its arrival moved; a replan that would change the belt before a part due reaches B is refused (it
    would need the part timed again).
    """

    def __init__(self, env: simpy.Environment, speed_in_s: float, length_in: float,
                 on_change: Callable[[float, float], Any] | None = None, stops: Any = None):
        self.env = env
        self.belt = Belt(speed_in_s, on_change, stoppable=stops is not None)
        self.length_in = length_in
        """Feeder drop point to B (in)."""
        self.stops = stops
        """What can stop the belt (:class:`cell.sim.failures.BeltStops`; None: nothing)."""
        self.loaded: Mailbox = Mailbox(env)
        """Parts dropped on the belt by the feeder."""
        self.at_bot: Mailbox = Mailbox(env)
        """Parts as they reach B (the controller waits on it)."""
        self.x_fed: dict[int, float] = {}
        """Belt travel at the instant each part on the belt was dropped (by index)."""
        self.due_s = -math.inf
        """When the part on its way to B gets there (-inf: none is)."""
        self._changed: simpy.Event | None = None
        self.timing = False
        """True while a part's way to B is waited for in steps a stop can interrupt."""
        self.process = env.process(self.run())

    def drop(self, part: Part, x: float, now: float) -> None:
        """The feeder puts a part on the belt now (the clock's ``now``), its travel being x."""
        self.x_fed[part.index] = x
        self.loaded.put((part, now))

    def changed(self) -> simpy.Event:
        """An event that succeeds when the belt's plan next changes (a replan, a stop or a
        restart): what the feeder waits on, beside its timeout, while it holds a part."""
        if self._changed is None:
            self._changed = self.env.event()
        return self._changed

    def _tell(self) -> None:
        changed, self._changed = self._changed, None
        if changed is not None:
            changed.succeed()

    def replan(self, t1: float, v1: float, t2: float | None = None, v2: float = 0.0) -> None:
        """New speed plan from the controller (:meth:`Belt.plan`), as a part reaches B."""
        if t1 < self.due_s:  # the plan's start, not env.now (a property: :meth:`.Robot.run`)
            raise RuntimeError("the input belt was replanned while a part was on its way to B")
        self.belt.plan(t1, v1, t2, v2)
        if self._changed is not None:
            self._tell()

    def stop(self, now: float) -> None:
        """A failure stops the belt now: the part on its way to B is timed again."""
        self.belt.stop(now)
        self._retime()

    def restart(self, now: float) -> None:
        """The belt runs again from now."""
        self.belt.restart(now)
        self._retime()

    def _retime(self) -> None:
        if self.timing:
            self.process.interrupt()
        self._tell()

    def run(self):  # noqa: ANN201 (SimPy generator)
        """Each part handed to the controller due at the instant it reaches B: one event,
        which wakes the controller and then this process, so the controller plans (and may
        replan the belt) before the next part is timed.  If the belt may stop before the
        part gets there (``stops``), the wait is a timeout that a stop or a restart
        interrupts, and the part is timed again."""
        env, get, hand_over, belt = self.env, self.loaded.get, self.at_bot.put_after, self.belt
        x_fed, length, stops = self.x_fed, self.length_in, self.stops
        while True:
            part, dropped = yield get()
            i = part.index
            # the clock: the drop, or the last hand-off if the part came while one was on its way
            now = dropped if dropped > self.due_s else self.due_s  # speed: docs/performance.md#input-clock
            target = x_fed[i] + length
            if stops is None or not belt.stopped:
                delay = belt.time_at(target) - now
                if delay < 0.0:
                    delay = 0.0
                if stops is None or stops.clear_until(now + delay):  # the arrival known now
                    part.at_bot_s = self.due_s = now + delay
                    yield hand_over(part, delay)  # the controller takes it (and replans) first
                    del x_fed[i]
                    continue
            while True:
                self.timing = True
                try:
                    if belt.stopped:
                        yield env.event()  # until the restart interrupts
                    delay = belt.time_at(target) - env.now
                    self.due_s = env.now + max(delay, 0.0)
                    if delay > 0.0:
                        yield env.timeout(delay)
                    break
                except simpy.Interrupt:
                    continue
                finally:
                    self.timing = False
            part.at_bot_s = self.due_s = env.now
            yield hand_over(part, 0.0)
            del x_fed[i]


class OutputConveyor:
    """Takes parts from the robot at TD and records their spacing (thesis §4.3 f).

    Spacing of a part = the output belt's travel between the previous part's touch-down and its own:
    the distance between the two on the belt.  Each part set down is handed on to ``delivered`` (the
    run's log).  The robot hands a part over due at its touch-down (``placed``), so this process
    wakes once per part, at TD.
    """

    def __init__(self, env: simpy.Environment, speed_in_s: float,
                 delivered: Callable[[Part], Any],
                 on_change: Callable[[float, float], Any] | None = None, stoppable: bool = False):
        self.env = env
        self.belt = Belt(speed_in_s, on_change, stoppable)  # stoppable: by a failure, a calendar
        self.placed: Mailbox = Mailbox(env)
        """Parts set down by the robot, each due at its touch-down, with that instant."""
        self.delivered = delivered
        self.last_td_x: float | None = None
        """Belt travel at the last touch-down (None before the first)."""
        self.last_td_s = math.nan
        """Instant of the last touch-down (read once ``last_td_x`` is set)."""
        self.process = env.process(self.run())

    def stop(self, now: float) -> None:
        """A failure stops the belt now (a part the robot sets down stays where it is put)."""
        self.belt.stop(now)

    def restart(self, now: float) -> None:
        """The belt runs again from now."""
        self.belt.restart(now)

    def run(self):  # noqa: ANN201 (SimPy generator)
        get, travel, delivered = self.placed.get, self.belt.travel, self.delivered
        while True:
            part, td = yield get()  # and the instant it was due, the clock's (:meth:`.Robot.run`)
            part.touchdown_s = td
            x = travel(td)
            last_x = self.last_td_x
            if last_x is not None:
                part.spacing_in = x - last_x
                part.delivery_interval_s = td - self.last_td_s
            self.last_td_x, self.last_td_s = x, td
            delivered(part)
