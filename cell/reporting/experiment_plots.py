"""The figures of an experiment's report: one PNG per headline measure.

Each shows the mean with its confidence interval (from ``summary.csv``) against
the varied key, one line per policy with its band; a policy that does not vary
the key is a level line with its band across the plot.  A key with named,
mapping or text values is drawn point by point (markers with error bars); a
second varied key (and any further ones) gives one panel per value; with no
varied key, one point per policy.  Built on :class:`matplotlib.figure.Figure`
(no pyplot, no display); the PNGs carry no software version, so reruns give
the same bytes.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from typing import Any

import matplotlib as mpl
import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from cell.reporting.experiment_text import display_columns, show
from cell.reporting.headlines import HEADLINES, Headline
from cell.sweep import Sweep, grid_columns
from cell.sweep.columns import NAME_SUFFIX

DPI = 110
#: Most panels a figure gets; a grid with more combinations gets no figures.
MAX_PANELS = 16
#: Means further apart than this (ratio) are drawn on a log scale.
LOG_SPAN = 1e3
COLOURS = {"adaptive": "#1f77b4", "non-adaptive": "#d62728"}
OTHERS = ("#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f")
RC: dict[str, Any] = {"font.size": 10, "axes.grid": True, "grid.alpha": 0.35, "grid.linestyle": ":",
      "axes.spines.top": False, "axes.spines.right": False, "legend.fontsize": 8.5}


def figures(summary: pd.DataFrame, replications: pd.DataFrame, sweep: Sweep) -> dict[str, bytes]:
    """``fig_<measure>.png`` -> PNG bytes, for each headline measure in the summary."""
    cols = display_columns(summary, sweep)
    panels: list[tuple[str, ...]] = [()]
    if cols:
        panels = list(dict.fromkeys(tuple(show(v) for v in r)
                                    for r in summary[cols[1:]].itertuples(index=False)))
    if len(panels) > MAX_PANELS:
        return {}
    policies = sweep.policies
    colours = {p: COLOURS.get(p) or OTHERS[i % len(OTHERS)] for i, p in enumerate(policies)}
    out = {}
    for h in HEADLINES:
        rows = summary[summary["measure"] == h.column]
        if rows.empty:
            continue
        out[f"fig_{h.column}.png"] = _figure(h, rows, sweep, cols, panels, colours)
    return out


def _figure(h: Headline, rows: pd.DataFrame, sweep: Sweep, cols: Sequence[str],
            panels: list[tuple[str, ...]], colours: dict[str, str]) -> bytes:
    n = len(panels)
    ncols = min(3, n)
    nrows = math.ceil(n / ncols)
    with mpl.rc_context(RC):  # type: ignore[arg-type]
        fig = Figure(figsize=(min(12.0, 1.0 + 5.2 * ncols), 3.8 * nrows + 0.6),
                     layout="constrained")
        axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False).ravel())
        level = f"{sweep.confidence * 100:g} %"
        mean = rows["mean"].to_numpy(float)
        log = bool(np.all(mean > 0) and mean.max() / mean.min() > LOG_SPAN)
        fig.suptitle(f"{h.title}: mean and {level} confidence interval"
                     + (" (log scale)" if log else ""), fontsize=11)
        if log:  # a few runs many orders of magnitude out: keep the others readable
            floor = mean.min() / 2
            rows = rows.assign(ci_low=rows["ci_low"].clip(lower=floor))
        for ax, combo in zip(axes, panels, strict=False):
            sub = rows
            for c, v in zip(cols[1:], combo, strict=True):
                sub = sub[sub[c].map(show) == v]
            _panel(ax, h, sub, sweep, cols, colours)
            if log:
                ax.set_yscale("log")
            if cols[1:]:
                ax.set_title(", ".join(f"{c.removesuffix(NAME_SUFFIX)} = {v}"
                                       for c, v in zip(cols[1:], combo, strict=True)),
                             fontsize=9.5)
        for ax in axes[n:]:
            ax.set_visible(False)
        axes[0].legend(loc="best")
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=DPI, metadata={"Software": None})
    return buffer.getvalue()


def _panel(ax: Axes, h: Headline, rows: pd.DataFrame, sweep: Sweep, cols: Sequence[str],
           colours: dict[str, str]) -> None:
    ax.set_ylabel(h.title)
    policies = sweep.policies
    if not cols:  # only the policies vary: a point per policy
        for i, policy in enumerate(policies):
            r = rows[rows["policy"] == policy]
            if len(r):
                _points(ax, [float(i)], r, colours[policy], policy)
        ax.set_xticks(range(len(policies)), policies)
        ax.set_xlim(-0.6, len(policies) - 0.4)
        return
    x = cols[0]
    key = next(c.key for c in grid_columns(sweep) if c.name == x)
    varies = {p.policy for p in sweep.points if key in dict(p.values)}
    numeric = not x.endswith(NAME_SUFFIX) and pd.to_numeric(rows[x], errors="coerce").notna().all() \
        and not rows[x].map(lambda v: isinstance(v, (bool, np.bool_))).any()
    ticks = list(dict.fromkeys(rows[x].map(show)))
    for k, policy in enumerate(policies):
        r = rows[rows["policy"] == policy]
        if r.empty:
            continue
        if policy not in varies:
            _level(ax, r.iloc[0], colours[policy], f"{policy} (does not vary {key})")
        elif numeric:
            r = r.assign(_x=pd.to_numeric(r[x])).sort_values("_x")
            x_num, mean = r["_x"].to_numpy(float), r["mean"].to_numpy(float)
            ax.plot(x_num, mean, "o-", color=colours[policy], label=policy, ms=4)
            ax.fill_between(x_num, r["ci_low"].to_numpy(float), r["ci_high"].to_numpy(float),
                            color=colours[policy], alpha=0.2, lw=0)
        else:
            dodge = (k - (len(policies) - 1) / 2) * 0.08
            xs = [ticks.index(v) + dodge for v in r[x].map(show)]
            _points(ax, xs, r, colours[policy], policy)
    if not numeric:
        ax.set_xticks(range(len(ticks)), ticks, rotation=0 if len(ticks) < 5 else 30)
        ax.set_xlim(-0.6, len(ticks) - 0.4)
    ax.set_xlabel(x.removesuffix(NAME_SUFFIX))


def _points(ax: Axes, xs: Sequence[float], r: pd.DataFrame, colour: str, label: str) -> None:
    mean = r["mean"].to_numpy(float)
    low = np.nan_to_num(mean - r["ci_low"].to_numpy(float))
    high = np.nan_to_num(r["ci_high"].to_numpy(float) - mean)
    ax.errorbar(xs, mean, yerr=[low, high], fmt="o", color=colour, label=label, capsize=4, ms=5)


def _level(ax: Axes, row: pd.Series, colour: str, label: str) -> None:
    ax.axhline(float(row["mean"]), color=colour, ls="--", lw=1.3, label=label)
    lo, hi = float(row["ci_low"]), float(row["ci_high"])
    if math.isfinite(lo) and math.isfinite(hi) and hi > lo:
        ax.axhspan(lo, hi, color=colour, alpha=0.15, lw=0)
