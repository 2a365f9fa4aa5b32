"""One adaptive transfer's tool-centre speed: Fig. 22 (thesis §7.1).

The part's six segment times come from its record (the simulation's own
timing); each is spread over its moves as the motors allow (§6.1), on the
joints' travel rather than on whole steps (:func:`~cell.reporting.figures.motion.joint_travel_min_times`):
a motor at its limit runs at one rate, so the tool centre's speed is smooth
where the simulation's whole-step count would alternate 10- and 11-step moves.
Each segment lasts exactly its recorded time, so LO, TD and the cycle are the run's.

Two moves stand out, and are real: in the move onto LO the fingers close on the
part and in the move after TD they open (eq. 6.2): the hand's length changes by
0.113 in within one move and the shoulder, taking it up at its peak rate, makes
that move the slowest of its stretch.  They are marked on the figure.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

from cell.arm.steptable import StepTable
from cell.reporting.figures.motion import Timeline, joint_travel_min_times, record_segments, timeline
from cell.reporting.figures.runs import Run, Runs
from cell.reporting.figures.style import (
    POLICY_COLOURS,
    REGIME_LABELS,
    Label,
    freeze_layout,
    mark_events,
    new_figure,
    place_clear,
    save,
    shade_regimes,
)
from cell.scenario.schema import Scenario
from cell.sim.conveyors import speed_at
from cell.sim.policy_setup import nominal_cycle

#: Offsets (points) tried, in order, for a label next to what it names.
OFFSETS = [(0, 9), (0, -9), (0, 16), (0, -16), (0, 24), (0, -24), (0, 34), (0, -34), (0, 48),
           (0, -48), (0, 64), (0, -64), (0, 82), (0, -82)]
#: Sideways shifts (points) tried at each height.
SHIFTS = (0, -40, 40, -80, 80)


def part_segments(row: pd.Series) -> dict[str, float]:
    """A simulated part's six segment times from its record (:func:`record_segments`)."""
    return record_segments(float(row["at_bot_s"]), float(row["pick_s"]),
                           float(row["touchdown_s"]), [row[f"r{r}_s"] for r in (1, 2, 3, 4)])


def belt_speed_at(history: ArrayLike, when: float) -> float:
    """A belt's speed at an instant, from its rows (instant, speed) in time order: the
    conveyors' own look-up (:func:`cell.sim.conveyors.speed_at`), so a change at that very
    instant already holds.  The run records the input belt's change at LO at the part's
    ``pick_s`` exactly (both are B + the look-ahead lag), so LO needs no nudge."""
    h = np.asarray(history, dtype=float).reshape(-1, 2)
    return float(speed_at(h[:, 0], h[:, 1], float(when)))  # columns as they are: no copy


def pick_transfer(run: Run) -> int:
    """Row of the adaptive part to draw: of the parts whose input belt speeds up at
    LO (the next part is late, step 3.1), the one with the longest lag before it
    may, as in the thesis's example (§7.1)."""
    d = run.parts
    hist = np.asarray(run.belts["input"], dtype=float)  # converted once, not per look-up
    best, lag = 0, -np.inf
    for i in np.flatnonzero(d["picked"].to_numpy(dtype=bool))[1:-1]:
        row = d.iloc[i]
        up = belt_speed_at(hist, row["pick_s"]) - belt_speed_at(hist, row["pick_s"] - 1e-6)
        this = float(row["pick_s"] - row["at_bot_s"])
        if up > 1e-6 and this > lag:
            best, lag = int(i), this
    return best


def transfer_timeline(table: StepTable, row: pd.Series) -> Timeline:
    """The part's cycle move by move: its recorded segment times spread on the joints' travel."""
    return timeline(table, part_segments(row), joint_travel_min_times(table))


def tip_speeds(table: StepTable, tl: Timeline) -> NDArray[np.float64]:
    """(N-1,) tool-centre speed over each move: its length over its time (0 if it has none)."""
    dt = tl.dt_s[1:]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(dt > 0, table.move_in[1:] / dt, 0.0)


def hand_moves(table: StepTable) -> tuple[int, int]:
    """Rows of the move in which the fingers close (onto LO) and open (after TD)."""
    change = np.flatnonzero(np.diff(table.path.opening_in) != 0) + 1
    return int(change[0]), int(change[-1])


def _belt_curve(ax: Axes, run: Run, row: pd.Series,
                tl: Timeline) -> tuple[Artist, float, float, NDArray[np.float64]]:
    """The input belt's speed over the part's cycle, drawn with time 0 at LO: the artist,
    the speeds just before and at LO, and the speeds drawn."""
    hist = run.belts["input"]
    at_b, pick = float(row["at_bot_s"]), float(row["pick_s"])
    before, after = belt_speed_at(hist, pick - 1e-6), belt_speed_at(hist, pick)
    end = at_b + float(tl.t_s[-1])
    changes = [(at_b, before)] + [(w, v) for w, v in hist if at_b < w <= end + 1e-9]
    bt = np.array([w for w, _ in changes] + [end]) - pick
    bv = np.array([v for _, v in changes])
    curve = ax.stairs(bv, bt, baseline=None, color=POLICY_COLOURS["non-adaptive"], lw=1.4,
                      ls="--", label="input belt speed")
    return curve, before, after, bv


def _regime_averages(ax: Axes, table: StepTable, t: NDArray[np.float64], row: pd.Series,
                     curves: list[Artist]) -> dict[int, tuple[float, float]]:
    """Each regime's average tip velocity drawn over its span (appended to ``curves``);
    the spans, by regime."""
    spans = {}
    for r in (1, 2, 3, 4):
        pts = table.regime_points(r)
        spans[r] = (float(t[pts[0]]), float(t[pts[-1]]))
        curves.append(ax.hlines(float(row[f"v_r{r}_in_s"]), *spans[r], colors="0.45",
                                linestyles=":", lw=1.3,
                                label="regime's average tip velocity (velocity state vector)"
                                if r == 1 else None))  # type: ignore[arg-type]  # None: no legend entry
    return spans


def _regime_labels(ax: Axes, row: pd.Series, spans: dict[int, tuple[float, float]]) -> list[Label]:
    """Each regime's average velocity written on its line."""
    labels: list[Label] = []
    for r in (1, 2, 3, 4):
        v = float(row[f"v_r{r}_in_s"])
        lo, hi = spans[r]
        # R I's from LO on, clear of the hatching; the others centred on their regime
        x, ha, dx = (0.0, "left", 3) if r == 1 else ((lo + hi) / 2, "center", 0)
        text = ax.annotate(f"{REGIME_LABELS[r]} {v:.3f}", (x, v), xytext=(dx, 3),
                           textcoords="offset points", fontsize=8, color="0.25", ha=ha,
                           va="center")
        labels.append(Label(text, [(dx + sx, dy) for _, dy in OFFSETS for sx in SHIFTS],
                            (max(lo, 0.0), hi)))
    return labels


def _hand_labels(ax: Axes, table: StepTable, tl: Timeline, t: NDArray[np.float64],
                 tip: NDArray[np.float64]) -> list[Label]:
    """The moves in which the fingers close and open, each pointed at on the tip curve."""
    labels: list[Label] = []
    grasp, release = hand_moves(table)
    for move, what in ((grasp, "fingers close on the part"), (release, "fingers open")):
        mid = float(t[move - 1] + t[move]) / 2
        text = ax.annotate(f"{what}: one move,\n{tl.dt_s[move]:.3f} s at {tip[move - 1]:.2f} in/s",
                           (mid, float(tip[move - 1])), xytext=(8, -8), textcoords="offset points",
                           fontsize=7.5, color="0.2", ha="left", va="top",
                           arrowprops={"arrowstyle": "-", "color": "0.4", "lw": 0.6})
        labels.append(Label(text, [(dx, dy) for dy in (-8, -20, -34, -50, 10, 26)
                                   for dx in (8, 20, -100, 40)]))
    return labels


def _lag_note(ax: Axes, lag: float, before: float) -> Label:
    """The note on the look-ahead lag before LO (§5.3 3.1)."""
    note = ax.annotate(f"◀ look-ahead lag {lag:.4f} s: B → LO at {before:.3f} in/s;\n"
                       f"   the input belt may change only from LO on", (0.0, 0.0),
                       xytext=(6, 0), textcoords="offset points", ha="left", va="bottom", fontsize=8.5,
                       bbox={"fc": "white", "ec": "0.6", "lw": 0.6})
    return Label(note, [(6, dy) for dy in range(250, -1, -10)])


def fig22_figure(runs: Runs, table: StepTable, s: Scenario) -> Figure:
    """Fig. 22, drawn and laid out (not saved)."""
    fig, ax = new_figure(22, "Robot Tip Velocity of a Transfer", size=(9.0, 5.4))
    run = runs.adaptive
    i = pick_transfer(run)
    row = run.parts.iloc[i]
    tl = transfer_timeline(table, row)
    lag = tl.segment_s["r1_pre"]
    t = tl.t_s - lag  # 0 at LO: from here on the input belt may change (§5.3 3.1)
    p = table.path
    shade_regimes(ax, t, p.regime)
    tip = tip_speeds(table, tl)
    curves: list[Artist] = [ax.stairs(tip, t, baseline=None, color="black", lw=1.5,
                                      label="tool-centre speed along the path")]
    belt, before, after, bv = _belt_curve(ax, run, row, tl)
    curves.append(belt)
    spans = _regime_averages(ax, table, t, row, curves)
    lag_box = ax.axvspan(-lag, 0, facecolor="none", hatch="///", edgecolor="0.6", lw=0)
    mark_events(ax, {"LO": 0.0, "TD": float(tl.t_s[p.td] - lag)})
    nxt = (f"next part {float(run.parts['interarrival_s'].iloc[i + 1]):.3f} s behind"
           if i + 1 < len(run.parts) else "the run's last")
    ax.set_title(f"adaptive run, part {int(row['part'])}: {nxt} "
                 f"(ideal {nominal_cycle(s):g} s); input belt {before:.3f} → "
                 f"{after:.3f} in/s at LO; cycle {tl.t_s[-1]:.3f} s", loc="left", fontsize=9,
                 pad=16)
    ax.set_xlabel("time from lift-off LO (s); negative: the look-ahead lag")
    ax.set_ylabel("velocity (in/s)")
    ax.set_xlim(-lag, t[-1])
    ax.set_ylim(0, 1.3 * max(float(tip.max()), float(bv.max())))
    fig.legend(loc="outside lower center", ncols=3, fontsize=8.5)
    freeze_layout(fig)

    labels = _regime_labels(ax, row, spans) + _hand_labels(ax, table, tl, t, tip)
    labels.append(_lag_note(ax, lag, before))
    place_clear(ax, labels, avoid=[*curves, *ax.lines], avoid_boxes=[lag_box])
    return fig


def fig22_tip_velocity(runs: Runs, table: StepTable, s: Scenario, out: Path) -> Path:
    return save(fig22_figure(runs, table, s), out)
