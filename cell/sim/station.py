"""A transfer station: the robot, its controller and its windows on the two belts (thesis §4.1).

The station is built from the assembled cell (:func:`cell.sim.assembly.assemble`): its input
conveyor (the window on the input belt, from the drop point to B and on to F), its output
conveyor (the window from G to TD and on), the robot between them, and the controller that
plans each part's cycle when it reaches B.  What can stop them (failures, planned stops, wear)
is handed to each at construction.  Upstream a source drops parts on :attr:`Station.input`
(the feeder, :mod:`cell.sim.feeder`); downstream the output conveyor hands each part set down
to ``delivered`` (the run's log).  A second station would be another instance whose input is fed
by a process that takes the first station's parts off its output belt (docs/architecture.md,
"Stations").
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import simpy

from cell.scenario.sections import SensorSettings
from cell.sim import wear_clock
from cell.sim.buffer import Buffer
from cell.sim.controller import Controller, RunLog, SensorView, View
from cell.sim.conveyors import InputConveyor, OutputConveyor
from cell.sim.failures import BeltStops, Downtime
from cell.sim.robot import Robot
from cell.sim.sensor import Sensor, sensor_position

if TYPE_CHECKING:
    from cell.sim.assembly import AssembledCell
    from cell.sim.records import Part
    from cell.sim.wear_clock import WearStops


class Station:
    """One robot with its controller and its two belts' windows, built from the cell.

    Built in two steps so that its processes start in the cell's order (the belts and the
    robot, then the source that feeds it, then the controller): :meth:`control` starts the
    controller once what comes to the station (``fed_s``) is known.
    """

    def __init__(self, env: simpy.Environment, cell: AssembledCell, seed: Any,
                 delivered: Callable[[Part], Any], told: Callable[[int], Any],
                 downtime: Downtime | None):
        k = cell.k
        self.env, self.cell, self.seed, self.downtime = env, cell, seed, downtime
        self.input = InputConveyor(env, k.v_nom, k.input_length, told(0),
                                   None if downtime is None else BeltStops(downtime, "input_belt"))
        """The window on the input belt: parts from the drop point to B (and on to F)."""
        self.output = OutputConveyor(env, k.u_nom, delivered, told(1), downtime is not None)
        """The window on the output belt: parts set down at TD, their spacing measured."""
        self.wear: WearStops | None = wear_clock.alone(cell, seed, downtime)
        """The motors' wear without failures (None: none, or counted by the failure clock)."""
        self.robot = Robot(env, self.output.placed,
                           None if downtime is None else downtime.robot, self.wear)
        self.view: View | None = None
        self.controller: Controller | None = None
        self.buffer: Buffer | None = None
        """The buffer before B (``buffer:`` with places; None: none, the thesis's cell)."""

    def control(self, fed_s: list[float] | None, n_parts: int, log: RunLog) -> None:
        """Start the controller: its view of the cell (the schedule of what comes, ``fed_s``,
        read by the ideal look-ahead; or a physical sensor's reports: ``fed_s`` None, a
        station fed by another, sees with an ideal sensor at its drop point), and the buffer
        its parts come through if it has one (docs/layout.md)."""
        cell, s = self.cell, self.cell.scenario
        self.view = _view(cell, self.seed, n_parts, fed_s, self.input, self.output)
        source = None
        if s.buffer is not None and s.buffer.places > 0:
            self.buffer = Buffer(self.env, s.buffer, self.robot, self.input.at_bot, log)
            self.view.queue, source = self.buffer.waiting, self.buffer.gate
        self.controller = Controller(self.env, cell.k, cell.policy, self.view, self.input,
                                     self.output, self.robot, log, s.controller.policy, source)
        if self.downtime is not None:
            self.downtime.attach(self.input, self.output, self.view, log)

    def close(self, end_s: float) -> None:
        """The run is over: every belt change handed on (a floor planned after the last
        touch-down never ran)."""
        self.input.belt.close()
        self.output.belt.close(until=end_s)


def _view(cell: AssembledCell, seed: Any, n: int, fed_s: list[float] | None,
          conveyor: InputConveyor, output: OutputConveyor) -> View:
    """What the controller sees: the feeder's schedule (``sensor.lookahead: ideal``), or only
    what a physical sensor has reported (``sensor``; a station fed by another, with no
    schedule, the ideal look-ahead as a perfect sensor at its drop point)."""
    s, k = cell.scenario, cell.k
    if s.sensor.lookahead == "ideal" and fed_s is not None:
        return View(k, fed_s, n, conveyor, output)
    settings = s.sensor if s.sensor.lookahead == "sensor" else PERFECT
    position = sensor_position(settings, k.input_length, s.source)
    return SensorView(k, Sensor(settings, position, conveyor, n, seed), n, conveyor, output)


#: The ideal look-ahead of a station fed by another: a sensor at its drop point that sees
#: every part at once, where it is (docs/layout.md).
PERFECT = SensorSettings(lookahead="sensor")
