"""The cell assembled from a scenario: where scenario keys become the maths' values.

:func:`assemble` makes every check and solves every value a run needs, from modules by job:
the maths' plain values (:mod:`cell.sim.scenario_values`), the checks that need the robot's
maths and the key each blames (:mod:`cell.sim.physics_checks`), the robot's timing solved and
cached (:mod:`cell.sim.timing_cache`), and the constants and policy
(:mod:`cell.sim.policy_setup`).  Their names are imported from those modules, not from here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from cell.plumbing.errors import ScenarioError
from cell.scenario.schema import Scenario, StationSettings
from cell.sim.physics_checks import step_table
from cell.sim.policies.base import CellConstants, Policy
from cell.sim.policy_setup import constants, make_policy
from cell.sim.robot import RobotTiming
from cell.sim.scenario_values import dynamics_path
from cell.sim.timing_cache import robot_timing

if TYPE_CHECKING:
    from cell.arm.steptable import StepTable

__all__ = ["AssembledCell", "assemble"]


# --------------------------------------------------------------------------- the whole cell
class AssembledCell:
    """A scenario's cell, ready to run: its timing, constants and policy (and its solved
    path, :attr:`table`, solved when first asked for)."""

    __slots__ = ("scenario", "timing", "k", "policy", "line")

    def __init__(self, scenario: Scenario, timing: RobotTiming, k: CellConstants,
                 policy: Policy):
        self.scenario, self.timing, self.k, self.policy = scenario, timing, k, policy
        self.line: list[tuple[StationSettings, AssembledCell]] = []
        """Each station after the first (``stations:``), assembled (docs/layout.md)."""

    @property
    def table(self) -> StepTable:
        """The scenario's solved path (the joint-step table)."""
        return step_table(self.scenario)


def assemble(s: Scenario) -> AssembledCell:
    """Every check and every solved value the simulation needs, errors first (a dynamics file
    is read and checked even when the timing does not use it)."""
    if s.robot.timing != "minimum-time" and (unused := dynamics_path(s)) is not None:
        from cell.scenario.dynamics_file import load_dynamics

        load_dynamics(unused)
    timing = robot_timing(s)
    k = constants(s, timing)
    from cell.sim.sensor import sensor_position

    sensor_position(s.sensor, k.input_length, s.source)  # a sensor beyond the feeder: refused
    cell = AssembledCell(s, timing, k, make_policy(s, k))
    for station, own in s.line:
        try:
            cell.line.append((station, assemble(own)))
        except ScenarioError as exc:  # the station's key, named in full
            raise ScenarioError(exc.file, f"stations.{station.name}.{exc.key}", exc.value,
                                exc.why) from None
    return cell
