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


def state_energy_j(lines: Timelines, energy: EnergySettings, busy: bool = True) -> float:
    """Σ over every piece of equipment's states of power × duration, J (``busy`` False: the
    robot's busy rows left out, the arm's own energy counting for them)."""
    return float(sum(energy.power(equipment, state) * (b - a)
                     for equipment, rows in lines.items() for state, a, b in rows
                     if busy or (equipment, state) != ("robot", "busy")))


class ArmTransfers:
    """A picked part's plan -> the electrical energy (J) of the arm's motion over its transfer,
    from the dynamic model (:meth:`cell.arm.energy.ArmEnergy.transfer` on the plan's six
    stretch times), summed as the run goes.  A call costs 0.2-0.5 ms; a fixed-cycle robot
    repeats its times, so each set of six is computed once."""

    def __init__(self, arm: Any, segments: Sequence[str]):
        self.arm, self.segments, self.total_j, self.transfers = arm, tuple(segments), 0.0, 0
        self.known: dict[tuple[float, ...], float] = {}

    def __call__(self, plan: Any) -> float:
        times = (plan.r1_pre, plan.r1_post, plan.r2, plan.r3_pre, plan.r3_post, plan.r4)
        joules = self.known.get(times)
        if joules is None:
            joules = self.known[times] = self.arm.transfer(dict(zip(self.segments, times))).electrical_j
        self.total_j += joules
        self.transfers += 1
        return joules


def arm_energy_of(cell: Any) -> ArmTransfers | None:
    """The arm's energy per transfer, with ``energy.arm: dynamics``; else None."""
    s = cell.scenario
    if s.energy is None or s.energy.arm != "dynamics":
        return None
    from cell.arm.energy import ArmEnergy, planned_legs
    from cell.arm.steptable import SEGMENTS
    from cell.scenario.dynamics_file import load_dynamics
    from cell.sim.scenario_values import dynamics_path, geometry_of, motors_of, planner_bounds

    path = dynamics_path(s)
    assert path is not None  # energy.arm: dynamics without one is refused (check_energy)
    model, geometry, table = load_dynamics(path), geometry_of(s), cell.table
    planned = None
    if s.robot.timing == "minimum-time":
        from cell.arm.mintime.regimes import plan_regimes

        results = plan_regimes(geometry, motors_of(s), planner_bounds(s))
        planned = planned_legs(table, model, geometry, results)
    return ArmTransfers(ArmEnergy.build(table, model, geometry, planned), SEGMENTS)


def timelines(scenario: Any, lines: Timelines, column: Callable[[str], np.ndarray],
              downtime: Any, end_s: float, stops: Sequence[tuple[str, str, float, float, Any]]
              ) -> Timelines:
    """The run's timelines for its energy: OEE's (``lines``), or made here if it made none,
    with the sensor's when the cell uses one."""
    out = dict(lines) if lines else oee.timelines(column, downtime, end_s, stops)
    if "sensor" not in out and scenario.sensor.lookahead == "sensor":
        out["sensor"] = [("up", 0.0, end_s)]
    return out


def measure(r: RunSummary, scenario: Any, lines: Timelines, log: Any, downtime: Any,
            end_s: float, stops: Sequence[tuple[str, str, float, float, Any]],
            line: Any = None) -> Timelines:
    """With an ``energy:`` section, fill the summary's energy columns and return the
    timelines states.csv shows; without one, ``lines`` as they are.  ``log``: the run's
    :class:`~cell.sim.simulation.RunLog` (its ``column`` and, with ``arm: dynamics``, its
    :class:`ArmTransfers`); ``line``: a layout's :class:`~cell.sim.line.Line`, whose every
    station's states count (states.csv's rows, station by station)."""
    energy, column = scenario.energy, log.column
    if energy is None:
        return lines
    lines = timelines(scenario, lines, column, downtime, end_s, stops)
    arm = log.energy_of
    joules = sum(state_energy_j(own, energy, busy=arm is None)
                 for own in ([lines] if line is None else [o for _, o in line.timelines]))
    if arm is not None:
        joules += arm.total_j
        r.arm_energy_per_transfer_j = arm.total_j / arm.transfers if arm.transfers else float("nan")
    _, good = oee.produced_and_good(column, scenario.quality.rule)
    r.energy_kwh = joules / J_PER_KWH
    r.energy_per_good_part_wh = joules / J_PER_WH / good if good else float("nan")
    return lines
