"""``cell animate --from-part K`` deep into a run: the frames need the parts and robot cycles
around part K only.  Timing every cycle before K and giving every part a label made
``--from-part 500000 --parts 1`` take 300 s and 7 GB for 7 frames."""

from __future__ import annotations

import numpy as np
import pytest

from cell.animation import simulate_scenes
from cell.animation.scene import FALLING, Scene, build_scene, frame_times, parts_at, robot_state, window
from cell.scenario import Scenario

FIRST, COUNT = 3000, 3


@pytest.fixture(scope="module")
def deep(scenario: Scenario) -> list[Scene]:
    return simulate_scenes(scenario, ["adaptive", "non-adaptive"], FIRST, COUNT)


def test_only_the_cycles_that_reach_the_window_are_timed(deep: list[Scene]) -> None:
    t0, _ = window(deep, FIRST, COUNT)
    for sc in deep:
        assert (sc.cycle_t_s[:, -1] >= t0).all()
        assert len(sc.cycle_part) < 50  # of about 3,000 picked before the window
        assert sc.cycle_part.min() <= FIRST - 1  # part K's own cycle, or one before it, is there


def test_the_robot_is_where_a_scene_with_every_cycle_puts_it(deep: list[Scene]) -> None:
    """The joints at every frame of the window, against the scene that times all cycles."""
    t0, t1 = window(deep, FIRST, COUNT)
    times = frame_times(t0, t1, 0.25)
    for sc in deep:
        every = build_scene(sc.data, sc.table, sc.scenario)
        assert len(every.cycle_part) > FIRST / 2
        ours, full = robot_state(sc, times), robot_state(every, times)
        np.testing.assert_array_equal(ours.q_rad, full.q_rad)
        np.testing.assert_array_equal(ours.regime, full.regime)
        np.testing.assert_array_equal(ours.part, full.part)


def test_every_part_a_frame_shows_has_its_label_and_few_others_do(deep: list[Scene]) -> None:
    from cell.animation.render import build_figure

    t0, t1 = window(deep, FIRST, COUNT)
    times = frame_times(t0, t1, 1.0)
    _, panels = build_figure(deep, dpi=50.0, span=(float(times[0]), float(times[-1])))
    for panel in panels:
        needed: set[int] = set()
        for t in times:
            at = parts_at(panel.scene, float(t))
            needed |= set(np.flatnonzero((at.where > 0) & (at.where != FALLING)).tolist())
        assert needed <= set(panel.labels)
        assert len(panel.labels) < 50
        for i in needed:
            assert panel.labels[i].get_text() == str(panel.scene.data.part[i])
