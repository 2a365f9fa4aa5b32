"""``report.md`` of an experiment: tables, paired differences and a reading, all
drawn from ``summary.csv`` and ``differences.csv`` (:mod:`cell.reporting.experiment`).

Every interval printed is one of those tables' (Student t, scipy.stats via
:mod:`cell.analysis.stats`); a measure that does not vary between replications
is said to, rather than shown with a zero-width interval.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from cell.analysis.stats import precision_reached, relative_half_width
from cell.reporting.experiment_data import runs_of
from cell.reporting.headlines import (
    HEADLINES,
    HUGE,
    Headline,
    decimals,
    half_width,
    number,
    plus_minus,
    table_head,
    table_row,
    too_few,
)
from cell.sweep import Sweep, grid_columns
from cell.sweep.columns import NAME_SUFFIX
from cell.sweep.windows import AUTO

#: Sentences listed per measure before the rest is left to differences.csv.
MAX_SENTENCES = 12


def display_columns(table: pd.DataFrame, sweep: Sweep) -> list[str]:
    """The grid columns that tell the points apart: a key's names if it has them, else
    its leaves that take more than one value."""
    out: list[str] = []
    columns = grid_columns(sweep)
    for key in sweep.keys:
        mine = [c for c in columns if c.key == key]
        named = [c.name for c in mine if c.is_name]
        if named:
            out += named
            continue
        varying = [c.name for c in mine if table[c.name].astype(str).nunique() > 1]
        out += varying or [c.name for c in mine]
    return out


def show(value: Any) -> str:
    if value is None or isinstance(value, float) and math.isnan(value):
        return "—"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def where(row: Mapping[Any, Any], cols: Sequence[str]) -> str:
    """``key = value, ...`` of a row's display columns."""
    return ", ".join(f"{c.removesuffix(NAME_SUFFIX)} = {show(row[c])}" for c in cols)


def cell(s: Mapping[Any, Any], whole: bool = False, runs: int | None = None) -> str:
    """A summary row as ``mean ± half [p2.5–p97.5]``, or what stands in for an interval;
    ``whole``: the measure counts things, so single runs are shown as whole numbers;
    ``runs``: the point's replications, said (``from 2 of 3 runs``) when fewer gave a value."""
    n, mean = int(s["n"]), float(s["mean"])
    if n == 0:
        return "—"
    few = runs is not None and n < runs
    if n == 1:
        return f"{number(mean)} " + (f"(from 1 of {runs} runs)" if few else "(one run)")
    of = f" (from {n} of {runs} runs)" if few else ""
    if float(s["sd"]) == 0.0:
        return f"{number(mean)} (no variation){of}"
    lo, hi = single_runs(s, whole)
    return f"{plus_minus(mean, half_width(s))} [{lo}–{hi}]{of}"


def single_runs(s: Mapping[Any, Any], whole: bool = False) -> tuple[str, str]:
    """A summary row's 2.5 and 97.5 % points of single runs, as its table cell shows them:
    whole numbers for a count (``whole``, or both already whole), else to the interval's
    precision."""
    lo, hi = float(s["run_p2_5"]), float(s["run_p97_5"])
    r = 0 if whole or lo == round(lo) and hi == round(hi) else decimals(half_width(s))
    return number(lo, r), number(hi, r)


def _against(a: str, b: str, at: bool = True) -> str:
    """``b`` without ``a``'s name when it is ``a``'s own policy elsewhere in the grid."""
    if b.startswith(a + " at "):
        return b[len(a) + 1:] if at else b[len(a) + 4:]
    return b


def _lower(title: str) -> str:
    """A title within a sentence: its first letter lowered, unless it starts an acronym (IP)."""
    return title if title[1:2].isupper() else title[:1].lower() + title[1:]


def sentence(h: Headline, d: Mapping[Any, Any], a: str, b: str, parts: int | None,
             confidence: float) -> str:
    """A paired difference in words: ``A delivers 31.2 ± 1.4 parts more than B per
    500-part run (95 % CI, paired over 200 replications).``"""
    n, mean = int(d["n"]), float(d["mean"])
    b = _against(a, b)
    level = f"{confidence * 100:g} %"
    if n == 0 or not math.isfinite(mean):
        return f"{a} against {b}: not compared, {too_few(0, _lower(h.title))}."
    if n < 2 or not math.isfinite(float(d["sd"])):
        return h.says(a, number(abs(mean)), mean, b, parts) + \
            f" ({n} replication{'s' if n != 1 else ''}: no interval)."
    if float(d["sd"]) == 0.0:
        if mean == 0.0:
            return f"{a} is the same as {b} in every replication ({h.title.lower()}: " \
                   f"no variation between replications)."
        return h.says(a, number(abs(mean)), mean, b, parts) + \
            f" in every one of {n} replications (no variation between replications)."
    lo, hi = float(d["ci_low"]), float(d["ci_high"])
    text = h.says(a, plus_minus(abs(mean), half_width(d)), mean, b, parts)
    text += f" ({level} CI, paired over {n} replications)"
    if lo <= 0.0 <= hi:
        text += "; the interval includes zero: no difference shown"
    return text + "."


def markdown(summary: pd.DataFrame, differences: pd.DataFrame, replications: pd.DataFrame,
             sweep: Sweep, command: str, figures: Sequence[str],
             caveat: str | None = None) -> str:
    """The whole ``report.md``; ``caveat``, if given, is said first (e.g. that counts
    come from different windows)."""
    parts = _parts(sweep)
    auto = _auto(sweep)
    per_run = None if auto else parts  # a warm-up of auto: the window is not `parts` parts
    cols = display_columns(summary, sweep)
    policies = sweep.policies
    level = f"{sweep.confidence * 100:g} %"
    lines = [f"# {sweep.name}" + (f": {sweep.description}" if sweep.description else ""), ""]
    lines += [" ".join([
        f"Generated by `{command}` from {_replications(sweep, parts)}, root seed {sweep.seed}; "
        "replication r draws the same parts at every point and for every policy "
        "(common random numbers).",
        f"Numbers: mean ± half-width of its {level} confidence interval (Student t) "
        "[the 2.5–97.5 % range of single runs].",
        "Differences are paired, replication by replication.",
        "Every numeric summary column: `summary.csv`; every paired difference: "
        "`differences.csv`."]), ""]
    if caveat:
        lines += [f"**Caveat:** {caveat}.", ""]
    lines += _variation(summary, sweep)
    lines += _precision(replications, summary, sweep, cols)
    present = [h for h in HEADLINES if h.column in set(summary["measure"])]
    runs = [len(runs_of(replications, sweep, i)) for i in range(len(sweep.points))]
    whole = {h.column for h in present  # counts: every run's value a whole number
             if np.all(np.mod(replications[h.column].dropna().to_numpy(float), 1) == 0)}
    for h in present:
        lines += [f"## {h.title}" + (_per_run(parts, auto) if h.per_run else ""), ""]
        lines += _table(summary[summary["measure"] == h.column], cols, policies,
                        h.column in whole, runs)
        if f"fig_{h.column}.png" in figures:
            lines += ["", f"![{h.title}](fig_{h.column}.png)"]
        lines += [""] + _sentences(h, differences, cols, per_run, sweep.confidence)
    lines += ["## Reading", ""]
    for text in reading(summary, differences, sweep, cols, present, whole):
        lines += [text, ""]
    return "\n".join(lines).rstrip() + "\n"


def _parts(sweep: Sweep) -> int | None:
    parts = {p.scenario.run.parts for p in sweep.points}
    return parts.pop() if len(parts) == 1 else None


def _auto(sweep: Sweep) -> str:
    """``all`` or ``some`` if all or some points leave MSER-5 to choose their warm-up
    (``run.warmup_parts: auto``), else ``""``."""
    auto = [p.scenario.run.warmup_parts == AUTO for p in sweep.points]
    return "all" if all(auto) else "some" if any(auto) else ""


def _per_run(parts: int | None, auto: str) -> str:
    """What a count's heading says it is per: ``, per 500-part run``; under a warm-up of
    ``auto`` the window is the parts after the warm-up MSER-5 chose, run by run, so no
    number of parts is named."""
    if auto == "all":
        return ", per run, after the warm-up MSER-5 chose for it"
    if auto:
        return ", per run, after its warm-up (chosen by MSER-5 where it is auto)"
    return f", per {parts}-part run" if parts else ""


def _replications(sweep: Sweep, parts: int | None) -> str:
    q = sweep.precision
    of = f" of {parts} part{'s' if parts != 1 else ''}" if parts else ""
    if q is None:
        return f"{sweep.replications} replication{'s' if sweep.replications != 1 else ''}{of} " \
               "per point"
    return (f"runs{of}, added in rounds of {sweep.batch} until the "
            f"{q.confidence * 100:g} % half-width of {q.measure} was at most "
            f"{q.precision * 100:g} % of its mean ({q.min_n} to {q.max_n} per point)")


def _variation(summary: pd.DataFrame, sweep: Sweep) -> list[str]:
    traced = all(p.scenario.arrivals.trace_csv for p in sweep.points)
    flat = summary[summary["n"] >= 2]
    if traced or (len(flat) and (flat["sd"] == 0).all()):
        why = (" the arrivals come from a trace (`arrivals.trace_csv`), so every replication is "
               "the same run" if traced else " every replication gave the same figures")
        return [f"**No variation between replications:**{why}; the figures are single values, "
                "without intervals, and a difference is exact.", ""]
    return []


def _precision(replications: pd.DataFrame, summary: pd.DataFrame, sweep: Sweep,
               cols: Sequence[str]) -> list[str]:
    q = sweep.precision
    if q is None:
        return []
    rows = summary[summary["measure"] == q.measure].to_dict("records")
    head = [*(c.removesuffix(NAME_SUFFIX) for c in cols), "policy", "replications",
            "half-width / |mean|", "precision"]
    lines = ["## Precision", "", f"Asked: the {q.confidence * 100:g} % half-width of "
             f"`{q.measure}` at most {q.precision * 100:g} % of |mean| at every point.", "",
             *table_head(head)]
    short = 0
    for i, row in enumerate(rows):
        values = runs_of(replications, sweep, i)[q.measure].to_numpy(dtype=float)
        rhw = relative_half_width(values, q.confidence)
        done = precision_reached({i: values}, q.precision, q.confidence, q.min_n)[i]
        short += not done
        verdict = "reached" if done else f"not reached: stopped at max = {q.max_n}"
        if int(row["n"]) < 2:
            verdict += f"; {int(row['n'])} of the runs gave {q.measure} a value"
        shown = f"{rhw * 100:.2f} %" if math.isfinite(rhw) else "—"
        lines.append(table_row([*(show(row[c]) for c in cols), str(row["policy"]),
                                str(len(values)), shown, verdict]))
    lines += ["", f"{len(rows) - short} of {len(rows)} points reached the precision"
              + (f"; {short} stopped at the maximum of {q.max_n} replications." if short
                 else "."), ""]
    return lines


def _table(rows: pd.DataFrame, cols: Sequence[str], policies: Sequence[str],
           whole: bool = False, runs: Sequence[int] | None = None) -> list[str]:
    """A measure's table: a row per grid combination, a column per policy; ``runs``: each
    row's point's replications (``rows`` are in point order, as summary.csv)."""
    grid: dict[tuple[str, ...], dict[str, str]] = {}
    for i, r in enumerate(rows.to_dict("records")):
        grid.setdefault(tuple(show(r[c]) for c in cols), {})[str(r["policy"])] = \
            cell(r, whole, runs[i] if runs is not None else None)
    head = [c.removesuffix(NAME_SUFFIX) for c in cols] + list(policies)
    out = table_head(head)
    for keys, cells in grid.items():
        out.append(table_row([*keys, *(cells.get(p, "") for p in policies)]))
    return out


def _sentences(h: Headline, differences: pd.DataFrame, cols: Sequence[str], parts: int | None,
               confidence: float) -> list[str]:
    rows = differences[differences["measure"] == h.column].to_dict("records")
    if not rows:
        return []
    out = []
    for r in rows[:MAX_SENTENCES]:
        at = where(r, cols)
        text = sentence(h, r, str(r["policy"]), str(r["versus"]), parts, confidence)
        out.append(f"- {'At ' + at + ': ' if at else ''}{text}")
    if len(rows) > MAX_SENTENCES:
        out.append(f"- … and {len(rows) - MAX_SENTENCES} more in `differences.csv`.")
    return out + [""]


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
        text = f"{str(a).capitalize()} against {_against(str(a), str(b), at=False)}: "
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


__all__ = ["display_columns", "markdown", "reading", "sentence"]
