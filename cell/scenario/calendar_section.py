"""The ``calendar:`` section: the plant's working week, and the arithmetic of its time
(docs/usage.md, "A shift calendar"; docs/model.md, "Time off shift").

A calendar is a start date and time and a week that repeats: the working days, the shifts of
each working day (clock times ``"HH:MM"``; a shift whose end is before its start crosses
midnight and belongs to the day it starts on) and the breaks inside them.  Working time is the
shifts less the breaks.  Clock times are the plant's local time, with no daylight saving.

:class:`WeekPattern` is a set of intervals that repeats every week, placed on the run's clock
(seconds from ``calendar.start``); it measures working time (:meth:`WeekPattern.measure`) and
finds the instant a given amount of working time is reached (:meth:`WeekPattern.instant`),
the two maps that put arrivals on the calendar and time a repair in its crew's hours.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, field_validator

from cell.plumbing.errors import ScenarioError
from cell.scenario.fields import Section

DAYS = ("mon", "tue", "wed", "thu", "fri", "sat", "sun")
DAY_S = 86_400.0
WEEK_S = 7 * DAY_S
Day = Literal["mon", "tue", "wed", "thu", "fri", "sat", "sun"]
WEEKDAYS: tuple[Day, ...] = ("mon", "tue", "wed", "thu", "fri")
#: ``"HH:MM"`` from 00:00 to 24:00 (24:00 only as an end: the day's midnight).
Clock = str
Span = tuple[Clock, Clock]


class CalendarSettings(Section):
    """The plant's working week (docs/usage.md, "A shift calendar")."""

    start: str
    """When the run starts, an ISO date and time (``2027-01-04T06:00``, a Monday): the
    calendar's timestamps count from it."""
    days: list[Day] = Field(default_factory=lambda: list(WEEKDAYS))
    """The working days of the week (``mon`` … ``sun``)."""
    shifts: list[Span]
    """Each working day's shifts, ``["06:00", "14:00"]``; one ending before it starts crosses
    midnight (``["22:00", "06:00"]``).  They may not overlap."""
    breaks: list[Span] = Field(default_factory=list)
    """Breaks, each inside one shift, taken every working day: no work, no parts."""

    @field_validator("start", mode="before")
    @classmethod
    def _iso(cls, value: Any) -> Any:
        if isinstance(value, dt.datetime):  # YAML reads 2027-01-04 06:00:00 as a datetime
            return value.isoformat()
        if isinstance(value, str):
            try:
                when = dt.datetime.fromisoformat(value)
            except ValueError:
                raise ValueError("must be an ISO date and time, such as 2027-01-04T06:00") from None
            if when.tzinfo is not None:
                raise ValueError("give the plant's local time, without a time zone")
        return value

    @property
    def start_at(self) -> dt.datetime:
        return dt.datetime.fromisoformat(self.start)


def clock_s(text: object, file: object, key: str, end: bool = False) -> float:
    """Seconds after midnight of ``"HH:MM"`` (``"24:00"`` only as an end)."""
    ok = isinstance(text, str) and len(text) == 5 and text[2] == ":" and \
        text[:2].isdigit() and text[3:].isdigit()
    h, m = (int(text[:2]), int(text[3:])) if ok else (0, 0)  # type: ignore[index]
    if not ok or m > 59 or h > 24 or (h == 24 and (m or not end)):
        raise ScenarioError(file, key, text, "must be a clock time \"HH:MM\" (00:00 to 23:59)")
    return h * 3600.0 + m * 60.0


@dataclass(frozen=True)
class WeekPattern:
    """Intervals that repeat every week, on the run's clock: seconds from the calendar's start.

    ``starts``/``ends``: sorted, disjoint intervals within one week from Monday 00:00
    (``ends`` at most a week); ``phase_s``: where in that week the run starts."""

    starts: NDArray[np.float64]
    ends: NDArray[np.float64]
    phase_s: float

    @property
    def per_week_s(self) -> float:
        return float(np.sum(self.ends - self.starts))

    def _cum(self) -> NDArray[np.float64]:
        return np.concatenate(([0.0], np.cumsum(self.ends - self.starts)))

    def _from_monday(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        weeks = np.floor(x / WEEK_S)
        within = x - weeks * WEEK_S
        k = np.searchsorted(self.starts, within, side="right") - 1
        kk = np.maximum(k, 0)
        inside = np.clip(within - self.starts[kk], 0.0, self.ends[kk] - self.starts[kk])
        return weeks * self.per_week_s + np.where(k >= 0, self._cum()[kk] + inside, 0.0)

    def measure(self, t: Any) -> NDArray[np.float64]:
        """The time inside the pattern from the run's start to ``t`` s after it."""
        x = np.asarray(t, dtype=float) + self.phase_s
        return self._from_monday(x) - float(self._from_monday(np.array([self.phase_s]))[0])

    def instant(self, amount: Any, at_end: bool = False) -> NDArray[np.float64]:
        """The inverse of :meth:`measure`: when ``amount`` s of the pattern's time have passed
        since the run's start.  An amount reached at an interval's end is the next interval's
        start (a part due then comes when work resumes), or with ``at_end`` that end (a
        repair finished then is finished)."""
        cum, total = self._cum(), self.per_week_s
        y = np.asarray(amount, dtype=float) + float(self._from_monday(np.array([self.phase_s]))[0])
        weeks = np.floor(y / total)
        rest = y - weeks * total
        over = rest >= total  # rounding
        weeks, rest = np.where(over, weeks + 1, weeks), np.where(over, rest - total, rest)
        k = np.searchsorted(cum, rest, side="left" if at_end else "right") - 1
        k = np.clip(k, 0, self.starts.size - 1)
        return weeks * WEEK_S + self.starts[k] + (rest - cum[k]) - self.phase_s

    def inside(self, t: Any) -> Any:
        """Whether each instant ``t`` (s from the start) lies in the pattern."""
        within = np.mod(np.asarray(t, dtype=float) + self.phase_s, WEEK_S)
        k = np.searchsorted(self.starts, within, side="right") - 1
        return (k >= 0) & (within < self.ends[np.maximum(k, 0)])

    def spans(self, a: float, b: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The pattern's intervals within [a, b] on the run's clock, in time order."""
        first = np.floor((a + self.phase_s) / WEEK_S)
        last = np.floor((b + self.phase_s) / WEEK_S)
        weeks = np.arange(first, last + 1) * WEEK_S - self.phase_s
        s = (weeks[:, None] + self.starts[None, :]).ravel()
        e = (weeks[:, None] + self.ends[None, :]).ravel()
        s, e = np.clip(s, a, b), np.clip(e, a, b)
        keep = e > s
        return s[keep], e[keep]

    def gaps(self, a: float, b: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The time within [a, b] outside the pattern."""
        s, e = self.spans(a, b)
        gs, ge = np.concatenate(([a], e)), np.concatenate((s, [b]))
        keep = ge > gs
        return gs[keep], ge[keep]

    def next_change(self, t: float) -> float:
        """The first instant after ``t`` at which the pattern starts or ends."""
        s, e = self.spans(t, t + WEEK_S + 1.0)
        edges = np.concatenate((s, e))
        later = edges[edges > t]
        return float(later.min()) if later.size else float("inf")


def _weekly(days: Sequence[str], spans: Sequence[tuple[float, float]]
            ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Spans (start from the day's midnight, length) on each of ``days``, as sorted intervals
    in one week from Monday 00:00 (one crossing Sunday midnight split at the week's end)."""
    s: list[float] = []
    e: list[float] = []
    for day in sorted({DAYS.index(d) for d in days}):
        for a, length in spans:
            lo = (day * DAY_S + a) % WEEK_S
            hi = lo + length
            s.append(lo)
            e.append(min(hi, WEEK_S))
            if hi > WEEK_S:
                s.append(0.0)
                e.append(hi - WEEK_S)
    return _merged(np.array(s), np.array(e))


def _merged(s: NDArray[np.float64], e: NDArray[np.float64]
            ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    order = np.argsort(s, kind="stable")
    s, e = s[order], e[order]
    out_s: list[float] = []
    out_e: list[float] = []
    for a, b in zip(s.tolist(), e.tolist()):
        if out_e and a <= out_e[-1]:
            out_e[-1] = max(out_e[-1], b)
        elif b > a:
            out_s.append(a)
            out_e.append(b)
    return np.array(out_s), np.array(out_e)


def _minus(s: NDArray[np.float64], e: NDArray[np.float64], cut_s: NDArray[np.float64],
           cut_e: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Intervals less the ``cut`` intervals."""
    out_s: list[float] = []
    out_e: list[float] = []
    for a, b in zip(s.tolist(), e.tolist()):
        pieces = [(a, b)]
        for c, d in zip(cut_s.tolist(), cut_e.tolist()):
            pieces = [q for (x, y) in pieces for q in ((x, min(y, c)), (max(x, d), y)) if q[1] > q[0]]
        for x, y in pieces:
            out_s.append(x)
            out_e.append(y)
    return np.array(out_s), np.array(out_e)


def _spans(given: Sequence[Span], file: object, key: str) -> list[tuple[float, float]]:
    """(start, length) of each clock span; an end before its start crosses midnight."""
    out = []
    for i, (a, b) in enumerate(given):
        start = clock_s(a, file, f"{key}[{i}][0]")
        end = clock_s(b, file, f"{key}[{i}][1]", end=True)
        if start == end or (start > end and end == DAY_S) or start == DAY_S:
            raise ScenarioError(file, f"{key}[{i}]", list(given[i]),
                                "ends when it starts: give a span of working time (one ending "
                                "before its start, such as [\"22:00\", \"06:00\"], crosses midnight)")
        out.append((start, (end - start) % DAY_S or DAY_S))
    return out


def shift_spans(cal: CalendarSettings, file: object) -> list[tuple[float, float]]:
    """(start, length) of each shift, checked: no two overlap (on the clock, any day)."""
    shifts = _spans(cal.shifts, file, "calendar.shifts")
    for i, (a, n) in enumerate(shifts):
        for j in range(i):
            b, m = shifts[j]
            if (a - b) % DAY_S < m or (b - a) % DAY_S < n:
                raise ScenarioError(file, f"calendar.shifts[{i}]", list(cal.shifts[i]),
                                    f"overlaps calendar.shifts[{j}] {list(cal.shifts[j])}")
    return shifts


def working_week(cal: CalendarSettings, file: object = "<calendar>",
                 hours: Sequence[Span] | None = None, hours_key: str = "") -> WeekPattern:
    """The calendar's working time (its shifts less its breaks on its days), or with ``hours``
    (a crew's) those spans less the breaks on the same days; refused in one line: a bad clock
    time, overlapping shifts, a break outside every shift, no working time at all."""
    shifts = shift_spans(cal, file)
    breaks = _spans(cal.breaks, file, "calendar.breaks")
    for i, (a, n) in enumerate(breaks):
        if not any((a - s) % DAY_S + n <= length for s, length in shifts):
            raise ScenarioError(file, f"calendar.breaks[{i}]", list(cal.breaks[i]),
                                "lies outside every shift: a break is taken inside one")
    # A break is taken in the shift it lies in, on that shift's day: one after midnight in a
    # night shift falls on the next morning, whether or not that day is a working day.
    taken = [(s + (a - s) % DAY_S, n) for s, length in shifts for a, n in breaks
             if (a - s) % DAY_S + n <= length]
    own = shifts if hours is None else _spans(hours, file, hours_key)
    s, e = _minus(*_weekly(cal.days, own), *_weekly(cal.days, taken))
    start = cal.start_at
    phase = start.weekday() * DAY_S + start.hour * 3600.0 + start.minute * 60.0 + \
        start.second + start.microsecond * 1e-6
    if not s.size:
        key, value = (hours_key, [list(h) for h in hours]) if hours is not None else \
            ("calendar.days", list(cal.days)) if not cal.days else \
            ("calendar.shifts", []) if not cal.shifts else \
            ("calendar.breaks", [list(b) for b in cal.breaks])
        raise ScenarioError(file, key, value, "leaves no working time in the week")
    return WeekPattern(s, e, phase)


def timestamps(cal: CalendarSettings, seconds: Any) -> list[str]:
    """ISO timestamps (to the millisecond) of instants ``seconds`` from the calendar's start."""
    start = cal.start_at
    return ["" if x != x else (start + dt.timedelta(seconds=float(x))).isoformat(
        timespec="milliseconds") for x in np.asarray(seconds, dtype=float).tolist()]


def days_end_s(cal: CalendarSettings, n: int) -> float:
    """The end of the ``n``-th working day's last shift, in seconds from the start: days with
    a shift counted from the start's date (a night shift belongs to the day it starts on)."""
    start = cal.start_at
    into_day = start.hour * 3600.0 + start.minute * 60.0 + start.second + start.microsecond * 1e-6
    shifts = [(clock_s(a, "", ""), (clock_s(b, "", "", end=True) - clock_s(a, "", "")) % DAY_S
               or DAY_S) for a, b in cal.shifts]
    working = {DAYS.index(d) for d in cal.days}
    counted, i = 0, 0
    while True:
        if (start.weekday() + i) % 7 in working:
            ends = [i * DAY_S - into_day + a + length for a, length in shifts]
            if max(ends) > 0:
                counted += 1
                if counted == n:
                    return max(ends)
        i += 1


def describe(cal: CalendarSettings, file: object = "<calendar>") -> str:
    """One line for a run's heading: the working week, and what it means for the run."""
    week = working_week(cal, file)
    return (f"from {cal.start}, {week.per_week_s / 3600.0:g} working hours a week "
            f"({', '.join(cal.days)}); nothing comes and the cell stands off shift, and an "
            f"arrivals profile counts working hours")
