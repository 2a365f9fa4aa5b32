"""``cell animate`` shows a stop: the stopped equipment marked, with its repair clock."""

from __future__ import annotations

import pytest
from matplotlib.colors import to_rgba

from cell.reporting.animation.movie import simulate_scenes
from cell.reporting.animation.render import build_figure, draw_frame
from cell.reporting.animation.stops import DOWN_COLOUR, duration, stop_lines
from cell.scenario.schema import default_scenario


def test_the_repair_clock_reads_hours_minutes_seconds() -> None:
    assert duration(3725.2) == "1:02:06"
    assert duration(59.5) == "1:00"
    assert duration(-1.0) == "0:00"
    words = stop_lines({"input_belt": ("failure", 90.0), "sensor": ("failure", 5.0)})
    assert words == {"input_belt": "STOPPED (breakdown), back in 1:30",
                     "sensor": "sensor down: back in 0:05"}


def test_a_worn_motor_stops_the_robot_on_the_frames() -> None:
    """Motors that wear out within minutes: a frame inside the robot's stop says so, in red,
    with the time left; a frame after it is the ordinary one again."""
    s = default_scenario().with_overrides({"wear.enabled": True, "wear.rated_life_h": 0.01,
                                           "wear.repair_h": 0.02})
    (scene,) = simulate_scenes(s, ["adaptive"], first=1, count=8)
    assert scene.stops and all(row[:2] == ("robot", "wear") for row in scene.stops)
    _, start, end = scene.stops[0][1:]
    assert end - start == pytest.approx(72.0)
    fig, (panel,) = build_figure([scene], dpi=40)
    draw_frame(panel, start + 30.0)
    assert panel.texts["robot"].get_text() == "robot DOWN (worn motor): back in 0:42"
    assert to_rgba(panel.arm[0].get_color()) == to_rgba(DOWN_COLOUR)
    draw_frame(panel, end + 1e-3)
    assert "DOWN" not in panel.texts["robot"].get_text()
