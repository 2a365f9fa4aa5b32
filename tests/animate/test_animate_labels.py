"""What a frame says about itself: each panel's header names the scenario, the seed and a
fixed robot's cycle, inside the frame and clear of the title and the drawing; part numbers
of any length stay inside their squares; the clock reads h:mm:ss past an hour."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from matplotlib.text import Text

from cell.reporting.animation.movie import simulate_scenes
from cell.reporting.animation.scene import INPUT, Scene, parts_at
from cell.scenario.schema import Scenario

from .helpers import sample_times


def header_texts(fig) -> list[Text]:  # noqa: ANN001
    return [t for t in fig.texts if " · seed " in t.get_text()]


def test_each_panel_names_the_scenario_the_seed_and_a_fixed_cycle(scenario: Scenario) -> None:
    from cell.reporting.animation.render import build_figure

    s = scenario.with_overrides({"name": "slow-robot", "run.seed": 7})
    fixed = s.with_overrides({"controller.policy": "non-adaptive", "controller.ideal_cycle_s": 21.0})
    scenes = [*simulate_scenes(s, ["adaptive"], 1, 1), *simulate_scenes(fixed, ["non-adaptive"], 1, 1)]
    fig, panels = build_figure(scenes, dpi=100.0)
    headers = header_texts(fig)
    assert [t.get_text().split(" · ") for t in headers] == [
        ["slow-robot", "seed 7"], ["slow-robot", "seed 7", "fixed cycle 21.0000 s"]]
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    frame = fig.bbox
    titles = [t for t in fig.texts if "§" in t.get_text()]
    assert len(titles) == 2
    for header, title, panel in zip(headers, titles, panels):
        box = header.get_window_extent(renderer)
        assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and box.y1 <= frame.y1
        assert not box.overlaps(title.get_window_extent(renderer))
        assert not box.overlaps(panel.parts.axes.get_window_extent(renderer))


def test_the_thesis_fixed_cycle_is_the_one_the_run_used(scenes: list[Scene]) -> None:
    from cell.reporting.animation.render import header

    assert header(scenes[0]).split(" · ") == ["baseline", "seed 1984"]
    assert header(scenes[1]).split(" · ") == ["baseline", "seed 1984", "fixed cycle 22.5872 s"]


@pytest.mark.parametrize("offset", [0, 199_990, 9_999_990], ids=["1-2 digits", "6", "8"])
def test_part_numbers_stay_inside_their_squares(scenes: list[Scene], offset: int) -> None:
    """Parts renumbered as deep into a run (``--from-part``): every label shown on the input
    belt in the close-up, where squares are not turned, fits inside its square."""
    from cell.reporting.animation.render import build_figure, draw_frame

    deep = dataclasses.replace(scenes[0], data=dataclasses.replace(
        scenes[0].data, part=scenes[0].data.part + offset))
    fig, (panel,) = build_figure([deep], dpi=100.0)
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    ax = panel.parts.axes
    side_px = np.diff(ax.transData.transform([(0, 0), (deep.scenario.part.size_in, 0)])[:, 0])[0]
    checked = 0
    for t in sample_times(scenes)[::10]:
        draw_frame(panel, float(t))
        at = parts_at(deep, float(t))
        for i in np.flatnonzero(at.where == INPUT):
            label = panel.labels[int(i)]
            if not label.get_visible():
                continue
            assert len(label.get_text()) == len(str(deep.data.part[i]))
            box = label.get_window_extent(renderer)
            if box.x1 < ax.bbox.x0:  # outside the close-up (labels are clipped to it)
                continue
            centre = ax.transData.transform(at.xy[i])
            assert box.x0 >= centre[0] - side_px / 2 and box.x1 <= centre[0] + side_px / 2
            assert box.y0 >= centre[1] - side_px / 2 and box.y1 <= centre[1] + side_px / 2
            checked += 1
    assert checked > 5


def test_the_clock_reads_hours_past_an_hour() -> None:
    from cell.reporting.animation.render import clock

    assert clock(0.0) == "t =    0.0 s"
    assert clock(3599.94) == "t = 3599.9 s"
    assert clock(3600.0) == "t = 1:00:00.0"
    assert clock(3659.96) == "t = 1:01:00.0"
    assert clock(4_516_646.1) == "t = 1254:37:26.1"
    assert 1254 * 3600 + 37 * 60 + 26.1 == pytest.approx(4_516_646.1)
