"""One column of a CSV as a spreadsheet or a line's log saves it: the cells of a trace's
``interarrival_s`` for a run (:func:`cell.scenario.arrivals.read_trace`), and of the column ``cell fit``
fits, read alike, each with the line of the file it is on, so both name a bad value by the
line a text editor or a spreadsheet shows.  The csv module only: no pandas at a run's start.
"""

from __future__ import annotations

import csv
from collections.abc import Iterable, Sequence

Records = list[tuple[int, list[str]]]


def column_cells(stream: Iterable[str], column: str) -> tuple[list[int], list[str]] | str:
    """The cells of ``column`` in a CSV text, spaces around them dropped ('' in a short row),
    each with the file line its row starts on (the header's line is 1 if nothing precedes it,
    as a spreadsheet numbers its rows); or why they cannot be read (:func:`records`,
    :func:`find_column`, :func:`cells_of`).  OSError or UnicodeDecodeError as ``stream`` raises."""
    rows = records(stream)
    if isinstance(rows, str):
        return rows
    index = find_column(rows[0][1], column)
    return index if isinstance(index, str) else cells_of(rows, index)


def records(stream: Iterable[str]) -> Records | str:
    """The non-blank rows of a CSV text (the header first), each with the file line it starts on;
    or why they cannot be read (a malformed quote, no rows, a blank line between readings).
    Blank lines, and a spreadsheet's rows of empty cells (',,'), are skipped before the header
    and after the last reading; one between readings is a missing reading, and skipping it would
    shift every later gap."""
    reader = csv.reader(stream, strict=True, skipinitialspace=True)
    rows: Records = []
    start, blank = 1, 0
    try:
        for row in reader:
            if "".join(row).strip():  # some cell not blank (one join, no generator per row)
                if blank:
                    return (f"line {blank} is blank and readings follow it: a missing reading (skipping "
                            "it would shift every later gap): remove the line or fill it")
                rows.append((start, row))
            elif rows and not blank:
                blank = start
            start = reader.line_num + 1
    except csv.Error as exc:
        return f"not a readable CSV: {' '.join(str(exc).split())[:120]}"
    return rows or "not a readable CSV: No columns to parse from file"


def cells_of(rows: Records, index: int) -> tuple[list[int], list[str]] | str:
    """The file lines and cells of column ``index`` in the readings of ``rows`` (:func:`records`),
    or why they cannot be read (a row with more fields than the header)."""
    (_, header), data = rows[0], rows[1:]
    ragged = next(((line, row) for line, row in data if len(row) > len(header)), None)
    if ragged is not None:
        return (f"not a readable CSV: line {ragged[0]} has {len(ragged[1])} fields, "
                f"the header {len(header)}")
    return ([line for line, _ in data],
            [row[index].strip() if index < len(row) else "" for _, row in data])


def find_column(header: Sequence[str], column: str) -> int | str:
    """Where ``column`` is among a CSV's ``header`` fields (spaces around a name ignored, as
    spreadsheets leave them), or why it cannot be read there: there is no such column (the
    names found are listed, and a header whose columns are separated by ';', as spreadsheets
    save CSV in locales with a decimal comma, is said to be), or two columns have the name."""
    names = [name.strip() for name in header]
    if names.count(column) > 1:
        return f"two columns are named {column}: keep one"
    if column in names:
        return names.index(column)
    if any(";" in name for name in names):
        return (f"needs a column named {column}; the columns are separated by ';': save the CSV "
                "with a comma between columns and a decimal point in numbers")
    found = ", ".join(repr(name) for name in names[:5]) + (", ..." if len(names) > 5 else "")
    return f"needs a column named {column} (found {found})"
