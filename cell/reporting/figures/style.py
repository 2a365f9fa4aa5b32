"""One look for every figure: fonts, colours, the title line and the atomic save.

Figures are built on :class:`matplotlib.figure.Figure` directly, never through
``pyplot``, so nothing needs a display and no global figure state leaks between
them; the Agg canvas renders the PNG.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib as mpl
import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import Collection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.path import Path as MplPath
from matplotlib.text import Annotation, Text
from matplotlib.transforms import Bbox
from numpy.typing import ArrayLike

from cell.plumbing.output.atomic import atomic_path

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
               size: tuple[float, float] = (8.0, 4.8), sharex: bool = False, sharey: bool = False,
               **subplot_kw: Any) -> tuple[Figure, Any]:
    """A figure titled "Figure N. caption" (the thesis's list of illustrations).

    ``sharex``/``sharey``: the panels share that axis (its limits, and the tick labels only
    on the outer panels); ``subplot_kw`` goes to each panel (e.g. ``projection="3d"``)."""
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, sharex=sharex, sharey=sharey, squeeze=True,
                        subplot_kw=subplot_kw or None)
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


# --------------------------------------------------------------------------- labels
def freeze_layout(fig: Figure) -> None:
    """Lay the figure out once and keep it so: labels placed afterwards see final positions."""
    fig.draw_without_rendering()
    fig.set_layout_engine("none")


def display_paths(artist: Artist) -> list[MplPath]:
    """An artist's outline in display pixels: a line's, a step curve's, a collection's lines.
    A 3-D line gives its projection as last drawn."""
    if isinstance(artist, (Line2D, Patch)):
        return [artist.get_transform().transform_path(artist.get_path())]
    if isinstance(artist, Collection):
        tr = artist.get_transform()
        return [tr.transform_path(path) for path in artist.get_paths()]
    raise TypeError(f"no outline for {type(artist).__name__}")


def text_box(text: Text, renderer: Any, pad_px: float = 2.0) -> Bbox:
    """The pixels a text covers (its words, and its frame if it has one), arrows left out."""
    if isinstance(text, Annotation):
        text.update_positions(renderer)
    box = Text.get_window_extent(text, renderer)
    frame = text.get_bbox_patch()
    if frame is not None:
        pad_px += float(text.get_fontsize()) * 0.5 * renderer.points_to_pixels(1.0) + 1.0
    return box.padded(pad_px)


def _set_place(text: Text, where: tuple[float, float]) -> None:
    if isinstance(text, Annotation):
        text.xyann = where
    else:
        text.set_position(where)


@dataclass(frozen=True)
class Label:
    """A text to place and where it may go."""

    text: Text
    candidates: Sequence[tuple[float, float]]
    """Places to try in order: an annotation's text offset, or a plain text's position."""
    x_range: tuple[float, float] | None = None
    """Data x-interval the text's centre must stay within (e.g. its regime), if any."""


def place_clear(ax: Axes, labels: Sequence[Label], avoid: Iterable[Artist],
                avoid_boxes: Iterable[Artist | Bbox] = ()) -> None:
    """Put each label at the first of its candidate places where it lies inside the axes
    (its centre within its x-range) and covers none of ``avoid``'s curves, none of ``avoid_boxes``
    (artists or pixel boxes),
    no label placed before it and none of the axes' other texts; else where it covers
    the fewest.  The figure must be laid out already (:func:`freeze_layout`).
    """
    canvas = ax.get_figure(root=True).canvas  # type: ignore[union-attr]
    assert isinstance(canvas, FigureCanvasAgg), "figures are drawn on an Agg canvas (new_figure)"
    renderer = canvas.get_renderer()
    paths = [path for artist in avoid for path in display_paths(artist)]
    own = {id(label.text) for label in labels}
    taken = [text_box(t, renderer) for t in ax.texts if id(t) not in own and t.get_visible()]
    taken += [a if isinstance(a, Bbox) else a.get_window_extent(renderer) for a in avoid_boxes]
    for label in labels:
        lo, hi = -np.inf, np.inf
        if label.x_range is not None:
            lo, hi = (ax.transData.transform((x, 0.0))[0] for x in label.x_range)
        best, fewest = label.candidates[0], np.inf
        for where in label.candidates:
            _set_place(label.text, where)
            box = text_box(label.text, renderer)
            inside = (box.x0 >= ax.bbox.x0 and box.x1 <= ax.bbox.x1 and lo <= (box.x0 + box.x1) / 2
                      <= hi and box.y0 >= ax.bbox.y0 and box.y1 <= ax.bbox.y1)
            hits = (0 if inside else 100) + sum(p.intersects_bbox(box, filled=False)
                                                for p in paths)
            hits += sum(box.overlaps(other) for other in taken)
            if hits < fewest:
                best, fewest = where, hits
            if hits == 0:
                break
        _set_place(label.text, best)
        taken.append(text_box(label.text, renderer))
