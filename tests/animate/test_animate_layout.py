"""``cell animate`` draws a layout (docs/layout.md): a buffer's waiting parts stand queued at
the gate at B at their pitch, read from the scene's data against the run's own record of who
waited when (parts.csv's ``at_bot_s`` and ``buffer_wait_s``); a line's second station is drawn
beside the first with the parts the first set down (series) or let go (downstream), its robot
carrying them."""

from __future__ import annotations

import numpy as np
import pytest

from cell.reporting.animation.movie import simulate_scenes
from cell.reporting.animation.scene import INPUT, Scene, parts_at
from cell.scenario.schema import load_scenario

PITCH = 3.0
#: The instants the queue is checked at, 2.1 s apart (a default frame is 20/12 s of the run):
#: over 200 of them find two parts or more queued.
STEP_S = 2.1


@pytest.fixture(scope="module")
def buffered() -> Scene:
    s = load_scenario("baseline", {
        "controller.policy": "non-adaptive", "controller.ideal_cycle_s": 22.0,
        "arrivals": {"distribution": "expon", "params": {"loc": 0.0, "scale": 14.0}},
        "buffer": {"places": 3, "pitch_in": PITCH}})
    return simulate_scenes(s, ["non-adaptive"], 1, 40)[0]


def test_the_parts_that_wait_stand_at_the_gate_at_their_pitch(buffered: Scene) -> None:
    d = buffered.data
    assert d.buffer_wait_s is not None and d.pitch_in == PITCH
    reached = d.at_bot_s - d.buffer_wait_s  # when each came to B (docs/layout.md)
    b, size = buffered.b_xy[0], buffered.scenario.part.size_in
    seen = 0
    for t in np.arange(reached[0], d.at_bot_s[-10], STEP_S):
        waiting = np.flatnonzero((d.buffer_wait_s > 0) & (reached <= t) & (t < d.at_bot_s))
        at = parts_at(buffered, float(t))
        order = waiting[np.argsort(d.at_bot_s[waiting])]  # the gate lets them go in order
        assert (at.where[order] == INPUT).all()
        assert at.xy[order, 0] == pytest.approx(b - PITCH * np.arange(len(order)), abs=1e-9), t
        assert at.xy[order, 1] == pytest.approx(np.full(len(order), buffered.b_xy[1]))
        # no part the robot will take is past the gate before it is let go, nor two closer
        # than a part's size (the feeder's clearance; those a full buffer lets ride past go
        # by on its bypass)
        before = (at.where == INPUT) & (d.at_bot_s > t) & d.picked
        xs = np.sort(at.xy[before, 0])
        assert (xs <= b + 1e-9).all() and (np.diff(xs) >= size - 1e-9).all(), t
        seen += len(order) >= 2
    assert seen > 5  # the run queued two parts or more at many of the frames


def test_a_part_let_go_moves_on_from_b_with_the_belt(buffered: Scene) -> None:
    from cell.reporting.animation.scene import travel

    d = buffered.data
    i = int(np.flatnonzero((d.buffer_wait_s > 0) & d.picked)[0])
    t = (d.at_bot_s[i] + d.pick_s[i]) / 2  # tracked, not yet lifted
    moved = travel(d.input_belt, t) - travel(d.input_belt, d.at_bot_s[i])
    assert parts_at(buffered, float(t)).xy[i, 0] == pytest.approx(buffered.b_xy[0] + moved)


def test_cell_animate_draws_a_buffer(tmp_path) -> None:  # noqa: ANN001
    from cell.cli.main import main

    out = tmp_path / "buffer.gif"
    assert main(["animate", "baseline", "--set", "buffer.places=2", "--parts", "3",
                 "--speed", "60", "--fps", "2", "--dpi", "20", "--out", str(out)]) == 0
    assert out.stat().st_size > 0


def _line(placement: dict) -> list[Scene]:
    s = load_scenario("baseline", {
        "controller.policy": "non-adaptive", "controller.ideal_cycle_s": 24.0,
        "arrivals": {"distribution": "expon", "params": {"loc": 0.0, "scale": 18.0}},
        "stations": [{"name": "two", "controller": {"policy": "non-adaptive",
                                                    "ideal_cycle_s": 20.5}, **placement}]})
    return simulate_scenes(s, ["non-adaptive"], 1, 16)


@pytest.fixture(scope="module")
def series() -> list[Scene]:
    return _line({"placement": "series", "transfer_in": 60.0})


@pytest.fixture(scope="module")
def downstream() -> list[Scene]:
    return _line({"placement": "downstream", "offset_in": 40.0})


def _held(scene: Scene, times: np.ndarray) -> set[int]:
    """The part numbers the scene's robot holds at any of ``times``."""
    from cell.reporting.animation.scene import HAND

    return {int(scene.data.part[i]) for t in times
            for i in np.flatnonzero(parts_at(scene, float(t)).where == HAND)}


def test_a_series_station_is_drawn_with_the_parts_the_first_set_down(series) -> None:  # noqa: ANN001
    from cell.reporting.animation.scene import frame_times, window

    first, two = series
    assert two.data.station == "two, series" and not first.data.station
    d1, d2 = first.data, two.data
    set_down = dict(zip(d1.part[d1.picked], d1.touchdown_s[d1.picked]))
    assert set(d2.part) <= set(set_down)  # it is fed by the first's output belt alone
    assert d2.arrival_s == pytest.approx([set_down[p] for p in d2.part])  # at the touch-down
    assert d2.input_length_in == 60.0  # transfer_in from TD to its B
    times = frame_times(*window(series, 1, 16), 0.5)
    held = _held(two, times)
    assert held and held <= set(d2.part[d2.picked])  # its robot carries what came to it


def test_a_downstream_robot_takes_what_the_first_let_go(downstream) -> None:  # noqa: ANN001
    from cell.reporting.animation.scene import frame_times, window

    first, two = downstream
    assert two.data.station == "two, downstream"
    d1, d2 = first.data, two.data
    let_go = set(d1.part[~d1.picked])
    assert let_go and set(d2.part) <= let_go  # what it let ride past, nothing else
    assert (d2.arrival_s > d1.at_bot_s[np.searchsorted(d1.part, d2.part)]).all()
    assert d2.input_length_in == 40.0  # offset_in past the first's F
    times = frame_times(*window(downstream, 1, 16), 0.5)
    held = _held(two, times)
    assert held and held <= let_go  # it catches parts the first let ride past


def test_cell_animate_draws_a_line(tmp_path) -> None:  # noqa: ANN001
    from cell.cli.main import main

    out = tmp_path / "line.gif"
    assert main(["animate", "two_station_line", "--parts", "3", "--speed", "60", "--fps", "2",
                 "--dpi", "20", "--out", str(out)]) == 0
    assert out.stat().st_size > 0
