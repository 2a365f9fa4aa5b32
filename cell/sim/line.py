"""A line of stations (``stations:``, ``buffer:``; docs/layout.md, docs/architecture.md
"Stations"): each station another :class:`~cell.sim.station.Station`, its own log of what it
did with the parts (:class:`StationLog`), and one new process, the transfer that carries the
parts a station lets ride past its F on to the station downstream (:class:`Transfer`).

A station's parts go on from it by its placement: those it lets go (busy, its buffer full, its
robot down) to a ``downstream`` station after it on the input line, those it sets down to the
``series`` station its output belt feeds.  A part nobody after it takes is done, for the line:
the run's log (:class:`~cell.sim.simulation.RunLog`) makes its row.  Each station after the
first draws its failures and its sensor from random streams of its own (children
``STATION_STREAM + i`` of the run's root seed), so the first station's are those of the cell
alone.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from functools import cached_property
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
import simpy

from cell.scenario.arrivals import root_seed
from cell.scenario.layout_sections import FIRST_STATION
from cell.sim import calendar, oee, state_energy, wear_clock
from cell.sim.failures import Downtime
from cell.sim.feeder import Feeder
from cell.sim.mailbox import Mailbox
from cell.sim.records import BUFFER_FULL, LOST_DOWNTIME, NAN, SCRAPPED, Part
from cell.sim.station import Station

if TYPE_CHECKING:
    from cell.sim.assembly import AssembledCell

#: The first of the stations' child streams of the run's root seed (station i: this + i).
STATION_STREAM = 100
#: The first station's name in stations.csv and parts.csv (the scenario's own cell).
FIRST = FIRST_STATION


class StationRow(NamedTuple):
    """A row of stations.csv: what one station did over the whole run (docs/layout.md)."""

    station: str
    """``first`` (the scenario's own cell), or the station's name."""
    parts_in: int
    """Parts that came to it (dropped on its input window)."""
    parts_delivered: int
    """Parts it set down on its output belt."""
    parts_lost: int
    """Parts it did not take: ``lost_busy`` + ``lost_full`` + ``lost_down`` (a station
    downstream may still take them)."""
    lost_busy: int
    """Let go: they reached B while the robot was busy."""
    lost_full: int
    """Rode on past its full buffer (``when_full: ride_off``)."""
    lost_down: int
    """Lost to its downtime (rode off while its robot was stopped, or scrapped from the hand)."""
    busy_fraction: float
    """Share of the run its robot was in motion."""
    starved_fraction: float
    """Share its robot was up and still with no part to take."""
    blocked_fraction: float
    """Share its robot was up and still while its output belt stood."""
    buffer_mean: float
    """Mean number of parts waiting in its buffer (0: none)."""
    buffer_max: int
    """The most parts that waited in it at once."""
    down_fraction: float = math.nan
    """Share its robot was down (failed or worn, a crew's wait included); a column only when
    a station can stop (``failures:`` at any station, or ``wear:``)."""


#: stations.csv's columns, in order (then ``down_fraction``: sim_result.station_columns).
STATION_COLUMNS = StationRow._fields[:-1]
#: The per-part values a station logs of its own visits (the first's: :meth:`Line.first_column`).
STATION_VALUES = ("arrival", "at_bot", "cycle", "picked")


#: What a station's log keeps of each part done there: when it came, its B (its cycle's
#: start), its cycle (NaN: not picked), whether it was picked, its index, and when it left
#: (set down, or rode on from B).
COLUMNS = ("arrival", "at_bot", "cycle", "picked", "part", "left")
_PACK = struct.Struct(f"={len(COLUMNS)}d").pack
#: What a station's log keeps besides, only when asked (``cell animate``), in the same order:
#: the part's lift-off and set-down there, its four regimes' times (NaN: not picked), and
#: its ``buffer_wait_s`` so far (its waits at this station's buffer and those before).
VISIT_COLUMNS = ("pick", "touchdown", "r1", "r2", "r3", "r4", "waited")


def station_seed(seed: Any, i: int) -> Any:
    """Station i's root seed: the run's for the first, a child stream's for the others."""
    if i == 0:
        return seed
    root = root_seed(seed)
    return np.random.SeedSequence(root.entropy, spawn_key=(*root.spawn_key, STATION_STREAM + i),
                                  pool_size=root.pool_size)


class StationLog:
    """What one station did with the parts that came to it, and where each goes next.

    It is the station's log for its controller, robot and failures (a part's limits noted, a
    part lost), and its output conveyor's ``delivered``.  A part done here goes on to the
    station that takes it (``on_lost``, ``on_delivered``), or, if none does, to the run's log
    with the limits it hit here."""

    def __init__(self, name: str, line: Any, keep_visits: bool = False):
        self.name, self.line = name, line
        self.visits: list[tuple[float, ...]] | None = [] if keep_visits else None
        """Per part done here, :data:`VISIT_COLUMNS` (None: not kept)."""
        self.flags: dict[int, int] = {}
        self.on_lost: Callable[[Part], Any] | None = None
        """The transfer to the station downstream on the input line (None: lost for good)."""
        self.on_delivered: Callable[[Part], Any] | None = None
        """The series station this one's output belt feeds (None: delivered by the line)."""
        self.parts_in = self.delivered = self.lost_busy = self.lost_full = self.lost_down = 0
        self.came: dict[int, float] = {}
        """When each part still here came to the station (dropped on its input window)."""
        self.per_part = bytearray()
        """Per part done here, :data:`COLUMNS` packed as doubles (one call a part, as the run's
        log keeps its own)."""

    def arrive(self, part: Part, now: float) -> None:
        """A part is dropped on this station's input window now."""
        self.parts_in += 1
        self.came[part.index] = now

    def flag(self, part: Part, limits: int) -> None:
        i = part.index
        self.flags[i] = self.flags.get(i, 0) | limits

    def _note(self, part: Part, picked: bool) -> int:
        i, at_bot, td = part.index, part.at_bot_s, part.touchdown_s
        if self.visits is not None:
            plan = part.plan if picked else None
            self.visits.append((part.pick_s, part.touchdown_s) + (
                (NAN,) * 4 if plan is None else (plan.r1_pre + plan.r1_post, plan.r2,
                                                 plan.r3_pre + plan.r3_post, plan.r4))
                + (part.buffer_wait_s,))
        # speed: docs/performance.md#station-log
        self.per_part.extend(_PACK(self.came.pop(i, part.arrival_s), at_bot,
                                   part.plan.cycle if picked else math.nan, picked, i,
                                   td if td == td else at_bot))
        return self.flags.pop(i, 0)

    def missed(self, part: Part) -> None:
        """The part is lost here: let go (the robot busy), past a full buffer, to downtime
        (or scrapped from the hand)."""
        scrapped = self.flags.get(part.index, 0) & SCRAPPED
        flags = self._note(part, bool(scrapped))
        if flags & BUFFER_FULL:
            self.lost_full += 1
        elif flags & (LOST_DOWNTIME | SCRAPPED):
            self.lost_down += 1
        else:
            self.lost_busy += 1
        if self.on_lost is not None and not scrapped:
            self.on_lost(part)
            return
        self._done(part, flags, self.line.missed)

    def delivered_part(self, part: Part) -> None:
        """The part is set down on this station's output belt."""
        flags = self._note(part, True)
        self.delivered += 1
        if self.on_delivered is not None:
            self.on_delivered(part)
            return
        self._done(part, flags, self.line.delivered_part)

    def _done(self, part: Part, flags: int, done: Callable[[Part], Any]) -> None:
        part.station = self.name
        if flags:
            self.line.flag(part, flags)
        done(part)

    def visit_table(self) -> dict[str, np.ndarray]:
        """Every part done here, in the order it came: :data:`COLUMNS` and, if kept,
        :data:`VISIT_COLUMNS`, each an array."""
        table = np.frombuffer(self.per_part, dtype=np.float64).reshape(-1, len(COLUMNS))
        out = {name: table[:, j] for j, name in enumerate(COLUMNS)}
        if self.visits is not None:
            more = np.array(self.visits, dtype=np.float64).reshape(-1, len(VISIT_COLUMNS))
            out.update({name: more[:, j] for j, name in enumerate(VISIT_COLUMNS)})
        order = np.argsort(out["arrival"], kind="stable")
        return {name: values[order] for name, values in out.items()}

    def column(self, name: str) -> np.ndarray:
        """One of :data:`COLUMNS` in the order the parts began their cycles here."""
        table = np.frombuffer(self.per_part, dtype=np.float64).reshape(-1, len(COLUMNS))
        order = np.argsort(table[:, 1], kind="stable")
        return table[order, COLUMNS.index(name)]


class Transfer:
    """Carries the parts a station lets ride past its F on to the station ``window_in`` past
    it on the input line (SimPy process): each dropped on that station's input window the
    instant the belt has carried it to F, reckoned on the belt's plan when it rides off."""

    def __init__(self, env: simpy.Environment, upstream: Station, downstream: Station,
                 log: StationLog):
        self.env, self.upstream, self.downstream, self.log = env, upstream, downstream, log
        k = upstream.cell.k
        self.window_in = k.timing.r1_length_in
        """B → F on the upstream station's belt (in)."""
        self.v_nom = k.v_nom
        self.box: Mailbox = Mailbox(env)
        self.process = env.process(self.run())

    def take(self, part: Part) -> None:
        """A part rides on past the upstream station's B now."""
        belt, now = self.upstream.input.belt, self.env.now
        past = belt.travel(now) - belt.travel(min(part.at_bot_s, now))  # how far past B
        left = max(self.window_in - past, 0.0)
        v = belt.speed(now)
        at_f = now + left / self.v_nom if belt.stopped or not v > 0 else \
            belt.time_at(belt.travel(now) + left)
        self.box.put((part, at_f))

    def run(self):  # noqa: ANN201 (SimPy generator)
        env, get, conveyor, log = self.env, self.box.get, self.downstream.input, self.log
        while True:
            part, at_f = yield get()
            if at_f > env.now:
                yield env.timeout(at_f - env.now)
            now = env.now
            log.arrive(part, now)
            conveyor.drop(part, conveyor.belt.travel(now), now)


def series_feed(env: simpy.Environment, downstream: Station, log: StationLog
                ) -> Callable[[Part], None]:
    """What a station's output belt hands each part set down to, when it feeds a series
    station: the part begins its visit there, dropped on that station's input window at its
    touch-down (the window starts at the touch-down point: ``transfer_in`` to B)."""
    conveyor = downstream.input

    def feed(part: Part) -> None:
        now = env.now
        part.begin_visit()
        log.arrive(part, now)
        conveyor.drop(part, conveyor.belt.travel(now), now)
    return feed


class Line:
    """The stations of a layout, built and wired; the first fed by the feeder."""

    def __init__(self, env: simpy.Environment, cell: AssembledCell, seed: Any, log: Any,
                 told: Callable[[int], Any], downtime: Downtime | None,
                 keep: Callable[[], Any] | None = None):
        self.env = env
        self.cells: list[tuple[str, str, AssembledCell]] = [(FIRST, "first", cell)] + [
            (st.name, st.placement, own) for st, own in cell.line]
        self.logs = [StationLog(name, log, keep is not None) for name, _, _ in self.cells]
        self.belt_logs: list[Any] = [
            keep() if keep is not None and i else None for i in range(len(self.cells))]
        """The belts of each station after the first (a :class:`~cell.sim.sim_result.BeltLog`
        each), kept only when asked (``keep`` makes one: the animation's; the first station's
        are the run's belts.csv)."""
        self.downtimes: list[Downtime | None] = [downtime]
        self.stopped: list[list[tuple[str, str, float, float, Any]]] = []
        """Each station's stops (failures.csv's rows), taken when the run closes (:meth:`close`)."""
        self.rows: list[StationRow] = []  # stations.csv's, taken at close (station_rows)
        self.end_s = math.nan  # when it closed
        self.stations: list[Station] = []
        none = _no_belts
        for i, (_, _, own) in enumerate(self.cells):
            seed_i = station_seed(seed, i)
            if i:  # its own failures, and a calendar's stands (with or without failures)
                f, cal = own.scenario.failures, own.scenario.calendar
                dt = None if f is None and cal is None else \
                    Downtime(env, f or calendar.NO_FAILURES, seed_i)
                wear_clock.count_on(dt, own, seed_i)
                self.downtimes.append(dt)
            belts = self.belt_logs[i]
            self.stations.append(Station(env, own, seed_i, self.logs[i].delivered_part,
                                         told if i == 0 else none if belts is None else belts.told,
                                         self.downtimes[i]))
        self.transfers: list[Transfer] = []
        head = 0  # the last station before that is not downstream: a series station's feeder
        for i, (_, placement, _) in enumerate(self.cells[1:], start=1):
            if placement == "downstream":
                t = Transfer(env, self.stations[i - 1], self.stations[i], self.logs[i])
                self.transfers.append(t)
                self.logs[i - 1].on_lost = t.take
            else:
                self.logs[head].on_delivered = series_feed(env, self.stations[i], self.logs[i])
                head = i

    @property
    def first(self) -> Station:
        return self.stations[0]

    def control(self, fed_s: list[float], n_parts: int) -> None:
        """Start every station's controller (the first's look-ahead reads ``fed_s``) and
        their failure clocks, a calendar's shifts with them (the first's: the run's)."""
        for i, station in enumerate(self.stations):
            station.control(fed_s if i == 0 else None, n_parts, self.logs[i])
            dt = self.downtimes[i]
            if i and dt is not None:
                calendar.keep(self.env, self.cells[i][2].scenario, dt)
                dt.start()

    def close(self, end_s: float) -> None:
        """The run is over: each station closed; its stops and stations.csv's rows taken once."""
        for station in self.stations:
            station.close(end_s)
        self.stopped = [wear_clock.station_stops(dt, None if st.wear is None else st.wear.log, end_s)
                        for dt, st in zip(self.downtimes, self.stations)]
        self.end_s, self.rows = end_s, self.station_rows(end_s)

    @cached_property
    def timelines(self) -> list[tuple[str, state_energy.Timelines]]:
        """Each station's name and its equipment's states over the run (states.csv; once, after
        :meth:`close`); with ``energy:``, its sensor's as :func:`state_energy.timelines` adds."""
        out, end_s = [], self.end_s
        for (name, _, own), log, dt, stops in zip(self.cells, self.logs, self.downtimes,
                                                  self.stopped):
            lines = oee.timelines(log.column, dt, end_s, stops, calendar.off_spans(own.scenario, end_s))
            if own.scenario.energy is not None:
                lines = state_energy.timelines(own.scenario, lines, log.column, dt, end_s, stops)
            out.append((name, lines))
        return out

    def first_column(self, column: Callable[[str], np.ndarray]) -> Callable[[str], np.ndarray]:
        """The run log's ``column`` with :data:`STATION_VALUES` the first station's own: the
        summary's time shares and OEE's times then describe the first station's robot (a part
        another station took has there its B and cycle), as states.csv's first rows do."""
        own = self.logs[0].column
        return lambda name: own(name) if name in STATION_VALUES else column(name)

    def station_rows(self, end_s: float) -> list[StationRow]:
        """stations.csv's rows (:data:`STATION_COLUMNS`, ``down_fraction``), over the whole run."""
        out = []
        for (name, _, own), log, station, dt, stops in zip(self.cells, self.logs, self.stations,
                                                           self.downtimes, self.stopped):
            off = calendar.off_spans(own.scenario, end_s)
            sec = oee.unit_seconds(log.column, dt, end_s, stops, () if off is None else (off,))
            share = (lambda x: x / end_s) if end_s > 0 else (lambda x: math.nan)
            b = station.buffer
            out.append(StationRow(name, log.parts_in, log.delivered,
                        log.lost_busy + log.lost_full + log.lost_down, log.lost_busy,
                        log.lost_full, log.lost_down, share(sec["busy"]),
                        share(sec["starved"]), share(sec["blocked"]),
                        b.occupancy_mean(end_s) if b is not None else 0.0,
                        b.most if b is not None else 0, share(sec["down"])))
        return out

    def measure(self, summary: Any, log: Any, end_s: float) -> None:
        """The line's throughput and work in process, over the whole run, into the summary
        (``line_throughput_per_h``, ``line_wip_mean``; docs/layout.md "Measures").

        A part is in the line from its drop on the input belt until it leaves it: set down by a
        station nothing is fed from (its touch-down), or lost for good (the instant it passed the
        B of the last station it came to); a part still in the line at the run's end counts until
        then.  The work in process is the time-average of that count, integrated step by step over
        the instants parts come and leave."""
        arrival, td = log.column("arrival"), log.column("touchdown")
        came = np.isfinite(arrival)
        left = np.where(np.isfinite(td), td, log.column("at_bot"))[came]
        left = np.where(np.isfinite(left), np.minimum(left, end_s), end_s)
        times = np.concatenate((arrival[came], left))
        steps = np.concatenate((np.ones(left.size), -np.ones(left.size)))
        order = np.argsort(times, kind="stable")
        times, count = times[order], np.cumsum(steps[order])  # parts in the line from each instant
        area = float(np.sum(count[:-1] * np.diff(times))) if times.size else 0.0
        done = int(np.count_nonzero(np.isfinite(td)))
        summary.line_wip_mean = area / end_s if end_s > 0 else math.nan
        summary.line_throughput_per_h = done / (end_s / 3600.0) if end_s > 0 else math.nan


def _no_belts(belt: int) -> None:
    """A station after the first keeps no belt history (belts.csv is the first's)."""


def build(env: simpy.Environment, cell: AssembledCell, seed: Any, log: Any, told: Any,
          downtime: Downtime | None, t_list: list[float], n: int,
          keep: Callable[[], Any] | None = None) -> tuple[Line | None, Station, Feeder]:
    """The station fed by the feeder, and with ``buffer:`` or ``stations:`` the line it is the
    first of (None without); ``keep``: each station's visits and belts kept (:class:`Line`)."""
    if not cell.scenario.has_layout:
        station = Station(env, cell, seed, log.delivered_part, told, downtime)
        feeder = Feeder(env, t_list, station.input, n, cell.k.part_size, log.flag)
        station.control(feeder.fed_s, n, log)
        return None, station, feeder
    line = Line(env, cell, seed, log, told, downtime, keep)
    feeder = Feeder(env, t_list, line.first.input, n, cell.k.part_size, log.flag)
    line.control(feeder.fed_s, n)
    line.logs[0].parts_in = n
    return line, line.first, feeder


def has_buffer(cell: AssembledCell) -> bool:
    """Whether any station of the layout has a ``buffer:`` (parts.csv's ``buffer_wait_s``)."""
    return any(c.scenario.buffer is not None for c in (cell, *(own for _, own in cell.line)))
