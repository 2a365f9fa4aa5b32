"""Running a sweep: tasks in local processes or on a dask cluster, resumable.

A task is one batch of replications of one grid point.  Tasks run in local
worker processes, or on a dask.distributed cluster through its
concurrent.futures executor; each finished task is written at once, atomically,
to ``OUT/tasks/``, so ``--resume`` runs only the tasks that are missing.

A sweep with a precision (:class:`cell.experiments.sweep.spec.Precision`) runs in rounds:
the first gives every point ``min`` replications; after each whole round, and
only then, each point's replications so far (in replication order) decide
whether it needs another ``batch`` (:func:`cell.experiments.stats.precision_reached`,
:func:`~cell.experiments.stats.next_round`).  A round's tasks are ordinary tasks, so
``--resume`` replays the same rounds from the files.

``OUT/replications.csv`` (or, with ``result_format="parquet"``, ``replications.parquet``
in its place; :mod:`cell.experiments.sweep.results`) is always assembled from those files in a fixed order
(point, then replication), so it is byte-identical however the sweep was run: no
result depends on the number of workers or the order tasks finish in.  Its
columns: ``policy``; ``point`` (index of the grid point within its policy); the
grid's columns (:mod:`cell.experiments.sweep.columns`: one per varied key, one per leaf for
mapping values, filled for points that do not vary the key); ``seed`` (the
sweep's root seed) and ``replication`` (r); then the run's summary
(:class:`cell.sim.records.RunSummary`, without its ``policy`` and ``seed``).  A row
is reproduced by ``simulate(scenario, seed=np.random.SeedSequence(seed,
spawn_key=(replication,)))``, which is ``SeedSequence(seed).spawn(n)[replication]``
for any n > replication.  ``--workers 1`` runs in this process.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import functools
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cell.experiments.sweep.columns import grid_columns
from cell.experiments.sweep.outdir import MANIFEST, RESULT_FILES, TASK_DIR, check_out, finished_tasks, prepare
from cell.experiments.sweep.results import (
    assemble_results,
    measure_values,
    read_task,
    task_records,
    write_task,
)
from cell.experiments.sweep.spec import Sweep, Task, overload_warning
from cell.experiments.sweep.windows import window_warning
from cell.plumbing.cache import Identity, memo
from cell.plumbing.errors import CellError
from cell.plumbing.progress import Progress
from cell.scenario.schema import Scenario

if TYPE_CHECKING:  # pandas is imported when first needed: local workers start without it
    import pandas as pd

    from cell.sim.assembly import AssembledCell

#: A replication: (scenario, stream) -> the run's summary row.
Replicate = Callable[[Scenario, np.random.SeedSequence], Mapping[str, Any]]

#: Seconds a dask client gets to close (a scheduler gone away does not answer).
CLOSE_TIMEOUT_S = 5
#: Tasks in flight on a dask cluster at once (local workers: twice their number).
CLUSTER_WINDOW = 1024


@memo(key=Identity, maxsize=1)
def assembled(scenario: Scenario) -> AssembledCell:
    """The scenario's cell, assembled once for the replications of one scenario object
    that follow each other (a task's; in one process, a point's)."""
    from cell.sim.assembly import assemble

    return assemble(scenario)


def simulate_summary(scenario: Scenario, seed: np.random.SeedSequence) -> Mapping[str, Any]:
    """The default replication: one run of the cell, its summary row."""
    from cell.sim.simulation import simulate

    return simulate(assembled(scenario), seed=seed, keep_parts=False,
                    keep_belts=False).summary.as_dict()


def run_task(replicate: Replicate, scenario: Scenario,
             seeds: Sequence[np.random.SeedSequence]) -> list[dict[str, Any]]:
    """Run one batch (in a worker): each stream's summary as a plain dict."""
    return [{k: _plain(v) for k, v in replicate(scenario, s).items()} for s in seeds]


def _plain(value: Any) -> Any:
    return value.item() if isinstance(value, np.generic) else value


@dataclass
class Outcome:
    """What :func:`run_sweep` did; ``replications`` reads ``replications.csv`` when asked."""

    path: Path
    tasks_run: int
    tasks_reused: int
    counts: dict[int, int] = field(default_factory=dict)
    """Replications run per point (index into :attr:`Sweep.points`)."""

    @functools.cached_property
    def replications(self) -> pd.DataFrame:
        import pandas as pd

        if self.path.suffix == ".parquet":
            return pd.read_parquet(self.path)
        return pd.read_csv(self.path)


def check_workers(workers: int | None, scheduler: str | None = None) -> int:
    """The number of local workers (None: one a core); refused below 1, or above
    :data:`WORKERS_PER_CORE` a core unless the tasks go to a dask cluster."""
    cores = os.cpu_count() or 1
    workers = cores if workers is None else workers
    if workers < 1:
        raise CellError(f"--workers {workers}: must be at least 1")
    if workers > WORKERS_PER_CORE * cores and not scheduler:
        raise CellError(f"--workers {workers}: at most {WORKERS_PER_CORE * cores} on this "
                        f"machine ({cores} cores)")
    return workers


def _open_executor(workers: int, scheduler: str | None, say: bool = True
                   ) -> tuple[cf.Executor | None, Any]:
    """The executor for the tasks (None: run in this process) and a client to close;
    ``say``: tell stderr while a scheduler is being reached."""
    if scheduler is not None:
        from cell.experiments.sweep.cluster import CONNECT_TIMEOUT_S, connect

        if say:
            print(f"connecting to the dask scheduler at {scheduler} (giving up after "
                  f"{CONNECT_TIMEOUT_S:g} s)", file=sys.stderr)
        client = connect(scheduler)
        return client.get_executor(pure=False), client
    if workers <= 1:
        return None, None
    return cf.ProcessPoolExecutor(max_workers=workers, initializer=_worker_init,
                                  initargs=(os.getpid(),)), None


#: Ctrl-C and kill: the sweep's to act on, never a local worker's (see :func:`_submit`).
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
#: Whether signals can be blocked (not on Windows, where workers are not forked).
_MASKS = hasattr(signal, "pthread_sigmask")


def _submit(executor: cf.Executor, *args: Any) -> cf.Future[list[dict[str, Any]]]:
    """``executor.submit(run_task, *args)`` with :data:`STOP_SIGNALS` blocked: a local worker
    is forked in there and starts with them blocked, so none reaches it before
    :func:`_worker_init` ignores them.  One that comes meanwhile acts when this returns."""
    if not _MASKS:
        return executor.submit(run_task, *args)
    signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    try:
        return executor.submit(run_task, *args)
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)


def _worker_init(parent: int) -> None:
    """In each local worker (started with :data:`STOP_SIGNALS` blocked): ignore them, as
    the sweep stops its workers itself (:func:`_close`); and exit if the sweep dies (even
    by kill -9), so no orphan keeps running."""
    for number in STOP_SIGNALS:
        signal.signal(number, signal.SIG_IGN)  # drops one that came while blocked
    if _MASKS:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="watch-sweep").start()


def _run_tasks(sweep: Sweep, todo: Iterable[Task], replicate: Replicate,
               executor: cf.Executor | None, window: int,
               done: Callable[[Task, list[dict[str, Any]]], None]) -> None:
    """Run ``todo``, at most ``window`` tasks in flight; ``done`` as each one finishes."""
    def args(task: Task) -> tuple[Any, ...]:
        # Streams made afresh for each task: a replication that spawns from its stream
        # (mutating it) cannot change what another point or policy sees.
        seeds = [sweep.stream(r) for r in range(task.first, task.last)]
        return (replicate, sweep.points[task.point].scenario, seeds)

    if executor is None:
        for task in todo:
            done(task, _guarded(sweep, task, functools.partial(run_task, *args(task))))
        return
    queue = iter(todo)
    pending: dict[cf.Future[list[dict[str, Any]]], Task] = {}
    try:
        while True:
            for task in queue:
                pending[_submit(executor, *args(task))] = task
                if len(pending) >= window:
                    break
            if not pending:
                return
            finished, _ = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
            for future in finished:
                task = pending.pop(future)
                done(task, _guarded(sweep, task, future.result))
    except BaseException:
        for future in pending:
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
    """Shut the executor down; without ``wait`` (a stop: Ctrl-C, kill, an error) kill and reap
    local workers at once, as Python 3.14's ``kill_workers()``: a worker left to finish a task
    whose result is thrown away would outlive the sweep, or hang its exit (its multiprocessing children)."""
    if isinstance(executor, cf.ProcessPoolExecutor):
        workers = [] if wait else multiprocessing.active_children()
        executor.shutdown(wait=wait, cancel_futures=not wait)
        for process in workers:
            process.kill()
            process.join()
    elif executor is not None:
        executor.shutdown(wait=wait)
    if client is not None:
        client.close(timeout=CLOSE_TIMEOUT_S)


#: At most this many local worker processes per core.
WORKERS_PER_CORE = 4


def run_sweep(sweep: Sweep, out: str | Path, *, workers: int | None = None,
              scheduler: str | None = None, resume: bool = False,
              replicate: Replicate = simulate_summary, progress: bool = True,
              warn_windows: bool = True, result_format: str = "csv") -> Outcome:
    """Run (or finish, with ``resume``) a sweep into ``out``; write replications.csv, or
    with ``result_format="parquet"`` replications.parquet instead (:data:`RESULT_FILES`).

    ``replicate`` is what one replication does; the default simulates the cell.
    It must be a module-level function when tasks run in other processes.
    It says first, on stderr, if some points cannot keep up on average
    (:func:`cell.experiments.sweep.spec.overload_warning`) and, with ``warn_windows``, if compared
    points count over different windows (:func:`cell.experiments.sweep.windows.window_warning`).
    """
    out = check_out(out)
    workers = check_workers(workers, scheduler)
    _warn(sweep, warn_windows)
    executor, client = _open_executor(workers, scheduler, progress)
    window = CLUSTER_WINDOW if scheduler else 2 * workers
    columns = grid_columns(sweep)
    task_dir = out / TASK_DIR
    counts = dict.fromkeys(range(len(sweep.points)), 0)
    run = reused = 0
    fresh = not (out / MANIFEST).exists()
    try:
        prepare(sweep, out, resume)
        bar = Progress(sweep.total_replications, sweep.name, "replications", file=sys.stderr,
                       enabled=progress)

        def done(task: Task, rows: list[dict[str, Any]]) -> None:
            write_task(task_records(sweep, columns, task, rows), task_dir / task.filename)
            bar.update(task.size)

        def todo(ranges: dict[int, tuple[int, int]]) -> Iterable[Task]:
            nonlocal run, reused
            for task in sweep.iter_tasks(ranges):
                if resume and read_task(sweep, task_dir / task.filename, task) is not None:
                    reused += 1
                    bar.update(task.size)
                else:
                    run += 1
                    yield task

        with bar:
            rounds = _run_rounds(sweep, counts, bar, task_dir,
                                 lambda ranges: _run_tasks(sweep, todo(ranges), replicate,
                                                           executor, window, done))
        _close(executor, client, wait=True)
    except BaseException as exc:
        _abandon(exc, executor, client, out, fresh, scheduler)
        raise
    # The files the rounds wrote, point by point: a round's tasks start where it does
    # (``min`` need not be a multiple of ``batch``), not where cutting from 0 would.
    tasks = (t for p in counts for r in rounds if p in r for t in sweep.iter_tasks({p: r[p]}))
    path = assemble_results(sweep, task_dir, tasks, out / RESULT_FILES[result_format])
    return Outcome(path, run, reused, counts)


def _warn(sweep: Sweep, warn_windows: bool) -> None:
    """On stderr: points that cannot keep up on average, and compared points that count over
    different windows (with ``warn_windows``)."""
    for warning in (overload_warning(sweep), window_warning(sweep) if warn_windows else None):
        if warning:
            print(f"cell: warning: {warning}", file=sys.stderr)


def _run_rounds(sweep: Sweep, counts: dict[int, int], bar: Progress, task_dir: Path,
                run_round: Callable[[dict[int, tuple[int, int]]], None],
                ) -> list[dict[int, tuple[int, int]]]:
    """Every round of the sweep, run by ``run_round``: one, or under a precision rule as many
    as it takes (``counts`` kept up to date); each round's replications, by point."""
    values: dict[int, list[float]] = {p: [] for p in counts}
    rounds: list[dict[int, tuple[int, int]]] = []  # each round's replications, by point
    ranges = {p: (0, sweep.first_round) for p in counts}
    while ranges:
        rounds.append(ranges)
        run_round(ranges)
        for p, (_, last) in ranges.items():
            counts[p] = last
        if sweep.precision is None:
            break
        from cell.experiments.stats import next_round, precision_reached

        q = sweep.precision
        for task in sweep.iter_tasks(ranges):
            values[task.point] += measure_values(sweep, task_dir, task, q.measure)
        reached = precision_reached(values, q.precision, q.confidence, q.min_n)
        more = next_round(counts, reached, sweep.batch, q.max_n)
        ranges = {p: (counts[p], counts[p] + k) for p, k in more.items() if k}
        bar.grow(sum(more.values()))
    return rounds


def _abandon(exc: BaseException, executor: Any, client: Any, out: Path, fresh: bool,
             scheduler: str | None) -> None:
    """A sweep failed or was stopped: its workers closed, nothing left behind if nothing was
    there before, and a lost cluster said as one line (raised here)."""
    gone = None
    if scheduler:  # judged before our own close, which would make any client look gone
        from cell.experiments.sweep.cluster import lost

        gone = lost(scheduler, exc, out, client)
    _close(executor, client, wait=False)
    if fresh:
        _unmade(out)
    if gone is not None:
        raise gone from None


def _unmade(out: Path) -> None:
    """A sweep that failed or stopped before any task finished leaves nothing behind: the
    manifest it wrote and its empty task folder are removed (and the folder itself by
    :func:`cell.experiments.sweep.outdir.lock`, if it made it)."""
    if finished_tasks(out):
        return
    (out / MANIFEST).unlink(missing_ok=True)
    with contextlib.suppress(OSError):
        (out / TASK_DIR).rmdir()

