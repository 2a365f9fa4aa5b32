"""A study file: what ``cell optimize`` and ``cell sensitivity`` vary, measure and ask.

::

    base: baseline.yaml                  # a scenario (relative to the study file, or built-in)
    set: {run.parts: 500}                # fixed overrides (optional)
    vary:                                # the keys to vary, written as in a scenario
      belts.input_nominal_in_s: [1.0, 3.0]                  # a number in [low, high]
      controller.nominal_cycle_s: {low: 21, high: 25, step: 0.1}   # or with step / log: true
      controller.policy: {choice: [adaptive, non-adaptive]}         # a choice (any values)
      robot.motors.max_rate_no_load_rad_s[0]: [0.40, 0.44]  # one entry of a list setting
    objectives: [{measure: parts_per_hr_wallclock, goal: maximize}]
    constraints: ["parts_missed <= 1", "spacing_outside_pct <= 1"]
    trials: 60                           # optimize
    replications: 10                     # per point, over common random numbers
    seed: 1984
    select: {candidates: 5, delta: 1.0, pcs: 0.95, n0: 10, max: 100}   # optimize (KN)

A measure is a numeric column of a run's summary (:class:`cell.sim.records.RunSummary`), one
of :data:`DERIVED`, or (for an objective) a varied key itself.  Replication ``r`` of every
point runs on ``SeedSequence(seed, spawn_key=(r,))``, as a sweep's does: common random
numbers across points, so two points differ by their keys, not their draws.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field, ValidationError

from cell.plumbing.errors import ScenarioError
from cell.scenario.fields import Section, error_from_validation, model_at
from cell.scenario.schema import Scenario, known_key, load_scenario
from cell.sim.records import RunSummary

#: Measures computed from a summary row: name -> (what, function of the row).
DERIVED = {"spacing_outside_pct": "spacings outside 45 ± 0.25 in, % of the spacings on the output belt",
           "parts_missed_pct": "parts lost on the wall clock, % of the parts arrived"}
#: Keys a study may not vary: each replication's stream comes from the study's seed.
RESERVED = {"run.seed": "every replication gets its own stream from the study's 'seed'"}
#: Measures only some built-in policies give (NaN for the others).
POLICY_MEASURES = {"thesis_slack_s": ("non-adaptive",), "ip_thesis_memoryless": ("adaptive",),
                   "cycle_vs_nominal_memoryless_pct": ("adaptive",)}
#: The most points a sensitivity design (Morris's or Sobol's) may have: as many as an
#: optimisation's trials.
MAX_POINTS = 100_000
_INDEX = re.compile(r"^(?P<key>[A-Za-z0-9_.]+)\[(?P<i>\d+)\]$")
_CONSTRAINT = re.compile(r"^\s*(?P<m>[A-Za-z_][A-Za-z0-9_]*)\s*(?P<op><=|>=)\s*(?P<v>[-+0-9.eE]+)\s*$")


def summary_measures() -> list[str]:
    """Every measure a run reports: the summary's numeric columns, then :data:`DERIVED`."""
    from dataclasses import fields

    return [f.name for f in fields(RunSummary)
            if isinstance(f.default, (int, float)) and f.name != "seed"] + list(DERIVED)


def measures_of(row: Mapping[str, Any]) -> dict[str, float]:
    """A summary row's measures (:func:`summary_measures`) as floats."""
    out = {k: float(v) for k, v in row.items()
           if isinstance(v, (int, float)) and not isinstance(v, bool) and k != "seed"}
    gaps = max(out.get("parts_delivered", 0.0) - 1, 1.0)
    out["spacing_outside_pct"] = 100 * out.get("spacing_outside_tol", math.nan) / gaps
    out["parts_missed_pct"] = 100 * out.get("parts_missed", math.nan) / max(
        out.get("parts_arrived", 0.0), 1.0)
    return out


def _count(default: Any, low: int, high: int | None = None) -> Any:
    """A whole number, strict as every count of a scenario is: ``'10'`` (text) and ``1e3`` (a
    number written as a float) are refused, not read as 10 and 1000."""
    return Field(default, strict=True, ge=low, le=high)


def _real(default: Any = ..., *, gt: float | None = None, lt: float | None = None) -> Any:
    """A number (ints accepted, text and booleans refused), as a scenario's numbers are."""
    return Field(default, strict=True, gt=gt, lt=lt)


class ObjectiveSettings(Section):
    measure: str
    """A measure of the run summary, or a varied key."""
    goal: Literal["minimize", "maximize"]


class SelectSettings(Section):
    candidates: int = _count(5, 2)
    """How many of the best trials KN re-runs."""
    delta: float = _real(gt=0)
    """The indifference zone, in the measure's units."""
    pcs: float = _real(0.95, gt=0.5, lt=1)
    """The probability of correct selection asked."""
    n0: int = _count(10, 2)
    """First-stage replications of each candidate."""
    max: int = _count(200, 2)
    """At most this many replications of each candidate."""
    measure: str | None = None
    """The measure to select on (default: the first objective that is a measure)."""


class MorrisSettings(Section):
    trajectories: int = _count(10, 2)
    """R: the design has R × (keys + 1) points (at most MAX_POINTS)."""
    levels: int = _count(4, 2)
    """P: the grid each key's range is cut into."""


class SobolSettings(Section):
    samples: int = _count(64, 2)
    """N, a power of 2: the design has N × (keys + 2) points (at most MAX_POINTS)."""
    keys: int | None = _count(None, 2)
    """The keys Morris ranks first that get Sobol indices (default: every key)."""


class StudySettings(Section):
    name: str = ""
    description: str = ""
    base: str
    fixed: dict[str, Any] = Field(default_factory=dict, alias="set")
    vary: dict[str, Any]
    objectives: list[ObjectiveSettings] = Field(default_factory=list)
    constraints: list[str] = Field(default_factory=list)
    trials: int = _count(50, 1, 100_000)
    replications: int = _count(10, 1, 10_000)
    seed: int = _count(1984, 0)
    select: SelectSettings | None = None
    measures: list[str] = Field(default_factory=list)
    """cell sensitivity: the measures whose indices are reported."""
    policies: list[str] = Field(default_factory=list)
    """cell sensitivity: each policy gets its own indices, on the same points."""
    morris: MorrisSettings = MorrisSettings()
    """cell sensitivity: {trajectories: R, levels: P}."""
    sobol: SobolSettings = SobolSettings()
    """cell sensitivity: {samples: N (a power of 2), keys: K (the K keys Morris ranks first)}."""


@dataclass(frozen=True)
class Param:
    """One varied key: a number in [low, high] (``log``, ``step``, whole if the setting is)
    or a choice among ``choices``."""

    key: str
    low: float = math.nan
    high: float = math.nan
    log: bool = False
    step: float | None = None
    whole: bool = False
    choices: tuple[Any, ...] = ()

    @property
    def is_choice(self) -> bool:
        return bool(self.choices)


@dataclass(frozen=True)
class Constraint:
    measure: str
    op: str
    bound: float

    def excess(self, value: float) -> float:
        """How far ``value`` breaks the constraint (<= 0: kept), as Optuna's constraints take it."""
        if math.isnan(value):
            return math.inf
        return value - self.bound if self.op == "<=" else self.bound - value

    def __str__(self) -> str:
        return f"{self.measure} {self.op} {self.bound:g}"


@dataclass(frozen=True)
class Study:
    source: Path
    settings: StudySettings
    base: Scenario
    params: tuple[Param, ...]
    constraints: tuple[Constraint, ...]

    @property
    def name(self) -> str:
        return self.settings.name or self.source.stem

    def scenario(self, values: Mapping[str, Any]) -> Scenario:
        """The scenario of one point: the base, ``set``, then the varied keys' ``values``."""
        over: dict[str, Any] = dict(self.settings.fixed)
        lists: dict[str, list[Any]] = {}
        for key, value in values.items():
            m = _INDEX.match(key)
            if m is None:
                over[key] = value
                continue
            whole = lists.setdefault(m["key"], list(over.get(m["key"], self.base.get(m["key"]))))
            whole[int(m["i"])] = value
        over.update(lists)
        return self.base.with_overrides(over, file=self.source, paths_from=self.source.parent)

    def stream(self, replication: int, offset: int = 0) -> np.random.SeedSequence:
        return np.random.SeedSequence(self.settings.seed, spawn_key=(offset + replication,))

    def policies_run(self) -> list[str]:
        p = next((q for q in self.params if q.key == "controller.policy"), None)
        if p is not None:
            return [str(c) for c in p.choices]
        if self.settings.policies:
            return list(self.settings.policies)
        return [self.scenario({}).controller.policy]


def load_study(path: str | Path, corners: bool = True) -> Study:
    """Read and check a study file; every problem is one :class:`ScenarioError`.
    ``corners``: also build each key's scenario at both ends of its range (a worker
    reading a file its command checked already skips it)."""
    from cell.scenario import catalog
    from cell.scenario.yamlio import load_mapping

    path = Path(path)
    raw = load_mapping(path, "study")
    catalog.refuse_other_kind(raw, path, "study")
    try:
        settings = StudySettings.model_validate(raw)
    except ValidationError as exc:
        raise error_from_validation(exc, raw, path, StudySettings) from None
    base_path = catalog.resolve(settings.base, beside=path.parent)
    if not base_path.exists():
        raise ScenarioError(path, "base", settings.base, f"no such scenario file ({base_path}) "
                            "nor built-in scenario (`cell scenarios` lists them)")
    base = load_scenario(base_path)
    for key, value in settings.fixed.items():
        if not known_key(key):
            raise ScenarioError(path, f"set.{key}", value, "unknown key: no such setting in a scenario")
    for i, policy in enumerate(settings.policies):
        if policy in settings.policies[:i]:
            raise ScenarioError(path, f"policies[{i}]", policy, "listed twice: each policy once")
    if not settings.vary:
        raise ScenarioError(path, "vary", settings.vary, "name at least one key to vary")
    fixed = base.with_overrides(settings.fixed, file=path, paths_from=path.parent) \
        if settings.fixed else base
    params = tuple(_param(path, fixed, key, spec) for key, spec in settings.vary.items())
    study = Study(path, settings, base, params, ())
    if corners:
        _check_corners(study)
    measures = summary_measures()
    constraints = tuple(_constraint(path, i, text, measures)
                        for i, text in enumerate(settings.constraints))
    study = Study(path, settings, base, params, constraints)
    for i, o in enumerate(settings.objectives):
        if o.measure not in measures and o.measure not in settings.vary:
            raise ScenarioError(path, f"objectives[{i}].measure", o.measure,
                                "no run reports it: name a measure of the run summary "
                                f"({', '.join(measures[:6])}, ...) or a varied key")
        _refuse_unset(study, f"objectives[{i}].measure", o.measure)
    for i, c in enumerate(constraints):
        _refuse_unset(study, f"constraints[{i}]", c.measure)
    for i, m in enumerate(settings.measures):
        if m not in measures:
            raise ScenarioError(path, f"measures[{i}]", m, "no run reports it (a measure of the "
                                "run summary: parts_missed, spacing_outside_tol, ...)")
    if settings.select is not None and settings.select.measure is not None \
            and settings.select.measure not in measures:
        raise ScenarioError(path, "select.measure", settings.select.measure,
                            "no run reports it: name a measure of the run summary")
    return study


def _param(path: Path, base: Scenario, key: str, spec: Any) -> Param:
    """One key of ``vary``, checked against ``base`` (the base scenario with ``set``)."""
    where = f"vary.{key}"
    m = _INDEX.match(key)
    plain = m["key"] if m else key
    if not known_key(plain):
        raise ScenarioError(path, where, spec, "unknown key: no such setting in a scenario")
    if plain in RESERVED:
        raise ScenarioError(path, where, spec, f"cannot be varied: {RESERVED[plain]}")
    current, absent = _setting(base, plain)
    if m is not None:
        if not isinstance(current, (list, tuple)) or int(m["i"]) >= len(current):
            raise ScenarioError(path, where, spec, f"{plain} has no entry {m['i']}")
        current = current[int(m["i"])]
    whole = isinstance(current, int) and not isinstance(current, bool) or \
        absent is not None and _whole_setting(plain)
    param = _range(path, where, key, spec, whole)
    if absent is not None:
        _refuse_alone(path, base, param, absent)
    return param


def _range(path: Path, where: str, key: str, spec: Any, whole: bool) -> Param:
    if isinstance(spec, Mapping) and "choice" in spec:
        choices = spec["choice"]
        if set(spec) != {"choice"} or not isinstance(choices, list) or not choices:
            raise ScenarioError(path, where, spec, "a choice is {choice: [value, ...]}, not empty")
        return Param(key, choices=tuple(choices))
    if isinstance(spec, list) and not (len(spec) == 2 and all(_number(v) for v in spec)):
        if not spec:
            raise ScenarioError(path, where, spec, "an empty choice: list at least one value")
        return Param(key, choices=tuple(spec))
    if isinstance(spec, list):
        spec = {"low": spec[0], "high": spec[1]}
    if not isinstance(spec, Mapping) or set(spec) - {"low", "high", "log", "step"} \
            or not {"low", "high"} <= set(spec):
        raise ScenarioError(path, where, spec, "write [low, high], {low: L, high: H, log: true} "
                            "or {low: L, high: H, step: S} for a number, {choice: [...]} for a choice")
    low, high, step, log = spec["low"], spec["high"], spec.get("step"), spec.get("log", False)
    if not (_number(low) and _number(high)) or not low < high:
        raise ScenarioError(path, where, [low, high], "an empty range: low must be a number below high")
    if step is not None and (not _number(step) or not 0 < step <= high - low):
        raise ScenarioError(path, where, step, "step must be a number in (0, high - low]")
    if step is not None and whole and not float(step).is_integer():
        raise ScenarioError(path, f"{where}.step", step, f"{key.split('.')[-1]} is a whole "
                            "number: the step must be one too (1, 2, ...)")
    if not isinstance(log, bool) or log and (low <= 0 or step is not None):
        raise ScenarioError(path, where, spec, "log: true needs 0 < low and no step")
    return Param(key, float(low), float(high), log, None if step is None else float(step), whole)


def _setting(base: Scenario, dotted: str) -> tuple[Any, str | None]:
    """A setting's value in ``base`` and None; or None and the section on its way that
    ``base`` leaves out (``failures``, absent unless given); an entry a mapping setting does
    not hold (``arrivals.params.loc``) is None."""
    obj: Any = base
    parts = dotted.split(".")
    for i, part in enumerate(parts):
        if obj is None:
            return None, ".".join(parts[:i])
        obj = obj.get(part) if isinstance(obj, Mapping) else getattr(obj, part)
    return obj, None


def _whole_setting(dotted: str) -> bool:
    """Whether the schema holds ``dotted`` as a whole number (``failures.repair.crews``)."""
    parts = dotted.split(".")
    section = model_at(Scenario, parts[:-1])
    field = section.model_fields.get(parts[-1]) if section is not None else None
    return field is not None and field.annotation is int


def _refuse_alone(path: Path, base: Scenario, p: Param, absent: str) -> None:
    """A key of a section the base leaves out is varied: the key alone must make the section
    (``failures.repair.crews`` does; a failure mode needs both its times), else refused."""
    value = p.choices[0] if p.is_choice else _value(p, p.low)
    try:
        base.with_overrides({p.key: value}, file=path)
    except ScenarioError as exc:
        raise ScenarioError(path, f"vary.{p.key}", value, f"the base scenario (with set:) has no "
                            f"{absent} section, and this key alone does not make one ({exc.key}: "
                            f"{exc.why}): give the section in the base or under set:") from None


def _number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _constraint(path: Path, i: int, text: Any, measures: Sequence[str]) -> Constraint:
    m = _CONSTRAINT.match(str(text))
    if m is None:
        raise ScenarioError(path, f"constraints[{i}]", text, "write MEASURE <= NUMBER or "
                            "MEASURE >= NUMBER, e.g. spacing_outside_tol <= 5")
    if m["m"] not in measures:
        raise ScenarioError(path, f"constraints[{i}]", text, f"unknown measure {m['m']}: no run "
                            "reports it (parts_missed, spacing_outside_tol, spacing_outside_pct, ...)")
    try:
        bound = float(m["v"])
    except ValueError:
        raise ScenarioError(path, f"constraints[{i}]", text, "the bound must be a number") from None
    return Constraint(m["m"], m["op"], bound)


def _refuse_unset(study: Study, where: str, measure: str) -> None:
    givers = POLICY_MEASURES.get(measure)
    policies = study.policies_run()
    if givers and not set(givers) & set(policies):
        raise ScenarioError(study.source, where, measure, f"no run reports it: only "
                            f"{' and '.join(givers)} gives it a value, and the study runs "
                            f"{', '.join(policies)}")


def _check_corners(study: Study) -> None:
    """Build the scenario at every key's low and high end (and each choice), one key at a
    time, so a bad range is refused before any work, naming its key.  (A point where several
    keys combine into a cell that cannot work is a refused trial of ``cell optimize``.)"""
    from cell.sim.assembly import assemble

    for p in study.params:
        for v in (p.choices if p.is_choice else (_value(p, p.low), _value(p, p.high))):
            try:
                assemble(study.scenario({p.key: v}))
            except ScenarioError as exc:
                raise ScenarioError(study.source, f"vary.{p.key}", v, f"at this value "
                                    f"{exc.key} = {exc.value}: {exc.why}") from None


def _value(p: Param, x: float) -> Any:
    return int(round(x)) if p.whole else x


def replicate(study: Study, values: Mapping[str, Any], replications: Sequence[int],
              offset: int = 0) -> list[dict[str, float]]:
    """The measures of replications ``replications`` of one point (in this process)."""
    from cell.sim.assembly import assemble
    from cell.sim.simulation import simulate

    cell = assemble(study.scenario(values))
    return [measures_of(simulate(cell, seed=study.stream(r, offset), keep_parts=False,
                                 keep_belts=False).summary.as_dict()) for r in replications]


def interval(xs: Sequence[float], confidence: float = 0.95) -> tuple[float, float]:
    """Mean and the t-interval's half-width (NaN with one value)."""
    from scipy import stats

    a = np.asarray(xs, dtype=float)
    if len(a) < 2:
        return float(a.mean()) if len(a) else math.nan, math.nan
    half = stats.t.ppf(0.5 + confidence / 2, len(a) - 1) * a.std(ddof=1) / math.sqrt(len(a))
    return float(a.mean()), float(half)
