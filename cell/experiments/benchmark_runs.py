"""The benchmark's runs (issue 36 item 4, ``make benchmark``): on each of :data:`POINTS`, the
fixed cycle, the thesis's adaptive controller and the learned one run on the same parts
(replication r: ``run.seed`` r for all, common random numbers), beside the hindsight optimum of
those parts (:mod:`cell.experiments.hindsight`: a schedule that knows every arrival, run
through the simulation, and the MILP's proved bound) and ``parts_bound``.

Runs are :data:`PARTS` parts long, short enough for the MILP to solve to its optimum within
:data:`BUDGET_S` (seconds a run on the 2-core machine, a minute for the hardest under load),
so the bound is proved and the numbers do not depend on the machine's speed.  The best feasible
schedule met is the hindsight search's or a controller's own run, whichever delivers more (each
is a schedule the cell ran).
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from typing import Any

from cell.scenario import catalog
from cell.scenario.schema import Scenario, load_scenario

#: (label, what it is, the keys set on baseline.yaml).  The stress map's cell is
#: scenarios/stress.yaml's ``set`` (the nominal cycle at the arrivals' mean, a physical sensor).
STRESS = {"controller.nominal_cycle_s": None, "sensor.lookahead": "sensor"}
POINTS: tuple[tuple[str, str, dict[str, Any]], ...] = (
    ("the thesis's arrivals", "the thesis's arrivals (eq. 6.9, load 0.80) and its ideal look-ahead", {}),
    ("gamma cv 1 load 0.95", "gamma, cv 1.0, mean 17.18 s",
     {**STRESS, "arrivals.distribution": "gamma", "arrivals.cv": 1.0, "arrivals.mean_s": 17.1799}),
    ("gamma cv 0.5 load 1.00", "gamma, cv 0.5, mean 18.08 s",
     {**STRESS, "arrivals.distribution": "gamma", "arrivals.cv": 0.5, "arrivals.mean_s": 18.0841}),
    ("lognorm cv 0.75 load 1.05", "lognormal, cv 0.75, mean 18.99 s",
     {**STRESS, "arrivals.distribution": "lognorm", "arrivals.cv": 0.75,
      "arrivals.mean_s": 18.9883}),
    ("weibull cv 1 load 1.10", "Weibull, cv 1.0, mean 19.89 s",
     {**STRESS, "arrivals.distribution": "weibull_min", "arrivals.cv": 1.0,
      "arrivals.mean_s": 19.8925}),
    ("gamma cv 0.25 load 1.20", "gamma, cv 0.25, mean 21.70 s (not a training point)",
     {**STRESS, "arrivals.distribution": "gamma", "arrivals.cv": 0.25,
      "arrivals.mean_s": 21.7009}),
)
CONTROLLERS = ("non-adaptive", "adaptive", "learned")
PARTS = 20
REPLICATIONS = 10
#: Seconds the hindsight of one run may take (the MILP gets 80 % of it).
BUDGET_S = 300.0
RUN_COLUMNS = ("point", "replication", *CONTROLLERS, "hindsight_search", "optimum", "milp_upper",
               "milp_status", "exact", "parts_bound")


def scenario(point: int, replication: int) -> Scenario:
    keys = POINTS[point][2]
    return load_scenario(catalog.path("baseline")).with_overrides(
        {**keys, "run.parts": PARTS, "run.seed": replication, "run.warmup_parts": 0})


def one(task: tuple[int, int]) -> dict[str, Any]:
    """One replication of one point: each controller's parts delivered and the hindsight."""
    from cell.experiments.hindsight.optimum import hindsight
    from cell.sim.simulation import simulate

    point, r = task
    s = scenario(point, r)
    row: dict[str, Any] = {"point": POINTS[point][0], "replication": r}
    for c in CONTROLLERS:
        row[c] = simulate(s.with_overrides({"controller.policy": c}), keep_parts=False,
                          keep_belts=False).summary.parts_delivered
    h = hindsight(s, BUDGET_S).summary
    row["hindsight_search"] = h["parts_optimum"]
    row["optimum"] = max(h["parts_optimum"], *(row[c] for c in CONTROLLERS))
    row["milp_upper"] = h["parts_upper"]
    row["milp_status"] = h["milp_status"]
    row["exact"] = row["optimum"] == h["parts_upper"]
    row["parts_bound"] = h["parts_bound"]
    return row


def runs(workers: int = 2) -> list[dict[str, Any]]:
    """Every point's replications, in order (the same rows whatever the number of workers)."""
    tasks = [(p, r) for p in range(len(POINTS)) for r in range(1, REPLICATIONS + 1)]
    if workers <= 1:
        return [one(t) for t in tasks]
    with ProcessPoolExecutor(workers) as pool:
        return list(pool.map(one, tasks))
