"""``cell bench`` / ``make bench``: how fast the simulation runs on this machine.

Measured in one run: simulated parts per second for a 500-part adaptive and a
500-part non-adaptive run (best of several, the path already solved, as in a
sweep), and a bare SimPy process doing ``yield env.timeout(1)`` in a loop
(events per second) for scale.  The planner's figures from
``cell.bench_planner.benchmarks()`` are merged in by ``cell bench``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import simpy

from cell.scenario import Scenario, default_scenario, load_scenario
from cell.simulation import simulate

#: The speed asked of both policies (simulated parts per second).
TARGET_PARTS_PER_S = 20_000


def _best_seconds(fn: Any, repeats: int) -> float:
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def parts_per_second(scenario: Scenario, repeats: int = 15) -> float:
    """Best-of-``repeats`` simulated parts per second (after one warm-up run)."""
    simulate(scenario)  # solves and caches the path
    seconds = _best_seconds(lambda: simulate(scenario), repeats)
    return scenario.run.parts / seconds


def simpy_timeouts_per_second(n: int = 200_000, repeats: int = 3) -> float:
    """A bare SimPy process yielding ``env.timeout(1)`` ``n`` times: events per second."""
    def once() -> None:
        env = simpy.Environment()

        def loop(env: simpy.Environment):  # noqa: ANN202
            for _ in range(n):
                yield env.timeout(1)

        env.process(loop(env))
        env.run()

    return n / _best_seconds(once, repeats)


def benchmarks(scenario_file: str | Path = "scenarios/baseline.yaml") -> dict[str, Any]:
    """The simulation's figures (the scenario file if present, else the built-in defaults)."""
    path = Path(scenario_file)
    base = load_scenario(path) if path.is_file() else default_scenario()
    base = base.with_overrides({"run.parts": 500})
    adaptive = base.with_overrides({"controller.policy": "adaptive"})
    fixed = base.with_overrides({"controller.policy": "non-adaptive"})
    return {
        "parts_per_s_adaptive": parts_per_second(adaptive),
        "parts_per_s_non_adaptive": parts_per_second(fixed),
        "simpy_timeouts_per_s": simpy_timeouts_per_second(),
    }
