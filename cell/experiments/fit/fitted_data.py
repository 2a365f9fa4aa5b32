"""``cell fit``'s data: the values read from a trace to fit (:func:`read_data`), with what the
block's comment calls them, the notes on what was left out or subsampled and the warning on gaps
far out of the body of the data; and the same log's gaps in operational time when a rate profile
is written (:func:`in_operational_time`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

from cell.plumbing.errors import ScenarioError

if TYPE_CHECKING:
    from cell.scenario.sections import RateProfile


class Data(NamedTuple):
    """What is fitted: the values, which are censored (None: none), what the block's comment
    calls them, and the notes on what was left out or subsampled."""

    values: Any
    censored: Any
    what: str
    notes: list[str]
    flag: str = ""
    """The warning on gaps far out of the body of the data ("" for none)."""
    ordered: Any = None
    """The log's gaps in its order, none left out (None: times to failure or repair, or
    sorted gaps: no order to test)."""
    kept: Any = None
    """Which of ``ordered`` are fitted (None: all)."""
    first_h: float = 0.0
    """Where on its clock the log begins, h (:func:`~cell.experiments.fit.column.first_clock_h`)."""


def read_data(trace: Path, column: str, *, lifetimes: bool, times: bool, gaps: bool,
              censored_by: str | None, max_gap: float | None, drop_outliers: bool) -> Data:
    """The values to fit, from the trace's ``column`` (``cell fit``'s options by their names),
    and the notes and warnings on them."""
    from cell.experiments.fit.column import first_clock_h, read_column, read_lifetimes
    from cell.experiments.fit.gaps import far_out, fence, flag, flagged, leave_out
    from cell.experiments.fit.mle import MIN_VALUES
    from cell.scenario.arrivals import MAX_INTERARRIVAL_S

    if lifetimes and not times:
        values, censored = read_lifetimes(trace, column, censored_by)
        cut = f", {int(censored.sum())} of them right-censored by {censored_by}" if censored_by else ""
        count = f"{values.size} times{cut}"
        return Data(values, censored if censored.any() else None, count, subsampled(values.size, "times"))
    values = read_column(trace, column, times=times, sorted_ok=gaps or lifetimes,
                         most=math.inf if lifetimes else MAX_INTERARRIVAL_S)
    ordered = None if lifetimes or gaps else values
    first_h = first_clock_h(trace, column, times) if ordered is not None else 0.0
    noun = "gaps" if times else "values"
    count = f"{values.size} gaps between {values.size + 1} arrival times" if times else \
        f"{values.size} values"
    notes: list[str] = []
    asked = max_gap is not None or drop_outliers
    kept = None
    if asked:
        limit = max_gap if max_gap is not None else fence(values)
        kept = values <= limit
        how = f"--max-gap {max_gap:g}" if max_gap is not None else \
            "--drop-outliers: beyond Q3 + 3 IQR"
        values, left = leave_out(values, limit, how)
        notes.append(left)
        if values.size < MIN_VALUES:
            option = "--max-gap" if max_gap is not None else "--drop-outliers"
            raise ScenarioError(trace, option, limit,
                                f"leaves {values.size} {noun}: at least {MIN_VALUES} are needed to fit")
    tail = far_out(values)
    said = flag(tail, noun) if flagged(tail) and not (lifetimes or asked) else ""
    return Data(values, None, count, [n for n in notes if n] + subsampled(values.size, noun), said,
                ordered, kept, first_h)


def subsampled(n: int, noun: str) -> list[str]:
    """The note on a fit to a random subsample of ``n`` values (none if all are fitted)."""
    from cell.experiments.fit.budget import MAX_FIT_VALUES

    if n <= MAX_FIT_VALUES:
        return []
    return [f"fitted to {MAX_FIT_VALUES:,} of the {n:,} {noun}, drawn at random with a fixed seed (the "
            "same each time): the likelihoods, AIC and KS statistics are theirs; the data's mean and sd "
            f"are all {n:,}'s"]


def in_operational_time(data: Data, profile: RateProfile) -> Data:
    """The data as the gaps a profile's base distribution draws: the log's gaps in operational
    time (:func:`~cell.experiments.fit.pattern.operational_gaps`), those left out left out."""
    from cell.experiments.fit.pattern import operational_gaps

    gaps = operational_gaps(data.ordered, profile)
    values = gaps if data.kept is None else gaps[data.kept]
    what = f"{data.what}, in operational time (the rate profile's)"
    return data._replace(values=values, what=what)
