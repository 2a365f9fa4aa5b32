"""Any environment: closed or full standard streams, a deleted working directory, odd HOME /
XDG_* / MPLCONFIGDIR, a low open-file limit, empty or impossible output paths.  Each case:
a correct run or one clean line, its exit code, and nothing left behind on failure."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

from cell.scenario import catalog
from tests.prose import in_order

BASELINE = str(catalog.path("baseline"))
RUN = ["run", BASELINE, "--set", "run.parts=20"]


def _cell(args, cwd: Path, env=None, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "cell", *args], cwd=cwd, text=True,
                          env={**os.environ, **(env or {})}, timeout=300, **kw)


def _files(out: Path) -> list[str]:
    return sorted(p.name for p in out.iterdir())


def test_closed_standard_streams_still_give_a_whole_run(tmp_path):
    out = tmp_path / "o"
    p = _cell([*RUN, "--out", str(out)], tmp_path, stdin=subprocess.DEVNULL,
              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
              pass_fds=(), preexec_fn=lambda: [os.close(fd) for fd in (0, 1, 2)])
    assert p.returncode == 0
    assert _files(out) == ["belts.csv", "parts.csv", "summary.csv"]
    assert (out / "summary.csv").read_text().startswith("scenario,")  # no stray print inside


def test_a_closed_stderr_on_a_refusal_is_exit_2_and_nothing_written(tmp_path):
    p = _cell(["run", BASELINE, "--set", "run.parts=-1", "--out", str(tmp_path / "o")],
              tmp_path, stdout=subprocess.DEVNULL, preexec_fn=lambda: os.close(2))
    assert p.returncode == 2 and os.listdir(tmp_path) == []


def test_a_deleted_working_directory_is_one_line(tmp_path):
    gone = tmp_path / "gone"
    gone.mkdir()
    p = subprocess.run(f"cd {gone} && rmdir {gone} && exec {sys.executable} -m cell run "
                       f"{BASELINE} --out o", shell=True, capture_output=True, text=True, timeout=300)
    assert p.returncode == 2
    (line,) = p.stderr.splitlines()
    assert in_order(line, "cell: error: the working directory", "(no such file or directory)", "cd ")
    assert os.listdir(tmp_path) == []


def test_a_file_for_home_prints_no_library_warning_and_leaves_no_temporary_folder(tmp_path):
    home = tmp_path / "home"
    home.write_text("")
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    out = tmp_path / "a.gif"
    env = {"HOME": str(home), "TMPDIR": str(tmp), "XDG_CACHE_HOME": "", "XDG_CONFIG_HOME": "",
           "MPLCONFIGDIR": ""}
    p = _cell(["animate", BASELINE, "--parts", "1", "--speed", "500", "--dpi", "20", "--out",
               str(out)], tmp_path, env=env, capture_output=True)
    assert p.returncode == 0, p.stderr
    assert [x for x in p.stderr.splitlines() if " frames (" not in x] == []
    assert os.listdir(tmp) == []
    assert out.read_bytes()[:3] == b"GIF"


def test_relative_home_and_cache_leave_nothing_in_the_working_directory(tmp_path):
    p = _cell([*RUN, "--out", str(tmp_path / "o")], tmp_path,
              env={"HOME": "rel-home", "XDG_CACHE_HOME": "rel-cache"}, capture_output=True)
    assert p.returncode == 0, p.stderr
    assert os.listdir(tmp_path) == ["o"]


def test_a_sweep_on_two_workers_under_twelve_open_files_is_one_line(tmp_path):
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(f"base: {BASELINE}\ngrid: {{run.parts: [20, 21, 22]}}\nreplications: 2\n")

    def low() -> None:
        resource.setrlimit(resource.RLIMIT_NOFILE, (12, 12))

    p = _cell(["sweep", str(sweep), "--out", str(tmp_path / "o"), "--workers", "2"],
              tmp_path, capture_output=True, preexec_fn=low)
    if p.returncode == 0:  # a machine where it fits: then it must be whole
        assert (tmp_path / "o" / "replications.csv").is_file()
        return
    assert p.returncode == 2, p.stderr
    assert in_order(p.stderr.splitlines()[-1], "cell: error: cell sweep:", "too many open files",
                    "may open 12", "ulimit -n", "--workers")
    assert os.listdir(tmp_path) == ["sweep.yaml"]


@pytest.mark.parametrize("args,says", [
    (["compare", "baseline", "non_adaptive", "--out", ""], "--out '': an empty path"),
    (["sweep", "SWEEP", "--out", "o", "--report", ""], "--report '': an empty path"),
    (["sweep", "SWEEP", "--out", "o", "--report", "o/report"], "inside the results folder"),
    (["sweep", "SWEEP", "--out", "o", "--report", "/proc/report"], "under /proc"),
    (["run", "baseline", "--out", "/sys/o"], "under /sys"),
])
def test_impossible_outputs_are_refused_before_any_work(tmp_path, monkeypatch, capsys, args, says):
    from cell.cli.main import main

    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(f"base: {BASELINE}\nset: {{run.parts: 20}}\nreplications: 2\n")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("cell.experiments.sweep.runner.run_sweep", None)  # reached: a TypeError, not 2
    monkeypatch.setattr("cell.sim.simulation.simulate", None)
    code = main([str(sweep) if a == "SWEEP" else a for a in args])
    err = capsys.readouterr().err.splitlines()
    assert code == 2 and len(err) == 1 and says in err[0], err
    assert os.listdir(tmp_path) == ["sweep.yaml"]
