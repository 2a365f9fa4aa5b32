"""The bound on any controller (cell/sim/bound.py, SPEC §11): a greedy pass over each part's
window at B, worked by hand here, and never below what either policy delivers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.scenario.schema import Scenario
from cell.sim.assembly import assemble
from cell.sim.bound import (
    all_picked,
    fastest_possible_cycle,
    greedy_pass,
    greedy_picks,
    parts_bound,
)
from cell.sim.conveyors import EPS_S
from cell.sim.simulation import simulate
from tests.sim.test_sensor import run_trace


def test_the_greedy_pass_worked_by_hand() -> None:
    """L = 12 in, belt 1..4 in/s, 1 in parts, picks 10 s apart: a part reaches B 3 to 12 s
    after it is dropped.  Parts at 0, 1, 2, 3 and 50 s have windows [3, 12], [4, 13], [5, 14],
    [6, 15], [53, 62].  The windows alone: picks at 3 and 13 take parts 1 and 2; 23 s is past
    the windows of 3 and 4; part 5 is picked at 53.  Three parts.  One belt: the parts are at
    most 4 in apart on it (the ceiling for 1 s), 4 s at the floor, so part 1 is picked at 3 and
    the next pick at 13 must be at least 10 s of the floor behind it: part 4 (12 s); then part 5:
    still three."""
    assert greedy_picks([0, 1, 2, 3, 50], 12.0, 1.0, 4.0, 1.0, 10.0) == 3
    assert greedy_picks([0, 1, 2, 3, 50], 12.0, 1.0, 4.0, 1.0, 10.0, one_belt=False) == 3
    # three parts at once: the feeder drops them 1 s apart (1 in at the floor), so the
    # windows are [3, 12], [3, 13], [3, 14]: picks at 3 and 13 by the windows alone; 23 is too
    # late.  On one belt they are 1 in apart, 2 s at the floor from first to last: one pick.
    assert greedy_picks([0, 0, 0], 12.0, 1.0, 4.0, 1.0, 10.0, one_belt=False) == 2
    assert greedy_picks([0, 0, 0], 12.0, 1.0, 4.0, 1.0, 10.0) == 1
    # eleven at once, 10 in from first to last (10 s at the floor): the first and the last
    # (its window [3, 22] holds the pick at 13)
    assert greedy_picks([0] * 11, 12.0, 1.0, 4.0, 1.0, 10.0) == 2
    assert greedy_picks([], 12.0, 1.0, 4.0, 1.0, 10.0) == 0


def test_the_fastest_cycle_is_below_every_cycle_the_robot_runs(thesis_cell: Scenario) -> None:
    k = assemble(thesis_cell).k
    c = fastest_possible_cycle(k)
    assert c <= k.fastest_cycle_s
    r = simulate(thesis_cell.with_overrides({"run.parts": 200}), seed=1)
    assert r.parts["motion_cycle_s"].min() >= c


def test_the_bound_is_the_deliveries_where_every_part_can_be_taken(thesis_cell: Scenario) -> None:
    """Parts 25 s apart, longer than either robot's cycle: by hand, every part is picked by
    both policies and no controller can deliver more than the 60 parts that came."""
    s = thesis_cell.with_overrides({"run.parts": 60})
    for policy in ("adaptive", "non-adaptive"):
        r = run_trace(s.with_overrides({"controller.policy": policy}), [25.0] * 61).summary
        assert r.parts_delivered == r.parts_bound == 60


def test_the_bound_counts_a_burst_by_hand(thesis_cell: Scenario) -> None:
    """Ten parts 0.1 s apart: the feeder spaces their drops by a part's size at the belt's
    speed, and each has the window [drop + L / v_max, drop + L / v_min]; by the windows alone
    the picks, a fastest cycle c apart from the first part's earliest, fit while
    r_1 + (j - 1) c <= d_j.  On one belt the ten are a part's size apart (1.2 in of belt at the
    ceiling in 0.1 s is less), 9 x 2 / 1.5 = 12 s of the floor from first to last, less than
    c: a burst of m parts yields at most 1 + (m - 1) size / v_min / c picks, here one."""
    s = thesis_cell.with_overrides({"run.parts": 10})
    k = assemble(s).k
    c = fastest_possible_cycle(k)
    early, late, clear = k.input_length / k.input_max, k.input_length / k.input_min, \
        k.part_size / k.input_min
    come = [0.1 * i for i in range(10)]
    drops = [come[0]]
    for a in come[1:]:
        drops.append(max(a, drops[-1] + clear))
    by_hand = sum(1 for j in range(10) if early + j * c <= drops[j] + late)
    assert 2 < by_hand < 10
    assert parts_bound(k, come, one_belt=False) == by_hand
    r = run_trace(s, [0.1] * 11).summary
    assert r.parts_bound == 1 + int(9 * clear // c) == 1 == r.parts_delivered  # reached
    # thirty at once: 29 x 1.33 s = 38.7 s of the floor, two cycles and more; the windows
    # (90 s long, opening together) hold picks at r, r + c and r + 2 c
    assert parts_bound(k, [0.0] * 30) == 1 + int(29 * clear // c) == 3


@settings(max_examples=12, deadline=None)
@given(family=st.sampled_from(["gamma", "lognorm", "weibull_min"]),
       cv=st.sampled_from([0.05, 0.5, 1.0]), load=st.floats(0.8, 1.4),
       seed=st.integers(0, 10_000), sensor=st.booleans())
def test_no_policy_delivers_more_than_the_bound(thesis_cell: Scenario, family: str, cv: float,
                                                load: float, seed: int, sensor: bool) -> None:
    s = thesis_cell.with_overrides({
        "run.parts": 120, "arrivals.distribution": family, "arrivals.cv": cv,
        "arrivals.mean_s": 18.0841 * load, "controller.nominal_cycle_s": None,
        "sensor.lookahead": "sensor" if sensor else "ideal"})
    for policy in ("adaptive", "non-adaptive"):
        r = simulate(s.with_overrides({"controller.policy": policy}), seed=seed).summary
        assert r.parts_delivered <= r.parts_bound <= r.parts_arrived


@pytest.mark.parametrize("warmup", [0, 40])
def test_the_bound_covers_the_parts_measured(thesis_cell: Scenario, warmup: int) -> None:
    r = simulate(thesis_cell.with_overrides({"run.parts": 100, "run.warmup_parts": warmup}),
                 seed=3).summary
    assert r.parts_bound == r.parts_arrived == 100 - warmup


def test_where_the_input_belt_stood_the_bound_counts_the_windows_alone(thesis_cell: Scenario) -> None:
    """The one-belt fact needs the belt's floor: a run in which the input belt stood (a failure
    every 20 s of its running on average, repaired in 5 s) gets the windows' count (six for the
    ten at once, test_the_bound_counts_a_burst_by_hand), one whose robot alone fails keeps the
    one belt's (one)."""
    s = thesis_cell.with_overrides({"run.parts": 10})
    k = assemble(s).k
    come = [5.0] * 10
    often = {"time_to_failure": {"distribution": "expon", "mean_s": 20.0},
             "time_to_repair": {"distribution": "expon", "mean_s": 5.0}}
    stood = run_trace(s.with_overrides({"failures": {"input_belt": often}}), [5.0] + [0.0] * 10)
    assert stood.summary.input_speed_min_in_s == 0.0
    assert stood.summary.parts_bound == parts_bound(k, come, one_belt=False) == 6
    robot = run_trace(s.with_overrides({"failures": {"robot": often}}), [5.0] + [0.0] * 10)
    assert robot.summary.input_speed_min_in_s > 0.0
    assert robot.summary.parts_bound == parts_bound(k, come) == 1


@settings(max_examples=60, deadline=None)
@given(gaps=st.lists(st.floats(0.0, 30.0), max_size=40), slack=st.floats(-1e-9, 1e-9),
       one_belt=st.booleans(), v=st.sampled_from([(1.0, 4.0), (2.0, 2.0), (3.0, 1.0)]))
def test_all_picked_read_at_once_is_the_pass(gaps: list[float], slack: float, one_belt: bool,
                                             v: tuple[float, float]) -> None:
    """Where :func:`all_picked` reads from the whole array that every part is picked, the
    part-at-a-time pass picks every part too; whatever it reads, greedy_picks is the pass's
    count.  Arrivals drawn about a cycle apart (10 s, some exactly, some a rounding less),
    so that both answers come up; belts slower than, as fast as and faster than the floor."""
    come = np.cumsum([g if g < 9.0 else 10.0 - EPS_S + slack for g in gaps]).tolist()
    args = (come, 12.0, v[0], v[1], 1.0, 10.0, one_belt)
    counted = greedy_pass(*args)
    assert greedy_picks(*args) == counted
    if all_picked(np.asarray(come, dtype=float), *args[1:]):
        assert counted == len(come)
