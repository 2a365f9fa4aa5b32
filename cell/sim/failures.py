"""Breakdowns, repairs and planned stops in the simulated cell (docs/model.md, "When
equipment fails").

Each piece of equipment with a ``failures:`` entry has a failure clock (:class:`Countdown`):
a budget, drawn from its time to failure, consumed at a rate that depends on what the
equipment is doing (1 while it works on the ``operating`` clock; 1 while it is up on the
``calendar`` clock).  When it runs out the equipment fails: it waits for a repair crew (a
``simpy.Resource`` when ``repair.crews`` is given), is repaired for a drawn time, and a
new budget is drawn.

The budget and its rates come from an :class:`Exposure`, the hook for a wear model: the
default (:class:`Distributed`) is a time to failure; a wear model gives one budget per motor
(the exposure at which it wears out) and a rate per leg of each cycle (its exposure per
second), told of every cycle's leg times as it starts (:meth:`Exposure.cycle`).

The robot (:class:`RobotStops`) runs each order as six legs, B → LO, LO → F, F → G,
G → TD, TD → K, K → B, each a timeout that a stop interrupts (SimPy's machine-shop
pattern); it is held while it is down or in maintenance, and in B → LO (G → TD) while the
input (output) belt, which it tracks there, stands.
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Callable, Sequence
from typing import Any, Protocol

import simpy

from cell.scenario.failure_spec import EQUIPMENT, SECONDS_PER_HOUR, STREAM_KEYS, Draws
from cell.sim.conveyors import EPS_S
from cell.sim.records import LET_GO, LOST_DOWNTIME, SCRAPPED

#: Legs of a cycle (the stretches a wear model times: cell.arm.steptable's segments).
LEGS = ("r1_pre", "r1_post", "r2", "r3_pre", "r3_post", "r4")
#: What the failure clock is told the robot is doing: a leg (0-5) in motion, or
MOVING_NOT, STOPPED = -1, -2
"""up and not in motion (at B, or held by a belt), or stopped (down, in maintenance)."""


class Exposure(Protocol):
    """What a failure clock counts down (the hook for wear, :mod:`cell.sim.wear`)."""

    cause: str
    """failures.csv's ``cause`` of a failure it brings: ``failure`` or ``wear``."""

    def thresholds(self) -> list[float]:
        """The budget of each component (a motor) at the start."""

    def renew(self, component: int) -> float:
        """A new budget for a component once repaired (replaced)."""

    def rates(self, leg: int) -> Sequence[float]:
        """Each component's budget used per second while the equipment does ``leg``."""

    def cycle(self, legs_s: Sequence[float]) -> None:
        """A cycle starts whose legs (:data:`LEGS`) take these times."""


class Distributed:
    """A time to failure drawn from a distribution, on the operating or calendar clock."""

    cause = "failure"

    def __init__(self, draw: Callable[[], float], clock: str):
        self.draw, self.calendar = draw, clock == "calendar"

    def thresholds(self) -> list[float]:
        return [self.draw()]

    def renew(self, component: int) -> float:
        return self.draw()

    def rates(self, leg: int) -> Sequence[float]:
        return (1.0,) if leg >= 0 or (self.calendar and leg == MOVING_NOT) else (0.0,)

    def cycle(self, legs_s: Sequence[float]) -> None:
        return None


class Countdown:
    """An equipment's failure clock (SimPy process): fails it when a budget runs out."""

    def __init__(self, env: simpy.Environment, exposure: Exposure,
                 fail: Callable[[int, str], Any], leg: int):
        self.env, self.exposure, self.fail = env, exposure, fail
        self.leg = leg
        self.left = exposure.thresholds()
        self.counting = False
        self.process = env.process(self.run())

    def set_leg(self, leg: int) -> None:
        """What the equipment does now (a leg, MOVING_NOT or STOPPED)."""
        if leg != self.leg:
            self.leg = leg
            if self.counting and self.env.active_process is not self.process:
                self.process.interrupt()

    def run(self):  # noqa: ANN201 (SimPy generator)
        env = self.env
        while True:
            first = -1
            while first < 0:
                rates = self.exposure.rates(self.leg)
                waits = [b / r if r > 0 else math.inf for b, r in zip(self.left, rates)]
                wait = min(waits)
                start = env.now
                self.counting = True
                try:
                    yield env.event() if wait == math.inf else env.timeout(wait)
                    first = waits.index(wait)
                except simpy.Interrupt:
                    pass
                finally:
                    self.counting = False
                used = env.now - start
                self.left = [max(b - used * r, 0.0) for b, r in zip(self.left, rates)]
            yield from self.fail(first, self.exposure.cause)
            self.left[first] = self.exposure.renew(first)


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
        self.clock: Countdown | None = None
        self.leg = leg

    def start(self) -> None:
        self.clock = Countdown(self.cell_env, self.exposure, self.fail, self.leg)

    def fail(self, component: int, cause: str):  # noqa: ANN201 (SimPy generator)
        env, crews = self.cell_env, self.cell.crews
        self.down = True
        key = self.cell.begin(self.name, cause, self.down_hook())
        request = crews.request() if crews is not None else None
        if request is not None:
            yield request
        yield env.timeout(self.repair())
        if request is not None:
            crews.release(request)  # type: ignore[union-attr]
        self.down = False
        self.up_hook()
        self.cell.end(key)


class RobotStops:
    """The robot's side of failures: its legs, its stops, and why a part was lost."""

    def __init__(self, cell: Downtime, scrap: bool):
        self.cell, self.env, self.scrap = cell, cell.env, scrap
        self.robot: Any = None
        self.stop: str | None = None
        """``down`` or ``maintenance`` while the robot is stopped."""
        self.in_cycle = False
        self.at_leg = -1
        self.part: Any = None
        """The part of the cycle under way, until it is set down (or lost)."""
        self.planned_free = -math.inf
        """When the cycle under way would have ended without a stop."""
        self.clocks: list[Countdown] = []
        self.motion = array("d")
        """Motion intervals, (from, to) pairs."""
        self._moving_since = math.nan
        self.maintenance_due: simpy.Event | None = None
        self.proc: Any = None
        """The process of the cycle under way (what a stop interrupts)."""

    def loss(self, now: float) -> int:
        """A part at B with the robot not back: lost to downtime if a stop kept it away."""
        return LOST_DOWNTIME if self.stop is not None or now + EPS_S >= self.planned_free \
            else LET_GO

    def touch(self) -> None:
        """Something that can hold the robot changed: its legs look again."""
        proc = self.proc
        if self.in_cycle and proc is not None and proc.is_alive and \
                self.env.active_process is not proc:
            proc.interrupt()

    def _doing(self, leg: int, free_at: float) -> None:
        now = self.env.now
        if leg >= 0 and self._moving_since != self._moving_since:
            self._moving_since = now
        elif leg < 0 and self._moving_since == self._moving_since:
            self.motion.extend((self._moving_since, now))
            self._moving_since = math.nan
        self.robot.free_at_s = free_at
        for clock in self.clocks:
            clock.set_leg(leg)

    def cycle(self, part: Any, to_lo: float, to_td: float):  # noqa: ANN201 (SimPy generator)
        """One order, leg by leg (the robot's process runs it)."""
        env, cell = self.env, self.cell
        plan = part.plan  # the regimes as parts.csv has them (R I, R III: their two legs summed)
        r1, r2, cycle = plan.r1_pre + plan.r1_post, plan.r2, plan.cycle
        r3_pre = to_td - (r1 + r2)
        r3_post = plan.r3_pre + plan.r3_post - r3_pre
        legs = (to_lo, r1 - to_lo, r2, r3_pre, r3_post, cycle - to_td - r3_post)
        self.planned_free, self.in_cycle, self.part = env.now + cycle, True, part
        self.proc = env.active_process
        for clock in self.clocks:
            clock.exposure.cycle(legs)
        rest = cycle
        for i, leg in enumerate(legs):
            rest -= leg
            self.at_leg, left = i, leg
            belt = cell.input_belt if i == 0 else cell.output_belt if i == 3 else None
            while left > 0.0:
                start = env.now
                try:
                    if self.stop is not None or (belt is not None and belt.stopped):
                        self._doing(STOPPED if self.stop is not None else MOVING_NOT, math.inf)
                        yield env.event()  # until whatever holds the robot lets go
                    # a planned stop due: the robot will not be free for a part at B
                    self._doing(i, start + left + max(rest, 0.0)
                                if self.maintenance_due is None else math.inf)
                    yield env.timeout(left)
                    left = 0.0
                except simpy.Interrupt:
                    if self._moving_since == self._moving_since:
                        left = max(left - (env.now - start), 0.0)
            p = self.part
            if p is not None and i == 0:
                p.pick_s = env.now
            elif p is not None and i == 3:
                cell.output.placed.put((p, env.now))  # touch-down: taken now, its instant
                self.part = None
        self.in_cycle, self.part = False, None
        self.at_rest()

    def at_rest(self) -> None:
        """Back at B (or repaired there): free, unless a planned stop is due."""
        due = self.maintenance_due
        if due is not None and self.stop is None:
            self.maintenance_due = None
            self.stop = "maintenance"
            self._doing(STOPPED, math.inf)
            due.succeed()
        elif self.stop is None:
            self._doing(MOVING_NOT, self.env.now)

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
            self._doing(STOPPED, math.inf)
        return part.index + 1 if part is not None else ""  # parts.csv's number

    def repaired(self) -> None:
        self.stop = None
        if self.in_cycle:
            self.touch()
        else:
            self.at_rest()

    def maintenance(self, every_s: float, duration_s: float):  # noqa: ANN201 (SimPy generator)
        env = self.env
        k = 1
        while True:
            yield env.timeout(max(k * every_s - env.now, 0.0))
            if self.in_cycle or self.stop is not None:
                self.maintenance_due = env.event()
                self.robot.free_at_s = math.inf  # no new part once back at B
                yield self.maintenance_due
            else:
                self.stop = "maintenance"
                self._doing(STOPPED, math.inf)
            key = self.cell.begin("robot", "maintenance", "")
            yield env.timeout(duration_s)
            self.cell.end(key)
            self.repaired()
            k = max(k + 1, math.floor(env.now / every_s) + 1)


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
        self._open: dict[int, tuple[str, str, float, Any]] = {}
        self._next = 0

    def attach(self, robot: Any, conveyor: Any, output: Any, feeder: Any, view: Any,
               log: Any) -> None:
        """Wire the failures into the cell's processes (before the run starts)."""
        f, rs = self.spec, self.robot
        self.log, self.output = log, output
        self.input_belt, self.output_belt = conveyor.belt, output.belt
        rs.robot = robot
        robot.loss = rs.loss
        conveyor.replan = _while_stopped(conveyor.belt, conveyor.replan)
        output.replan = _while_stopped(output.belt, output.replan)

        def belt(which: Any, stop: bool) -> Callable[[], Any]:
            def change() -> str:
                b = which.belt
                if stop:
                    b.stop(self.env.now)
                else:
                    b.restart(self.env.now)
                if which is conveyor:
                    conveyor.retime()
                    if not stop and feeder.holding:
                        feeder.process.interrupt()
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
        """Start the failure clocks and the planned stops (after :meth:`attach`; a wear model
        may replace the robot's ``exposure`` in between)."""
        rs = self.robot
        for e in self.equipment:
            e.start()
            if e.name == "robot" and e.clock is not None:
                rs.clocks.append(e.clock)
        m = self.spec.maintenance
        if m is not None:
            self.env.process(rs.maintenance(m.every_h * SECONDS_PER_HOUR, m.duration_min * 60.0))

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


def _while_stopped(belt: Any, replan: Callable[..., None]) -> Callable[..., None]:
    """A belt's replan that, while the belt stands, plans for the restart instead."""
    def plan(t1: float, v1: float, t2: float | None = None, v2: float = 0.0) -> None:
        if belt.stopped:
            belt.plan_stopped(t1, v1, t2, v2)
        else:
            replan(t1, v1, t2, v2)
    return plan
