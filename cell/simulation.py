"""One run of the cell in simulated time (thesis §6).

Five SimPy processes talk through one-event hand-offs: the feeder drops parts
on the input conveyor; the conveyor hands each to the controller as it reaches
B; the controller asks the scenario's policy for the part's cycle, sets the
belts and sends the robot an order; the robot's touch-down hands the part to
the output conveyor, which measures its spacing.  Each part's
:class:`~cell.records.PartRecord` is filled in as these things happen; when a
part is done (set down, or fallen off at F) the run's log completes its
accounting and passes it on, in part order, to whoever asked for rows (a CSV
writer, a list), keeping only a few numbers per part for the summary.

:func:`simulate` is what ``cell run`` and every sweep replication call.
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import simpy

from cell import accounting
from cell.arrivals import interarrival_times
from cell.assembly import AssembledCell, assemble
from cell.controller import Controller, View
from cell.conveyors import InputConveyor, OutputConveyor
from cell.feeder import Feeder
from cell.policies.base import Accounting
from cell.records import LIMIT_BIT, SPACING_OFF, BeltChange, PartRecord, RunSummary, limit_names
from cell.robot import Robot
from cell.scenario import Scenario

PartSink = Callable[[PartRecord], Any]
BeltSink = Callable[[BeltChange], Any]


@dataclass
class SimResult:
    """A run: its summary, and its part records and belt changes if they were kept."""

    summary: RunSummary
    records: list[PartRecord] | None = None
    belt_changes: list[BeltChange] = field(default_factory=list)

    @property
    def parts(self) -> Any:
        """The part records as a pandas DataFrame (the columns of parts.csv)."""
        import pandas as pd

        from cell.records import PART_COLUMNS

        rows = [[getattr(r, c) for c in PART_COLUMNS] for r in self.records or ()]
        return pd.DataFrame(rows, columns=PART_COLUMNS)

    @property
    def belts(self) -> dict[str, list[tuple[float, float]]]:
        """(instant, speed) of every speed change of the ``input`` and ``output`` belts."""
        out: dict[str, list[tuple[float, float]]] = {"input": [], "output": []}
        for c in self.belt_changes:
            out[c.belt].append((c.from_s, c.speed_in_s))
        return out


class RunLog:
    """Completes each part's record and hands the records on in part order.

    Parts finish out of order (a part can fall off at F while the one before it
    is still in the hand), so a finished part waits here until those before it
    are done; at most a few do.  What the summary needs is kept per part in flat
    arrays (a few dozen bytes a part), so a warm-up can be cut off at the end.
    """

    def __init__(self, t: list[float], acct: Accounting, sinks: list[PartSink],
                 spacing_in: float, tol_in: float):
        self.t = t
        """T_1 … T_{n+1}: the last is only part n's "next arrival"."""
        self.acct, self.sinks = acct, sinks
        self.spacing_in, self.tol_in = spacing_in, tol_in
        self.waiting: dict[int, PartRecord] = {}
        self.flags: dict[int, int] = {}
        """Limit bits of parts not yet handed on."""
        self.next = 1
        self.td = array("d")
        self.picked = array("b")
        self.r4 = array("d")
        self.out_speed = array("d")
        self.ip_wall = array("d")
        self.interval = array("d")
        self.spacing = array("d")
        self.limits = array("l")
        self.feed_delay = array("d")

    def flag(self, part: PartRecord, limits: int) -> None:
        self.flags[part.part] = self.flags.get(part.part, 0) | limits

    def missed(self, part: PartRecord) -> None:
        self._done(part)

    def delivered_part(self, part: PartRecord) -> None:
        self._done(part)

    def _done(self, part: PartRecord) -> None:
        if part.part != self.next:
            self.waiting[part.part] = part
            return
        self._emit(part)
        while self.next in self.waiting:
            self._emit(self.waiting.pop(self.next))

    def _emit(self, p: PartRecord) -> None:
        t_next = self.t[p.part]
        p.ip_wallclock = t_next / p.delivery_interval_s
        self.acct.part(p, t_next)
        flags = self.flags.pop(p.part, 0)
        sp = p.spacing_in
        if sp == sp and abs(sp - self.spacing_in) > self.tol_in + 1e-9:
            flags |= SPACING_OFF
        p.limits = limit_names(flags) if flags else ""
        self.td.append(p.touchdown_s)
        self.picked.append(p.picked)
        self.r4.append(p.r4_s)
        self.out_speed.append(p.output_speed_in_s)
        self.ip_wall.append(p.ip_wallclock)
        self.interval.append(p.delivery_interval_s)
        self.spacing.append(sp)
        self.limits.append(flags)
        self.feed_delay.append(p.feed_delay_s)
        for sink in self.sinks:
            sink(p)
        self.next += 1

    def warmup(self, setting: int | str) -> int:
        """The number of leading parts to leave out: ``setting``, or for ``auto`` the
        MSER-5 truncation point of the delivery intervals (White 1997)."""
        if setting != "auto":
            return int(setting)
        from cell.analysis.stats import mser5

        interval = np.frombuffer(self.interval)
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
             keep_belts: bool = True) -> SimResult:
    """Run ``run.parts`` parts through the cell under its policy.

    ``seed``: int or SeedSequence; None means ``run.seed``.  Policies given the
    same seed see the same inter-arrival times (common random numbers).
    ``keep_parts`` / ``keep_belts``: keep every part's record / belt speed change
    in the result (off for long runs, which stream them to ``on_part`` /
    ``on_belt`` instead, as each becomes final: memory then stays flat).
    """
    cell = scenario if isinstance(scenario, AssembledCell) else assemble(scenario)
    s, k, policy = cell.scenario, cell.k, cell.policy
    seed = s.run.seed if seed is None else seed
    n = s.run.parts
    # T_1 .. T_{n+1}: the last is only the last part's "next arrival".
    t_all = interarrival_times(s.arrivals, n + 1, seed, s.base_dir)

    records: list[PartRecord] | None = [] if keep_parts else None
    sinks: list[PartSink] = [records.append] if records is not None else []
    if on_part is not None:
        sinks.append(on_part)
    changes: list[BeltChange] = []

    def belt_sink(name: str) -> Callable[[float, float], None]:
        def told(t: float, v: float) -> None:
            change = BeltChange(name, t, v)
            if keep_belts:
                changes.append(change)
            if on_belt is not None:
                on_belt(change)
        return told

    acct = policy.accounting()
    env = simpy.Environment()
    log = RunLog(t_all.tolist(), acct, sinks, k.spacing, k.tol)
    conveyor = InputConveyor(env, k.v_nom, k.input_length, belt_sink("input"))
    output = OutputConveyor(env, k.u_nom, log.delivered_part, belt_sink("output"))
    robot = Robot(env, output.placed)
    feeder = Feeder(env, t_all, conveyor, n, k.part_size, log.flag)
    conveyor.feeder = feeder
    view = View(env, k, feeder.fed_s, n, conveyor, output)
    Controller(env, k, policy, view, conveyor, output, robot, log)
    env.run()
    conveyor.belt.close()
    output.belt.close()
    changes.sort(key=lambda c: (c.belt != "input", c.from_s))

    summary = _summary(cell, log, acct, t_all, n, env.now)
    summary.seed = _seed_value(seed)
    summary.input_speed_max_in_s = conveyor.belt.max_speed_in_s
    summary.input_speed_min_in_s = conveyor.belt.min_speed_in_s
    return SimResult(summary, records, changes)


def _summary(cell: AssembledCell, log: RunLog, acct: Accounting, t: np.ndarray, n: int,
             end_s: float) -> RunSummary:
    """The run's measures over the parts after the warm-up (all of them by default)."""
    s, k = cell.scenario, cell.k
    w = log.warmup(s.run.warmup_parts)
    td = np.frombuffer(log.td)[w:]
    picked = np.frombuffer(log.picked, dtype=np.int8)[w:].astype(bool)
    vout = np.frombuffer(log.out_speed)[w:][picked]
    ip_wall = np.frombuffer(log.ip_wall)[w:]
    sp = np.frombuffer(log.spacing)[w:]
    sp = sp[np.isfinite(sp)]
    limits = np.frombuffer(log.limits, dtype=np.int_)[w:] if len(log.limits) else \
        np.zeros(0, dtype=np.int_)
    delay = np.frombuffer(log.feed_delay)[w:]
    done = td[np.isfinite(td)]
    d = done.size
    missed = int((~picked).sum())

    def count(name: str) -> int:
        return int(np.count_nonzero(limits & LIMIT_BIT[name]))

    held = limits & LIMIT_BIT["held_at_feeder"] != 0
    r = RunSummary(
        scenario=s.name, policy=cell.policy.name, ideal_cycle_s=cell.policy.ideal_cycle_s,
        parts_arrived=n - w, parts_delivered=d, parts_missed=missed,
        parts_in_cell=n - w - d - missed,
        actual_cycle_wallclock_s=float((done[-1] - done[0]) / (d - 1)) if d > 1 else math.nan,
        ip_wallclock=float(np.nanmean(ip_wall)) if np.isfinite(ip_wall).any() else math.nan,
        spacing_min_in=float(sp.min()) if sp.size else math.nan,
        spacing_max_in=float(sp.max()) if sp.size else math.nan,
        spacing_outside_tol=count("spacing_off"),
        limit_input_floor=count("input_floor"), limit_input_ceiling=count("input_ceiling"),
        limit_input_tracking=count("input_tracking"), limit_output_floor=count("output_floor"),
        limit_output_ceiling=count("output_ceiling"), limit_r2_peak=count("r2_peak"),
        limit_r4_peak=count("r4_peak"), parts_held=int(held.sum()),
        feed_delay_max_s=float(delay[held].max()) if held.any() else 0.0,
        output_speed_min_in_s=float(vout.min()) if vout.size else math.nan,
        output_speed_max_in_s=float(vout.max()) if vout.size else math.nan,
        r1_nominal_s=k.r1_nom, r2_nominal_s=k.r2_nom, nominal_cycle_s=k.cycle_nom,
        nominal_from=k.nominal_from, mean_interarrival_s=k.mean_interarrival_s,
        fastest_cycle_s=k.fastest_cycle_s, utilisation=k.utilisation, warmup_parts=w,
        sim_end_s=end_s)
    acct.finish(r, w, np.frombuffer(log.r4)[w:][picked], t[1:])
    r.parts_per_hr_wallclock = float(accounting.parts_per_hr(r.actual_cycle_wallclock_s))
    r.parts_per_hr_thesis = float(accounting.parts_per_hr(r.actual_cycle_thesis_s))
    r.vavg_r4_in_s = k.timing.r4.length_in / r.r4_s if r.r4_s == r.r4_s else math.nan
    return r
