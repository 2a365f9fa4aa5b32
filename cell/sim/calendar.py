"""The cell on a shift calendar (docs/model.md, "Time off shift"): a SimPy process, the
shifts, that stands the cell when working time ends and starts it again when it resumes.

Off shift the feeder brings nothing (the arrivals are laid out in working time:
:func:`cell.sim.horizon.run_arrivals`) and the cell stands where it is: both belts stop with
their parts on them, the robot is held in the leg it is in with the part it holds, nothing is
lost.  When work resumes everything carries on from where it stood.  A failure clock counts
what its ``clock`` says: ``calendar`` all the time the equipment is up, ``working`` the
working time it is up (:class:`WorkingTime`), ``operating`` its motion (a belt's running).
A repair progresses only in its crew's hours (``failures.repair.hours``, by default the
working time): a failure outside them waits.  The stand is the failures' machinery (the
belts' stop and restart, the robot held as by a stop) with no loss; the cell's
:class:`~cell.sim.failures.Downtime` carries it, with or without a ``failures:`` section.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import simpy

from cell.scenario.calendar_section import WEEK_S, WeekPattern, working_week
from cell.scenario.failure_sections import FailureSettings
from cell.sim.failure_clock import MOVING_NOT, Distributed

#: A calendar without a ``failures:`` section: the cell's downtime with nothing that fails.
NO_FAILURES = FailureSettings()


class WorkingTime(Distributed):
    """A time to failure counted in the calendar's working time while the equipment is up:
    the ``calendar`` clock's rates, nothing while the cell stands off shift."""

    def __init__(self, draw: Callable[[], float], standing: Callable[[], bool]):
        super().__init__(draw, "calendar")
        self.standing = standing
        self.leg = MOVING_NOT
        """What the equipment was last said to do (told again when the shift changes)."""

    def rates(self, leg: int) -> Sequence[float]:
        self.leg = leg
        return (0.0,) if self.standing() else super().rates(leg)


class Shifts:
    """Stands the cell when working time ends, starts it when work resumes (SimPy process);
    counts repairs in the crews' hours (:meth:`repair_s`)."""

    def __init__(self, env: simpy.Environment, week: WeekPattern, crews: WeekPattern,
                 downtime: Any):
        self.env, self.week, self.crews, self.downtime = env, week, crews, downtime
        self.off: simpy.Event = env.event()
        """Succeeds when the cell next stands (a planned stop waiting to be done off shift)."""
        for e in downtime.equipment:
            if getattr(downtime.spec, e.name).clock == "working" and \
                    type(e.exposure) is Distributed:  # (a wear model counts motion)
                e.exposure = WorkingTime(e.exposure.draw, lambda: downtime.standing)

    def start(self) -> None:
        """Start the process (the failure clocks started)."""
        self.env.process(self.run())

    def run(self):  # noqa: ANN201 (SimPy generator)
        env, week, d = self.env, self.week, self.downtime
        while True:
            now = env.now
            working = bool(week.inside(now))
            change = week.next_change(now)
            if working:
                d.off_at = change
                if d.standing:
                    self.resume()
            elif not d.standing:
                self.stand()
            yield env.timeout(change - now)

    def stand(self) -> None:
        """Working time ends: the belts stop, the robot is held, the clocks told."""
        d, now = self.downtime, self.env.now
        d.standing, d.off_at = True, now
        for conveyor in d.conveyors:
            if not conveyor.belt.stopped:
                conveyor.stop(now)
        self._tell_clocks()
        d.robot.touch()
        off, self.off = self.off, self.env.event()
        off.succeed()

    def resume(self) -> None:
        """Working time resumes: the belts not down run again, the robot carries on."""
        d, now = self.downtime, self.env.now
        d.standing = False
        down = {e.name for e in d.equipment if e.down}
        for name, conveyor in zip(("input_belt", "output_belt"), d.conveyors):
            if conveyor.belt.stopped and name not in down:
                conveyor.restart(now)
        self._tell_clocks()
        d.robot.touch()

    def _tell_clocks(self) -> None:
        """Every failure clock told what its equipment does now: a belt or the sensor runs in
        working time only; the robot does what it did (a working clock's rate changes)."""
        d = self.downtime
        for e in d.equipment:
            if e.clock is None:
                continue
            if e.name != "robot":
                e.clock.follow(MOVING_NOT if d.standing else 0)
            elif isinstance(e.exposure, WorkingTime):
                e.clock.follow(e.exposure.leg)

    def off_for(self, duration_s: float):  # noqa: ANN201 (SimPy generator)
        """Until the cell stands for a time off shift at least ``duration_s`` long (or the
        week's longest, if none is that long)."""
        gaps_s, gaps_e = self.week.gaps(0.0, 2 * WEEK_S)  # each of the week's gaps whole
        longest = float(np.max(gaps_e - gaps_s))
        need = min(duration_s, longest) - 1e-6
        while not (self.downtime.standing and
                   self.week.next_change(self.env.now) - self.env.now >= need):
            yield self.off

    def repair_s(self, work_s: float) -> float:
        """How long from now a repair of ``work_s`` seconds of crew time takes."""
        now = self.env.now
        done = float(self.crews.instant(float(self.crews.measure(now)) + work_s, at_end=True))
        return max(done - now, 0.0)


def keep(env: simpy.Environment, s: Any, downtime: Any) -> Shifts | None:
    """The shifts of a scenario with a calendar (None without one), handed to the cell's
    downtime, which starts them with its clocks (after the equipment is attached)."""
    if s.calendar is None or downtime is None:
        return None
    week = working_week(s.calendar, s.source)
    f = s.failures
    hours = None if f is None or f.repair is None else f.repair.hours
    crews = week if hours is None else working_week(s.calendar, s.source, hours,
                                                     "failures.repair.hours")
    shifts = Shifts(env, week, crews, downtime)
    downtime.shifts = shifts
    return shifts


def off_spans(s: Any, end_s: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The run's time off shift within [0, end_s] (None without a calendar)."""
    if s.calendar is None:
        return None
    return working_week(s.calendar, s.source).gaps(0.0, end_s)




class Dated:
    """A row with some of its instants as calendar timestamps (``times``: parts.csv's
    ``arrival_time``, states.csv's and failures.csv's ``from_time`` and ``to_time``), every
    other column the record's."""

    __slots__ = ("record", "times")

    def __init__(self, record: Any, **times: str):
        self.record, self.times = record, times

    def __getattr__(self, name: str) -> Any:
        times = self.times
        return times[name] if name in times else getattr(self.record, name)


def clock(s: Any) -> Callable[[float], str]:
    """Seconds from the run's start -> the calendar's ISO timestamp (to the millisecond)."""
    import datetime as dt

    start = s.calendar.start_at
    return lambda seconds: (start + dt.timedelta(seconds=seconds)).isoformat(timespec="milliseconds")


def stamped(s: Any, sink: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """``sink`` told each record with its ``arrival_time`` (an ISO timestamp) under a
    calendar; ``sink`` itself without one."""
    if s.calendar is None:
        return sink
    at = clock(s)
    return lambda record: sink(Dated(record, arrival_time=at(record.arrival_s)))


def dated(s: Any, rows: Any) -> tuple[list[str], Any]:
    """The extra columns and the rows of states.csv or failures.csv: under a calendar each
    row's ``from_s`` and ``to_s`` also as ISO timestamps; without one, no column and the rows."""
    if s.calendar is None:
        return [], rows
    at = clock(s)
    return ["from_time", "to_time"], (Dated(r, from_time=at(r.from_s), to_time=at(r.to_s))
                                      for r in rows)
