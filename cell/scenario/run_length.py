"""How long a run may be: ``run.parts`` and ``run.hours`` are exclusive, and the parts an
hours-long run would bring stay within the bound on parts (checked where a scenario is read;
:mod:`cell.sim.horizon` draws the run's arrivals and runs it to its end)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from cell.plumbing.errors import ScenarioError
from cell.scenario.arrivals import mean_interarrival

SECONDS_PER_HOUR = 3600.0


@dataclass(frozen=True)
class RunLength:
    """How long each run is: ``run.parts`` parts, or ``run.hours`` hours."""

    count: float
    unit: str
    """``part`` or ``hour``."""

    @classmethod
    def of(cls, run: Any) -> RunLength:
        """A scenario's ``run`` section's length."""
        return cls(run.parts, "part") if run.hours is None else cls(run.hours, "hour")

    @property
    def number(self) -> str:
        """``500``, ``0.5``: a count of parts as a whole number, hours as given."""
        return str(self.count) if isinstance(self.count, int) else f"{self.count:g}"

    @property
    def run(self) -> str:
        """``500-part run``, ``8-hour run``."""
        return f"{self.number}-{self.unit} run"

    def __str__(self) -> str:
        """``500 parts``, ``1 hour``."""
        return f"{self.number} {self.unit}{'s' if self.count != 1 else ''}"


#: The keys of ``run`` that set its length; a scenario gives one or the other.
LENGTH_KEYS = ("parts", "hours")


def lengths_given(layer: Mapping[str, Any], dotted: bool) -> set[str]:
    """The length keys a layer gives a value (``hours: null`` gives none): a file's mapping, or
    ``dotted`` overrides (``run.hours``, or ``run`` given as a mapping)."""
    run = layer.get("run")
    given = {k for k in LENGTH_KEYS if isinstance(run, Mapping) and run.get(k) is not None}
    if dotted:
        given |= {k for k in LENGTH_KEYS if layer.get(f"run.{k}") is not None}
    return given


def keep_one_length(raw: dict[str, Any], given: set[str]) -> None:
    """A layer (a file over the defaults, ``--set`` over a file) that gives the run's length one
    way sets it: the other key, from the layers below, goes from ``raw``.  A layer that gives
    both keeps both, for :func:`check_hours` to refuse."""
    run = raw.get("run")
    if len(given) == 1 and isinstance(run, Mapping):
        (other,) = set(LENGTH_KEYS) - given
        raw["run"] = {k: v for k, v in run.items() if k != other}


def check_hours(s: Any, file: object) -> None:
    """``run.hours`` and ``run.parts`` are exclusive (both *given*, whatever their values); the
    parts an hours-long run brings stay within the bound on parts."""
    hours = s.run.hours
    if hours is None:
        return
    if "parts" in s.run.model_fields_set:
        raise ScenarioError(file, "run.hours", hours, f"give run.hours or run.parts "
                            f"({s.run.parts}), not both")
    from cell.scenario.sections import MAX_PARTS

    expected = expected_parts(s)
    if expected > MAX_PARTS:
        raise ScenarioError(file, "run.hours", hours, f"about {expected:.3g} parts would come; "
                            f"at most {MAX_PARTS:g} a run")


def expected_parts(s: Any) -> float:
    """The parts a run brings: ``run.parts``, or about ``run.hours`` over the mean
    inter-arrival time (what an hours-long run's progress counts towards)."""
    if s.run.hours is None:
        return float(s.run.parts)
    return float(s.run.hours * SECONDS_PER_HOUR / mean_interarrival(s.arrivals, s.base_dir))


def expected_seconds(s: Any) -> float:
    """The run's length in simulated time: ``run.hours``, or ``run.parts`` mean inter-arrival
    times (what bounds the stops a run can bring: :mod:`cell.scenario.failure_spec`)."""
    if s.run.hours is not None:
        return float(s.run.hours * SECONDS_PER_HOUR)
    return float(s.run.parts * mean_interarrival(s.arrivals, s.base_dir))
