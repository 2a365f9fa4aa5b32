"""Ctrl-C and kill during a parallel ``cell sweep``, in a real process: wherever the signal
lands (loading, a worker starting, tasks running), one line, exit 130 (Ctrl-C) or 143
(kill), no traceback, no process of the sweep left, and the finished tasks kept."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
import yaml

from cell.scenario import catalog

#: Long enough (400 one-replication tasks) that every signal below comes while it runs.
SWEEP = {"base": str(catalog.path("baseline")), "set": {"run.parts": 200},
         "policies": ["adaptive", "non-adaptive"], "replications": 200, "batch": 1, "seed": 5}
#: Seconds any one try may take before it counts as a hang.
HANG_S = 90


def _stat(pid: str) -> list[str]:
    """A process's /proc stat fields after its name: state, parent, process group, ..."""
    with open(f"/proc/{pid}/stat", encoding="utf-8") as f:
        return f.read().rsplit(")", 1)[1].split()


def _live(match: Callable[[list[str]], bool]) -> list[int]:
    """The living (not zombie) processes whose stat fields ``match``."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            fields = _stat(pid)
        except OSError:  # ended meanwhile
            continue
        if fields[0] != "Z" and match(fields):
            found.append(int(pid))
    return found


def _catches_sigterm(pid: int) -> bool:
    with open(f"/proc/{pid}/status", encoding="utf-8") as f:
        caught = next(line for line in f if line.startswith("SigCgt:")).split()[1]
    return bool(int(caught, 16) >> (signal.SIGTERM - 1) & 1)


def _while_loading(proc: subprocess.Popen[str]) -> None:
    """As soon as ``cell sweep`` handles kill: it then loads the sweep (seconds of imports
    and checks) before it runs anything."""
    deadline = time.monotonic() + HANG_S
    while not _catches_sigterm(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.005)


def _children(pid: int) -> list[str]:
    """The living (not zombie) children of process ``pid``, from its threads' lists (a scan
    of every process of the machine each 5 ms cost more CPU than the sweep it waited for)."""
    found = []
    for task in Path(f"/proc/{pid}/task").glob("*/children"):
        try:
            found += task.read_text().split()
        except OSError:  # the thread ended meanwhile
            continue
    living = []
    for child in found:
        try:
            if _stat(child)[0] != "Z":
                living.append(child)
        except OSError:  # ended meanwhile
            continue
    return living


def _when_a_worker_starts(proc: subprocess.Popen[str]) -> None:
    deadline = time.monotonic() + HANG_S
    while not _children(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.005)


def _after_some_tasks(proc: subprocess.Popen[str]) -> None:
    assert proc.stderr is not None
    for line in proc.stderr:  # progress lines come on stderr when it is not a terminal
        if "replications (" in line:
            return


def _ctrl_c(proc: subprocess.Popen[str]) -> None:
    """A terminal's Ctrl-C: SIGINT to the whole process group."""
    os.killpg(proc.pid, signal.SIGINT)


def _timeout(proc: subprocess.Popen[str]) -> None:
    """``timeout -s TERM``: SIGTERM to the command, then to its whole group (twice to it)."""
    proc.send_signal(signal.SIGTERM)
    os.killpg(proc.pid, signal.SIGTERM)


def _kill(proc: subprocess.Popen[str]) -> None:
    proc.send_signal(signal.SIGTERM)


@pytest.mark.parametrize(("when", "send", "code", "said"), [
    (_while_loading, _ctrl_c, 130, "cell: interrupted"),
    (_while_loading, _timeout, 143, "cell: terminated"),  # SIGTERM is said as such (issue 25)
    (_when_a_worker_starts, _ctrl_c, 130, "cell sweep: stopped; "),
    (_when_a_worker_starts, _timeout, 143, "cell sweep: stopped; "),
    (_after_some_tasks, _kill, 143, "cell sweep: stopped; "),
])
def test_a_stopped_sweep_says_one_line_and_leaves_nothing_running(tmp_path, when, send, code,
                                                                   said):
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(SWEEP))
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "cell", "sweep", str(path), "--out", str(out),
                             "--workers", "2"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        when(proc)
        send(proc)
        err = proc.communicate(timeout=HANG_S)[1]
    finally:
        left = _live(lambda f: f[2] == str(proc.pid))  # the sweep's process group
        if proc.poll() is None or left:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert not left, f"processes of the sweep still running: {left}"
    lines = [line for line in err.splitlines() if "replications (" not in line]
    assert (proc.returncode, len(lines)) == (code, 1), err
    assert lines[0].startswith(said) and "Traceback" not in err, err
    if said.startswith("cell sweep"):
        kept = len(list(Path(out, "tasks").glob("task-*.csv")))
        assert f"; {kept} finished task" in lines[0] and "--resume" in lines[0]
        if when is _after_some_tasks:
            assert kept > 0
