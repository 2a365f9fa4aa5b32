"""Whether a sweep's cells can keep up: the warning for points whose offered load is 1 or
more, and how far a stated nominal cycle is off the arrivals' mean."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from cell.experiments.sweep.options import show

if TYPE_CHECKING:
    from cell.experiments.sweep.spec import Sweep
    from cell.sim.policies.base import CellConstants


def overload_warning(sweep: Sweep) -> str | None:
    """One line if some points' cells cannot keep up on average (offered load 1 or more,
    as ``cell run`` warns of a run), naming the worst; else None."""
    over = [p for p in sweep.points if p.offered_load >= 1]
    if not over:
        return None
    worst = max(over, key=lambda p: p.offered_load)
    where = ", ".join(f"{k} {worst.name_of(k) or show(v)}" for k, v in worst.values) \
        or worst.policy
    return overloaded(f"{len(over)} of {len(sweep.points)} points have offered load 1 or more "
                      f"(up to {worst.offered_load:.3f}, at {where})")


def overloaded(how_much: str, times_s: tuple[float, float] | None = None) -> str:
    """The one line saying a cell cannot keep up on average (offered load 1 or more), opened
    by ``how_much``: for a sweep's points (:func:`overload_warning`) and for a run
    (:func:`cell.reporting.run_summary.warnings`, with its fastest cycle and mean inter-arrival
    time, s)."""
    fastest, mean = (f" ({times_s[0]:.2f} s)", f" ({times_s[1]:.2f} s)") if times_s else \
        ("", " there")
    return (f"{how_much}: the robot's fastest cycle{fastest} is not shorter than the mean "
            f"inter-arrival time{mean}; the cell cannot keep up on average and every policy "
            "will lose parts")


def nominal_gap(k: CellConstants) -> float:
    """How far the nominal cycle a scenario states is off its arrivals' mean, relative and
    signed; NaN where the cycle follows the arrivals (or the robot): for
    :attr:`Point.nominal_gap` and :func:`cell.reporting.run_summary.warnings`."""
    return k.cycle_nom / k.mean_interarrival_s - 1 if k.nominal_from == "scenario" else math.nan
