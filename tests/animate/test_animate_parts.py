"""``cell animate``, where the parts are: on the input belt by its travel from the drop,
in the hand from LO to TD, on the output belt by its travel from TD, fallen off at F.

Positions are checked against facts computed here, not by the animation's code:
belt travel by fine numerical integration of the recorded speed history, the
named points of the scenario (B, LO, F, G, TD, K, §4.2), the records' event
instants (arrival, at B, LO, TD).
"""

from __future__ import annotations

import numpy as np
import pytest

from cell.reporting.animation.movie import simulate_scenes
from cell.reporting.animation.scene import HAND, INPUT, OUTPUT, Scene, parts_at, time_at, travel
from cell.scenario.schema import Scenario

from .helpers import COUNT, FIRST, integrated, named_points, sample_times


def test_travel_is_the_area_under_the_speed_history() -> None:
    history = np.array([[0.0, 3.0], [10.0, 1.0], [20.0, 2.0]])
    assert travel(history, [0.0, 5.0, 10.0, 15.0, 25.0]) == pytest.approx([0, 15, 30, 35, 50])
    assert time_at(history, [15.0, 35.0, 50.0]) == pytest.approx([5.0, 15.0, 25.0])


def test_the_input_length_is_two_nominal_cycles_of_belt(scenes: list[Scene],
                                                         scenario: Scenario) -> None:
    """Baseline leaves it empty: 2 x 3.0 in/s x 22.5872 s = 135.52 in (docs/assumptions.md)."""
    for sc in scenes:
        assert sc.data.input_length_in == pytest.approx(2 * 3.0 * 22.5872)


@pytest.mark.parametrize("policy", [0, 1], ids=["adaptive", "non-adaptive"])
def test_parts_on_the_input_belt_ride_its_travel(scenes: list[Scene], scenario: Scenario,
                                                 policy: int) -> None:
    sc = scenes[policy]
    d = sc.data
    times = sample_times(scenes)
    x_of = integrated(d.input_belt, times[-1] + 1)
    b = np.array(scenario.path.bot_in)
    length = 2 * scenario.belts.input_nominal_in_s * scenario.controller.nominal_cycle_s
    checked = 0
    for t in times:
        at = parts_at(sc, t)
        on = np.flatnonzero(at.where == INPUT)
        expected = b[0] - length + (x_of(t) - x_of(d.arrival_s[on]))
        assert at.xy[on, 0] == pytest.approx(expected, abs=0.02)
        assert at.xy[on, 1] == pytest.approx(np.full(len(on), b[1]))
        checked += len(on)
    assert checked > 200
    # and each part is at B when the run says it reached B
    for i in range(FIRST - 1, FIRST + COUNT - 1):
        assert parts_at(sc, d.at_bot_s[i]).xy[i] == pytest.approx(b[:2], abs=1e-9)


@pytest.mark.parametrize("policy", [0, 1], ids=["adaptive", "non-adaptive"])
def test_parts_on_the_output_belt_ride_its_travel_from_td(scenes: list[Scene],
                                                          scenario: Scenario, policy: int) -> None:
    sc = scenes[policy]
    d = sc.data
    times = sample_times(scenes)
    y_of = integrated(d.output_belt, times[-1] + 1)
    td = named_points(scenario)["TD"]
    checked = 0
    for t in times:
        at = parts_at(sc, t)
        on = np.flatnonzero(at.where == OUTPUT)
        assert at.xy[on, 1] == pytest.approx(td[1] + y_of(t) - y_of(d.touchdown_s[on]), abs=0.02)
        assert at.xy[on, 0] == pytest.approx(np.full(len(on), td[0]))
        checked += len(on)
    assert checked > 200


def test_parts_in_the_hand_are_at_lo_and_td(scenes: list[Scene], scenario: Scenario) -> None:
    pts = named_points(scenario)
    for sc in scenes:
        d = sc.data
        for i in np.flatnonzero(d.picked)[FIRST - 1:]:
            at_lo = parts_at(sc, d.pick_s[i])
            assert at_lo.where[i] == HAND
            assert at_lo.xy[i] == pytest.approx(pts["LO"][:2], abs=1e-6)
            at_td = parts_at(sc, d.touchdown_s[i] - 1e-9)
            assert at_td.where[i] == HAND
            assert at_td.xy[i] == pytest.approx(pts["TD"][:2], abs=1e-6)
            assert parts_at(sc, d.touchdown_s[i]).where[i] == OUTPUT


def test_no_two_parts_on_a_belt_overlap(scenes: list[Scene], scenario: Scenario) -> None:
    size = scenario.part.size_in
    for sc in scenes:
        for t in sample_times(scenes):
            at = parts_at(sc, t)
            for where, axis in ((INPUT, 0), (OUTPUT, 1)):
                along = np.sort(at.xy[at.where == where, axis])
                assert np.all(np.diff(along) >= size), (sc.data.policy, t, along)


def test_a_part_not_caught_falls_off_at_f(scenes: list[Scene], scenario: Scenario) -> None:
    """Fixed cycle: the belt stays at 3 in/s, so B -> F (8 in) takes 8/3 s (§6.3)."""
    sc = scenes[1]
    d = sc.data
    lost = np.flatnonzero(~d.picked)
    assert len(lost) > 0
    np.testing.assert_allclose(sc.fall_s[lost], d.at_bot_s[lost] + 8.0 / 3.0, atol=1e-9)
    i = lost[0]
    before = parts_at(sc, sc.fall_s[i] - 1e-6)
    assert before.where[i] == INPUT
    assert before.xy[i, 0] == pytest.approx(scenario.path.f_in[0], abs=1e-4)
    assert parts_at(sc, sc.fall_s[i] + 0.1).alpha[i] < 1.0
    assert not np.any(~scenes[0].data.picked[:FIRST + COUNT])   # the adaptive robot saves them


def test_both_policies_see_the_same_parts(scenes: list[Scene]) -> None:
    np.testing.assert_array_equal(scenes[0].data.arrival_s, scenes[1].data.arrival_s)


def test_the_belts_are_the_runs_recorded_history(scenes: list[Scene], scenario: Scenario) -> None:
    """The animation's belts are the run's own speed changes (belts.csv), nothing recomputed."""
    from cell.sim.simulation import simulate

    for sc in scenes:
        d = sc.data
        run = simulate(scenario.with_overrides({"controller.policy": d.policy,
                                                "run.parts": len(d.part)}))
        for belt, history in (("input", d.input_belt), ("output", d.output_belt)):
            rows = sorted((c.from_s, c.speed_in_s) for c in run.belt_changes if c.belt == belt)
            np.testing.assert_array_equal(history, np.array(rows))
        assert len(np.unique(d.input_belt[:, 1])) > 2 or d.policy == "non-adaptive"



def test_the_demo_shows_a_part_the_fixed_cycle_loses_and_the_adaptive_saves() -> None:
    from cell.reporting.animation.movie import DEMO_FIRST, DEMO_PARTS
    from cell.scenario.schema import load_scenario

    adaptive, fixed = simulate_scenes(load_scenario("baseline"), ["adaptive", "non-adaptive"],
                                      DEMO_FIRST, DEMO_PARTS)
    shown = slice(DEMO_FIRST - 1, DEMO_FIRST - 1 + DEMO_PARTS)
    assert adaptive.data.picked[shown].all()
    assert (~fixed.data.picked[shown]).sum() >= 2
