"""On small traces the hindsight MILP's proved optimum is at least what the learned controller
(a plug-in) and a random agent in CellEnv deliver, and at most ``parts_bound``."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cell.experiments.hindsight.optimum import hindsight
from cell.rl import CellEnv
from cell.sim.simulation import simulate
from tests.traces import trace_scenario


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("rl_traces")


gap = st.one_of(st.just(0.0), st.floats(0.0, 40.0, allow_nan=False))


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(gaps=st.lists(gap, min_size=8, max_size=10).filter(lambda g: sum(g) > 1.0),
       agent_seed=st.integers(0, 2**16))
def test_learned_and_any_agent_sit_below_the_milp(folder: Path, gaps: list[float],
                                                  agent_seed: int) -> None:
    out = hindsight(trace_scenario(folder, gaps, "adaptive"), budget_s=20.0).summary
    assert out["milp_status"] == "optimal"
    upper = out["parts_upper"]
    assert upper <= out["parts_bound"]
    learned = simulate(trace_scenario(folder, gaps, "learned")).summary
    assert learned.parts_delivered <= upper
    env = CellEnv(trace_scenario(folder, gaps, "adaptive"))
    env.action_space.seed(agent_seed)
    env.reset()
    done, info = False, {}
    while not done:
        _, _, done, _, info = env.step(env.action_space.sample())
    assert info["summary"].parts_delivered <= upper
    env.close()
