"""``cell animate``, the file: a whole GIF at the asked rate (or nothing at all), and bad
options refused in one line before anything is simulated."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image, ImageSequence

from cell.cli.animate import add_arguments
from cell.cli.animate import main as cmd_animate
from cell.plumbing.errors import CellError
from cell.reporting.animation.movie import animate
from cell.reporting.animation.scene import TAIL_S
from cell.scenario.schema import Scenario


def gif_durations_ms(path: Path) -> list[int]:
    """Each frame's delay, read back by Pillow (the file must be a GIF)."""
    assert path.read_bytes()[:4] == b"GIF8"
    with Image.open(path) as im:
        return [int(frame.info["duration"]) for frame in ImageSequence.Iterator(im)]


def gif_frames(path: Path) -> int:
    return len(gif_durations_ms(path))


def test_a_short_gif_is_written_whole(tmp_path: Path, scenario: Scenario) -> None:
    from cell.sim.simulation import simulate

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

    monkeypatch.setattr("cell.sim.simulation.simulate", refuse)


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

    monkeypatch.setattr("cell.reporting.animation.render.render", half)
    with pytest.raises(RuntimeError):
        animate(scenario, tmp_path / "a.gif", parts=1, progress=False)
    assert list(tmp_path.iterdir()) == []


def test_importing_the_command_loads_no_plotting() -> None:
    code = ("import sys, cell.reporting.animation.movie; "
            "print('matplotlib' in sys.modules, 'numpy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


def test_a_gif_too_long_to_hold_is_refused_before_drawing(tmp_path: Path,
                                                          scenario: Scenario) -> None:
    with pytest.raises(CellError, match="raise --speed"):
        animate(scenario, tmp_path / "a.gif", parts=12, speed=0.05, progress=False)
    assert list(tmp_path.iterdir()) == []
