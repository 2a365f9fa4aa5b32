"""The sentences of an experiment's report: who is ahead where and by how much, trends,
and where single runs scatter so widely that the mean says little; with the small helpers
that show a grid point's values (:mod:`cell.reporting.experiment_text` lays them out)."""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from cell.reporting.headlines import HUGE, Headline, decimals, half_width, number, plus_minus, too_few
from cell.sweep import Sweep
from cell.sweep.columns import NAME_SUFFIX


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


def reading(summary: pd.DataFrame, differences: pd.DataFrame, sweep: Sweep,
            cols: Sequence[str], present: Sequence[Headline],
            whole: Collection[str] = ()) -> list[str]:
    """Sentences drawn from the numbers: who is ahead where, by how much, trends, and
    where single runs scatter so widely that the mean says little; ``whole``: the measures
    that count things (shown as whole numbers, as in their tables)."""
    out: list[str] = []
    if differences.empty:
        out.append("No paired differences: the sweep runs one policy and names no "
                   "`baseline:`; name a point there to compare the others with it.")
    for h in present:
        text = _verdicts(h, differences, cols) + _trend(h, summary, sweep, cols) \
            + _scatter(h, summary, cols, h.column in whole)
        if text:
            out.append(f"**{h.title}.** " + " ".join(text))
    return out


def _verdicts(h: Headline, differences: pd.DataFrame, cols: Sequence[str]) -> list[str]:
    out = []
    rows = differences[differences["measure"] == h.column]
    for (a, b), group in rows.groupby(["policy", "versus"], sort=False):
        mean, lo, hi = (group[k].to_numpy(dtype=float) for k in ("mean", "ci_low", "ci_high"))
        up, down = int(np.sum(lo > 0)), int(np.sum(hi < 0))
        unknown = int(np.sum(~(np.isfinite(lo) & np.isfinite(hi))))  # fewer than two pairs
        level, n = len(group) - up - down - unknown, len(group)
        counts = [f"{h.words[0]} at {up}" if up else "", f"{h.words[1]} at {down}" if down else "",
                  f"no difference shown at {level}" if level else "",
                  f"not compared ({too_few(None, why=False)}) at {unknown}" if unknown else ""]
        counts = [c for c in counts if c]
        if n == 1:
            counts[0] = counts[0].removesuffix(" at 1")
        elif len(counts) == 1:
            counts[0] = counts[0].replace(f" at {n}", f" at all {n} points")
        else:
            counts[0] += f" of {n} points"
        text = f"{str(a).capitalize()} against {against(str(a), str(b), at=False)}: "
        text += ", ".join(counts)
        recs = group.to_dict("records")
        if n > 1 and np.isfinite(mean).all():
            order = np.argsort(-np.abs(mean), kind="stable")
            big, small = recs[int(order[0])], recs[int(order[-1])]
            text += (f"; furthest from zero {_signed(big)} (at {where(big, cols)}), nearest "
                     f"zero {_signed(small)} (at {where(small, cols)})")
        elif n == 1 and np.isfinite(mean).all():
            text += f" ({_signed(recs[0])})"
        out.append(text + ".")
    return out


def _signed(row: Mapping[Any, Any]) -> str:
    """A difference's mean, signed, to its interval's precision."""
    mean, sd = float(row["mean"]), float(row["sd"])
    if not sd > 0:
        return f"{mean:+.6g}"
    half = half_width(row)
    return f"{mean:+.3g}" if abs(mean) >= HUGE else f"{mean:+.{decimals(half)}f}"


def _scatter(h: Headline, summary: pd.DataFrame, cols: Sequence[str],
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


def _trend(h: Headline, summary: pd.DataFrame, sweep: Sweep, cols: Sequence[str]) -> list[str]:
    """Along a single numeric key: each policy's mean at its first and last value that
    have one (a run too short for a rate has none)."""
    if len(cols) != 1 or cols[0].endswith(NAME_SUFFIX):
        return []
    col, out = cols[0], []
    rows = summary[summary["measure"] == h.column]
    for policy, group in rows.groupby("policy", sort=False):
        if pd.to_numeric(group[col], errors="coerce").isna().any():
            continue
        group = group[np.isfinite(group["mean"].to_numpy(dtype=float))]
        if len(group) < 2:
            continue
        first, last = group.iloc[0], group.iloc[-1]
        a, b = _ends(first, last)
        who = str(policy).capitalize()
        if a == b:
            out.append(f"{who} stays at {a} from {col} = {show(first[col])} to "
                       f"{show(last[col])}.")
        else:
            out.append(f"{who} goes from {a} at {col} = {show(first[col])} to {b} at "
                       f"{show(last[col])}.")
    return out


def _ends(first: pd.Series, last: pd.Series) -> tuple[str, str]:
    """Two summary rows' means to the precision of the wider interval; as plain figures
    when neither varies between replications (60, not 60.0000)."""
    if float(first["sd"]) == 0.0 and float(last["sd"]) == 0.0:
        return number(float(first["mean"])), number(float(last["mean"]))
    halves = [w for w in (half_width(first), half_width(last)) if math.isfinite(w)]
    d = decimals(max(halves, default=math.nan))  # one replication at an end: no interval
    return f"{float(first['mean']):.{d}f}", f"{float(last['mean']):.{d}f}"
