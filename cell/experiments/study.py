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

from cell.experiments.varied import INDEXED, Param, param, value_at
from cell.plumbing.errors import ScenarioError
from cell.scenario.fields import Section, error_from_validation
from cell.scenario.schema import Scenario, known_key, load_scenario
from cell.sim.records import RunSummary

#: Measures computed from a summary row: name -> (what, function of the row).
DERIVED = {"spacing_outside_pct": "spacings outside 45 ± 0.25 in, % of the spacings on the output belt",
           "parts_missed_pct": "parts lost on the wall clock, % of the parts arrived"}
#: Measures only some built-in policies give (NaN for the others).
POLICY_MEASURES = {"thesis_slack_s": ("non-adaptive",), "ip_thesis_memoryless": ("adaptive",),
                   "cycle_vs_nominal_memoryless_pct": ("adaptive",)}
#: The most points a sensitivity design (Morris's or Sobol's) may have: as many as an
#: optimisation's trials.
MAX_POINTS = 100_000
_CONSTRAINT = re.compile(r"^\s*(?P<m>[A-Za-z_][A-Za-z0-9_]*)\s*(?P<op><=|>=)\s*(?P<v>[-+0-9.eE]+)\s*$")


#: The usual sense of the headline measures: ``--select-best`` without ``--goal``, ``select.measure``.
GOALS = {"parts_missed": "minimize", "parts_missed_pct": "minimize", "parts_missed_thesis": "minimize",
         "spacing_outside_tol": "minimize", "spacing_outside_pct": "minimize",
         "parts_per_hr_wallclock": "maximize", "parts_per_hr_thesis": "maximize",
         "parts_delivered": "maximize", "actual_cycle_wallclock_s": "minimize",
         "actual_cycle_thesis_s": "minimize", "oee": "maximize", "cost_per_good_part": "minimize",
         "cost_per_h": "minimize", "energy_kwh": "minimize", "energy_per_good_part_wh": "minimize"}


def summary_measures() -> list[str]:
    """Every measure a run reports: the summary's numeric columns, then :data:`DERIVED`."""
    from dataclasses import fields

    from cell.sim.records import OPTIONAL_COLUMNS

    return [f.name for f in fields(RunSummary)
            if isinstance(f.default, (int, float)) and f.name != "seed"] + list(DERIVED) \
        + list(OPTIONAL_COLUMNS)


def measures_of(row: Mapping[str, Any]) -> dict[str, float]:
    """A summary row's measures (:func:`summary_measures`) as floats."""
    out = {k: float(v) for k, v in row.items()
           if isinstance(v, (int, float)) and not isinstance(v, bool) and k != "seed"}
    gaps = max(out.get("parts_delivered", 0.0) - 1, 1.0)
    out["spacing_outside_pct"] = 100 * out.get("spacing_outside_tol", math.nan) / gaps
    out["parts_missed_pct"] = float(parts_missed_pct(out.get("parts_missed", math.nan),
                                                     out.get("parts_arrived", 0.0)))
    return out


def parts_missed_pct(missed: Any, arrived: Any) -> Any:
    """Parts lost on the wall clock, % of the parts arrived (of one part if none arrived):
    run by run, a number or an array of them (a sweep's summary takes it from here too)."""
    return 100 * np.asarray(missed, dtype=float) / np.maximum(np.asarray(arrived, dtype=float), 1.0)


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
    delta: float = Field(strict=True, gt=0, allow_inf_nan=False)
    """The indifference zone, in the measure's units (a finite number)."""
    pcs: float = _real(0.95, gt=0.5, lt=1)
    """The probability of correct selection asked."""
    n0: int = _count(10, 2)
    """First-stage replications of each candidate."""
    max: int = _count(200, 2)
    """At most this many replications of each candidate."""
    measure: str | None = None
    """The measure to select on (default: the first objective that is a measure)."""
    goal: Literal["minimize", "maximize"] | None = None
    """Whether more or less of ``measure`` is better, where no objective on it says so and it
    is not one of the headline measures whose sense is known (GOALS)."""


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
    """cell sensitivity: the measures whose indices are reported; cell optimize: further
    measures each trial records (trials.csv and the report's tables)."""
    policies: list[str] = Field(default_factory=list)
    """cell sensitivity: each policy gets its own indices, on the same points."""
    morris: MorrisSettings = MorrisSettings()
    """cell sensitivity: {trajectories: R, levels: P}."""
    sobol: SobolSettings = SobolSettings()
    """cell sensitivity: {samples: N (a power of 2), keys: K (the K keys Morris ranks first)}."""


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
            m = INDEXED.match(key)
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
    params = tuple(param(path, fixed, key, spec) for key, spec in settings.vary.items())
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
        _refuse_unset(study, f"measures[{i}]", m)  # NaN in every run: no index to give it
    if settings.select is not None and settings.select.measure is not None:
        if settings.select.measure not in measures:
            raise ScenarioError(path, "select.measure", settings.select.measure,
                                "no run reports it: name a measure of the run summary")
        _refuse_unset(study, "select.measure", settings.select.measure)
        if _selection_goal(settings.objectives, settings.select) is None:
            raise ScenarioError(path, "select.measure", settings.select.measure,
                                "say whether more or less is better (select.goal: maximize or "
                                "minimize)")
    return study


def _selection_goal(objectives: Any, select: SelectSettings) -> str | None:
    """The sense of ``select.measure``: ``select.goal``, an objective's goal on the same
    measure, or the headline measure's usual sense; None if none of them says."""
    return select.goal or next((o.goal for o in objectives if o.measure == select.measure),
                               GOALS.get(select.measure or ""))


def selection_goal(study: Study) -> str | None:
    """The sense of the study's ``select.measure`` (None: no selection measure named)."""
    sel = study.settings.select
    return None if sel is None or not sel.measure else _selection_goal(study.settings.objectives,
                                                                        sel)


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
    if why := unset_why(measure, study.policies_run()) or section_why(measure, study.base):
        raise ScenarioError(study.source, where, measure, why)


#: The summary's measures that only a scenario with their section reports (``energy:``,
#: ``costs:``; :data:`cell.sim.records.OPTIONAL_COLUMNS`).
SECTION_MEASURES = {"energy_kwh": "energy", "energy_per_good_part_wh": "energy",
                    "cost_per_good_part": "costs", "cost_per_h": "costs",
                    "arm_energy_per_transfer_j": "energy"}
#: The line's measures: only a scenario with ``buffer:`` or ``stations:`` reports them.
LINE_MEASURES = ("line_throughput_per_h", "line_wip_mean")


def section_why(measure: str, base: Scenario) -> str | None:
    """Why no run of ``base`` reports ``measure`` (its section is absent), or None."""
    section = SECTION_MEASURES.get(measure)
    if section is not None and getattr(base, section, None) is None:
        return f"no run reports it: the base scenario has no {section}: section"
    if measure in LINE_MEASURES and not base.has_layout:
        return "no run reports it: the base scenario has no buffer: or stations: section"
    if measure == "arm_energy_per_transfer_j" and base.energy is not None and base.energy.arm != "dynamics":
        return "no run reports it: the base scenario's energy.arm is not dynamics"
    return None


def unset_why(measure: str, policies: Sequence[str]) -> str | None:
    """Why no run of ``policies`` reports ``measure`` (NaN in every run: only a policy they
    do not include gives it a value), or None."""
    givers = POLICY_MEASURES.get(measure)
    if givers and not set(givers) & set(policies):
        return (f"no run reports it: only {' and '.join(givers)} gives it a value, and the "
                f"runs are of {', '.join(policies)}")
    return None


def _check_corners(study: Study) -> None:
    """Build the scenario at every key's low and high end (and each choice), one key at a
    time, so a bad range is refused before any work, naming its key.  (A point where several
    keys combine into a cell that cannot work is a refused trial of ``cell optimize``.)"""
    from cell.sim.assembly import assemble

    for p in study.params:
        for v in (p.choices if p.is_choice else (value_at(p, p.low), value_at(p, p.high))):
            try:
                assemble(study.scenario({p.key: v}))
            except ScenarioError as exc:
                raise ScenarioError(study.source, f"vary.{p.key}", v, f"at this value "
                                    f"{exc.key} = {exc.value}: {exc.why}") from None


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
