"""A sweep's results on disk: each finished task's file in ``OUT/tasks/`` and the result
file assembled from them (``replications.csv``, or ``replications.parquet``), written and
read through :mod:`cell.experiments.sweep.taskfile` (pandas where that module leaves a file to it).
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cell.experiments.sweep.columns import Column, point_values
from cell.experiments.sweep.outdir import RESULT_FILES
from cell.experiments.sweep.spec import Sweep, Task
from cell.experiments.sweep.taskfile import TaskRows, read_task_text, task_csv
from cell.plumbing.errors import CellError
from cell.plumbing.output.atomic import FLOAT_FORMAT, atomic_path, float_formatter, write_csv
from cell.plumbing.output.paths import failing

if TYPE_CHECKING:
    import pandas as pd

#: Float digits in the per-task files: enough to round-trip exactly.
TASK_FLOAT_FORMAT = "%.17g"


def task_records(sweep: Sweep, columns: Sequence[Column], task: Task,
                  rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    point = sweep.points[task.point]
    records = []
    for r, summary in zip(range(task.first, task.last), rows, strict=True):
        record: dict[str, Any] = {"policy": point.policy, "point": point.index}
        record.update(point_values(columns, point, summary))
        record["seed"] = sweep.seed
        record["replication"] = r
        record.update({k: v for k, v in summary.items() if k not in record})
        records.append(record)
    return records


def _publish(text: str, path: Path) -> None:
    """``text`` as the task file ``path``, whole or not at all: written beside it as
    ``.NAME.cell-PID.tmp`` (removed by :func:`cell.experiments.sweep.outdir.prepare` if a kill leaves it)
    and renamed over it.  Unlike :func:`cell.plumbing.output.atomic.atomic_path` there is no fsync and no
    scan of the folder for stale files (12.9 ms of wall time a task in a folder of 300
    files, against 0.8 ms so, on a busy machine; ``cell bench``,
    ``sweep_overhead_ms_per_point``): a task file a power cut leaves damaged is found so
    by :func:`read_task`, and ``--resume`` runs it again."""
    tmp = path.with_name(f".{path.name}.cell-{os.getpid()}.tmp")
    with failing(str(path)):
        path.parent.mkdir(parents=True, exist_ok=True)
        try:
            with open(tmp, "w", encoding="utf-8", newline="") as stream:
                stream.write(text)
            os.replace(tmp, path)
        finally:
            tmp.unlink(missing_ok=True)


def write_task(records: list[dict[str, Any]], path: Path) -> None:
    """A finished task's file: through the csv module (:mod:`cell.experiments.sweep.taskfile`), or
    pandas when its rows are of a kind that module leaves to it; the same bytes either way."""
    text = task_csv(records, TASK_FLOAT_FORMAT)
    if text is not None:
        _publish(text, path)
        return
    import pandas as pd

    write_csv(pd.DataFrame.from_records(records), path, float_format=TASK_FLOAT_FORMAT)


def _names(data: TaskRows | pd.DataFrame) -> list[str]:
    return data.header if isinstance(data, TaskRows) else [str(c) for c in data.columns]


def _values(data: TaskRows | pd.DataFrame, name: str) -> list[Any]:
    return data.values(name) if isinstance(data, TaskRows) else list(data[name])


def read_task(sweep: Sweep, path: Path, task: Task) -> TaskRows | pd.DataFrame | None:
    """A finished task's rows, or None if the file is missing or not this task's."""
    if not path.is_file():
        return None
    data: TaskRows | pd.DataFrame | None
    try:
        data = read_task_text(path.read_text(encoding="utf-8"))
        if data is None:
            import pandas as pd

            data = pd.read_csv(path)
    except (OSError, ValueError, csv.Error):
        return None
    if len(data) != task.size or not {"replication", "policy", "point"} <= set(_names(data)):
        return None
    point = sweep.points[task.point]
    if _values(data, "replication") != list(range(task.first, task.last)) \
            or any(v != point.policy for v in _values(data, "policy")) \
            or any(v != point.index for v in _values(data, "point")):
        return None
    return data


def finished(sweep: Sweep, task_dir: Path, task: Task) -> TaskRows | pd.DataFrame:
    """A finished task's rows, from its file (:func:`read_task`); an error if it is gone."""
    frame = read_task(sweep, task_dir / task.filename, task)
    if frame is None:
        raise CellError(f"{task_dir / task.filename}: missing or damaged; rerun the sweep")
    return frame


def measure_values(sweep: Sweep, task_dir: Path, task: Task, measure: str) -> list[float]:
    """A finished task's values of the precision's measure, from its file."""
    data = finished(sweep, task_dir, task)
    if measure not in _names(data):
        raise CellError(f"{sweep.source}: replications.measure = {measure!r}: the replications "
                        "have no such column")
    if isinstance(data, TaskRows):  # text is never a number there (cell.experiments.sweep.taskfile)
        return [math.nan if isinstance(v, str) else float(v) for v in data.values(measure)]
    import pandas as pd

    return [float(v) for v in pd.to_numeric(data[measure], errors="coerce")]


def write_rows(frames: Sequence[TaskRows | pd.DataFrame], names: Sequence[str],
               stream: Any) -> None:
    """The tasks' rows under the header ``names`` (blank where a task lacks a column), as
    ``frame.reindex(columns=names).to_csv(...)`` of each, one after another, writes them."""
    writer = csv.writer(stream, lineterminator="\n")
    if frames:
        writer.writerow(list(names))
    for data in frames:
        if isinstance(data, TaskRows):
            shown = dict(zip(data.header, data.shown(FLOAT_FORMAT), strict=True))
            blank = [""] * data.size
            writer.writerows(zip(*(shown.get(n, blank) for n in names), strict=True))
        else:
            data.reindex(columns=list(names)).to_csv(
                stream, header=False, index=False, float_format=float_formatter(),
                lineterminator="\n")


def assemble_results(sweep: Sweep, task_dir: Path, tasks: Iterable[Task], target: Path) -> Path:
    """``replications.csv`` from the task files, in the tasks' order (each file read once);
    a ``target`` ending in ``.parquet`` gets that CSV as Parquet
    (:func:`cell.plumbing.output.parquet.csv_text_to_parquet`: the same columns, types and values),
    and the other format's file, from an earlier run of the sweep, goes.

    Assembled from the files, never from the results in memory: a resumed sweep and
    an uninterrupted one go through the same bytes.
    """
    frames = []
    names: dict[str, None] = {}
    for task in tasks:
        data = finished(sweep, task_dir, task)
        names.update(dict.fromkeys(_names(data)))
        frames.append(data)

    def write(stream: Any) -> None:
        write_rows(frames, list(names), stream)

    if target.suffix == ".parquet":
        import io

        from cell.plumbing.output.parquet import csv_text_to_parquet

        text = io.StringIO()
        write(text)
        with atomic_path(target) as tmp:
            csv_text_to_parquet(text.getvalue(), tmp)
    else:
        with atomic_path(target) as tmp, open(tmp, "w", encoding="utf-8", newline="") as stream:
            write(stream)
    for name in RESULT_FILES.values():
        if name != target.name:
            (target.parent / name).unlink(missing_ok=True)
    return target


def runs_of(replications: pd.DataFrame, sweep: Sweep, i: int) -> pd.DataFrame:
    """Point ``i``'s replications, in replication order."""
    p = sweep.points[i]
    rows = replications[(replications["policy"] == p.policy) & (replications["point"] == p.index)]
    return rows.sort_values("replication")
