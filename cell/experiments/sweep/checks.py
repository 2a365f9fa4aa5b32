"""Checks of a sweep file beyond its keys' values, made before any work: a key both set
and varied, a precision's measure no swept policy gives, and a word on a large sweep's
size."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from cell.plumbing.errors import ScenarioError
from cell.scenario import registry

if TYPE_CHECKING:
    from cell.experiments.sweep.spec import Sweep


def refuse_set_and_varied(fixed: dict[Any, Any], grids: dict[str, dict[str, list[Any]]],
                          file: Path) -> None:
    """Refuse a key given in ``set`` that a grid varies too, or whose section a grid gives
    whole: the grid's values would replace it without a word.  (A section given whole in
    ``set`` with one of its keys varied is fine: the grid changes that key only.)"""
    for key, value in fixed.items():
        for where, varied in grids.items():
            for other in varied:
                if f"{key}.".startswith(f"{other}."):
                    raise ScenarioError(file, f"set.{key}", value, f"also varied in "
                                        f"'{where}' ({other}), whose values would replace it; "
                                        "keep one")


#: The summary measures only some built-in policies give a value (None for the others).
POLICY_MEASURES = {"thesis_slack_s": ("non-adaptive",),
                   "ip_thesis_memoryless": ("adaptive",),
                   "cycle_vs_nominal_memoryless_pct": ("adaptive",)}


def refuse_measure_unset(measure: str, policies: list[str], file: Path) -> None:
    """Refuse a precision's measure that none of the swept policies gives a value (it would
    run every point to ``max``, then report no value)."""
    givers = POLICY_MEASURES.get(measure)
    if givers and all(p in registry.BUILT_IN and p not in givers for p in policies):
        raise ScenarioError(file, "replications.measure", measure,
                            f"only {' and '.join(givers)} gives it a value, and the sweep runs "
                            f"{', '.join(policies)}; choose another measure")


#: Above this many runs a sweep says first how many, and roughly how long they take.
LARGE_RUNS = 100_000
#: A rough cost of a run on one core: this much, plus its parts at this rate (parts/s).
RUN_OVERHEAD_S, PARTS_PER_S = 0.004, 50_000


def size_note(sweep: Sweep, workers: int | None = None) -> str | None:
    """One line before a large sweep starts: its number of runs, and roughly how long."""
    runs = len(sweep.points) * sweep.replications
    if runs <= LARGE_RUNS:
        return None
    parts = sum(p.scenario.run.parts + (w if isinstance(w := p.scenario.run.warmup_parts, int)
                                         else 0) for p in sweep.points) / len(sweep.points)
    core_h = runs * (RUN_OVERHEAD_S + parts / PARTS_PER_S) / 3600
    per = f", about {core_h / workers:,.1f} h with {workers} workers" if workers else ""
    return (f"{runs:,} runs ({len(sweep.points):,} points x {sweep.replications:,} "
            f"replications): roughly {core_h:,.1f} hours of one core{per}; Ctrl-C stops it, "
            "and the same command with --resume goes on")
