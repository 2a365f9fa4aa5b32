"""cell.rl.CellEnv: gymnasium's own checker, a random agent against the plan check, seeds, the
thesis's adaptive decision through the environment against `cell run`, and vector envs."""

from __future__ import annotations

import csv
import math

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.cli.main import main
from cell.plumbing.csvfile import RowWriter
from cell.rl import ENV_ID, CellEnv
from cell.rl.actions import FIELDS, PLAN_LIMITS, ActionMap, action_of
from cell.scenario import catalog
from cell.scenario.schema import load_scenario
from cell.sim.policies.adaptive import Adaptive
from cell.sim.policies.check import PlanCheck
from cell.sim.records import PART_COLUMNS
from cell.sim.simulation import simulate


def scenario(parts: int = 60, **over):
    return load_scenario(catalog.path("baseline")).with_overrides(
        {"run.parts": parts, "controller.policy": "adaptive", **over})


@pytest.fixture(scope="module")
def stress_point():
    """A clustered, overloaded point of the stress map (parts lost whatever the decisions)."""
    return scenario(40, **{"arrivals.distribution": "gamma", "arrivals.cv": 1.0,
                           "arrivals.mean_s": 17.1799, "controller.nominal_cycle_s": None,
                           "sensor.lookahead": "sensor"})


def test_gymnasium_env_checker_passes(stress_point):
    env = CellEnv(stress_point)
    check_env(env, skip_render_check=True)
    env.close()


def test_random_agent_never_refused_never_raises(stress_point):
    """10,000 random actions, each mapped into the feasible set: every plan the controller gets
    passes the check (a refused plan would raise), every episode ends."""
    env = CellEnv(stress_point.with_overrides({"run.parts": 400}))
    env.action_space.seed(7)
    rng = np.random.default_rng(7)
    obs, _ = env.reset(seed=3)
    episodes = steps = 0
    while steps < 10_000:
        a = env.action_space.sample()
        wild = rng.random(len(a)) < 0.05  # now and then NaN, an infinity or a negative
        a[wild] = rng.choice([np.nan, np.inf, -np.inf, -1e6], wild.sum())
        obs, reward, done, truncated, _ = env.step(a)
        assert env.observation_space.contains(obs)
        assert reward >= 0.0  # parts delivered only (the default reward)
        steps += 1
        if done:
            episodes += 1
            obs, _ = env.reset()
    env.close()
    assert episodes >= 10


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64),
                min_size=len(FIELDS), max_size=len(FIELDS)),
       st.floats(0.0, 10.0))
def test_map_lands_in_the_checked_set_and_fixes_it(k, values, v):
    """Any vector maps to a plan the check passes; a plan that passes maps to itself, bit for
    bit (the map is the identity on the feasible set)."""
    m = ActionMap(k)
    plan = m.to_plan(np.array(values), v)
    PlanCheck(k, "agent").passes(plan)  # raises if refused
    assert plan.limits & ~PLAN_LIMITS == 0  # no outcome claimed (let go, scrapped...)
    again = m.to_plan(action_of(plan), plan.input_speed)
    assert action_of(again).tobytes() == action_of(plan).tobytes()


def test_same_seed_same_episode_and_the_parts_of_cell_run(stress_point):
    def episode(seed):
        env = CellEnv(stress_point, keep_parts=True)
        env.action_space.seed(11)
        obs, _ = env.reset(seed=seed)
        seen, done = [obs], False
        while not done:
            obs, r, done, _, info = env.step(env.action_space.sample())
            seen.append(obs)
        return np.array(seen), env.result

    a, ra = episode(5)
    b, rb = episode(5)
    assert a.tobytes() == b.tobytes()
    run = simulate(stress_point, seed=5, keep_parts=True)
    parts = [r.interarrival_s for r in ra.records]  # the feeder's draws
    assert len(parts) == stress_point.run.parts
    assert parts == [r.interarrival_s for r in run.records]
    assert [r.arrival_s for r in ra.records] == [r.arrival_s for r in rb.records]
    c, _ = episode(6)
    assert c[:, 0].tobytes() != a[:, 0].tobytes()


@pytest.mark.parametrize("lookahead", ["sensor", "ideal"])
def test_adaptive_decisions_through_the_env_reproduce_cell_run(tmp_path, lookahead):
    """An agent that takes the thesis's adaptive decision at each step: parts.csv is the one
    `cell run` writes for the same seed, byte for byte."""
    s = scenario(120, **{"sensor.lookahead": lookahead, "run.seed": 17})
    out = tmp_path / "run"
    assert main(["run", "baseline", "--out", str(out), "--set", "run.parts=120",
                 "--set", "controller.policy=adaptive", "--set", f"sensor.lookahead={lookahead}",
                 "--set", "run.seed=17"]) == 0
    env = CellEnv(s, keep_parts=True)
    rule = Adaptive(env.k, s.controller)
    env.reset(seed=17)
    done, steps = False, 0
    while not done:
        _, _, done, _, _ = env.step(env.action_of(rule.plan(env.view)))
        steps += 1
    mine = tmp_path / "parts.csv"
    with open(mine, "w", newline="") as f:
        w = RowWriter(f, PART_COLUMNS)
        for r in env.result.records:
            w.record(r)
    assert mine.read_bytes() == (out / "parts.csv").read_bytes()
    with open(mine, newline="") as f:
        assert steps == sum(row["picked"] == "True" for row in csv.DictReader(f))


def test_vector_env_steps_each_copy_as_alone(stress_point):
    envs = gymnasium.vector.SyncVectorEnv([lambda: CellEnv(stress_point)] * 2)
    obs, _ = envs.reset(seed=21)
    alone = CellEnv(stress_point)
    first, _ = alone.reset(seed=22)
    assert obs[1].tobytes() == first.tobytes()  # copy i seeded 21 + i
    total = np.zeros(2)
    for _ in range(30):
        obs, r, done, trunc, _ = envs.step(envs.action_space.sample())
        total += r
    assert (total > 0).all()
    envs.close()


def test_async_vector_env_runs_each_copy_in_its_process(stress_point):
    envs = gymnasium.vector.AsyncVectorEnv([lambda: CellEnv(stress_point)] * 2)
    obs, _ = envs.reset(seed=21)
    alone, _ = CellEnv(stress_point).reset(seed=21)
    assert obs[0].tobytes() == alone.tobytes()
    for _ in range(10):
        obs, r, done, trunc, _ = envs.step(envs.action_space.sample())
    assert envs.observation_space.contains(obs)
    envs.close()


def test_registered_with_gymnasium(stress_point):
    env = gymnasium.make(ENV_ID, scenario=stress_point)
    obs, _ = env.reset(seed=1)
    assert obs.shape == (len(env.observation_space.low),) and math.isfinite(obs[0])
    env.close()


def test_reward_terms_refused_by_name(stress_point):
    from cell.plumbing.errors import ScenarioError

    with pytest.raises(ScenarioError, match="reward.profit"):
        CellEnv(stress_point, reward={"profit": 1.0})
    with pytest.raises(ScenarioError, match="reward.cost"):
        CellEnv(stress_point, reward={"cost": 1.0})


def test_the_cost_reward_sums_to_the_runs_cost(stress_point):
    """With costs: and no failures or energy, the cost terms summed over an episode are the
    run's cost (cell.sim.run_cost): lost parts x part_value + the options' hours."""
    from cell.sim.run_cost import run_cost

    s = stress_point.with_overrides({"costs": {"part_value": 12.0,
                                               "options_per_h": {"robot": 6.0, "sensor": 0.4}}})
    env = CellEnv(s, reward={"delivered": 0.0, "cost": 1.0})
    env.action_space.seed(5)
    env.reset(seed=9)
    total, done, info = 0.0, False, {}
    while not done:
        _, r, done, _, info = env.step(env.action_space.sample())
        total += r
    summary = info["summary"]
    assert summary.parts_missed > 0
    assert total == pytest.approx(-run_cost(summary, s, []), rel=1e-9)
