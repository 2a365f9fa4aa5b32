"""``cell animate --from-part K`` deep into a run: the frames need the parts and robot cycles
around part K only.  Timing every cycle before K and giving every part a label made
``--from-part 500000 --parts 1`` take 300 s and 7 GB for 7 frames."""

from __future__ import annotations

import numpy as np
import pytest

from cell.reporting.animation.arm_pose import robot_state
from cell.reporting.animation.movie import simulate_scenes
from cell.reporting.animation.scene import FALLING, Scene, build_scene, frame_times, parts_at, window
from cell.scenario.schema import Scenario

#: Deep enough that the cycles before the window outnumber those that reach it many times over
#: (about 400 picked before it, under 50 timed); the window's depth changes nothing else.
FIRST, COUNT = 400, 3


@pytest.fixture(scope="module")
def deep(scenario: Scenario) -> list[Scene]:
    return simulate_scenes(scenario, ["adaptive", "non-adaptive"], FIRST, COUNT)


def test_only_the_cycles_that_reach_the_window_are_timed(deep: list[Scene]) -> None:
    t0, _ = window(deep, FIRST, COUNT)
    for sc in deep:
        assert (sc.cycle_t_s[:, -1] >= t0).all()
        assert len(sc.cycle_part) < 50  # of about 400 picked before the window
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
    from cell.reporting.animation.render import build_figure

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


@pytest.mark.parametrize("policy", ["adaptive", "non-adaptive"])
def test_the_frames_kept_from_a_streamed_run_are_the_full_runs(scenario: Scenario, policy: str) -> None:
    """The few fields a deep run keeps per part (flat arrays, the belts streamed) give the
    same frames' input as the run's full records: every array equal, dtype and all."""
    from cell.reporting.animation.movie import simulated
    from cell.reporting.animation.scene import frames_input
    from cell.sim.simulation import simulate

    s = scenario.with_overrides({"controller.policy": policy, "run.parts": 400,
                                 "arrivals.params.scale": 3.0})  # belts at their limits too
    ours, full = frames_input(simulated(s), s), frames_input(simulate(s), s)
    for name in full.__dataclass_fields__:
        a, b = getattr(ours, name), getattr(full, name)
        if isinstance(b, np.ndarray):
            assert a.dtype == b.dtype, name
            np.testing.assert_array_equal(a, b, err_msg=name)
        else:
            assert a == b, name


def test_a_long_run_before_the_window_shows_its_progress(scenario: Scenario, monkeypatch: pytest.MonkeyPatch,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    import cell.reporting.animation.movie as animation

    monkeypatch.setattr(animation, "PROGRESS_FROM_PARTS", 100)
    animation.simulated(scenario.with_overrides({"run.parts": 300}), progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert lines[-1].startswith("cell animate: simulating (adaptive): ")
    assert "300/300 parts (100 %)" in lines[-1]
    animation.simulated(scenario.with_overrides({"run.parts": 99}), progress=True)
    assert capsys.readouterr().err == ""


def test_a_part_held_back_longer_in_one_run_does_not_cut_the_others_cycles(
        scenario: Scenario) -> None:
    """Arrivals as bunched as these make the feeder hold parts back (§6.2 d), for longer under
    the fixed cycle's slower belt: part 13 arrives about 1 s later there than in the adaptive
    run, whose arrival starts the window.  The fixed-cycle robot is still in an earlier part's
    cycle then, as the scene with every cycle timed has it, not waiting at B."""
    bunched = scenario.with_overrides({"arrivals": {"distribution": "gamma", "mean_s": 21,
                                                    "cv": 2.5}})
    first = 13
    scenes = simulate_scenes(bunched, ["adaptive", "non-adaptive"], first, 2)
    arrived = [float(sc.data.arrival_s[first - 1]) for sc in scenes]
    assert arrived[1] > arrived[0] + 0.5  # the premise: held back longer in the second run
    t0, t1 = window(scenes, first, 2)
    times = frame_times(t0, t1, 0.05)
    for sc in scenes:
        every = build_scene(sc.data, sc.table, sc.scenario)
        ours, full = robot_state(sc, times), robot_state(every, times)
        np.testing.assert_array_equal(ours.regime, full.regime)
        np.testing.assert_array_equal(ours.q_rad, full.q_rad)
    fixed = robot_state(scenes[1], times[times < arrived[1]])
    assert (fixed.regime > 0).any()  # the stretch the fix is about: a cycle under way
