"""How long a run may be: ``run.parts``, ``run.hours``, and with a calendar ``run.days`` and
``run.weeks``, one of them; the parts a run of a time would bring stay within the bound on
parts (checked where a scenario is read; :mod:`cell.sim.horizon` draws the run's arrivals and
runs it to its end)."""

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
    """``part``, ``hour``, ``day`` (working days of a calendar) or ``week``."""

    @classmethod
    def of(cls, run: Any) -> RunLength:
        """A scenario's ``run`` section's length."""
        for key in LENGTH_KEYS[1:]:
            if getattr(run, key, None) is not None:
                return cls(getattr(run, key), key[:-1])
        return cls(run.parts, "part")

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


#: The keys of ``run`` that set its length; a scenario gives one of them.
LENGTH_KEYS = ("parts", "hours", "days", "weeks")


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
    way sets it: the other keys, from the layers below, go from ``raw``.  A layer that gives
    two keeps both, for :func:`check_hours` to refuse."""
    run = raw.get("run")
    if len(given) == 1 and isinstance(run, Mapping):
        raw["run"] = {k: v for k, v in run.items() if k in given or k not in LENGTH_KEYS}


def check_hours(s: Any, file: object) -> None:
    """``run.parts``, ``run.hours``, ``run.days`` and ``run.weeks`` are exclusive (two *given*,
    whatever their values); days and weeks need a calendar; the parts a run of a time brings
    stay within the bound on parts."""
    timed = [k for k in LENGTH_KEYS[1:] if getattr(s.run, k, None) is not None]
    if not timed:
        return
    key = timed[0]
    value = getattr(s.run, key)
    others = [k for k in timed if k != key] + \
        (["parts"] if "parts" in s.run.model_fields_set else [])
    if others:
        other = others[0]
        raise ScenarioError(file, f"run.{key}", value, f"give run.{key} or run.{other} "
                            f"({getattr(s.run, other)}), not both")
    if key in ("days", "weeks") and getattr(s, "calendar", None) is None:
        raise ScenarioError(file, f"run.{key}", value, "counts the working days of a "
                            "calendar: give a calendar: section, or run.hours")
    from cell.scenario.sections import MAX_PARTS

    expected = expected_parts(s)
    if expected > MAX_PARTS:
        raise ScenarioError(file, f"run.{key}", value, f"about {expected:.3g} parts would come; "
                            f"at most {MAX_PARTS:g} a run")


def horizon_s(s: Any) -> float | None:
    """The run's length in seconds from its start when given as a time (``run.hours``,
    ``run.days``, ``run.weeks``), else None."""
    if s.run.hours is not None:
        return float(s.run.hours * SECONDS_PER_HOUR)
    days, weeks = getattr(s.run, "days", None), getattr(s.run, "weeks", None)
    if days is None and weeks is None:
        return None
    from cell.scenario.calendar_section import WEEK_S, days_end_s

    if weeks is not None:
        return float(weeks * WEEK_S)
    return None if days is None else days_end_s(s.calendar, days)


def expected_parts(s: Any) -> float:
    """The parts a run brings: ``run.parts``, or about its working time over the mean
    inter-arrival time (what a run of a time's progress counts towards)."""
    horizon = horizon_s(s)
    if horizon is None:
        return float(s.run.parts)
    return float(working_s(s, horizon) / mean_interarrival(s.arrivals, s.base_dir))


def working_s(s: Any, t: float) -> float:
    """The working time in the run's first ``t`` seconds: all of it without a calendar."""
    if getattr(s, "calendar", None) is None:
        return t
    from cell.scenario.calendar_section import working_week

    return float(working_week(s.calendar, s.source).measure(t))


def expected_seconds(s: Any) -> float:
    """The run's length in simulated time: its horizon, or ``run.parts`` mean inter-arrival
    times (what bounds the stops a run can bring: :mod:`cell.scenario.failure_spec`)."""
    horizon = horizon_s(s)
    if horizon is not None:
        return horizon
    return float(s.run.parts * mean_interarrival(s.arrivals, s.base_dir))
