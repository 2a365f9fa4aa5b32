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
    replications: 200              # or {precision: 0.01, measure: ..., min: 10, max: 2000}
    seed: 1984
    batch: 20                      # replications per task (optional)
    baseline: {policy: non-adaptive, controller.ideal_cycle_s: 22.5872}   # optional

Replication ``r`` of every grid point and every policy is driven by the same
stream, ``SeedSequence(seed, spawn_key=(r,))`` -- the same as
``SeedSequence(seed).spawn(n)[r]`` for any n > r, so it does not depend on how
many replications are run: the policies and the grid points see the same parts
(common random numbers), and a precision-driven sweep that stops early draws
exactly what a fixed one would.

``replications`` as a mapping asks for a precision (:class:`Precision`): rounds
of ``batch`` replications are added to every point whose confidence half-width
for ``measure`` is still above ``precision`` × |mean|, until ``max``.

``baseline`` names the point every other point is compared with (paired
differences, :meth:`Sweep.pairs`); without it, every policy is compared with
each policy listed before it, at every grid point.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cell.experiments.sweep.checks import refuse_measure_unset, refuse_set_and_varied
from cell.experiments.sweep.options import (
    RESERVED,
    Baseline,
    PointIndex,
    Precision,
    baseline_point,
    grid,
    read_baseline,
    read_replications,
    reserved,
    summary_measures,
)
from cell.experiments.sweep.overload import nominal_gap, overload_warning, overloaded
from cell.experiments.sweep.policy_names import check_policy_names
from cell.experiments.sweep.sweep_schema import SweepFile, read
from cell.plumbing.errors import ScenarioError
from cell.plumbing.progress import Progress
from cell.scenario import registry
from cell.scenario.schema import Scenario, known_key, load_scenario

#: At most this many grid points, and this many runs (points x replications), in a sweep.
MAX_POINTS = 100_000
MAX_RUNS = 10_000_000
#: Checking this many points or more shows progress.
SHOW_CHECKING = 1_000

SWEEP_KEYS = tuple(SweepFile.model_fields)
__all__ = ["RESERVED", "SWEEP_KEYS", "Baseline", "Pair", "Point", "Precision", "Sweep", "Task",
           "load_sweep", "nominal_gap", "overload_warning", "overloaded", "summary_measures"]


@dataclass(frozen=True)
class Point:
    """One scenario of the grid: a policy and the values of the varied keys."""

    policy: str
    index: int
    """Position of the point within its policy's grid (0-based)."""
    values: tuple[tuple[str, Any], ...]
    """The varied keys and their values here, in the sweep file's order."""
    scenario: Scenario
    names: tuple[tuple[str, str], ...] = ()
    """For keys whose grid values are named: the name of the value here."""
    offered_load: float = math.nan
    """The robot's fastest cycle over the mean inter-arrival time here (1 or more: the cell
    cannot keep up on average)."""
    nominal_gap: float = math.nan
    """How far the nominal cycle the scenario states (``controller.nominal_cycle_s``) is off
    the arrivals' mean here, relative and signed; NaN where the cycle follows the arrivals."""

    def name_of(self, key: str) -> str | None:
        """The name of this point's value of ``key``, if the sweep file named it."""
        return dict(self.names).get(key)


@dataclass(frozen=True)
class Pair:
    """A paired comparison: point ``point`` minus point ``versus``, replication by replication."""

    point: int
    versus: int
    label: str
    """How the report names ``versus``: its policy, and the keys a baseline fixes."""


@dataclass(frozen=True)
class Task:
    """A batch of replications ``first .. last-1`` of one point."""

    point: int
    """Index into :attr:`Sweep.points`."""
    first: int
    last: int

    @property
    def size(self) -> int:
        return self.last - self.first

    @property
    def filename(self) -> str:
        return f"task-{self.point:05d}-{self.first:010d}.csv"


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
    """Replications per point; with a precision, the most any point gets (``max``)."""
    seed: int
    batch: int
    precision: Precision | None = None
    baseline: Baseline | None = None

    def stream(self, replication: int) -> np.random.SeedSequence:
        """Replication r's stream: the same for every point and policy (CRN), and
        ``SeedSequence(seed).spawn(n)[r]`` for any n > r."""
        return np.random.SeedSequence(self.seed, spawn_key=(replication,))

    @property
    def policies(self) -> list[str]:
        """The sweep's policies, in the order its points list them."""
        return list(dict.fromkeys(p.policy for p in self.points))

    @property
    def confidence(self) -> float:
        """The confidence level of every interval of the sweep's report."""
        return self.precision.confidence if self.precision else 0.95

    @property
    def first_round(self) -> int:
        """Replications every point gets before any precision is judged."""
        return self.precision.min_n if self.precision else self.replications

    def iter_tasks(self, ranges: dict[int, tuple[int, int]] | None = None) -> Iterator[Task]:
        """The tasks covering replications ``first .. last-1`` of each point (by default
        the first round), cut into batches, in point order; one at a time, so a sweep of
        many replications holds no list of them."""
        if ranges is None:
            ranges = {p: (0, self.first_round) for p in range(len(self.points))}
        for p, (start, last) in sorted(ranges.items()):
            for first in range(start, last, self.batch):
                yield Task(p, first, min(first + self.batch, last))

    @property
    def total_replications(self) -> int:
        return len(self.points) * self.first_round

    def fingerprint(self, replications: bool = True) -> str:
        """Hash of everything that decides the results (for ``--resume``): the settings,
        the content of every file the points name (:mod:`cell.experiments.sweep.inputs`) and the
        version of cell.  Without ``replications``: of all but the number of replications,
        the batch and a precision, which replication r's results do not depend on (what a
        sweep run again at another count shares with the first run:
        :func:`cell.experiments.sweep.outdir.check_owner`)."""
        from cell import __version__
        from cell.experiments.sweep.inputs import digest, sweep_files

        doc: dict[str, Any] = {
            "base": self.base.to_dict(), "fixed": [list(kv) for kv in self.fixed],
            "points": [[p.policy, [list(kv) for kv in p.values]] for p in self.points],
            "seed": self.seed,
            "files": sorted(str(digest(f)) for f in sweep_files(self)), "version": __version__}
        if replications:
            doc |= {"replications": self.replications, "batch": self.batch}
        if replications and self.precision is not None:
            doc["precision"] = self.precision.as_dict()
        text = json.dumps(doc, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()

    def pairs(self) -> list[Pair]:
        """The paired comparisons: every point against its baseline point (the one the
        ``baseline`` names, with this point's values for the keys it does not name); or,
        without a baseline, every point against each point of a policy listed before
        its own that agrees with it on the keys both vary."""
        out: list[Pair] = []
        index = PointIndex(self.points)
        if self.baseline is not None:
            b = self.baseline
            for i, p in enumerate(self.points):
                j = baseline_point(index, b, p)
                if j is not None and j != i:
                    out.append(Pair(i, j, b.label(self.points[j].policy)))
            return out
        order = self.policies
        for i, p in enumerate(self.points):
            mine = dict(p.values)
            before = order[:order.index(p.policy)]
            found = sorted(j for q in before for j in index.find(q, mine, every=False))
            out += [Pair(i, j, self.points[j].policy) for j in found]
        return out


def load_sweep(path: str | Path, sets: dict[str, Any] | None = None) -> Sweep:
    """Read and validate a sweep file (or a built-in one by name); every grid point's
    scenario is built and checked.  ``sets``: dotted keys set on top of its ``set:``
    (``cell sweep --set``), checked as that is."""
    from cell.scenario import catalog
    from cell.scenario.yamlio import load_mapping

    path = catalog.resolve(path)
    raw = load_mapping(path, "sweep")
    catalog.refuse_other_kind(raw, path, "sweep")
    doc = read(SweepFile, raw, path)  # keys, types and bounds (pydantic, as a scenario's)
    base_path = catalog.resolve(raw["base"], beside=path.parent)  # or a built-in by name
    if not base_path.exists():
        raise ScenarioError(path, "base", raw["base"],
                            f"no such scenario file ({base_path}) nor built-in scenario "
                            "(`cell scenarios` lists them)")
    base = load_scenario(base_path)
    fixed = {**(doc.set or {}), **(sets or {})}  # --set on top of the file's set:
    for key, value in fixed.items():
        if not known_key(str(key)):
            raise ScenarioError(path, str(key), value, "unknown key: no such setting in a scenario")
        found = reserved(str(key), [value])
        if found:
            raise ScenarioError(path, str(key), value, f"cannot be set here: {RESERVED[found]}")
    shared, names = grid(raw["grid"], path, "grid") if "grid" in raw else ({}, {})
    check_policy_names(raw.get("policies", [base.controller.policy]), path)  # one name each
    per_policy, named_by_policy = _policies(raw, path, base, shared, names)
    refuse_set_and_varied(fixed, {"grid": shared, **{f"policies.{p}": g
                                                      for p, g in per_policy.items()}}, path)
    replications, precision = read_replications(raw, path)
    if precision is not None:
        refuse_measure_unset(precision.measure, list(per_policy), path)
    seed = base.run.seed if doc.seed is None else doc.seed
    batch = min(20, precision.min_n if precision else replications) if doc.batch is None else doc.batch

    keys = tuple(dict.fromkeys(itertools.chain(shared, *per_policy.values())))
    n_points = sum(math.prod(len(v) for v in {**shared, **own}.values())
                   for own in per_policy.values())
    if n_points > MAX_POINTS:
        raise ScenarioError(path, "grid", f"{n_points:,} points", f"at most {MAX_POINTS:,} grid "
                            "points in one sweep (split it into several)")
    if n_points * replications > MAX_RUNS:
        raise ScenarioError(path, "replications", replications,
                            f"{n_points:,} points x {replications:,} replications: at most "
                            f"{MAX_RUNS:,} runs in one sweep")
    points = _points(path, base, fixed, shared, names, per_policy, named_by_policy, n_points)

    name = path.stem if doc.name is None else doc.name
    sweep = Sweep(str(path), str(name), "" if doc.description is None else str(doc.description), base,
                  tuple(fixed.items()), keys, tuple(points), replications, seed, batch,
                  precision)
    if "baseline" in raw:
        baseline = read_baseline(raw["baseline"], sweep, path)
        sweep = dataclasses.replace(sweep, baseline=baseline)
    return sweep


PolicyGrids = dict[str, dict[str, list[Any]]]
PolicyNames = dict[str, dict[str, list[str]]]


def _policies(raw: dict[Any, Any], path: Path, base: Scenario, shared: dict[str, list[Any]],
              names: dict[str, list[str]]) -> tuple[PolicyGrids, PolicyNames]:
    """``policies``: each policy's own grid, and its named values (the shared grid's too)."""
    policies_raw = raw.get("policies", [base.controller.policy])
    per_policy: PolicyGrids | None = None
    named_by_policy: PolicyNames = {}
    if isinstance(policies_raw, list) and policies_raw:
        per_policy = {p: {} for p in policies_raw}
    elif isinstance(policies_raw, dict) and policies_raw:
        per_policy = {}
        for p, g in policies_raw.items():
            per_policy[p], own_names = grid(g, path, f"policies.{p}") if g else ({}, {})
            named_by_policy[p] = {**names, **own_names}
    if not per_policy:
        raise ScenarioError(path, "policies", policies_raw, "must list at least one of "
                            + ", ".join(registry.names()) + " (a list, or policy: {key: [values]})")
    for policy, own in per_policy.items():
        if policy not in registry.names():
            raise ScenarioError(path, "policies", policy,
                                "must be one of " + ", ".join(registry.names()))
        for key in set(own) & set(shared):
            raise ScenarioError(path, f"policies.{policy}", key,
                                "varied both in 'grid' and under the policy; keep one")
    return per_policy, named_by_policy


def _points(path: Path, base: Scenario, fixed: dict[Any, Any], shared: dict[str, list[Any]],
            names: dict[str, list[str]], per_policy: PolicyGrids, named_by_policy: PolicyNames,
            n_points: int) -> list[Point]:
    """Every grid point of every policy, its scenario built and checked (:func:`_check_point`)."""
    points: list[Point] = []
    checking = Progress(n_points, f"checking {path.name}", "points",
                        enabled=n_points >= SHOW_CHECKING)
    for policy, own in per_policy.items():
        combined = {**shared, **own}
        for i, combo in enumerate(itertools.product(*(range(len(v)) for v in combined.values()))):
            values = tuple((k, combined[k][j]) for k, j in zip(combined, combo, strict=True))
            own_names = named_by_policy.get(policy, names)
            named = tuple((k, own_names[k][j]) for k, j in zip(combined, combo, strict=True)
                          if k in own_names)
            scenario = base.with_overrides(  # files the sweep names: from its folder
                {**fixed, "controller.policy": policy, **dict(values)}, file=path,
                paths_from=path.parent)
            points.append(Point(policy, i, values, scenario, named,
                                **_check_point(scenario, path)))
            checking.update()
    checking.close()
    return points


def _check_point(scenario: Scenario, file: object) -> dict[str, float]:
    """Assemble a grid point's cell now, so that no bad point is found after work began;
    an error names the sweep file, with the key and value it was about.  Returns the
    point's offered load and nominal_gap (:class:`Point`)."""
    from cell.sim.assembly import assemble

    try:
        k = assemble(scenario).k
    except ScenarioError as exc:
        raise ScenarioError(file, exc.key, exc.value, exc.why) from None
    return {"offered_load": k.offered_load, "nominal_gap": nominal_gap(k)}


def comparison(a: Scenario, b: Scenario, labels: tuple[str, str], replications: int, seed: int,
               batch: int = 20) -> Sweep:
    """Two scenarios as a sweep of two points, varying the pseudo-key ``scenario`` (their
    labels, which must differ: :func:`cell.cli.compare.labels`): ``a`` against ``b``
    (the baseline), with common random numbers."""
    la, lb = labels
    if la == lb:
        raise ValueError(f"the two sides of a comparison need different labels, not {la!r} twice")
    pa = Point(a.controller.policy, 0, (("scenario", la),), a, (), **_check_point(a, a.source))
    pb = Point(b.controller.policy, int(b.controller.policy == a.controller.policy),
               (("scenario", lb),), b, (), **_check_point(b, b.source))
    return Sweep(f"{la} against {lb}", "compare", f"{la} against {lb}", a, (), ("scenario",),
                 (pa, pb), replications, seed, min(batch, replications),
                 baseline=Baseline(b.controller.policy, (("scenario", lb),),
                                   text=lb))  # the report names the scenarios, not policies


def comparison_sides(sweep: Sweep) -> tuple[tuple[str, Point], tuple[str, Point]]:
    """(label, point) of A and of B, of a :func:`comparison`."""
    (la, a), (lb, b) = ((dict(p.values)["scenario"], p) for p in sweep.points)
    return (la, a), (lb, b)
