"""``cell animate`` shows a stop: the stopped equipment marked, with its repair clock."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.colors import to_rgba

from cell.reporting.animation.arm_pose import robot_state
from cell.reporting.animation.movie import simulate_scenes
from cell.reporting.animation.render import build_figure, draw_frame
from cell.reporting.animation.stops import DOWN_COLOUR, OperatingClock, duration, stop_lines
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


def test_the_operating_clock_takes_the_robots_stops_out() -> None:
    """Two overlapping robot stops merge, a belt's stop is not the robot's, and ``wall``
    inverts ``operating`` (to a stop's start, the earliest instant reaching it)."""
    clock = OperatingClock.of([("robot", "failure", 10.0, 20.0), ("input_belt", "failure", 0, 99),
                               ("robot", "maintenance", 15.0, 25.0), ("robot", "wear", 40, 45)])
    assert clock.start_s.tolist() == [10.0, 40.0] and clock.end_s.tolist() == [25.0, 45.0]
    t = np.array([5.0, 10.0, 17.0, 25.0, 30.0, 42.0, 50.0])
    assert clock.operating(t).tolist() == [5.0, 10.0, 10.0, 10.0, 15.0, 25.0, 30.0]
    assert clock.wall([5.0, 10.0, 15.0, 25.0, 30.0]).tolist() == [5.0, 10.0, 30.0, 40.0, 50.0]


def test_the_arm_stands_still_while_the_robot_is_down_mid_move() -> None:
    """A breakdown while a part is in the hand (``part_in_hand: finish``): the arm's joints do
    not move through the stop, and after the repair the cycle goes on from there, reaching
    the path's TD point at the part's recorded touch-down and B again its regime times
    plus the stop after its start."""
    s = default_scenario().with_overrides({"failures": {"robot": {
        "time_to_failure": {"distribution": "expon", "params": {"scale": 600}},
        "time_to_repair": {"distribution": "expon", "params": {"scale": 60}},
        "clock": "calendar"}}})
    (scene,) = simulate_scenes(s, ["adaptive"], first=14, count=4)
    d, path = scene.data, scene.table.path
    caught = [(a, b, i) for name, _, a, b in scene.stops
              for i in np.flatnonzero(d.picked & (d.pick_s < a) & (d.touchdown_s > a))]
    assert caught, "the seed's first breakdowns catch a part in the hand"
    a, b, i = caught[0]
    still = robot_state(scene, np.linspace(a, b, 9)[:-1])
    assert np.ptp(still.q_rad, axis=0).max() == 0.0 and (still.part == i).all()
    assert robot_state(scene, d.touchdown_s[i]).q_rad[0] == pytest.approx(path.q_rad[path.td])
    row = int(np.flatnonzero(scene.cycle_part == i)[0])
    assert scene.cycle_t_s[row, -1] == pytest.approx(d.start_s[i] + d.regime_s[i].sum() + b - a)
