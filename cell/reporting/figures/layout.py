"""The cell and its path: Fig. 8, 9 and 12 (thesis §4.1-4.2, §6.1)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle, FancyArrow, Rectangle
from matplotlib.transforms import Bbox
from mpl_toolkits.mplot3d import proj3d  # type: ignore[import-untyped]

from cell.arm.kinematics import hand_length
from cell.arm.steptable import StepTable
from cell.reporting.figures.style import (
    REGIME_COLOURS,
    REGIME_LABELS,
    Label,
    freeze_layout,
    new_figure,
    place_clear,
    save,
)
from cell.scenario.schema import Scenario
from cell.sim.scenario_values import geometry_of

BELT_COLOUR = "#c8c8c8"


def named_points(s: Scenario, table: StepTable) -> dict[str, np.ndarray]:
    """B, F, G, K (the scenario's) and LO, TD (the path's), global frame (in)."""
    p = table.path
    return {"B": np.asarray(s.path.bot_in), "F": np.asarray(s.path.f_in),
            "G": np.asarray(s.path.g_in), "K": np.asarray(s.path.eot_in),
            "LO": p.xyz_in[p.lo], "TD": p.xyz_in[p.td]}


def _belt_extent(s: Scenario) -> tuple[tuple[float, float], tuple[float, float]]:
    """x-range of the input belt and y-range of the output belt: the windows plus 8 in."""
    xs = (min(s.path.bot_in[0], s.path.f_in[0]) - 10.0, -s.cell.belt_width_in / 2)
    ys = (s.cell.belt_width_in / 2, max(s.path.g_in[1], s.path.eot_in[1]) + 10.0)
    return xs, ys


def fig08_working_environment(s: Scenario, table: StepTable, out: Path) -> Path:
    fig, ax = new_figure(8, "Working Environment", size=(7.4, 7.0))
    w = s.cell.belt_width_in
    (x0, x1), (y0, y1) = _belt_extent(s)
    ax.add_patch(Rectangle((x0, -w / 2), x1 - x0, w, color=BELT_COLOUR, zorder=0))
    ax.add_patch(Rectangle((-w / 2, y0), w, y1 - y0, color=BELT_COLOUR, zorder=0))
    ax.add_patch(FancyArrow(x0 + 1.5, -w / 2 + 0.9, 4.0, 0, width=0.12, color="0.35"))
    ax.text(x0 + 0.5, -w / 2 - 0.4, f"input conveyor: {w:g} in wide, parts move +x at "
            f"{s.belts.input_nominal_in_s:g} in/s (nominal)", fontsize=8.5, color="0.2", va="top")
    ax.add_patch(FancyArrow(w / 2 - 0.9, y1 - 7.0, 0, 4.0, width=0.12, color="0.35"))
    ax.text(-w / 2 - 0.4, y1 - 0.5, f"output conveyor: {w:g} in wide, parts move +y at "
            f"{s.belts.output_nominal_in_s:g} in/s", fontsize=8.5, color="0.2", rotation=90,
            ha="right", va="top")
    bx, by, _ = s.cell.robot_base_in
    ax.add_patch(Circle((bx, by), 1.5, color="0.25", zorder=3))
    ax.text(bx - 2.0, by, f"robot base\naxis ({bx:g}, {by:g})", fontsize=9, ha="right",
            va="center")
    p = table.path
    for reg in (1, 2, 3, 4):
        idx = table.regime_points(reg)
        ax.plot(p.xyz_in[idx, 0], p.xyz_in[idx, 1], color=REGIME_COLOURS[reg], lw=2.4,
                label=f"{REGIME_LABELS[reg]} path", zorder=4)
    offsets = {"B": (-0.6, 0.9), "F": (0.4, 0.9), "G": (0.7, -0.3), "K": (0.7, 0.2),
               "LO": (-0.6, -1.3), "TD": (0.8, -0.3)}
    for name, pt in named_points(s, table).items():
        ax.plot(pt[0], pt[1], "o", color="black", ms=5, zorder=5)
        dx, dy = offsets[name]
        ax.text(pt[0] + dx, pt[1] + dy, f"{name} ({pt[0]:g}, {pt[1]:g})", fontsize=9,
                fontweight="bold", zorder=6)
    ax.set_aspect("equal")
    ax.set_xlim(x0, w / 2 + 2)
    ax.set_ylim(-w / 2 - 2, y1)
    ax.set_xlabel("x, global (in)")
    ax.set_ylabel("y, global (in)")
    ax.legend(loc="upper left", fontsize=9)
    ax.set_title("plan view of the table (z = 0); parts travel +x in, +y out", loc="left",
                 fontsize=9)
    return save(fig, out)


def fig09_path(s: Scenario, table: StepTable, out: Path) -> Path:
    return save(fig09_figure(s, table), out)


def fig09_figure(s: Scenario, table: StepTable) -> Figure:
    """Fig. 9, drawn and laid out (not saved); every name placed where nothing covers it."""
    fig, ax = new_figure(9, "Path Definition for the Robot", size=(8.0, 6.8), projection="3d")
    w = s.cell.belt_width_in
    (x0, x1), (y0, y1) = _belt_extent(s)
    x0, y1 = x0 + 6.0, y1 - 6.0  # a closer crop than the plan view
    for xs, ys in (((x0, x1), (-w / 2, w / 2)), ((-w / 2, w / 2), (y0, y1))):
        gx, gy = np.meshgrid(xs, ys)
        ax.plot_surface(gx, gy, np.zeros_like(gx), color=BELT_COLOUR, alpha=0.45, lw=0)
    bx, by, bz = s.cell.robot_base_in
    top = (bx, by, bz + s.cell.shoulder_height_in)
    curves = ax.plot([bx, bx], [by, by], [bz, top[2]], color="0.25", lw=4)
    p = table.path
    for reg in (1, 2, 3, 4):
        idx = table.regime_points(reg)
        xyz = p.xyz_in[idx]
        curves += ax.plot(xyz[:, 0], xyz[:, 1], xyz[:, 2], color=REGIME_COLOURS[reg], lw=2.6,
                          label=f"{REGIME_LABELS[reg]} ({idx.size - 1} moves, "
                                f"{table.regime_length(reg):.3f} in)")
    named = named_points(s, table)
    for pt in named.values():
        ax.scatter(*pt, color="black", s=14, depthshade=False)
    ax.set_xlabel("x (in)")
    ax.set_ylabel("y (in)")
    ax.set_zlabel("z (in)", labelpad=2)
    ax.set_zlim(0, 8)
    ax.set_xlim(x0, w / 2)
    ax.set_ylim(-w / 2, y1)
    ax.set_box_aspect((w / 2 - x0, y1 + w / 2, 8 * 2.2), zoom=1.0)
    ax.view_init(elev=24, azim=-128)
    ax.legend(loc="upper left", fontsize=8.5)
    _label_points(fig, ax, named, top, curves)
    return fig


#: Text offsets (points) tried for a point's name, nearest first.
AROUND = [(dx, dy) for r in (5, 9, 14) for dx, dy in
          ((r, -r - 6), (r, r - 3), (-r - 12, -r - 6), (-r - 12, r - 3), (r + 2, -4), (-r - 14, -4),
           (-5, r), (-5, -r - 10))]


def _label_points(fig: Figure, ax: Any, named: dict[str, np.ndarray], shoulder: tuple,
                  curves: list) -> None:
    """Name the points in 2-D, each where no curve, point or other name covers it.

    The view is fixed, so each point's projection is computed once the figure is
    laid out; the names are then ordinary annotations of the projected plane.
    """
    freeze_layout(fig)

    def at(xyz: tuple | np.ndarray) -> tuple[float, float]:
        x, y, _ = proj3d.proj_transform(*(np.atleast_1d(float(c)) for c in xyz), ax.get_proj())
        return float(x[0]), float(y[0])

    marks = []
    for pt in named.values():
        cx, cy = ax.transData.transform(at(pt))
        marks.append(Bbox.from_extents(cx - 3, cy - 3, cx + 3, cy + 3))
    labels = [Label(ax.annotate("shoulder", at(shoulder), xytext=(-20, 6),
                                textcoords="offset points", fontsize=8.5, zorder=20),
                    [(-20, 6), (4, 4), (-50, 4)])]
    for name, pt in named.items():
        text = ax.annotate(name, at(pt), xytext=AROUND[0], textcoords="offset points",
                           fontsize=9, fontweight="bold", zorder=20)
        labels.append(Label(text, AROUND))
    place_clear(ax, labels, avoid=curves, avoid_boxes=marks)


def fig12_hand_length(s: Scenario, out: Path) -> Path:
    fig, ax = new_figure(12, "Hand Length Variation versus Hand Opening", size=(7.2, 4.6))
    h = s.robot.hand
    g_max = (h.g0_in + h.l2_in * np.sqrt(2)) * (1 - 1e-12)  # where w11 = L1
    g = np.linspace(0.0, g_max, 400)
    ax.plot(g, hand_length(g, geometry_of(s).hand), color="black",
            label="w11 = L1 + √(L2² − (G − G0)²/2)  (eq. 6.2)")
    marks = {f"G0 = {h.g0_in:g} in (longest)": h.g0_in,
             f"holding a {s.part.size_in:g} in cube": s.part.size_in,
             "open, no part (assumed)": h.open_in}
    for (label, gv), col in zip(marks.items(), ("#2ca02c", "#1f77b4", "#ff7f0e"), strict=True):
        wv = float(hand_length(gv, geometry_of(s).hand))
        ax.plot(gv, wv, "o", color=col, ms=7, label=f"{label}: G = {gv:g}, w11 = {wv:.4f} in")
    ax.set_xlabel("finger opening G (in)")
    ax.set_ylabel("hand length w11 (in)")
    ax.set_xlim(0, g_max * 1.02)
    ax.legend(loc="lower center", fontsize=8.5)
    ax.set_title(f"L1 = {h.l1_in:g} in, L2 = {h.l2_in:g} in, G0 = {h.g0_in:g} in", loc="left",
                 fontsize=9)
    return save(fig, out)
