"""One look for every figure: fonts, colours, the title line and the atomic save.

Figures are built on :class:`matplotlib.figure.Figure` directly, never through
``pyplot``, so nothing needs a display and no global figure state leaks between
them; the Agg canvas renders the PNG.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import matplotlib as mpl
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from cell.output import atomic_path

#: Resolution of the saved PNGs: readable on screen, modest on disk.
DPI = 110

#: rcParams shared by every figure.
RC: dict[str, Any] = {
    "font.size": 10.5,
    "axes.titlesize": 10.5,
    "axes.labelsize": 10.5,
    "figure.titlesize": 13,
    "figure.titleweight": "bold",
    "legend.fontsize": 9,
    "legend.framealpha": 0.9,
    "axes.grid": True,
    "grid.alpha": 0.35,
    "grid.linestyle": ":",
    "axes.spines.top": False,
    "axes.spines.right": False,
    "lines.linewidth": 1.6,
    "savefig.dpi": DPI,
    "figure.dpi": DPI,
}

#: One colour per regime, used wherever a regime is drawn (R I .. R IV).
REGIME_COLOURS = {1: "#1f77b4", 2: "#2ca02c", 3: "#ff7f0e", 4: "#9467bd"}
REGIME_LABELS = {1: "R I", 2: "R II", 3: "R III", 4: "R IV"}
#: The two policies, everywhere they are compared.
POLICY_COLOURS = {"adaptive": "#1f77b4", "non-adaptive": "#d62728"}
IDEAL_COLOUR = "#333333"
LIMIT_COLOUR = "#d62728"


@contextmanager
def style() -> Iterator[None]:
    """Apply the shared rcParams for the figures drawn inside the block."""
    with mpl.rc_context(RC):  # type: ignore[arg-type]
        yield


def new_figure(number: int, caption: str, *, nrows: int = 1, ncols: int = 1,
               size: tuple[float, float] = (8.0, 4.8), **subplot_kw: Any) -> tuple[Figure, Any]:
    """A figure titled "Figure N. caption" (the thesis's list of illustrations)."""
    fig = Figure(figsize=size, layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=True, subplot_kw=subplot_kw or None)
    fig.suptitle(f"Figure {number}. {caption}")
    return fig, axes


def save(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` as PNG through a temporary file renamed into place."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI)
    return path


def shade_regimes(ax: Axes, t_points: ArrayLike, regime: ArrayLike, *, label: bool = True) -> None:
    """Tint the time axis by regime and name each band at the top of ``ax``.

    ``t_points`` are the times at the path points and ``regime[i]`` the regime of
    the move arriving at point i (point 0 belongs to R I).
    """
    t = np.asarray(t_points, dtype=float)
    r = np.asarray(regime)
    for reg in (1, 2, 3, 4):
        idx = np.flatnonzero(r[1:] == reg) + 1
        if idx.size == 0:
            continue
        t0, t1 = t[idx[0] - 1], t[idx[-1]]
        ax.axvspan(t0, t1, color=REGIME_COLOURS[reg], alpha=0.08, lw=0)
        if label:
            ax.text((t0 + t1) / 2, 1.0, REGIME_LABELS[reg], transform=ax.get_xaxis_transform(),
                    ha="center", va="bottom", fontsize=9, color=REGIME_COLOURS[reg],
                    fontweight="bold")


def mark_events(ax: Axes, events: dict[str, float]) -> None:
    """Dotted vertical lines at named instants (LO, TD), labelled at the bottom."""
    for name, when in events.items():
        ax.axvline(when, color="0.3", lw=0.9, ls="--")
        ax.text(when, 0.02, f" {name}", transform=ax.get_xaxis_transform(), fontsize=8.5,
                color="0.25", ha="left", va="bottom")
