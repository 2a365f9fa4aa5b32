"""Running a sweep: tasks in local processes or on a dask cluster, resumable.

A task is one batch of replications of one grid point.  Tasks run in local
worker processes, or on a dask.distributed cluster through its
concurrent.futures executor; each finished task is written at once, atomically,
to ``OUT/tasks/``, so ``--resume`` runs only the tasks that are missing.
``OUT/replications.csv`` is always assembled from those files in a fixed order,
so it is byte-identical however the sweep was run: no result depends on the
number of workers or the order tasks finish in.  Its columns: ``policy``,
``point`` (index of the grid point within its policy), one column per varied key
(empty where a policy does not vary it), ``replication``, then the run's summary
(:class:`cell.records.RunSummary`).  ``--workers 1`` runs in this process.
"""

from __future__ import annotations

import concurrent.futures as cf
import functools
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

from cell.errors import CellError
from cell.output import write_csv, write_text
from cell.scenario import Scenario
from cell.sweep.spec import Sweep, Task

#: A replication: (scenario, stream) -> the run's summary row.
Replicate = Callable[[Scenario, np.random.SeedSequence], Mapping[str, Any]]

#: Float digits in the per-task files: enough to round-trip exactly.
TASK_FLOAT_FORMAT = "%.17g"
MANIFEST = "sweep.json"
#: How long to try reaching a dask scheduler.
CONNECT_TIMEOUT = "20s"
TASK_DIR = "tasks"


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
