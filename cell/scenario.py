"""Scenario files: the schema, its defaults (the thesis's cell) and validation.

A scenario is a YAML mapping whose sections mirror the models below; a key left
out takes the thesis's value (source beside it).  The schema is a set of
pydantic models: they validate types and bounds, document every key (the
attribute docstrings) and give the JSON Schema that editors use for scenario
files (``cell schema``).  Every failure becomes one
:class:`~cell.errors.ScenarioError` line naming the file, the dotted key and
the value.  Checks that need the robot's maths (a point out of reach, a cycle
the motors cannot make) are made where the cell is assembled
(:mod:`cell.assembly`), with the same kind of message.

Magnitudes are bounded so that no input can exhaust the machine or overflow:
lengths and coordinates within 1,000 in, belt speeds up to 1,000 in/s, times up
to 10⁶ s, at most 10,000 moves per regime, 10⁷ parts per run, 10⁵ planner grid
points, and seeds below 2¹²⁸.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field, PrivateAttr, ValidationError, field_validator

from cell import registry
from cell.errors import ScenarioError
from cell.overrides import apply_overrides, merge
from cell.settings import Section, error_from_validation, model_at

MAX_LENGTH_IN = 1000.0
MAX_SPEED_IN_S = 1000.0
MAX_TIME_S = 1e6
MAX_PARTS = 10_000_000
MAX_MOVES = 10_000
MAX_GRID_POINTS = 100_000
MAX_SEED = 2**128


def _num(default: Any = None, *, gt: float | None = None, ge: float | None = None,
         le: float | None = None) -> Any:
    """A finite number field (ints accepted, booleans and text refused) with bounds."""
    return Field(default, strict=True, allow_inf_nan=False, gt=gt, ge=ge, le=le)


Coord = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=-MAX_LENGTH_IN,
                               le=MAX_LENGTH_IN)]
Point = tuple[Coord, Coord, Coord]
Positive = Annotated[float, Field(strict=True, allow_inf_nan=False, gt=0.0, le=1e9)]
NonNegative = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=0.0, le=1e9)]
Five = tuple[Positive, Positive, Positive, Positive, Positive]
#: A motor makes at least one step per radian, or it cannot follow any path.
StepsPerRad = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=1.0, le=1e7)]
Angle = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=-360.0, le=360.0)]
Range = tuple[Angle, Angle]


# --------------------------------------------------------------------------- cell
class LayoutSettings(Section):
    """Where the robot stands (thesis §4.1, §6.1, eq. 6.1)."""

    robot_base_in: Point = (-8.0, 8.0, 0.0)
    """Base axis on the table, global frame (§4.1)."""
    shoulder_height_in: float = _num(7.68, gt=0.0, le=MAX_LENGTH_IN)
    """Shoulder above the table (§6.1)."""
    robot_yaw_deg: float = _num(-45.0, ge=-360.0, le=360.0)
    """Robot frame = global rotated about z by this (eq. 6.1)."""
    belt_width_in: float = _num(8.0, gt=0.0, le=MAX_LENGTH_IN)
    """Both conveyors (§4.1); used for drawings only."""


# --------------------------------------------------------------------------- path
class MoveSettings(Section):
    """Moves per regime; 459 in all, 460 points (§4.2)."""

    R1: int = Field(96, strict=True, ge=2, le=MAX_MOVES)
    """Divisions along the input belt, B → F."""
    R2: int = Field(117, strict=True, ge=1, le=MAX_MOVES)
    """Divisions of the F → G arc."""
    R3: int = Field(96, strict=True, ge=2, le=MAX_MOVES)
    """Divisions along the output belt, G → K."""
    R4: int = Field(150, strict=True, ge=1, le=MAX_MOVES)
    """150 equal chords reproduce the R IV length 35.5424 in that Table 7.1's Vavg implies."""


class PathSettings(Section):
    """The transfer path B → F → G → K → B (thesis §4.2, Fig. 9)."""

    bot_in: Point = (-16.0, 0.0, 3.0)
    """B, beginning of tracking on the input belt (§4.2)."""
    f_in: Point = (-8.0, 0.0, 3.0)
    """F, end of input tracking (§4.2)."""
    g_in: Point = (0.0, 8.0, 3.0)
    """G, beginning of output tracking (§4.2)."""
    eot_in: Point = (0.0, 16.0, 3.0)
    """K, end of tracking on the output belt (§4.2)."""
    pick_height_in: float = _num(1.0, gt=0.0, le=MAX_LENGTH_IN)
    """Tool-centre height at lift-off LO: the cube's centre (§4.2, §6.2 f)."""
    place_height_in: float = _num(1.0, gt=0.0, le=MAX_LENGTH_IN)
    """Tool-centre height at touch-down TD (§4.2)."""
    lo_from_bot_in: float = _num(4.0, gt=0.0, le=MAX_LENGTH_IN)
    """Distance B → LO; the thesis does not place LO: mid-window (docs/model.md)."""
    td_from_g_in: float = _num(4.0, gt=0.0, le=MAX_LENGTH_IN)
    """Distance G → TD: mid-window, as LO."""
    moves: MoveSettings = MoveSettings()


# --------------------------------------------------------------------------- part
class PartSettings(Section):
    """The parts: oriented cubes (thesis §6.2 c, f)."""

    size_in: float = _num(2.0, gt=0.0, le=MAX_LENGTH_IN)
    """Cube edge; also the finger opening while holding it (§6.2 f)."""
    weight_oz: float = _num(4.0, ge=0.0, le=1e6)
    """Load carried from LO to TD (§6.2 f)."""


# --------------------------------------------------------------------------- robot
class JointLimitSettings(Section):
    """Joint ranges (degrees) in the DH convention of Table 3.1 (docs/model.md)."""

    theta1: Range = (-90.0, 90.0)
    """Base ±90°."""
    theta2: Range = (-35.0, 144.0)
    """Shoulder +144° / -35°."""
    theta3: Range = (-149.0, 0.0)
    """Elbow 0° / -149°."""
    theta4: Range = (-180.0, 0.0)
    """Wrist pitch: the thesis's ±90° about the in-line pose, which is θ4 = -90° here."""
    theta5: Range = (-180.0, 180.0)
    """Wrist roll ±180°."""

    def as_list(self) -> list[tuple[float, float]]:
        return [self.theta1, self.theta2, self.theta3, self.theta4, self.theta5]


class HandSettings(Section):
    """Hand length against finger opening G, eq. 6.2 (corrected: docs/sources.md)."""

    l1_in: float = _num(1.884, ge=0.0, le=MAX_LENGTH_IN)
    """L1 of w11 = L1 + √(L2² − (G − G0)²/2)."""
    l2_in: float = _num(1.700, gt=0.0, le=MAX_LENGTH_IN)
    """L2 of eq. 6.2."""
    g0_in: float = _num(1.520, ge=0.0, le=MAX_LENGTH_IN)
    """G0 of eq. 6.2."""
    open_in: float = _num(2.5, gt=0.0, le=MAX_LENGTH_IN)
    """Finger opening with no part; ASSUMED (the thesis gives no figure)."""


class MotorSettings(Section):
    """Stepper drives (thesis §6.1): rates linear in the load, 75 % nominal."""

    steps_per_rad: tuple[StepsPerRad, StepsPerRad, StepsPerRad, StepsPerRad, StepsPerRad] = (
        1125.0, 1125.0, 672.0, 241.0, 241.0)
    """TeachMover half-steps per radian: base, shoulder, elbow, pitch, roll."""
    max_rate_no_load_rad_s: Five = (0.4194527, 0.36, 0.82, 2.02, 2.02)
    """TeachMover no-load speeds, except the base: CALIBRATED to 0.4194527 rad/s
    (TeachMover 0.42) so that R IV at the nominal 75 % takes the thesis's 9.9855 s."""
    max_rate_full_load_rad_s: Five = (0.37, 0.15, 0.23, 1.31, 1.31)
    """TeachMover speeds carrying the full load (1 lb)."""
    full_load_oz: float = _num(16.0, gt=0.0, le=1e6)
    """The load of those full-load figures."""
    nominal_fraction: float = _num(0.75, gt=0.0, le=1.0)
    """Nominal operation at 75 % of rated output, peak on request (§7.2)."""


class RobotSettings(Section):
    """The MICROBOT arm (thesis §3, Table 3.1; link lengths from the TeachMover)."""

    l2_in: float = _num(7.0, gt=0.0, le=MAX_LENGTH_IN)
    """Upper arm (TeachMover)."""
    l3_in: float = _num(7.0, gt=0.0, le=MAX_LENGTH_IN)
    """Forearm (TeachMover)."""
    joint_limits_deg: JointLimitSettings = JointLimitSettings()
    hand: HandSettings = HandSettings()
    motors: MotorSettings = MotorSettings()
    timing: Literal["constant-rate", "minimum-time"] = "constant-rate"
    """How the fastest R II and R IV are found: constant maximum step rates (the
    thesis) or the minimum-time planner (Shin & McKay)."""


# --------------------------------------------------------------------------- belts
class BeltSettings(Section):
    """The two conveyors (thesis §4.3, §5.2)."""

    input_nominal_in_s: float = _num(3.0, gt=0.0, le=MAX_SPEED_IN_S)
    """Nominal input belt speed (§5.2)."""
    output_nominal_in_s: float = _num(2.0, gt=0.0, le=MAX_SPEED_IN_S)
    """Nominal output belt speed (§5.2)."""
    spacing_in: float = _num(45.0, gt=0.0, le=MAX_LENGTH_IN)
    """Required spacing of parts on the output belt (§4.3 f)."""
    spacing_tol_in: float = _num(0.25, ge=0.0, le=MAX_LENGTH_IN)
    """Tolerance on that spacing (§4.3 f)."""
    input_min_in_s: float = _num(1.5, gt=0.0, le=MAX_SPEED_IN_S)
    """Slowest the adaptive controller may run the input belt; ASSUMED: half the nominal
    speed (§6.2 a gives belts unlimited range; docs/assumptions.md)."""
    input_max_in_s: float = _num(12.0, gt=0.0, le=MAX_SPEED_IN_S)
    """Fastest the input belt may run; ASSUMED (§6.2 a gives belts unlimited range)."""
    output_min_in_s: float = _num(0.25, gt=0.0, le=MAX_SPEED_IN_S)
    """Slowest the output belt may run; ASSUMED: a set-down part then clears a 2 in part's
    size before the next touch-down even at the robot's shortest cycle (docs/assumptions.md)."""
    output_max_in_s: float = _num(12.0, gt=0.0, le=MAX_SPEED_IN_S)
    """Fastest the output belt may run; ASSUMED, as the input's."""
    input_length_in: float | None = _num(None, gt=0.0, le=MAX_LENGTH_IN * 10)
    """Feeder drop point to B; the thesis gives none.  Empty: two nominal cycles of
    belt travel (2 × 3.0 × 22.5872 = 135.52 in), so the next part is usually on the
    belt when the controller looks ahead (§5.2)."""


# --------------------------------------------------------------------------- arrivals
WEIBULL_SHAPE = 1.0 / 0.2038
"""Eq. 6.9's exponent is 1/shape."""


class ArrivalSettings(Section):
    """Inter-arrival times of parts (thesis §6.2 d, eq. 6.9)."""

    distribution: str = "weibull_min"
    """Any continuous distribution in scipy.stats, by name."""
    params: dict[str, Annotated[float, Field(strict=True, allow_inf_nan=True)]] = Field(
        default_factory=lambda: {"c": WEIBULL_SHAPE, "loc": 17.6019, "scale": 5.4342})
    """Its parameters by scipy's names; the default is eq. 6.9."""
    mean_s: float | None = _num(None, gt=0.0, le=MAX_TIME_S)
    """With ``cv``: the mean inter-arrival time; the family's shape and scale are then
    derived from the two (no location) and ``params`` is not used."""
    cv: float | None = _num(None, gt=0.0, le=10.0)
    """With ``mean_s``: the coefficient of variation (sd / mean) of the inter-arrival time;
    ``gamma``, ``weibull_min``, ``lognorm`` and ``expon`` (shifted; cv ≤ 1) take it."""
    trace_csv: str | None = None
    """A CSV of observed inter-arrival times (column ``interarrival_s``), used in
    order instead of the distribution; relative to the scenario file."""


# --------------------------------------------------------------------------- controller
class ControllerSettings(Section):
    """Operating policy (thesis §5.3, §6.3)."""

    policy: str = "adaptive"
    """A registered policy: ``adaptive`` (§5.3), ``non-adaptive`` (§6.3), or a plug-in."""
    nominal_cycle_s: float | None = _num(None, gt=0.0, le=MAX_TIME_S)
    """The ideal transfer time of §5.3, the mean inter-arrival time.  Empty: the mean of
    the arrivals (the distribution's, or the trace's); the thesis quotes 22.5872 s."""
    ideal_cycle_s: float | None = _num(None, gt=0.0, le=MAX_TIME_S)
    """The robot's fixed cycle for the non-adaptive policy (Table 7.1, column 1);
    shortened in R IV only.  Empty: the nominal cycle."""

    @field_validator("policy")
    @classmethod
    def _known_policy(cls, value: str) -> str:
        if value not in registry.names():
            raise ValueError("must be one of " + ", ".join(registry.names()))
        return value


class RunSettings(Section):
    """How long a run is and where its random numbers come from (§6.3)."""

    parts: int = Field(500, strict=True, ge=1, le=MAX_PARTS)
    """Parts to arrive (§6.3: 500)."""
    warmup_parts: Annotated[int, Field(strict=True, ge=0, le=MAX_PARTS)] | Literal["auto"] = 0
    """Parts left out of every measure as warm-up: a number, or ``auto`` (MSER-5 on the
    delivery intervals).  The thesis's terminating 500-part runs keep 0."""
    seed: int = Field(1984, strict=True, ge=0, lt=MAX_SEED)
    """Root of every random stream (numpy SeedSequence)."""


class MinTimeSettings(Section):
    """Minimum-time planner settings (Shin & McKay 1983; docs/model.md)."""

    grid_points: int = Field(460, strict=True, ge=3, le=MAX_GRID_POINTS)
    """Grid points per regime (R II, R IV), s scaled to [0, 1]; 460 as the thesis's path."""
    rate_fraction: float = _num(1.0, gt=0.0, le=1.0)
    """Joint velocity bounds = the motors' step rates at the regime's load (§6.1) times
    this: 1.0 is the peak, as in the thesis's minimum feasible cycle (§7.2)."""
    acceleration_bounds: bool = Field(True, strict=True)
    """Apply ``qddot_max_rad_s2``; switch off when the dynamic model is to set the
    accelerations alone."""
    qddot_max_rad_s2: Five = (2.0, 2.0, 4.0, 8.0, 8.0)
    """Joint acceleration bounds; ASSUMED (a stepper indexer's ramp; the thesis has none)."""
    dynamics_file: str | None = None
    """YAML of the rigid-body model (relative to the scenario file); empty: no torque bounds."""


# --------------------------------------------------------------------------- scenario
class Scenario(Section):
    """A whole scenario: the cell, the robot, the parts and how the run goes."""

    name: str = "baseline"
    """A short name, printed in summaries."""
    description: str = ""
    """One line on what the scenario is for."""
    cell: LayoutSettings = LayoutSettings()
    path: PathSettings = PathSettings()
    part: PartSettings = PartSettings()
    robot: RobotSettings = RobotSettings()
    belts: BeltSettings = BeltSettings()
    arrivals: ArrivalSettings = ArrivalSettings()
    controller: ControllerSettings = ControllerSettings()
    run: RunSettings = RunSettings()
    mintime: MinTimeSettings = MinTimeSettings()

    _source: str = PrivateAttr(default="<defaults>")

    @property
    def source(self) -> str:
        """The file it was read from (``<defaults>`` for the built-in one)."""
        return self._source

    @property
    def base_dir(self) -> Path:
        """Where the files it names (trace, dynamics model) are looked for."""
        return Path(self._source).parent if self._source != "<defaults>" else Path.cwd()

    def get(self, dotted: str) -> Any:
        obj: Any = self
        for part in dotted.split("."):
            obj = obj[part] if isinstance(obj, Mapping) else getattr(obj, part)
        return obj

    def to_dict(self) -> dict[str, Any]:
        """Plain YAML-able data (tuples as lists)."""
        return _plain(self.model_dump())

    def with_overrides(self, overrides: Mapping[str, Any], file: object = None) -> Scenario:
        """A new scenario with dotted keys replaced, validated as if read from ``file``."""
        raw = apply_overrides(self.to_dict(), overrides, file or self._source, is_section)
        return validate(raw, file or self._source, source=self._source)


def _plain(obj: Any) -> Any:
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, Mapping):
        return {k: _plain(v) for k, v in obj.items()}
    return obj


# --------------------------------------------------------------------------- validation
def validate(raw: Any, file: object = "<dict>", source: str | None = None) -> Scenario:
    """The scenario of a raw mapping; the first problem as one :class:`ScenarioError`."""
    if not isinstance(raw, Mapping):
        raise ScenarioError(file, "(top level)", raw, "must be a mapping of keys")
    try:
        scenario = Scenario.model_validate(raw)
    except ValidationError as exc:
        raise error_from_validation(exc, raw, file, Scenario) from None
    scenario._source = str(source if source is not None else file)
    _cross_checks(scenario, file)
    return scenario


def is_section(path: tuple[str, ...]) -> bool:
    """Whether a dotted path names a section (a model) of the schema."""
    return model_at(Scenario, list(path)) is not None


def known_key(dotted: str) -> bool:
    """Whether a dotted key names a setting of the schema, or an entry of a mapping one
    (``arrivals.params.scale``)."""
    parts = dotted.split(".")
    model: Any = Scenario
    for i, part in enumerate(parts):
        field = model.model_fields.get(part)
        if field is None:
            return False
        annotation = field.annotation
        if isinstance(annotation, type) and issubclass(annotation, BaseModel):
            model = annotation
            continue
        rest = parts[i + 1:]
        is_mapping = getattr(annotation, "__origin__", None) is dict
        return not rest or (is_mapping and len(rest) == 1 and bool(rest[0]))
    return True


def _cross_checks(s: Scenario, file: object) -> None:
    """Checks that need more than one value but no maths."""
    h = s.robot.hand
    for key, g in (("robot.hand.open_in", h.open_in), ("part.size_in", s.part.size_in)):
        if (g - h.g0_in) ** 2 / 2 > h.l2_in ** 2:
            raise ScenarioError(file, key, g, "finger opening beyond what the hand linkage "
                                "allows (eq. 6.2: (G - G0)^2 / 2 must not exceed L2^2)")
    p, m = s.path, s.path.moves
    for (start, end), (key, value), moves in (
            (("bot_in", "f_in"), ("lo_from_bot_in", p.lo_from_bot_in), m.R1),
            (("g_in", "eot_in"), ("td_from_g_in", p.td_from_g_in), m.R3)):
        window = math.dist(getattr(p, start), getattr(p, end))
        if window < s.part.size_in:
            if window >= _DEFAULTS.part.size_in:   # the window is the thesis's; the part grew
                raise ScenarioError(file, "part.size_in", s.part.size_in, f"longer than the "
                                    f"{window:.4g} in tracking window from path.{start} to path.{end}")
            moved, other = (start, end) if getattr(p, start) != getattr(_DEFAULTS.path, start) \
                else (end, start)
            raise ScenarioError(file, f"path.{moved}", list(getattr(p, moved)),
                                f"lies {window:.4g} in from path.{other}: a tracking window must "
                                f"be at least a part's size ({s.part.size_in:g} in) long")
        step = window / moves
        if not step <= value <= window - step:
            raise ScenarioError(file, f"path.{key}", value,
                                f"must leave at least one move ({step:.4g} in) of the "
                                f"{window:g} in window on each side")
    for i, (lo, hi) in enumerate(s.robot.joint_limits_deg.as_list()):
        if not lo < hi:
            raise ScenarioError(file, f"robot.joint_limits_deg.theta{i + 1}", [lo, hi],
                                "lower limit must be below the upper")
    b = s.belts
    if b.spacing_in - b.spacing_tol_in < s.part.size_in:
        key, value = ("belts.spacing_tol_in", b.spacing_tol_in) if b.spacing_tol_in > 0 and \
            b.spacing_in >= s.part.size_in else ("belts.spacing_in", b.spacing_in)
        raise ScenarioError(file, key, value, f"parts {s.part.size_in:g} in long set down "
                            f"{b.spacing_in:g} ± {b.spacing_tol_in:g} in apart could overlap")
    w = s.run.warmup_parts
    if isinstance(w, int) and w >= s.run.parts:
        raise ScenarioError(file, "run.warmup_parts", w,
                            f"must be fewer than run.parts ({s.run.parts})")
    for belt in ("input", "output"):
        lo, nom, hi = (getattr(b, f"{belt}_{k}_in_s") for k in ("min", "nominal", "max"))
        if hi < nom:
            raise ScenarioError(file, f"belts.{belt}_max_in_s", hi,
                                f"must be at least belts.{belt}_nominal_in_s ({nom:g})")
        if lo > nom:
            raise ScenarioError(file, f"belts.{belt}_min_in_s", lo,
                                f"must be at most belts.{belt}_nominal_in_s ({nom:g})")
    from cell.arrivals import check_arrivals

    check_arrivals(s.arrivals, s.base_dir, file)


# --------------------------------------------------------------------------- files
def load_scenario(path: str | Path, overrides: Mapping[str, Any] | None = None) -> Scenario:
    """Read and validate a scenario file (or a built-in one by name, ``baseline``);
    dotted ``overrides`` replace its values."""
    from cell import catalog
    from cell.yamlio import load_mapping

    path = catalog.resolve(path)
    raw = merge(_DEFAULTS.to_dict(), load_mapping(path, "scenario"), (), is_section)
    raw = apply_overrides(raw, overrides or {}, path, is_section)
    return validate(raw, path, source=str(path))


def default_scenario() -> Scenario:
    """The thesis's cell with every default."""
    return _DEFAULTS


_DEFAULTS = Scenario()


def json_schema() -> dict[str, Any]:
    """The JSON Schema of a scenario file, for editors (``cell schema``)."""
    schema = Scenario.model_json_schema()
    schema["title"] = "cell scenario"
    return schema
