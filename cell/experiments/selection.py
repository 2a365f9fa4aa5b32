"""KN (:mod:`cell.experiments.kn`) on simulated scenarios: a study's best candidates, or a sweep's
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

from cell.experiments.kn import FlatFirstStage, NotANumber, Selection, kn
from cell.experiments.study import GOALS
from cell.plumbing.errors import CellError
from cell.scenario.schema import Scenario

Stream = Callable[[int], np.random.SeedSequence]



def select_scenarios(scenarios: Sequence[Scenario], measure: str, maximize: bool, delta: float,
                     pcs: float, n0: int, max_n: int, stream: Stream,
                     known: Mapping[int, Sequence[float]] | None = None,
                     labels: Sequence[str] | None = None, where: str = "") -> Selection:
    """KN over ``scenarios`` on ``measure``: replication r of candidate i is ``known[i][r]``
    where given, else a run of ``scenarios[i]`` on ``stream(r)`` (in this process).

    A first stage KN cannot screen (:class:`cell.experiments.kn.FlatFirstStage`) or a run
    whose measure is not a number is a :class:`CellError` whose line starts with ``where``
    (the option or the study file's key) and names the candidates by ``labels``."""
    from cell.experiments.study import measures_of
    from cell.sim.assembly import assemble
    from cell.sim.simulation import simulate

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

    names = list(labels) if labels is not None else [f"candidate {i}" for i in range(len(scenarios))]
    try:
        return kn(lambda systems, r: [one(i, r) for i in systems], len(scenarios), delta, pcs,
                  n0=n0, maximize=maximize, max_n=max_n)
    except FlatFirstStage as exc:
        raise CellError(
            f"{where}: {names[exc.i]} and {names[exc.l]} differ by the same {measure} in all "
            f"{exc.n0} first-stage replications: KN scales its eliminations by that "
            "difference's variance, here 0, and would decide on one replication's difference; "
            "give more replications") from None
    except NotANumber as exc:
        raise CellError(f"{where}: {names[exc.i]}, replication {exc.r}: {measure} is {exc.value} "
                        "(no run of it reports a number): KN cannot compare it") from None


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
    left = [labels[i] for i in sel.survivors if i != sel.best]
    near = [labels[i] for i in sel.within_delta() if i not in sel.survivors]
    text = (f"KN (Kim & Nelson 2001) chose **{labels[sel.best]}** on {measure}, with probability "
            f"of correct selection at least {sel.pcs:g} when the best is better by δ = "
            f"{sel.delta:g} or more.")
    if left:
        text += (" The replications allowed did not tell it apart from " + ", ".join(left) + ".")
    if near:
        text += (" Within δ of it (a difference the study calls too small to matter, so not "
                 "told apart from it): " + ", ".join(near) + ".")
    if not left and not near:
        text += " Every other candidate was eliminated, and is more than δ from it."
    return text


def check_sweep(sweep: Any, measure: str, goal: str | None) -> str:
    """Refuse ``--select-best measure`` on ``sweep`` before it runs: a measure of no known
    direction without ``goal``, fewer than 2 replications a point, or a measure that only a
    policy the sweep does not run gives a value.  Returns the goal."""
    from cell.experiments.study import unset_why

    goal = goal or GOALS.get(measure)
    if goal is None:
        raise CellError(f"--select-best {measure}: say whether more or less is better "
                        "(--goal maximize or --goal minimize)")
    if sweep.first_round < 2:
        raise CellError(f"--select-best {measure}: KN needs at least 2 replications of every "
                        f"point (the sweep's replications: {sweep.first_round})")
    if why := unset_why(measure, sweep.policies):
        raise CellError(f"--select-best {measure}: {why}")
    return goal


def select_sweep(sweep: Any, replications: Any, measure: str, delta: float, pcs: float,
                 goal: str | None = None, max_n: int = 1000) -> tuple[Selection, list[str]]:
    """KN over a sweep's points on ``measure``: the replications ``replications.csv`` holds
    are the first stage (their fewest per point is n0) and the start of every point's
    sequence; more run on the sweep's own streams.  Returns the selection and the points'
    labels."""
    from cell.experiments.study import measures_of

    goal = check_sweep(sweep, measure, goal)
    known: dict[int, list[float]] = {}
    labels: list[str] = []
    for i, p in enumerate(sweep.points):
        rows = replications[(replications["policy"] == p.policy) & (replications["point"] == p.index)]
        rows = rows.sort_values("replication")
        if measure in rows.columns:
            known[i] = [float(v) for v in rows[measure]]
        else:
            known[i] = [measures_of(r)[measure] for r in rows.to_dict("records")]
        labels.append(", ".join([p.policy] + [f"{k} {p.name_of(k) or v}" for k, v in p.values]))
    n0 = min(len(v) for v in known.values())
    sel = select_scenarios([p.scenario for p in sweep.points], measure, goal == "maximize", delta,
                           pcs, n0, max(max_n, n0), sweep.stream, known,
                           [f"'{label}'" for label in labels], f"--select-best {measure}")
    return sel, labels
