"""``cell animate``, the frames drawn: the squares on the belt strips are the parts the
records put there, where the belts' integrated travel has carried them, and nothing is
drawn past the output belt's end."""

from __future__ import annotations

import numpy as np
import pytest

from cell.reporting.animation.scene import ABSENT, HAND, OUTPUT, Scene, parts_at
from cell.scenario.schema import Scenario

from .helpers import integrated, named_points, output_reach, sample_times, square_centres


@pytest.mark.parametrize("policy", [0, 1], ids=["adaptive", "non-adaptive"])
def test_drawn_parts_sit_where_the_belts_travel_puts_them(scenes: list[Scene], scenario: Scenario,
                                                          policy: int) -> None:
    """At sampled frames, the squares drawn on the two belt strips are exactly the parts the
    records put there, each where the belt's integrated travel has carried it: dropped
    ``input_length`` upstream of B, fallen off at F (lying just past it), or set down at TD
    (and kept until it is a part's size past the farthest output belt drawn)."""
    from cell.reporting.animation.render import build_figure, draw_frame
    from cell.reporting.animation.scene import FALL_S

    panel = build_figure(scenes, dpi=20.0)[1][policy]
    sc = scenes[policy]
    d = sc.data
    times = sample_times(scenes)[::8]
    x_of = integrated(d.input_belt, times[-1] + 1)
    y_of = integrated(d.output_belt, times[-1] + 1)
    b, f, td = (named_points(scenario)[k] for k in ("B", "F", "TD"))
    length = 2 * scenario.belts.input_nominal_in_s * scenario.controller.nominal_cycle_s
    grid = np.arange(0.0, times[-1] + 1, 1e-3)
    fall = np.interp(x_of(d.arrival_s) + length + (f[0] - b[0]), x_of(grid), grid)
    drawn_in = drawn_out = 0
    for t in times:
        draw_frame(panel, float(t))
        riding = (d.arrival_s <= t) & np.where(d.picked, t < d.pick_s, t < fall)
        fallen = ~d.picked & (t >= fall) & (t < fall + FALL_S)
        expected_in = np.sort(np.r_[b[0] - length + x_of(t) - x_of(d.arrival_s[riding]),
                                    np.full(fallen.sum(), f[0] + scenario.part.size_in / 2)])
        centres = square_centres(panel.parts_in)
        assert np.sort(centres[:, 0]) == pytest.approx(expected_in, abs=0.02), t
        assert centres[:, 1] == pytest.approx(np.full(len(centres), b[1]))
        set_down = d.picked & (d.touchdown_s <= t)
        y_out = td[1] + y_of(t) - y_of(d.touchdown_s[set_down])
        expected_out = np.sort(y_out[y_out <= output_reach(panel) + scenario.part.size_in])
        assert np.sort(square_centres(panel.parts_out)[:, 0]) == pytest.approx(expected_out,
                                                                               abs=0.02), t
        drawn_in, drawn_out = drawn_in + len(expected_in), drawn_out + len(expected_out)
        # the belt speeds written on the frame are the recorded ones at t
        v_in = [v for start, v in d.input_belt if start <= t][-1]
        v_out = [v for start, v in d.output_belt if start <= t][-1]
        assert panel.texts["belts"].get_text().split() == [
            "input", "belt", f"{v_in:.2f}", "in/s", "output", "belt", f"{v_out:.2f}", "in/s"]
    assert drawn_in > 40 and drawn_out > 40


@pytest.mark.parametrize("policy", [0, 1], ids=["adaptive", "non-adaptive"])
def test_a_part_far_past_the_output_belts_drawn_end_has_left_the_scene(
        scenes: list[Scene], scenario: Scenario, policy: int) -> None:
    """A part set down rides the output belt while any of it can be drawn, and is gone (no
    square, no label) once the belt has carried it well past the farthest belt drawn."""
    from cell.reporting.animation.render import build_figure, draw_frame

    panel = build_figure(scenes, dpi=20.0)[1][policy]
    sc = scenes[policy]
    d = sc.data
    size = scenario.part.size_in
    reach = output_reach(panel)
    end = sample_times(scenes)[-1]
    y_of = integrated(d.output_belt, end + 1)
    grid = np.arange(0.0, end + 1, 1e-3)
    td = named_points(scenario)["TD"][1]
    i = int(np.flatnonzero(d.picked)[0])

    def when_at(y: float) -> float:
        """The instant part i's centre is at y on the output belt."""
        return float(np.interp(y_of(d.touchdown_s[i]) + y - td, y_of(grid), grid))

    visible, far = when_at(reach + size / 4), when_at(reach + 3 * size)
    assert visible < far < end
    assert parts_at(sc, visible).where[i] == OUTPUT
    at = parts_at(sc, far)
    assert at.where[i] == ABSENT and np.isnan(at.xy[i]).all()
    draw_frame(panel, far)
    assert not panel.labels[i].get_visible()
    assert np.all(square_centres(panel.parts_out)[:, 0] < reach + size)
    # and nothing rides on out of sight at any instant of the window
    for t in sample_times(scenes):
        at = parts_at(sc, t)
        assert np.all(at.xy[at.where == OUTPUT, 1] <= reach + size), t


def test_a_lone_part_at_the_strips_end_shows_nothing_past_it(scenes: list[Scene],
                                                              scenario: Scenario) -> None:
    """A square drawn alone across the output strip's end is cut at the strip's edge, as
    when it shares the strip with others (matplotlib's one-path shortcut is not taken)."""
    from matplotlib.colors import to_rgba

    from cell.reporting.animation.render import PART_COLOUR, build_figure

    fig, panels = build_figure(scenes, dpi=50.0)  # the stray pixel shows at 50 dpi as at 100
    strip = panels[0].parts_out
    ax = strip.axes
    end = ax.get_xlim()[1]
    size = scenario.part.size_in

    def pixels_past_the_end(squares: list[float]) -> np.ndarray:
        strip.set_verts([[(x - size / 2, -size / 2), (x + size / 2, -size / 2),
                          (x + size / 2, size / 2), (x - size / 2, size / 2)] for x in squares])
        strip.set_facecolor([to_rgba(PART_COLOUR)] * len(squares))
        fig.canvas.draw()
        rgba = np.asarray(fig.canvas.buffer_rgba())
        box = ax.bbox
        rows = slice(rgba.shape[0] - int(box.y1), rgba.shape[0] - int(box.y0))
        return rgba[rows, int(np.ceil(box.x1)):int(np.ceil(box.x1)) + 3].copy()

    empty = pixels_past_the_end([])
    np.testing.assert_array_equal(pixels_past_the_end([end, end - 3 * size]), empty)
    np.testing.assert_array_equal(pixels_past_the_end([end]), empty)


def test_a_frame_looks_the_robot_up_once_and_draws_the_held_part_between_the_fingers(
        scenes: list[Scene], monkeypatch: pytest.MonkeyPatch) -> None:
    """While a part is in the hand, one frame asks for the joints once, and the part (its
    number) is drawn midway between the finger tips drawn in the same frame."""
    from cell.reporting.animation import arm_pose as robot
    from cell.reporting.animation import render
    from cell.reporting.animation.render import build_figure, draw_frame

    sc = scenes[0]
    d = sc.data
    i = int(np.flatnonzero(d.picked)[1])
    t = float(d.pick_s[i] + d.touchdown_s[i]) / 2
    assert parts_at(sc, t).where[i] == HAND
    panel = build_figure(scenes, dpi=20.0)[1][0]
    asked: list[object] = []
    original = robot.robot_state

    def counted(*args: object) -> object:
        asked.append(args[1])
        return original(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(robot, "robot_state", counted)
    monkeypatch.setattr(render, "robot_state", counted, raising=False)
    draw_frame(panel, t)
    assert asked == [t]
    fingers = np.column_stack(panel.arm[2].get_data())
    assert panel.labels[i].get_position() == pytest.approx(fingers.mean(axis=0), abs=1e-9)
