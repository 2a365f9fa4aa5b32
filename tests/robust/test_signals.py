"""SIGINT and SIGTERM at any moment of a command: ``cell: interrupted`` (130) or
``cell: terminated`` (143), its temporary folders removed, finished outputs intact.

Each test waits for a readiness marker on disk (a temporary folder, a finished task) before
it sends the signal: no fixed delays.  The first milliseconds, before any command runs:
tests/robust/test_signals_startup.py.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cell.scenario import catalog

BASELINE = str(catalog.path("baseline"))
NON_ADAPTIVE = str(catalog.path("non_adaptive"))
LINES = {signal.SIGINT: (130, "cell: interrupted"), signal.SIGTERM: (143, "cell: terminated")}


def _start(args, tmp_path: Path) -> subprocess.Popen:
    tmp = tmp_path / "tmp"
    tmp.mkdir(exist_ok=True)
    env = {**os.environ, "TMPDIR": str(tmp), "XDG_CACHE_HOME": str(tmp_path / ".cache")}
    return subprocess.Popen([sys.executable, "-m", "cell", *args], cwd=tmp_path, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def _wait_for(proc: subprocess.Popen, ready, what: str, limit_s: float = 120) -> None:
    end = time.monotonic() + limit_s
    while not ready():
        if proc.poll() is not None:
            pytest.fail(f"ended ({proc.returncode}) before {what}: {proc.stderr.read()}")
        if time.monotonic() > end:
            proc.kill()
            pytest.fail(f"no {what} within {limit_s} s")
        time.sleep(0.01)


def _stop(proc: subprocess.Popen, number: int) -> list[str]:
    proc.send_signal(number)
    err = proc.communicate()[1]  # read to the end, closed, waited for
    code = proc.returncode
    expected_code, line = LINES[number]
    assert code == expected_code, err
    lines = [x for x in err.splitlines() if "%)" not in x and not x.startswith("cell: warning")]
    assert lines[-1] == line or lines[-1].startswith("cell sweep: stopped"), err
    return lines


def _left(folder: Path) -> list[str]:
    """What is in ``folder`` beside the cache the test gave the command."""
    return sorted(name for name in os.listdir(folder) if name != ".cache")


def _glob(folder: Path, pattern: str) -> list[Path]:
    return list(folder.glob(pattern)) if folder.is_dir() else []


@pytest.mark.parametrize("number", [signal.SIGTERM])
def test_compare_stopped_removes_its_temporary_folder(tmp_path, number):
    out = tmp_path / "cmp"
    proc = _start(["compare", BASELINE, NON_ADAPTIVE, "--set", "run.parts=200",
                   "--replications", "3000", "--workers", "1", "--out", str(out)], tmp_path)
    _wait_for(proc, lambda: _glob(tmp_path / "tmp", "cell-compare-*/**/sweep.json"),
              "compare's temporary folder")
    assert _stop(proc, number) == [LINES[number][1]]
    assert list((tmp_path / "tmp").iterdir()) == []
    assert not out.exists()


def test_run_terminated_leaves_no_output_and_no_staging(tmp_path):
    out = tmp_path / "run"
    proc = _start(["run", BASELINE, "--set", "run.parts=2000000", "--out", str(out)], tmp_path)
    _wait_for(proc, lambda: _glob(tmp_path, ".run.cell-tmp-*/parts.csv"), "the run's staging")
    assert _stop(proc, signal.SIGTERM)[-1] == "cell: terminated"
    assert _left(tmp_path) == ["tmp"] and list((tmp_path / "tmp").iterdir()) == []


def test_sweep_terminated_keeps_its_finished_tasks_for_resume(tmp_path):
    sweep = tmp_path / "sweep.yaml"
    # 8 tasks of 3 x 500 parts: the 7 left after the first outlast the few ms the test takes
    # to see it and send the signal, on a loaded machine too
    sweep.write_text(f"base: {BASELINE}\ngrid: {{run.parts: [500, 501, 502, 503, 504, "
                     "505, 506, 507]}\nreplications: 3\nseed: 1\n")
    out = tmp_path / "out"
    proc = _start(["sweep", str(sweep), "--out", str(out), "--workers", "1"], tmp_path)
    _wait_for(proc, lambda: _glob(out, "tasks/task-*.csv"), "a finished task")
    lines = _stop(proc, signal.SIGTERM)
    assert "--resume" in lines[-1]
    kept = {p.name: p.read_bytes() for p in _glob(out, "tasks/task-*.csv")}
    assert kept and not (out / "replications.csv").exists()
    assert _glob(out, "tasks/.task-*.tmp") == []


def _swallowed_then(number: int, error: BaseException):
    """A command that gets ``number`` while it works, loses the KeyboardInterrupt it raised
    (as code that catches too much would), then fails with ``error``: the race of Ctrl-C and
    ffmpeg, which the same Ctrl-C stopped first (a broken pipe, or its exit status)."""
    def main(args):
        try:
            os.kill(os.getpid(), number)
            for _ in range(1000):  # the handler runs here
                pass
        except KeyboardInterrupt:
            pass
        raise error
    return main


# each signal once and each kind of error once (the signal's line and the error's kind are
# separate rules: two cases walk both)
@pytest.mark.parametrize("number,error", [
    (signal.SIGINT, BrokenPipeError(32, "Broken pipe")),
    (signal.SIGTERM, RuntimeError("ffmpeg stopped with exit status 255"))],
    ids=["SIGINT, broken pipe", "SIGTERM, another error"])
def test_a_stop_that_became_another_error_is_still_the_stop(monkeypatch, capsys, number, error):
    from cell.cli.main import main

    monkeypatch.setattr("cell.cli.scenarios.main", _swallowed_then(number, error))
    assert main(["scenarios"]) == LINES[number][0]
    assert capsys.readouterr().err == LINES[number][1] + "\n"


def test_a_refusal_that_came_of_a_stop_is_the_stop(monkeypatch, capsys):
    from cell.cli.main import main
    from cell.plumbing.errors import CellError

    monkeypatch.setattr("cell.cli.scenarios.main",
                        _swallowed_then(signal.SIGINT, CellError("a.mp4: ffmpeg stopped")))
    assert main(["scenarios"]) == 130
    assert capsys.readouterr().err == "cell: interrupted\n"


class _StoppedInADestructor:
    """An object whose destructor gets the signal and lets its handler run there, where Python
    drops whatever is raised ("Exception ignored in": matplotlib's many weakref callbacks
    made a Ctrl-C during ``cell figures`` print a traceback, now and then)."""

    def __init__(self, number: int):
        self.number = number

    def __del__(self):
        os.kill(os.getpid(), self.number)
        for _ in range(1000):  # the handler runs here, and what it raises is dropped
            pass


@pytest.mark.parametrize("number", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_stop_raised_in_a_destructor_still_stops_the_command_and_says_only_its_line(
        monkeypatch, capsys, number):
    import threading

    from cell.cli.main import main

    went_on = []

    def command(args):
        _StoppedInADestructor(number)  # made and freed at once
        threading.Event().wait(20)  # the stop, raised again, ends this wait
        went_on.append(True)
        return 0

    monkeypatch.setattr("cell.cli.scenarios.main", command)
    assert main(["scenarios"]) == LINES[number][0]
    assert capsys.readouterr().err == LINES[number][1] + "\n"
    assert went_on == []
