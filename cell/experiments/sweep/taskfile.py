"""A sweep task's file (``OUT/tasks/``) written and read with the csv module, as pandas
writes and reads it, in a fraction of the time: the bytes of the task files and of
``replications.csv`` stay those that ``DataFrame.to_csv`` and ``read_csv`` give.

Measured (CPU time, a task of one 20-part replication): writing its file took 5.1 ms and
reading it back for ``replications.csv`` 2.4 ms through pandas, 0.4 and 0.2 ms here; the
whole overhead of a sweep point beyond its simulation (``cell bench``,
``sweep_overhead_ms_per_point``, CPU time) went from 17.7 ms to 2.7 ms with the devices of
:mod:`cell.experiments.sweep.results` and :mod:`cell.reporting.experiment.data`.

The typing follows pandas, column by column and file by file: a column of Python ints is
written as integers, of floats (or floats and ints, or floats and None) as floats
(``%.17g``, a whole number with ``.0``), of bools as ``True``/``False``, of strings (or
strings and None) as they are, None as an empty field.  Read back, a column whose every
field is an integer is integer; one of numbers and empty fields is float; ``True``/``False``
alone is boolean; anything else is text.  A column outside these cases (mixed kinds, a
field pandas reads as missing, such as ``NA``) returns None, and the caller uses pandas
itself (:mod:`cell.experiments.sweep.runner`), so the result is the same either way.
"""

from __future__ import annotations

import csv
import io
import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

from cell.plumbing.output.atomic import float_text

#: Fields pandas' read_csv takes as missing by default (besides the empty field).
PANDAS_NA = frozenset({"#N/A", "#N/A N/A", "#NA", "-1.#IND", "-1.#QNAN", "-NaN", "-nan",
                       "1.#IND", "1.#QNAN", "<NA>", "N/A", "NA", "NULL", "NaN", "None", "n/a",
                       "nan", "null"})
_INT = re.compile(r"[+-]?\d{1,18}")
_FLOAT = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|[+-]?inf")


def task_csv(records: Sequence[Mapping[str, Any]], float_format: str) -> str | None:
    """The CSV text ``DataFrame.from_records(records).to_csv(index=False, ...)`` writes with
    floats as :func:`cell.plumbing.output.atomic.float_text` (``float_format``); None for a column this does
    not type as pandas would (see the module's docstring)."""
    names: dict[str, None] = {}
    for r in records:
        names.update(dict.fromkeys(r))
    columns = []
    for name in names:
        shown = _written([r.get(name) for r in records], float_format)
        if shown is None:
            return None
        columns.append(shown)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(list(names))
    writer.writerows(zip(*columns, strict=True))
    return out.getvalue()


def _written(values: list[Any], fmt: str) -> list[str] | None:
    kinds = {type(v) for v in values if v is not None}
    if kinds == {bool} and None not in values:
        return ["True" if v else "False" for v in values]
    if kinds == {int} and None not in values:
        return [str(v) for v in values]
    if float in kinds and kinds <= {float, int}:
        return ["" if v is None or math.isnan(v) else float_text(float(v), fmt) for v in values]
    if kinds == {str}:
        return ["" if v is None else v for v in values]
    return None


class TaskRows:
    """A task file's columns as text, with each column's kind as pandas reads it."""

    def __init__(self, header: list[str], columns: list[list[str]], kinds: list[str]):
        self.header, self.columns, self.kinds = header, columns, kinds
        self.size = len(columns[0]) if columns else 0

    def __len__(self) -> int:
        return self.size

    def column(self, name: str) -> list[str]:
        return self.columns[self.header.index(name)]

    def values(self, name: str) -> list[Any]:
        """A column's values as pandas reads them (int, float with NaN, bool or str)."""
        i = self.header.index(name)
        return [_value(s, self.kinds[i]) for s in self.columns[i]]

    def shown(self, float_format: str) -> list[list[str]]:
        """Each column as ``to_csv`` writes pandas' reading of it (floats as ``float_format``)."""
        return [[_shown(s, kind, float_format) for s in col]
                for col, kind in zip(self.columns, self.kinds, strict=True)]


def read_task_text(text: str) -> TaskRows | None:
    """A task file's text as :class:`TaskRows`; None if pandas might read it otherwise."""
    rows = list(csv.reader(io.StringIO(text)))
    if not rows or any(len(r) != len(rows[0]) for r in rows):
        return None
    header, body = rows[0], rows[1:]
    if len(set(header)) != len(header) or not body:
        return None
    columns = [list(c) for c in zip(*body, strict=True)]
    kinds = [_kind(c) for c in columns]
    if None in kinds:
        return None
    return TaskRows(header, columns, kinds)  # type: ignore[arg-type]


def _kind(fields: list[str]) -> str | None:
    if any(f in PANDAS_NA or f != f.strip() for f in fields):
        return None
    if all(_INT.fullmatch(f) for f in fields):
        return "int"
    if all(f == "" or _FLOAT.fullmatch(f) for f in fields):
        return "float"
    if all(f in ("True", "False") for f in fields):
        return "bool"
    if any(f.lower() in ("true", "false") or _FLOAT.fullmatch(f) for f in fields):
        return None  # text with numbers or truth values among it: left to pandas
    return "str"


def _value(field: str, kind: str) -> Any:
    if kind == "int":
        return int(field)
    if kind == "float":
        return float(field) if field else math.nan
    if kind == "bool":
        return field == "True"
    return field if field else math.nan


def _shown(field: str, kind: str, fmt: str) -> str:
    if kind == "int":
        return str(int(field))
    if kind == "float":
        return float_text(float(field), fmt) if field else ""
    return field
