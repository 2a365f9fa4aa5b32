"""Atomic output: whole or nothing, checked up front, readable like any new file, even when killed."""

from __future__ import annotations

import errno
import os
import signal
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

import cell.output as output
from cell.errors import CellError
from cell.output import OutputDir, atomic_path, check_file, write_csv, write_text

NAMES = ["parts.csv", "summary.csv", "belts.csv"]
ROOT = Path(__file__).resolve().parent.parent


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


def _write_set(target: Path, tag: str, names: list[str] = NAMES) -> None:
    with OutputDir(target, NAMES) as out:
        for name in names:
            out.write_text(name, f"{name} {tag}\n" * 50)


def _state(target: Path) -> str | None:
    """"old" or "new" when ``target`` holds that whole set, None when absent; anything else fails."""
    if not target.exists():
        return None
    files = {p.name: p.read_text() for p in target.iterdir()}
    for tag in ("old", "new"):
        if files == {name: f"{name} {tag}\n" * 50 for name in NAMES}:
            return tag
    raise AssertionError(f"{target} holds a mixed or partial set: {sorted(files)}")


def _siblings(target: Path) -> list[str]:
    return sorted(p.name for p in target.parent.iterdir())


def _dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def _one_line(exc: BaseException) -> str:
    text = str(exc)
    assert "\n" not in text and len(text) < 300, text
    return text


# --- single files ---------------------------------------------------------------------------

def test_written_whole_with_ordinary_permissions(tmp_path):
    target = tmp_path / "sub" / "a.csv"
    write_csv(pd.DataFrame({"x": [1.5, 2.0]}), target)
    assert target.read_text() == "x\n1.5\n2\n"
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~_umask()
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
    assert words in _one_line(info.value)
    with pytest.raises(CellError, match=words):
        write_text("x", target)
    with pytest.raises(CellError, match="empty path"):
        write_text("x", "")


def test_single_file_full_disk_is_one_line(tmp_path, monkeypatch):
    target = tmp_path / "a.csv"
    target.write_text("old")
    monkeypatch.setattr(output, "_open", _full_disk_open)
    with pytest.raises(CellError) as info:
        write_csv(pd.DataFrame({"x": range(1000)}), target)
    assert "no space left on device" in _one_line(info.value)
    assert target.read_text() == "old" and _siblings(target) == ["a.csv"]


def test_stale_temporary_files_of_killed_writes_are_removed(tmp_path):
    target = tmp_path / "a.json"
    dead = tmp_path / f".a.json.cell-{_dead_pid()}-x1y2z3.tmp"
    legacy = tmp_path / ".a.json.k2j4h5g6.tmp"  # an older cell's temporary file
    mine = tmp_path / f".a.json.cell-{os.getpid()}-q1w2e3.tmp"  # a live writer's: kept
    for path in (dead, legacy, mine):
        path.write_text("half")
    write_text("{}\n", target)
    assert _siblings(target) == sorted([mine.name, "a.json"])


# --- output sets ----------------------------------------------------------------------------

def test_whole_set_appears_with_ordinary_modes(tmp_path):
    target = tmp_path / "new" / "run"
    with OutputDir(target, NAMES) as out:
        out.write_csv("parts.csv", pd.DataFrame({"x": [1.5, 2.0]}))
        out.open("belts.csv", "wb").write(b"b\n")
        with out.open("summary.csv") as stream:
            stream.write("s\n")
        assert not target.exists()  # nothing visible before the end
    assert (target / "parts.csv").read_text() == "x\n1.5\n2\n"
    assert sorted(p.name for p in target.iterdir()) == sorted(NAMES)
    assert _siblings(target) == ["run"]
    umask = _umask()
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
    _write_set(target, "old")
    target.chmod(0o750)
    (target / "belts.csv").unlink()
    _write_set(target, "new")
    assert _state(target) == "new" and _siblings(target) == ["run"]
    assert stat.S_IMODE(target.stat().st_mode) == 0o750  # the directory keeps its mode
    with OutputDir(target, NAMES) as out:
        out.write_text("parts.csv", "only\n")
    assert [p.name for p in target.iterdir()] == ["parts.csv"]  # a set, not a merge


@pytest.mark.parametrize("problem", [RuntimeError("bad input"), KeyboardInterrupt()])
def test_exception_inside_keeps_the_old_set(tmp_path, problem):
    target = tmp_path / "run"
    _write_set(target, "old")
    with pytest.raises(type(problem)):
        with OutputDir(target, NAMES) as out:
            out.write_text("parts.csv", "parts.csv new\n")
            raise problem
    assert _state(target) == "old" and _siblings(target) == ["run"]


def test_exception_in_a_new_place_leaves_nothing(tmp_path):
    with pytest.raises(RuntimeError):
        with OutputDir(tmp_path / "a" / "b" / "run", NAMES):
            raise RuntimeError("bad input")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("write", ["text", "csv", "caller"])
def test_full_disk_is_one_line_and_keeps_the_old_set(tmp_path, monkeypatch, write):
    target = tmp_path / "run"
    _write_set(target, "old")
    monkeypatch.setattr(output, "_open", _full_disk_open)
    with pytest.raises(CellError) as info:
        with OutputDir(target, NAMES) as out:
            out.write_text("parts.csv", "parts.csv new\n")
            if write == "text":
                out.write_text("summary.csv", "x" * 100_000)
            elif write == "csv":
                out.write_csv("summary.csv", pd.DataFrame({"x": range(100_000)}))
            else:  # a library writing to out.path() meets a full disk
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert "no space left on device" in _one_line(info.value)
    assert _state(target) == "old" and _siblings(target) == ["run"]


class _FullFile:
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


def _full_disk_open(path, mode="r", **kwargs):
    return _FullFile(open(path, mode, **kwargs))


@pytest.mark.parametrize("case, words", [
    ("foreign", "holds files cell did not write (notes.txt); choose another --out"),
    ("many foreign", "holds files cell did not write (a.txt, b.txt, c.txt, …)"),
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
    _write_set(target, "old")
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
    assert words in _one_line(info.value)
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
    _write_set(target, "old")
    with pytest.raises(CellError, match="changed while cell ran"):
        with OutputDir(target, NAMES) as out:
            out.write_text("parts.csv", "new\n")
            (target / "notes.txt").write_text("mine")
    assert (target / "notes.txt").read_text() == "mine" and _siblings(target) == ["run"]


def test_a_symlinked_directory_stays_a_link(tmp_path):
    real, link = tmp_path / "real", tmp_path / "link"
    _write_set(real, "old")
    link.symlink_to(real)
    _write_set(link, "new")
    assert link.is_symlink() and _state(real) == "new"
    assert _siblings(real) == ["link", "real"]


def test_stages_of_dead_runs_are_removed_and_live_ones_kept(tmp_path):
    target = tmp_path / "run"
    _write_set(target, "old")
    dead = tmp_path / f".run.cell-tmp-{_dead_pid()}-abc"
    live = tmp_path / f".run.cell-tmp-{os.getpid()}-def"
    for stage in (dead, live):
        stage.mkdir()
        (stage / "parts.csv").write_text("half")
    OutputDir(target, NAMES).discard()
    assert _siblings(target) == [live.name, "run"]


def test_an_old_set_moved_aside_by_a_killed_run_comes_back(tmp_path):
    target = tmp_path / "run"
    _write_set(target, "old")
    target.rename(tmp_path / f".run.cell-old-{_dead_pid()}-xyz")
    OutputDir(target, NAMES).discard()
    assert _state(target) == "old" and _siblings(target) == ["run"]


# --- killed at every step -------------------------------------------------------------------

CHILD = textwrap.dedent("""
    import sys
    import cell.output as out
    from tests.killing import die_at_step

    target, k, fallback, names = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1", sys.argv[4:]
    die_at_step(k, fallback)
    if names == ["--single"]:
        out.write_text("new\\n", target)
    else:
        with out.OutputDir(target, names) as d:
            for name in names:
                d.write_text(name, f"{name} new\\n" * 50)
    print("finished")
""")


def _run_child(target: Path, k: int, fallback: bool, names: list[str]) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-c", CHILD, str(target), str(k), str(int(fallback)), *names],
                          capture_output=True, text=True, timeout=60, env=env)


@pytest.mark.parametrize("fallback", [False, True], ids=["exchange", "fallback"])
def test_killed_at_any_step_leaves_the_old_set_or_the_new(tmp_path, fallback):
    if not fallback and output._renameat2 is None:
        pytest.skip("no renameat2 here")
    target = tmp_path / "run"
    _write_set(target, "old")
    seen = set()
    for k in range(1, 100):
        child = _run_child(target, k, fallback, NAMES)
        assert child.returncode in (0, -signal.SIGKILL), child.stderr
        state = _state(target)
        seen.add(state)
        assert state in (("old", "new", None) if fallback else ("old", "new"))
        OutputDir(target, NAMES).discard()  # the next run cleans up (and puts an old set back)
        assert _state(target) in ("old", "new") and _siblings(target) == ["run"]
        if child.returncode == 0:
            assert "finished" in child.stdout and state == "new"
            break
        if state == "new":
            _write_set(target, "old")
    else:
        pytest.fail("the child never finished")
    assert k > 10 and {"old", "new"} <= seen


def test_single_file_killed_at_any_step_is_old_or_new(tmp_path):
    target = tmp_path / "a.txt"
    target.write_text("old\n")
    for k in range(1, 50):
        child = _run_child(target, k, False, ["--single"])
        assert child.returncode in (0, -signal.SIGKILL), child.stderr
        assert target.read_text() in ("old\n", "new\n")
        write_text(target.read_text(), target)  # cleans the temporary files of killed writes
        assert _siblings(target) == ["a.txt"]
        if child.returncode == 0:
            assert target.read_text() == "new\n"
            break
        target.write_text("old\n")
    else:
        pytest.fail("the child never finished")

