"""A sweep file's keys as pydantic models, read with the scenario's machinery (:mod:`cell.scenario.fields`).

:class:`SweepFile` holds the top level (unknown keys refused, each value's type and bounds),
:class:`PrecisionFile` a ``replications:`` mapping; pydantic's report becomes the one line a
user reads through :func:`cell.scenario.fields.error_from_validation`, as for a scenario.  What needs
the base scenario or the grid's points (a key's name in ``set`` or ``grid``, a policy's name,
the baseline point) is checked afterwards by :mod:`cell.experiments.sweep.options`.
"""

from __future__ import annotations

import math
from typing import Any, cast

from pydantic import Field, ValidationError, ValidationInfo, field_validator

from cell.plumbing.errors import ScenarioError
from cell.scenario.fields import Section, error_from_validation, write_instead


def whole_number(value: Any, lo: int) -> int:
    """``value`` as a whole number of at least ``lo``; a float of one (``20.0``) is refused too,
    as a scenario's counts are, but told to write ``20``."""
    if isinstance(value, bool) or not isinstance(value, int) or value < lo:
        hint = write_instead("int_from_float", value) if isinstance(value, float) and value >= lo else ""
        raise ValueError(f"must be a whole number of at least {lo}{hint}")
    return value


def summary_measures() -> list[str]:
    """The numeric columns of a run's summary (:class:`cell.sim.records.RunSummary`), in order:
    what a report summarises and a precision can be asked of."""
    from dataclasses import fields

    from cell.sim.records import RunSummary

    return [f.name for f in fields(RunSummary)
            if isinstance(f.default, (int, float)) and f.name != "seed"]


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


class SweepFile(Section):
    """The top level of a sweep file (:mod:`cell.experiments.sweep.spec`'s docstring shows one)."""

    name: Any = None
    """The sweep's name (default: the file's stem)."""
    description: Any = None
    """A line saying what the sweep is for."""
    base: Any = Field(None, validate_default=True)
    """The base scenario: a file (relative to the sweep file) or a built-in one."""
    set: Any = None
    """Fixed overrides, dotted keys to values."""
    grid: Any = None
    """Keys varied for every policy (checked by :func:`cell.experiments.sweep.options.grid`)."""
    policies: Any = None
    """A list of policies, or policy -> its own grid."""
    replications: Any = Field(None, validate_default=True)
    """Replications per point, or a precision to reach (:class:`PrecisionFile`)."""
    seed: Any = None
    """The root seed (default: the base scenario's ``run.seed``)."""
    batch: Any = None
    """Replications per task (default: 20, or fewer)."""
    baseline: Any = None
    """The point every other is compared with (:func:`cell.experiments.sweep.options.read_baseline`)."""

    @field_validator("base")
    @classmethod
    def _base(cls, value: Any) -> Any:
        if not isinstance(value, str) or not value.strip():
            raise ValueError("name the base scenario: a file (relative to the sweep file) or "
                             "a built-in one (`cell scenarios`)")
        return value

    @field_validator("set")
    @classmethod
    def _set(cls, value: Any) -> Any:
        if value and not isinstance(value, dict):
            raise ValueError("must be a mapping of dotted keys to values")
        return value or {}

    @field_validator("replications")
    @classmethod
    def _replications(cls, value: Any) -> Any:
        return value if isinstance(value, dict) else whole_number(value, 1)

    @field_validator("seed")
    @classmethod
    def _seed(cls, value: Any) -> Any:
        return None if value is None else whole_number(value, 0)

    @field_validator("batch")
    @classmethod
    def _batch(cls, value: Any) -> Any:
        return None if value is None else whole_number(value, 1)


class PrecisionFile(Section):
    """``replications:`` as a precision to reach: rounds until the confidence half-width of
    ``measure`` is at most ``precision`` x |mean| at every point, or ``max`` is reached."""

    precision: Any = Field(None, validate_default=True)
    """The largest confidence half-width, as a fraction of |mean|."""
    measure: Any = Field(None, validate_default=True)
    """A numeric column of a run's summary."""
    min: Any = Field(10, validate_default=True)
    """Replications every point gets first (at least 2)."""
    max: Any = Field(None, validate_default=True)
    """The most replications a point gets (at least ``min``)."""
    confidence: Any = Field(0.95, validate_default=True)
    """The intervals' confidence level."""

    @field_validator("precision")
    @classmethod
    def _precision(cls, value: Any) -> float:
        if not _number(value) or not 0 < value < math.inf:
            raise ValueError("must be a number above 0: the largest confidence half-width, "
                             "as a fraction of |mean|")
        return float(value)

    @field_validator("measure")
    @classmethod
    def _measure(cls, value: Any) -> str:
        known = summary_measures()
        if value not in known:
            raise ValueError("must be a numeric column of a run's summary, e.g. "
                             "parts_per_hr_wallclock (known: " + ", ".join(known) + ")")
        return str(value)

    @field_validator("min")
    @classmethod
    def _min(cls, value: Any) -> int:
        return whole_number(value, 2)

    @field_validator("max")
    @classmethod
    def _max(cls, value: Any, info: ValidationInfo) -> int:
        return whole_number(value, info.data.get("min", 2))

    @field_validator("confidence")
    @classmethod
    def _confidence(cls, value: Any) -> float:
        if not _number(value) or not 0 < value < 1:
            raise ValueError("must be a number between 0 and 1, e.g. 0.95")
        return float(value)


class _KeysFirst:
    """pydantic's report with unknown keys first: a file is told of a key it misspelt before
    any value (as a sweep file always was), whatever the fields' order."""

    def __init__(self, exc: ValidationError):
        self.exc = exc

    def errors(self) -> list[Any]:
        return sorted(self.exc.errors(), key=lambda e: e["type"] != "extra_forbidden")


def read(model: type[SweepFile] | type[PrecisionFile], raw: Any, file: object,
         prefix: str = "") -> Any:
    """``raw`` validated as ``model``; the first problem as one line naming the file, the
    key (under ``prefix``) and the value."""
    try:
        return model.model_validate(raw)
    except ValidationError as exc:
        err = error_from_validation(cast(ValidationError, _KeysFirst(exc)), raw, file, model)
        raise ScenarioError(file, prefix + err.key, err.value, err.why) from None
