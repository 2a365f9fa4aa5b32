"""``make learn``: train the ``learned`` policy's network with CMA-ES (docs/rl.md).

The objective is the parts delivered, summed over a fixed training set of runs (:data:`POINTS`
x :data:`SEEDS`, the stress map's families at its loads around the robot's fastest cycle, with a
physical sensor; seeds apart from the benchmark's), each candidate run on the same parts (common
random numbers).  CMA-ES (the ``cma`` package, in the optional extra ``[rl]``) starts from zero
weights, the adaptive decision itself, and runs :data:`GENERATIONS` generations of
:data:`POPULATION` candidates, its random numbers seeded: the same weights come out every time,
to the bit.  The budget: about 3 minutes on the 2-core machine the project is built on, its
candidates scored two at a time, when the machine is otherwise idle (``make learn`` prints the
time taken; 6 minutes on one core).  The best candidate met is written to
``cell/rl/weights/learned.json`` beside its score and the adaptive decision's on the same runs.
"""

from __future__ import annotations

import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

from cell.rl.learned import WEIGHTS, Learned, size
from cell.scenario import catalog
from cell.scenario.schema import Scenario, load_scenario
from cell.sim.assembly import AssembledCell, assemble
from cell.sim.simulation import simulate

#: The training runs: (distribution, cv, mean inter-arrival s) of the stress map's grid.
POINTS = (("gamma", 1.0, 17.1799), ("gamma", 0.5, 18.0841), ("lognorm", 0.75, 18.9883),
          ("weibull_min", 1.0, 19.8925))
#: Seeds of the training runs (the benchmark's are below 1000).
SEEDS = (7001, 7002)
PARTS = 150
GENERATIONS = 100
POPULATION = 10
SIGMA0 = 0.5
SEED = 1984


def training_scenarios() -> list[Scenario]:
    """The training runs' scenarios: the stress map's cell (scenarios/stress.yaml's ``set``)."""
    base = load_scenario(catalog.path("baseline"))
    return [base.with_overrides({"arrivals.distribution": d, "arrivals.cv": cv,
                                 "arrivals.mean_s": mean, "run.parts": PARTS,
                                 "controller.nominal_cycle_s": None,
                                 "sensor.lookahead": "sensor", "controller.policy": "adaptive"})
            for d, cv, mean in POINTS]


#: Processes the candidates of a generation are scored in (the scores do not depend on it).
WORKERS = 2


class Objective:
    """Parts delivered by a network's weights over the training runs."""

    def __init__(self) -> None:
        self.cells = [assemble(s) for s in training_scenarios()]

    def score(self, theta: Any) -> int:
        total = 0
        for cell in self.cells:
            policy = Learned(cell.k, cell.scenario.controller, None, np.asarray(theta))
            learned = AssembledCell(cell.scenario, cell.timing, cell.k, policy)
            for seed in SEEDS:
                total += simulate(learned, seed=seed, keep_parts=False,
                                  keep_belts=False).summary.parts_delivered
        return total


#: The objective of this process (built once, in each worker).
OBJECTIVE: list[Objective] = []


def score(theta: Any) -> int:
    """:meth:`Objective.score` in this process."""
    if not OBJECTIVE:
        OBJECTIVE.append(Objective())
    return OBJECTIVE[0].score(theta)


def train() -> dict[str, Any]:
    import cma

    started = time.perf_counter()
    zero = np.zeros(size())
    baseline = score(zero)
    es = cma.CMAEvolutionStrategy(zero, SIGMA0, {"popsize": POPULATION, "seed": SEED,
                                                 "maxiter": GENERATIONS, "verbose": -9})
    best, best_score = zero, baseline
    pool = ProcessPoolExecutor(WORKERS)
    for generation in range(GENERATIONS):
        candidates = es.ask()
        scores = list(pool.map(score, candidates))
        es.tell(candidates, [-float(s) for s in scores])
        i = int(np.argmax(scores))
        if scores[i] > best_score:
            best, best_score = np.asarray(candidates[i]), scores[i]
        print(f"generation {generation + 1}/{GENERATIONS}: best {max(scores)}, "
              f"kept {best_score} (adaptive {baseline}), "
              f"{time.perf_counter() - started:.0f} s", file=sys.stderr)
    pool.shutdown()
    return {"theta": [float(x) for x in best], "parts_delivered": int(best_score),
            "parts_delivered_adaptive": int(baseline),
            "training": {"points": [list(p) for p in POINTS], "seeds": list(SEEDS),
                         "parts": PARTS, "generations": GENERATIONS, "population": POPULATION,
                         "sigma0": SIGMA0, "seed": SEED}}


def main() -> int:
    started = time.perf_counter()
    found = train()
    WEIGHTS.parent.mkdir(parents=True, exist_ok=True)
    WEIGHTS.write_text(json.dumps(found, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {WEIGHTS} ({found['parts_delivered']} parts against the adaptive decision's "
          f"{found['parts_delivered_adaptive']}; {time.perf_counter() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
