"""``cell animate``, the arm: its tool centre passes the scenario's named points (§4.2) at
the records' instants and regime times, and its links keep their lengths."""

from __future__ import annotations

import numpy as np
import pytest

from cell.reporting.animation.arm_pose import arm_pose, robot_state
from cell.reporting.animation.scene import Scene
from cell.reporting.figures.motion import timeline
from cell.scenario.schema import Scenario

from .helpers import FIRST, named_points


def test_the_arm_tip_passes_the_named_points_at_the_recorded_instants(
        scenes: list[Scene], scenario: Scenario) -> None:
    pts = named_points(scenario)
    waits = 0
    for sc in scenes:
        d = sc.data
        starts = np.append(d.start_s[d.picked], np.inf)
        for n, i in enumerate(np.flatnonzero(d.picked)):
            start, (r1, r2, r3, r4) = d.start_s[i], d.regime_s[i]
            when = {"B": start, "LO": d.pick_s[i], "F": start + r1, "G": start + r1 + r2,
                    "TD": d.touchdown_s[i], "K": start + r1 + r2 + r3}
            state = robot_state(sc, list(when.values()))
            tip = arm_pose(scenario, state.q_rad, state.opening_in).tcp
            for k, name in enumerate(when):
                assert tip[k] == pytest.approx(pts[name], abs=1e-6), (sc.data.policy, i, name)
            # back at B at the end of the cycle, and waiting there until the next one
            end = start + r1 + r2 + r3 + r4
            assert starts[n + 1] >= end - 1e-9
            between = [end, (end + starts[n + 1]) / 2] if starts[n + 1] > end + 1e-6 else [end]
            idle = robot_state(sc, between)
            back = arm_pose(scenario, idle.q_rad, idle.opening_in).tcp
            assert back == pytest.approx(np.tile(pts["B"], (len(between), 1)), abs=1e-6)
            waits += int(idle.regime[-1] == 0)
    assert waits > 3


def test_the_arm_tip_is_on_the_path_at_every_path_point(scenes: list[Scene],
                                                         scenario: Scenario) -> None:
    sc = scenes[0]
    d, table = sc.data, sc.table
    i = int(np.flatnonzero(d.picked)[FIRST])
    r1, r2, r3, r4 = d.regime_s[i]
    r1_pre = d.pick_s[i] - d.start_s[i]
    r3_pre = d.touchdown_s[i] - d.start_s[i] - r1 - r2
    tl = timeline(table, {"r1_pre": r1_pre, "r1_post": r1 - r1_pre, "r2": r2, "r3_pre": r3_pre,
                          "r3_post": r3 - r3_pre, "r4": r4})
    state = robot_state(sc, d.start_s[i] + tl.t_s)
    tip = arm_pose(scenario, state.q_rad, state.opening_in).tcp
    np.testing.assert_allclose(tip, table.path.xyz_in, atol=1e-6)
    assert set(state.regime[1:]) == {1, 2, 3, 4}


def test_the_links_keep_their_lengths(scenes: list[Scene], scenario: Scenario) -> None:
    """Upper arm and forearm 7 in (docs/model.md), shoulder 7.68 in above the base (§6.1), and the
    hand 3.5498 in long while it holds the 2 in cube (eq. 6.2)."""
    sc = scenes[0]
    d = sc.data
    times = np.linspace(d.start_s[FIRST], d.start_s[FIRST + 2], 997)
    state = robot_state(sc, times)
    base, elbow, wrist, tcp = np.moveaxis(arm_pose(scenario, state.q_rad, state.opening_in).joints,
                                          1, 0)
    shoulder = base + [0.0, 0.0, 7.68]
    np.testing.assert_allclose(np.linalg.norm(elbow - shoulder, axis=1), 7.0, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(wrist - elbow, axis=1), 7.0, atol=1e-9)
    holding = np.zeros(len(times), dtype=bool)
    for i in np.flatnonzero(d.picked):
        holding |= (times >= d.pick_s[i]) & (times <= d.touchdown_s[i])
    assert holding.any() and not holding.all()
    np.testing.assert_allclose(np.linalg.norm(tcp - wrist, axis=1)[holding], 3.5498, atol=5e-5)
