"""Scenario files: read, validate and fill in the thesis's defaults.

A scenario is a YAML mapping whose sections mirror the dataclasses below.  Any
key left out takes the thesis's value (source in the comment beside it).  A bad
key or value raises :class:`~cell.errors.ScenarioError` naming the file, the
dotted key and the value, before anything is computed or written.

Keys are written dotted when overridden, as in a sweep file:
``controller.ideal_cycle_s``, ``robot.motors.nominal_fraction``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, is_dataclass
from pathlib import Path
from typing import Any, Literal, Union

import yaml

from cell.errors import ScenarioError

Point = tuple[float, float, float]
Five = tuple[float, float, float, float, float]


def _num(default: Any, *, lo: float | None = None, hi: float | None = None,
         lo_open: bool = False, doc: str = "") -> Any:
    """A numeric field with bounds (checked elementwise for tuples)."""
    meta = {"lo": lo, "hi": hi, "lo_open": lo_open, "doc": doc}
    if isinstance(default, (dict, list)):
        raise TypeError("use a tuple or a factory for mutable defaults")
    return field(default=default, metadata=meta)


def _sub(cls: type) -> Any:
    return field(default_factory=cls)


# --------------------------------------------------------------------------- cell
@dataclass(frozen=True)
class CellLayout:
    """Where the robot stands (thesis §4.1, §6.1, eq. 6.1)."""

    robot_base_in: Point = (-8.0, 8.0, 0.0)
    """Base axis on the table, global frame (§4.1)."""
    shoulder_height_in: float = _num(7.68, lo=0.0, lo_open=True)
    """Shoulder above the table (§6.1)."""
    robot_yaw_deg: float = -45.0
    """Robot frame = global rotated about z by this (eq. 6.1)."""
    belt_width_in: float = _num(8.0, lo=0.0, lo_open=True)
    """Both conveyors (§4.1); used for drawings only."""


# --------------------------------------------------------------------------- path
@dataclass(frozen=True)
class Moves:
    """Moves per regime; 459 in all, 460 points (§4.2)."""

    R1: int = _num(96, lo=2)
    R2: int = _num(117, lo=1)
    R3: int = _num(96, lo=2)
    R4: int = _num(150, lo=1)
    """150 equal chords reproduce the R IV length 35.5424 in (SPEC §3, derived)."""


@dataclass(frozen=True)
class PathSpec:
    """The transfer path B → F → G → K → B (thesis §4.2, Fig. 9)."""

    bot_in: Point = (-16.0, 0.0, 3.0)
    """B, beginning of tracking on the input belt (§4.2)."""
    f_in: Point = (-8.0, 0.0, 3.0)
    """F, end of input tracking (§4.2)."""
    g_in: Point = (0.0, 8.0, 3.0)
    """G, beginning of output tracking (§4.2)."""
    eot_in: Point = (0.0, 16.0, 3.0)
    """K, end of tracking on the output belt (§4.2)."""
    pick_height_in: float = _num(1.0, lo=0.0, lo_open=True)
    """Tool-centre height at lift-off LO: the cube's centre (§4.2, §6.2 f)."""
    place_height_in: float = _num(1.0, lo=0.0, lo_open=True)
    """Tool-centre height at touch-down TD (§4.2)."""
    lo_from_bot_in: float = _num(4.0, lo=0.0, lo_open=True)
    """Distance B → LO; the thesis does not place LO, SPEC §3 reads it as mid-window."""
    td_from_g_in: float = _num(4.0, lo=0.0, lo_open=True)
    """Distance G → TD (SPEC §3: mid-window)."""
    moves: Moves = _sub(Moves)


# --------------------------------------------------------------------------- part
@dataclass(frozen=True)
class Part:
    """The parts: oriented cubes (thesis §6.2 c, f)."""

    size_in: float = _num(2.0, lo=0.0, lo_open=True)
    """Cube edge; also the finger opening while holding it (§6.2 f)."""
    weight_oz: float = _num(4.0, lo=0.0)
    """Load carried from LO to TD (§6.2 f)."""


# --------------------------------------------------------------------------- robot
@dataclass(frozen=True)
class JointLimits:
    """Joint ranges in the DH convention of Table 3.1 (SPEC §2)."""

    theta1: tuple[float, float] = (-90.0, 90.0)
    theta2: tuple[float, float] = (-35.0, 144.0)
    theta3: tuple[float, float] = (-149.0, 0.0)
    theta4: tuple[float, float] = (-180.0, 0.0)
    """The thesis's ±90° about the in-line pose, which is θ4 = -90° here (SPEC §2)."""
    theta5: tuple[float, float] = (-180.0, 180.0)

    def as_array(self) -> list[tuple[float, float]]:
        return [self.theta1, self.theta2, self.theta3, self.theta4, self.theta5]


@dataclass(frozen=True)
class Hand:
    """Hand length against finger opening, eq. 6.2 (corrected in SPEC §2)."""

    l1_in: float = _num(1.884, lo=0.0)
    l2_in: float = _num(1.700, lo=0.0, lo_open=True)
    g0_in: float = _num(1.520, lo=0.0)
    open_in: float = _num(2.5, lo=0.0, lo_open=True)
    """Finger opening with no part; assumed (the thesis gives no figure)."""


@dataclass(frozen=True)
class Motors:
    """Stepper drives (thesis §6.1, SPEC §4)."""

    steps_per_rad: Five = _num((1125.0, 1125.0, 672.0, 241.0, 241.0), lo=0.0, lo_open=True)
    """TeachMover half-steps per radian: base, shoulder, elbow, pitch, roll."""
    max_rate_no_load_rad_s: Five = _num((0.4194527, 0.36, 0.82, 2.02, 2.02), lo=0.0, lo_open=True)
    """TeachMover no-load speeds, except the base: CALIBRATED to 0.4194527 rad/s
    (TeachMover 0.42) so that R IV at the nominal 75 % takes the thesis's 9.9855 s."""
    max_rate_full_load_rad_s: Five = _num((0.37, 0.15, 0.23, 1.31, 1.31), lo=0.0, lo_open=True)
    """TeachMover speeds carrying the full load (1 lb)."""
    full_load_oz: float = _num(16.0, lo=0.0, lo_open=True)
    nominal_fraction: float = _num(0.75, lo=0.0, hi=1.0, lo_open=True)
    """Nominal operation at 75 % of rated output, peak on request (§7.2)."""


@dataclass(frozen=True)
class Robot:
    """The MICROBOT arm (thesis §3, Table 3.1; link lengths from the TeachMover)."""

    l2_in: float = _num(7.0, lo=0.0, lo_open=True)
    l3_in: float = _num(7.0, lo=0.0, lo_open=True)
    joint_limits_deg: JointLimits = _sub(JointLimits)
    hand: Hand = _sub(Hand)
    motors: Motors = _sub(Motors)
    timing: Literal["constant-rate", "minimum-time"] = "constant-rate"
    """How the fastest R II and R IV are found: constant maximum step rates (the
    thesis) or the minimum-time planner (Shin & McKay)."""


# --------------------------------------------------------------------------- belts
@dataclass(frozen=True)
class Belts:
    """The two conveyors (thesis §4.3, §5.2)."""

    input_nominal_in_s: float = _num(3.0, lo=0.0, lo_open=True)
    output_nominal_in_s: float = _num(2.0, lo=0.0, lo_open=True)
    spacing_in: float = _num(45.0, lo=0.0, lo_open=True)
    """Required spacing of parts on the output belt (§4.3 f)."""
    spacing_tol_in: float = _num(0.25, lo=0.0)
    input_max_in_s: float = _num(12.0, lo=0.0, lo_open=True)
    """Fastest the input belt may run; assumed (§6.2 a gives belts infinite range)."""
    output_max_in_s: float = _num(12.0, lo=0.0, lo_open=True)
    """Fastest the output belt may run; assumed, as the input's."""
    input_length_in: float | None = _num(None, lo=0.0, lo_open=True)
    """Feeder drop point to B; the thesis gives none.  Empty: two nominal cycles of
    belt travel (2 × 3.0 × 22.5872 = 135.52 in), so the next part is usually on the
    belt when the controller looks ahead (§5.2)."""


# --------------------------------------------------------------------------- arrivals
WEIBULL_SHAPE = 1.0 / 0.2038  # eq. 6.9 exponent is 1/shape


@dataclass(frozen=True)
class Arrivals:
    """Inter-arrival times of parts (thesis §6.2 d, eq. 6.9)."""

    distribution: str = "weibull_min"
    """Any continuous distribution in scipy.stats, by name."""
    params: Mapping[str, float] = field(
        default_factory=lambda: {"c": WEIBULL_SHAPE, "loc": 17.6019, "scale": 5.4342})
    """Its parameters by scipy's names; the default is eq. 6.9."""
    trace_csv: str | None = None
    """A CSV of observed inter-arrival times (column ``interarrival_s``), used in
    order instead of the distribution. Relative to the scenario file."""


# --------------------------------------------------------------------------- controller
@dataclass(frozen=True)
class Controller:
    """Operating policy (thesis §5.3, §6.3)."""

    policy: Literal["adaptive", "non-adaptive"] = "adaptive"
    nominal_cycle_s: float = _num(22.5872, lo=0.0, lo_open=True)
    """Mean inter-arrival time: the ideal transfer time of §5.3."""
    ideal_cycle_s: float | None = _num(None, lo=0.0, lo_open=True)
    """The robot's fixed cycle for the non-adaptive policy (Table 7.1, column 1);
    shortened in R IV only. Empty means the nominal cycle."""


@dataclass(frozen=True)
class Run:
    parts: int = _num(500, lo=1)
    """Parts to arrive (§6.3)."""
    seed: int = _num(1984, lo=0)
    """Root of every random stream (numpy SeedSequence)."""


@dataclass(frozen=True)
class MinTime:
    """Minimum-time planner settings (Shin & McKay 1983; SPEC §9)."""

    grid_points: int = _num(460, lo=3)
    """Grid points per regime (R II, R IV), s scaled to [0, 1]; 460 as the thesis's path."""
    rate_fraction: float = _num(1.0, lo=0.0, hi=1.0, lo_open=True)
    """Joint velocity bounds = the motors' step rates at the regime's load (§6.1) times
    this: 1.0 is the peak, as in the thesis's minimum feasible cycle (§7.2)."""
    acceleration_bounds: bool = True
    """Apply ``qddot_max_rad_s2``; switch off when the dynamic model is to set the
    accelerations alone."""
    qddot_max_rad_s2: Five = _num((2.0, 2.0, 4.0, 8.0, 8.0), lo=0.0, lo_open=True)
    """Joint acceleration bounds; ASSUMED (a stepper indexer's ramp; the thesis has none)."""
    dynamics_file: str | None = None
    """YAML of the rigid-body model (relative to the scenario file); empty: no torque bounds."""


# --------------------------------------------------------------------------- scenario
@dataclass(frozen=True)
class Scenario:
    """A whole scenario: the cell, the robot, the parts and how the run goes."""

    name: str = "baseline"
    description: str = ""
    cell: CellLayout = _sub(CellLayout)
    path: PathSpec = _sub(PathSpec)
    part: Part = _sub(Part)
    robot: Robot = _sub(Robot)
    belts: Belts = _sub(Belts)
    arrivals: Arrivals = _sub(Arrivals)
    controller: Controller = _sub(Controller)
    run: Run = _sub(Run)
    mintime: MinTime = _sub(MinTime)
    source: str = field(default="<defaults>", metadata={"internal": True})
    """The file it was read from (not a YAML key)."""

    @property
    def base_dir(self) -> Path:
        return Path(self.source).parent if self.source != "<defaults>" else Path.cwd()

    def get(self, dotted: str) -> Any:
        obj: Any = self
        for part in dotted.split("."):
            obj = obj[part] if isinstance(obj, Mapping) else getattr(obj, part)
        return obj

    def with_overrides(self, overrides: Mapping[str, Any], file: object = None) -> Scenario:
        """A new scenario with dotted keys replaced, validated as if read from ``file``."""
        raw = to_dict(self)
        for key, value in overrides.items():
            set_dotted(raw, key, value, file or self.source)
        return from_dict(raw, file or self.source, source=self.source)


# --------------------------------------------------------------------------- validation
def _type_name(tp: Any) -> str:
    return getattr(tp, "__name__", None) or str(tp).replace("typing.", "")


def _check_bounds(value: float, meta: Mapping[str, Any], file: object, key: str, shown: Any) -> None:
    if not math.isfinite(value):
        raise ScenarioError(file, key, shown, "must be a finite number")
    lo, hi = meta.get("lo"), meta.get("hi")
    if lo is not None:
        if meta.get("lo_open") and value <= lo:
            raise ScenarioError(file, key, shown, f"must be greater than {lo:g}")
        if value < lo:
            raise ScenarioError(file, key, shown, f"must be at least {lo:g}")
    if hi is not None and value > hi:
        raise ScenarioError(file, key, shown, f"must be at most {hi:g}")


def _convert(tp: Any, value: Any, file: object, key: str, meta: Mapping[str, Any]) -> Any:
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin in (Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        (inner,) = [a for a in args if a is not type(None)]
        return _convert(inner, value, file, key, meta)
    if is_dataclass(tp):
        return build(tp, value, file, key)
    if origin is Literal:
        if value not in args:
            raise ScenarioError(file, key, value, "must be one of " + ", ".join(map(str, args)))
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise ScenarioError(file, key, value, "must be true or false")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ScenarioError(file, key, value, "must be a whole number")
        _check_bounds(value, meta, file, key, value)
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ScenarioError(file, key, value, "must be a number")
        _check_bounds(float(value), meta, file, key, value)
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            raise ScenarioError(file, key, value, "must be text")
        return value
    if origin is tuple:
        if not isinstance(value, (list, tuple)):
            raise ScenarioError(file, key, value, f"must be a list of {len(args)} numbers")
        if len(value) != len(args):
            raise ScenarioError(file, key, value, f"must have exactly {len(args)} entries")
        return tuple(_convert(a, v, file, f"{key}[{i}]", meta) for i, (a, v) in
                     enumerate(zip(args, value)))
    if origin in (Mapping, dict, typing.Mapping):
        if not isinstance(value, Mapping):
            raise ScenarioError(file, key, value, "must be a mapping")
        return {str(k): _convert(args[1], v, file, f"{key}.{k}", meta) for k, v in value.items()}
    raise TypeError(f"unsupported schema type {_type_name(tp)} at {key}")  # pragma: no cover


def build(cls: type, data: Any, file: object, prefix: str = "") -> Any:
    """Build dataclass ``cls`` from a mapping, rejecting unknown keys and bad values."""
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        raise ScenarioError(file, prefix or "(top level)", data, "must be a mapping of keys")
    hints = typing.get_type_hints(cls)
    allowed = {f.name: f for f in fields(cls) if not f.metadata.get("internal")}
    for k, v in data.items():
        if k not in allowed:
            raise ScenarioError(file, f"{prefix}.{k}" if prefix else str(k), v,
                                "unknown key (known: " + ", ".join(allowed) + ")")
    kwargs = {name: _convert(hints[name], data[name], file,
                             f"{prefix}.{name}" if prefix else name, f.metadata)
              for name, f in allowed.items() if name in data}
    return cls(**kwargs)


def to_dict(obj: Any) -> Any:
    """Plain YAML-able data of a scenario (no internal fields)."""
    if is_dataclass(obj):
        return {f.name: to_dict(getattr(obj, f.name)) for f in fields(obj)
                if not f.metadata.get("internal")}
    if isinstance(obj, tuple):
        return [to_dict(v) for v in obj]
    if isinstance(obj, Mapping):
        return {k: to_dict(v) for k, v in obj.items()}
    return obj


def known_key(dotted: str) -> bool:
    """Whether a dotted key names a setting of the scenario schema."""
    cls: Any = Scenario
    for part in dotted.split("."):
        if not (is_dataclass(cls)):
            return False
        names = {f.name: f for f in fields(cls) if not f.metadata.get("internal")}
        if part not in names:
            return False
        cls = typing.get_type_hints(cls)[part]
    return True


def set_dotted(raw: dict[str, Any], key: str, value: Any, file: object) -> None:
    if not known_key(key):
        raise ScenarioError(file, key, value, "unknown key: no such setting in a scenario")
    node = raw
    parts = key.split(".")
    for part in parts[:-1]:
        node = node.setdefault(part, {})
    node[parts[-1]] = value


def from_dict(raw: Any, file: object = "<dict>", source: str | None = None) -> Scenario:
    scenario = build(Scenario, raw, file)
    scenario = dataclasses.replace(scenario, source=str(source if source is not None else file))
    _cross_checks(scenario, file)
    return scenario


def _cross_checks(s: Scenario, file: object) -> None:
    """Checks that need more than one value."""
    import numpy as np
    import scipy.stats

    p = s.path
    window_in = float(np.linalg.norm(np.subtract(p.f_in, p.bot_in)))
    if not p.lo_from_bot_in < window_in:
        raise ScenarioError(file, "path.lo_from_bot_in", p.lo_from_bot_in,
                            f"must lie inside the input window B-F ({window_in:g} in)")
    window_out = float(np.linalg.norm(np.subtract(p.eot_in, p.g_in)))
    if not p.td_from_g_in < window_out:
        raise ScenarioError(file, "path.td_from_g_in", p.td_from_g_in,
                            f"must lie inside the output window G-K ({window_out:g} in)")
    for name, (lo, hi) in zip(("theta1", "theta2", "theta3", "theta4", "theta5"),
                              s.robot.joint_limits_deg.as_array()):
        if not lo < hi:
            raise ScenarioError(file, f"robot.joint_limits_deg.{name}", [lo, hi],
                                "lower limit must be below the upper")
    h = s.robot.hand
    for key, g in (("robot.hand.open_in", h.open_in), ("part.size_in", s.part.size_in)):
        if (g - h.g0_in) ** 2 / 2 > h.l2_in ** 2:
            raise ScenarioError(file, key, g, "finger opening beyond what the hand linkage "
                                "allows (eq. 6.2: (G - G0)^2 / 2 must not exceed L2^2)")
    a = s.arrivals
    if a.trace_csv is None:
        dist = getattr(scipy.stats, a.distribution, None)
        if not isinstance(dist, scipy.stats.rv_continuous):
            raise ScenarioError(file, "arrivals.distribution", a.distribution,
                                "not a continuous distribution in scipy.stats")
        try:
            frozen = dist(**a.params)
            mean = float(frozen.mean())
        except (TypeError, ValueError) as exc:
            raise ScenarioError(file, "arrivals.params", dict(a.params),
                                f"not accepted by scipy.stats.{a.distribution}: {exc}") from None
        if not math.isfinite(mean) or frozen.support()[0] < 0:
            raise ScenarioError(file, "arrivals.params", dict(a.params),
                                "inter-arrival times must be non-negative with a finite mean")
    else:
        trace_path = s.base_dir / a.trace_csv
        read_trace(trace_path, file)
    c = s.controller
    if c.ideal_cycle_s is not None and c.policy == "adaptive" and c.ideal_cycle_s != c.nominal_cycle_s:
        raise ScenarioError(file, "controller.ideal_cycle_s", c.ideal_cycle_s,
                            "the adaptive policy runs at the nominal cycle; "
                            "set controller.nominal_cycle_s instead")


def read_trace(path: Path, file: object = None) -> Any:
    """Inter-arrival times from a CSV trace: one column ``interarrival_s``, all > 0.

    Parsed once per version of the file (path, size, modification time), so a
    sweep's replications do not read it again.  The array is read-only.
    """
    if not path.is_file():
        raise ScenarioError(file or path, "arrivals.trace_csv", str(path), "no such file")
    st = path.stat()
    times = _parse_trace(str(path.resolve()), st.st_size, st.st_mtime_ns)
    if isinstance(times, str):
        raise ScenarioError(file or path, "arrivals.trace_csv", str(path), times)
    return times


@functools.lru_cache(maxsize=32)
def _parse_trace(path: str, size: int, mtime_ns: int) -> Any:
    """The trace's times, or why they cannot be used (a message)."""
    import numpy as np
    import pandas as pd

    del size, mtime_ns  # part of the cache key only
    try:
        frame = pd.read_csv(path)
    except Exception as exc:  # pandas raises many kinds
        return f"not a readable CSV: {exc}"
    if "interarrival_s" not in frame.columns:
        return "needs a column named interarrival_s"
    times = pd.to_numeric(frame["interarrival_s"], errors="coerce").to_numpy(dtype=float)
    bad = np.flatnonzero(~np.isfinite(times) | (times <= 0))
    if bad.size:
        return (f"row {bad[0] + 1} has inter-arrival time "
                f"{frame['interarrival_s'].iloc[bad[0]]}; times must be positive")
    if times.size == 0:
        return "has no inter-arrival times"
    times.setflags(write=False)
    return times


def read_yaml_mapping(path: str | Path, what: str = "scenario") -> dict[str, Any]:
    """A YAML file's top-level mapping (an empty file is an empty mapping)."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(path, "(file)", str(path), f"no such {what} file")
    try:
        raw = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ScenarioError(path, "(file)", str(path), f"not valid YAML: {exc}") from None
    raw = {} if raw is None else raw
    if not isinstance(raw, dict):
        raise ScenarioError(path, "(top level)", raw, "must be a mapping of keys")
    return raw


def load_scenario(path: str | Path, overrides: Mapping[str, Any] | None = None) -> Scenario:
    """Read and validate a scenario file; dotted ``overrides`` replace its values."""
    raw = read_yaml_mapping(path)
    for key, value in (overrides or {}).items():
        set_dotted(raw, key, value, path)
    return from_dict(raw, path, source=str(path))


def default_scenario() -> Scenario:
    """The thesis's cell with every default."""
    return from_dict({}, "<defaults>")
