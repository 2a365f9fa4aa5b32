"""The two controllers compared: Fig. 23-30 (thesis §7.2, Table 7.1).

One adaptive run and one non-adaptive run at each of Table 7.1's six robot
cycles, all from the same seed, so every policy sees the same inter-arrival
times (common random numbers).  Each run is simulated once and shared by the
figures that need it.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from numpy.typing import NDArray

from cell.reporting.figures.style import (
    IDEAL_COLOUR,
    POLICY_COLOURS,
    new_figure,
    save,
)
from cell.reporting.published import TABLE_7_1_CYCLES
from cell.reporting.table_7_1.table import fixed_cycle
from cell.scenario.schema import Scenario
from cell.sim.policy_setup import nominal_cycle

#: Parts per lot of Fig. 23's lumped averages (§7.2).
LOT = 10
#: Fig. 25-30 and the non-adaptive robot's cycle each draws (Table 7.1, column 1).
IP_FIGURES: dict[int, float] = dict(zip(range(25, 31), TABLE_7_1_CYCLES, strict=True))


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
    """Keyed by the robot's cycle (Table 7.1, column 1, and the scenario's own)."""
    own_cycle_s: float
    """The scenario's own non-adaptive cycle (:func:`fixed_cycle`), drawn in Fig. 23/24."""

    @property
    def own(self) -> Run:
        """The non-adaptive run at the scenario's own cycle."""
        return self.non_adaptive[self.own_cycle_s]


def missed_cycles(s: Scenario, cycles: tuple[float, ...] = TABLE_7_1_CYCLES
                  ) -> tuple[tuple[float, ...], float]:
    """(the ``cycles`` the non-adaptive robot of ``s`` cannot make, its shortest cycle)."""
    from cell.plumbing.errors import ScenarioError
    from cell.sim.policies.fixed import fixed_plan
    from cell.sim.policy_setup import constants
    from cell.sim.timing_cache import robot_timing

    k = constants(s, robot_timing(s))
    missed = []
    for c in cycles:
        try:
            fixed_plan(k, c)
        except ScenarioError:
            missed.append(c)
    return tuple(missed), k.shortest_cycle_s


def skipped_note(s: Scenario, numbers: Iterable[int]) -> tuple[list[int], str | None]:
    """Which of Fig. ``numbers`` (25-30) cannot be drawn, their Table 7.1 cycles being out of the
    non-adaptive robot's reach, and one line saying so (None: all can): the cycles, the scenario's
    shortest, and the ``--set`` that helps when the nominal cycle is why."""
    wanted = {n: c for n, c in IP_FIGURES.items() if n in set(numbers)}
    if not wanted:
        return [], None
    missed, shortest = missed_cycles(s, tuple(wanted.values()))
    skipped = [n for n, c in wanted.items() if c in missed]
    if not skipped:
        return [], None
    thesis = {"controller.nominal_cycle_s": TABLE_7_1_CYCLES[0]}
    nominal = nominal_cycle(s)
    fix = (f"; its nominal cycle is {nominal:.4f} s: --set controller.nominal_cycle_s="
           f"{TABLE_7_1_CYCLES[0]:g} draws them" if nominal != TABLE_7_1_CYCLES[0]
           and not missed_cycles(s.with_overrides(thesis), missed)[0] else "")
    return skipped, (f"Fig. {', '.join(map(str, skipped))} not drawn: this scenario's non-adaptive "
                     f"robot cannot make Table 7.1's {' and '.join(f'{c:g}' for c in missed)} s "
                     f"cycle{'s' if len(missed) > 1 else ''} (its shortest fixed cycle is "
                     f"{shortest:.4f} s{fix})")


def simulate_runs(s: Scenario, cycles: tuple[float, ...] = TABLE_7_1_CYCLES) -> Runs:
    """The adaptive run and the non-adaptive run at each cycle and at the scenario's own
    (:func:`fixed_cycle`), same seed throughout."""
    from cell.sim.simulation import simulate

    ideal = nominal_cycle(s)
    a = simulate(s.with_overrides({"controller.policy": "adaptive",
                                   "controller.ideal_cycle_s": None}))
    adaptive = Run("adaptive", ideal, a.parts, a.summary.as_dict(), a.belts)
    own = fixed_cycle(s)
    non = {}
    for c in dict.fromkeys((*cycles, own)):
        r = simulate(s.with_overrides({"controller.policy": "non-adaptive",
                                       "controller.ideal_cycle_s": c}))
        non[c] = Run("non-adaptive", c, r.parts, r.summary.as_dict(), r.belts)
    return Runs(adaptive, non, own)


def _sums(v: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Sum and count of the finite values along the last axis (as ``np.nanmean`` sums them)."""
    ok = np.isfinite(v)
    return np.sum(np.where(ok, v, 0.0), axis=-1), np.sum(ok, axis=-1)


def finite_mean(values: Any) -> float | None:
    """Mean of the finite ``values``; None if there is none (no numpy warning, no NaN)."""
    total, count = _sums(np.asarray(values, dtype=float))
    return float(total / count) if count else None


def lot_means(values: pd.Series, lot: int = LOT) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(last part number of each lot, mean of the lot's finite values; NaN if it has none)
    (§7.2).  A last lot of fewer than ``lot`` parts is kept, at its own last part."""
    v = values.to_numpy(dtype=float)
    blocks = np.pad(v, (0, -len(v) % lot), constant_values=np.nan).reshape(-1, lot)
    total, count = _sums(blocks)
    means = np.divide(total, count, out=np.full(len(blocks), np.nan), where=count > 0)
    return np.minimum(np.arange(1, len(blocks) + 1) * lot, len(v)).astype(float), means


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


def _parts(n: int) -> str:
    return f"{n} part" if n == 1 else f"{n} parts"


def who(run: Run, ideal: float) -> str:
    """A run's name in a legend: its policy, and its cycle when that is not the ideal."""
    return run.policy if run.cycle_s == ideal else f"{run.policy} at {run.cycle_s:.4f} s"


def mean_note(run: Run, ideal: float) -> str:
    """Which non-adaptive mean the thesis panel draws, and why the summary's differs."""
    d = run.parts
    total = float(np.nansum(d["thesis_interval_s"]))
    every = int(d["thesis_interval_s"].notna().sum())
    delivered = every - int(d["missed_thesis"].sum())
    drawn = f"{total / every:.3f} s" if every else "no part counted"
    actual = (f"by the {_parts(delivered)}\ndelivered: {run.summary['actual_cycle_thesis_s']:.3f} s"
              if delivered else "by the parts delivered:\nno part delivered, so no actual cycle")
    return (f"{who(run, ideal)}, as the thesis counted:\n"
            f"the mean drawn is over every part,\n"
            f"lost ones (D = T + C) included:\n"
            f"Σ D / {_parts(every)} = {drawn}.\n"
            f"summary.csv's actual cycle divides\n"
            f"the same Σ D {actual} [2].")


def _legend(run: Run, ideal: float, values: pd.Series, lumped: bool) -> str:
    """A run's legend in Fig. 23 (its mean, and how far off the cycle it ran at) or 24."""
    name = who(run, ideal)
    if lumped:
        mean = finite_mean(values)
        if mean is None:
            return f"{name}: no interval to average"
        against = "the ideal" if run.cycle_s == ideal else "its cycle"
        return (f"{name}: mean {mean:.3f} s\n"
                f"({100 * (mean / run.cycle_s - 1):+.1f} % against {against})")
    last = running_mean(values)[-1]
    return f"{name}: after part {len(values)}: " + (
        f"{last:.3f} s" if np.isfinite(last) else "no interval yet")


def _interval_figure(runs: Runs, s: Scenario, number: int, caption: str, lumped: bool,
                     out: Path) -> Path:
    fig, axes = new_figure(number, caption, nrows=2, size=(10.0, 7.4), sharex=True)
    ideal = nominal_cycle(s)
    na = runs.own
    n = len(na.parts)
    short = n % LOT if lumped else 0  # parts in a last, partial lot
    few = n < LOT  # a run shorter than one lot: dots on the curves, the axis one lot wide
    for ax, (what, col, _, _) in zip(axes, ACCOUNTS, strict=True):
        drawn = False
        for run in (na, runs.adaptive):
            values = run.parts[col]
            colour = POLICY_COLOURS[run.policy]
            if lumped:
                x, y = lot_means(values)
                ax.plot(x, y, "o-", ms=3.5, lw=1.3, color=colour,
                        label=_legend(run, ideal, values, lumped))
                if short:
                    ax.plot(x[-1:], y[-1:], "o", ms=3.5, mfc="white", color=colour)
            else:
                y = running_mean(values)
                ax.plot(run.parts["part"], y, color=colour, marker="." if few else "",
                        label=_legend(run, ideal, values, lumped))
            drawn = drawn or bool(np.isfinite(y).any())
        ax.axhline(ideal, color=IDEAL_COLOUR, lw=1.2, ls="--", label=f"ideal cycle {ideal:g} s")
        if na.cycle_s != ideal:
            ax.axhline(na.cycle_s, color=POLICY_COLOURS[na.policy], lw=1.0, ls=":",
                       label=f"non-adaptive's cycle {na.cycle_s:g} s")
        if not drawn:
            ax.text(0.5, 0.5, f"no time between two deliveries in {_parts(n)}: nothing to draw",
                    transform=ax.transAxes, ha="center", va="center", color="0.3",
                    bbox={"fc": "white", "ec": "0.75", "lw": 0.6, "boxstyle": "round,pad=0.4"})
        ax.set_title(what, loc="left", fontsize=9)
        ax.set_ylabel(f"{LOT}-part lot mean (s)" if lumped else "running mean (s)")
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8.5)
    axes[0].text(1.015, 0.0, mean_note(na, ideal), transform=axes[0].transAxes, ha="left",
                 va="bottom", fontsize=8, color="0.15", linespacing=1.3,
                 bbox={"fc": "#f4f4f4", "ec": "0.75", "lw": 0.6, "boxstyle": "round,pad=0.4"})
    last = f"; the last, hollow, holds only {_parts(short)}" if short else ""
    for ax in axes if few else ():
        ax.set_xlim(0.5, LOT + 0.5)
    axes[-1].set_xlabel(f"part number (end of each {LOT}-part lot{last})" if lumped
                        else "part number")
    fig.supylabel("time between parts delivered")
    docs_footer(fig)
    return save(fig, out)


def fig23_lumped(runs: Runs, s: Scenario, out: Path) -> Path:
    return _interval_figure(runs, s, 23, "Time Between Parts Delivered (lumped)", True, out)


def fig24_running(runs: Runs, s: Scenario, out: Path) -> Path:
    return _interval_figure(runs, s, 24, "Time Between Parts Delivered (running)", False, out)


def _mean_ip(ip: NDArray[np.float64]) -> str:
    mean = finite_mean(ip)
    return f"mean IP {mean:.4f}" if mean is not None else "no IP (no part delivered)"


def fig_ip(runs: Runs, cycle: float, number: int, out: Path) -> Path:
    """Fig. 25-30: each part's instantaneous IP (eq. 5.1), missed parts marked.

    A part lost on the wall clock has no delivery and so no IP: it is marked on
    the panel's floor.  In the thesis's bookkeeping a lost part does have an IP,
    T(i+1) / 2(T(i) + C), and is drawn as a triangle at that value.
    """
    ideal = runs.adaptive.cycle_s
    caption = (f"IP-Ideal Cycle Time is {cycle:.4f} sec." if ideal == TABLE_7_1_CYCLES[0] else
               f"IP: non-adaptive at Table 7.1's {cycle:.4f} s, adaptive at the ideal {ideal:.4f} s")
    fig, axes = new_figure(number, caption, nrows=2, size=(10.0, 7.4), sharex=True)
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
                    label=f"{run.policy}: {_mean_ip(ip)}")
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
