"""``cell sensitivity``: global sensitivity of a study's measures to its keys (SALib).

Two stages, as screening designs are meant to be used (Saltelli et al., *Global Sensitivity
Analysis: The Primer*, 2008, ch. 3-4):

1. Morris's elementary effects (Morris 1991; Campolongo et al. 2007's μ*) over every key:
   ``trajectories`` × (keys + 1) points;
2. Sobol's indices (first order S1 and total ST, Saltelli 2002 / Jansen 1999 estimators,
   bootstrap 95 % intervals) over the ``keys`` Morris ranks first by μ* on any measure and
   policy: ``samples`` × (keys + 2) points.

Every point runs each policy on the same ``replications`` streams (common random numbers):
the measures are then a deterministic function of the keys, so the indices measure the keys'
effect and not the draws'.  Points are evaluated in a fixed order and gathered in that
order, so the numbers do not depend on the number of workers.  The measure ``advantage``
(the adaptive robot's parts delivered minus the fixed-cycle robot's, at the same point and on
the same streams) is added when both policies run: the thesis's conclusion holds at a
point where it is above 0.
"""

from __future__ import annotations

import concurrent.futures as cf
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cell.experiments.study import Param, Study

#: The paired difference added when both built-in policies run.
ADVANTAGE = "advantage"


@dataclass(frozen=True)
class Design:
    keys: tuple[str, ...]
    points: np.ndarray
    """(n, len(keys)) values, in SALib's order."""
    problem: dict[str, Any]


def problem(params: Sequence[Param]) -> dict[str, Any]:
    for p in params:
        if p.is_choice:
            raise ValueError(f"{p.key}: sensitivity needs a range, not a choice")
    return {"num_vars": len(params), "names": [p.key for p in params],
            "bounds": [[p.low, p.high] for p in params]}


def morris_design(params: Sequence[Param], trajectories: int, levels: int, seed: int) -> Design:
    from SALib.sample import morris

    prob = problem(params)
    x = morris.sample(prob, trajectories, num_levels=levels, seed=seed)
    return Design(tuple(prob["names"]), x, prob)


def sobol_design(params: Sequence[Param], samples: int, seed: int) -> Design:
    from SALib.sample import sobol

    prob = problem(params)
    x = sobol.sample(prob, samples, calc_second_order=False, scramble=True, seed=seed)
    return Design(tuple(prob["names"]), x, prob)


def _point(args: tuple[str, tuple[str, ...], tuple[float, ...], tuple[str, ...],
                       tuple[str, ...], int]) -> list[float]:
    """One point in a worker: every policy's mean of every measure over the replications
    (and the advantage), as one flat list in a fixed order."""
    from cell.experiments.study import load_study, replicate

    source, keys, xs, policies, measures, reps = args
    study = _cached(source)
    values = {k: (int(round(x)) if _whole(study, k) else float(x)) for k, x in zip(keys, xs)}
    out: list[float] = []
    delivered: dict[str, np.ndarray] = {}
    for policy in policies:
        rows = replicate(study, {**values, "controller.policy": policy}, range(reps))
        out += [float(np.mean([r[m] for r in rows])) for m in measures]
        delivered[policy] = np.array([r["parts_delivered"] for r in rows])
    if {"adaptive", "non-adaptive"} <= set(policies):
        out.append(float(np.mean(delivered["adaptive"] - delivered["non-adaptive"])))
    del load_study
    return out


_STUDIES: dict[str, Study] = {}


def _cached(source: str) -> Study:
    from cell.experiments.study import load_study

    if source not in _STUDIES:
        _STUDIES.clear()
        _STUDIES[source] = load_study(source, corners=False)
    return _STUDIES[source]


def _whole(study: Study, key: str) -> bool:
    return any(p.key == key and p.whole for p in study.params)


def evaluate(study: Study, design: Design, policies: Sequence[str], measures: Sequence[str],
             workers: int, progress: Any) -> np.ndarray:
    """Every point of ``design``: an array (points, columns) of :func:`columns`, in order."""
    jobs = [(str(study.source.resolve()), design.keys, tuple(float(v) for v in x),
             tuple(policies), tuple(measures), study.settings.replications) for x in design.points]
    rows: list[list[float]] = []
    _STUDIES.clear()
    _STUDIES[str(study.source.resolve())] = study  # forked workers start with it too
    if workers <= 1:
        for job in jobs:
            rows.append(_point(job))
            progress.update()
    else:
        with cf.ProcessPoolExecutor(workers) as pool:  # as a sweep's workers: forked on Linux
            for row in pool.map(_point, jobs, chunksize=max(1, len(jobs) // (8 * workers))):
                rows.append(row)
                progress.update()
    return np.asarray(rows, dtype=float)


def columns(policies: Sequence[str], measures: Sequence[str]) -> list[tuple[str, str]]:
    """(policy, measure) of each column :func:`evaluate` returns."""
    out = [(p, m) for p in policies for m in measures]
    if {"adaptive", "non-adaptive"} <= set(policies):
        out.append(("both", ADVANTAGE))
    return out


def morris_indices(design: Design, y: np.ndarray, levels: int, seed: int) -> dict[str, np.ndarray]:
    from SALib.analyze import morris

    res = morris.analyze(design.problem, design.points, y, num_levels=levels, seed=seed,
                         conf_level=0.95, print_to_console=False)
    return {k: np.asarray(res[k], dtype=float) for k in ("mu_star", "mu_star_conf", "sigma")}


def sobol_indices(design: Design, y: np.ndarray, seed: int) -> dict[str, np.ndarray]:
    from SALib.analyze import sobol

    if not np.isfinite(y).any():  # no run gives the measure: no share of its variance
        n = np.full(len(design.keys), np.nan)
        return {"S1": n, "S1_conf": n, "ST": n, "ST_conf": n}
    if np.ptp(y) == 0:  # a measure no key moves: every index 0, exactly
        z = np.zeros(len(design.keys))
        return {"S1": z, "S1_conf": z, "ST": z, "ST_conf": z}
    res = sobol.analyze(design.problem, y, calc_second_order=False, conf_level=0.95, seed=seed,
                        print_to_console=False)
    return {k: np.asarray(res[k], dtype=float) for k in ("S1", "S1_conf", "ST", "ST_conf")}


def screened(params: Sequence[Param], mu_star: dict[tuple[str, str], np.ndarray],
             spread: dict[tuple[str, str], float], keep: int) -> list[Param]:
    """The ``keep`` keys with the largest μ* relative to the measure's spread, on any
    measure and policy (each key's largest such share), in the study file's order."""
    score = np.zeros(len(params))
    for col, mu in mu_star.items():
        if spread[col] > 0:
            score = np.maximum(score, mu / spread[col])
    order = sorted(range(len(params)), key=lambda i: (-score[i], i))[:keep]
    return [params[i] for i in sorted(order)]
