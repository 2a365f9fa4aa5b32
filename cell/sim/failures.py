"""Breakdowns, repairs and planned stops in the simulated cell (docs/model.md, "When
equipment fails").

Each piece of equipment with a ``failures:`` entry has a failure clock (:mod:`cell.sim.failure_clock`):
a budget, drawn from its time to failure, consumed at a rate that depends on what the
equipment is doing (1 while it works on the ``operating`` clock; 1 while it is up on the
``calendar`` clock).  When it runs out the equipment fails: it waits for a repair crew (a
``simpy.Resource`` when ``repair.crews`` is given), is repaired for a drawn time, and a
new budget is drawn.

The budget and its rates come from an :class:`Exposure`, the hook for a wear model: the
default (:class:`Distributed`) is a time to failure; a wear model gives one budget per motor
(the exposure at which it wears out) and a rate per leg of each cycle (its exposure per
second), told of every cycle's leg times as it starts (:meth:`Exposure.cycle`).

A stop costs what it is.  Each clock has one event, at the instant its first budget runs
out, moved only when what the equipment will do changes; the robot's clock is told each
cycle's six legs, B → LO, LO → F, F → G, G → TD, TD → K, K → B, as the cycle starts
(:meth:`~cell.sim.failure_clock.FailureClock.cycle`).  A cycle that nothing can stop before
it ends (no equipment down, no failure or planned stop due) runs as it would with no failures
at all; one that
something may stop runs leg by leg, each a timeout that a stop interrupts (SimPy's
machine-shop pattern, :meth:`cell.sim.robot.Robot.run`): the robot is held while it is down
or in maintenance, and in B → LO (G → TD) while the input (output) belt, which it tracks
there, stands.  An interrupt is sent only when equipment fails or comes back.
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Callable
from typing import Any

import numpy as np
import simpy

from cell.scenario.failure_spec import EQUIPMENT, SECONDS_PER_HOUR, STREAM_KEYS, Draws
from cell.sim.conveyors import EPS_S
from cell.sim.failure_clock import MOVING_NOT, STOPPED, Distributed, Exposure, FailureClock
from cell.sim.records import LET_GO, LOST_DOWNTIME, SCRAPPED


class Equipment:
    """One piece of equipment's failures: its clock, its repairs, its log of stops."""

    def __init__(self, cell: Downtime, name: str, spec: Any, seed: Any,
                 down: Callable[[], Any], up: Callable[[], None], leg: int = MOVING_NOT):
        ttf, ttr = STREAM_KEYS[name]
        self.cell, self.name, self.down_hook, self.up_hook = cell, name, down, up
        self.repair = Draws(spec.time_to_repair, seed, ttr)
        self.exposure: Exposure = Distributed(Draws(spec.time_to_failure, seed, ttf), spec.clock)
        self.down = False
        self.cell_env = cell.env
        self.clock: FailureClock | None = None
        self.leg = leg

    def start(self) -> None:
        self.clock = FailureClock(self.cell_env, self.exposure, self.fail, self.leg)

    def fail(self, component: int, cause: str):  # noqa: ANN201 (SimPy generator)
        env, crews = self.cell_env, self.cell.crews
        self.down = True
        key = self.cell.begin(self.name, cause, self.down_hook())
        request = crews.request() if crews is not None else None
        if request is not None:
            yield request
        work = self.repair()
        shifts = self.cell.shifts  # a calendar: the repair in its crew's hours
        yield env.timeout(work if shifts is None else shifts.repair_s(work))
        if request is not None:
            crews.release(request)  # type: ignore[union-attr]
        self.down = False
        self.up_hook()
        self.cell.end(key)


class RobotStops:
    """What can stop the robot (handed to :class:`cell.sim.robot.Robot`): its failures and
    planned stops, and the belts it tracks; its failure clock, its motion, and why a part
    was lost.  The robot's cycle is the robot's (:meth:`cell.sim.robot.Robot.run`); this
    says whether anything can stop it (:meth:`begin`), holds it (:meth:`held`), and
    interrupts it when something does (:meth:`touch`)."""

    def __init__(self, cell: Downtime, scrap: bool):
        self.cell, self.env, self.scrap = cell, cell.env, scrap
        self.robot: Any = None
        """The robot stopped (set by the robot it is handed to)."""
        self.stop: str | None = None
        """``down`` or ``maintenance`` while the robot is stopped."""
        self.in_cycle = False
        """True while a cycle runs leg by leg (one something may stop)."""
        self.at_leg = -1
        self.part: Any = None
        """The part of the cycle under way, until it is set down (or lost)."""
        self.planned_free = -math.inf
        """When the cycle under way would have ended without a stop."""
        self.clocks: list[FailureClock] = []
        self.motion = array("d")
        """Motion intervals, (from, to) pairs."""
        self.moving_since = math.nan
        """When the motion under way began (NaN: the robot is not moving)."""
        self.maintenance_due: simpy.Event | None = None
        self.maintenance_at = math.inf
        """When the next planned stop comes."""
        self._freed: simpy.Event | None = None

    def loss(self, now: float) -> int:
        """A part at B with the robot not back: lost to downtime if a stop kept it away."""
        return LOST_DOWNTIME if self.stop is not None or now + EPS_S >= self.planned_free \
            else LET_GO

    def begin(self, part: Any, to_lo: float, to_td: float) -> tuple[float, ...] | None:
        """A cycle starts now: None if nothing can stop the robot before it is back at B
        (no equipment down, no stop planned or due till then: the robot runs it as if
        nothing could fail), else its legs (:data:`LEGS`), to run one by one."""
        env, cell = self.env, self.cell
        now = env.now
        plan = part.plan  # the regimes as parts.csv has them (R I, R III: their two legs summed)
        r1, r2, cycle = plan.r1_pre + plan.r1_post, plan.r2, plan.cycle
        r3_pre = to_td - (r1 + r2)
        r3_post = plan.r3_pre + plan.r3_post - r3_pre
        legs = (to_lo, r1 - to_lo, r2, r3_pre, r3_post, cycle - to_td - r3_post)
        end = now + cycle
        self.planned_free = end
        clear = self.stop is None and self.maintenance_due is None and \
            self.maintenance_at > end and cell.clear_until(end)
        for clock in self.clocks:
            clear = clock.cycle(legs, end, clear)
        if clear:
            self.motion.extend((now, end))
            return None
        self.in_cycle, self.part = True, part
        return legs

    def held(self, leg: int) -> bool:
        """Whether the robot is held now in ``leg``: stopped, or tracking a stopped belt."""
        belt = self.cell.input_belt if leg == 0 else self.cell.output_belt if leg == 3 else None
        return self.stop is not None or self.cell.standing or (belt is not None and belt.stopped)

    def touch(self) -> None:
        """Something that can hold the robot changed: its legs look again."""
        proc = self.robot.process if self.robot is not None else None
        if self.in_cycle and proc is not None and proc.is_alive and \
                self.env.active_process is not proc:
            proc.interrupt()

    def doing(self, leg: int, free_at: float) -> None:
        """What the robot does from now on (a leg, MOVING_NOT or STOPPED), and when it will
        be free for a part at B."""
        now = self.env.now
        if leg >= 0 and self.moving_since != self.moving_since:
            self.moving_since = now
        elif leg < 0 and self.moving_since == self.moving_since:
            self.motion.extend((self.moving_since, now))
            self.moving_since = math.nan
        robot = self.robot
        if not robot.orders.items:  # an order given as this cycle ends keeps its own
            robot.free_at_s = free_at
        freed, self._freed = self._freed, None
        if freed is not None:
            freed.succeed()
        for clock in self.clocks:
            clock.follow(leg)

    def freed(self) -> simpy.Event:
        """An event that succeeds when it is next told when the robot will be free (what a
        buffer waits on while the robot is stopped: docs/layout.md)."""
        if self._freed is None:
            self._freed = self.env.event()
        return self._freed

    def busy(self, end_s: float) -> tuple[Any, Any]:
        """(from, to) of the robot's motion up to ``end_s``."""
        motion = np.frombuffer(self.motion, dtype=float).reshape(-1, 2)
        if self.moving_since == self.moving_since:
            motion = np.vstack([motion, [[self.moving_since, end_s]]])
        motion = np.minimum(motion, end_s)
        return motion[:, 0], motion[:, 1]

    def set_down(self) -> Any:
        """The part at touch-down (None: scrapped in a stop); the hand is empty after."""
        part, self.part = self.part, None
        return part

    def at_rest(self) -> None:
        """Back at B (or repaired there): free, unless a planned stop is due."""
        self.in_cycle, self.part = False, None
        due = self.maintenance_due
        if due is not None and self.stop is None:
            self.maintenance_due = None
            self.stop = "maintenance"
            self.doing(STOPPED, math.inf)
            due.succeed()
        elif self.stop is None:
            self.doing(MOVING_NOT, self.env.now)

    def fails(self) -> Any:
        """The robot fails now: held where it is; the part before lift-off rides off, the
        part in the hand is scrapped (or kept to finish).  The part's number, or ""."""
        self.stop = "down"
        part, log = self.part, self.cell.log
        if part is not None and self.at_leg == 0:
            self.part = None
            log.flag(part, LOST_DOWNTIME)  # rode off (RODE_OFF): not picked
            log.missed(part)
        elif part is not None and self.scrap:
            self.part = None
            log.flag(part, SCRAPPED)
            log.missed(part)
        if self.in_cycle:
            self.touch()
        else:
            self.doing(STOPPED, math.inf)
        return part.index + 1 if part is not None else ""  # parts.csv's number

    def repaired(self) -> None:
        self.stop = None
        if self.in_cycle:
            self.touch()
        else:
            self.at_rest()

    def maintenance(self, every_s: float, duration_s: float, off_shift: bool = False):  # noqa: ANN201
        env, shifts = self.env, self.cell.shifts
        k = 1
        while True:
            self.maintenance_at = k * every_s
            yield env.timeout(max(k * every_s - env.now, 0.0))
            if off_shift and shifts is not None:  # a time off shift it fits in (the cell stands)
                yield from shifts.off_for(duration_s)
            self.maintenance_at = math.inf
            if (self.in_cycle and not self.cell.standing) or self.stop is not None:
                self.maintenance_due = env.event()
                self.robot.free_at_s = math.inf  # no new part once back at B
                yield self.maintenance_due
            else:
                self.stop = "maintenance"
                if self.in_cycle:  # held off shift mid-cycle: held for the maintenance too
                    self.touch()
                else:
                    self.doing(STOPPED, math.inf)
            key = self.cell.begin("robot", "maintenance", "")
            yield env.timeout(duration_s)
            self.cell.end(key)
            self.repaired()
            k = max(k + 1, math.floor(env.now / every_s) + 1)


class BeltStops:
    """What can stop a belt (handed to its conveyor): its failures."""

    def __init__(self, cell: Downtime, name: str):
        self.cell, self.name = cell, name

    def clear_until(self, t: float) -> bool:
        """Whether the belt runs now and cannot fail before ``t``."""
        return self.cell.clear_until(t, self.name)


class Downtime:
    """A run's failures: every piece of equipment's clock and repairs, and their log."""

    def __init__(self, env: simpy.Environment, failures: Any, seed: Any,
                 robot_exposure: Exposure | None = None):
        self.env, self.spec, self.seed = env, failures, seed
        self.robot_exposure = robot_exposure
        """What the robot's failure clock counts down instead of its drawn time to failure
        (a wear model's exposure); None: ``failures.robot.time_to_failure``."""
        self.crews = simpy.Resource(env, failures.repair.crews) if failures.repair else None
        self.stops: list[tuple[str, str, float, float, Any]] = []
        """(equipment, cause, from_s, to_s, part) of every stop, as each ends."""
        robot = failures.robot
        self.robot = RobotStops(self, robot is not None and robot.part_in_hand == "scrap")
        self.log: Any = None
        self.output: Any = None
        self.input_belt: Any = None
        self.output_belt: Any = None
        self.equipment: list[Equipment] = []
        self.shifts: Any = None
        """A calendar's shifts (:class:`cell.sim.calendar.Shifts`), None without one."""
        self.standing = False
        """True while the cell stands off shift."""
        self.off_at = math.inf
        """When the cell next stands off shift (now, while it stands; inf: never)."""
        self.conveyors: tuple[Any, ...] = ()
        self._belt_clocks: list[Equipment] = []
        self._open: dict[int, tuple[str, str, float, Any]] = {}
        self._next = 0

    def attach(self, conveyor: Any, output: Any, view: Any, log: Any) -> None:
        """The equipment its failures stop, and the log of parts they lose (before the
        run starts): kept, never rewired (each piece stops and restarts by its own methods)."""
        f, rs = self.spec, self.robot
        self.log, self.output = log, output
        self.input_belt, self.output_belt = conveyor.belt, output.belt
        self.conveyors = (conveyor, output)

        def belt(which: Any, stop: bool) -> Callable[[], Any]:
            def change() -> str:
                if stop != which.belt.stopped and (stop or not self.standing):  # off shift: stands
                    (which.stop if stop else which.restart)(self.env.now)
                rs.touch()
                return ""
            return change

        def sensor(up: bool) -> Callable[[], Any]:
            def change() -> str:
                view.sensor_up = up
                return ""
            return change

        hooks = {"robot": (rs.fails, rs.repaired),
                 "input_belt": (belt(conveyor, True), belt(conveyor, False)),
                 "output_belt": (belt(output, True), belt(output, False)),
                 "sensor": (sensor(False), sensor(True))}
        for name in EQUIPMENT:
            spec = getattr(f, name)
            if spec is None:
                continue
            down, up = hooks[name]
            e = Equipment(self, name, spec, self.seed, down, up,
                          MOVING_NOT if name == "robot" else 0)
            if name == "robot" and self.robot_exposure is not None:
                e.exposure = self.robot_exposure
            self.equipment.append(e)

    def start(self) -> None:
        """Start the failure clocks and the planned stops (after :meth:`attach`)."""
        rs = self.robot
        for e in self.equipment:
            e.start()
            if e.name == "robot" and e.clock is not None:
                rs.clocks.append(e.clock)
            elif e.name in ("input_belt", "output_belt"):
                self._belt_clocks.append(e)
        m = self.spec.maintenance
        if m is not None:
            self.env.process(rs.maintenance(m.every_h * SECONDS_PER_HOUR, m.duration_min * 60.0,
                                            m.off_shift))
        if self.shifts is not None:
            self.shifts.start()

    def clear_until(self, t: float, name: str | None = None) -> bool:
        """Whether the belts (or the one named) run now and cannot fail (or stand off shift)
        before ``t``."""
        if t >= self.off_at:
            return False
        for e in self._belt_clocks:
            if (name is None or e.name == name) and (e.down or e.clock.due_s <= t):  # type: ignore[union-attr]
                return False
        return True

    def settle(self) -> None:
        """Every clock's kept cycles counted (:meth:`FailureClock.settle`), as at the run's end."""
        for e in self.equipment:
            if e.clock is not None:
                e.clock.settle()

    def begin(self, name: str, cause: str, part: Any) -> int:
        """A stop begins now; its key (for :meth:`end`)."""
        self._open[self._next] = (name, cause, self.env.now, part)
        self._next += 1
        return self._next - 1

    def end(self, key: int) -> None:
        name, cause, start, part = self._open.pop(key)
        self.stops.append((name, cause, start, self.env.now, part))

    def all_stops(self, end_s: float) -> list[tuple[str, str, float, float, Any]]:
        """Every stop, those still under way ending at ``end_s``, in order of start."""
        out = self.stops + [(n, c, a, end_s, p) for n, c, a, p in self._open.values()]
        return sorted(out, key=lambda row: (row[2], EQUIPMENT.index(row[0])))
