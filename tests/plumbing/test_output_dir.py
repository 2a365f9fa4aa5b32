"""Atomic output of file sets (cell.plumbing.output.atomic.OutputDir): whole or nothing, checked up front,
readable like any new directory; a killed run's stage cleaned up by the next."""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

import pandas as pd
import pytest

import cell.plumbing.output.atomic as output
from cell.plumbing.errors import CellError
from cell.plumbing.output.atomic import OutputDir
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

# --- output sets ----------------------------------------------------------------------------

def test_whole_set_appears_with_ordinary_modes(tmp_path):
    target = tmp_path / "new" / "run"
    with OutputDir(target, NAMES) as out:
        out.write_csv("parts.csv", pd.DataFrame({"x": [1.5, 2.0]}))
        out.open("belts.csv", "wb").write(b"b\n")
        with out.open("summary.csv") as stream:
            stream.write("s\n")
        assert not target.exists()  # nothing visible before the end
    assert (target / "parts.csv").read_text() == "x\n1.5\n2.0\n"
    assert sorted(p.name for p in target.iterdir()) == sorted(NAMES)
    assert siblings(target) == ["run"]
    umask = current_umask()
    assert stat.S_IMODE(target.stat().st_mode) == 0o777 & ~umask
    for path in target.iterdir():
        assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask


def test_streams_left_open_are_flushed_before_the_commit(tmp_path):
    target = tmp_path / "run"
    with OutputDir(target, NAMES) as out:
        stream = out.open("parts.csv")
        stream.write("x,y\n" * 10_000)  # more than one buffer, never closed by the caller
        with pytest.raises(ValueError):
            out.open("summary.csv", "r")
    assert (target / "parts.csv").read_text() == "x,y\n" * 10_000 and stream.closed


@pytest.mark.parametrize("exchange", [True, False], ids=["exchange", "fallback"])
def test_old_set_replaced_as_a_unit(tmp_path, monkeypatch, exchange):
    if not exchange:
        monkeypatch.setattr(output, "_exchange", lambda a, b: False)
    elif output._renameat2 is None:
        pytest.skip("no renameat2 here")
    target = tmp_path / "run"
    write_set(target, "old")
    target.chmod(0o750)
    (target / "belts.csv").unlink()
    write_set(target, "new")
    assert set_state(target) == "new" and siblings(target) == ["run"]
    assert stat.S_IMODE(target.stat().st_mode) == 0o750  # the directory keeps its mode
    with OutputDir(target, NAMES) as out:
        out.write_text("parts.csv", "only\n")
    assert [p.name for p in target.iterdir()] == ["parts.csv"]  # a set, not a merge


@pytest.mark.parametrize("problem", [RuntimeError("bad input"), KeyboardInterrupt()])
def test_exception_inside_keeps_the_old_set(tmp_path, problem):
    target = tmp_path / "run"
    write_set(target, "old")
    with pytest.raises(type(problem)):
        with OutputDir(target, NAMES) as out:
            out.write_text("parts.csv", "parts.csv new\n")
            raise problem
    assert set_state(target) == "old" and siblings(target) == ["run"]


def test_exception_in_a_new_place_leaves_nothing(tmp_path):
    with pytest.raises(RuntimeError):
        with OutputDir(tmp_path / "a" / "b" / "run", NAMES):
            raise RuntimeError("bad input")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("write", ["text", "csv", "caller"])
def test_full_disk_is_one_line_and_keeps_the_old_set(tmp_path, monkeypatch, write):
    target = tmp_path / "run"
    write_set(target, "old")
    monkeypatch.setattr(output, "_open", full_disk_open)
    with pytest.raises(CellError) as info:
        with OutputDir(target, NAMES) as out:
            out.write_text("parts.csv", "parts.csv new\n")
            if write == "text":
                out.write_text("summary.csv", "x" * 100_000)
            elif write == "csv":
                out.write_csv("summary.csv", pd.DataFrame({"x": range(100_000)}))
            else:  # a library writing to out.path() meets a full disk
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert "no space left on device" in one_line(info.value)
    assert set_state(target) == "old" and siblings(target) == ["run"]


@pytest.mark.parametrize("case, words", [
    ("foreign", "holds files this command does not write (notes.txt); choose another --out"),
    ("many foreign", "holds files this command does not write (a.txt, b.txt, c.txt, …)"),
    ("a file", "is a file, not a directory; choose another --out"),
    ("under a file", "not a directory ("),
    ("empty", "'': an empty path; name a directory"),
    ("current directory", "holds the current directory"),
    ("read-only parent", "permission denied"),
    ("read-only file system", "read-only file system"),
    ("mkdtemp refused", "permission denied"),
])
def test_refusals_are_one_line_and_change_nothing(tmp_path, monkeypatch, case, words):
    target = tmp_path / "run"
    write_set(target, "old")
    if case == "foreign":
        (target / "notes.txt").write_text("mine")
    elif case == "many foreign":
        for name in "abcd":
            (target / f"{name}.txt").write_text("mine")
    elif case == "a file":
        target = tmp_path / "run" / "parts.csv"
    elif case == "under a file":
        target = tmp_path / "run" / "parts.csv" / "deeper" / "out"
    elif case == "empty":
        target = ""
    elif case == "current directory":
        monkeypatch.chdir(target)
        target = Path(".")
    elif case == "read-only parent":  # root may write anyway: make the check see what a user would
        monkeypatch.setattr(os, "access", lambda path, mode: False)
    elif case == "read-only file system":
        monkeypatch.setattr(os, "statvfs", lambda path: os.statvfs_result((0,) * 8 + (os.ST_RDONLY, 255)))
    else:
        def refuse(*args, **kwargs):
            raise PermissionError(errno.EACCES, "Permission denied")
        monkeypatch.setattr(output.tempfile, "mkdtemp", refuse)
        target = tmp_path / "fresh" / "run"
    before = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*"))
    with pytest.raises(CellError) as info:
        OutputDir(target, NAMES)
    assert words in one_line(info.value)
    assert sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*")) == before


def test_check_changes_nothing(tmp_path):
    assert OutputDir.check(tmp_path / "a" / "b" / "run", NAMES) == tmp_path / "a" / "b" / "run"
    assert list(tmp_path.iterdir()) == []


def test_what_cell_may_replace(tmp_path):
    target = tmp_path / "report"
    names = ["table.md", "fig_*.png", "tasks/task-*.csv"]
    with OutputDir(target, names) as out:
        out.write_text("table.md", "t\n")
        out.open("fig_1.png", "wb").write(b"\x89PNG")
        out.write_text("tasks/task-0001.csv", "x\n")
        with pytest.raises(ValueError):
            out.path("notes.txt")
        with pytest.raises(ValueError):
            out.path("tasks/../../escape.csv")
    # an OS's junk and an older cell's temporary file do not make the directory foreign
    (target / ".DS_Store").write_text("")
    (target / ".table.md.abcd1234.tmp").write_text("half")
    with OutputDir(target, names) as out:
        out.write_text("table.md", "t2\n")
    assert sorted(p.name for p in target.iterdir()) == ["table.md"]
    (target / "tasks").mkdir()
    (target / "tasks" / "mine.txt").write_text("x")
    with pytest.raises(CellError, match=r"tasks/mine\.txt"):
        OutputDir(target, names)


def test_a_file_added_while_running_stops_the_commit(tmp_path):
    target = tmp_path / "run"
    write_set(target, "old")
    with pytest.raises(CellError, match="changed while cell ran"):
        with OutputDir(target, NAMES) as out:
            out.write_text("parts.csv", "new\n")
            (target / "notes.txt").write_text("mine")
    assert (target / "notes.txt").read_text() == "mine" and siblings(target) == ["run"]


def test_a_symlinked_directory_stays_a_link(tmp_path):
    real, link = tmp_path / "real", tmp_path / "link"
    write_set(real, "old")
    link.symlink_to(real)
    write_set(link, "new")
    assert link.is_symlink() and set_state(real) == "new"
    assert siblings(real) == ["link", "real"]


def test_stages_of_dead_runs_are_removed_and_live_ones_kept(tmp_path):
    target = tmp_path / "run"
    write_set(target, "old")
    dead = tmp_path / f".run.cell-tmp-{dead_pid()}-abc"
    live = tmp_path / f".run.cell-tmp-{os.getpid()}-def"
    for stage in (dead, live):
        stage.mkdir()
        (stage / "parts.csv").write_text("half")
    OutputDir(target, NAMES).discard()
    assert siblings(target) == [live.name, "run"]


def test_an_old_set_moved_aside_by_a_killed_run_comes_back(tmp_path):
    target = tmp_path / "run"
    write_set(target, "old")
    target.rename(tmp_path / f".run.cell-old-{dead_pid()}-xyz")
    OutputDir(target, NAMES).discard()
    assert set_state(target) == "old" and siblings(target) == ["run"]
