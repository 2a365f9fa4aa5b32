"""A run's result: its summary, and its part records and belt changes if they were kept
(:class:`SimResult`), with the log the belt changes are kept in as they become final
(:class:`BeltLog`).

Kept parts are held as tuples of plain values, belt changes as flat arrays; the record
objects are made when first asked for.
"""

from __future__ import annotations

import functools
import math
from array import array
from collections.abc import Callable
from operator import attrgetter
from typing import Any

import numpy as np

from cell.sim import oee, wear_clock
from cell.sim.failures import Downtime
from cell.sim.records import (
    OPTIONAL_PART_COLUMNS,
    PART_COLUMNS,
    BeltChange,
    PartRecord,
    RunSummary,
    StateSpan,
    Stop,
)

BeltSink = Callable[[BeltChange], Any]


def part_columns(cell: Any) -> list[str]:
    """parts.csv's columns for an assembled cell: every run's, then those that come with their
    sections: ``energy_j`` (``energy.arm: dynamics``), ``station`` (``stations:``),
    ``buffer_wait_s`` (a ``buffer:`` at any station), ``arrival_time`` (``calendar:``)."""
    from cell.sim.line import has_buffer

    s = cell.scenario
    arm = s.energy is not None and s.energy.arm == "dynamics"
    return PART_COLUMNS + ["energy_j"] * arm + ["station"] * (s.stations is not None) + \
        ["buffer_wait_s"] * has_buffer(cell) + ["arrival_time"] * (s.calendar is not None)


def stops_anything(scenario: Any) -> bool:
    """Whether the scenario can stop the cell, any station of its layout (``failures:``, or
    ``wear:`` on): failures.csv."""
    return any(s.failures is not None or s.wear.enabled
               for s in (scenario, *(own for _, own in scenario.line)))


def station_columns(scenario: Any) -> list[str]:
    """stations.csv's columns (docs/layout.md): ``down_fraction`` last when a station can stop."""
    from cell.sim.line import STATION_COLUMNS

    return [*STATION_COLUMNS, *["down_fraction"] * stops_anything(scenario)]


def named_columns(result: Any, columns: list[str]) -> list[str]:
    """states.csv's or failures.csv's columns: with a layout, ``station`` after the others."""
    return columns + ["station"] * (result.line is not None)


def writes_states(scenario: Any) -> bool:
    """Whether a run writes states.csv: with stops, ``energy:`` (its states) or a calendar."""
    return stops_anything(scenario) or scenario.energy is not None or scenario.calendar is not None
#: parts.csv's columns of a record, as a tuple.
part_row = attrgetter(*PART_COLUMNS)
_BELTS = ("input", "output")


class SimResult:
    """A run: its summary, and its part records and belt changes if they were kept.

    Kept parts are held as tuples of plain values (which the cyclic garbage collector
    stops tracking), belt changes as flat arrays; the record objects are made when
    first asked for.
    """
    wear: wear_clock.WearResult | None = None  # with wear.enabled: its measures and stops
    line: Any = None
    """The layout's stations and their logs (cell.sim.line.Line; None without one)."""
    station_rows: list[Any] | None = None
    """stations.csv's rows (with ``stations:`` or ``buffer:``; cell.sim.line.STATION_COLUMNS)."""

    def __init__(self, summary: RunSummary, rows: list[tuple[Any, ...]] | None = None,
                 belt_log: BeltLog | None = None):
        self.summary = summary
        self._rows = rows
        self._belt_log = belt_log
        self.downtime: Downtime | None = None
        """The run's failures (None without a ``failures:`` section)."""
        self.timelines: dict[str, list[tuple[str, float, float]]] = {}
        """Each piece of equipment's (state, from_s, to_s) over the run."""
        self.stop_rows: list[tuple[str, str, float, float, Any]] = []
        """Every failure and planned stop (wear's included), in order of start."""

    def state_spans(self) -> list[StateSpan]:
        """states.csv's rows; a layout's station by station, each naming its station."""
        if self.line is None:
            return oee.state_spans(self.timelines)
        return [span for name, lines in self.line.timelines
                for span in oee.state_spans(lines, name)]

    def stops(self) -> list[Stop]:
        """failures.csv's rows: every failure and planned stop, in order of start (a layout's
        every station's, each naming its station; at one instant, in station order)."""
        if self.line is None:
            return [Stop(*row) for row in self.stop_rows]
        names = [name for name, _, _ in self.line.cells]
        rows = [Stop(e, cause, a, b, part, name)
                for name, stops in zip(names, self.line.stopped)
                for e, cause, a, b, part in stops]
        return sorted(rows, key=attrgetter("from_s"))  # stable: station order kept

    @functools.cached_property
    def records(self) -> list[PartRecord] | None:
        """Every part's record, in part order (None if the run did not keep them)."""
        return None if self._rows is None else [PartRecord._make(row) for row in self._rows]

    @functools.cached_property
    def belt_changes(self) -> list[BeltChange]:
        """Every belt speed change, the input belt's first, each belt's in time order."""
        log = self._belt_log
        if log is None:
            return []
        changes = [BeltChange(_BELTS[b], t, v) for b, t, v in zip(log.belt, log.t, log.v)]
        changes.sort(key=lambda c: (c.belt != "input", c.from_s))
        return changes

    @property
    def parts(self) -> Any:
        """The part records as a pandas DataFrame (the columns of parts.csv)."""
        import pandas as pd

        if "records" in self.__dict__ and self.records is not None:
            rows: Any = [part_row(r) for r in self.records]
            return pd.DataFrame(rows, columns=PART_COLUMNS)
        rows = self._rows or []
        frame = pd.DataFrame(rows, columns=[*PART_COLUMNS, *OPTIONAL_PART_COLUMNS])
        n = len(PART_COLUMNS)  # an optional column is there when its section is (not None)
        return frame[PART_COLUMNS + [c for i, c in enumerate(OPTIONAL_PART_COLUMNS)
                                     if rows and rows[0][n + i] is not None]]

    def belt_histories(self) -> dict[str, np.ndarray]:
        """Each belt's speed changes as (m, 2) rows (from_s, speed_in_s), in time order: the
        flat arrays the run kept, with no object made per change (a long run has millions)."""
        log = self._belt_log
        if log is None:
            return {name: np.empty((0, 2)) for name in _BELTS}
        which, rows = np.frombuffer(log.belt, dtype=np.int8), np.column_stack(
            [np.frombuffer(log.t), np.frombuffer(log.v)]).reshape(-1, 2)
        out = {}
        for b, name in enumerate(_BELTS):
            own = rows[which == b]
            out[name] = own[np.argsort(own[:, 0], kind="stable")]
        return out

    @property
    def belts(self) -> dict[str, list[tuple[float, float]]]:
        """(instant, speed) of every speed change of the ``input`` and ``output`` belts."""
        out: dict[str, list[tuple[float, float]]] = {"input": [], "output": []}
        for c in self.belt_changes:
            out[c.belt].append((c.from_s, c.speed_in_s))
        return out


class BeltLog:
    """Belt speed changes as they become final: kept in flat arrays, and/or handed on."""

    def __init__(self, keep: bool, sink: BeltSink | None):
        self.belt, self.t, self.v = array("b"), array("d"), array("d")
        self.keep, self.sink = keep, sink

    def told(self, belt: int) -> Callable[[float, float], None] | None:
        """What a belt calls with (instant, speed) of each final change (None: nobody asks)."""
        if not self.keep and self.sink is None:
            return None
        mark, times, speeds, sink = self.belt.append, self.t.append, self.v.append, self.sink
        last = [math.nan]  # the belt's speed so far: a "change" to the same speed is none

        def keep(t: float, v: float) -> None:
            mark(belt)
            times(t)
            speeds(v)
        if sink is None:
            told = keep
        else:
            name = _BELTS[belt]

            def told(t: float, v: float) -> None:
                if self.keep:
                    keep(t, v)
                sink(BeltChange(name, t, v))

        def changed(t: float, v: float) -> None:
            if v != last[0]:
                last[0] = v
                told(t, v)
        return changed

