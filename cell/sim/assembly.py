"""The cell assembled from a scenario: where scenario keys become the maths' values.

The maths (kinematics, path, motors, planner) works on small plain values
(:class:`~cell.arm.path.CellGeometry`, :class:`~cell.arm.motors.Motors`,
:class:`~cell.arm.mintime.regimes.PlannerBounds`) and knows nothing of files.  This
module builds those values from a :class:`~cell.scenario.schema.Scenario`, checks what
needs the robot's maths (reach, motor rates at the load, a nominal cycle the
motors can make), and turns any maths error into a
:class:`~cell.plumbing.errors.ScenarioError` naming the key and file that caused it.
Everything solved is cached on the plain values it depends on; the robot's
timing on disk as well (:mod:`cell.plumbing.cache`), so a start whose cell was solved
before neither solves the path nor imports what solving needs (scipy's splines).
"""

from __future__ import annotations

import functools
import hashlib
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cell.arm.kinematics import JOINT_NAMES, Arm, Hand, Placement
from cell.arm.motors import Motors, max_rates
from cell.plumbing.cache import Remembered, memo
from cell.plumbing.errors import CellError, InfeasibleError, NoMotionError, ScenarioError, UnreachableError
from cell.scenario import registry
from cell.scenario.arrivals import mean_interarrival
from cell.scenario.schema import MAX_TIME_S, Scenario, default_scenario, load_scenario
from cell.sim.policies.base import CellConstants, Policy
from cell.sim.robot import RobotTiming, build_timing, timing_from_plain, timing_to_plain

if TYPE_CHECKING:
    from cell.arm.path import CellGeometry
    from cell.arm.steptable import StepTable


# --------------------------------------------------------------------------- plain values
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

    changed = [k for k in GEOMETRY_KEYS if s.get(k) != _thesis().get(k)]
    for key in changed:
        trial = _with(s, key, _thesis().get(key))
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


def _with(s: Scenario, key: str, value: Any) -> Scenario | None:
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


# --------------------------------------------------------------------------- timing
def robot_timing(s: Scenario) -> RobotTiming:
    """The robot's regime segments (§6.1), floored by the planner under minimum-time timing."""
    key = _timing_key(s)
    timing = _TIMINGS.get(key) if key is not None else None
    if timing is None:
        timing = _solved_timing(s)
        if key is not None:
            _TIMINGS.put(key, timing)
    return _checked(s, timing)


def _solved_timing(s: Scenario) -> RobotTiming:
    step_table(s)  # reach and motor checks, with their keys
    if s.robot.timing != "minimum-time":
        return _timing(geometry_of(s), motors_of(s), None)
    bounds = planner_bounds(s)
    try:
        return _timing(geometry_of(s), motors_of(s), bounds)
    except InfeasibleError as exc:
        key = "robot.motors.max_rate_no_load_rad_s"
        if s.get(key) == _thesis().get(key):
            key = "mintime.dynamics_file"
        raise ScenarioError(s.source, key, s.get(key),
                            f"{exc} of the dynamic model ({s.mintime.dynamics_file})") from None
    except NoMotionError as exc:
        raise planner_error(s, exc, "robot.timing = 'minimum-time'") from None


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


@functools.cache
def _thesis() -> Scenario:
    """The thesis's cell, which a changed key is blamed against (read when first needed)."""
    return default_scenario()

#: Keys that set how fast the robot can move, in the order blame is given.
SPEED_KEYS = ("mintime.rate_fraction", "robot.motors.max_rate_no_load_rad_s",
              "robot.motors.max_rate_full_load_rad_s", "robot.motors.nominal_fraction",
              "robot.motors.full_load_oz", "part.weight_oz", "robot.motors.steps_per_rad")


def _checked(s: Scenario, t: RobotTiming) -> RobotTiming:
    """Refuse motors so slow that a regime would take longer than any time the tool
    handles (scenario times are bounded by 10⁶ s), naming the key that slowed them."""
    longest = max(t.r2_min_s, t.r4_min_s, t.r4_nominal_s, t.r1_pre.floor_s + t.r1_post.floor_s,
                  t.r3_pre.floor_s + t.r3_post.floor_s)
    if longest <= MAX_TIME_S:
        return t
    key = next((k for k in SPEED_KEYS if s.get(k) != _thesis().get(k)
                and (k != "mintime.rate_fraction" or s.robot.timing == "minimum-time")),
               "robot.motors.max_rate_no_load_rad_s")
    raise ScenarioError(s.source, key, s.get(key),
                        f"the motors would take {longest:.4g} s over one regime; at most "
                        f"{MAX_TIME_S:g} s")


@memo(maxsize=16)
def _timing(geometry: CellGeometry, motors: Motors, bounds: Any) -> RobotTiming:
    from cell.arm.steptable import StepTable

    table = StepTable.solve(geometry, motors)
    if bounds is None:
        return build_timing(table)
    from cell.arm.mintime.regimes import fastest_regime_times

    return build_timing(table, fastest_regime_times(geometry, motors, bounds))


def constants(s: Scenario, timing: RobotTiming) -> CellConstants:
    """The policies' constants; a cell that cannot run its nominal cycle is an error."""
    b, c = s.belts, s.controller
    for belt, where, most in (("input", "LO", timing.input_track_max_in_s),
                              ("output", "TD", timing.output_track_max_in_s)):
        speed = getattr(b, f"{belt}_nominal_in_s")
        if speed > most:
            key, value = _tracking_blame(s, belt, speed)
            speed_key = f"belts.{belt}_nominal_in_s"
            change = "" if key == speed_key else f" (with this {key}); set {speed_key} to " \
                f"at most {most:.4f}, or change {key}"
            raise ScenarioError(s.source, key, value,
                                f"the robot can follow the {belt} belt ({speed:g} in/s) down to "
                                f"{where} at no more than {most:.4f} in/s{change}")
    t = timing
    r1a, r1b = t.r1_time(b.input_nominal_in_s)
    r3a, r3b = t.r3_time(b.output_nominal_in_s)
    mean = mean_interarrival(s.arrivals, s.base_dir)
    cycle, source = (c.nominal_cycle_s, "scenario") if c.nominal_cycle_s is not None else \
        (mean, "arrivals")
    # The nominal split (docs/model.md): R IV at the base's nominal rate, R II the rest of
    # the cycle; a cycle too short for that takes R IV down toward its peak-rate time,
    # and one shorter than the robot's fastest is the fastest.
    r4 = max(t.r4_nominal_s, t.r4_min_s)
    r2 = cycle - r1a - r1b - r3a - r3b - r4
    if r2 < t.r2_min_s:
        r2 = t.r2_min_s
        r4 = cycle - r1a - r1b - r3a - r3b - r2
        if r4 < t.r4_min_s:
            r4, source = t.r4_min_s, "fastest"
            cycle = r1a + r1b + r2 + r3a + r3b + r4
    length = b.input_length_in if b.input_length_in is not None else \
        b.input_nominal_in_s * cycle * 2
    return CellConstants(
        timing=t, v_nom=b.input_nominal_in_s, u_nom=b.output_nominal_in_s,
        cycle_nom=cycle, input_max=min(b.input_max_in_s, 1e9),
        output_max=b.output_max_in_s, spacing=b.spacing_in, tol=b.spacing_tol_in,
        input_length=length, r1_pre_nom=r1a, r1_post_nom=r1b, r3_pre_nom=r3a,
        r3_post_nom=r3b, r4_nom=r4, r2_nom=r2, r1_nom=r1a + r1b,
        input_min=b.input_min_in_s, output_min=b.output_min_in_s, part_size=s.part.size_in,
        input_absorb=_absorbable(t, b.input_nominal_in_s, r1a + r1b + (r2 - t.r2_min_s)),
        mean_interarrival_s=mean, nominal_from=source,
        lookahead_margin_s=lookahead_margin(s))


def lookahead_margin(s: Scenario) -> float:
    """``sensor.margin_s``, or its default: 0 for the ideal look-ahead; three standard
    deviations of a sensor's error, in time at the nominal input speed."""
    m = s.sensor
    if m.margin_s is not None:
        return float(m.margin_s)
    if m.lookahead == "ideal":
        return 0.0
    return 3.0 * m.noise_sd_in / s.belts.input_nominal_in_s


def _absorbable(t: RobotTiming, v_nom: float, r1_most_s: float) -> float:
    """The slowest belt speed at which R I (B → F, tracking) takes at most ``r1_most_s``:
    R I only lengthens as the belt slows, so bisect on the speed (to 1e-9 relative)."""
    def r1(v: float) -> float:
        return sum(t.r1_time(v))

    if r1(v_nom) >= r1_most_s:
        return v_nom
    lo, hi = v_nom * 1e-6, v_nom
    if r1(lo) <= r1_most_s:
        return lo
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if r1(mid) <= r1_most_s else (mid, hi)
    return hi


def _tracking_blame(s: Scenario, belt: str, speed: float) -> tuple[str, Any]:
    """The belt's speed, unless a changed motor or load key alone makes it untrackable."""
    for key in SPEED_KEYS[1:-1]:
        if s.get(key) == _thesis().get(key):
            continue
        trial = _with(s, key, _thesis().get(key))
        if trial is None:
            continue
        t = robot_timing(trial)
        most = t.input_track_max_in_s if belt == "input" else t.output_track_max_in_s
        if speed <= most:
            return key, s.get(key)
    return f"belts.{belt}_nominal_in_s", speed


def nominal_cycle(s: Scenario) -> float:
    """The ideal cycle the controller aims at: ``controller.nominal_cycle_s``, else the
    arrivals' mean (or the robot's fastest cycle if the arrivals come faster)."""
    return constants(s, robot_timing(s)).cycle_nom


# --------------------------------------------------------------------------- the whole cell
class AssembledCell:
    """A scenario's cell, ready to run: its timing, constants and policy (and its solved
    path, :attr:`table`, solved when first asked for)."""

    __slots__ = ("scenario", "timing", "k", "policy")

    def __init__(self, scenario: Scenario, timing: RobotTiming, k: CellConstants,
                 policy: Policy):
        self.scenario, self.timing, self.k, self.policy = scenario, timing, k, policy

    @property
    def table(self) -> StepTable:
        """The scenario's solved path (the joint-step table)."""
        return step_table(self.scenario)


def make_policy(s: Scenario, k: CellConstants) -> Policy:
    """The scenario's policy, its every plan checked (:mod:`cell.sim.policies.check`)."""
    from cell.sim.policies.check import check_policy

    name = s.controller.policy
    cls = registry.load(name, s.source)
    try:
        policy = cls(k, s.controller, s.source)
    except CellError:
        raise
    except Exception as exc:  # noqa: BLE001 - a plug-in's failure, named
        raise registry.PluginError.of(name, "could not be built", exc) from exc
    return check_policy(policy, name, k)


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
    return AssembledCell(s, timing, k, make_policy(s, k))
