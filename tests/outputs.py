"""Helpers of the output tests (test_output.py, test_output_dir.py): sets written and read back,
a full disk, a dead process's id."""

from __future__ import annotations

import errno
import os
import subprocess
import sys
from pathlib import Path

from cell.plumbing.output.atomic import OutputDir

NAMES = ["parts.csv", "summary.csv", "belts.csv"]
ROOT = Path(__file__).resolve().parent.parent


def current_umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


def write_set(target: Path, tag: str, names: list[str] = NAMES) -> None:
    with OutputDir(target, NAMES) as out:
        for name in names:
            out.write_text(name, f"{name} {tag}\n" * 50)


def set_state(target: Path) -> str | None:
    """"old" or "new" when ``target`` holds that whole set, None when absent; anything else fails."""
    if not target.exists():
        return None
    files = {p.name: p.read_text() for p in target.iterdir()}
    for tag in ("old", "new"):
        if files == {name: f"{name} {tag}\n" * 50 for name in NAMES}:
            return tag
    raise AssertionError(f"{target} holds a mixed or partial set: {sorted(files)}")


def siblings(target: Path) -> list[str]:
    return sorted(p.name for p in target.parent.iterdir())


def dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def one_line(exc: BaseException) -> str:
    text = str(exc)
    assert "\n" not in text and len(text) < 300, text
    return text


class FullFile:
    """A file on a disk with room for 10 bytes."""

    def __init__(self, stream):
        self.stream, self.room = stream, 10

    def write(self, data):
        if len(data) > self.room:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        self.room -= len(data)
        return self.stream.write(data)

    def __getattr__(self, name):
        return getattr(self.stream, name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stream.close()


def full_disk_open(path, mode="r", **kwargs):
    return FullFile(open(path, mode, **kwargs))
