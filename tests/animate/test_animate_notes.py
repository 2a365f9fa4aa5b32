"""What ``cell animate`` says besides the file: the memory refusal's advice fits the
machine, an overloaded cell is warned of as ``cell run`` warns, and parts past the
scenario's run get a note."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.animation import animate
from cell.errors import CellError
from cell.scenario import Scenario


@pytest.mark.parametrize("ffmpeg", [True, False])
def test_the_memory_refusal_suggests_an_mp4_only_with_ffmpeg(
        tmp_path: Path, scenario: Scenario, monkeypatch: pytest.MonkeyPatch, ffmpeg: bool) -> None:
    from matplotlib.animation import writers

    monkeypatch.setattr(writers, "is_available", lambda name: ffmpeg)
    with pytest.raises(CellError, match="raise --speed, lower --dpi or --parts") as info:
        animate(scenario, tmp_path / "a.gif", parts=12, speed=0.05, progress=False)
    assert ("write a .mp4" in str(info.value)) == ffmpeg
    assert list(tmp_path.iterdir()) == []
