"""One column of a CSV as a spreadsheet or a line's log saves it: the cells of a trace's
``interarrival_s`` for a run (:func:`cell.arrivals.read_trace`), and of the column ``cell fit``
fits, read alike, each with the line of the file it is on, so both name a bad value by the
line a text editor or a spreadsheet shows.  The csv module only: no pandas at a run's start.
"""

from __future__ import annotations

import csv
from collections.abc import Iterable, Sequence


def column_cells(stream: Iterable[str], column: str) -> tuple[list[int], list[str]] | str:
    """The cells of ``column`` in a CSV text, spaces around them dropped ('' in a short row),
    each with the file line its row starts on (the header's line is 1 if nothing precedes it,
    as a spreadsheet numbers its rows); or why they cannot be read (:func:`find_column`, a row
    with more fields than the header, a blank line between readings).  Blank lines, and a
    spreadsheet's rows of empty cells (',,'), are skipped before the header and after the last
    reading; one between readings is a missing reading, and skipping it would shift every later
    gap.  csv.Error on a malformed quote."""
    reader = csv.reader(stream, strict=True, skipinitialspace=True)
    records: list[tuple[int, list[str]]] = []
    start, blank = 1, 0
    for row in reader:
        if any(c.strip() for c in row):
            if blank:
                return (f"line {blank} is blank and readings follow it: a missing reading (skipping "
                        "it would shift every later gap): remove the line or fill it")
            records.append((start, row))
        elif records and not blank:
            blank = start
        start = reader.line_num + 1
    if not records:
        return "not a readable CSV: No columns to parse from file"
    (_, header), data = records[0], records[1:]
    index = find_column(header, column)
    if isinstance(index, str):
        return index
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
