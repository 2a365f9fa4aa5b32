"""The robot's timing solved for a scenario, cached on the plain values it depends on, in
this process and on disk (:mod:`cell.plumbing.cache`), so a start whose cell was solved
before neither solves the path nor imports what solving needs (scipy's splines)."""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING, Any

from cell.arm.motors import Motors
from cell.plumbing.cache import Remembered, memo
from cell.plumbing.errors import InfeasibleError, NoMotionError, ScenarioError
from cell.scenario.schema import Scenario
from cell.sim.physics_checks import checked, planner_error, step_table, thesis
from cell.sim.robot import RobotTiming, build_timing, timing_from_plain, timing_to_plain
from cell.sim.scenario_values import dynamics_path, geometry_of, motors_of, planner_bounds

if TYPE_CHECKING:
    from cell.arm.path import CellGeometry


def robot_timing(s: Scenario) -> RobotTiming:
    """The robot's regime segments (§6.1), floored by the planner under minimum-time timing."""
    key = _timing_key(s)
    timing = _TIMINGS.get(key) if key is not None else None
    if timing is None:
        timing = _solved_timing(s)
        if key is not None:
            _TIMINGS.put(key, timing)
    return checked(s, timing)


def _solved_timing(s: Scenario) -> RobotTiming:
    step_table(s)  # reach and motor checks, with their keys
    if s.robot.timing != "minimum-time":
        return _timing(geometry_of(s), motors_of(s), None)
    bounds = planner_bounds(s)
    try:
        return _timing(geometry_of(s), motors_of(s), bounds)
    except InfeasibleError as exc:
        key = "robot.motors.max_rate_no_load_rad_s"
        if s.get(key) == thesis().get(key):
            key = "mintime.dynamics_file"
        raise ScenarioError(s.source, key, s.get(key),
                            f"{exc} of the dynamic model ({s.mintime.dynamics_file})") from None
    except NoMotionError as exc:
        raise planner_error(s, exc, "robot.timing = 'minimum-time'") from None


#: The scenario sections the robot's timing is solved from: the cell's layout, the path,
#: the part, the arm with its motors and timing, the planner's settings (read only under
#: minimum-time timing, which also reads the dynamics file: its bytes are in the key).
TIMING_SECTIONS = ("cell", "path", "part", "robot", "mintime")


def _timing_key(s: Scenario) -> dict[str, Any] | None:
    """The plain values the robot's timing depends on (None: not to be cached; a key that is
    not JSON data is not cached either, :class:`~cell.plumbing.cache.Remembered` sees to that)."""
    key: dict[str, Any] = {name: getattr(s, name).model_dump() for name in TIMING_SECTIONS}
    if s.robot.timing == "minimum-time" and s.mintime.dynamics_file is not None:
        try:
            path = dynamics_path(s)
            assert path is not None  # dynamics_file is set
            key["dynamics_file_sha256"] = hashlib.sha256(path.read_bytes()).hexdigest()
        except (OSError, ValueError):  # no such file: solving it says so, with its key
            return None
    return key


#: Timings solved before, in this process or an earlier one, by the values they depend on.
_TIMINGS: Remembered[RobotTiming] = Remembered("timing", timing_to_plain, timing_from_plain)


@memo(maxsize=16)
def _timing(geometry: CellGeometry, motors: Motors, bounds: Any) -> RobotTiming:
    from cell.arm.steptable import StepTable

    table = StepTable.solve(geometry, motors)
    if bounds is None:
        return build_timing(table)
    from cell.arm.mintime.regimes import fastest_regime_times

    return build_timing(table, fastest_regime_times(geometry, motors, bounds))

