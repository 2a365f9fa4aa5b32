"""One key a study varies (``vary:``): its range or its choices, checked against the base
scenario (with the study's ``set:``) before any work: a key of a section the base leaves out,
a step that is not a whole number on a whole-number key, are refused in one line naming the
study file, the key and the value."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cell.plumbing.errors import ScenarioError
from cell.scenario.fields import model_at
from cell.scenario.schema import Scenario, known_key

#: Keys a study may not vary: each replication's stream comes from the study's seed.
RESERVED = {"run.seed": "every replication gets its own stream from the study's 'seed'"}

#: A key naming one entry of a list setting: ``robot.motors.max_rate_no_load_rad_s[0]``.
INDEXED = re.compile(r"^(?P<key>[A-Za-z0-9_.]+)\[(?P<i>\d+)\]$")


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


def param(path: Path, base: Scenario, key: str, spec: Any) -> Param:
    """One key of ``vary``, checked against ``base`` (the base scenario with ``set``)."""
    where = f"vary.{key}"
    m = INDEXED.match(key)
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
    if isinstance(spec, list) and not (len(spec) == 2 and all(number(v) for v in spec)):
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
    if not (number(low) and number(high)) or not low < high:
        raise ScenarioError(path, where, [low, high], "an empty range: low must be a number below high")
    if step is not None and (not number(step) or not 0 < step <= high - low):
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
    if parts[0] == "stations" and len(parts) > 2:  # a station's key, by its name (docs/layout.md)
        for station, own in base.line:
            if station.name == parts[1]:
                if len(parts) == 3 and parts[2] in type(station).model_fields:
                    return getattr(station, parts[2]), None
                value, absent = _setting(own, ".".join(parts[2:]))
                return value, None if absent is None else f"stations.{parts[1]}.{absent}"
        return None, ".".join(parts[:2])
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
    value = p.choices[0] if p.is_choice else value_at(p, p.low)
    try:
        base.with_overrides({p.key: value}, file=path)
    except ScenarioError as exc:
        raise ScenarioError(path, f"vary.{p.key}", value, f"the base scenario (with set:) has no "
                            f"{absent} section, and this key alone does not make one ({exc.key}: "
                            f"{exc.why}): give the section in the base or under set:") from None


def number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def value_at(p: Param, x: float) -> Any:
    """``x`` as the setting takes it: rounded for a whole-number key."""
    return int(round(x)) if p.whole else x
