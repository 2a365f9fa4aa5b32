"""``cell compare``'s verdict when A and B are not fed alike, or one of them does not vary.

Parts per hour and the per-run counts grow with the demand: a scenario whose parts arrive
faster delivers more of them per hour without being the better cell.  When the two arrival
rates differ the verdict says so and judges on measures free of the rate:

- service level: parts delivered / parts arrived (higher is better);
- parts lost per 100 arrivals (lower is better);
- spacings off per 100 parts delivered (lower is better);

each a paired difference, replication by replication (common random numbers), as the
headline measures are (:func:`cell.experiments.stats.paired_difference`).  A side that gives
the same figures in every replication (a trace, say) leaves the paired interval resting on
the other side's variation alone: said in a warning line.

Each side's parts delivered as a share of its bound (``parts_bound``, :mod:`cell.sim.bound`:
the most any controller could deliver from the same arrivals) is said after them, paired the
same way, fed alike or not; it is not counted in the overall line (:data:`SHOWN_ONLY`): where
every part could be delivered it is the service level again.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import pandas as pd

    from cell.experiments.sweep import Sweep

#: Arrival rates closer than this (relative) are the same, whatever their sampling errors.
RATE_APART = 1e-9
#: (title, how it is computed from a replication's columns, higher is better?)
RATE_FREE = (
    ("Service level (delivered / arrived)", ("parts_delivered", "parts_arrived", 1.0), True),
    ("Parts lost per 100 arrivals", ("parts_missed", "parts_arrived", 100.0), False),
    ("Spacings off per 100 delivered", ("spacing_outside_tol", "parts_delivered", 100.0), False),
    ("Delivered of the bound (%)", ("parts_delivered", "parts_bound", 100.0), True),
)
#: Rate-free measures said but not counted in the overall line.
SHOWN_ONLY = frozenset({"Delivered of the bound (%)"})


def _mean(summary: pd.DataFrame, measure: str, label: str) -> float:
    rows = summary[(summary["measure"] == measure) & (summary["scenario"] == label)]
    return float(rows["mean"].iloc[0]) if len(rows) else math.nan


def rate_error_s(arrivals: object, base_dir: object) -> float:
    """The standard error of a side's mean inter-arrival time, s: a trace's mean is its
    sample's (sd / sqrt(n) of its inter-arrival times), a distribution's is exact (0)."""
    from pathlib import Path

    from cell.scenario.arrivals import read_trace

    trace = getattr(arrivals, "trace_csv", None)
    if trace is None:
        return 0.0
    times = read_trace(Path(str(base_dir)) / trace)
    return float(np.std(times, ddof=1) / math.sqrt(len(times))) if len(times) > 1 else 0.0


def rates_differ(summary: pd.DataFrame, la: str, lb: str, errors: tuple[float, float] = (0, 0),
                 confidence: float = 0.95) -> str | None:
    """A line if A's and B's mean inter-arrival times differ by more than their sampling
    errors explain, else None.  ``errors``: each side's standard error of its mean
    (:func:`rate_error_s`); the two differ when their difference is outside the two-sided
    ``confidence`` interval of a difference of 0 (a fitted distribution against the trace it
    was fitted to: its mean agrees with the trace's within the trace's own sampling error)."""
    from scipy.stats import norm

    ta, tb = (_mean(summary, "mean_interarrival_s", x) for x in (la, lb))
    if not (math.isfinite(ta) and math.isfinite(tb)):
        return None
    allowed = float(norm.ppf(0.5 + confidence / 2)) * math.hypot(*errors)
    if abs(ta - tb) <= max(RATE_APART * max(ta, tb), allowed):
        return None
    return (f"arrival rates differ: {la} a part every {ta:.4g} s ({3600 / ta:.4g}/hr), {lb} every "
            f"{tb:.4g} s ({3600 / tb:.4g}/hr); parts per hour and the per-run counts follow the "
            "demand, so the verdict rests on the rate-free measures below")


def still_sides(summary: pd.DataFrame, la: str, lb: str) -> list[str]:
    """A warning per side whose headline measures do not vary between replications while
    the other's do: the paired interval then rests on the other side alone."""
    from cell.reporting.formatting import HEADLINES

    def still(label: str) -> bool:
        rows = summary[(summary["scenario"] == label) & (summary["n"] >= 2)
                       & summary["measure"].isin([h.column for h in HEADLINES])]
        return bool(len(rows)) and bool((rows["sd"] == 0).all())

    out = []
    for me, other in ((la, lb), (lb, la)):
        if still(me) and not still(other):
            out.append(f"warning: {me} gives the same figures in every replication (e.g. a "
                       f"trace): each interval rests on {other}'s variation alone")
    return out


def rate_free(replications: pd.DataFrame, sweep: Sweep, la: str, lb: str,
              width: int) -> list[tuple[str, int, float, str]]:
    """(title, +1 A better / -1 B better / 0, the difference's size in parts per 1,000, the
    verdict's line) per rate-free measure."""
    from cell.experiments.stats import paired_difference
    from cell.reporting.formatting import half_width, number, plus_minus

    def ratio(label: str, num: str, den: str, scale: float) -> np.ndarray:
        rows = replications[replications["scenario"] == label].sort_values("replication")
        d = rows[den].to_numpy(float)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(d > 0, scale * rows[num].to_numpy(float) / d, np.nan)

    out = []
    for title, (num, den, scale), higher in RATE_FREE:
        if not {num, den} <= set(replications.columns):
            continue
        xa, xb = ratio(la, num, den, scale), ratio(lb, num, den, scale)
        d = paired_difference(xa, xb, sweep.confidence)
        ma, mb = float(np.nanmean(xa)), float(np.nanmean(xb))
        if int(d["n"]) < 2:
            continue
        sd, lo, hi = float(d["sd"]), float(d["ci_low"]), float(d["ci_high"])
        judged = float(d["mean"]) != 0 if sd == 0 else not lo <= 0.0 <= hi
        side = (1 if (float(d["mean"]) > 0) == higher else -1) if judged else 0
        who = {1: f"{la} better", -1: f"{lb} better", 0: "neither"}[side]
        diff = f"{float(d['mean']):+.6g} in every replication" if sd == 0 else \
            plus_minus(float(d["mean"]), half_width(d), signed=True) + \
            (" (interval excludes 0)" if judged else " (interval includes 0)")
        size = 1000.0 * abs(float(d["mean"])) / scale  # a share (scale 1) or per 100
        out.append((title, side, size, f"  {title:<{width}}  {who}: {la} - {lb} {diff}; means "
                                       f"{number(ma)} against {number(mb)}"))
    return out
