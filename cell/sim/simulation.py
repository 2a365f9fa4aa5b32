"""One run of the cell in simulated time (thesis §6).

Five SimPy processes talk through :class:`~cell.sim.mailbox.Mailbox` hand-offs: the
feeder drops parts on the input conveyor; the conveyor hands each to the
controller due at the instant it reaches B; the controller asks the scenario's
policy for the part's cycle, sets the belts and sends the robot an order; the
robot hands the part to the output conveyor due at its touch-down, and the
conveyor measures its spacing.  A part picked up costs about four SimPy events
(its drop, its arrival at B, the order, the set-down), one fallen off at F two.
Each part's :class:`~cell.sim.records.Part` is filled in as these things happen,
each slot by its owner; when a part is done (set down, or fallen off at F) the run's
log completes its accounting, makes its :class:`~cell.sim.records.PartRecord` row and
passes it on, in part order, to whoever asked for rows (a CSV writer, a list),
keeping only a few numbers per part for the summary.

Nothing per part outlives its part unless the run keeps the rows, and those are
kept as tuples of plain values, which Python's cyclic garbage collector stops
tracking: its full collections then cost the same at any run length, so the
cost per part does not grow with the run.

:func:`simulate` is what ``cell run`` and every sweep replication call.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from typing import Any

import numpy as np
import simpy

from cell.scenario.schema import Scenario
from cell.sim import accounting, calendar, oee, run_cost, state_energy, wear_clock
from cell.sim.assembly import AssembledCell, assemble
from cell.sim.bound import parts_bound
from cell.sim.failures import Downtime
from cell.sim.horizon import run_arrivals, run_until_done
from cell.sim.line import build, has_buffer
from cell.sim.policies.base import Accounting
from cell.sim.records import (
    LIMIT_BIT,
    LIMIT_COUNTS,
    LIMIT_NAMES,
    NAN,
    RODE_OFF,
    SPACING_OFF,
    Part,
    PartRecord,
    RunSummary,
    limit_names,
)
from cell.sim.sim_result import BeltLog, BeltSink, SimResult

__all__ = ["PER_PART", "BeltLog", "BeltSink", "PartSink", "Run", "RunLog", "SimResult", "simulate"]

PartSink = Callable[[PartRecord], Any]
#: What the run's log keeps of each part for the summary: seven floats, then the limits' bits
#: and the part's index as 32-bit unsigned integers (64 bytes a part, as before failures came
#: in); ``picked``, ``interval`` and ``feed_delay`` are derived (:meth:`RunLog.column`).  ``make
#: bench``'s ``peak_mb_1m_parts``: twelve floats a part (96 bytes) made it 325 MB, nine and two
#: integers (80 bytes) 313 MB.
PER_PART = ("touchdown", "r4", "output_speed", "spacing", "arrival", "at_bot", "cycle", "limits",
            "part")
_PER_PART_DTYPE = np.dtype([(name, "=u4" if name in ("limits", "part") else "=f8")
                            for name in PER_PART])
_PER_PART_STRUCT = struct.Struct("=7d2I")
_PACK_PER_PART = _PER_PART_STRUCT.pack


class RunLog:
    """Completes each part's record and hands the records on in part order.

    Parts finish out of order (a part can fall off at F while the one before it
    is still in the hand), so a finished part waits here until those before it
    are done; at most a few do.  What the summary needs is kept per part in flat
    arrays (a few dozen bytes a part), so a warm-up can be cut off at the end;
    no per-part object outlives its part unless the run keeps the rows.
    """

    def __init__(self, t: list[float], acct: Accounting, sink: PartSink | None,
                 spacing_in: float, tol_in: float, rows: list[tuple[Any, ...]] | None = None,
                 lengths: tuple[float, float, float, float] = (NAN, NAN, NAN, NAN),
                 finished: simpy.Event | None = None, n_parts: int = 0,
                 energy_of: Callable[[Any], float] | None = None,
                 layout: tuple[bool, bool] = (False, False)):
        self.t = t
        self.layout = layout
        """Whether parts.csv's ``station`` and ``buffer_wait_s`` columns are made (``stations:``,
        a ``buffer:`` anywhere)."""
        self.energy_of = energy_of
        """A picked part's plan -> the arm's motion energy of its transfer (J), or None."""
        """T_1 … T_{n+1}: the last is only part n's "next arrival"."""
        self.acct, self.sink = acct, sink
        """Told of every completed record, in part order (None: nobody asks)."""
        self.spacing_in, self.tol_in = spacing_in, tol_in
        self.rows = rows
        """The kept rows (parts.csv's columns), if the run keeps them."""
        self.lengths = lengths
        """The four regimes' lengths (in): a row's average tip velocities."""
        self.waiting: dict[int, Part] = {}
        """Parts done but not yet handed on (a part before them is not done)."""
        self.flags: dict[int, int] = {}
        """Limit bits of parts not yet handed on, by index."""
        self.per_part = bytearray()
        """What the summary needs of each part, :data:`PER_PART` values a part in that order,
        as packed doubles (``struct``'s pack is a third of ``array.extend``'s cost a part)."""
        self.finished, self.n_parts = finished, n_parts
        """Succeeded once all ``n_parts`` parts are handed on (None: nobody waits for that)."""
        self.missed = self.delivered_part = self._logger()
        """A part fell off at F / was set down: see :meth:`_logger`."""

    def flag(self, part: Part, limits: int) -> None:
        i = part.index
        self.flags[i] = self.flags.get(i, 0) | limits

    def _logger(self) -> Callable[[Part], None]:
        """``done(part)``: a part is done; it is completed and handed on now if every part
        before it is, else kept till then; its row made only if someone keeps or streams the
        rows (speed: docs/performance.md#run-log)."""
        t, acct_part, flags_of = self.t, self.acct.part, self.flags.pop
        spacing_in, tol = self.spacing_in, self.tol_in + 1e-9
        note, pack = self.per_part.extend, _PACK_PER_PART
        row_of = self._row if self.rows is not None or self.sink is not None or \
            self.energy_of is not None else None  # the arm's energy: summed row by row
        names_of = LIMIT_NAMES.get  # limit_names' cache, read first
        waiting, finished, last = self.waiting, self.finished, self.n_parts
        following = 0  # the index of the part to hand on next

        def done(p: Part) -> None:
            nonlocal following
            i = p.index
            if i != following:
                waiting[i] = p
                return
            while True:  # complete p (part i) and hand it on, then any waiting after it
                flags = flags_of(i, 0)
                sp = p.spacing_in
                off = sp - spacing_in  # NaN (none yet): neither test holds
                if off > tol or off < -tol:  # NaN (none yet): not off
                    flags |= SPACING_OFF
                picked = not flags & RODE_OFF
                plan = p.plan
                acct_part(plan, picked, t[i])
                if plan is None:
                    note(pack(p.touchdown_s, NAN, NAN, sp, p.arrival_s, p.at_bot_s, NAN, flags, i))
                else:
                    note(pack(p.touchdown_s, plan.r4, plan.output_to_g, sp, p.arrival_s,
                              p.at_bot_s, plan.cycle, flags, i))
                if row_of is not None:
                    row_of(p, flags, picked,
                           (names_of(flags) or limit_names(flags)) if flags else "")
                i += 1
                if not waiting or i not in waiting:
                    following = i
                    if i == last and finished is not None:
                        finished.succeed()
                    return
                p = waiting.pop(i)

        def skip_to(i: int) -> None:  # the parts before i will never be done (:meth:`flush`)
            nonlocal following
            following = i
        self._skip_to = skip_to
        return done

    def _row(self, p: Part, flags: int, picked: bool, limits: str) -> None:
        """The part's row of parts.csv, made from its :class:`Part`, its limit bits and the
        accounting's last values: every derived column derived here, once."""
        i, t, plan = p.index, self.t, p.plan
        t_next, d = t[i + 1], p.delivery_interval_s
        lost_thesis, thesis_d, ip_thesis = self.acct.last(t_next)
        if plan is None:
            cycle = speed_in = speed_out = r1 = r2 = r3 = r4 = v1 = v2 = v3 = v4 = NAN
        else:
            cycle, speed_in, speed_out = plan.cycle, plan.input_speed, plan.output_to_g
            r1, r2 = plan.r1_pre + plan.r1_post, plan.r2
            r3, r4 = plan.r3_pre + plan.r3_post, plan.r4
            (l1, l2, l3, l4) = self.lengths
            v1, v2, v3, v4 = l1 / r1, l2 / r2, l3 / r3, l4 / r4
        row = (i + 1, p.arrival_s, t[i], p.at_bot_s, picked, not picked, lost_thesis, p.pick_s,
               p.touchdown_s, d, cycle, thesis_d, t_next / d, ip_thesis, speed_in, speed_out,
               p.spacing_in, v1, v2, v3, v4, r1, r2, r3, r4, p.feed_delay_s, limits,
               None if self.energy_of is None else self.energy_of(plan) if picked and plan else NAN,
               p.station if self.layout[0] else None, p.buffer_wait_s if self.layout[1] else None)
        if self.rows is not None:
            self.rows.append(row)
        if self.sink is not None:
            self.sink(PartRecord._make(row))

    @property
    def handed_on(self) -> int:
        """Parts completed and handed on so far."""
        return len(self.per_part) // _PER_PART_DTYPE.itemsize

    def flush(self) -> None:
        """The run stopped with parts still in the cell: hand on those done after them."""
        waiting = self.waiting
        while waiting:
            first = min(waiting)
            self._skip_to(first)
            self.delivered_part(waiting.pop(first))

    def column(self, name: str, start: int = 0) -> np.ndarray:
        """One of :data:`PER_PART`'s values of every part from ``start`` on (a copy), or one
        derived, to the bit as the processes have it: ``picked`` (1.0 for a part picked, 0.0
        for one that rode off), ``interval`` (the time since the last set-down: parts are set
        down in part order) and ``feed_delay`` (the drop less the feeder's schedule)."""
        if name == "picked":
            return ((self.column("limits", start) & RODE_OFF) == 0).astype(np.float64)
        table = np.frombuffer(self.per_part, dtype=_PER_PART_DTYPE)
        if name == "interval":  # as the output conveyor subtracts (OutputConveyor.run)
            td = table["touchdown"]
            done = np.flatnonzero(np.isfinite(td))
            out = np.full(td.size, NAN)
            out[done[1:]] = td[done[1:]] - td[done[:-1]]
            return out[start:]
        if name == "feed_delay":  # the feeder's schedule, as Feeder.fed_s sums it
            return table["arrival"][start:] - np.cumsum(self.t)[table["part"][start:]]
        return np.ascontiguousarray(table[name][start:])

    def warmup(self, setting: int | str) -> int:
        """The number of leading parts to leave out: ``setting``, or for ``auto`` the
        MSER-5 truncation point of the delivery intervals (White 1997)."""
        if setting != "auto":
            return int(setting)
        from cell.sim.warmup import mser5

        interval = self.column("interval")
        delivered = np.flatnonzero(np.isfinite(interval))
        if delivered.size < 10:
            return 0
        cut = mser5(interval[delivered])
        return int(delivered[cut]) if cut < delivered.size else 0


def _seed_value(seed: Any) -> Any:
    if isinstance(seed, np.random.SeedSequence):
        return str(seed.entropy) + ("/" + ".".join(map(str, seed.spawn_key))
                                    if seed.spawn_key else "")
    return seed


def simulate(scenario: Scenario | AssembledCell,
             seed: int | np.random.SeedSequence | None = None, *, keep_parts: bool = True,
             on_part: PartSink | None = None, on_belt: BeltSink | None = None,
             keep_belts: bool = True, keep_stations: bool = False) -> SimResult:
    """Run ``run.parts`` parts (or ``run.hours`` of parts) through the cell under its policy.

    ``seed``: int or SeedSequence; None means ``run.seed``.  Policies given the
    same seed see the same inter-arrival times (common random numbers).
    ``keep_parts`` / ``keep_belts``: keep every part's record / belt speed change in the result
    (off for long runs, which stream them to ``on_part`` / ``on_belt`` instead, as each becomes
    final: memory then stays flat); ``keep_stations``: a layout's stations' visits and belts.
    """
    run = Run(scenario, seed, keep_parts=keep_parts, on_part=on_part, on_belt=on_belt,
              keep_belts=keep_belts, keep_stations=keep_stations)
    run.go()
    return run.result()


class Run:
    """One run set up, its processes started: :func:`simulate` runs it to its end in one go
    (:meth:`go`); :class:`cell.rl.CellEnv` steps its SimPy environment from one decision of the
    controller to the next (:meth:`over` says when there is nothing left to step), then reads
    the same :meth:`result`."""

    def __init__(self, scenario: Scenario | AssembledCell,
                 seed: int | np.random.SeedSequence | None = None, *, keep_parts: bool = True,
                 on_part: PartSink | None = None, on_belt: BeltSink | None = None,
                 keep_belts: bool = True, keep_stations: bool = False):
        cell = scenario if isinstance(scenario, AssembledCell) else assemble(scenario)
        s, k, policy = cell.scenario, cell.k, cell.policy
        seed = s.run.seed if seed is None else seed
        # T_1 .. T_{n+1}: the last is only the last part's "next arrival".
        t_all, n, horizon = run_arrivals(s, seed)
        t_list: list[float] = t_all.tolist()
        rows: list[tuple[Any, ...]] | None = [] if keep_parts else None
        belts, keep = BeltLog(keep_belts, on_belt), (lambda: BeltLog(True, None)) if keep_stations else None

        acct = policy.accounting()
        env = simpy.Environment()
        tm = k.timing
        stands = s.failures is not None or s.calendar is not None  # clocks that never end (or a
        later = any(c.scenario.failures for _, c in cell.line)  # later station's): the run ends
        finished = env.event() if (stands or later) and horizon is None else None  # with its parts
        log = RunLog(t_list, acct, on_part, k.spacing, k.tol, rows,
                     (tm.r1_length_in, tm.r2.length_in, tm.r3_length_in, tm.r4.length_in),
                     finished, n, state_energy.arm_energy_of(cell),
                     (s.stations is not None, has_buffer(cell)))
        downtime = None if not stands else Downtime(env, s.failures or calendar.NO_FAILURES, seed)
        wear_clock.count_on(downtime, cell, seed)  # wear counted by the robot's failure clock
        line, station, feeder = build(env, cell, seed, log, belts.told, downtime, t_list, n, keep)
        calendar.keep(env, s, downtime)  # a calendar's shifts, started with the failure clocks
        if downtime is not None:
            downtime.start()
        self.cell, self.seed, self.env, self.log, self.acct = cell, seed, env, log, acct
        self.t_all, self.n, self.horizon, self.finished = t_all, n, horizon, finished
        self.rows, self.belts, self.keep_belts, self.downtime = rows, belts, keep_belts, downtime
        self.station, self.feeder, self.line = station, feeder, line

    def go(self) -> None:
        """Run to the end: every part done, or the horizon (:func:`run_until_done`)."""
        if self.downtime is None and self.finished is None and self.horizon is None:
            self.env.run()
        else:
            run_until_done(self.env, self.log, self.horizon, self.finished)

    def over(self) -> bool:
        """Whether stepping the environment on would pass the run's end (then :meth:`go`
        finishes it without a further event of the run's own)."""
        nxt = self.env.peek()
        if self.finished is not None:
            return self.finished.processed or nxt == math.inf
        return nxt == math.inf or (self.horizon is not None and nxt >= self.horizon)

    def result(self) -> SimResult:
        """The run's result once it is over: its summary, rows and belts."""
        cell, log, acct, env, station, downtime, line = \
            self.cell, self.log, self.acct, self.env, self.station, self.downtime, self.line
        s, k, n, seed = cell.scenario, cell.k, self.n, self.seed
        (line or station).close(env.now)
        column = log.column if line is None else line.first_column(log.column)  # its robot's
        summary = _summary(cell, log, acct, self.t_all, n, env.now)
        wear = None if station.wear is None else station.wear.log  # wear: without failures
        stops = line.stopped[0] if line else wear_clock.station_stops(downtime, wear, env.now)
        lines = oee.measure(summary, column, downtime, k.cycle_nom, env.now, stops,
                            s.quality.rule, calendar.off_spans(s, env.now))
        lines = state_energy.measure(summary, s, lines, log, downtime, env.now, stops, line)
        run_cost.measure(summary, s, stops, log.column, line)
        summary.seed = _seed_value(seed)
        summary.input_speed_max_in_s = station.input.belt.max_speed_in_s
        summary.input_speed_min_in_s = station.input.belt.min_speed_in_s
        summary.parts_bound = parts_bound(k, self.feeder.fed_s[summary.warmup_parts:n], station.input.belt)
        result = SimResult(summary, self.rows, self.belts if self.keep_belts else None)
        result.downtime, result.timelines, result.stop_rows = downtime, lines, stops
        result.wear = wear_clock.measures(wear, downtime, env.now)
        if line:  # stations.csv's rows, the line's measures (cell.sim.line)
            result.station_rows, result.line = line.rows, line
            line.measure(summary, log, env.now)
        return result


def _summary(cell: AssembledCell, log: RunLog, acct: Accounting, t: np.ndarray, n: int,
             end_s: float) -> RunSummary:
    """The run's measures over the parts after the warm-up (all of them by default), each
    column read as it is needed and let go (``make bench``'s ``peak_mb_1m_parts``: all read at
    once, the summary took the run from 231 to 315 MB)."""
    s, k = cell.scenario, cell.k
    w = log.warmup(s.run.warmup_parts)
    limits = log.column("limits", w)
    picked = (limits & RODE_OFF) == 0

    def count(name: str) -> int:
        return int(np.count_nonzero(limits & LIMIT_BIT[name]))

    r = RunSummary(
        scenario=s.name, policy=cell.policy.name, ideal_cycle_s=cell.policy.ideal_cycle_s,
        parts_arrived=n - w, parts_missed=int((~picked).sum()),
        spacing_outside_tol=count("spacing_off"),
        r1_nominal_s=k.r1_nom, r2_nominal_s=k.r2_nom, nominal_cycle_s=k.cycle_nom,
        nominal_from=k.nominal_from, mean_interarrival_s=k.mean_interarrival_s,
        fastest_cycle_s=k.fastest_cycle_s, offered_load=k.offered_load, warmup_parts=w,
        sim_end_s=end_s)
    for name, counted in LIMIT_COUNTS.items():
        setattr(r, counted.field, count(name))
    _deliveries(r, log, t, w)
    r.parts_in_cell = n - w - r.parts_delivered - r.parts_missed - count("scrapped")
    held = limits & LIMIT_BIT["held_at_feeder"] != 0
    r.feed_delay_max_s = float(log.column("feed_delay", w)[held].max()) if held.any() else 0.0
    vout = log.column("output_speed", w)[picked]
    r.output_speed_min_in_s = float(vout.min()) if vout.size else math.nan
    r.output_speed_max_in_s = float(vout.max()) if vout.size else math.nan
    del vout, held
    # every handed-on part's next inter-arrival time (all of T_2 … T_{n+1} unless the run
    # stopped with parts in the cell)
    acct.finish(r, w, log.column("r4", w)[picked], t[log.column("part").astype(np.int_) + 1])
    r.parts_per_hr_wallclock = float(accounting.parts_per_hr(r.actual_cycle_wallclock_s))
    r.parts_per_hr_thesis = float(accounting.parts_per_hr(r.actual_cycle_thesis_s))
    r.vavg_r4_in_s = k.timing.r4.length_in / r.r4_s if r.r4_s == r.r4_s else math.nan
    return r


def _deliveries(r: RunSummary, log: RunLog, t: np.ndarray, w: int) -> None:
    """The summary's measures of the parts set down: their count, the wall-clock cycle, the
    mean IP (each part's, as its row has it: T_{i+1} over its interval) and the spacings."""
    td = log.column("touchdown", w)
    done = td[np.isfinite(td)]
    d = r.parts_delivered = done.size
    r.actual_cycle_wallclock_s = float((done[-1] - done[0]) / (d - 1)) if d > 1 else math.nan
    del td, done
    ip_wall = t[log.column("part", w).astype(np.int_) + 1] / log.column("interval", w)
    r.ip_wallclock = float(np.nanmean(ip_wall)) if np.isfinite(ip_wall).any() else math.nan
    del ip_wall
    sp = log.column("spacing", w)
    sp = sp[np.isfinite(sp)]
    r.spacing_min_in = float(sp.min()) if sp.size else math.nan
    r.spacing_max_in = float(sp.max()) if sp.size else math.nan
