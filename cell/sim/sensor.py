"""The look-ahead sensor (``sensor.lookahead: sensor``; docs/model.md, "The look-ahead").

A sensor ``position_in`` before B reports each part as the input belt carries it
past: ``latency_s`` later, the controller is told the part was ``position_in`` (plus
a normal error of ``noise_sd_in``) from B when it passed; the latency is the
sensor's known, fixed delay, so the controller dates the report back by it, and a
latency only makes a report late.  With ``miss_probability`` a part passes
unreported.  The controller knows its own belt's travel (it commands the belt), so
from a report it can tell where the part is at any later instant, to the sensor's
error.

Each part's error and miss are drawn from streams of their own, spawned from the
run's seed (keys :data:`NOISE_STREAM` and :data:`MISS_STREAM`), one draw per part
in part order: the arrivals, and any other stream, are unchanged by the sensor,
and two policies or two sensor settings see the same parts (common random numbers).

The sensor's state is brought up to date when the controller reads it, at a
decision (a part at B): the input belt's schedule between two decisions is fixed,
so the instant a part passed the sensor is exact whenever it is computed.  A
part's index is the only thing the sensor takes from the belt besides its travel:
the parts the feeder has dropped (:attr:`cell.sim.conveyors.InputConveyor.x_fed`);
nothing here reads the feeder's schedule.
"""

from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, Any

import numpy as np

from cell.plumbing.errors import ScenarioError
from cell.scenario.arrivals import stream

if TYPE_CHECKING:
    from cell.sim.conveyors import InputConveyor

#: The sensor's child streams of the run's root SeedSequence (the feeder's is 0).
NOISE_STREAM = 20
MISS_STREAM = 21


def sensor_position(settings: Any, input_length_in: float, file: object = None) -> float:
    """The sensor's distance before B (in): ``position_in``, or the feeder's drop point."""
    position = settings.position_in
    if position is None:
        return input_length_in
    if position > input_length_in + 1e-9:
        raise ScenarioError(file, "sensor.position_in", position,
                            f"is beyond the feeder's drop point, {input_length_in:.4g} in before "
                            "B (belts.input_length_in): parts are not on the belt there yet")
    return float(position)


class Sensor:
    """Reports parts as they pass ``position`` inches before B (see the module's text)."""

    def __init__(self, settings: Any, position_in: float, conveyor: InputConveyor,
                 n_parts: int, seed: Any):
        self.position = position_in
        self.latency = float(settings.latency_s)
        self.conveyor = conveyor
        self._length = conveyor.length_in
        sd, p = float(settings.noise_sd_in), float(settings.miss_probability)
        self.error = stream(seed, NOISE_STREAM).normal(0.0, sd, n_parts) if sd > 0 else \
            np.zeros(n_parts)
        self.misses = stream(seed, MISS_STREAM).random(n_parts) < p if p > 0 else \
            np.zeros(n_parts, dtype=bool)
        self._scanned = -1
        """The highest part index taken from the belt so far."""
        self._pending: deque[tuple[int, float]] = deque()
        """(part, belt travel at which it passes the sensor): on the belt, not yet past it."""
        self._passed: deque[tuple[int, float]] = deque()
        """(part, instant its report arrives): past the sensor, report still on its way."""
        self.reports: deque[tuple[int, float, float]] = deque()
        """(part, reported distance from B, belt travel when it passed): what the controller
        has been told, oldest first."""

    def update(self, now: float, current: int) -> None:
        """Bring the reports up to ``now``; forget parts up to ``current`` (at B or gone)."""
        belt, length, position = self.conveyor.belt, self._length, self.position
        for j, x in self.conveyor.x_fed.items():  # the parts on the belt, in drop order
            if j > self._scanned:
                self._scanned = j
                self._pending.append((j, x + length - position))
        pending, passed, latency = self._pending, self._passed, self.latency
        x_now = belt.travel(now)
        while pending and pending[0][1] <= x_now + 1e-9:
            j, x_pass = pending.popleft()
            if not self.misses[j]:
                passed.append((j, belt.time_at(x_pass) + latency))
        reports, error = self.reports, self.error
        while passed and passed[0][1] <= now:
            j, told = passed.popleft()
            reports.append((j, position + float(error[j]), belt.travel(told - latency)))
        while reports and reports[0][0] <= current:
            reports.popleft()
