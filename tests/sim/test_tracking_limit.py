"""No part is picked while the input belt runs faster than the robot can follow (issue 35,
item 2; docs/model.md "What a cycle may take"): the adaptive robot, whatever its look-ahead
sensor (noise, latency, misses, range, margin), and the plan check, which refuses a pick the
arm cannot track and ties R I to the belt's speed.

The speed is read from the belt's own history (``belts.csv``'s rows), not from the plan: for
each part picked, the input belt from its arrival at B until lift-off."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
from hypothesis import example, given, settings
from hypothesis import strategies as st

from cell.scenario.schema import default_scenario
from cell.sim.conveyors import EPS_S, speed_at
from cell.sim.policies.check import problem
from cell.sim.policies.fixed import fixed_plan
from cell.sim.simulation import simulate

#: Slack on the belt's speed (in/s): the check's own.
SLACK = 1e-9


def fastest_at_picks(r) -> tuple[float, int]:
    """The fastest input belt over any picked part's B → LO (the belt's recorded speed from
    its arrival at B, as the controller reads it, to its lift-off), and the parts picked."""
    h = r.belt_histories()["input"]
    p = r.parts
    p = p[p["picked"]]
    t, v = h[:, 0], h[:, 1]
    worst = 0.0
    for at_b, lo in zip(p["at_bot_s"].to_numpy(), p["pick_s"].to_numpy()):
        worst = max(worst, speed_at(t, v, at_b + EPS_S))
        inside = (t > at_b + EPS_S) & (t < lo - EPS_S)
        if inside.any():
            worst = max(worst, float(v[inside].max()))
    return worst, len(p)


@settings(max_examples=15, deadline=None)
@example(cv=0.75, noise=0.5, latency=0.0, miss=0.0, position=None, margin=None, seed=0)
@given(cv=st.sampled_from([0.25, 0.75, 1.0]),
       noise=st.sampled_from([0.0, 0.25, 0.5, 2.0]) | st.floats(0.0, 4.0),
       latency=st.sampled_from([0.0, 2.0]) | st.floats(0.0, 20.0),
       miss=st.sampled_from([0.0, 0.1]) | st.floats(0.0, 0.5),
       position=st.none() | st.floats(30.0, 135.0),
       margin=st.none() | st.sampled_from([0.0, 0.1, 1.0]),
       seed=st.integers(0, 2**32 - 1))
def test_the_adaptive_robot_never_picks_from_a_belt_it_cannot_follow(
        k, cv: float, noise: float, latency: float, miss: float, position: float | None,
        margin: float | None, seed: int) -> None:
    sensor = {"lookahead": "sensor", "noise_sd_in": noise, "latency_s": latency,
              "miss_probability": miss, "position_in": position, "margin_s": margin}
    s = default_scenario().with_overrides({
        "run.parts": 100, "controller.policy": "adaptive",
        "arrivals": {"distribution": "gamma", "params": {}, "mean_s": 22.5872, "cv": cv},
        "sensor": {key: value for key, value in sensor.items() if value is not None}})
    worst, picked = fastest_at_picks(simulate(s, seed=seed))
    assert picked > 0
    assert worst <= k.timing.input_track_max_in_s + SLACK


def test_the_check_refuses_a_pick_from_a_belt_the_arm_cannot_follow(k) -> None:
    """The issue's pick: the input belt at 6.19 in/s, above the 4.3693 in/s the robot can
    follow, refused even with R I as long as at that limit, and with R I timed at 6.19 in/s
    (below its 2.2112 s at the limit); and a pick at 3 in/s with R I timed as at 4 in/s."""
    t = k.timing
    plan = fixed_plan(k, k.cycle_nom)
    fast, limit = 6.19, t.input_track_max_in_s
    r1a, r1b = t.r1_time(limit)
    why = problem(_with(plan, input_speed=fast, r1_pre=r1a, r1_post=r1b), k)
    assert why is not None and why.startswith("input_speed =") and f"{limit:.6g}" in why
    r1a, r1b = t.r1_time(fast)
    assert r1a + r1b < sum(t.r1_time(limit))
    assert problem(_with(plan, input_speed=fast, r1_pre=r1a, r1_post=r1b), k) is not None
    r1a, r1b = t.r1_time(4.0)
    ahead_of_belt = _with(plan, r1_pre=r1a, r1_post=r1b)  # the belt at 3 in/s
    why = problem(ahead_of_belt, k)
    assert why is not None and why.startswith("r1_pre =")
    assert f"{t.r1_pre.time(k.v_nom):.6g}" in why


def _with(plan, **change):
    """``plan`` with fields changed and ``to_g`` and ``cycle`` summed again."""
    p = replace(plan, **change)
    p.to_g = p.r1_pre + p.r1_post + p.r2
    p.cycle = p.to_g + p.r3_pre + p.r3_post + p.r4
    return p


def test_the_reading_of_the_belt_sees_a_pick_above_the_limit() -> None:
    """The measure above can fail: a belt history with a change to 6 in/s inside one part's
    B → LO is read as 6."""
    class R:
        parts = pd.DataFrame(
            {"picked": [True], "at_bot_s": [10.0], "pick_s": [11.0]})

        @staticmethod
        def belt_histories():
            return {"input": np.array([[0.0, 3.0], [10.5, 6.0], [11.0, 3.0]])}

    assert fastest_at_picks(R()) == (6.0, 1)
