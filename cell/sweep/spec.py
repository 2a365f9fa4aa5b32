"""A sweep file: the base scenario, the grid, the policies and the replications.

A sweep file names a base scenario, the keys to vary (a grid, keys written as in
a scenario), the policies to run, the number of replications and a root seed::

    base: baseline.yaml            # relative to the sweep file
    set: {run.parts: 500}          # fixed overrides (optional)
    grid:                          # applied to every policy (optional)
      belts.output_nominal_in_s: [2.0, 2.5]
    policies:                      # a list, or policy -> its own extra grid
      non-adaptive: {controller.ideal_cycle_s: [22.5872, 22.0]}
      adaptive: {}
    replications: 200
    seed: 1984
    batch: 20                      # replications per task (optional)

Replication ``r`` of every grid point and every policy is driven by the same
stream, ``SeedSequence(seed).spawn(replications)[r]``: the policies and the
grid points see the same parts (common random numbers).
"""

from __future__ import annotations

import hashlib
import itertools
import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cell import registry
from cell.errors import ScenarioError
from cell.scenario import Scenario, known_key, load_scenario

SWEEP_KEYS = ("name", "description", "base", "set", "grid", "policies",
              "replications", "seed", "batch")
#: Keys the sweep itself sets for every run; they cannot be varied in a grid.
RESERVED = {"controller.policy": "list policies under 'policies'",
            "run.seed": "every replication gets its own stream from the sweep's 'seed'"}


@dataclass(frozen=True)
class Point:
    """One scenario of the grid: a policy and the values of the varied keys."""

    policy: str
    index: int
    """Position of the point within its policy's grid (0-based)."""
    values: tuple[tuple[str, Any], ...]
    """The varied keys and their values here, in the sweep file's order."""
    scenario: Scenario


@dataclass(frozen=True)
class Task:
    """A batch of replications ``first .. last-1`` of one point."""

    id: int
    point: int
    """Index into :attr:`Sweep.points`."""
    first: int
    last: int

    @property
    def size(self) -> int:
        return self.last - self.first

    @property
    def filename(self) -> str:
        return f"task-{self.id:05d}.csv"


@dataclass(frozen=True)
class Sweep:
    """A validated sweep file."""

    source: str
    name: str
    description: str
    base: Scenario
    fixed: tuple[tuple[str, Any], ...]
    keys: tuple[str, ...]
    """Every varied key, in order of first appearance (the grid's, then each policy's)."""
    points: tuple[Point, ...]
    replications: int
    seed: int
    batch: int

    def seeds(self) -> list[np.random.SeedSequence]:
        """Replication r's stream: the same for every point and policy (CRN)."""
        return np.random.SeedSequence(self.seed).spawn(self.replications)

    def tasks(self) -> list[Task]:
        out: list[Task] = []
        for p in range(len(self.points)):
            for first in range(0, self.replications, self.batch):
                out.append(Task(len(out), p, first, min(first + self.batch, self.replications)))
        return out

    @property
    def total_replications(self) -> int:
        return len(self.points) * self.replications

    def fingerprint(self) -> str:
        """Hash of everything that decides the results (for ``--resume``)."""
        doc = {"base": self.base.to_dict(), "fixed": [list(kv) for kv in self.fixed],
               "points": [[p.policy, [list(kv) for kv in p.values]] for p in self.points],
               "replications": self.replications, "seed": self.seed, "batch": self.batch}
        text = json.dumps(doc, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()


def _grid(raw: Any, file: object, where: str) -> dict[str, list[Any]]:
    """A mapping of dotted keys to non-empty lists of values, checked against the schema."""
    if raw is None or (isinstance(raw, Mapping) and not raw and where == "grid"):
        raise ScenarioError(file, where, raw, "empty grid: give at least one key with a "
                            "list of values (or leave 'grid' out and vary keys per policy)")
    if not isinstance(raw, Mapping):
        raise ScenarioError(file, where, raw, "must be a mapping of dotted scenario keys "
                            "to lists of values, e.g. controller.ideal_cycle_s: [22.0, 21.5]")
    out: dict[str, list[Any]] = {}
    for key, values in raw.items():
        key = str(key)
        if not known_key(key):
            raise ScenarioError(file, key, values, "unknown key to vary: no such setting in a "
                                "scenario (keys are dotted, e.g. controller.ideal_cycle_s)")
        reserved = _reserved(key, values)
        if reserved:
            raise ScenarioError(file, key, values, f"cannot be varied: {RESERVED[reserved]}")
        if not isinstance(values, list):
            raise ScenarioError(file, key, values, "must be a list of values to try")
        if not values:
            raise ScenarioError(file, key, values, "empty list: nothing to vary")
        seen: list[Any] = []
        for v in values:
            if v in seen:
                raise ScenarioError(file, key, v, "listed twice")
            seen.append(v)
        out[key] = values
    return out


def _reserved(key: str, values: Any) -> str | None:
    """The reserved key that ``key`` (or a section mapping given for it) would set."""
    if key in RESERVED:
        return key
    for value in values if isinstance(values, list) else [values]:
        if isinstance(value, Mapping):
            for sub in value:
                found = _reserved(f"{key}.{sub}", [value[sub]])
                if found:
                    return found
    return None


def _whole(raw: Mapping[str, Any], key: str, default: Any, lo: int, file: object) -> int:
    value = raw.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < lo:
        raise ScenarioError(file, key, value, f"must be a whole number of at least {lo}")
    return value


def load_sweep(path: str | Path) -> Sweep:
    """Read and validate a sweep file; every grid point's scenario is built and checked."""
    path = Path(path)
    from cell.yamlio import load_mapping

    raw = load_mapping(path, "sweep")
    for key in raw:
        if key not in SWEEP_KEYS:
            raise ScenarioError(path, str(key), raw[key],
                                "unknown key (known: " + ", ".join(SWEEP_KEYS) + ")")
    if "base" not in raw or not isinstance(raw["base"], str):
        raise ScenarioError(path, "base", raw.get("base"),
                            "name the base scenario file (relative to the sweep file)")
    base = load_scenario(path.parent / raw["base"])

    fixed = raw.get("set") or {}
    if not isinstance(fixed, Mapping):
        raise ScenarioError(path, "set", fixed, "must be a mapping of dotted keys to values")
    for key, value in fixed.items():
        if not known_key(str(key)):
            raise ScenarioError(path, str(key), value, "unknown key: no such setting in a scenario")
        reserved = _reserved(str(key), [value])
        if reserved:
            raise ScenarioError(path, str(key), value, f"cannot be set here: {RESERVED[reserved]}")

    shared = _grid(raw["grid"], path, "grid") if "grid" in raw else {}
    policies_raw = raw.get("policies", [base.controller.policy])
    per_policy: dict[str, dict[str, list[Any]]] | None
    if isinstance(policies_raw, list):
        per_policy = {p: {} for p in policies_raw} if policies_raw else None
    elif isinstance(policies_raw, Mapping):
        per_policy = {p: (_grid(g, path, f"policies.{p}") if g else {})
                      for p, g in policies_raw.items()} if policies_raw else None
    else:
        per_policy = None
    if not per_policy:
        raise ScenarioError(path, "policies", policies_raw, "must list at least one of "
                            + ", ".join(registry.names()) + " (a list, or policy: {key: [values]})")
    for policy, grid in per_policy.items():
        if policy not in registry.names():
            raise ScenarioError(path, "policies", policy,
                                "must be one of " + ", ".join(registry.names()))
        for key in set(grid) & set(shared):
            raise ScenarioError(path, f"policies.{policy}", key,
                                "varied both in 'grid' and under the policy; keep one")

    replications = _whole(raw, "replications", None, 1, path)
    seed = _whole(raw, "seed", base.run.seed, 0, path)
    batch = _whole(raw, "batch", min(20, replications), 1, path)

    keys = tuple(dict.fromkeys(itertools.chain(shared, *per_policy.values())))
    points: list[Point] = []
    for policy, own in per_policy.items():
        grid = {**shared, **own}
        for i, combo in enumerate(itertools.product(*grid.values())):
            values = tuple(zip(grid, combo, strict=True))
            scenario = base.with_overrides(
                {**fixed, "controller.policy": policy, **dict(values)}, file=path)
            _check_point(scenario, path)
            points.append(Point(policy, i, values, scenario))

    name = raw.get("name", path.stem)
    return Sweep(str(path), str(name), str(raw.get("description", "")), base,
                 tuple(fixed.items()), keys, tuple(points), replications, seed, batch)


def _check_point(scenario: Scenario, file: object) -> None:
    """Assemble a grid point's cell now, so that no bad point is found after work began;
    an error names the sweep file, with the key and value it was about."""
    from cell.assembly import assemble

    try:
        assemble(scenario)
    except ScenarioError as exc:
        raise ScenarioError(file, exc.key, exc.value, exc.why) from None


