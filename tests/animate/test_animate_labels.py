"""What a frame says about itself: each panel's header names the scenario, the seed and a
fixed robot's cycle, inside the frame and clear of the title and the drawing."""

from __future__ import annotations

from matplotlib.text import Text

from cell.animation import simulate_scenes
from cell.animation.scene import Scene
from cell.scenario import Scenario


def header_texts(fig) -> list[Text]:  # noqa: ANN001
    return [t for t in fig.texts if " · seed " in t.get_text()]


def test_each_panel_names_the_scenario_the_seed_and_a_fixed_cycle(scenario: Scenario) -> None:
    from cell.animation.render import build_figure

    s = scenario.with_overrides({"name": "slow-robot", "run.seed": 7})
    fixed = s.with_overrides({"controller.policy": "non-adaptive", "controller.ideal_cycle_s": 21.0})
    scenes = [*simulate_scenes(s, ["adaptive"], 1, 1), *simulate_scenes(fixed, ["non-adaptive"], 1, 1)]
    fig, panels = build_figure(scenes, dpi=100.0)
    headers = header_texts(fig)
    assert [t.get_text() for t in headers] == [
        "slow-robot · seed 7", "slow-robot · seed 7 · fixed cycle 21.0000 s"]
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
    from cell.animation.render import header

    assert header(scenes[0]) == "baseline · seed 1984"
    assert header(scenes[1]) == "baseline · seed 1984 · fixed cycle 22.5872 s"
