"""The checks that need the robot's maths (reach, motor rates at the load, regimes the tool
can time, the planner's "no motion"), each naming the key to blame.

The key blamed is, of the keys that differ from the thesis's cell, the one whose thesis value
alone mends it (found by solving again).
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from cell.arm.kinematics import JOINT_NAMES
from cell.arm.motors import max_rates
from cell.plumbing.errors import CellError, NoMotionError, ScenarioError, UnreachableError
from cell.scenario.schema import MAX_TIME_S, Scenario, default_scenario, load_scenario
from cell.sim.robot import RobotTiming
from cell.sim.scenario_values import dynamics_path, geometry_of, motors_of, planner_bounds

if TYPE_CHECKING:
    from cell.arm.steptable import StepTable


# --------------------------------------------------------------------------- the path
def step_table(s: Scenario) -> StepTable:
    """The scenario's solved path; a point out of reach names the key that put it there."""
    from cell.arm.steptable import StepTable

    _check_motor_rates(s)
    geometry, motors = geometry_of(s), motors_of(s)
    try:
        return StepTable.solve(geometry, motors)
    except UnreachableError as exc:
        key, value, hint = _blame(s)
        raise ScenarioError(s.source, key, value, f"{exc}{hint}") from None


#: Keys that shape the path, in the order blame is given.
GEOMETRY_KEYS = (
    "cell.robot_base_in", "cell.shoulder_height_in", "cell.robot_yaw_deg",
    "path.bot_in", "path.f_in", "path.g_in", "path.eot_in", "path.pick_height_in",
    "path.place_height_in", "path.lo_from_bot_in", "path.td_from_g_in",
    "robot.l2_in", "robot.l3_in", "robot.hand.l1_in", "robot.hand.l2_in", "robot.hand.g0_in",
    "robot.hand.open_in", "part.size_in",
    *(f"robot.joint_limits_deg.theta{j}" for j in range(1, 6)),
    *(f"path.moves.R{j}" for j in range(1, 5)),
)


def _blame(s: Scenario) -> tuple[str, Any, str]:
    """The key whose value makes the path unreachable: of the keys that differ from the
    thesis's cell, the first whose thesis value alone makes every point reachable."""
    from cell.arm.path import build_path

    changed = [k for k in GEOMETRY_KEYS if s.get(k) != thesis().get(k)]
    for key in changed:
        trial = with_key(s, key, thesis().get(key))
        if trial is None:
            continue
        try:
            build_path(geometry_of(trial))
        except UnreachableError:
            continue
        return key, s.get(key), f" (with the thesis's {key} it is reachable)"
    if changed:
        others = ", ".join(changed[1:])
        return changed[0], s.get(changed[0]), \
            f" (together with {others})" if others else ""
    return "path", None, ""  # pragma: no cover - the thesis's own cell is reachable


def with_key(s: Scenario, key: str, value: Any) -> Scenario | None:
    try:
        return s.with_overrides({key: value})
    except ScenarioError:
        return None


def _check_motor_rates(s: Scenario) -> None:
    """Rates are linear in the load (§6.1): each must stay positive at the part's weight."""
    m = s.robot.motors
    rates = max_rates(s.part.weight_oz, motors_of(s))
    if np.all(rates > 0):
        return
    j = int(np.flatnonzero(rates <= 0)[0])
    no, full = m.max_rate_no_load_rad_s[j], m.max_rate_full_load_rad_s[j]
    limit = m.full_load_oz * no / (no - full) if no > full else math.inf
    raise ScenarioError(s.source, "part.weight_oz", s.part.weight_oz,
                        f"the {JOINT_NAMES[j]} motor's rate, linear in the load (§6.1), would be "
                        f"{rates[j]:.4g} steps/s at this load: the parts may weigh less than "
                        f"{limit:.4g} oz")


def planner_error(s: Scenario, exc: NoMotionError, asked: str) -> CellError:
    """The planner's "no motion" as one line naming its cause: a drive too weak to hold the
    arm (the dynamics file, the key that made it so, the torques), no bound on the
    accelerations at all (``mintime.acceleration_bounds``), else the scenario and ``asked``, the
    key that asked for the planner, with the dynamic model planned with."""
    from cell.arm.mintime.regimes import WeakDriveError
    from cell.scenario import catalog
    from cell.scenario.dynamics_file import load_dynamics

    mt = s.mintime
    if not mt.acceleration_bounds and mt.dynamics_file is None:
        key, other = "mintime.acceleration_bounds", "mintime.dynamics_file empty"
        try:  # the file itself names a dynamics file, emptied by --set: blame that key
            if load_scenario(s.source).mintime.dynamics_file is not None:
                key, other = "mintime.dynamics_file", "mintime.acceleration_bounds false"
        except (CellError, OSError):
            pass
        return ScenarioError(s.source, key, s.get(key), f"with {other} too, nothing bounds the "
                             "minimum-time planner's accelerations: the fastest motion would need "
                             "infinite acceleration (set either)")
    path = dynamics_path(s)
    if isinstance(exc, WeakDriveError) and path is not None:
        built_in = "microbot_dynamics.yaml"  # against which the user's file is compared
        key, value, also = exc.blame(planner_bounds(s).dynamics,
                                     load_dynamics(catalog.path(built_in)), built_in)
        return ScenarioError(path, key, value,
                             f"{exc} (the dynamic model of {catalog.shown(s.source)}{also})")
    model_used = f" (dynamic model {path})" if path is not None else ""
    return CellError(f"{s.source}: {asked}: {exc}{model_used}")


@functools.cache
def thesis() -> Scenario:
    """The thesis's cell, which a changed key is blamed against (read when first needed)."""
    return default_scenario()


#: Keys that set how fast the robot can move, in the order blame is given.
SPEED_KEYS = ("mintime.rate_fraction", "robot.motors.max_rate_no_load_rad_s",
              "robot.motors.max_rate_full_load_rad_s", "robot.motors.nominal_fraction",
              "robot.motors.full_load_oz", "part.weight_oz", "robot.motors.steps_per_rad")


def checked(s: Scenario, t: RobotTiming) -> RobotTiming:
    """Refuse motors so slow that a regime would take longer than any time the tool
    handles (scenario times are bounded by 10⁶ s), naming the key that slowed them."""
    longest = max(t.r2_min_s, t.r4_min_s, t.r4_nominal_s, t.r1_pre.floor_s + t.r1_post.floor_s,
                  t.r3_pre.floor_s + t.r3_post.floor_s)
    if longest <= MAX_TIME_S:
        return t
    key = next((k for k in SPEED_KEYS if s.get(k) != thesis().get(k)
                and (k != "mintime.rate_fraction" or s.robot.timing == "minimum-time")),
               "robot.motors.max_rate_no_load_rad_s")
    raise ScenarioError(s.source, key, s.get(key),
                        f"the motors would take {longest:.4g} s over one regime; at most "
                        f"{MAX_TIME_S:g} s")

