"""A reader that goes away (``cell run ... | head -1``) does not stop a command half-way."""

import io
import os
import subprocess
import sys

import pandas as pd
import pytest

from cell.plumbing.streams import Guarded, reader_may_leave


def _with_closed_reader(args, tmp_path, unbuffered, closed="stdout"):
    """Run ``cell ARGS`` with stdout (or stderr) a pipe whose reader has already left."""
    read, write = os.pipe()
    os.close(read)  # every write to the pipe now fails with EPIPE
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    if unbuffered:  # as in many containers: each print reaches the pipe at once
        env["PYTHONUNBUFFERED"] = "1"
    other = subprocess.PIPE
    try:
        streams = {"stdout": write, "stderr": other} if closed == "stdout" else \
            {"stdout": other, "stderr": write}
        res = subprocess.run([sys.executable, "-m", "cell", *args], env=env, cwd=os.getcwd(),
                             text=True, **streams)
    finally:
        os.close(write)
    return res


@pytest.mark.parametrize("unbuffered", [True, False])
def test_cell_run_writes_its_files_when_stdout_is_closed(tmp_path, unbuffered):
    """Unbuffered, the heading's print met the closed pipe before the run: nothing was written
    and the exit code was 0; buffered, the last flush failed with exit 120 and two lines."""
    out = tmp_path / "run"
    res = _with_closed_reader(["run", "baseline", "--set", "run.parts=5", "--out", str(out)],
                              tmp_path, unbuffered)
    assert res.returncode == 0, res.stderr
    assert res.stderr == ""
    parts = pd.read_csv(out / "parts.csv")
    summary = pd.read_csv(out / "summary.csv").iloc[0]
    assert list(parts.part) == [1, 2, 3, 4, 5]
    assert summary.parts_arrived == 5
    assert summary.parts_arrived == summary.parts_delivered + summary.parts_missed \
        + summary.parts_in_cell


def test_cell_run_writes_its_files_when_stderr_is_closed(tmp_path):
    """A warning on stderr (offered load over 1) met the closed pipe during the run."""
    out = tmp_path / "run"
    res = _with_closed_reader(["run", "baseline", "--set", "run.parts=5", "--set",
                               "arrivals={distribution: gamma, mean_s: 5, cv: 0.5}",
                               "--out", str(out)], tmp_path, True, closed="stderr")
    assert res.returncode == 0
    assert "parts arrived / delivered" in res.stdout
    assert len(pd.read_csv(out / "parts.csv")) == 5


@pytest.mark.parametrize("args", [["scenarios"], ["docs"], ["schema"]])
def test_listings_end_quietly_when_stdout_is_closed(tmp_path, args):
    res = _with_closed_reader(args, tmp_path, False)
    assert (res.returncode, res.stderr) == (0, "")


def test_cell_path_ends_quietly_when_stdout_is_closed(tmp_path):
    out = tmp_path / "steps.csv"
    res = _with_closed_reader(["path", "baseline", "--out", str(out)], tmp_path, False)
    assert (res.returncode, res.stderr) == (0, "")
    assert len(pd.read_csv(out)) == 460


@pytest.mark.parametrize("unbuffered", [True, False])
def test_a_refused_command_keeps_exit_2_when_stderr_is_closed(tmp_path, unbuffered):
    """The error line met the closed pipe outside the guard: exit 120 (its last flush), or 1
    and a traceback unbuffered, where a refused command ends with 2."""
    res = _with_closed_reader(["run", str(tmp_path / "missing.yaml"), "--out", str(tmp_path / "o")],
                              tmp_path, unbuffered, closed="stderr")
    assert (res.returncode, res.stdout) == (2, "")
    res = _with_closed_reader(["run", "--no-such-option"], tmp_path, unbuffered, closed="stderr")
    assert (res.returncode, res.stdout) == (2, "")


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


def test_every_command_outlives_its_reader(tmp_path):
    """The guard is around every command (cell.cli.main), not only those that write files: a sweep
    and a compare with --out (its report drawn) write their sets whole behind a closed stdout."""
    sweep = tmp_path / "s.yaml"
    sweep.write_text("base: baseline\nset: {run.parts: 10}\npolicies: [adaptive, non-adaptive]\n"
                     "replications: 2\nbatch: 2\n")
    res = _with_closed_reader(["sweep", str(sweep), "--out", str(tmp_path / "o"), "--workers",
                               "1"], tmp_path, True)
    assert res.returncode == 0, res.stderr
    assert len(pd.read_csv(tmp_path / "o" / "replications.csv")) == 4
    res = _with_closed_reader(["compare", "baseline", "non_adaptive", "--replications", "2",
                               "--set", "run.parts=10", "--workers", "1",
                               "--out", str(tmp_path / "cmp")], tmp_path, False)
    assert (res.returncode, res.stderr.count("Exception ignored")) == (0, 0), res.stderr
    assert (tmp_path / "cmp" / "report.md").is_file()


TRACE = "interarrival_s\n" + "".join(f"{22 + (i * 7919 % 13) / 5:.3f}\n" for i in range(60))


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
@pytest.mark.parametrize("args", [["fit", "{trace}"],
                                  ["compare", "baseline", "non_adaptive", "--replications", "2",
                                   "--set", "run.parts=10"]], ids=["fit", "compare"])
def test_a_product_on_stdout_that_cannot_be_written_is_an_error(tmp_path, args):
    """stdout on a full device (ENOSPC): the command's product is lost, so exit 2 and one line
    naming standard output (it exited 0); a reader that left (EPIPE) stays no error."""
    trace = tmp_path / "trace.csv"
    trace.write_text(TRACE)
    argv = [sys.executable, "-m", "cell", *(a.replace("{trace}", str(trace)) for a in args)]
    with open("/dev/full", "w") as full:
        res = subprocess.run(argv, stdout=full, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    lines = [x for x in res.stderr.splitlines() if "%)" not in x]  # compare's progress lines
    assert res.returncode == 2 and len(lines) == 1 and "standard output" in lines[0], res.stderr
    if args[0] == "fit":
        res = _with_closed_reader([a.replace("{trace}", str(trace)) for a in args], tmp_path, False)
        assert (res.returncode, res.stderr) == (0, "")
