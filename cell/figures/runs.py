"""The two controllers compared: Fig. 23-30 (thesis §7.2, Table 7.1).

One adaptive run and one non-adaptive run at each of Table 7.1's six robot
cycles, all from the same seed, so every policy sees the same inter-arrival
times (common random numbers).  Each run is simulated once and shared by the
figures that need it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from cell.assembly import nominal_cycle
from cell.conveyors import speed_at
from cell.figures.motion import Timeline, timeline
from cell.figures.style import (
    IDEAL_COLOUR,
    POLICY_COLOURS,
    REGIME_LABELS,
    mark_events,
    new_figure,
    save,
    shade_regimes,
)
from cell.scenario import Scenario
from cell.steptable import SEGMENTS, StepTable
from cell.thesis import TABLE_7_1_CYCLES

#: Parts per lot of Fig. 23's lumped averages (§7.2).
LOT = 10


@dataclass(frozen=True)
class Run:
    policy: str
    cycle_s: float
    parts: pd.DataFrame
    summary: dict[str, Any]
    belts: dict[str, list[tuple[float, float]]]
    """(instant, speed) of every belt speed change (SimResult.belts)."""


@dataclass(frozen=True)
class Runs:
    adaptive: Run
    non_adaptive: dict[float, Run]
    """Keyed by the robot's cycle (Table 7.1, column 1)."""


def simulate_runs(s: Scenario, cycles: tuple[float, ...] = TABLE_7_1_CYCLES) -> Runs:
    """The adaptive run and the non-adaptive run at each cycle, same seed throughout."""
    from cell.simulation import simulate

    ideal = nominal_cycle(s)
    a = simulate(s.with_overrides({"controller.policy": "adaptive"}))
    adaptive = Run("adaptive", ideal, a.parts, a.summary.as_dict(), a.belts)
    non = {}
    for c in cycles:
        r = simulate(s.with_overrides({"controller.policy": "non-adaptive",
                                       "controller.ideal_cycle_s": c}))
        non[c] = Run("non-adaptive", c, r.parts, r.summary.as_dict(), r.belts)
    return Runs(adaptive, non)


def lot_means(values: pd.Series, lot: int = LOT) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(last part number of each lot, mean of the lot's non-missing values) (§7.2)."""
    v = values.to_numpy(dtype=float)
    n = len(v) // lot * lot
    blocks = v[:n].reshape(-1, lot)
    with np.errstate(invalid="ignore"):
        means = np.nanmean(np.where(np.isfinite(blocks), blocks, np.nan), axis=1)
    return (np.arange(1, len(blocks) + 1) * lot).astype(float), means


def running_mean(values: pd.Series) -> NDArray[np.float64]:
    """Mean of every value so far, missing ones skipped (§7.2, Fig. 24)."""
    v = values.to_numpy(dtype=float)
    ok = np.isfinite(v)
    count = np.cumsum(ok)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, np.cumsum(np.where(ok, v, 0.0)) / count, np.nan)


#: The two accountings, drawn one above the other (SPEC §8): column of each measure.
ACCOUNTS = (
    ("as the thesis counted (adaptive: robot motion time, step 6.2; "
     "non-adaptive: SPEC §8 reconstruction)", "thesis_interval_s", "ip_thesis",
     "missed_thesis"),
    ("on the wall clock (between consecutive set-downs; lost parts have none)",
     "delivery_interval_s", "ip_wallclock", "missed"),
)


def _interval_figure(runs: Runs, s: Scenario, number: int, caption: str, lumped: bool,
                     out: Path) -> Path:
    fig, axes = new_figure(number, caption, nrows=2, size=(10.0, 7.4), sharex=True)
    ideal = nominal_cycle(s)
    na = runs.non_adaptive[TABLE_7_1_CYCLES[0]]
    for ax, (what, col, _, _) in zip(axes, ACCOUNTS, strict=True):
        for run in (na, runs.adaptive):
            values = run.parts[col]
            mean = float(np.nanmean(values))
            if lumped:
                x, y = lot_means(values)
                ax.plot(x, y, "o-", ms=3.5, lw=1.3, color=POLICY_COLOURS[run.policy],
                        label=f"{run.policy}: mean {mean:.3f} s\n"
                              f"({100 * (mean / ideal - 1):+.1f} % against the ideal)")
            else:
                y = running_mean(values)
                ax.plot(run.parts["part"], y, color=POLICY_COLOURS[run.policy],
                        label=f"{run.policy}: after part {len(y)}: {y[-1]:.3f} s")
        ax.axhline(ideal, color=IDEAL_COLOUR, lw=1.2, ls="--", label=f"ideal cycle {ideal:g} s")
        ax.set_title(what, loc="left", fontsize=9)
        ax.set_ylabel(f"{LOT}-part lot mean (s)" if lumped else "running mean (s)")
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8.5)
    axes[-1].set_xlabel(f"part number (end of each {LOT}-part lot)" if lumped else "part number")
    fig.supylabel("time between parts delivered")
    return save(fig, out)


def fig23_lumped(runs: Runs, s: Scenario, out: Path) -> Path:
    return _interval_figure(runs, s, 23, "Time Between Parts Delivered (lumped)", True, out)


def fig24_running(runs: Runs, s: Scenario, out: Path) -> Path:
    return _interval_figure(runs, s, 24, "Time Between Parts Delivered (running)", False, out)


def fig_ip(runs: Runs, cycle: float, number: int, out: Path) -> Path:
    """Fig. 25-30: each part's instantaneous IP (eq. 5.1), missed parts marked.

    A part lost on the wall clock has no delivery and so no IP: it is marked on
    the panel's floor.  In the thesis's bookkeeping a lost part does have an IP,
    T(i+1) / 2(T(i) + C), and is drawn as a triangle at that value.
    """
    fig, axes = new_figure(number, f"IP-Ideal Cycle Time is {cycle:.4f} sec.", nrows=2,
                           size=(10.0, 7.4), sharex=True)
    na = runs.non_adaptive[cycle]
    for ax, (what, _, col, lost_col) in zip(axes, ACCOUNTS, strict=True):
        floor = ax.get_xaxis_transform()
        for run in (runs.adaptive, na):
            d = run.parts
            part = d["part"].to_numpy()
            ip = d[col].to_numpy(dtype=float)
            lost = d[lost_col].to_numpy(dtype=bool)
            colour = POLICY_COLOURS[run.policy]
            ok = ~lost & np.isfinite(ip)
            ax.plot(part[ok], ip[ok], ".", ms=4, color=colour,
                    label=f"{run.policy}: mean IP {np.nanmean(ip):.4f}")
            if not lost.any():
                continue
            shown = lost & np.isfinite(ip)
            if shown.any():
                ax.plot(part[shown], ip[shown], "v", ms=5, mfc="none", color=colour,
                        label=f"{run.policy}: part missed ({int(shown.sum())})")
            hidden = lost & ~np.isfinite(ip)
            if hidden.any():
                ax.plot(part[hidden], np.full(hidden.sum(), 0.025), "v", ms=5, mfc="none",
                        color=colour, transform=floor, clip_on=False,
                        label=f"{run.policy}: part missed ({int(hidden.sum())}),\n"
                              "no delivery so no IP: marked on the floor")
        ax.axhline(1.0, color=IDEAL_COLOUR, lw=1.0, ls="--", label="IP = 1")
        ax.set_ylabel("instantaneous IP (–)")
        ax.set_title(what, loc="left", fontsize=9)
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8.5)
    axes[-1].set_xlabel("part number")
    return save(fig, out)


# --------------------------------------------------------------------------- Fig. 22
def part_segments(row: pd.Series) -> dict[str, float]:
    """A simulated part's six segment times from its record: each regime's time, split
    at lift-off (``pick_s``) in R I and at touch-down in R III."""
    start = float(row["at_bot_s"])
    r1_pre = float(row["pick_s"]) - start
    r3_pre = float(row["touchdown_s"]) - start - float(row["r1_s"]) - float(row["r2_s"])
    seg = {"r1_pre": r1_pre, "r1_post": float(row["r1_s"]) - r1_pre, "r2": float(row["r2_s"]),
           "r3_pre": r3_pre, "r3_post": float(row["r3_s"]) - r3_pre, "r4": float(row["r4_s"])}
    return {k: seg[k] for k in SEGMENTS}


def belt_speed_at(history: list[tuple[float, float]], when: float) -> float:
    """Speed of a belt at an instant, from its (instant, speed) changes."""
    return speed_at([t for t, _ in history], [v for _, v in history], when + 1e-9)


def pick_transfer(run: Run) -> int:
    """Row of the adaptive part to draw: of the parts whose input belt speeds up at
    LO (the next part is late, step 3.1), the one with the longest lag before it
    may, as in the thesis's example (§7.1)."""
    d = run.parts
    hist = run.belts["input"]
    best, lag = 0, -np.inf
    for i in np.flatnonzero(d["picked"].to_numpy(dtype=bool))[1:-1]:
        row = d.iloc[i]
        up = belt_speed_at(hist, row["pick_s"]) - belt_speed_at(hist, row["pick_s"] - 1e-6)
        this = float(row["pick_s"] - row["at_bot_s"])
        if up > 1e-6 and this > lag:
            best, lag = int(i), this
    return best


def fig22_tip_velocity(runs: Runs, table: StepTable, s: Scenario, out: Path) -> Path:
    fig, ax = new_figure(22, "Robot Tip Velocity of a Transfer", size=(9.0, 5.2))
    run = runs.adaptive
    i = pick_transfer(run)
    row = run.parts.iloc[i]
    tl: Timeline = timeline(table, part_segments(row))
    lag = tl.segment_s["r1_pre"]
    t = tl.t_s - lag  # 0 at LO: from here on the input belt may change (§5.3 3.1)
    p = table.path
    shade_regimes(ax, t, p.regime)
    with np.errstate(invalid="ignore", divide="ignore"):
        tip = np.where(tl.dt_s[1:] > 0, p.move_in[1:] / tl.dt_s[1:], 0.0)
    ax.stairs(tip, t, baseline=None, color="black", lw=1.5, label="tool-centre speed along the path")
    for r in (1, 2, 3, 4):
        rows = table.regime_rows(r)
        v = float(row[f"v_r{r}_in_s"])
        ax.hlines(v, t[np.flatnonzero(rows)[0] - 1], t[np.flatnonzero(rows)[-1]],
                  colors="0.45", linestyles=":", lw=1.3,
                  label="regime's average tip velocity (velocity state vector)" if r == 1 else None)
        ax.text(t[np.flatnonzero(rows)[-1]], v, f"{REGIME_LABELS[r]} {v:.3f} ", fontsize=8,
                color="0.3", ha="right", va="bottom")
    hist = run.belts["input"]
    at_b, pick = float(row["at_bot_s"]), float(row["pick_s"])
    before, after = belt_speed_at(hist, pick - 1e-6), belt_speed_at(hist, pick)
    end = at_b + float(tl.t_s[-1])
    changes = [(at_b, before)] + [(w, v) for w, v in hist if at_b < w <= end + 1e-9]
    bt = np.array([w for w, _ in changes] + [end]) - pick
    bv = np.array([v for _, v in changes])
    ax.stairs(bv, bt, baseline=None, color=POLICY_COLOURS["non-adaptive"], lw=1.4, ls="--",
              label="input belt speed")
    ax.axvspan(-lag, 0, facecolor="none", hatch="///", edgecolor="0.6", lw=0)
    ax.annotate(f"◀ look-ahead lag {lag:.4f} s: B → LO at {before:.3f} in/s;\n"
                f"   the input belt may change only from LO on",
                xy=(0.15, 0.97), xycoords=("data", "axes fraction"), ha="left", va="top",
                fontsize=8.5, bbox={"fc": "white", "ec": "0.6", "lw": 0.6})
    mark_events(ax, {"LO": 0.0, "TD": float(tl.t_s[p.td] - lag)})
    nxt = float(run.parts["interarrival_s"].iloc[i + 1]) if i + 1 < len(run.parts) else np.nan
    ax.set_title(f"adaptive run, part {int(row['part'])}: next part {nxt:.3f} s behind "
                 f"(ideal {nominal_cycle(s):g} s); input belt {before:.3f} → "
                 f"{after:.3f} in/s at LO; cycle {tl.t_s[-1]:.3f} s", loc="left", fontsize=9,
                 pad=16)
    ax.set_xlabel("time from lift-off LO (s); negative: the look-ahead lag")
    ax.set_ylabel("velocity (in/s)")
    ax.set_xlim(-lag, t[-1])
    ax.set_ylim(0, 1.3 * max(float(tip.max()), float(bv.max())))
    fig.legend(loc="outside lower center", ncols=3, fontsize=8.5)
    return save(fig, out)
