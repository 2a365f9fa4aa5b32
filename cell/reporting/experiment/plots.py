"""The figures of an experiment's report: one PNG per headline measure.

Each shows the mean with its confidence interval (from ``summary.csv``) against
the first varied key, one line per policy with its band; a policy that does not
vary that key is a level line with its band across the plot.  A key with named,
mapping or text values is drawn point by point (markers with error bars).  The
other keys that every policy varies give one panel per combination of values,
titled with them (wrapped to the panel's width); a key that only some policies
vary gives each of them one line per value in every panel (same colour, another
marker and line style), so the policies always share a panel.  With no varied
key, one point per policy.  Intervals of counts are drawn from 0 at the lowest.
Several panels share one legend below them, naming every line drawn.  Built on
:class:`matplotlib.figure.Figure` (no pyplot, no display); the PNGs carry no
software version, so reruns give the same bytes.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import matplotlib as mpl
import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from cell.experiments.sweep import Sweep, grid_columns
from cell.experiments.sweep.columns import NAME_SUFFIX
from cell.reporting.experiment.reading import show
from cell.reporting.experiment.text import display_columns
from cell.reporting.formatting import HEADLINES, Headline

DPI = 110
#: Most panels a figure gets; a grid with more combinations gets no figures.
MAX_PANELS = 16
#: Means further apart than this (ratio) are drawn on a log scale.
LOG_SPAN = 1e3
#: Characters per line of a panel's title.
TITLE_WIDTH = 50
COLOURS = {"adaptive": "#1f77b4", "non-adaptive": "#d62728"}
OTHERS = ("#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f")
#: A policy's lines over the keys only it varies: marker and line style, in turn.
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")
STYLES = ("-", "--", ":", "-.")
RC: dict[str, Any] = {"font.size": 10, "axes.grid": True, "grid.alpha": 0.35, "grid.linestyle": ":",
      "axes.spines.top": False, "axes.spines.right": False, "legend.fontsize": 8.5}


@dataclass(frozen=True)
class Layout:
    """Which grid columns go where: the x axis, the panels (keys every policy varies)
    and each policy's own lines (keys only some policies vary)."""

    x: str | None
    panels: tuple[str, ...]
    own: dict[str, tuple[str, ...]]
    keys: dict[str, str]
    """Grid column -> its varied key."""
    varies: dict[str, set[str]]
    """Varied key -> the policies that vary it."""


def layout(summary: pd.DataFrame, sweep: Sweep) -> Layout:
    """Where each of the summary's display columns goes (see the module's docstring)."""
    cols = display_columns(summary, sweep)
    keys = {c.name: c.key for c in grid_columns(sweep)}
    varies = {k: {p.policy for p in sweep.points if k in dict(p.values)} for k in sweep.keys}
    policies = set(sweep.policies)
    panels = tuple(c for c in cols[1:] if varies[keys[c]] == policies)
    own = {p: tuple(c for c in cols[1:] if c not in panels and p in varies[keys[c]])
           for p in sweep.policies}
    return Layout(cols[0] if cols else None, panels, own, keys, varies)


def figures(summary: pd.DataFrame, replications: pd.DataFrame, sweep: Sweep) -> dict[str, bytes]:
    """``fig_<measure>.png`` -> PNG bytes, for each headline measure in the summary."""
    plan = layout(summary, sweep)
    panels = _combos(summary, plan.panels)
    if len(panels) > MAX_PANELS:
        return {}
    policies = sweep.policies
    colours = {p: COLOURS.get(p) or OTHERS[i % len(OTHERS)] for i, p in enumerate(policies)}
    out = {}
    for h in HEADLINES:
        rows = summary[summary["measure"] == h.column]
        if rows.empty:
            continue
        out[f"fig_{h.column}.png"] = _figure(h, rows, sweep, plan, panels, colours)
    return out


def _figure(h: Headline, rows: pd.DataFrame, sweep: Sweep, plan: Layout,
            panels: list[tuple[str, ...]], colours: dict[str, str]) -> bytes:
    with mpl.rc_context(RC):  # type: ignore[arg-type]
        fig = draw(h, rows, sweep, plan, panels, colours)
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=DPI, metadata={"Software": None})
    return buffer.getvalue()


def draw(h: Headline, rows: pd.DataFrame, sweep: Sweep, plan: Layout,
         panels: list[tuple[str, ...]], colours: dict[str, str]) -> Figure:
    """The figure of one headline measure: ``rows``, its summary rows, over ``panels``
    (values of ``plan.panels``)."""
    n = len(panels)
    ncols = min(3, n)
    nrows = math.ceil(n / ncols)
    fig = Figure(figsize=(min(12.0, 1.0 + 5.2 * ncols), 3.8 * nrows + 0.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False, sharey=True).ravel())
    level = f"{sweep.confidence * 100:g} %"
    if h.per_run:  # a count is never below 0, nor is its interval drawn there
        rows = rows.assign(ci_low=rows["ci_low"].clip(lower=0.0))
    mean = rows["mean"].to_numpy(float)
    log = bool(np.all(mean > 0) and mean.max() / mean.min() > LOG_SPAN)
    fig.suptitle(f"{h.title}: mean and {level} confidence interval"
                 + (" (log scale)" if log else ""), fontsize=11)
    if log:  # a few runs many orders of magnitude out: keep the others readable
        floor = mean.min() / 2
        rows = rows.assign(ci_low=rows["ci_low"].clip(lower=floor))
    for ax, combo in zip(axes, panels, strict=False):
        _panel(ax, h, _select(rows, plan.panels, combo), sweep, plan, colours)
        if log:
            ax.set_yscale("log")
        if plan.panels:
            ax.set_title(title(list(zip(plan.panels, combo, strict=True))), fontsize=9.5)
    for ax in axes[n:]:
        ax.set_visible(False)
    if n == 1:
        axes[0].legend(loc="best")
    else:  # every panel's lines, once, below them all
        drawn: dict[str, Any] = {}
        for ax in axes[:n]:
            for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
                drawn.setdefault(label, handle)
        fig.legend(list(drawn.values()), list(drawn), loc="outside lower center",
                   ncols=_legend_columns(list(drawn), fig.get_figwidth()))
    return fig


#: Scenario keys in words, for an axis.
KEY_WORDS = {
    "arrivals.mean_s": "mean inter-arrival time (s)",
    "arrivals.cv": "inter-arrival coefficient of variation",
    "arrivals.params": "inter-arrival distribution",
    "belts.input_nominal_in_s": "input belt's nominal speed (in/s)",
    "belts.output_nominal_in_s": "output belt's nominal speed (in/s)",
    "controller.ideal_cycle_s": "fixed robot cycle (s)",
    "controller.nominal_cycle_s": "nominal robot cycle (s)",
    "part.weight_oz": "part weight (oz)",
    "run.parts": "parts per run",
}
#: Unit suffixes of a key's last part, in words.
UNITS = (("_in_s", "in/s"), ("_oz", "oz"), ("_in", "in"), ("_pct", "%"), ("_s", "s"))


def key_words(key: str) -> str:
    """A scenario key as an axis label: in words where known (``input belt's nominal
    speed (in/s)``), else its last parts with spaces and the unit its suffix names."""
    if key in KEY_WORDS:
        return KEY_WORDS[key]
    head, _, leaf = key.rpartition(".")
    for suffix, unit in UNITS:
        if leaf.endswith(suffix):
            words = f"{head.rpartition('.')[2]} {leaf.removesuffix(suffix)}".replace("_", " ")
            return f"{words.strip()} ({unit})"
    return f"{head.rpartition('.')[2]} {leaf}".replace("_", " ").strip()


def _legend_columns(labels: Sequence[str], width_in: float) -> int:
    """As many columns as fit the figure's width (8.5 pt entries), fewer if that fills
    the rows evenly (one policy's lines to a column when they are as many)."""
    fits = max(1, min(len(labels), int(width_in * 14 / (max(map(len, labels)) + 6))))
    even = max(c for c in range(1, fits + 1) if len(labels) % c == 0)
    return even if 2 * even >= fits else fits


def title(values: Sequence[tuple[str, str]], width: int = TITLE_WIDTH) -> str:
    """``key = value, ...`` broken between pairs into lines of at most ``width``
    characters where it can be."""
    lines: list[str] = []
    for c, v in values:
        item = f"{c.removesuffix(NAME_SUFFIX)} = {v}"
        if lines and len(lines[-1]) + 2 + len(item) <= width:
            lines[-1] += ", " + item
        else:
            lines.append(item)
    return "\n".join(lines)


def _series(rows: pd.DataFrame, plan: Layout, policies: Sequence[str]
            ) -> list[tuple[str, int, str, pd.DataFrame]]:
    """The lines of a panel: (policy, index among its own lines, label, rows), one per
    combination of the keys only that policy varies (one line if it has none)."""
    out = []
    for policy in policies:
        r = rows[rows["policy"] == policy]
        own = list(plan.own[policy])
        if not own:
            out.append((policy, 0, policy, r))
            continue
        for j, combo in enumerate(_combos(r, own)):
            label = f"{policy}: " + ", ".join(f"{c.removesuffix(NAME_SUFFIX)} = {v}"
                                               for c, v in zip(own, combo, strict=True))
            out.append((policy, j, label, _select(r, own, combo)))
    return out


def _combos(rows: pd.DataFrame, cols: Sequence[str]) -> list[tuple[str, ...]]:
    """The combinations of ``cols``' values in ``rows``, as shown, in order of appearance."""
    return list(dict.fromkeys(tuple(show(v) for v in t)
                              for t in rows[list(cols)].itertuples(index=False)))


def _select(rows: pd.DataFrame, cols: Sequence[str], combo: Sequence[str]) -> pd.DataFrame:
    """The rows whose ``cols`` show as ``combo``."""
    for c, v in zip(cols, combo, strict=True):
        rows = rows[rows[c].map(show) == v]
    return rows


def _panel(ax: Axes, h: Headline, rows: pd.DataFrame, sweep: Sweep, plan: Layout,
           colours: dict[str, str]) -> None:
    ax.set_ylabel(h.title + (", per run" if h.per_run else ""))
    policies = sweep.policies
    lines = _series(rows, plan, policies)
    step = min(0.08, 0.6 / max(len(lines), 1))
    x = plan.x
    if x is None:  # only the policies vary: a point per policy
        for i, policy in enumerate(policies):
            r = rows[rows["policy"] == policy]
            if len(r):
                _points(ax, [float(i)], r, colours[policy], policy)
        ax.set_xticks(range(len(policies)), policies)
        ax.set_xlim(-0.6, len(policies) - 0.4)
        return
    key = plan.keys[x]
    numeric = not x.endswith(NAME_SUFFIX) and pd.to_numeric(rows[x], errors="coerce").notna().all() \
        and not rows[x].map(lambda v: isinstance(v, (bool, np.bool_))).any()
    ticks = list(dict.fromkeys(rows[x].map(show)))
    for k, (policy, j, label, r) in enumerate(lines):
        if r.empty:
            continue
        colour, marker = colours[policy], MARKERS[j % len(MARKERS)]
        if policy not in plan.varies[key]:
            _level(ax, r.iloc[0], colour, f"{label} (does not vary {key})",
                   ("--", ":", "-.")[j % 3])
        elif numeric:
            r = r.assign(_x=pd.to_numeric(r[x])).sort_values("_x")
            x_num, mean = r["_x"].to_numpy(float), r["mean"].to_numpy(float)
            ax.plot(x_num, mean, marker=marker, ls=STYLES[j % len(STYLES)], color=colour,
                    label=label, ms=4)
            ax.fill_between(x_num, r["ci_low"].to_numpy(float), r["ci_high"].to_numpy(float),
                            color=colour, alpha=0.2, lw=0)
        else:
            dodge = (k - (len(lines) - 1) / 2) * step
            xs = [ticks.index(v) + dodge for v in r[x].map(show)]
            _points(ax, xs, r, colour, label, marker)
    if not numeric:
        ax.set_xticks(range(len(ticks)), ticks, rotation=0 if len(ticks) < 5 else 30)
        ax.set_xlim(-0.6, len(ticks) - 0.4)
    ax.set_xlabel(key_words(x.removesuffix(NAME_SUFFIX)))


def _points(ax: Axes, xs: Sequence[float], r: pd.DataFrame, colour: str, label: str,
            marker: str = "o") -> None:
    mean = r["mean"].to_numpy(float)
    low = np.nan_to_num(mean - r["ci_low"].to_numpy(float))
    high = np.nan_to_num(r["ci_high"].to_numpy(float) - mean)
    ax.errorbar(xs, mean, yerr=[low, high], fmt=marker, color=colour, label=label, capsize=4,
                ms=5)


def _level(ax: Axes, row: pd.Series, colour: str, label: str, style: str = "--") -> None:
    ax.axhline(float(row["mean"]), color=colour, ls=style, lw=1.3, label=label)
    lo, hi = float(row["ci_low"]), float(row["ci_high"])
    if math.isfinite(lo) and math.isfinite(hi) and hi > lo:
        ax.axhspan(lo, hi, color=colour, alpha=0.15, lw=0)
