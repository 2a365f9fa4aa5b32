"""Drawing the scene frame by frame, and writing the GIF or MP4.

The cell is seen from above as in Fig. 8 (§4.1): a close-up of the robot and
both tracking windows, and under it each belt whole as a strip (the input belt
from the feeder's drop point to its end at F; the output belt unrolled from its
edge past two part spacings, with the distance between neighbours).  The static
drawing is rendered once; each frame restores it and draws only what moves.
Nothing here computes a position: :mod:`cell.reporting.animation.scene` does.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PolyCollection
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Rectangle
from matplotlib.text import Text

from cell.plumbing.errors import one_line, shown_path
from cell.reporting.animation.scene import (
    CLOSE_X,
    CLOSE_Y,
    FALLING,
    INPUT,
    OUTPUT,
    Floats,
    Scene,
    counts_at,
    parts_at,
    robot_at,
    shown_between,
)
from cell.reporting.animation.stops import mark_stops
from cell.reporting.animation.writers import CanvasGifWriter, Mp4Writer
from cell.reporting.figures.layout import BELT_COLOUR, named_points
from cell.reporting.figures.style import LIMIT_COLOUR, POLICY_COLOURS, REGIME_COLOURS, REGIME_LABELS, style
from cell.reporting.figures.tip import belt_speed_at

PART_COLOUR = "#d9a441"
PART_EDGE = "#5c4510"
LOST_COLOUR = LIMIT_COLOUR
IDLE_COLOUR = "0.45"
#: Figure height and one column's width (in); the layout below is in inches too.
HEIGHT_IN, COLUMN_IN = 7.0, 5.5
CLOSE_IN, STRIP_IN, GAP_IN = 4.55, 0.55, 0.36
#: A strip spans at most this many belt widths across, and a part on it is drawn at least this
#: fraction of its length wide: a long belt (a far drop point) stays visible, squares stretched.
STRIP_MAX_BELTS, STRIP_MIN_PART = 3.0, 1 / 250

POLICY_TITLES = {"adaptive": "adaptive controller (§5.3)",
                 "non-adaptive": "fixed cycle, not adaptive (§6.3)"}
#: A part's number is drawn at most this size (pt), and smaller if it is wider than this
#: fraction of its square, down to this size (pt, and a pixel: at a very low --dpi nothing fits).
LABEL_PT, LABEL_FILL, LABEL_MIN_PT = 6.0, 0.95, 1.5


def header(scene: Scene) -> str:
    """What a panel shows, under its title: the scenario, the seed, a fixed robot's cycle."""
    s = scene.scenario
    line = f"{one_line(s.name, 40)} · seed {s.run.seed}"
    line += f" · fixed cycle {scene.data.cycle_s:.4f} s" if scene.data.policy == "non-adaptive" else ""
    return line + (f" · station {scene.data.station}" if scene.data.station else "")  # a line's


def clock(t: float) -> str:
    """The frame's instant: seconds, or h:mm:ss.s from an hour on."""
    if t < 3600:
        return f"t = {t:6.1f} s"
    minutes, seconds = divmod(round(t, 1), 60)
    hours, minutes = divmod(int(minutes), 60)
    return f"t = {hours}:{minutes:02d}:{seconds:04.1f}"


def fitted(label: Text, width_px: float, renderer: Any) -> Text:
    """``label`` made smaller until it is at most ``width_px`` wide, as drawn (small glyphs are
    whole pixels wide, so the width steps with the size: it is measured, not estimated)."""
    least = max(LABEL_MIN_PT, 72 / renderer.dpi)  # a glyph under a pixel cannot be drawn
    for _ in range(10):
        width, size = label.get_window_extent(renderer).width, float(label.get_fontsize())
        if width <= width_px or size <= least:
            break
        label.set_fontsize(max(least, size * max(0.5, 0.97 * width_px / width)))
    return label


def _square(xy: Floats, angle: Floats, size: float) -> Floats:
    """(n, 4, 2) corners of squares of side ``size`` centred at xy, turned by angle."""
    h = size / 2
    corners = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    x = xy[:, None, 0] + c * corners[:, 0] - s * corners[:, 1]
    y = xy[:, None, 1] + s * corners[:, 0] + c * corners[:, 1]
    return np.stack([x, y], axis=-1)


@dataclass
class Panel:
    """The moving artists of one run's column."""

    scene: Scene
    parts: PolyCollection
    """Parts in the close-up."""
    parts_in: PolyCollection
    parts_out: PolyCollection
    labels: dict[int, Text]
    """Part numbers in the close-up, by part index: the parts the frames can show."""
    arm: list[Line2D]
    """Upper arm, forearm with the hand, fingers."""
    texts: dict[str, Text]
    gaps: list[Text]
    """Distances between neighbours on the output belt."""
    in_stretch: float = 1.0
    """How much wider than they are parts are drawn on the input strip (see STRIP_MIN_PART)."""

    def artists(self) -> list[Artist]:
        """Everything that moves, in drawing order."""
        moving: list[Artist] = [self.parts_in, self.parts_out, *self.gaps, self.parts,
                                *self.labels.values(), *self.arm, *self.texts.values()]
        return sorted(moving, key=lambda a: a.get_zorder())


def _axes(fig: Figure, left: float, bottom: float, width: float, height: float) -> Axes:
    w, h = fig.get_size_inches()
    return fig.add_axes((left / w, bottom / h, width / w, height / h))


def _strip(ax: Axes, x0: float, x1: float, w: float, width_in: float,
           marks: dict[str, float], title: str, title_x: float, ha: str) -> None:
    """A belt drawn whole along x, squares kept square (equal aspect by the limits) unless the
    belt would then be thinner than a third of the strip (:func:`strip_span`)."""
    y0 = -w / 2 - 1.0
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y0 + strip_span(x1 - x0, w, width_in))
    ax.add_patch(Rectangle((x0, -w / 2), x1 - x0, w, color=BELT_COLOUR, zorder=0))
    for name, x in marks.items():
        ax.plot([x, x], [-w / 2, w / 2 + 0.4], color="0.3", lw=0.6, zorder=1)
        ax.text(x, w / 2 + 0.5, name, fontsize=6.5, ha="center", va="bottom", color="0.25")
    ax.text(title_x, w / 2 + 0.5, title, fontsize=7, ha=ha, va="bottom", color="0.15")
    ax.set_yticks([])
    ax.tick_params(labelsize=6.5, pad=1, length=2)
    ax.grid(False)
    for side in ("left", "right", "top"):
        ax.spines[side].set_visible(False)


def strip_span(length_in: float, w: float, width_in: float) -> float:
    """The y-span (in) of a strip ``width_in`` wide showing ``length_in`` of a belt ``w`` wide:
    equal aspect, or at most STRIP_MAX_BELTS belt widths."""
    return min(length_in * STRIP_IN / width_in, STRIP_MAX_BELTS * w)


def stretch(verts: Floats, factor: float) -> Floats:
    """(n, 4, 2) corners widened along x by ``factor`` about each square's centre."""
    if factor == 1.0:
        return verts
    centre = verts[:, :, 0].mean(axis=1, keepdims=True)
    out = verts.copy()
    out[:, :, 0] = centre + (verts[:, :, 0] - centre) * factor
    return out


def _parts_collection(linewidth: float, zorder: float) -> PolyCollection:
    """Squares for parts, drawn alike however many there are: the line width is given per
    square (twice the same) so that matplotlib never takes its one-path shortcut, which lets
    a lone square show a pixel past the axes' edge."""
    return PolyCollection([], edgecolors=PART_EDGE, linewidths=[linewidth, linewidth],
                          zorder=zorder)


def _panel(fig: Figure, left_in: float, column_in: float, scene: Scene,
           span: tuple[float, float] | None) -> Panel:
    """One run's column: title, header, the close-up and the belt strips, and what moves."""
    policy = scene.data.policy
    centre = (left_in + column_in / 2) / fig.get_size_inches()[0]
    fig.text(centre, 1 - 0.13 / HEIGHT_IN, POLICY_TITLES.get(policy, policy), ha="center",
             va="center", fontsize=11, fontweight="bold", color=POLICY_COLOURS.get(policy, "black"))
    fig.text(centre, 1 - 0.32 / HEIGHT_IN, header(scene), ha="center", va="center", fontsize=7.5,
             color="0.25")
    close_bottom = HEIGHT_IN - 0.42 - CLOSE_IN
    close = _axes(fig, left_in + (column_in - CLOSE_IN) / 2 + 0.12, close_bottom, CLOSE_IN, CLOSE_IN)
    strip_w = column_in - 0.45
    in_bottom = close_bottom - GAP_IN - STRIP_IN
    strip_in = _axes(fig, left_in + 0.25, in_bottom, strip_w, STRIP_IN)
    strip_out = _axes(fig, left_in + 0.25, in_bottom - GAP_IN - STRIP_IN, strip_w, STRIP_IN)
    arm, parts, labels, texts = _close_up(fig, close, scene, span)
    parts_in, parts_out, gaps, in_stretch = _strips(strip_in, strip_out, scene, strip_w)
    return Panel(scene, parts, parts_in, parts_out, labels, arm, texts, gaps, in_stretch)


def _close_up(fig: Figure, close: Axes, scene: Scene, span: tuple[float, float] | None
              ) -> tuple[list[Any], PolyCollection, dict[int, Any], dict[str, Any]]:
    """The close-up, Fig. 8's plan view, and what moves in it: the arm's three lines, the
    parts, their labels (the parts shown in ``span``) and the clock, tally and state texts."""
    s, p = scene.scenario, scene.table.path
    w = s.cell.belt_width_in
    b, f = scene.b_xy, scene.f_xy
    close.add_patch(Rectangle((CLOSE_X[0] - 1, b[1] - w / 2), f[0] - CLOSE_X[0] + 1, w,
                              color=BELT_COLOUR, zorder=0))
    close.add_patch(Rectangle((scene.td_xy[0] - w / 2, w / 2), w, CLOSE_Y[1] + 1 - w / 2,
                              color=BELT_COLOUR, zorder=0))
    for reg in (1, 2, 3, 4):
        idx = scene.table.regime_points(reg)
        close.plot(p.xyz_in[idx, 0], p.xyz_in[idx, 1], color=REGIME_COLOURS[reg], lw=0.9,
                   alpha=0.5, zorder=1)
    for name, (x, y, _) in named_points(s, scene.table).items():
        close.plot(x, y, "+", color="0.25", ms=5, mew=0.9, zorder=2)
        close.annotate(name, (x, y), xytext=(3, -9), textcoords="offset points", fontsize=7,
                       color="0.25", zorder=2)
    bx, by, _ = s.cell.robot_base_in
    close.add_patch(Circle((bx, by), 1.3, color="0.25", zorder=5))
    close.set_xlim(*CLOSE_X)
    close.set_ylim(*CLOSE_Y)
    close.set_aspect("equal")
    close.tick_params(labelsize=6.5, pad=1, length=2)
    close.grid(False)
    close.text(0.99, 0.01, "x, y (in)", transform=close.transAxes, fontsize=6.5, ha="right",
               va="bottom", color="0.4")
    arm = [close.plot([], [], "-", lw=5.5, solid_capstyle="round", zorder=6)[0],
           close.plot([], [], "o-", lw=3.5, ms=4.5, solid_capstyle="round", zorder=6)[0],
           close.plot([], [], "-", lw=2.2, color="0.1", solid_capstyle="butt", zorder=7)[0]]
    parts = _parts_collection(0.6, 4)
    close.add_collection(parts)
    shown = range(len(scene.data.part)) if span is None else shown_between(scene, *span)
    side_px = s.part.size_in * CLOSE_IN / (CLOSE_X[1] - CLOSE_X[0]) * fig.dpi
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    labels = {int(i): fitted(close.text(0, 0, str(scene.data.part[i]), fontsize=LABEL_PT,
                                        ha="center", va="center", zorder=4.5, clip_on=True),
                             LABEL_FILL * side_px, renderer) for i in shown}
    mono: dict[str, Any] = {"transform": close.transAxes, "fontsize": 8, "va": "top", "ha": "left",
            "family": "monospace", "zorder": 8}
    texts = {"clock": close.text(0.02, 0.985, "", fontweight="bold", **mono),
             "tally": close.text(0.02, 0.94, "", **mono),
             "lost": close.text(0.02, 0.895, "", **mono),
             "belts": close.text(0.02, 0.845, "", **mono),
             "robot": close.text(0.02, 0.755, "", fontweight="bold", **mono)}
    return arm, parts, labels, texts


def _strips(strip_in: Axes, strip_out: Axes, scene: Scene, strip_w: float
            ) -> tuple[PolyCollection, PolyCollection, list[Any], float]:
    """The whole input belt, drop point to F (the close-up's stretch dotted), and the output
    belt unrolled along its y: parts, gap labels and the input strip's parts' stretch."""
    s, b, f = scene.scenario, scene.b_xy, scene.f_xy
    w = s.cell.belt_width_in
    drop = b[0] - scene.data.input_length_in
    x0, x1 = drop - 3, f[0] + 3
    _strip(strip_in, x0, x1, w, strip_w, {"drop": drop, "B": b[0], "F": f[0]},
           "input belt, drop point → F (falls off at F)", (drop + b[0]) / 2, "center")
    strip_in.add_patch(Rectangle((CLOSE_X[0], -w / 2), f[0] - CLOSE_X[0], w, fill=False, ec="0.45",
                                 lw=0.6, ls=":", zorder=1))
    parts_in = _parts_collection(0.4, 2)
    strip_in.add_collection(parts_in)
    y_end = scene.output_end_y
    _strip(strip_out, w / 2, y_end, w, strip_w, {"TD": scene.td_xy[1], "K": s.path.eot_in[1]},
           "output belt, unrolled (y) →", y_end, "right")
    parts_out = _parts_collection(0.4, 2)
    strip_out.add_collection(parts_out)
    gaps = [strip_out.text(0, 0, "", fontsize=6.5, ha="center", va="center", color="0.1",
                           clip_on=True, zorder=3) for _ in range(4)]
    in_stretch = max(1.0, STRIP_MIN_PART * (x1 - x0) / s.part.size_in)
    return parts_in, parts_out, gaps, in_stretch


def _figure_in(columns: int) -> tuple[float, float]:
    """Width and height of the figure (in) for one or more runs side by side."""
    return (COLUMN_IN if columns > 1 else COLUMN_IN + 0.5) * columns, HEIGHT_IN


def frame_pixels(columns: int, dpi: float) -> int:
    """Pixels in one frame."""
    w, h = _figure_in(columns)
    return round(w * dpi) * round(h * dpi)


def build_figure(scenes: list[Scene], dpi: float, span: tuple[float, float] | None = None
                 ) -> tuple[Figure, list[Panel]]:
    """The figure, on an Agg canvas, and one :class:`Panel` per run, side by side.

    ``span``: the first and last frame's instants; only the parts in the scene between them
    get a label (a window deep into a long run labels a few parts, not every one)."""
    size = _figure_in(len(scenes))
    column = size[0] / len(scenes)
    fig = Figure(figsize=size, dpi=dpi)
    FigureCanvasAgg(fig)
    panels = [_panel(fig, i * column, column, sc, span) for i, sc in enumerate(scenes)]
    return fig, panels


def draw_frame(panel: Panel, t: float) -> None:
    """Move every artist of ``panel`` to instant t."""
    sc = panel.scene
    d = sc.data
    size = sc.scenario.part.size_in
    robot = robot_at(sc, t)  # once a frame: the arm, and where a part in its hand is
    state, pose = robot
    at = parts_at(sc, t, robot)
    falling = at.where == FALLING
    face = np.tile(np.array(to_rgba(PART_COLOUR)), (len(d.part), 1))
    edge = np.tile(np.array(to_rgba(PART_EDGE)), (len(d.part), 1))
    face[falling] = edge[falling] = to_rgba(LOST_COLOUR)
    face[:, 3] = edge[:, 3] = at.alpha
    corners = _square(np.nan_to_num(at.xy), at.angle_rad, size)

    def show(collection: PolyCollection, rows: Any, verts: Floats) -> None:
        collection.set_verts(list(verts))
        collection.set_facecolor(face[rows])
        collection.set_edgecolor(edge[rows])

    shown = at.where > 0
    show(panel.parts, shown, corners[shown])
    for i, label in panel.labels.items():
        label.set_visible(bool(shown[i] and not falling[i]))
        if shown[i]:
            label.set_position(at.xy[i])
    on_in = (at.where == INPUT) | falling
    show(panel.parts_in, on_in, stretch(corners[on_in], panel.in_stretch))
    on_out = at.where == OUTPUT
    y_out = at.xy[on_out, 1]
    show(panel.parts_out, on_out,
         _square(np.column_stack([y_out, np.zeros_like(y_out)]), np.zeros(len(y_out)), size))
    ys = np.sort(y_out[y_out + size / 2 <= sc.output_end_y])  # gaps only on the strip
    for k, gap in enumerate(panel.gaps):
        gap.set_visible(k + 1 < len(ys))
        if k + 1 < len(ys):
            gap.set_position(((ys[k] + ys[k + 1]) / 2, sc.td_xy[0]))
            gap.set_text(f"{ys[k + 1] - ys[k]:.2f} in")
    j = pose.joints[0]
    reg = int(state.regime[0])
    colour = REGIME_COLOURS.get(reg, IDLE_COLOUR)
    upper, fore, fingers = panel.arm
    upper.set_data(j[:2, 0], j[:2, 1])
    fore.set_data(j[1:, 0], j[1:, 1])
    upper.set_color(colour)
    fore.set_color(colour)
    fingers.set_data(pose.fingers[0, :, 0], pose.fingers[0, :, 1])
    n = counts_at(sc, t)
    texts = panel.texts
    texts["clock"].set_text(clock(t))
    texts["tally"].set_text(f"arrived {n.arrived:3d}   delivered {n.delivered:3d}")
    texts["lost"].set_text(f"lost {n.lost:3d} (fell off at F)")
    texts["lost"].set_color(LOST_COLOUR if n.lost else "black")
    v_in, v_out = belt_speed_at(d.input_belt, t), belt_speed_at(d.output_belt, t)
    texts["belts"].set_text(f"input belt  {v_in:5.2f} in/s\noutput belt {v_out:5.2f} in/s")
    texts["robot"].set_text(f"robot: {REGIME_LABELS[reg]}, part {d.part[state.part[0]]}" if reg
                            else "robot: waiting at B")
    texts["robot"].set_color(colour)
    mark_stops(sc.stopped_at(t), texts, (upper, fore))


def render(scenes: list[Scene], times: Floats, out: Path, *, fps: int, dpi: float,
           progress: bool = True, target: Path | None = None) -> None:
    """Draw one frame per instant of ``times`` into ``out``, as a GIF or an MP4 by the suffix
    of ``target`` (the file ``out`` is to become, which errors name; default ``out``).

    ``out`` is written as given; making it atomic is the caller's business.  Stopped
    half-way (Ctrl-C, an error), the writer is abandoned: ffmpeg is stopped, not waited on.
    """
    from cell.plumbing.progress import progress as counted

    target = out if target is None else target
    gif = target.suffix.lower() == ".gif"
    with style():
        fig, panels = build_figure(scenes, dpi, (float(times[0]), float(times[-1])))
        canvas = fig.canvas
        assert isinstance(canvas, FigureCanvasAgg)
        moving = [a for panel in panels for a in panel.artists()]
        for a in moving:
            a.set_visible(False)
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
        for a in moving:
            a.set_visible(True)
        writer = CanvasGifWriter(fps=fps) if gif else Mp4Writer(fps, shown_path(target))
        label = " | ".join(sc.data.policy for sc in scenes)
        with writer.saving(fig, str(out), dpi):
            try:
                for t in counted(times, f"cell animate ({label})", "frames", file=sys.stderr,
                                 enabled=progress):
                    for panel in panels:
                        draw_frame(panel, float(t))
                    if gif:  # ffmpeg's writer redraws the whole figure itself
                        canvas.restore_region(background)
                        for a in moving:
                            if a.get_visible():  # most parts' labels are hidden in any frame
                                fig.draw_artist(a)
                    writer.grab_frame()
            except BaseException:
                writer.abandon()
                raise
