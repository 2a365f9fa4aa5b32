"""The parts of a sweep file beside the grid's scenarios: the grid's lists, the
replications (a number, or a precision to reach) and the baseline point.

Every bad value raises :class:`cell.plumbing.errors.ScenarioError`: one line naming the
sweep file, the key and the value.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from cell.experiments.sweep.sweep_schema import PrecisionFile, read, whole_number
from cell.experiments.sweep.sweep_schema import summary_measures as summary_measures  # re-exported
from cell.plumbing.errors import ScenarioError
from cell.scenario.schema import known_key

if TYPE_CHECKING:
    from cell.experiments.sweep.spec import Point, Sweep

#: Keys the sweep itself sets for every run; they cannot be varied in a grid.
RESERVED = {"controller.policy": "list policies under 'policies'",
            "run.seed": "every replication gets its own stream from the sweep's 'seed'"}


@dataclass(frozen=True)
class Precision:
    """Replications to a precision: rounds until the confidence half-width of ``measure``
    is at most ``precision`` × |mean| at every point, or ``max_n`` is reached."""

    precision: float
    measure: str
    min_n: int
    max_n: int
    confidence: float = 0.95

    def as_dict(self) -> dict[str, Any]:
        return {"precision": self.precision, "measure": self.measure, "min": self.min_n,
                "max": self.max_n, "confidence": self.confidence}


@dataclass(frozen=True)
class Baseline:
    """The point the others are compared with: a policy and/or values of varied keys;
    a key it does not name takes the compared point's own value."""

    policy: str | None
    values: tuple[tuple[str, Any], ...]
    names: tuple[tuple[str, str], ...] = ()
    """For keys with named grid values: the name the sweep file used."""
    text: str = ""
    """How to name the baseline point, if not by its policy and values."""

    def label(self, policy: str) -> str:
        """``policy``, with the values the baseline fixes: ``non-adaptive at x = 3``."""
        if self.text:
            return self.text
        named = dict(self.names)
        fixed = [f"{k} = {named.get(k) or show(v)}" for k, v in self.values]
        return policy + (" at " + ", ".join(fixed) if fixed else "")


def show(value: Any) -> str:
    """A grid value in a short, readable form (floats with %g)."""
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{k}: {show(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(show(v) for v in value) + "]"
    return str(value)


def reserved(key: str, values: Any) -> str | None:
    """The reserved key that ``key`` (or a section mapping given for it) would set."""
    if key in RESERVED:
        return key
    for value in values if isinstance(values, list) else [values]:
        if isinstance(value, Mapping):
            for sub in value:
                found = reserved(f"{key}.{sub}", [value[sub]])
                if found:
                    return found
    return None


def grid(raw: Any, file: object, where: str) -> tuple[dict[str, list[Any]], dict[str, list[str]]]:
    """A mapping of dotted keys to non-empty lists of values, checked against the schema;
    a key's values may also be named (``name: value``).  Returns the values and, for
    keys with named values, their names."""
    if raw is None or (isinstance(raw, Mapping) and not raw and where == "grid"):
        raise ScenarioError(file, where, raw, "empty grid: give at least one key with a "
                            "list of values (or leave 'grid' out and vary keys per policy)")
    if not isinstance(raw, Mapping):
        raise ScenarioError(file, where, raw, "must be a mapping of dotted scenario keys "
                            "to lists of values, e.g. controller.ideal_cycle_s: [22.0, 21.5]")
    out: dict[str, list[Any]] = {}
    names: dict[str, list[str]] = {}
    for key, values in raw.items():
        key = str(key)
        if not known_key(key):
            raise ScenarioError(file, key, values, "unknown key to vary: no such setting in a "
                                "scenario (keys are dotted, e.g. controller.ideal_cycle_s)")
        found = reserved(key, list(values.values()) if isinstance(values, Mapping) else values)
        if found:
            raise ScenarioError(file, key, values, f"cannot be varied: {RESERVED[found]}")
        if isinstance(values, Mapping):
            names[key] = [str(n) for n in values]
            values = list(values.values())
        if not isinstance(values, list):
            raise ScenarioError(file, key, values, "must be a list of values to try "
                                "(or a mapping of names to values)")
        if not values:
            raise ScenarioError(file, key, values, "empty list: nothing to vary")
        seen: list[Any] = []
        for v in values:
            if v in seen:
                raise ScenarioError(file, key, v, "listed twice")
            seen.append(v)
        out[key] = values
    return out, names


def read_replications(raw: Mapping[str, Any], file: object) -> tuple[int, Precision | None]:
    """``replications``: a whole number, or a precision to reach (then the number is ``max``)."""
    spec = raw.get("replications")
    if not isinstance(spec, Mapping):
        try:
            return whole_number(spec, 1), None
        except ValueError as exc:
            raise ScenarioError(file, "replications", spec, str(exc)) from None
    p = read(PrecisionFile, spec, file, "replications.")
    return p.max, Precision(p.precision, p.measure, p.min, p.max, p.confidence)


def read_baseline(raw: Any, sweep: Sweep, file: object) -> Baseline:
    """``baseline``: the policy and/or values of varied keys of the point to compare with,
    checked against the grid; every point must have a baseline point."""
    policies = sweep.policies
    if not isinstance(raw, Mapping) or not raw:
        raise ScenarioError(file, "baseline", raw, "must name a point of the grid, e.g. "
                            "{policy: non-adaptive, controller.ideal_cycle_s: 22.5872}")
    policy = raw.get("policy")
    if "policy" in raw and policy not in policies:
        raise ScenarioError(file, "baseline.policy", policy,
                            "not a policy of this sweep (its policies: " + ", ".join(policies) + ")")
    values: list[tuple[str, Any]] = []
    names: list[tuple[str, str]] = []
    for key, value in raw.items():
        if key == "policy":
            continue
        key = str(key)
        if key not in sweep.keys:
            raise ScenarioError(file, f"baseline.{key}", value, "not a key this sweep varies"
                                + (" (it varies: " + ", ".join(sweep.keys) + ")" if sweep.keys
                                   else "; it varies only the policies"))
        holders = [p for p in sweep.points if key in dict(p.values)
                   and (policy is None or p.policy == policy)]
        if not holders:
            raise ScenarioError(file, f"baseline.{key}", value,
                                f"the {policy} policy does not vary this key")
        offered = [(p.name_of(key), dict(p.values)[key]) for p in holders]
        by_name = {n: v for n, v in offered if n is not None}
        if isinstance(value, str) and value in by_name:
            value = by_name[value]
        grid_values = distinct(v for _, v in offered)
        if value not in grid_values:
            raise ScenarioError(file, f"baseline.{key}", value, "not among the grid's values ("
                                + ", ".join(show(v) for v in grid_values) + ")")
        name = next((n for n, v in offered if n is not None and v == value), None)
        if name is not None:
            names.append((key, name))
        values.append((key, value))
    baseline = Baseline(policy, tuple(values), tuple(names))
    index = PointIndex(sweep.points)
    for p in sweep.points:
        if baseline_point(index, baseline, p) is None:
            target = policy or p.policy
            keys = [k for k, _ in next(q for q in sweep.points if q.policy == target).values
                    if k not in dict(p.values) and k not in dict(values)]
            raise ScenarioError(file, "baseline", dict(raw),
                                f"names no {target} point for the {p.policy} points; "
                                "name the value of " + (", ".join(keys) or "its keys"))
    return baseline


def baseline_point(index: PointIndex, baseline: Baseline, p: Point) -> int | None:
    """The index of ``p``'s baseline point among the indexed points: the baseline's policy
    (or ``p``'s) with the baseline's values, and ``p``'s for the keys it does not name."""
    target = {**dict(p.values), **dict(baseline.values)}
    found = index.find(baseline.policy or p.policy, target)
    return found[0] if found else None


def frozen(value: Any) -> Hashable:
    """A hashable stand-in for a grid value (YAML's lists and mappings too), equal to
    another's whenever the values are equal."""
    if isinstance(value, Mapping):
        return ("mapping", frozenset((k, frozen(v)) for k, v in value.items()))
    if isinstance(value, (list, tuple)):
        return ("sequence", tuple(frozen(v) for v in value))
    if isinstance(value, (set, frozenset)):
        return ("set", frozenset(frozen(v) for v in value))
    return value


def distinct(values: Any) -> list[Any]:
    """``values`` without repeats (by ``==``), in order of first appearance, in linear time."""
    seen: dict[Hashable, list[Any]] = {}
    out: list[Any] = []
    for v in values:
        alike = seen.setdefault(frozen(v), [])
        if not any(u is v or u == v for u in alike):
            alike.append(v)
            out.append(v)
    return out


class PointIndex:
    """A sweep's points by policy and values, so that finding the points that agree with
    some values takes time in proportion to the answer, not to the number of points."""

    def __init__(self, points: Sequence[Point]) -> None:
        self.points = points
        self._members: dict[tuple[str, tuple[str, ...]], list[int]] = {}
        for j, q in enumerate(points):
            self._members.setdefault((q.policy, tuple(k for k, _ in q.values)), []).append(j)
        self._tables: dict[tuple[str, tuple[str, ...], tuple[str, ...]],
                           dict[Hashable, list[int]]] = {}

    def _table(self, group: tuple[str, tuple[str, ...]],
               on: tuple[str, ...]) -> dict[Hashable, list[int]]:
        """The group's points by their values of the keys ``on`` (built once)."""
        table = self._tables.get((*group, on))
        if table is None:
            table = {}
            for j in self._members[group]:
                mine = dict(self.points[j].values)
                table.setdefault(frozen([mine[k] for k in on]), []).append(j)
            self._tables[(*group, on)] = table
        return table

    def find(self, policy: str, values: Mapping[str, Any], every: bool = True) -> list[int]:
        """Indices, ascending, of ``policy``'s points whose values equal ``values``: on every
        key the point varies (``every``: each of them must be in ``values``), or on the keys
        both have."""
        found: list[int] = []
        for group in self._members:
            keys = group[1]
            if group[0] != policy or every and not all(k in values for k in keys):
                continue
            on = tuple(k for k in keys if k in values)
            found += [j for j in self._table(group, on).get(frozen([values[k] for k in on]), ())
                      if all(values[k] == v for k, v in self.points[j].values if k in values)]
        return sorted(found)
