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
from matplotlib.figure import Figure
from numpy.typing import NDArray

from cell.assembly import nominal_cycle
from cell.figures.style import (
    IDEAL_COLOUR,
    POLICY_COLOURS,
    new_figure,
    save,
)
from cell.scenario import Scenario
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


def _shortest_missed(s: Scenario, cycles: tuple[float, ...]) -> tuple[float, float] | None:
    """(the first of ``cycles`` the non-adaptive robot cannot make, its shortest cycle), or None."""
    from cell.assembly import constants, robot_timing
    from cell.errors import ScenarioError
    from cell.policies.fixed import fixed_plan

    k = constants(s, robot_timing(s))
    for c in cycles:
        try:
            fixed_plan(k, c)
        except ScenarioError:
            return c, k.shortest_cycle_s
    return None


def check_cycles(s: Scenario, cycles: tuple[float, ...] = TABLE_7_1_CYCLES) -> None:
    """Refuse, before anything is drawn, a scenario whose non-adaptive robot cannot make one of
    ``cycles`` (Fig. 22-30 run it at each): one line naming the scenario, the cycle, its shortest,
    and the ``--set`` that helps when the nominal cycle (by default the arrivals' mean) is why."""
    from cell.errors import ScenarioError

    missed = _shortest_missed(s, cycles)
    if missed is None:
        return
    thesis = {"controller.nominal_cycle_s": cycles[0]}
    nominal = nominal_cycle(s)
    fix = (f" (its nominal cycle is {nominal:.4f} s: --set controller.nominal_cycle_s="
           f"{cycles[0]:g} draws them)" if nominal != cycles[0]
           and _shortest_missed(s.with_overrides(thesis), cycles) is None else "")
    raise ScenarioError(s.source, "(figures)", f"{missed[0]:g} s",
                        f"Fig. 22-30 run the non-adaptive robot at Table 7.1's cycles "
                        f"({', '.join(f'{x:g}' for x in cycles)} s), and this scenario's shortest "
                        f"is {missed[1]:.4f} s{fix}")


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


#: Where each accounting is defined (``docs/accounting.md``, by its GitHub anchors).
DOCS = {"adaptive": "docs/accounting.md#the-adaptive-robot-in-the-thesiss-bookkeeping",
        "non-adaptive": "docs/accounting.md#the-non-adaptive-robot-in-the-thesiss-bookkeeping"
                        "-a-reconstruction-of-table-71",
        "wallclock": "docs/accounting.md#on-the-wall-clock"}

#: The two accountings, drawn one above the other: panel title, column of each measure.
ACCOUNTS = (
    ("as the thesis counted: adaptive, the robot's motion time between set-downs (step 6.2) [1]; "
     "non-adaptive, the bookkeeping\nthat reproduces Table 7.1: a part lost when its "
     "inter-arrival time is shorter than the cycle, and booked as one more cycle (D = T + C) [2]",
     "thesis_interval_s", "ip_thesis", "missed_thesis"),
    ("on the wall clock: between consecutive set-downs on the output belt; "
     "a lost part has none [3]", "delivery_interval_s", "ip_wallclock", "missed"),
)


def docs_footer(fig: Figure) -> None:
    """The references [1]-[3] of the panel titles, under the figure."""
    fig.supxlabel(f"[1] {DOCS['adaptive']}   [3] {DOCS['wallclock']}\n[2] {DOCS['non-adaptive']}",
                  x=0.01, ha="left", fontsize=7.5, color="0.3")


def mean_note(run: Run) -> str:
    """Which non-adaptive mean the thesis panel draws, and why the summary's differs."""
    d = run.parts
    total = float(np.nansum(d["thesis_interval_s"]))
    every = int(d["thesis_interval_s"].notna().sum())
    delivered = every - int(d["missed_thesis"].sum())
    return (f"non-adaptive, as the thesis counted:\n"
            f"the mean drawn is over every part,\n"
            f"lost ones (D = T + C) included:\n"
            f"Σ D / {every} parts = {total / every:.3f} s.\n"
            f"summary.csv's actual cycle divides\n"
            f"the same Σ D by the {delivered} parts\n"
            f"delivered: {run.summary['actual_cycle_thesis_s']:.3f} s [2].")


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
    axes[0].text(1.015, 0.0, mean_note(na), transform=axes[0].transAxes, ha="left", va="bottom",
                 fontsize=8, color="0.15", linespacing=1.3,
                 bbox={"fc": "#f4f4f4", "ec": "0.75", "lw": 0.6, "boxstyle": "round,pad=0.4"})
    axes[-1].set_xlabel(f"part number (end of each {LOT}-part lot)" if lumped else "part number")
    fig.supylabel("time between parts delivered")
    docs_footer(fig)
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
    docs_footer(fig)
    return save(fig, out)
