"""An MP4 stopped half-way: Ctrl-C is one line and exit 130, and a killed run's file is
swept away by the next run to the same name.  These need ffmpeg (on the PATH, or the
imageio-ffmpeg wheel's); without it they are skipped."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cell.cli.main import main as cli
from cell.plumbing.output.atomic import atomic_path

from ..outputs import dead_pid


def ffmpeg() -> str | None:
    found = shutil.which("ffmpeg")
    if found is None:
        try:
            import imageio_ffmpeg  # type: ignore[import-not-found]
        except ImportError:
            return None
        found = imageio_ffmpeg.get_ffmpeg_exe()
    return found


@pytest.fixture
def ffmpeg_path(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> str:
    """A PATH with ffmpeg on it (here and for child processes), or the test is skipped."""
    exe = ffmpeg()
    if exe is None:
        pytest.skip("no ffmpeg on the PATH and no imageio-ffmpeg")
    bin_dir = tmp_path_factory.mktemp("bin")
    (bin_dir / "ffmpeg").symlink_to(exe)
    path = f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}"
    monkeypatch.setenv("PATH", path)
    return path


def started(out: Path) -> subprocess.Popen[str]:
    """``cell animate`` writing ``out`` in its own process group, once it is drawing frames
    (its progress lines come on stderr when that is not a terminal)."""
    proc = subprocess.Popen([sys.executable, "-m", "cell", "animate", "baseline", "--out", str(out),
                             "--parts", "8", "--speed", "40", "--dpi", "30"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    assert proc.stderr is not None
    for line in proc.stderr:
        if " frames (" in line:
            return proc
    raise AssertionError(f"no frames drawn: {proc.wait()}")


def settled(folder: Path, timeout_s: float = 20.0) -> None:
    """Wait until the files in ``folder`` stop changing (an orphaned ffmpeg finishing)."""
    def sizes() -> list[tuple[str, int]]:
        return sorted((p.name, p.stat().st_size) for p in folder.iterdir())

    before, end = sizes(), time.monotonic() + timeout_s
    while time.monotonic() < end:
        time.sleep(0.5)
        now = sizes()
        if now == before:
            return
        before = now


def test_ctrl_c_while_writing_an_mp4_is_one_line(tmp_path: Path, ffmpeg_path: str) -> None:
    """Ctrl-C reaches the whole foreground group: ffmpeg dies too, and it is still
    ``cell: interrupted``, exit 130, nothing left (not matplotlib's CalledProcessError)."""
    out = tmp_path / "out"
    out.mkdir()
    proc = started(out / "a.mp4")
    os.killpg(proc.pid, signal.SIGINT)
    rest = proc.communicate()[1]  # the rest, then closed and waited for
    assert proc.returncode == 130, rest
    said = [line for line in rest.splitlines() if " frames (" not in line]
    assert said == ["cell: interrupted"]
    assert list(out.iterdir()) == []


def test_a_killed_mp4_leaves_only_what_the_next_run_sweeps(tmp_path: Path, ffmpeg_path: str,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    """SIGKILL leaves the hidden temporary file (ffmpeg, orphaned, may still write it); the
    next run to the same name removes it: no ``.a.mp4.cell-PID-….tmp.mp4`` stays behind."""
    out = tmp_path / "out"
    out.mkdir()
    proc = started(out / "a.mp4")
    proc.kill()
    proc.communicate()
    settled(out)
    left = [p.name for p in out.iterdir()]
    assert len(left) == 1 and left[0].startswith(f".a.mp4.cell-{proc.pid}-"), left
    assert cli(["animate", "baseline", "--out", str(out / "a.mp4"), "--parts", "1",
                "--speed", "200", "--dpi", "20"]) == 0
    assert [p.name for p in out.iterdir()] == ["a.mp4"]
    assert (out / "a.mp4").read_bytes()[4:8] == b"ftyp"  # an MP4 whatever ffmpeg was handed


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_older_versions_staged_animations_are_swept(tmp_path: Path, suffix: str) -> None:
    """Before, an animation was staged as ``.NAME.cell-PID-XXXX.tmp`` + NAME's suffix: a dead
    process's is removed with its ``.tmp``; a live one's, and other names, are kept."""
    target = tmp_path / f"a{suffix}"
    dead = f".a{suffix}.cell-{dead_pid()}-x1y2z3.tmp"
    live = f".a{suffix}.cell-{os.getpid()}-q1w2e3.tmp{suffix}"
    other = f".a{suffix}.cell-{dead_pid()}-x1y2z3.tmp.png"
    for name in (dead, dead + suffix, live, other):
        (tmp_path / name).write_bytes(b"half")
    with atomic_path(target) as tmp:
        tmp.write_bytes(b"new")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([live, other, target.name])
