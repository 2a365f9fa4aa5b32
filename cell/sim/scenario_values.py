"""The maths' plain values built from a scenario: the cell's geometry, the motors, the
minimum-time planner's bounds and the dynamics file they read.

The maths (kinematics, path, motors, planner) works on small plain values
(:class:`~cell.arm.path.CellGeometry`, :class:`~cell.arm.motors.Motors`,
:class:`~cell.arm.mintime.regimes.PlannerBounds`) and knows nothing of files; this module
is where scenario keys become those values.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cell.arm.kinematics import Arm, Hand, Placement
from cell.arm.motors import Motors
from cell.plumbing.errors import ScenarioError
from cell.scenario.schema import Scenario

if TYPE_CHECKING:
    from cell.arm.path import CellGeometry


def geometry_of(s: Scenario) -> CellGeometry:
    """Everything the path's shape and joint angles depend on."""
    from cell.arm.path import CellGeometry, Route

    p, r = s.path, s.robot
    m = p.moves
    h = r.hand
    return CellGeometry(
        route=Route(p.bot_in, p.f_in, p.g_in, p.eot_in, p.pick_height_in, p.place_height_in,
                    p.lo_from_bot_in, p.td_from_g_in, (m.R1, m.R2, m.R3, m.R4)),
        placement=Placement(s.cell.robot_base_in, s.cell.shoulder_height_in,
                            math.radians(s.cell.robot_yaw_deg)),
        arm=Arm(r.l2_in, r.l3_in, tuple((math.radians(lo), math.radians(hi))
                                        for lo, hi in r.joint_limits_deg.as_list())),
        hand=Hand(h.l1_in, h.l2_in, h.g0_in, h.open_in),
        part_size_in=s.part.size_in, part_weight_oz=s.part.weight_oz)


def motors_of(s: Scenario) -> Motors:
    m = s.robot.motors
    return Motors(m.steps_per_rad, m.max_rate_no_load_rad_s, m.max_rate_full_load_rad_s,
                  m.full_load_oz, m.nominal_fraction)


def planner_bounds(s: Scenario) -> Any:
    """The minimum-time planner's bounds (``mintime`` section; the dynamics file read)."""
    from cell.arm.mintime.regimes import PlannerBounds
    from cell.scenario.dynamics_file import load_dynamics

    mt = s.mintime
    path = dynamics_path(s)
    model = load_dynamics(path) if path is not None else None
    return PlannerBounds(mt.grid_points, mt.rate_fraction, mt.qddot_max_rad_s2,
                         mt.acceleration_bounds, model)


def dynamics_path(s: Scenario) -> Path | None:
    """The scenario's dynamics file: beside the scenario, else a built-in one of that name
    (so a copy of ``baseline.yaml`` anywhere still finds ``microbot_dynamics.yaml``)."""
    from cell.scenario import catalog

    name = s.mintime.dynamics_file
    if name is None:
        return None
    beside = s.base_dir / name
    if beside.is_file():
        return beside
    built_in = catalog.path(name)
    if Path(name).name == name and built_in.is_file():
        return built_in
    raise ScenarioError(s.source, "mintime.dynamics_file", name, f"no such file (looked for {beside})")
