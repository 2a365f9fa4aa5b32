"""A reader that goes away (``cell run ... | head -1``) does not stop a command half-way.

The commands run in real processes (a real pipe whose reader left, a real full device, the
interpreter's own flush as it exits, PYTHONUNBUFFERED read at start-up), several in one process
(tests/plumbing/closed_reader.py): one buffered, one unbuffered."""

import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from cell.plumbing.streams import Guarded, reader_may_leave

DRIVER = Path(__file__).with_name("closed_reader.py")
TRACE = "interarrival_s\n" + "".join(f"{22 + (i * 7919 % 13) / 5:.3f}\n" for i in range(60))
FULL = os.path.exists("/dev/full")


def _in_one_process(tmp: Path, commands: dict[str, dict], unbuffered: bool) -> dict[str, dict]:
    """Each of ``commands`` (name: args, closed stream, device) run in one real ``cell`` process;
    its outcome by name (see closed_reader.py), the process itself ending 0 and saying nothing."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    if unbuffered:  # as in many containers: each print reaches the pipe at once
        env["PYTHONUNBUFFERED"] = "1"
    spec, results = tmp / "spec.json", tmp / "results.json"
    spec.write_text(json.dumps(list(commands.values())))
    proc = subprocess.run([sys.executable, str(DRIVER), str(spec), str(results)], env=env,
                          cwd=tmp, capture_output=True, text=True, timeout=600)
    assert (proc.returncode, proc.stdout, proc.stderr) == (0, "", ""), proc.stderr
    outcomes = json.loads(results.read_text())
    for outcome in outcomes:  # nothing escaped main(), and its last flush would not fail (120)
        assert (outcome["escaped"], outcome["flush"]) == (None, None), outcome
    return dict(zip(commands, outcomes))


def _stdout_closed(*args, device="pipe"):
    return {"args": [str(a) for a in args], "closed": "stdout", "device": device}


def _stderr_closed(*args):
    return {"args": [str(a) for a in args], "closed": "stderr", "device": "pipe"}


@pytest.fixture(scope="module")
def buffered(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("buffered")
    (tmp / "trace.csv").write_text(TRACE)
    commands = {
        "run": _stdout_closed("run", "baseline", "--set", "run.parts=5", "--out", tmp / "run"),
        "scenarios": _stdout_closed("scenarios"),
        "docs": _stdout_closed("docs"),
        "schema": _stdout_closed("schema"),
        "path": _stdout_closed("path", "baseline", "--out", tmp / "steps.csv"),
        "missing": _stderr_closed("run", tmp / "missing.yaml", "--out", tmp / "o"),
        "option": _stderr_closed("run", "--no-such-option"),
        "compare": _stdout_closed("compare", "baseline", "non_adaptive", "--replications", "2",
                                  "--set", "run.parts=10", "--workers", "1", "--out", tmp / "cmp"),
        "fit": _stdout_closed("fit", tmp / "trace.csv"),
    }
    if FULL:
        commands["run full"] = _stdout_closed("run", "baseline", "--set", "run.parts=20", "--out",
                                              tmp / "run-full", device="full")
        commands["fit full"] = _stdout_closed("fit", tmp / "trace.csv", device="full")
        commands["compare full"] = _stdout_closed(
            "compare", "baseline", "non_adaptive", "--replications", "2", "--set", "run.parts=10",
            device="full")
    return tmp, _in_one_process(tmp, commands, unbuffered=False)


@pytest.fixture(scope="module")
def unbuffered(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("unbuffered")
    (tmp / "s.yaml").write_text("base: baseline\nset: {run.parts: 10}\npolicies: [adaptive, "
                                "non-adaptive]\nreplications: 2\nbatch: 2\n")
    commands = {
        "run": _stdout_closed("run", "baseline", "--set", "run.parts=5", "--out", tmp / "run"),
        "warning": _stderr_closed("run", "baseline", "--set", "run.parts=5", "--set",
                                  "arrivals={distribution: gamma, mean_s: 5, cv: 0.5}",
                                  "--out", tmp / "warned"),
        "missing": _stderr_closed("run", tmp / "missing.yaml", "--out", tmp / "o"),
        "option": _stderr_closed("run", "--no-such-option"),
        "sweep": _stdout_closed("sweep", tmp / "s.yaml", "--out", tmp / "sw", "--workers", "1"),
    }
    return tmp, _in_one_process(tmp, commands, unbuffered=True)


@pytest.mark.parametrize("mode", ["unbuffered", "buffered"])
def test_cell_run_writes_its_files_when_stdout_is_closed(request, mode):
    """Unbuffered, the heading's print met the closed pipe before the run: nothing was written
    and the exit code was 0; buffered, the last flush failed with exit 120 and two lines."""
    tmp, res = request.getfixturevalue(mode)
    assert (res["run"]["code"], res["run"]["other"]) == (0, "")
    out = tmp / "run"
    parts = pd.read_csv(out / "parts.csv")
    summary = pd.read_csv(out / "summary.csv").iloc[0]
    assert list(parts.part) == [1, 2, 3, 4, 5]
    assert summary.parts_arrived == 5
    assert summary.parts_arrived == summary.parts_delivered + summary.parts_missed \
        + summary.parts_in_cell


def test_cell_run_writes_its_files_when_stderr_is_closed(unbuffered):
    """A warning on stderr (offered load over 1) met the closed pipe during the run."""
    tmp, res = unbuffered
    assert res["warning"]["code"] == 0
    assert "parts arrived / delivered" in res["warning"]["other"]
    assert len(pd.read_csv(tmp / "warned" / "parts.csv")) == 5


@pytest.mark.parametrize("name", ["scenarios", "docs", "schema"])
def test_listings_end_quietly_when_stdout_is_closed(buffered, name):
    res = buffered[1][name]
    assert (res["code"], res["other"]) == (0, "")


def test_cell_path_ends_quietly_when_stdout_is_closed(buffered):
    tmp, res = buffered
    assert (res["path"]["code"], res["path"]["other"]) == (0, "")
    assert len(pd.read_csv(tmp / "steps.csv")) == 460


@pytest.mark.parametrize("mode", ["unbuffered", "buffered"])
def test_a_refused_command_keeps_exit_2_when_stderr_is_closed(request, mode):
    """The error line met the closed pipe outside the guard: exit 120 (its last flush), or 1
    and a traceback unbuffered, where a refused command ends with 2."""
    tmp, res = request.getfixturevalue(mode)
    for name in ("missing", "option"):
        assert (res[name]["code"], res[name]["other"]) == (2, ""), name
    assert not (tmp / "o").exists()


class _Gone(io.StringIO):
    def write(self, text):
        raise BrokenPipeError(32, "Broken pipe")

    def fileno(self):
        raise io.UnsupportedOperation("no descriptor")


def test_a_guarded_stream_drops_writes_once_its_reader_is_gone():
    guarded = Guarded(_Gone())
    assert guarded.write("heading\n") == len("heading\n")
    assert guarded.gone
    guarded.write("more\n")
    guarded.flush()


def test_the_streams_are_given_back_after_the_block():
    before = sys.stdout, sys.stderr
    with reader_may_leave():
        assert isinstance(sys.stdout, Guarded) and sys.stdout.stream is before[0]
        print("shown", file=sys.stderr)
    assert (sys.stdout, sys.stderr) == before
    with pytest.raises(KeyError), reader_may_leave():
        raise KeyError("an error goes through")
    assert (sys.stdout, sys.stderr) == before


def test_every_command_outlives_its_reader(buffered, unbuffered):
    """The guard is around every command (cell.cli.main), not only those that write files: a sweep
    and a compare with --out (its report drawn) write their sets whole behind a closed stdout."""
    tmp, res = unbuffered
    progress = [x for x in res["sweep"]["other"].splitlines() if "%)" not in x]
    assert (res["sweep"]["code"], progress) == (0, []), res["sweep"]
    assert len(pd.read_csv(tmp / "sw" / "replications.csv")) == 4
    tmp, res = buffered
    assert (res["compare"]["code"], res["compare"]["other"].count("Exception ignored")) == (0, 0)
    assert (tmp / "cmp" / "report.md").is_file()


@pytest.mark.skipif(not FULL, reason="needs /dev/full")
def test_a_full_stdout_loses_only_the_commentary(buffered):
    """Beside the files a run writes, what it prints is commentary: its loss is no error."""
    tmp, res = buffered
    assert res["run full"]["code"] == 0, res["run full"]
    assert sorted(p.name for p in (tmp / "run-full").iterdir()) == ["belts.csv", "parts.csv",
                                                                    "summary.csv"]


@pytest.mark.skipif(not FULL, reason="needs /dev/full")
@pytest.mark.parametrize("name", ["fit", "compare"])
def test_a_product_on_stdout_that_cannot_be_written_is_an_error(buffered, name):
    """stdout on a full device (ENOSPC): the command's product is lost, so exit 2 and one line
    naming standard output (it exited 0); a reader that left (EPIPE) stays no error."""
    res = buffered[1][f"{name} full"]
    lines = [x for x in res["other"].splitlines() if "%)" not in x]  # compare's progress lines
    assert res["code"] == 2 and len(lines) == 1 and "standard output" in lines[0], res
    if name == "fit":
        assert (buffered[1]["fit"]["code"], buffered[1]["fit"]["other"]) == (0, "")
