"""The wear model in a run: the robot's five motors worn cycle by cycle (:mod:`cell.sim.wear`).

Two ways in.  With ``wear:`` alone, :func:`alone` wraps the robot's orders: each cycle's
stretch times wear the motors (:class:`WearClock`) and, when one wears out, the robot stops
``wear.repair_h`` once it is back at B (:func:`stop_rows`: its stops as failures.csv's rows,
which the run's states and summary count as well).  With ``failures.robot`` as well, the
failures' robot clock counts the wear instead of a drawn time to failure (:class:`WearExposure`,
:func:`count_on`): the robot stops mid-move, waits for a crew and is repaired for a
drawn ``failures.robot.time_to_repair``, and failures.csv says ``wear``.  Either way the
run's measures come back as :class:`WearResult` (:func:`measures`); its MTBF is the long-run
figure of motors replaced one at a time (:func:`cell.sim.wear.renewal_mtbf_h`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from cell.scenario.arrivals import stream
from cell.sim.wear import (
    HOUR_S,
    STRETCHES,
    CycleWear,
    WearModel,
    draw_thresholds,
    renewal_mtbf_h,
    series_life_h,
)

if TYPE_CHECKING:
    from cell.arm.steptable import StepTable
    from cell.sim.robot import RobotTiming


#: The wear clock's child stream of the run's root SeedSequence (the feeder's is 0; the
#: key is far from the few that other random draws of a run take).
WEAR_STREAM = 21
JOINTS = ("base", "shoulder", "elbow", "pitch", "roll")


def model_of(settings: WearSettingsLike) -> WearModel:
    return WearModel(float(settings.exponent), float(settings.rated_life_h),
                     float(settings.reference_stress), float(settings.shape))


class WearSettingsLike(Protocol):
    """What the wear clock reads of the scenario's ``wear:`` section."""

    @property
    def exponent(self) -> float: ...
    @property
    def rated_life_h(self) -> float: ...
    @property
    def reference_stress(self) -> float: ...
    @property
    def shape(self) -> float: ...
    @property
    def repair_h(self) -> float: ...


class WearLog:
    """A run's wear: the clock (a :class:`WearClock` or a :class:`WearExposure`), and each
    stop for a worn motor (from_s, to_s, joint; joint -1 where the failures' log keeps none)."""

    def __init__(self, clock: WearClock | WearExposure, repair_s: float):
        self.clock, self.repair_s = clock, repair_s
        self.stops: list[tuple[float, float, int]] = []
        self.held_s = 0.0
        """The robot's time in planned stops (maintenance), worn by no motor."""

    def row(self, end_s: float) -> dict[str, float]:
        """The run's wear measures, one row (wear_* columns).  A motor's life at this duty is
        the robot's up time (the run less its stops) over the motor's exposure; the MTBF is
        the renewal figure (:func:`cell.sim.wear.renewal_mtbf_h`), up time between stops."""
        model = self.clock.wear.model
        hours = end_s / HOUR_S
        stops = [(a, b) for a, b, _ in self.stops if a < end_s]
        down_h = sum(min(b, end_s) - a for a, b in stops) / HOUR_S
        up_h = hours - down_h - self.held_s / HOUR_S
        lives = [up_h / e if e > 0 else math.inf for e in self.clock.total]
        robot = series_life_h(lives, model.shape)
        mtbf = renewal_mtbf_h(lives, model.shape)
        out: dict[str, float] = {
            "wear_exponent": model.exponent, "wear_failures": float(len(stops)),
            "wear_down_h": down_h, "wear_hours": hours,
            "wear_robot_life_h": robot, "wear_mtbf_h": mtbf,
            "wear_availability": mtbf / (mtbf + self.repair_s / HOUR_S)
            if math.isfinite(mtbf) else 1.0}
        for name, life in zip(JOINTS, lives):
            out[f"wear_life_{name}_h"] = life
        return out


def stop_rows(wear: WearLog | None, end_s: float) -> list[tuple[str, str, float, float, Any]]:
    """failures.csv's rows of the stops of ``wear:`` alone (the robot at B, no part in hand),
    as :meth:`cell.sim.failures.Downtime.all_stops` gives a run's with failures."""
    if wear is None:
        return []
    return [("robot", "wear", a, min(b, end_s), "") for a, b, _ in wear.stops if a < end_s]


def station_stops(downtime: Any, wear: WearLog | None, end_s: float
                  ) -> list[tuple[str, str, float, float, Any]]:
    """failures.csv's rows of a station's stops: its :class:`~cell.sim.failures.Downtime`'s
    (``all_stops``), or, with nothing that can fail, its worn motors' alone."""
    return downtime.all_stops(end_s) if downtime is not None else stop_rows(wear, end_s)


class WearStops:
    """Wear without failures, handed to the robot (:class:`cell.sim.robot.Robot`): each cycle
    it is ordered to run wears its motors (the stretch times read from the part's record and
    the order); when a motor wears out, the robot stops for ``repair_h`` once that cycle is
    done (back at B), and the motor is replaced."""

    def __init__(self, clock: WearClock, log: WearLog):
        self.clock, self.log = clock, log

    def cycle_s(self, part: Any, to_lo_s: float, to_td_s: float, cycle_s: float,
                now: float) -> float:
        """The cycle's time until the robot is free again: ``cycle_s``, and the repair after
        it if a motor wears out in it."""
        plan = part.plan  # the regimes as parts.csv has them (R I, R III: their legs summed)
        r1, r2, r3 = plan.r1_pre + plan.r1_post, plan.r2, plan.r3_pre + plan.r3_post
        r3_pre = round(to_td_s - (r1 + r2), 9)  # B → TD less R I and R II
        joint = self.clock.cycle((to_lo_s, r1 - to_lo_s, r2, r3_pre, r3 - r3_pre, plan.r4))
        if joint >= 0:
            back, repair_s = now + cycle_s, self.log.repair_s
            self.log.stops.append((back, back + repair_s, joint))
            self.clock.replace(joint)
            cycle_s += repair_s
        return cycle_s


def wear_stops(table: StepTable, timing: RobotTiming, settings: WearSettingsLike,
               seed: int | np.random.SeedSequence) -> WearStops:
    """The robot's motors, worn by every cycle (``wear:`` without failures)."""
    clock = WearClock(CycleWear(table, timing, model_of(settings)), stream(seed, WEAR_STREAM))
    return WearStops(clock, WearLog(clock, float(settings.repair_h) * HOUR_S))


class WearClock:
    """The robot's five motors, each worn by the cycles it runs until it fails.

    :meth:`cycle` adds a cycle's exposure and answers the motor that wore out in it (the
    first whose exposure crossed its drawn threshold), or -1; :meth:`replace` starts that
    motor again from zero with a new threshold.
    """

    def __init__(self, wear: CycleWear, rng: np.random.Generator):
        self.wear, self.rng = wear, rng
        self.total = [0.0] * 5
        """Each motor's exposure over the whole run (for its life at this duty)."""
        self.since = [0.0] * 5
        """Each motor's total exposure when it was fitted."""
        self.threshold: list[float] = draw_thresholds(rng, 5, wear.model).tolist()
        """The exposure since fitting at which each motor wears out."""
        self._due = list(self.threshold)
        self._first = min(self._due)

    @property
    def exposure(self) -> list[float]:
        """Each motor's exposure since it was fitted."""
        return [t - s for t, s in zip(self.total, self.since)]

    def cycle(self, times_s: Sequence[float]) -> int:
        """Add a cycle's exposure: the motor that wore out in it, or -1."""
        e = self.wear.of_times(times_s)
        before = self.total
        self.total = now = [x + y for x, y in zip(before, e)]
        if max(now) < self._first:
            return -1
        due = self._due
        over = [j for j in range(5) if now[j] >= due[j]]
        if not over:
            return -1
        # the motor whose threshold the cycle reached first (the smallest share of the cycle)
        return min(over, key=lambda j: (due[j] - before[j]) / e[j] if e[j] else 0.0)

    def replace(self, joint: int) -> None:
        """A new motor at ``joint``: exposure 0, a new threshold."""
        self.since[joint] = self.total[joint]
        self.threshold[joint] = float(draw_thresholds(self.rng, 1, self.wear.model)[0])
        self._due[joint] = self.since[joint] + self.threshold[joint]
        self._first = min(self._due)


class WearExposure:
    """The robot's failure clock counting motor wear (:class:`cell.sim.failure_clock.Exposure`):
    five budgets, one a motor (the exposure at which it wears out), each used at its
    exposure per second of the leg the robot is in, told of each cycle's leg times as it
    starts (the cycle's whole exposure, :meth:`cell.sim.wear.CycleWear.of_times`, is what the
    clock takes at once when no motor can wear out in it).  Within a leg the rate is the leg's
    mean, so a motor wears out at the leg's end exposure exactly and in between by linear
    interpolation."""

    cause = "wear"

    def __init__(self, wear: CycleWear, rng: np.random.Generator):
        self.wear, self.rng = wear, rng
        self._legs: Sequence[float] = (0.0,) * len(STRETCHES)
        """The leg times of the cycle under way."""
        self._rates: dict[int, list[float]] = {}
        """Each leg's exposure per second, as the clock asks for them (this cycle's)."""
        self.total = [0.0] * 5
        """Each motor's exposure over the run's cycles (for its life at this duty)."""

    def thresholds(self) -> list[float]:
        return draw_thresholds(self.rng, 5, self.wear.model).tolist()

    def renew(self, component: int) -> float:
        return float(draw_thresholds(self.rng, 1, self.wear.model)[0])

    def rates(self, leg: int) -> Sequence[float]:
        if leg < 0:
            return (0.0,) * 5
        rates = self._rates.get(leg)
        if rates is None:  # asked only of a cycle the clock counts leg by leg
            t = self._legs[leg]
            e = self.wear.stretches[leg].at_time(t)
            rates = self._rates[leg] = [x / t for x in e] if t > 0 else [0.0] * 5
        return rates

    def cycle(self, legs_s: Sequence[float]) -> Sequence[float]:
        self._legs, self._rates = legs_s, {}
        use = self.wear.of_times(legs_s)
        self.total = [a + b for a, b in zip(self.total, use)]
        return use

    def cycles(self, legs_s: Sequence[Sequence[float]]) -> np.ndarray:
        uses = self.wear.of_many(legs_s)
        # added in the cycles' order, as cycle by cycle (``add.accumulate`` adds in order)
        self.total = np.add.accumulate(np.vstack([self.total, uses]), axis=0)[-1].tolist()
        return uses

    def peak_rates(self) -> Sequence[float] | None:
        return self.wear.peak_rates  # nothing worn at rest


def _exposure(table: StepTable, timing: RobotTiming, settings: WearSettingsLike,
                      seed: int | np.random.SeedSequence) -> WearExposure:
    """The robot's failure clock counting motor wear (``wear:`` with ``failures.robot``)."""
    return WearExposure(CycleWear(table, timing, model_of(settings)), stream(seed, WEAR_STREAM))


def failures_log(exposure: WearExposure, downtime: Any, failures: Any, end_s: float) -> WearLog:
    """The wear measures of a run whose failures' robot clock counted ``exposure``: the stops
    with cause ``wear`` from its log, the repair time's mean for the expected availability."""
    from cell.scenario.failure_spec import frozen

    downtime.settle()  # the cycles the robot's clock has kept counted in the totals
    log = WearLog(exposure, float(frozen(failures.robot.time_to_repair).mean()))
    robot = [(cause, a, b) for name, cause, a, b, _ in downtime.all_stops(end_s)
             if name == "robot"]
    log.stops = [(a, b, -1) for cause, a, b in robot if cause == "wear"]
    log.held_s = sum(b - a for cause, a, b in robot if cause != "wear")
    return log


@dataclass(frozen=True)
class WearResult:
    """A run's wear: its measures (wear_* columns) and its stops for a worn motor."""

    measures: dict[str, float]
    stops: list[tuple[float, float, int]] = field(default_factory=list)
    """(from_s, to_s, joint) of each stop; joint -1 where the failures' log keeps none."""

    def __getitem__(self, key: str) -> float:
        return self.measures[key]


def count_on(downtime: Any, cell: Any, seed: int | np.random.SeedSequence) -> None:
    """Have the failures' robot clock count wear (before the failures are attached), if the
    scenario asks for wear and the robot can fail."""
    s = cell.scenario
    if downtime is None or not s.wear.enabled or s.failures.robot is None:
        return
    downtime.robot_exposure = _exposure(cell.table, cell.timing, s.wear, seed)


def alone(cell: Any, seed: int | np.random.SeedSequence, downtime: Any) -> WearStops | None:
    """``wear:`` without failures: the robot's motors' wear (:class:`WearStops`); else None."""
    if not cell.scenario.wear.enabled or downtime is not None:
        return None
    return wear_stops(cell.table, cell.timing, cell.scenario.wear, seed)


def measures(wear: WearLog | None, downtime: Any, end_s: float) -> WearResult | None:
    """The run's wear measures, whichever way the wear was counted (None: no wear)."""
    exposure = getattr(downtime, "robot_exposure", None)
    if isinstance(exposure, WearExposure):
        wear = failures_log(exposure, downtime, downtime.spec, end_s)
    return None if wear is None else WearResult(wear.row(end_s), wear.stops)
