"""The sentences of an experiment's report: who is ahead where and by how much, trends,
and where single runs scatter so widely that the mean says little; with the small helpers
that show a grid point's values (:mod:`cell.reporting.experiment.text` lays them out)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from cell.experiments.sweep.columns import NAME_SUFFIX
from cell.reporting.formatting import Headline, decimals, half_width, number, plus_minus


def show(value: Any) -> str:
    """A grid value as the report shows it ("—" for none, a float as %g)."""
    if value is None or isinstance(value, float) and math.isnan(value):
        return "—"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def where(row: Mapping[Any, Any], cols: Sequence[str]) -> str:
    """``key = value, ...`` of a row's display columns."""
    return ", ".join(f"{c.removesuffix(NAME_SUFFIX)} = {show(row[c])}" for c in cols)


def single_runs(s: Mapping[Any, Any], whole: bool = False) -> tuple[str, str]:
    """A summary row's 2.5 and 97.5 % points of single runs, as its table cell shows them:
    whole numbers for a count (``whole``, or both already whole), else to the interval's
    precision."""
    lo, hi = float(s["run_p2_5"]), float(s["run_p97_5"])
    r = 0 if whole or lo == round(lo) and hi == round(hi) else decimals(half_width(s))
    return number(lo, r), number(hi, r)


def against(a: str, b: str, at: bool = True) -> str:
    """``b`` without ``a``'s name when it is ``a``'s own policy elsewhere in the grid."""
    if b.startswith(a + " at "):
        return b[len(a) + 1:] if at else b[len(a) + 4:]
    return b


def scatter(h: Headline, summary: pd.DataFrame, cols: Sequence[str],
             whole: bool = False) -> list[str]:
    """Points whose interval is wider than their mean: runs far apart, or a mean made
    by a few extreme runs (it lies outside the range of 95 % of them).  A count (``whole``)
    is read in whole runs' counts: runs within one of each other (0 or 1) are not far apart,
    and when 95 % of runs give one same count the rest make the mean."""
    out = []
    rows = summary[(summary["measure"] == h.column) & (summary["n"] >= 2)]
    for r in rows.to_dict("records"):
        mean, half = float(r["mean"]), half_width(r)
        if not half > abs(mean) / 2:
            continue
        shown = single_runs(r, whole)
        lo, hi = (float(r["run_p2_5"]), float(r["run_p97_5"])) if not whole else \
            (float(shown[0]), float(shown[1]))
        at = where(r, cols)
        who = f"{str(r['policy']).capitalize()}{' at ' + at if at else ''}"
        runs = f"95 % of single runs {shown[0]} to {shown[1]}"
        mean_shown = plus_minus(mean, half)
        if lo <= mean <= hi:
            if whole and hi - lo <= 1:
                continue
            out.append(f"{who} scatters widely between runs ({runs}; mean {mean_shown}).")
        elif whole and lo == hi:
            out.append(f"{who}: {shown[0]} in 95 % of single runs; the mean, {mean_shown}, "
                       "comes from the few others (look at the replications).")
        else:
            out.append(f"{who}: a few runs lie far outside the others ({runs}, yet the mean is "
                       f"{mean_shown}): the mean is theirs; look at the replications.")
    return out
