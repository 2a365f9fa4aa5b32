"""Scenario files: the whole scenario, its defaults (the thesis's cell), validation, reading.

A scenario is a YAML mapping whose sections are the models of :mod:`cell.scenario.sections`; a
key left out takes the thesis's value.  The schema is a set of pydantic models: they
validate types and bounds, document every key (the attribute docstrings) and give the
JSON Schema that editors use for scenario files (``cell schema``).  Every failure
becomes one :class:`~cell.plumbing.errors.ScenarioError` line naming the file, the dotted key and
the value.  Checks that need the robot's maths (a point out of reach, a cycle the
motors cannot make) are made where the cell is assembled (:mod:`cell.sim.assembly`), with
the same kind of message.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from pydantic import BaseModel, Field, PrivateAttr, ValidationError

from cell.plumbing.errors import ScenarioError
from cell.scenario.calendar_section import CalendarSettings
from cell.scenario.energy_sections import (  # noqa: F401 - the schema, re-exported
    CostSettings,
    EnergySettings,
    check_energy,
)
from cell.scenario.failure_sections import (  # noqa: F401 - the schema, re-exported
    FailureSettings,
    WearSettings,
)
from cell.scenario.fields import Section, error_from_validation, model_at, unwrap_optional
from cell.scenario.layout_sections import (  # noqa: F401 - the schema, re-exported
    MAX_STATIONS,
    STATION_SECTIONS,
    BufferSettings,
    StationSettings,
    check_layout,
    named_station,
)
from cell.scenario.overrides import apply_overrides, merge
from cell.scenario.run_length import keep_one_length, lengths_given
from cell.scenario.sections import (  # noqa: F401 - the schema, re-exported
    MAX_GRID_POINTS,
    MAX_LENGTH_IN,
    MAX_MOVES,
    MAX_PARTS,
    MAX_SEED,
    MAX_SPEED_IN_S,
    MAX_TIME_S,
    WEIBULL_SHAPE,
    ArrivalSettings,
    BeltSettings,
    ControllerSettings,
    HandSettings,
    JointLimitSettings,
    LayoutSettings,
    MinTimeSettings,
    MotorSettings,
    MoveSettings,
    PartSettings,
    PathSettings,
    QualitySettings,
    RobotSettings,
    RunSettings,
    SensorSettings,
)


# --------------------------------------------------------------------------- scenario
class Scenario(Section):
    """A whole scenario: the cell, the robot, the parts and how the run goes."""

    name: str = "baseline"
    """A short name, printed in summaries; a file without one is named after the file."""
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
    wear: WearSettings = WearSettings()
    failures: FailureSettings | None = None
    """Breakdowns and repairs (docs/model.md, "When equipment fails"); absent: none."""
    sensor: SensorSettings = SensorSettings()
    quality: QualitySettings = QualitySettings()
    """Which parts OEE counts as good; absent: every part set down."""
    energy: EnergySettings | None = None
    """Power per state and the arm's motion energy (docs/usage.md, "Energy and cost"); absent:
    no energy measured."""
    costs: CostSettings | None = None
    """Money: lost parts, energy, downtime, repairs, maintenance, options (docs/usage.md, "Energy
    and cost"); absent: no cost measured."""
    buffer: BufferSettings | None = None
    """An accumulating buffer before B (docs/layout.md); absent or ``places: 0``: none."""
    stations: list[StationSettings] | None = Field(None, max_length=MAX_STATIONS)
    """More stations, downstream on the input line or in series (docs/layout.md); the
    scenario's own cell is the first; absent: the thesis's one cell."""

    calendar: CalendarSettings | None = None
    """The plant's working week: shifts, breaks, working days (docs/usage.md, "A shift
    calendar"); absent: the cell works without a break from the run's start."""

    _source: str = PrivateAttr(default="<defaults>")
    _stations: list[tuple[StationSettings, Scenario]] = PrivateAttr(default_factory=list)

    @property
    def line(self) -> list[tuple[StationSettings, Scenario]]:
        """Each station after the first: its settings and its own scenario (the scenario's
        sections with its overrides), in order; empty without ``stations:``."""
        return self._stations

    @property
    def has_layout(self) -> bool:
        """Whether a ``buffer:`` or ``stations:`` section is given (stations.csv is written)."""
        return self.buffer is not None or self.stations is not None

    @property
    def source(self) -> str:
        """The file it was read from (``<defaults>`` for the built-in one)."""
        return self._source

    @property
    def base_dir(self) -> Path:
        """Where the files it names (trace, dynamics model) are looked for."""
        return Path(self._source).parent if self._source != "<defaults>" else Path.cwd()

    def get(self, dotted: str) -> Any:
        parts = dotted.split(".")
        if parts[0] == "stations" and len(parts) > 2:  # a station's own value, by its name
            for station, scenario in self._stations:
                if station.name == parts[1]:
                    own = getattr(station, parts[2]) if parts[2] not in STATION_SECTIONS else None
                    return own if len(parts) == 3 and parts[2] not in STATION_SECTIONS \
                        else scenario.get(".".join(parts[2:]))
            raise KeyError(dotted)
        obj: Any = self
        for part in parts:
            obj = obj[part] if isinstance(obj, Mapping) else getattr(obj, part)
        return obj

    def to_dict(self) -> dict[str, Any]:
        """Plain YAML-able data (tuples as lists); ``failures``, ``run.hours``,
        ``arrivals.profile``, ``energy``, ``costs`` and a ``quality`` rule other than the
        default only when given (so a scenario without them reads as it did before they
        existed), and with ``run.hours`` no ``run.parts`` (the run's length is given one way)."""
        d = _plain(self.model_dump())
        for optional in ("failures", "energy", "costs", "calendar", "buffer", "stations"):
            if d.get(optional) is None:
                d.pop(optional, None)
        given = [k for k in ("hours", "days", "weeks") if d["run"].get(k) is not None]
        for k in ("hours", "days", "weeks", *(["parts"] if given else [])):
            if k not in given:
                d["run"].pop(k, None)
        if d["arrivals"].get("profile") is None:
            d["arrivals"].pop("profile", None)
        if d["quality"] == QualitySettings().model_dump():
            d.pop("quality")
        return d

    def with_overrides(self, overrides: Mapping[str, Any], file: object = None,
                       paths_from: Path | None = None) -> Scenario:
        """A new scenario with dotted keys replaced, validated as if read from ``file``;
        a file the overrides name by a relative path is looked for from ``paths_from``
        (None: from this scenario's folder, as its own files are)."""
        raw = apply_overrides(self.to_dict(), overrides, file or self._source, is_section)
        keep_one_length(raw, lengths_given(overrides, dotted=True))
        if paths_from is not None:
            _anchor_paths(overrides, raw, paths_from)
        return validate(raw, file or self._source, source=self._source)


#: The settings that name a file (relative paths: from the scenario file's folder).
PATH_KEYS = (("arrivals", "trace_csv"), ("mintime", "dynamics_file"))


def _anchor_paths(overrides: Mapping[str, Any], after: dict[str, Any], where: Path) -> None:
    """In ``after``, a file setting that one of ``overrides`` names (even with the value the
    scenario has) and is a relative path becomes relative to ``where`` instead of the
    scenario's folder."""
    for section, key in PATH_KEYS:
        value = (after.get(section) or {}).get(key)
        if isinstance(value, str) and _names(overrides, (section, key)) and not Path(value).is_absolute():
            after[section] = {**after[section], key: str(Path(where).resolve() / value)}


def _names(overrides: Mapping[str, Any], path: tuple[str, ...]) -> bool:
    """Whether a dotted key of ``overrides`` is ``path``, or a section given whole that holds it."""
    for dotted, value in overrides.items():
        parts = tuple(str(dotted).split("."))
        if parts != path[:len(parts)]:
            continue
        for part in path[len(parts):]:
            if not (isinstance(value, Mapping) and part in value):
                break
            value = value[part]
        else:
            return True
    return False


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
        raise named_station(error_from_validation(exc, raw, file, Scenario), raw) from None
    scenario._source = str(source if source is not None else file)
    _cross_checks(scenario, file)
    check_energy(scenario.energy, scenario.mintime.dynamics_file, file)
    check_layout(scenario, raw, file, lambda r: validate(r, file, source=scenario.source),
                 lambda base, more: merge(base, more, (), is_section))
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
        annotation = unwrap_optional(field.annotation)
        if isinstance(annotation, type) and issubclass(annotation, BaseModel):
            model = annotation
            continue
        rest = parts[i + 1:]
        if model is Scenario and part == "stations":  # stations.NAME.KEY..., by the station's name
            return not rest or len(rest) >= 2 and bool(rest[0]) and (
                rest[1] in ("placement", "offset_in", "transfer_in") and len(rest) == 2
                or rest[1] in STATION_SECTIONS and known_key(".".join(rest[1:])))
        is_mapping = getattr(annotation, "__origin__", None) is dict
        return not rest or (is_mapping and len(rest) == 1 and bool(rest[0]))
    return True


def inert_settings(s: Scenario) -> list[str]:
    """One line for each setting given a value of its own that has no effect under the
    others (for a warning): the planner's acceleration bounds while they are switched off."""
    m = s.mintime
    if not m.acceleration_bounds and tuple(m.qddot_max_rad_s2) != _DEFAULTS.mintime.qddot_max_rad_s2:
        return [f"mintime.qddot_max_rad_s2 ([{', '.join(f'{v:g}' for v in m.qddot_max_rad_s2)}]) "
                "has no effect while mintime.acceleration_bounds is false"]
    return []


def _cross_checks(s: Scenario, file: object) -> None:
    """Checks that need more than one value but no maths."""
    h = s.robot.hand
    for key, g in (("robot.hand.open_in", h.open_in), ("part.size_in", s.part.size_in)):
        if (g - h.g0_in) ** 2 / 2 > h.l2_in ** 2:
            raise ScenarioError(file, key, g, "finger opening beyond what the hand linkage "
                                "allows (eq. 6.2: (G - G0)^2 / 2 must not exceed L2^2)")
    if s.part.size_in > s.cell.belt_width_in:
        changed = ("part.size_in", s.part.size_in) if s.part.size_in != _DEFAULTS.part.size_in \
            else ("cell.belt_width_in", s.cell.belt_width_in)
        raise ScenarioError(file, *changed, f"a {s.part.size_in:g} in part does not fit on a "
                            f"{s.cell.belt_width_in:g} in wide belt (part.size_in must not exceed "
                            "cell.belt_width_in)")
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
    from cell.scenario.arrivals import check_arrivals

    check_arrivals(s.arrivals, s.base_dir, file)
    _length_and_failures(s, file)


def _length_and_failures(s: Scenario, file: object) -> None:
    """``run.hours`` against ``run.parts``; the ``failures:`` section's times and the motors'
    wear, against the run's length (what bounds the stops it brings); the calendar."""
    from cell.scenario.calendar_checks import check_calendar

    check_calendar(s, file)
    timed = s.run.hours is not None or s.run.days is not None or s.run.weeks is not None
    if timed or s.failures is not None or s.wear.enabled:
        from cell.scenario.failure_spec import check_failures, check_wear
        from cell.scenario.run_length import check_hours, expected_seconds

        check_hours(s, file)
        run_s = expected_seconds(s)
        check_failures(s.failures, file, run_s)
        check_wear(s.wear, file, run_s)
    if s.wear.enabled and s.failures is not None and s.failures.robot is None:
        raise ScenarioError(file, "wear.enabled", True,
                            "with a failures: section, wear needs failures.robot (its "
                            "time_to_repair is a worn motor's replacement)")


# --------------------------------------------------------------------------- files
def load_scenario(path: str | Path, overrides: Mapping[str, Any] | None = None) -> Scenario:
    """Read and validate a scenario file (or a built-in one by name, ``baseline``);
    dotted ``overrides`` replace its values."""
    from cell.scenario import catalog
    from cell.scenario.yamlio import load_mapping

    path = catalog.resolve(path)
    given = load_mapping(path, "scenario")
    catalog.refuse_other_kind(given, path, "scenario")
    if given.get("name") in (None, ""):  # a file without a name goes by the file's
        given = {**given, "name": path.stem}
    raw = merge(_DEFAULTS.to_dict(), given, (), is_section)
    keep_one_length(raw, lengths_given(given, dotted=False))
    try:
        changed = apply_overrides(raw, overrides or {}, path, is_section)
        keep_one_length(changed, lengths_given(overrides or {}, dotted=True))
        _anchor_paths(overrides or {}, changed, Path.cwd())  # a file named on the command line: from here
        return validate(changed, path, source=str(path))
    except ScenarioError as exc:  # a value from --set: the line says so
        marked = exc.given_with_set(overrides or ())
        if marked is exc:
            raise
        raise marked from None


def default_scenario() -> Scenario:
    """The thesis's cell with every default."""
    return _DEFAULTS


_DEFAULTS = Scenario()


def json_schema() -> dict[str, Any]:
    """The JSON Schema of a scenario file, for editors (``cell schema``)."""
    schema = Scenario.model_json_schema()
    schema["title"] = "cell scenario"
    return schema
