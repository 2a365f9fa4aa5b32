"""What a run costs (docs/usage.md, "Energy and cost"): with a ``costs:`` section, summary.csv's
``cost_per_good_part`` and ``cost_per_h``; without one nothing here runs.

cost = lost parts × part_value + energy (kWh) × energy_per_kwh + the robot's downtime (h) ×
downtime_per_h + repairs × repair + maintenance stops × maintenance + Σ options_per_h × the
run's hours, each option counted as the scenario has it (the sensor with ``sensor.lookahead:
sensor``, the adaptive controller under the ``adaptive`` policy, a robot per robot, a buffer
place per place, for each station of a layout: docs/layout.md).  Lost parts: those ridden off
and those scrapped from the hand (the summary's
``parts_missed`` and ``parts_scrapped``); repairs: every failure in failures.csv, of any piece
of equipment (a worn motor's included); the downtime and the repairs of a layout are every
station's; good parts: by ``quality.rule``, as OEE counts them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from cell.sim import oee
from cell.sim.records import RunSummary

#: Robots in the cell (the options' ``robot`` is per robot).
ROBOTS = 1


def options_per_h(scenario: Any) -> float:
    """The hourly cost of the options the scenario has, its stations' summed (``stations:``)."""
    o = scenario.costs.options_per_h
    total = 0.0
    for s in (scenario, *(own for _, own in scenario.line)):
        total += (o.robot * ROBOTS + (o.sensor if s.sensor.lookahead == "sensor" else 0.0)
                  + (o.adaptive_controller if s.controller.policy == "adaptive" else 0.0)) + \
            (o.buffer_place * s.buffer.places if s.buffer is not None else 0.0)
    return total


def cost(c: Any, lost: Any, energy_kwh: Any, down_h: Any, repairs: Any, maintenance: Any,
         options_per_h: Any, hours: Any) -> Any:
    """The cost (the module's sum) under the ``costs:`` section ``c``: numbers, or arrays of
    them (a study's options, cell.reporting.money_reading)."""
    return (lost * c.part_value + energy_kwh * c.energy_per_kwh + down_h * c.downtime_per_h
            + repairs * c.repair + maintenance * c.maintenance + options_per_h * hours)


def run_cost(r: RunSummary, scenario: Any, stops: Sequence[tuple[str, str, float, float, Any]],
             down_fraction: float | None = None) -> float:
    """The run's cost (see the module's text) from its summary and failures.csv's rows;
    ``down_fraction``: the robots' downtime over the run (None: the summary's robot's)."""
    hours = r.sim_end_s / 3600.0
    maintenance = sum(1 for _, cause, *_ in stops if cause == "maintenance")
    energy_kwh = r.energy_kwh if r.energy_kwh is not None else 0.0
    down = r.robot_down_fraction if down_fraction is None else down_fraction
    return float(cost(scenario.costs, r.parts_missed + r.parts_scrapped, energy_kwh,
                      down * hours, len(stops) - maintenance, maintenance,
                      options_per_h(scenario), hours))


def measure(r: RunSummary, scenario: Any, stops: Sequence[tuple[str, str, float, float, Any]],
            column: Callable[[str], np.ndarray], line: Any = None) -> None:
    """With a ``costs:`` section, fill the summary's cost columns (``line``: a layout's
    :class:`~cell.sim.line.Line`, whose every station's stops and downtime count)."""
    if scenario.costs is None:
        return
    if line is None:
        total = run_cost(r, scenario, stops)
    else:
        total = run_cost(r, scenario, [row for rows in line.stopped for row in rows],
                         sum(row.down_fraction for row in line.rows))
    _, good = oee.produced_and_good(column, scenario.quality.rule)
    r.cost_per_good_part = total / good if good else math.nan
    r.cost_per_h = total / (r.sim_end_s / 3600.0) if r.sim_end_s > 0 else math.nan
