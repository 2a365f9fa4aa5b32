"""The compact table of a headline measure in ``report.md``: a row per grid point (its
values and its load), a column per policy (mean ± half-width), then a column per paired
comparison (the policies against each other, and each against the named ``baseline:``),
each a difference with its interval; a difference whose interval holds 0 is in italics.
Parts delivered has, beside each policy's column, that policy's ``of bound %`` (said in a
line above the table): its runs'
deliveries as a share of their bound (:data:`cell.reporting.experiment.data.BOUND_SHARE`),
mean ± half-width over the replications.

Every figure is one of ``summary.csv``'s or ``differences.csv``'s rows
(:mod:`cell.reporting.experiment.data`); single runs' ranges stay in ``summary.csv``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from cell.experiments.sweep.columns import NAME_SUFFIX
from cell.reporting.experiment.data import BOUND_SHARE
from cell.reporting.experiment.reading import against, show
from cell.reporting.formatting import Headline, half_width, number, plus_minus, table_head, table_row

#: The summary column that says how loaded a point's robot is (its fastest cycle over the
#: mean inter-arrival time), under its new name first.
LOAD_COLUMNS = ("offered_load", "load", "utilisation")  # today's name, then older sweeps'
#: A headline measure shown with a share beside each policy's column: (the share's
#: measure, its column's heading, the line under the table that says what it is).
SHARES = {"parts_delivered": (BOUND_SHARE, "of bound %", (
    "of bound %: each run's parts delivered over its `parts_bound`, the most any controller "
    "could deliver from the same arrivals with the same robot and belts (docs/model.md, "
    "\"The bound on any controller\"), mean ± half-width over the runs."))}


def load_column(summary: pd.DataFrame) -> str | None:
    """The load's measure in ``summary``, if it has one."""
    have = set(summary["measure"])
    return next((c for c in LOAD_COLUMNS if c in have), None)


def mean_cell(s: Mapping[Any, Any], runs: int | None = None) -> str:
    """A summary row as ``mean ± half``; what stands in for an interval otherwise."""
    n, mean = int(s["n"]), float(s["mean"])
    if n == 0:
        return "—"
    of = f" (from {n} of {runs} runs)" if runs is not None and n < runs else ""
    if n == 1 or not math.isfinite(float(s["sd"])):
        return f"{number(mean)}{of}"
    if float(s["sd"]) == 0.0:
        return f"{number(mean)} (no variation){of}"
    return plus_minus(mean, half_width(s)) + of


def difference_cell(d: Mapping[Any, Any]) -> str:
    """A paired difference as ``+3.1 ± 0.4``, in italics when its interval holds 0."""
    n, mean = int(d["n"]), float(d["mean"])
    if n == 0 or not math.isfinite(mean):
        return "—"
    if n < 2 or not math.isfinite(float(d["sd"])):
        return f"{mean:+.6g} (1 pair)"
    if float(d["sd"]) == 0.0:
        return "0 (same)" if mean == 0.0 else f"{mean:+.6g} (exact)"
    text = plus_minus(mean, half_width(d), signed=True)
    return f"*{text}*" if float(d["ci_low"]) <= 0.0 <= float(d["ci_high"]) else text


def comparison_name(policy: str, versus: str, policies: Sequence[str],
                    row: Mapping[Any, Any] | None = None, cols: Sequence[str] = ()) -> str:
    """A difference column's heading: ``adaptive − non-adaptive``, ``adaptive − baseline``;
    two scenarios compared (``cell compare``: the baseline named by its scenario's name):
    ``heavy-gamma − baseline``, by ``row``'s values of ``cols``."""
    if versus in policies:
        return f"{policy} − {versus}"
    if versus.startswith(policy + " at ") or row is None or not cols:
        return f"{policy} − baseline"
    return " ".join(show(row[c]) for c in cols) + f" − {versus}"


def baseline_words(differences: pd.DataFrame, policies: Sequence[str]) -> str | None:
    """What the baseline is, in words (``arrivals.params = thesis``), if a column has one."""
    for r in differences.to_dict("records"):
        if str(r["versus"]) not in policies:
            v = str(r["versus"])
            return against(str(r["policy"]), v, at=False) if v.startswith(f"{r['policy']} at ") \
                else v
    return None


def compact_table(h: Headline, summary: pd.DataFrame, differences: pd.DataFrame,
                  cols: Sequence[str], policies: Sequence[str],
                  runs: Sequence[int] | None = None) -> list[str]:
    """The measure ``h``'s table (see the module's docstring); ``summary`` is all of
    ``summary.csv`` (the load comes from it), ``runs`` each point's replications, in
    ``summary``'s point order."""
    rows: dict[tuple[str, ...], dict[str, str]] = {}
    load_of: dict[tuple[str, ...], list[str]] = {}
    share = SHARES.get(h.column)
    beside = [name for p in policies for name in (p, *([f"{p} {share[1]}"] if share else ()))]
    mine = summary[summary["measure"] == h.column]
    for i, r in enumerate(mine.to_dict("records")):
        key = tuple(show(r[c]) for c in cols)
        rows.setdefault(key, {})[str(r["policy"])] = \
            mean_cell(r, runs[i] if runs is not None else None)
    if share is not None:
        for i, r in enumerate(summary[summary["measure"] == share[0]].to_dict("records")):
            rows.setdefault(tuple(show(r[c]) for c in cols), {})[f"{r['policy']} {share[1]}"] = \
                mean_cell(r, runs[i] if runs is not None else None)
    loaded = load_column(summary)
    if loaded is not None:
        for r in summary[summary["measure"] == loaded].to_dict("records"):
            shown = f"{float(r['mean']):.3f}" if math.isfinite(float(r["mean"])) else "—"
            load_of.setdefault(tuple(show(r[c]) for c in cols), []).append(shown)
    compared: list[str] = []
    for d in differences[differences["measure"] == h.column].to_dict("records"):
        name = comparison_name(str(d["policy"]), str(d["versus"]), policies, d, cols)
        if name not in compared:
            compared.append(name)
        rows.setdefault(tuple(show(d[c]) for c in cols), {})[name] = difference_cell(d)
    compared.sort(key=lambda name: name.endswith(" − baseline"))  # the policies' first
    have = {name for cells in rows.values() for name in cells}
    beside = [p for p in beside if p in policies or p in have]  # no share: no column
    head = [c.removesuffix(NAME_SUFFIX) for c in cols] + (["load"] if loaded else []) \
        + [p if share is None or p in policies else share[1] for p in beside] + compared
    out = [share[2], ""] if share is not None and len(beside) > len(policies) else []
    out += table_head(head)
    for key, cells in rows.items():
        load = " / ".join(dict.fromkeys(load_of.get(key, ["—"]))) if loaded else None
        out.append(table_row([*key, *([load] if load is not None else []),
                              *(cells.get(p, "") for p in [*beside, *compared])]))
    return out
