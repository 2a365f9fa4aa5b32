"""``cell fit``'s figure: the data under the fitted densities, on an axis in seconds that
shows the body of the data (a few stoppages do not stretch it); for censored times to
failure or repair, the Kaplan-Meier estimate under the fitted cdfs."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.experiments.fit.gaps import fence
from cell.experiments.fit.mle import Fit


def _canvas() -> tuple[Any, Any]:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8.0, 5.0))
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


def body_range(x: NDArray[np.float64]) -> tuple[float, float]:
    """The axis's span: from the least value to the largest within Q3 + 3 IQR
    (:func:`~cell.experiments.fit.gaps.fence`), 5 % of that span more on each side."""
    lo = float(x.min())
    hi = float(x[x <= fence(x)].max())
    pad = 0.05 * (hi - lo) if hi > lo else 0.05 * max(abs(lo), 1.0)
    return lo - pad, hi + pad


def _curves(ax: Any, fits: Sequence[Fit], best: Fit | None, grid: NDArray[np.float64], curve: str) -> None:
    for f in fits:
        bold = f is best
        with np.errstate(all="ignore"):
            y = getattr(f.frozen(), curve)(grid)
        ax.plot(grid, y, lw=2.6 if bold else 1.2, ls="-" if bold else "--", zorder=3 if bold else 2,
                label=f"{f.family}{' (chosen)' if bold else ''}: D = {f.statistic:.4f}, AIC = {f.aic:.1f}")


def figure(values: ArrayLike, fits: Sequence[Fit], *, best: Fit | None = None,
           xlabel: str = "inter-arrival time (s)") -> Any:
    """Histogram of ``values`` (a density over all of them, 1/s) under each fitted pdf, on
    :func:`body_range`; the values beyond it counted in the title; ``best`` (default the first
    fit) drawn bold (not saved)."""
    x = np.asarray(values, dtype=float).ravel()
    best = best if best is not None else (fits[0] if fits else None)
    fig, ax = _canvas()
    lo, hi = body_range(x)
    shown = x[x <= hi]
    counts, edges = np.histogram(shown, bins="auto")
    heights = counts / (x.size * np.diff(edges))  # a density over all the values: the pdfs' scale
    ax.stairs(heights, edges, fill=True, color="0.85", label=f"data (n = {x.size})")
    ax.stairs(heights, edges, color="0.6")
    _curves(ax, fits, best, np.linspace(lo, hi, 600), "pdf")
    ax.set_xlim(lo, hi)
    ax.set_ylim(0.0, 1.6 * float(np.max(heights)) if heights.size and heights.max() > 0 else 1.0)
    off = x[x > hi]
    if off.size:
        ax.set_title(f"{off.size} of {x.size} values beyond {hi:.4g} s (up to {off.max():.4g} s) lie "
                     "off the axis, far out of the body of the data", loc="left", fontsize=9)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("density (1/s)")
    ax.legend(fontsize="small")
    return fig


def draw(values: ArrayLike, fits: Sequence[Fit], out_png: str | Path, *, best: Fit | None = None,
         xlabel: str = "inter-arrival time (s)") -> None:
    """:func:`figure`, written as PNG to ``out_png``."""
    figure(values, fits, best=best, xlabel=xlabel).savefig(out_png, format="png", dpi=100)


def draw_censored(values: ArrayLike, censored: ArrayLike, fits: Sequence[Fit], out_png: str | Path, *,
                  best: Fit | None = None, xlabel: str = "time (s)") -> None:
    """The Kaplan-Meier estimate of the cdf of right-censored ``values`` (``censored`` True
    where the item was still working) under each fitted cdf; written as PNG to ``out_png``."""
    from scipy import stats

    x = np.asarray(values, dtype=float).ravel()
    c = np.asarray(censored, dtype=bool).ravel()
    best = best if best is not None else (fits[0] if fits else None)
    fig, ax = _canvas()
    km = stats.ecdf(stats.CensoredData.right_censored(x, c)).cdf
    ax.step(np.concatenate([[0.0], km.quantiles]), np.concatenate([[0.0], km.probabilities]),
            where="post", color="0.45", lw=2.0,
            label=f"Kaplan-Meier ({int((~c).sum())} observed, {int(c.sum())} censored)")
    hi = float(x.max()) * 1.05
    _curves(ax, fits, best, np.linspace(0.0, hi, 600), "cdf")
    ax.set_xlim(0.0, hi)
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("cumulative probability")
    ax.legend(fontsize="small", loc="upper left")
    fig.savefig(out_png, format="png", dpi=100)
