"""KN (:mod:`cell.select`) on simulated scenarios: a study's best candidates, or a sweep's
points, re-run in pairs over common random numbers until one is left.

Replication ``r`` of every candidate runs on the same stream, ``stream(r)``; for a sweep's
points the replications ``replications.csv`` holds already are used first (they are the
sweep's streams ``SeedSequence(seed, spawn_key=(r,))``, so the procedure just continues
them).  The report's table names each candidate's mean, replications and verdict.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from cell.scenario import Scenario
from cell.select import Selection, kn

Stream = Callable[[int], np.random.SeedSequence]

#: The usual sense of the headline measures, for ``--select-best`` without ``--goal``.
GOALS = {"parts_missed": "minimize", "parts_missed_pct": "minimize", "parts_missed_thesis": "minimize",
         "spacing_outside_tol": "minimize", "spacing_outside_pct": "minimize",
         "parts_per_hr_wallclock": "maximize", "parts_per_hr_thesis": "maximize",
         "parts_delivered": "maximize", "actual_cycle_wallclock_s": "minimize",
         "actual_cycle_thesis_s": "minimize"}


def select_scenarios(scenarios: Sequence[Scenario], measure: str, maximize: bool, delta: float,
                     pcs: float, n0: int, max_n: int, stream: Stream,
                     known: Mapping[int, Sequence[float]] | None = None) -> Selection:
    """KN over ``scenarios`` on ``measure``: replication r of candidate i is ``known[i][r]``
    where given, else a run of ``scenarios[i]`` on ``stream(r)`` (in this process)."""
    from cell.assembly import assemble
    from cell.simulation import simulate
    from cell.study import measures_of

    cells: dict[int, Any] = {}
    known = known or {}

    def one(i: int, r: int) -> float:
        have = known.get(i, ())
        if r < len(have):
            return float(have[r])
        if i not in cells:
            cells[i] = assemble(scenarios[i])
        row = simulate(cells[i], seed=stream(r), keep_parts=False, keep_belts=False).summary
        return measures_of(row.as_dict())[measure]

    return kn(lambda systems, r: [one(i, r) for i in systems], len(scenarios), delta, pcs,
              n0=n0, maximize=maximize, max_n=max_n)


def verdicts(sel: Selection) -> list[str]:
    """One word per candidate: chosen, alike (cannot be told apart from it), or eliminated."""
    alike = set(sel.alike())
    return ["chosen" if i == sel.best else "alike" if i in alike else "eliminated"
            for i in range(len(sel.means))]


def table(sel: Selection, labels: Sequence[str], measure: str) -> list[str]:
    """The selection as a markdown table."""
    words = verdicts(sel)
    out = [f"| candidate | {measure} (mean) | replications | verdict |", "|---|---|---|---|"]
    out += [f"| {labels[i]} | {sel.means[i]:.4g} | {sel.counts[i]} | {words[i]} |"
            for i in range(len(labels))]
    return out


def sentence(sel: Selection, labels: Sequence[str], measure: str) -> str:
    """The selection in words."""
    alike = [labels[i] for i in sel.alike()]
    text = (f"KN (Kim & Nelson 2001) chose **{labels[sel.best]}** on {measure}, with probability "
            f"of correct selection at least {sel.pcs:g} when the best is better by δ = "
            f"{sel.delta:g} or more")
    if alike:
        text += ("; it cannot be told apart, within δ or the replications allowed, from "
                 + ", ".join(alike))
    else:
        text += "; every other candidate was eliminated"
    return text + "."
