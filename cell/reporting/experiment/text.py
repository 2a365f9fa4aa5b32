"""``report.md`` of an experiment: tables, paired differences and a reading
(:mod:`cell.reporting.experiment.reading`), all drawn from ``summary.csv`` and
``differences.csv`` (:mod:`cell.reporting.experiment.report`).

Every interval printed is one of those tables' (Student t, scipy.stats via
:mod:`cell.experiments.stats`); a measure that does not vary between replications
is said to, rather than shown with a zero-width interval.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from cell.experiments.stats import precision_reached, relative_half_width
from cell.experiments.sweep import Sweep, grid_columns
from cell.experiments.sweep.columns import NAME_SUFFIX
from cell.experiments.sweep.results import runs_of
from cell.experiments.sweep.windows import AUTO
from cell.reporting.experiment.compact import baseline_words, compact_table
from cell.reporting.experiment.data import run_counts
from cell.reporting.experiment.explain import reading
from cell.reporting.experiment.reading import against, show, single_runs
from cell.reporting.formatting import (
    HEADLINES,
    Headline,
    half_width,
    number,
    plus_minus,
    table_head,
    table_row,
    too_few,
)
from cell.scenario.run_length import RunLength

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


def _lower(title: str) -> str:
    """A title within a sentence: its first letter lowered, unless it starts an acronym (IP)."""
    return title if title[1:2].isupper() else title[:1].lower() + title[1:]


def sentence(h: Headline, d: Mapping[Any, Any], a: str, b: str, length: RunLength | None,
             confidence: float) -> str:
    """A paired difference in words: ``A delivers 31.2 ± 1.4 parts more than B per
    500-part run (95 % CI, paired over 200 replications).``"""
    n, mean = int(d["n"]), float(d["mean"])
    b = against(a, b)
    level = f"{confidence * 100:g} %"
    if n == 0 or not math.isfinite(mean):
        return f"{a} against {b}: not compared, {too_few(0, _lower(h.title))}."
    if n < 2 or not math.isfinite(float(d["sd"])):
        return h.says(a, number(abs(mean)), mean, b, length) + \
            f" ({n} replication{'s' if n != 1 else ''}: no interval)."
    if float(d["sd"]) == 0.0:
        if mean == 0.0:
            return f"{a} is the same as {b} in every replication ({h.title.lower()}: " \
                   f"no variation between replications)."
        return h.says(a, number(abs(mean)), mean, b, length) + \
            f" in every one of {n} replications (no variation between replications)."
    lo, hi = float(d["ci_low"]), float(d["ci_high"])
    text = h.says(a, plus_minus(abs(mean), half_width(d)), mean, b, length)
    text += f" ({level} CI, paired over {n} replications)"
    if lo <= 0.0 <= hi:
        text += "; the interval includes zero: no difference shown"
    return text + "."


def markdown(summary: pd.DataFrame, differences: pd.DataFrame, replications: pd.DataFrame,
             sweep: Sweep, command: str, figures: Sequence[str],
             caveat: str | None = None, table_7_1: bool = False) -> str:
    """The whole ``report.md``; ``caveat``, if given, is said first (e.g. that counts
    come from different windows); ``table_7_1``: the report holds Table 7.1's two files,
    linked before the first section."""
    length = _length(sweep)
    auto = _auto(sweep)
    cols = display_columns(summary, sweep)
    policies = sweep.policies
    level = f"{sweep.confidence * 100:g} %"
    base = baseline_words(differences, policies)
    lines = [f"# {sweep.name}" + (f": {sweep.description}" if sweep.description else ""), ""]
    lines += [" ".join([
        f"Generated by `{command}` from {_replications(sweep, length)}, root seed {sweep.seed}; "
        "replication r draws the same parts at every point and for every policy "
        "(common random numbers).",
        f"Numbers: mean ± half-width of its {level} confidence interval (Student t); "
        "load: the robot's fastest cycle over the mean inter-arrival time.",
        "Differences are paired, replication by replication, in italics where the interval "
        "holds 0" + (f"; the baseline: {base}." if base else "."),
        "Every numeric summary column, with the range of single runs: `summary.csv`; every "
        "paired difference: `differences.csv`."]), ""]
    if caveat:
        lines += [f"**Caveat:** {caveat}.", ""]
    lines += _variation(summary, sweep) + _stationarity(sweep)
    if table_7_1:
        lines += ["Table 7.1 beside the thesis's: [`table_7_1.md`](table_7_1.md); its numbers: "
                  "[`table_7_1.csv`](table_7_1.csv).", ""]
    lines += _precision(replications, summary, sweep, cols)
    present = [h for h in HEADLINES if h.column in set(summary["measure"])]
    runs = run_counts(replications, sweep)
    whole = {h.column for h in present  # counts: every run's value a whole number
             if np.all(np.mod(replications[h.column].dropna().to_numpy(float), 1) == 0)}
    for h in present:
        lines += [f"## {h.title}" + (_per_run(length, auto) if h.per_run else ""), ""]
        lines += compact_table(h, summary, differences, cols, policies, runs) + [""]
    shown = [f"![{h.title}](fig_{h.column}.png)" for h in present
             if f"fig_{h.column}.png" in figures]
    if shown:
        lines += ["## Figures", "", " ".join(shown), ""]
    lines += ["## Reading", ""]
    lines += reading(summary, differences, sweep, cols, present, whole)
    return "\n".join(lines).rstrip() + "\n"


def _length(sweep: Sweep) -> RunLength | None:
    """The points' run length, if they share one."""
    lengths = {RunLength.of(p.scenario.run) for p in sweep.points}
    return lengths.pop() if len(lengths) == 1 else None


def _auto(sweep: Sweep) -> str:
    """``all`` or ``some`` if all or some points leave MSER-5 to choose their warm-up
    (``run.warmup_parts: auto``), else ``""``."""
    auto = [p.scenario.run.warmup_parts == AUTO for p in sweep.points]
    return "all" if all(auto) else "some" if any(auto) else ""


def _per_run(length: RunLength | None, auto: str) -> str:
    """What a count's heading says it is per: ``, per 500-part run``; under a warm-up of
    ``auto`` the window is the parts after the warm-up MSER-5 chose, run by run, so no
    number of parts is named."""
    if auto == "all":
        return ", per run, after the warm-up MSER-5 chose for it"
    if auto:
        return ", per run, after its warm-up (chosen by MSER-5 where it is auto)"
    return f", per {length.run}" if length else ""


def _replications(sweep: Sweep, length: RunLength | None) -> str:
    q = sweep.precision
    of = f" of {length}" if length else ""
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


def _stationarity(sweep: Sweep) -> list[str]:
    """A line when the arrivals of some points change their rate over a period (a profile)."""
    from cell.scenario.rate_profile import describe

    profiles = [p.scenario.arrivals.profile for p in sweep.points]
    varying = [p for p in profiles if p is not None]
    if not varying:
        return []
    some = "" if len(varying) == len(profiles) else f" ({len(varying)} of {len(profiles)} points)"
    return [f"**Arrivals not stationary** (`arrivals.profile`){some}: {describe(varying[0])}.", ""]


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


__all__ = ["display_columns", "markdown", "reading", "sentence"]


def first_tables(markdown: str, tables: int = 3) -> str:
    """The first ``tables`` tables of a report, each under its heading, for the terminal
    (``cell sweep`` prints them)."""
    out: list[str] = []
    heading, shown = "", 0
    lines = markdown.splitlines()
    for i, line in enumerate(lines):
        if line.startswith("## "):
            heading = line[3:]
        elif line.startswith("|") and (i == 0 or not lines[i - 1].startswith("|")):
            if shown == tables:
                break
            out += ["", heading] if heading else [""]
            shown += 1
        if line.startswith("|"):
            out.append(line)
    return "\n".join(out).strip("\n")
