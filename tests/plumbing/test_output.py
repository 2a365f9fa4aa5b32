"""Atomic output of single files: whole or nothing, checked up front, readable like any new
file, even when killed (sets of files: test_output_dir.py)."""

from __future__ import annotations

import os
import signal
import stat
from pathlib import Path

import pandas as pd
import pytest

import cell.plumbing.output.atomic as output
from cell.plumbing.errors import CellError
from cell.plumbing.output.atomic import OutputDir, atomic_path, check_file, write_csv, write_text
from tests.killing import die_at_step
from tests.outputs import (
    NAMES,
    current_umask,
    dead_pid,
    full_disk_open,
    one_line,
    set_state,
    siblings,
    write_set,
)

# --- single files ---------------------------------------------------------------------------

def test_written_whole_with_ordinary_permissions(tmp_path):
    target = tmp_path / "sub" / "a.csv"
    write_csv(pd.DataFrame({"x": [1.5, 2.0]}), target)
    assert target.read_text() == "x\n1.5\n2.0\n"
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~current_umask()
    assert [p.name for p in target.parent.iterdir()] == ["a.csv"]


def test_failure_leaves_nothing_and_keeps_the_old_file(tmp_path):
    target = tmp_path / "a.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("disk full")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def test_failure_removes_the_directories_it_made(tmp_path):
    with pytest.raises(RuntimeError):
        with atomic_path(tmp_path / "a" / "b" / "c.txt"):
            raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("make, words", [
    (lambda d: (d / "x").mkdir(), "is a directory; name a file"),
    (lambda d: (d / "f").write_text(""), "not a directory"),
])
def test_single_file_targets_checked_up_front(tmp_path, make, words):
    make(tmp_path)
    target = tmp_path / "x" if "directory;" in words else tmp_path / "f" / "x.csv"
    with pytest.raises(CellError) as info:
        check_file(target)
    assert words in one_line(info.value)
    with pytest.raises(CellError, match=words):
        write_text("x", target)
    with pytest.raises(CellError, match="empty path"):
        write_text("x", "")


def test_single_file_full_disk_is_one_line(tmp_path, monkeypatch):
    target = tmp_path / "a.csv"
    target.write_text("old")
    monkeypatch.setattr(output, "_open", full_disk_open)
    with pytest.raises(CellError) as info:
        write_csv(pd.DataFrame({"x": range(1000)}), target)
    assert "no space left on device" in one_line(info.value)
    assert target.read_text() == "old" and siblings(target) == ["a.csv"]


def test_stale_temporary_files_of_killed_writes_are_removed(tmp_path):
    target = tmp_path / "a.json"
    dead = tmp_path / f".a.json.cell-{dead_pid()}-x1y2z3.tmp"
    legacy = tmp_path / ".a.json.k2j4h5g6.tmp"  # an older cell's temporary file
    mine = tmp_path / f".a.json.cell-{os.getpid()}-q1w2e3.tmp"  # a live writer's: kept
    for path in (dead, legacy, mine):
        path.write_text("half")
    write_text("{}\n", target)
    assert siblings(target) == sorted([mine.name, "a.json"])



# --- killed at every step -------------------------------------------------------------------

def _run_child(target: Path, k: int, fallback: bool, names: list[str]) -> int:
    """Fork; the child writes the new set (``names == ["--single"]``: the one file) and SIGKILLs
    itself at its ``k``-th file-system step (tests/killing.py).  The child's wait status: exit 0
    once it finished the write, 1 if it raised, or killed."""
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child never returns
        code = 1
        try:
            die_at_step(k, fallback)
            if names == ["--single"]:
                write_text("new\n", target)
            else:
                with OutputDir(target, names) as d:
                    for name in names:
                        d.write_text(name, f"{name} new\n" * 50)
            code = 0
        finally:
            os._exit(code)
    _, status = os.waitpid(pid, 0)
    return status


def _ended(status: int) -> bool:
    """Whether the child finished (exit 0); else it must have been killed, not raised."""
    assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0 or \
        os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL, status
    return os.WIFEXITED(status)


@pytest.mark.parametrize("fallback", [False, True], ids=["exchange", "fallback"])
def test_killed_at_any_step_leaves_the_old_set_or_the_new(tmp_path, fallback):
    if not fallback and output._renameat2 is None:
        pytest.skip("no renameat2 here")
    target = tmp_path / "run"
    write_set(target, "old")
    seen = set()
    for k in range(1, 100):
        finished = _ended(_run_child(target, k, fallback, NAMES))
        state = set_state(target)
        seen.add(state)
        assert state in (("old", "new", None) if fallback else ("old", "new"))
        OutputDir(target, NAMES).discard()  # the next run cleans up (and puts an old set back)
        assert set_state(target) in ("old", "new") and siblings(target) == ["run"]
        if finished:
            assert state == "new"
            break
        if state == "new":
            write_set(target, "old")
    else:
        pytest.fail("the child never finished")
    assert k > 10 and {"old", "new"} <= seen


def test_single_file_killed_at_any_step_is_old_or_new(tmp_path):
    target = tmp_path / "a.txt"
    target.write_text("old\n")
    for k in range(1, 50):
        finished = _ended(_run_child(target, k, False, ["--single"]))
        assert target.read_text() in ("old\n", "new\n")
        write_text(target.read_text(), target)  # cleans the temporary files of killed writes
        assert siblings(target) == ["a.txt"]
        if finished:
            assert target.read_text() == "new\n"
            break
        target.write_text("old\n")
    else:
        pytest.fail("the child never finished")

