"""The run's energy from its states (docs/usage.md, "Energy and cost"): each piece of
equipment draws the ``energy:`` section's power in each of its states, so the run's energy is
the sum over states.csv's rows of power × duration.  Only with an ``energy:`` section; without
one nothing here runs and no output changes.

The timelines are those OEE makes with failures (:func:`cell.sim.oee.timelines`); a run
without stops has none made for OEE, so they are made here.  The look-ahead sensor has a
timeline of its own only when it can fail; a cell that uses one (``sensor.lookahead:
sensor``) and has no such timeline gets one, up the whole run, so its draw is counted and
states.csv shows it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from cell.scenario.energy_sections import EnergySettings
from cell.sim import oee
from cell.sim.records import RunSummary

Timelines = dict[str, list[tuple[str, float, float]]]
J_PER_KWH = 3.6e6
J_PER_WH = 3600.0


def state_energy_j(lines: Timelines, energy: EnergySettings) -> float:
    """Σ over every piece of equipment's states of power × duration, J."""
    return float(sum(energy.power(equipment, state) * (b - a)
                     for equipment, rows in lines.items() for state, a, b in rows))


def timelines(scenario: Any, lines: Timelines, column: Callable[[str], np.ndarray],
              downtime: Any, end_s: float, stops: Sequence[tuple[str, str, float, float, Any]]
              ) -> Timelines:
    """The run's timelines for its energy: OEE's (``lines``), or made here if it made none,
    with the sensor's when the cell uses one."""
    out = dict(lines) if lines else oee.timelines(column, downtime, end_s, stops)
    if "sensor" not in out and scenario.sensor.lookahead == "sensor":
        out["sensor"] = [("up", 0.0, end_s)]
    return out


def measure(r: RunSummary, scenario: Any, lines: Timelines,
            column: Callable[[str], np.ndarray], downtime: Any, end_s: float,
            stops: Sequence[tuple[str, str, float, float, Any]]) -> Timelines:
    """With an ``energy:`` section, fill the summary's energy columns and return the
    timelines states.csv shows; without one, ``lines`` as they are."""
    energy = scenario.energy
    if energy is None:
        return lines
    lines = timelines(scenario, lines, column, downtime, end_s, stops)
    joules = state_energy_j(lines, energy)
    _, good = oee.produced_and_good(column, scenario.quality.rule)
    r.energy_kwh = joules / J_PER_KWH
    r.energy_per_good_part_wh = joules / J_PER_WH / good if good else float("nan")
    return lines
