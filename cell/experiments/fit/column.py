"""The column ``cell fit`` reads: a CSV's inter-arrival gaps, or arrival times made gaps.

Every problem is one :class:`~cell.plumbing.errors.ScenarioError` line naming the file, the
column (and the file's line) and the value as written; :mod:`cell.experiments.fit.mle` fits what is read.
"""

from __future__ import annotations

import io
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cell.experiments.fit.mle import MIN_VALUES
from cell.plumbing.errors import ScenarioError
from cell.scenario.arrivals import MAX_INTERARRIVAL_S
from cell.scenario.trace_file import cells_of, find_column, records


def read_column(path: str | Path, column: str = "interarrival_s", *, times: bool = False,
                sorted_ok: bool = False, most: float = MAX_INTERARRIVAL_S) -> NDArray[np.float64]:
    """The inter-arrival gaps in a CSV column: at least :data:`MIN_VALUES`, finite, > 0, not all equal
    (zero gaps, from a log stamped to the second, are refused, counted: see ``cell fit --help``).

    With ``times`` the column holds arrival times (finite, strictly increasing), as
    numbers of seconds or as ISO 8601 date-times, and their differences (s) are
    returned.  Without it, a column of :data:`MIN_VALUES` or more values that never
    decreases is refused as arrival times (n iid gaps come
    in increasing order with probability 1/n!, < 1e-18 at n = 20), unless
    ``sorted_ok`` says they are gaps in sorted order.  Gaps must be at most ``most`` seconds
    (a scenario's longest inter-arrival time by default).  Any problem raises
    :class:`~cell.plumbing.errors.ScenarioError` naming the file, the key (``(file)``,
    ``--column``, ``COLUMN`` or ``COLUMN[line N]``, N the file's line, the header's 1, as a
    spreadsheet numbers its rows) and the value as written.
    """
    import pandas as pd

    p = Path(path)
    lines, cells = _read_cells(p, column)
    values = pd.to_numeric(cells, errors="coerce").to_numpy(dtype=float)
    dated = times and bool(np.isnan(values).all())
    if dated:  # arrival times as date-times (ISO 8601, e.g. 2026-03-02 08:15:04.5): seconds
        values, dated = _stamps_as_seconds(cells, values)
    finite = np.isfinite(values)
    if not (times or sorted_ok):
        _refuse_rising(p, column, cells, values, finite)
    bad = np.flatnonzero(~finite if times else ~finite | (values < 0.0) | (values > most))
    if bad.size:
        i = int(bad[0])
        raise ScenarioError(p, f"{column}[line {lines[i]}]", cells.iloc[i],
                            _why_unusable(cells.iloc[i], values[i], times=times, dated=dated, most=most))
    noun = "values"
    if times:
        values, noun = _time_gaps(p, column, lines, cells, values, most), "gaps"
    _check_fittable(p, column, lines, cells, values, times=times, noun=noun)
    return values


def first_clock_h(path: str | Path, column: str, times: bool) -> float:
    """Where on its own clock a log begins, in hours: the first time stamp's wall-clock time
    (an ISO date-time, as written, whatever its offset), or the first time in seconds / 3600
    (numbers); 0 for a column of gaps (the log's clock then starts at its first arrival)."""
    import pandas as pd

    if not times:
        return 0.0
    cell = str(_read_cells(Path(path), column)[1].iloc[0])
    first = pd.to_numeric(pd.Series([cell]), errors="coerce").iloc[0]
    if math.isfinite(first):
        return float(first) / 3600.0
    stamp = pd.Timestamp(cell)
    return (stamp - stamp.normalize()).total_seconds() / 3600.0


def _refuse_rising(p: Path, column: str, cells: Any, values: NDArray[np.float64],
                   finite: NDArray[np.bool_]) -> None:
    """Refuse as arrival times a column of :data:`MIN_VALUES` or more finite gaps that never
    decreases (and is not all equal)."""
    if values.size >= MIN_VALUES and finite.all() \
            and np.all(np.diff(values) >= 0.0) and np.ptp(values) > 0.0:
        seen = f"{values.size} values rising from {cells.iloc[0]} to {cells.iloc[-1]}"
        raise ScenarioError(p, column, seen,
                            "the column never decreases, so it looks like arrival times, not gaps: "
                            "use --times to fit their differences (or --gaps if these are sorted gaps)")


def _time_gaps(p: Path, column: str, lines: list[int], cells: Any, values: NDArray[np.float64],
               most: float) -> NDArray[np.float64]:
    """The differences of arrival times, refused where a time goes back or a gap is over ``most``
    (a first repeated time is left to :func:`_check_fittable`)."""
    step = np.diff(values)
    back = np.flatnonzero(~(step > 0.0) | (step > most))
    if back.size and step[back[0]] != 0.0:  # a first repeated time is said below
        i = int(back[0]) + 1
        why = (f"arrival times must increase: not after {cells.iloc[i - 1]} on line {lines[i - 1]}"
               if step[i - 1] < 0.0 else f"{step[i - 1]:.10g} s after line {lines[i - 1]}; "
               f"gaps must be at most {most:g} s")
        raise ScenarioError(p, f"{column}[line {lines[i]}]", cells.iloc[i], why)
    return step


def _check_fittable(p: Path, column: str, lines: list[int], cells: Any, values: NDArray[np.float64],
                    *, times: bool, noun: str) -> None:
    """Refuse gaps no continuous distribution fits: any zero, fewer than :data:`MIN_VALUES`,
    or all equal."""
    zero = np.flatnonzero(values == 0.0)  # Weibull's, gamma's, lognorm's likelihood is 0 or inf there
    if zero.size:
        i = int(zero[0]) + times
        same = f"the same time as line {lines[i - 1]}: " if times else ""
        raise ScenarioError(p, f"{column}[line {lines[i]}]", cells.iloc[i],
                            f"{same}{zero.size} of {values.size} gaps are 0 (logged in the same second?): no "
                            "continuous distribution fits them; log the times more finely, or replay the "
                            "gaps as a trace (arrivals.trace_csv takes zeros)")
    if values.size < MIN_VALUES:
        shown = f"{cells.size} arrival times" if times else f"{values.size} values"
        need = f"{MIN_VALUES + 1} arrival times" if times else f"{MIN_VALUES} values"
        raise ScenarioError(p, column, shown, f"needs at least {need} to fit a distribution")
    if np.ptp(values) == 0.0:
        raise ScenarioError(p, column, f"all {values.size} {noun} = {values[0]:g}",
                            f"{noun} without variation cannot be fitted")


#: An ISO 8601 date, or date and time (what ``--times`` reads as a time stamp).
ISO_STAMP = re.compile(r"\d{4}-\d{2}-\d{2}([T ]\d{1,2}:\d{2}(:\d{2}([.,]\d+)?)?)?(Z|[+-]\d{2}:?\d{2})?")


def _stamps_as_seconds(cells: Any, values: NDArray[np.float64]) -> tuple[NDArray[np.float64], bool]:
    """ISO 8601 date-times as seconds from the earliest, and True; ``values`` and False if
    none of the cells is one."""
    import pandas as pd

    stamps = pd.to_datetime(cells, format="ISO8601", errors="coerce", utc=True)
    if not stamps.notna().any():
        return values, False
    return (stamps - stamps.min()).dt.total_seconds().to_numpy(dtype=float), True


def _why_unusable(cell: str, value: float, *, times: bool, dated: bool,
                  most: float = MAX_INTERARRIVAL_S) -> str:
    """Why a cell of the column cannot be used (``value`` as read, NaN if not a number)."""
    if cell == "":
        return "missing value"
    if dated:
        return "not a date-time (YYYY-MM-DD hh:mm:ss)"
    if math.isnan(value) and cell.lower() != "nan":
        if re.fullmatch(r"[+-]?\d*,\d+", cell):
            return "not a number: write a decimal point, not a comma"
        if times:
            return "not a number of seconds nor an ISO date-time (YYYY-MM-DD hh:mm:ss)"
        if ISO_STAMP.fullmatch(cell):
            return "not a number; looks like timestamps: use --times to fit the gaps between them"
        return "not a number"
    if times:
        return "arrival times must be finite"
    if math.isinf(most):
        return "times must be finite and > 0"
    return f"inter-arrival times must be finite, > 0 and at most {most:g} s"


def _read_cells(p: Path, column: str) -> tuple[list[int], Any]:
    """The cells of ``column`` in the CSV file ``p`` as a pandas Series of str (read as a run's
    trace reader reads them, :func:`~cell.scenario.trace_file.column_cells`: the same header, rows and
    lines), and each one's file line."""
    lines, (cells,) = _read_columns(p, [(column, "--column")])
    return lines, cells


def _read_columns(p: Path, columns: list[tuple[str, str]]) -> tuple[list[int], list[Any]]:
    """The file lines of the readings of the CSV file ``p``, and the cells of each of
    ``columns`` (a name and the option that named it) as pandas Series of str."""
    import pandas as pd

    if not p.is_file():
        raise ScenarioError(p, "(file)", str(p), "no such file")
    try:
        raw = p.read_bytes()
        if b"\x00" in raw:
            raise ScenarioError(p, "(file)", str(p), "binary data, not a CSV text file")
        text = raw.decode("utf-8-sig")
    except OSError as exc:
        raise ScenarioError(p, "(file)", str(p), f"cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise ScenarioError(p, "(file)", str(p),
                            f"not UTF-8 text (byte {exc.start}); save the CSV as UTF-8") from None
    if not text.strip():
        raise ScenarioError(p, "(file)", str(p), "empty file")
    fast = _plain_columns(text, [column for column, _ in columns])
    if fast is not None:
        return fast
    rows = records(io.StringIO(text, newline=""))
    if isinstance(rows, str):
        raise ScenarioError(p, "(file)", str(p), rows)
    lines: list[int] = []
    found = []
    for column, option in columns:
        index = find_column(rows[0][1], column)
        if isinstance(index, str):  # the column the user named (--column) is not there
            raise ScenarioError(p, option, column, index)
        cells = cells_of(rows, index)
        if isinstance(cells, str):
            raise ScenarioError(p, "(file)", str(p), cells)
        lines = cells[0]
        found.append(pd.Series(cells[1], dtype=str))
    return lines, found


#: A line of nothing but spaces, tabs and commas (a blank row, as :func:`~cell.scenario.trace_file.records`
#: sees one), anywhere in a text without quotes.
_BLANK_LINE = re.compile(r"^(?:[^\S\n]|,)*$", re.MULTILINE)


def _plain_columns(text: str, columns: list[str]) -> tuple[list[int], list[Any]] | None:
    """The file lines and cells of ``columns`` (as :func:`_read_columns` returns them) of a
    plain CSV text, read by pandas's C parser: a million rows in about a second, where the
    csv module's row by row reading (:func:`~cell.scenario.trace_file.records`) takes ten.  Plain: no
    quote, no carriage return but in CR LF, no blank line (not even of empty cells) before
    or between the readings, as many fields in no row as in the header, each column named
    once; then each row is one line of the file, and both readers read the same cells.  None
    for any other text, which the csv module reads, and whose problems it names."""
    import pandas as pd

    if '"' in text or text.count("\r") != text.count("\r\n"):
        return None
    body = text.replace("\r\n", "\n").rstrip("\n")
    if _BLANK_LINE.search(body):
        return None
    try:
        table = pd.read_csv(io.StringIO(body), header=None, dtype=str, keep_default_na=False,
                            skip_blank_lines=False, engine="c")
    except (ValueError, pd.errors.ParserError):  # ragged rows and the like: the csv module says so
        return None
    header = [str(v).strip() for v in table.iloc[0]]
    if any(header.count(c) != 1 for c in columns):
        return None
    found = [table[table.columns[header.index(c)]].iloc[1:].str.strip().reset_index(drop=True)
             for c in columns]
    return list(range(2, table.shape[0] + 1)), found


#: How a censoring column says a time is censored (the item was still working) or observed.
CENSORED_WORDS = frozenset({"1", "true", "yes", "y", "t"})
OBSERVED_WORDS = frozenset({"0", "false", "no", "n", "f"})


def read_lifetimes(path: str | Path, column: str, censor_column: str | None = None) -> tuple[
        NDArray[np.float64], NDArray[np.bool_]]:
    """Times to failure or repair (finite, > 0, at least :data:`MIN_VALUES`, of which at least
    two observed and not all equal) in ``column`` of a CSV, and which are right-censored: True
    where ``censor_column`` says 1, true or yes (the item was still working then), False for
    0, false or no (it failed, or the repair ended, then); all False without the column.
    Sorted times are accepted (life data often come sorted).  Problems as :func:`read_column`."""
    p = Path(path)
    named = [(column, "--column")] + ([(censor_column, "--censored")] if censor_column is not None else [])
    lines, found = _read_columns(p, named)
    cells = found[0]
    import pandas as pd

    values = pd.to_numeric(cells, errors="coerce").to_numpy(dtype=float)
    bad = np.flatnonzero(~np.isfinite(values) | ~(values > 0.0))
    if bad.size:
        i = int(bad[0])
        raise ScenarioError(p, f"{column}[line {lines[i]}]", cells.iloc[i],
                            _why_unusable(cells.iloc[i], values[i], times=False, dated=False,
                                          most=math.inf))
    censored = np.zeros(values.size, dtype=bool)
    if censor_column is not None:  # '' names no column: refused by _read_columns, not ignored
        flags = found[1].str.lower()
        known = flags.isin(CENSORED_WORDS | OBSERVED_WORDS).to_numpy()
        if not known.all():
            i = int(np.flatnonzero(~known)[0])
            raise ScenarioError(p, f"{censor_column}[line {lines[i]}]", found[1].iloc[i],
                                "not a censoring flag: 1, true or yes (censored: still working then), "
                                "0, false or no (observed)")
        censored = flags.isin(CENSORED_WORDS).to_numpy()
    observed = values[~censored]
    if values.size < MIN_VALUES:
        raise ScenarioError(p, column, f"{values.size} values",
                            f"needs at least {MIN_VALUES} values to fit a distribution")
    if observed.size < 2 or np.ptp(observed) == 0.0:
        raise ScenarioError(p, censor_column or column, f"{observed.size} observed of {values.size}",
                            "needs at least two observed (uncensored) times, not all equal, to fit")
    return values, censored
