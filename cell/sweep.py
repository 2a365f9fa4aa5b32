"""Replicated sweeps over scenario keys: ``cell sweep`` (thesis §6.3, §7.2; SPEC §8).

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
grid points see the same parts (common random numbers), and no result depends
on the number of workers or the order tasks finish in.

A task is one batch of replications of one grid point.  Tasks run in local
worker processes, or on a dask.distributed cluster through its
concurrent.futures executor; each finished task is written at once, atomically,
to ``OUT/tasks/``, so ``--resume`` runs only the tasks that are missing.
``OUT/replications.csv`` is always assembled from those files in a fixed order,
so it is byte-identical however the sweep was run.  Its columns: ``policy``,
``point`` (index of the grid point within its policy), one column per varied key
(empty where a policy does not vary it), ``replication``, then the run's summary
(``cell.simulation``'s summary.csv columns).  ``--workers 1`` runs in this process.
"""

from __future__ import annotations

import concurrent.futures as cf
import functools
import hashlib
import itertools
import json
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cell import registry
from cell.errors import CellError, ScenarioError
from cell.output import write_csv, write_text
from cell.scenario import Scenario, known_key, load_scenario

#: A replication: (scenario, stream) -> the run's summary row.
Replicate = Callable[[Scenario, np.random.SeedSequence], Mapping[str, Any]]

SWEEP_KEYS = ("name", "description", "base", "set", "grid", "policies",
              "replications", "seed", "batch")
#: Keys the sweep itself sets for every run; they cannot be varied in a grid.
RESERVED = {"controller.policy": "list policies under 'policies'",
            "run.seed": "every replication gets its own stream from the sweep's 'seed'"}
#: Float digits in the per-task files: enough to round-trip exactly.
TASK_FLOAT_FORMAT = "%.17g"
MANIFEST = "sweep.json"
#: How long to try reaching a dask scheduler.
CONNECT_TIMEOUT = "20s"
TASK_DIR = "tasks"


# --------------------------------------------------------------------------- the sweep
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


# --------------------------------------------------------------------------- running
def simulate_summary(scenario: Scenario, seed: np.random.SeedSequence) -> Mapping[str, Any]:
    """The default replication: one run of the cell, its summary row."""
    from cell.simulation import simulate

    return simulate(scenario, seed=seed, keep_parts=False).summary.as_dict()


def run_task(replicate: Replicate, scenario: Scenario,
             seeds: Sequence[np.random.SeedSequence]) -> list[dict[str, Any]]:
    """Run one batch (in a worker): each stream's summary as a plain dict.

    Each replication gets a fresh copy of its stream, so a replication that
    spawns from it cannot change what the next point or policy sees.
    """
    return [{k: _plain(v) for k, v in replicate(scenario, _fresh(s)).items()} for s in seeds]


def _fresh(seed: np.random.SeedSequence) -> np.random.SeedSequence:
    return np.random.SeedSequence(seed.entropy, spawn_key=seed.spawn_key,
                                  pool_size=seed.pool_size)


def _plain(value: Any) -> Any:
    return value.item() if isinstance(value, np.generic) else value


def _task_frame(sweep: Sweep, task: Task, rows: Sequence[Mapping[str, Any]]) -> pd.DataFrame:
    point = sweep.points[task.point]
    values = dict(point.values)
    records = []
    for r, summary in zip(range(task.first, task.last), rows, strict=True):
        record: dict[str, Any] = {"policy": point.policy, "point": point.index}
        record.update({k: values.get(k) for k in sweep.keys})
        record["replication"] = r
        record.update({k: v for k, v in summary.items() if k not in record})
        records.append(record)
    return pd.DataFrame.from_records(records)


def _read_task(path: Path, task: Task) -> pd.DataFrame | None:
    """A finished task's rows, or None if the file is missing or not this task's."""
    if not path.is_file():
        return None
    try:
        frame = pd.read_csv(path)
    except (OSError, ValueError):
        return None
    if len(frame) != task.size or "replication" not in frame.columns:
        return None
    if list(frame["replication"]) != list(range(task.first, task.last)):
        return None
    return frame


@dataclass
class Outcome:
    """What :func:`run_sweep` did."""

    replications: pd.DataFrame
    tasks_run: int
    tasks_reused: int


def _open_executor(workers: int, scheduler: str | None) -> tuple[cf.Executor | None, Any]:
    """The executor for the tasks (None: run in this process) and a client to close."""
    if scheduler:
        try:
            import distributed
        except ImportError:
            raise CellError("--scheduler needs dask.distributed: "
                            "pip install 'cell[dist]'") from None
        try:
            client = distributed.Client(scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError) as exc:
            raise CellError(f"--scheduler {scheduler}: cannot reach the dask scheduler "
                            f"({exc})") from None
        return client.get_executor(pure=False), client
    if workers <= 1:
        return None, None
    return cf.ProcessPoolExecutor(max_workers=workers, initializer=_worker_init,
                                  initargs=(os.getpid(),)), None


def _worker_init(parent: int) -> None:
    """In each local worker: leave Ctrl-C to the sweep, and exit if the sweep dies
    (even by kill -9), so no orphan keeps running."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="watch-sweep").start()


def _run_tasks(sweep: Sweep, todo: Sequence[Task], replicate: Replicate,
               executor: cf.Executor | None,
               done: Callable[[Task, list[dict[str, Any]]], None]) -> None:
    seeds = sweep.seeds()

    def args(task: Task) -> tuple[Any, ...]:
        return (replicate, sweep.points[task.point].scenario, seeds[task.first:task.last])

    if executor is None:
        for task in todo:
            done(task, _guarded(sweep, task, functools.partial(run_task, *args(task))))
        return
    futures = {executor.submit(run_task, *args(task)): task for task in todo}
    try:
        for future in cf.as_completed(futures):
            task = futures[future]
            done(task, _guarded(sweep, task, future.result))
    except BaseException:
        for future in futures:
            future.cancel()
        raise


def _guarded(sweep: Sweep, task: Task, call: Callable[[], list[dict[str, Any]]]
             ) -> list[dict[str, Any]]:
    try:
        return call()
    except CellError as exc:
        point = sweep.points[task.point]
        where = ", ".join(f"{k}={v!r}" for k, v in point.values) or "base"
        raise CellError(f"{sweep.source}: {point.policy} {where}, replications "
                        f"{task.first}-{task.last - 1}: {exc}") from None


def _close(executor: cf.Executor | None, client: Any, wait: bool) -> None:
    if isinstance(executor, cf.ProcessPoolExecutor):
        executor.shutdown(wait=wait, cancel_futures=not wait)
    elif executor is not None:
        executor.shutdown(wait=wait)
    if client is not None:
        client.close()


def run_sweep(sweep: Sweep, out: str | Path, *, workers: int | None = None,
              scheduler: str | None = None, resume: bool = False,
              replicate: Replicate = simulate_summary, progress: bool = True) -> Outcome:
    """Run (or finish, with ``resume``) a sweep into ``out``; write replications.csv.

    ``replicate`` is what one replication does; the default simulates the cell.
    It must be a module-level function when tasks run in other processes.
    """
    from tqdm import tqdm

    out = Path(out)
    workers = (os.cpu_count() or 1) if workers is None else workers
    if workers < 1:
        raise CellError(f"--workers {workers}: must be at least 1")
    executor, client = _open_executor(workers, scheduler)
    try:
        tasks = sweep.tasks()
        task_dir = out / TASK_DIR
        manifest = out / MANIFEST
        fingerprint = sweep.fingerprint()
        frames: dict[int, pd.DataFrame] = {}
        if resume and manifest.is_file():
            try:
                previous = json.loads(manifest.read_text()).get("fingerprint")
            except (OSError, ValueError):
                previous = None
            if previous != fingerprint:
                raise CellError(f"--resume: {out} holds the results of a different sweep "
                                f"(or of {sweep.source} before it was edited); "
                                "run without --resume or choose another --out")
            for task in tasks:
                frame = _read_task(task_dir / task.filename, task)
                if frame is not None:
                    frames[task.id] = frame
        else:
            for stale in task_dir.glob("task-*.csv") if task_dir.is_dir() else ():
                stale.unlink()
            (out / "replications.csv").unlink(missing_ok=True)
        write_text(json.dumps({"sweep": sweep.source, "name": sweep.name,
                               "fingerprint": fingerprint, "tasks": len(tasks),
                               "replications": sweep.replications, "seed": sweep.seed,
                               "batch": sweep.batch}, indent=2) + "\n", manifest)
        todo = [t for t in tasks if t.id not in frames]
        bar = tqdm(total=sweep.total_replications, initial=sweep.total_replications
                   - sum(t.size for t in todo), unit="rep", desc=sweep.name,
                   disable=not progress, file=sys.stderr, dynamic_ncols=True)

        def done(task: Task, rows: list[dict[str, Any]]) -> None:
            write_csv(_task_frame(sweep, task, rows), task_dir / task.filename,
                      float_format=TASK_FLOAT_FORMAT)
            bar.update(task.size)

        with bar:
            _run_tasks(sweep, todo, replicate, executor, done)
    except BaseException:
        _close(executor, client, wait=False)
        raise
    _close(executor, client, wait=True)

    # Assemble from the files, never from memory: a resumed sweep and an
    # uninterrupted one go through the same bytes.
    parts = []
    for task in tasks:
        frame = _read_task(task_dir / task.filename, task)
        if frame is None:  # pragma: no cover - written above
            raise CellError(f"{task_dir / task.filename}: missing or damaged; rerun the sweep")
        parts.append(frame)
    table = pd.concat(parts, ignore_index=True)
    write_csv(table, out / "replications.csv")
    return Outcome(pd.read_csv(out / "replications.csv"), len(todo), len(tasks) - len(todo))
