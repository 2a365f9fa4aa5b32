"""``cell animate``: every part is drawn where the belts and the arm put it, and the
file is a whole GIF (or nothing at all).

Positions are checked against facts computed here, not by the animation's code:
belt travel by fine numerical integration of the recorded speed history, the
named points of the scenario (B, LO, F, G, TD, K, §4.2), the records' event
instants (arrival, at B, LO, TD) and regime times.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageSequence
from scipy.integrate import cumulative_trapezoid  # type: ignore[import-untyped]

from cell.animation import animate, simulate_scenes
from cell.animation.scene import (
    ABSENT,
    HAND,
    INPUT,
    OUTPUT,
    TAIL_S,
    Scene,
    arm_pose,
    parts_at,
    robot_state,
    time_at,
    travel,
    window,
)
from cell.commands.animate import add_arguments
from cell.commands.animate import main as cmd_animate
from cell.errors import CellError
from cell.figures.motion import timeline
from cell.scenario import Scenario, default_scenario

FIRST, COUNT = 2, 6


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return default_scenario().with_overrides({"controller.nominal_cycle_s": 22.5872})


@pytest.fixture(scope="module")
def scenes(scenario: Scenario) -> list[Scene]:
    """Both policies, the same parts (common random numbers)."""
    return simulate_scenes(scenario, ["adaptive", "non-adaptive"], FIRST, COUNT)


def integrated(history: np.ndarray, until_s: float, dt: float = 1e-3):  # noqa: ANN201
    """X(t) of a belt by the trapezoid rule on a fine grid, speeds looked up the plain way."""
    grid = np.arange(0.0, until_s + dt, dt)
    speed = np.empty_like(grid)
    for start, v in history:                  # each change holds from its instant on
        speed[grid >= start] = v
    x = cumulative_trapezoid(speed, grid, initial=0.0)
    return lambda t: np.interp(t, grid, x)


def sample_times(scenes: list[Scene]) -> np.ndarray:
    t0, t1 = window(scenes, FIRST, COUNT)
    return np.linspace(t0 - 40.0, t1, 400)


def named_points(s: Scenario) -> dict[str, np.ndarray]:
    p = s.path
    b, g = np.array(p.bot_in), np.array(p.g_in)
    return {"B": b, "F": np.array(p.f_in), "G": g, "K": np.array(p.eot_in),
            "LO": np.array([b[0] + p.lo_from_bot_in, b[1], p.pick_height_in]),
            "TD": np.array([g[0], g[1] + p.td_from_g_in, p.place_height_in])}


# --------------------------------------------------------------------------- belts
def test_travel_is_the_area_under_the_speed_history() -> None:
    history = np.array([[0.0, 3.0], [10.0, 1.0], [20.0, 2.0]])
    assert travel(history, [0.0, 5.0, 10.0, 15.0, 25.0]) == pytest.approx([0, 15, 30, 35, 50])
    assert time_at(history, [15.0, 35.0, 50.0]) == pytest.approx([5.0, 15.0, 25.0])


def test_the_input_length_is_two_nominal_cycles_of_belt(scenes: list[Scene],
                                                         scenario: Scenario) -> None:
    """Baseline leaves it empty: 2 x 3.0 in/s x 22.5872 s = 135.52 in (README)."""
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
    from cell.simulation import simulate

    for sc in scenes:
        d = sc.data
        run = simulate(scenario.with_overrides({"controller.policy": d.policy,
                                                "run.parts": len(d.part)}))
        for belt, history in (("input", d.input_belt), ("output", d.output_belt)):
            rows = sorted((c.from_s, c.speed_in_s) for c in run.belt_changes if c.belt == belt)
            np.testing.assert_array_equal(history, np.array(rows))
        assert len(np.unique(d.input_belt[:, 1])) > 2 or d.policy == "non-adaptive"


def output_reach(panel) -> float:  # noqa: ANN001
    """The farthest y (in) of output belt drawn: the strip's end or the close-up's top."""
    return max(panel.parts_out.axes.get_xlim()[1], panel.parts.axes.get_ylim()[1])


def square_centres(collection) -> np.ndarray:  # noqa: ANN001
    """Centres of the squares a PolyCollection draws."""
    return np.array([p.vertices[:4].mean(axis=0) for p in collection.get_paths()]).reshape(-1, 2)


@pytest.mark.parametrize("policy", [0, 1], ids=["adaptive", "non-adaptive"])
def test_drawn_parts_sit_where_the_belts_travel_puts_them(scenes: list[Scene], scenario: Scenario,
                                                          policy: int) -> None:
    """At sampled frames, the squares drawn on the two belt strips are exactly the parts the
    records put there, each where the belt's integrated travel has carried it: dropped
    ``input_length`` upstream of B, fallen off at F (lying just past it), or set down at TD
    (and kept until it is a part's size past the farthest output belt drawn)."""
    from cell.animation.render import build_figure, draw_frame
    from cell.animation.scene import FALL_S

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
    from cell.animation.render import build_figure, draw_frame

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

    from cell.animation.render import PART_COLOUR, build_figure

    fig, panels = build_figure(scenes, dpi=100.0)
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


def test_the_demo_shows_a_part_the_fixed_cycle_loses_and_the_adaptive_saves() -> None:
    from cell.animation import DEMO_FIRST, DEMO_PARTS
    from cell.scenario import load_scenario

    adaptive, fixed = simulate_scenes(load_scenario("baseline"), ["adaptive", "non-adaptive"],
                                      DEMO_FIRST, DEMO_PARTS)
    shown = slice(DEMO_FIRST - 1, DEMO_FIRST - 1 + DEMO_PARTS)
    assert adaptive.data.picked[shown].all()
    assert (~fixed.data.picked[shown]).sum() >= 2


# --------------------------------------------------------------------------- the arm
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


# --------------------------------------------------------------------------- files
def gif_durations_ms(path: Path) -> list[int]:
    """Each frame's delay, read back by Pillow (the file must be a GIF)."""
    assert path.read_bytes()[:4] == b"GIF8"
    with Image.open(path) as im:
        return [int(frame.info["duration"]) for frame in ImageSequence.Iterator(im)]


def gif_frames(path: Path) -> int:
    return len(gif_durations_ms(path))


def test_a_short_gif_is_written_whole(tmp_path: Path, scenario: Scenario) -> None:
    from cell.simulation import simulate

    parts = simulate(scenario.with_overrides({"run.parts": 3})).parts
    step = 20.0                                   # --speed 120 at 6 fps
    t0 = parts["arrival_s"].iloc[0]
    t1 = parts["touchdown_s"].iloc[0] + TAIL_S
    out = tmp_path / "cell.gif"
    done = animate(scenario, out, policy="adaptive", parts=1, speed=120.0, fps=6, dpi=20.0,
                   progress=False)
    assert gif_frames(out) == done.frames == int((t1 - t0) // step) + 1
    # plays at 6 frames a second although GIF delays are whole hundredths
    assert sum(gif_durations_ms(out)) == pytest.approx(1000 * done.frames / 6, abs=10)
    with Image.open(out) as im:
        assert im.size == (120, 140)
    assert [p.name for p in tmp_path.iterdir()] == ["cell.gif"]


def test_both_policies_side_by_side(tmp_path: Path, scenario: Scenario) -> None:
    out = tmp_path / "both.gif"
    done = animate(scenario, out, policy="both", parts=2, first=3, speed=240.0, fps=6,
                   dpi=20.0, progress=False)
    assert gif_frames(out) == done.frames >= 2
    with Image.open(out) as im:
        assert im.size == (220, 140)


def parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return parser.parse_args(argv)


@pytest.fixture
def no_simulation(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("simulated before checking --out")

    monkeypatch.setattr("cell.simulation.simulate", refuse)


def test_mp4_without_ffmpeg_is_one_clear_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                               no_simulation: None) -> None:
    from matplotlib.animation import writers

    monkeypatch.setattr(writers, "is_available", lambda name: False)
    with pytest.raises(CellError, match="MP4 needs ffmpeg on the PATH; write a .gif instead"):
        cmd_animate(parse(["scenarios/baseline.yaml", "--out", str(tmp_path / "a.mp4")]))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["a.png", "a", "a.gif.tmp"])
def test_a_bad_suffix_is_refused(tmp_path: Path, name: str, no_simulation: None) -> None:
    with pytest.raises(CellError, match=r"\.gif or \.mp4"):
        cmd_animate(parse(["scenarios/baseline.yaml", "--out", str(tmp_path / name)]))
    assert list(tmp_path.iterdir()) == []


def test_a_failed_render_leaves_nothing(tmp_path: Path, scenario: Scenario,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    def half(scenes: object, times: object, out: Path, **kwargs: object) -> None:
        out.write_bytes(b"GIF89a")
        raise RuntimeError("interrupted")

    monkeypatch.setattr("cell.animation.render.render", half)
    with pytest.raises(RuntimeError):
        animate(scenario, tmp_path / "a.gif", parts=1, progress=False)
    assert list(tmp_path.iterdir()) == []


def test_importing_the_command_loads_no_plotting() -> None:
    code = "import sys, cell.animation; print('matplotlib' in sys.modules, 'numpy' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


def test_a_gif_too_long_to_hold_is_refused_before_drawing(tmp_path: Path,
                                                          scenario: Scenario) -> None:
    with pytest.raises(CellError, match="raise --speed"):
        animate(scenario, tmp_path / "a.gif", parts=12, speed=0.05, progress=False)
    assert list(tmp_path.iterdir()) == []
