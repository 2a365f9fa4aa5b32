"""Kill tests through the real commands: SIGKILL at every file-system step of ``cell run`` leaves
the old set or the new one, never a mixed or partial one, by exchange and by the fallback (each
step of the output protocol is a rule: the planner's report and every other set commit through
the same OutputDir, so ``cell run`` walks its steps for them).

Each child is a fork of this process running the command's ``main`` (the planner's results,
already solved here, are shared), with every open, mkdir, fsync, rename, exchange, unlink,
rmdir and link counted; at the k-th it kills itself, for k = 1, 2, ... until it finishes.
"""

from __future__ import annotations

import contextlib
import io
import os
from pathlib import Path

import pytest

import cell.plumbing.output.atomic as output
from cell.plumbing.output.atomic import OutputDir

from ..killing import die_at_step
from .harness import case, tree

NAMES = ["parts.csv", "summary.csv", "belts.csv"]


def _run_killed_at(k: int, job, fallback: bool) -> int:
    """Fork; the child runs ``job()`` and SIGKILLs itself at its ``k``-th file-system step (open,
    mkdir, fsync, rename, exchange, unlink, rmdir).  The child's wait status."""
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child never returns
        try:
            die_at_step(k, fallback)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 1)
            os.dup2(devnull, 2)
            job()
        finally:
            os._exit(0)
    _, status = os.waitpid(pid, 0)
    return status


def _every_kill(tmp_path: Path, target: Path, write_old, job, names, fallback: bool) -> set[str]:
    """Kill ``job`` at step 1, 2, ... until it finishes: each time ``target`` holds the old set or
    the new one whole (absent too, with the fallback, until the next run puts the old one back)."""
    write_old()
    old = tree(target)
    job()
    new = tree(target)
    assert old != new and old is not None and new is not None
    seen = set()
    for k in range(1, 200):
        write_old()
        status = _run_killed_at(k, job, fallback)
        state = {_key(old): "old", _key(new): "new"}.get(_key(tree(target)), "mixed")
        seen.add(state if tree(target) is not None else "absent")
        assert state in ("old", "new") or fallback and tree(target) is None, \
            f"killed at step {k}: {target} holds {sorted(tree(target) or [])}"
        OutputDir(target, names).discard()  # what the next run does first: clean up, put back
        assert _key(tree(target)) in (_key(old), _key(new))
        assert sorted(p.name for p in target.parent.iterdir() if p.name.startswith("." + target.name)) == []
        if os.WIFEXITED(status):
            assert tree(target) == new
            break
    else:
        pytest.fail("the command never finished")
    for _ in range(k):
        case("kill step", "other")
    assert k > 10 and {"old", "new"} <= seen
    print(f"{target.name}: finished at step {k}; seen {sorted(seen)}")
    return seen


def _key(files: dict[str, bytes] | None) -> tuple | None:
    return None if files is None else tuple(sorted(files.items()))


@pytest.mark.parametrize("fallback", [False, True], ids=["exchange", "fallback"])
def test_cell_run_killed_at_any_step_leaves_the_old_set_or_the_new(tmp_path, fallback):
    """The real ``cell run`` (a forked process), SIGKILLed at each file-system step in turn."""
    if not fallback and output._renameat2 is None:
        pytest.skip("no renameat2 here")
    from cell.cli.main import main

    target = tmp_path / "run"
    argv = ["run", "baseline", "--set", "run.parts=8", "--out", str(target), "--force"]  # again
    seen = _every_kill(tmp_path, target, lambda: _quiet(main, argv + ["--set", "run.seed=1"]),
                       lambda: _quiet(main, argv + ["--set", "run.seed=2"]), NAMES, fallback)
    assert seen <= {"old", "new", "absent"}


def _quiet(main, argv):
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(argv) == 0
